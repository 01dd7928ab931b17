"""Open3D interop: its point array goes to jetfit.estimate without a copy
and the normals go back; both libraries load in one process."""
import numpy as np
import pytest

o3d = pytest.importorskip("open3d", reason="python3-open3d is not installed")

import jetfit  # noqa: E402
from conftest import fib_sphere  # noqa: E402


def test_open3d_round_trip():
    pcd = o3d.geometry.PointCloud()
    pcd.points = o3d.utility.Vector3dVector(fib_sphere(5000, 2.0))
    pts = np.asarray(pcd.points)
    r = jetfit.estimate(pts, neighbors="knn:16", orient="viewpoint:0,0,0")
    pcd.normals = o3d.utility.Vector3dVector(r.normal)
    assert np.array_equal(np.asarray(pcd.normals), r.normal)
    assert np.allclose(r.k1, 0.5, atol=0.01)  # inward normal: +1/R
    # Open3D's own PCA normals agree up to sign on a sphere
    q = o3d.geometry.PointCloud(pcd.points)
    q.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(16))
    cos = np.abs(np.einsum("ij,ij->i", np.asarray(q.normals), r.normal))
    assert (cos > 0.999).all()
