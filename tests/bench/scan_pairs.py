#!/usr/bin/env python3
"""scan_pairs.py -- normals of overlapping Stanford bunny range scans against
each other (docs/robustness.md, "Real scans").

    python3 tests/bench/scan_pairs.py BUILD DATA [--settings "knn:32 auto"]
                                      [--near D] [SCAN ...]

For each --neighbors setting, `jetfit estimate` on each raw scan (DATA as
scan_mesh.py's; default bun000 bun045 bun090 bun315), the normals posed
into one frame by bun.conf; for each pair of scans, every point of the
first with a point of the second within D (default 0.2 mm) gives one
unoriented angle between the two scans' normals there.  Prints each pair's
median and, over all pairs, the median and the mean (degrees).  The two
scans' noise is independent, their surface the same: the angle is the two
estimates' noise (and the pose's error), with no truth to favour a scale;
the surface's bias, shared by both, cancels.  numpy only.
"""
import argparse
import itertools
import os
import subprocess
import sys
import tempfile

import numpy as np

from scan_mesh import H, nearest, pose


def pairs(P, Q, h):
    """(i, j): P[i]'s nearest row of Q within h (h <= scan_mesh's cell)"""
    d, at = nearest(Q, P)
    i = np.flatnonzero(d < h)
    return i, at[i]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("data")
    ap.add_argument("--settings", default="knn:32 auto")
    ap.add_argument("--near", type=float, default=0.0002)
    ap.add_argument("scans", nargs="*")
    a = ap.parse_args()
    if not 0 < a.near <= H:
        sys.exit("scan_pairs: --near must be in (0, %g]" % H)
    jetfit = os.path.join(a.build, "jetfit")
    root = os.path.join(a.data, "scans", "stanford_bunny", "data")
    if not os.access(jetfit, os.X_OK):
        sys.exit("scan_pairs: %s not built" % jetfit)
    conf = {}
    with open(os.path.join(root, "bun.conf")) as f:
        for line in f:
            w = line.split()
            if w and w[0] == "bmesh":
                conf[w[1][:-4]] = [float(t) for t in w[2:9]]
    scans = a.scans or ["bun000", "bun045", "bun090", "bun315"]
    settings = a.settings.split()
    est = {}
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "o.xyz")
        for s in settings:
            for scan in scans:
                subprocess.run([jetfit, "estimate", os.path.join(root, scan + ".ply"), "-o", out,
                                "--neighbors", s, "--quiet"], check=True)
                A = np.loadtxt(out, comments="#")
                R, t = pose(conf[scan])
                est[s, scan] = (A[:, :3] @ R + t, A[:, 3:6] @ R)
    print("| pair | points | " + " | ".join("%s: median" % s for s in settings) + " |")
    print("|---|---|" + "---|" * len(settings))
    every = {s: [] for s in settings}
    for x, y in itertools.combinations(scans, 2):
        ia, ib = pairs(est[settings[0], x][0], est[settings[0], y][0], a.near)
        if len(ia) < 1000:
            continue
        cells = []
        for s in settings:
            c = np.abs((est[s, x][1][ia] * est[s, y][1][ib]).sum(1))
            ang = np.degrees(np.arccos(np.clip(c[np.isfinite(c)], 0.0, 1.0)))
            every[s].append(ang)
            cells.append("%.3f" % np.median(ang))
        print("| %s %s | %d | %s |" % (x, y, len(ia), " | ".join(cells)), flush=True)
    print("| all: median / mean | | " +
          " | ".join("%.3f / %.3f" % (np.median(np.concatenate(every[s])), np.mean(np.concatenate(every[s])))
                     for s in settings) + " |")


if __name__ == "__main__":
    main()
