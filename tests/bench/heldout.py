#!/usr/bin/env python3
"""heldout.py -- issue 27 on shapes no rule of `--neighbors auto` was
chosen on (docs/robustness.md, "Held-out shapes").

    python3 tests/bench/heldout.py BUILD DATA [--shapes "bunny cube fandisk"]
        [--levels 0,0.00125,0.006,0.012] [--seed S] [--settings "..."]

DATA holds pcpnet/hexygen_prerelease/SHAPE100k.{xyz,normals}: PCPNet's
authors' older samplings, 100,000 points each with the normal of the mesh
face it was drawn on (cube and fandisk have sharp edges).  Auto's
thresholds were set on the release armadillo, `jetfit generate`'s
surfaces and the bunny range scans; these clouds were not looked at.
Per shape and level (Gaussian noise per axis, sigma = level x the
bounding-box diagonal, as bench_pcpnet's; the truth normals stay
aligned), `jetfit estimate` with each setting; the RMS unoriented angle
(degrees) on 5,000 points drawn once per shape (PCPNet's protocol; a
row without a normal counts 90 degrees).  knn:K+1 is the plain degree-2
jet on CGAL's K + 1 points, which equals CGAL's jet_estimate_normals at
K (docs/robustness.md); the last column is auto over the best of them.
numpy only; about a minute a shape.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np


def rms_angle(N, T):
    c = np.abs((N * T).sum(1)) / (np.linalg.norm(N, axis=1) * np.linalg.norm(T, axis=1))
    a = np.degrees(np.arccos(np.clip(c, 0.0, 1.0)))
    a[~np.isfinite(a)] = 90.0
    return float(np.sqrt((a * a).mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("data")
    ap.add_argument("--shapes", default="bunny cube fandisk")
    ap.add_argument("--levels", default="0,0.00125,0.006,0.012")
    ap.add_argument("--settings", default="knn:19 knn:33 knn:65 knn:129 knn:257 auto")
    ap.add_argument("--seed", type=int, default=20031)
    a = ap.parse_args()
    jetfit = os.path.join(a.build, "jetfit")
    if not os.access(jetfit, os.X_OK):
        sys.exit("heldout: %s not built" % jetfit)
    settings = a.settings.split()
    fixed = [s for s in settings if s.startswith("knn:")]
    print("| shape | level | " + " | ".join(settings) + " | auto / best knn |")
    print("|---|---|" + "---|" * (len(settings) + 1))
    with tempfile.TemporaryDirectory() as work:
        for shape in a.shapes.split():
            base = os.path.join(a.data, "pcpnet", "hexygen_prerelease", shape + "100k")
            P = np.loadtxt(base + ".xyz")
            T = np.loadtxt(base + ".normals")
            if P.shape != T.shape or P.ndim != 2 or P.shape[1] != 3:
                sys.exit("heldout: %s: .xyz and .normals disagree" % base)
            rng = np.random.default_rng(a.seed)
            ev = np.sort(rng.choice(len(P), 5000, replace=False))
            diag = float(np.linalg.norm(P.max(0) - P.min(0)))
            for lv in (float(t) for t in a.levels.split(",")):
                Q = P + rng.normal(0.0, lv * diag, P.shape) if lv > 0 else P
                src, out = os.path.join(work, "in.xyz"), os.path.join(work, "o.xyz")
                np.savetxt(src, Q, fmt="%.17g")
                r = {}
                for s in settings:
                    subprocess.run([jetfit, "estimate", src, "-o", out, "--neighbors", s, "--quiet"],
                                   check=True)
                    A = np.loadtxt(out, comments="#", usecols=(3, 4, 5))
                    if len(A) != len(P):
                        sys.exit("heldout: %s wrote %d rows for %d points" % (s, len(A), len(P)))
                    r[s] = rms_angle(A[ev], T[ev])
                best = min(fixed, key=lambda s: r[s]) if fixed else None
                ratio = "%.3f (%s)" % (r["auto"] / r[best], best) if best and "auto" in r else "-"
                print("| %s | %g%% | %s | %s |" % (shape, 100 * lv, " | ".join("%.3f" % r[s] for s in settings),
                                                   ratio), flush=True)


if __name__ == "__main__":
    main()
