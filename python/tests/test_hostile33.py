"""Issue 33 (hostile probe, round 3) through the Python module: faces that
jetfit.write must write or refuse (item 3), short bad rows under
bad_rows='skip' (4), option strings holding a NUL (10), and the
--degree-select message (11).  Each test fails on the code before the fix."""
import numpy as np
import pytest

import jetfit
from conftest import fib_sphere


def test_write_refuses_face_out_of_range(tmp_path):
    # before: no faces written, nothing raised
    p = fib_sphere(100)
    r = jetfit.estimate(p)
    out = tmp_path / "f.ply"
    with pytest.raises(ValueError, match="^faces: face 0 has vertex index 99999, the points have 100 rows$"):
        jetfit.write(str(out), r, faces=[[0, 1, 99999]])
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_write_keeps_a_300_vertex_face(tmp_path):
    # before: a polygon over 255 vertices dropped every face, rc/raise none
    n = 300
    t = 2 * np.pi * np.arange(n) / n
    p = np.c_[np.cos(t), np.sin(t), 0.01 * np.sin(5 * np.arange(n))]
    p = np.vstack([p, [0, 0, 0.1]])
    r = jetfit.estimate(p, neighbors="knn:8")
    faces = [list(range(n)), [0, 1, n]]
    out = tmp_path / "g.ply"
    jetfit.write(str(out), r, faces=faces, ascii=True)
    text = out.read_bytes().decode()
    assert "element face 2\nproperty list uint int vertex_indices\n" in text
    body = text.split("end_header\n", 1)[1].splitlines()
    assert len(body) == n + 1 + 2
    assert [int(x) for x in body[n + 1].split()] == [n] + list(range(n))
    assert [int(x) for x in body[n + 2].split()] == [3, 0, 1, n]
    _, _, f2, _ = jetfit.read(str(out))
    assert [list(f) for f in f2] == faces


def test_read_short_bad_rows_skip(tmp_path):
    # before: "more rows than supported"
    f = tmp_path / "s.xyz"
    f.write_text("1 2 3\n4 5\n7 8 9\n1 1 1\n")
    with pytest.warns(RuntimeWarning, match="lines 2"):
        pts, _, _, _ = jetfit.read(str(f), bad_rows="skip")
    assert pts.shape == (4, 3)
    assert np.isnan(pts[1]).all()
    assert (pts[0] == [1, 2, 3]).all() and (pts[3] == [1, 1, 1]).all()


@pytest.mark.parametrize("kw,val", [
    ("neighbors", "knn:16\x00junk"),
    ("orient", "none\x00junk"),
    ("robust", "huber\x00junk"),
    ("fit", "approx\x00"),
])
def test_option_with_nul_refused(kw, val):
    # before: the text after the NUL was dropped and the run went on
    with pytest.raises(ValueError, match=f"^{kw}: embedded null character$"):
        jetfit.estimate(fib_sphere(100), **{kw: val})


def test_option_too_long_refused():
    with pytest.raises(ValueError, match="^neighbors: value too long"):
        jetfit.estimate(fib_sphere(100), neighbors="knn:16" + " " * 300)


def test_degree_select_message_names_value():
    # before: "--degree-select '': must not exceed --degree"; Python names
    # keywords (issue 31)
    with pytest.raises(ValueError, match="^degree_select=5: must not exceed degree$"):
        jetfit.estimate(fib_sphere(100), degree=2, degree_select=5)
