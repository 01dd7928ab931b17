"""Issue 31: the module follows the command where it said nothing.

- No point fitted: `jetfit estimate` exits 1 with one line; estimate()
  and estimate_mesh() raise ValueError with the same reason.  Most points
  unfitted: the command's warning, as a RuntimeWarning (the Result is
  returned).
- neighbors="auto" gives a sigma column in the command's output: the
  module's as_structured() and write() carry it too, in the same place,
  byte for byte the command's file; without auto there is none."""
import re
import warnings

import numpy as np
import pytest

import jetfit
from conftest import fib_sphere, save_xyz
from test_command_equal import ply_table


def command_reason(cmd, tmp_path, pts, *flags):
    """The command's line for these points, without 'jetfit: FILE: ' and
    '; nothing written'; asserts exit 1 and no output file."""
    src, out = tmp_path / "in.xyz", tmp_path / "never.ply"
    save_xyz(src, pts)
    rc, err = cmd("estimate", src, "-o", out, "--quiet", *flags, check=False)
    assert rc == 1 and not out.exists(), err
    line = err.strip()
    assert line.count("\n") == 0, err
    m = re.match(r"jetfit: [^:]+: (.*); nothing written$", line)
    assert m, line
    return m.group(1)


def test_no_point_fitted_raises_the_commands_reason(cmd, tmp_path):
    pts = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [np.nan, 0.0, 0.0]])
    want = command_reason(cmd, tmp_path, pts)
    assert "no point could be fitted (1 non-finite, 2 failed)" in want
    with pytest.raises(ValueError) as e:
        jetfit.estimate(pts)
    assert str(e.value) == want


def test_knn1_fails_every_point(cmd, tmp_path):
    """The issue's case: knn:1 leaves no point a fit."""
    pts = fib_sphere(300)
    want = command_reason(cmd, tmp_path, pts, "--neighbors", "knn:1")
    with pytest.raises(ValueError) as e:
        jetfit.estimate(pts, neighbors="knn:1")
    assert str(e.value) == want
    assert "K must be at least 3" in want


def test_every_point_nan(cmd, tmp_path):
    pts = np.full((20, 3), np.nan)
    want = command_reason(cmd, tmp_path, pts)
    with pytest.raises(ValueError) as e:
        jetfit.estimate(pts)
    assert str(e.value).startswith("no point could be fitted (20 non-finite, 0 failed)")
    assert want.startswith(str(e.value))  # the command also guesses at a cause


def test_mesh_with_no_fit_raises():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match="no point could be fitted"):
        jetfit.estimate_mesh(v, np.array([[0, 1, 2]]), neighbors="knn:2")


def test_most_unfitted_warns(cmd, tmp_path):
    pts = fib_sphere(400)
    pts[:250] = np.nan
    src = tmp_path / "most.xyz"
    save_xyz(src, pts)
    rc, err = cmd("estimate", src, "-o", tmp_path / "o.ply", "--quiet")
    assert rc == 0
    assert "warning: 250 of 400 points could not be fitted (status failed or nonfinite)" in err
    with pytest.warns(RuntimeWarning, match=r"^250 of 400 points could not be fitted "
                                            r"\(status failed or nonfinite\)$"):
        r = jetfit.estimate(pts)
    assert len(r) == 400
    assert np.all(r.status[250:] == 0)
    with warnings.catch_warnings():  # warnings made errors: no Result
        warnings.simplefilter("error")
        with pytest.raises(RuntimeWarning):
            jetfit.estimate(pts)
    # half or fewer unfitted: silent
    pts[200:250] = fib_sphere(400)[200:250]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        jetfit.estimate(pts)


def test_empty_cloud_is_no_error():
    r = jetfit.estimate(np.zeros((0, 3)))
    assert len(r) == 0


@pytest.mark.parametrize("ext", ["ply", "csv"])
def test_auto_sigma_column_as_the_command(cmd, tmp_path, ext):
    pts = fib_sphere(800, radius=2.0)
    pts += np.random.default_rng(7).normal(0, 0.004, pts.shape)
    src = tmp_path / "in.xyz"
    save_xyz(src, pts)
    out_cmd, out_py = tmp_path / ("cmd." + ext), tmp_path / ("py." + ext)
    cmd("estimate", src, "-o", out_cmd, "--quiet", "--neighbors", "auto", "--keep", "none")
    r = jetfit.estimate(jetfit.read(str(src))[0], neighbors="auto")
    assert np.isfinite(r.sigma).all() and (r.sigma > 0).all()
    jetfit.write(str(out_py), r)
    assert out_cmd.read_bytes() == out_py.read_bytes()
    s = r.as_structured()
    names = s.dtype.names
    assert names[-3:] == ("residual", "sigma", "status")
    assert np.array_equal(s["sigma"], r.sigma)
    assert np.array_equal(s["status"], r.status)
    if ext == "ply":
        table = ply_table(out_cmd)
        assert table.dtype.names == names
        assert s.tobytes() == table.tobytes()


def test_no_sigma_column_without_auto(tmp_path):
    r = jetfit.estimate(fib_sphere(300))
    assert "sigma" not in r.as_structured().dtype.names
    assert np.isnan(r.sigma).all()
    jetfit.write(str(tmp_path / "o.csv"), r)
    head = (tmp_path / "o.csv").read_text().split("\n", 1)[0].split(",")
    assert head[-2:] == ["residual", "status"]
