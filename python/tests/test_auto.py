"""neighbors="auto" (issue 27): per point K and degree chosen, flagged, and
the noise it saw in Result.sigma; same bits for any thread count."""
import numpy as np

import jetfit
from conftest import fib_sphere, save_xyz


def test_auto_sigma_flags_threads():
    rng = np.random.default_rng(27)
    noise = 0.01
    p = fib_sphere(4000) + rng.normal(0, noise, (4000, 3))
    r = jetfit.estimate(p, neighbors="auto", threads=2)
    assert np.all(r.status & jetfit.STATUS["auto"])
    assert np.all((r.neighbors >= 16) & (r.neighbors <= 256))
    assert set(np.unique(r.degree)) <= {2, 3}
    assert np.all(np.isfinite(r.sigma))
    # isotropic noise of sd `noise`: its component along the normal too
    assert 0.6 * noise < np.median(r.sigma) < 1.5 * noise
    r1 = jetfit.estimate(p, neighbors="auto", threads=1)
    for a in ("normal", "k1", "k2", "sigma", "neighbors", "degree", "status"):
        assert np.array_equal(getattr(r, a), getattr(r1, a), equal_nan=True)
    k = jetfit.estimate(p, neighbors="knn:32")
    assert np.all(np.isnan(k.sigma))


def test_auto_capped_clean_only():
    """step 0: a clean cloud's cross-validation caps K (every row flagged
    auto_capped, K <= 24); on the same sphere with noise CV is least at a
    large K and nothing is capped"""
    cap = jetfit.STATUS["auto_capped"]
    clean = jetfit.estimate(fib_sphere(3000), neighbors="auto", threads=2)
    assert np.all(clean.status & cap)
    assert np.all(clean.neighbors <= 24)
    rng = np.random.default_rng(5)
    noisy = jetfit.estimate(fib_sphere(3000) + rng.normal(0, 0.02, (3000, 3)), neighbors="auto")
    assert not np.any(noisy.status & cap)
    assert np.median(noisy.neighbors) > 96


def test_auto_weighted_where_noise_bound():
    """step 0's bias test: on a noisy plane no fit is biased, every row
    takes step 6's weighted mean (flag auto_weighted); on a clean sphere
    (capped) none does"""
    w = jetfit.STATUS["auto_weighted"]
    rng = np.random.default_rng(9)
    p = np.column_stack([rng.random(4000), rng.random(4000), rng.normal(0, 0.003, 4000)])
    plane = jetfit.estimate(p, neighbors="auto", threads=2)
    assert np.all(plane.status & w)
    assert not np.any(plane.status & jetfit.STATUS["auto_capped"])
    clean = jetfit.estimate(fib_sphere(3000), neighbors="auto")
    assert not np.any(clean.status & w)


def test_auto_step0_as_command(cmd, tmp_path):
    """Result.auto_step0 says step 0's decision as the command's summary
    line does, and matches the rows: capped (K <= 24, every row flagged)
    on a clean sphere, no cap on a noisy one; None for knn"""
    clean = fib_sphere(3000)
    rng = np.random.default_rng(5)
    noisy = fib_sphere(3000) + rng.normal(0, 0.02, (3000, 3))
    for name, p in (("clean", clean), ("noisy", noisy)):
        r = jetfit.estimate(p, neighbors="auto", threads=2)
        f = save_xyz(tmp_path / (name + ".xyz"), p)
        _, err = cmd("estimate", f, "-o", tmp_path / "o.ply", "--neighbors", "auto")
        line = [ln for ln in err.splitlines() if ln.startswith("  auto step 0: ")]
        assert line == ["  auto step 0: " + r.auto_step0], (err, r.auto_step0)
        capped = np.all(r.status & jetfit.STATUS["auto_capped"])
        if name == "clean":
            cap = int(r.auto_step0.split(";")[0].removeprefix("K capped at "))
            assert capped and np.all(r.neighbors <= cap)
        else:
            assert r.auto_step0.startswith("no cap on K") and not np.any(r.status & jetfit.STATUS["auto_capped"])
    assert jetfit.estimate(clean, neighbors="knn:16").auto_step0 is None
