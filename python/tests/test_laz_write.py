"""jetfit.write to .laz (issue 25.2): the library's LAZ writer, the file
jetfit.read gives back as the .las written from the same Result (same
points, same attributes, bit for bit), smaller; a failed write leaves an
existing file untouched."""
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
    assert np.array_equal(ps, pz) and np.array_equal(ns, nz)
    assert list(a_s) == list(a_z)
    for k in a_s:
        assert np.array_equal(a_s[k], a_z[k]), k
    assert os.path.getsize(tmp_path / "o.laz") < os.path.getsize(tmp_path / "o.las")


def test_write_laz_failure_leaves_file(tmp_path):
    r = jetfit.estimate(fib_sphere(200), neighbors="knn:12")
    with pytest.raises(OSError):
        jetfit.write(str(tmp_path / "no" / "o.laz"), r)
    assert not os.path.exists(tmp_path / "no")
