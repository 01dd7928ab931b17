"""orient="scanner" from Python (issue 13, item 3): jetfit.read gives a PTX
file's scan and scanner position per row (attributes "scan", "scanner"),
estimate(..., scanners=) orients every normal towards the scanner of its
point, and read + estimate + write gives the command's output file byte for
byte (the command's default for PTX is --orient scanner)."""
import os

import numpy as np
import pytest

import jetfit
from conftest import fib_sphere


def rot(a, b):
    """A rotation (rows) about z by a, then about x by b."""
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    rz = np.array([[ca, sa, 0], [-sa, ca, 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, cb, sb], [0, -sb, cb]])
    return rz @ rx


def write_ptx(path, scans):
    """scans: (registered points, scanner position t, rotation rows R); the
    points are written in the scanner's frame q = (p - t) R^T, so the PTX
    row-vector transform [q 1] M with M = [R; t] gives them back; each scan
    ends with a "0 0 0" row (no return)."""
    with open(path, "w") as f:
        for p, t, r in scans:
            q = (p - t) @ r.T
            f.write(f"{len(p) + 1}\n1\n")
            f.write("%.17g %.17g %.17g\n" % tuple(t))
            for row in r:
                f.write("%.17g %.17g %.17g\n" % tuple(row))
            for row in r:
                f.write("%.17g %.17g %.17g 0\n" % tuple(row))
            f.write("%.17g %.17g %.17g 1\n" % tuple(t))
            for row in q:
                f.write("%.17g %.17g %.17g 0.5\n" % tuple(row))
            f.write("0 0 0 0\n")


@pytest.fixture
def two_scans(tmp_path):
    """A unit sphere seen by two scanners 4 units away on either side."""
    p = fib_sphere(1200)
    s0, s1 = np.array([4.0, 0.5, 0.2]), np.array([-4.0, -0.3, 0.1])
    scans = [(p[p[:, 0] > 0.1], s0, rot(0.3, 0.2)), (p[p[:, 0] < -0.1], s1, rot(-1.1, 0.4))]
    path = tmp_path / "two.ptx"
    write_ptx(path, scans)
    return path, scans


def test_read_gives_scans(two_scans):
    path, scans = two_scans
    pts, nrm, faces, at = jetfit.read(str(path))
    n0, n1 = len(scans[0][0]) + 1, len(scans[1][0]) + 1
    assert pts.shape == (n0 + n1, 3) and nrm is None and faces is None
    assert sorted(at) == ["intensity", "scan", "scanner"]  # intensity kept (issue 26.5)
    assert np.array_equal(at["intensity"], np.repeat([0.5, 0.0, 0.5, 0.0], [n0 - 1, 1, n1 - 1, 1]))
    assert at["scan"].dtype == np.int32 and at["scanner"].shape == (n0 + n1, 3)
    assert np.array_equal(at["scan"], np.repeat([0, 1], [n0, n1]))
    assert np.array_equal(at["scanner"][:n0], np.tile(scans[0][1], (n0, 1)))
    assert np.array_equal(at["scanner"][n0:], np.tile(scans[1][1], (n1, 1)))
    assert np.isnan(pts[n0 - 1]).all() and np.isnan(pts[-1]).all()  # the 0 0 0 rows
    assert np.allclose(pts[:n0 - 1], scans[0][0], atol=1e-12)


def test_normals_face_their_scanner(two_scans):
    path, _ = two_scans
    pts, _, _, at = jetfit.read(str(path))
    r = jetfit.estimate(pts, neighbors="knn:16", scanners=at["scanner"])
    ok = np.isfinite(pts).all(1)
    assert (r.status[~ok] == jetfit.STATUS["nonfinite"]).all()
    facing = np.einsum("ij,ij->i", r.normal[ok], at["scanner"][ok] - pts[ok])
    assert (facing > 0).all()
    # without the scanners (no orientation) some face away: the test can fail
    r0 = jetfit.estimate(pts, neighbors="knn:16")
    assert (np.einsum("ij,ij->i", r0.normal[ok], at["scanner"][ok] - pts[ok]) < 0).any()
    # orient= given wins over the default, as --orient does on a PTX file
    rn = jetfit.estimate(pts, neighbors="knn:16", scanners=at["scanner"], orient="none")
    assert np.array_equal(rn.normal, r0.normal, equal_nan=True)


def test_same_file_as_the_command(two_scans, tmp_path, cmd):
    path, _ = two_scans
    # --keep none: the PTX attributes (intensity, scan; issue 26.5) are not in p.csv
    cmd("estimate", path, "-o", tmp_path / "c.csv", "--quiet", "--neighbors", "knn:16",
        "--keep", "none")
    pts, _, _, at = jetfit.read(str(path))
    r = jetfit.estimate(pts, neighbors="knn:16", scanners=at["scanner"], threads=2)
    jetfit.write(str(tmp_path / "p.csv"), r)
    assert (tmp_path / "p.csv").read_bytes() == (tmp_path / "c.csv").read_bytes()


def test_scanner_without_positions_is_a_value_error():
    p = fib_sphere(100)
    with pytest.raises(ValueError, match=r"^orient='scanner' needs scanners=: "):
        jetfit.estimate(p, orient="scanner")
    with pytest.raises(ValueError, match=r"^scanners: 99 rows for 100 points$"):
        jetfit.estimate(p, scanners=np.zeros((99, 3)))
    with pytest.raises(ValueError):
        jetfit.estimate(p, scanners=np.zeros((100, 2)))


def test_read_e57():
    """An E57 file (libE57Format's test data, tests/data/e57/SOURCE.md): its
    7680 points within the prototype's [-0.5, 0.5], colours, scan and
    scanner (the identity pose: the origin) per row (issue 26.6)."""
    from conftest import TOP
    path = os.path.join(TOP, "tests", "data", "e57", "ColouredCubeFloat.e57")
    pts, nrm, faces, at = jetfit.read(path)
    assert pts.shape == (7680, 3) and nrm is None and faces is None
    assert pts.min() == -0.5 and pts.max() == 0.5
    assert {"colorRed", "colorGreen", "colorBlue", "scan", "scanner"} <= set(at)
    assert at["colorRed"].dtype == np.uint8
    assert (at["scan"] == 0).all() and (at["scanner"] == 0).all()
    with pytest.raises(Exception, match="bad-crc.e57: page 0"):
        jetfit.read(os.path.join(TOP, "tests", "data", "e57", "bad-crc.e57"))
