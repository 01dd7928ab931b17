#!/usr/bin/env python3
"""scan_mesh.py -- normals of the raw Stanford bunny range scans against the
zippered mesh (docs/robustness.md, "Why the defaults" and "Real scans").

    python3 tests/bench/scan_mesh.py BUILD DATA [--settings "knn:32 auto"]
                                     [SCAN ...]

DATA holds scans/stanford_bunny/data/*.ply with bun.conf (each scan's pose:
translation, then a unit quaternion qx qy qz qw) and
scans/stanford_bunny/reconstruction/bun_zipper.ply.  For each scan (all ten
by default) and each --neighbors setting, `jetfit estimate` on the raw
scan; the estimated normals, posed into the mesh's frame, against the
mesh's vertex normals (area-weighted faces) at the scan points within
0.5 mm of a mesh vertex; prints the median, mean and 90th percentile of
the unoriented angle (degrees).  The mesh is a consensus of all the scans,
smoothed by its reconstruction: it judges the noise of one scan, and it
favours the scale it was smoothed at.  numpy only; about 20 s a scan.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

H = 0.0005  # "near a vertex": 0.5 mm, the grid cell of the search


def read_mesh(path):
    with open(path) as f:
        nv = nf = 0
        for line in f:
            if line.startswith("element vertex"):
                nv = int(line.split()[2])
            elif line.startswith("element face"):
                nf = int(line.split()[2])
            elif line.startswith("end_header"):
                break
        V = np.array([[float(t) for t in f.readline().split()[:3]] for _ in range(nv)])
        F = np.array([[int(t) for t in f.readline().split()[1:4]] for _ in range(nf)])
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N = np.zeros_like(V)
    for k in range(3):
        np.add.at(N, F[:, k], fn)
    with np.errstate(invalid="ignore", divide="ignore"):
        N /= np.linalg.norm(N, axis=1, keepdims=True)  # unused vertices: NaN
    return V, N


def pose(q):
    """bun.conf's bmesh line: x = R^T p + t maps the scan to the mesh"""
    t = np.array(q[:3])
    x, y, z, w = q[3:]
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    return R, t


def nearest(V, P):
    """the nearest vertex within H of each row of P (distance inf: none)"""
    cells = {}
    for j, k in enumerate(map(tuple, np.floor(V / H).astype(np.int64))):
        cells.setdefault(k, []).append(j)
    d = np.full(len(P), np.inf)
    at = np.zeros(len(P), dtype=np.int64)
    for n, k in enumerate(map(tuple, np.floor(P / H).astype(np.int64))):
        cand = [j for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
                for j in cells.get((k[0] + dx, k[1] + dy, k[2] + dz), ())]
        if cand:
            e = ((V[cand] - P[n]) ** 2).sum(1)
            b = int(np.argmin(e))
            d[n], at[n] = np.sqrt(e[b]), cand[b]
    return d, at


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("data")
    ap.add_argument("--settings", default="knn:32 auto")
    ap.add_argument("scans", nargs="*")
    a = ap.parse_args()
    jetfit = os.path.join(a.build, "jetfit")
    root = os.path.join(a.data, "scans", "stanford_bunny")
    if not os.access(jetfit, os.X_OK):
        sys.exit("scan_mesh: %s not built" % jetfit)
    V, VN = read_mesh(os.path.join(root, "reconstruction", "bun_zipper.ply"))
    conf = {}
    with open(os.path.join(root, "data", "bun.conf")) as f:
        for line in f:
            w = line.split()
            if w and w[0] == "bmesh":
                conf[w[1][:-4]] = [float(t) for t in w[2:9]]
    settings = a.settings.split()
    print("| scan | points judged | " + " | ".join("%s: median / mean / p90" % s for s in settings) + " |")
    print("|---|---|" + "---|" * len(settings))
    with tempfile.TemporaryDirectory() as work:
        for scan in a.scans or sorted(conf):
            R, t = pose(conf[scan])
            cells, near = [], None
            for s in settings:
                out = os.path.join(work, "o.xyz")
                subprocess.run([jetfit, "estimate", os.path.join(root, "data", scan + ".ply"), "-o", out,
                                "--neighbors", s, "--quiet"], check=True)
                A = np.loadtxt(out, comments="#")
                P, N = A[:, :3] @ R + t, A[:, 3:6] @ R
                if near is None:
                    near = nearest(V, P)
                d, at = near
                m = (d < H) & np.isfinite(N).all(1) & np.isfinite(VN[at]).all(1)
                ang = np.degrees(np.arccos(np.clip(np.abs((N[m] * VN[at[m]]).sum(1)), 0.0, 1.0)))
                cells.append("%.3f / %.3f / %.3f" % (np.median(ang), ang.mean(), np.percentile(ang, 90)))
            print("| %s | %d | %s |" % (scan, m.sum(), " | ".join(cells)), flush=True)


if __name__ == "__main__":
    main()
