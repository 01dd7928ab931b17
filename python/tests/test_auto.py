"""neighbors="auto" (issue 27): per point K and degree chosen, flagged, and
the noise it saw in Result.sigma; same bits for any thread count."""
import numpy as np

import jetfit
from conftest import fib_sphere


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
