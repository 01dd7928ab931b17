"""jetfit.write to .laz (issue 25.2): the library's LAZ writer, with the
command's default column types (compact: floats, unit vectors on
multiples of 2^-16; .las: doubles), the command's bytes; read back as the
.las written from the same Result to those types, smaller; a failed write
leaves an existing file untouched."""
import os

import numpy as np
import pytest

import jetfit
from conftest import fib_sphere


def test_write_laz_reads_back_as_las(tmp_path):
    pts = fib_sphere(3000)
    r = jetfit.estimate(pts, neighbors="knn:12")
    jetfit.write(str(tmp_path / "o.las"), r)
    jetfit.write(str(tmp_path / "o.laz"), r)
    with open(tmp_path / "o.laz", "rb") as f:
        head = f.read(105)
    assert head[104] & 0x80  # LASzip's compression bit
    ps, ns, _, a_s = jetfit.read(str(tmp_path / "o.las"))
    pz, nz, _, a_z = jetfit.read(str(tmp_path / "o.laz"))
    # the .laz compact as the command's default (test below): the same
    # points, unit vectors to 2^-17, other reals as floats
    assert np.array_equal(ps, pz) and np.max(np.abs(ns - nz)) <= 2.0 ** -17
    assert list(a_s) == list(a_z)
    for k in a_s:
        if a_z[k].dtype == np.float32:
            assert np.array_equal(a_s[k].astype(np.float32), a_z[k]) or k[0] in "nd", k
        else:
            assert np.array_equal(a_s[k], a_z[k]), k
    assert os.path.getsize(tmp_path / "o.laz") < os.path.getsize(tmp_path / "o.las")


def test_write_laz_failure_leaves_file(tmp_path):
    r = jetfit.estimate(fib_sphere(200), neighbors="knn:12")
    with pytest.raises(OSError):
        jetfit.write(str(tmp_path / "no" / "o.laz"), r)
    assert not os.path.exists(tmp_path / "no")


@pytest.mark.parametrize("ext", ["laz", "las"])
def test_write_las_laz_equal_the_command(tmp_path, cmd, ext, monkeypatch):
    """The command's default column types: a .laz compact (floats, unit
    vectors on multiples of 2^-16), a .las doubles; the same bytes."""
    from conftest import save_xyz
    f = save_xyz(tmp_path / "in.xyz", fib_sphere(500))
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")  # the same header date
    cmd("estimate", f, "-o", tmp_path / f"c.{ext}", "--quiet", "--neighbors", "knn:12")
    pts, _, _, _ = jetfit.read(str(f))
    r = jetfit.estimate(pts, neighbors="knn:12")
    jetfit.write(str(tmp_path / f"p.{ext}"), r)
    assert (tmp_path / f"p.{ext}").read_bytes() == (tmp_path / f"c.{ext}").read_bytes()
    _, _, _, a = jetfit.read(str(tmp_path / f"p.{ext}"))
    if ext == "laz":
        assert a["nx"].dtype == np.float32 and a["k1"].dtype == np.float32
        q = a["nx"].astype(np.float64) * 65536.0
        assert np.array_equal(q, np.round(q))
        assert np.array_equal(a["k1"], r.k1.astype(np.float32))
    else:
        assert a["nx"].dtype == np.float64 and np.array_equal(a["k1"], r.k1)
