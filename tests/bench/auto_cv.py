#!/usr/bin/env python3
"""auto_cv.py -- does leave-one-out cross-validation pick each cloud's best K?

    python3 tests/bench/auto_cv.py BUILD [--pcpnet DIR] [--no-generated]
                                         [--frame own|fixed|k32] [--cyl]
                                         [--local M,...]

Issue 27's open cells (docs/robustness.md, "What is not met") need a
statistic that tells the armadillo at 0.125% (best k = 32) from smooth
surfaces of the same noise-to-spacing ratio (best k = 200-256).  This
script measures one candidate, for the whole cloud: at every evaluated
point p the degree-d jet on p's K + 1 nearest (p first) in a PCA frame
centred at p, and its leave-one-out residual at p, a0 / (1 - h00) (a0 the
jet's height at p, h00 = (M^T M)^-1 [0, 0]: the hat matrix's diagonal at
p, which sits at the origin), so CV(K) = mean of its square: noise
variance + the jet's error at p.  Per cloud and (degree, K in 16..256) it
prints the RMS normal angle against the truth and CV, then a SUM line:
the best (degree, K) by the truth, the one CV picks (and its K among
degree 2 alone), and the cloud's median sigma / r16 (auto's `sigma`
column over the 16th nearest distance: noise thicker than the spacing
where it is large, and there the 3-D nearest of a noisy p lie on its
side of the surface, so CV is least at the smallest K).

--frame own: each K in the PCA frame of its own K + 1 points (CGAL's
jet); fixed: every K in the frame of the 257 nearest; k32: every K in
the frame of the 32 nearest, p first (auto's step 1 frame, which serves all its
candidates).  --cyl: the K nearest by planar distance in that one frame
(a cylinder), not by 3-D distance.  --local M,...: per point instead of
per cloud, the degree-2 K of least CV over the point's M nearest
evaluated points (their own leave-one-out residuals) and the RMS normal
of the pure fits so chosen, against the best degree-2 K (LOCAL lines).

Clouds: jetfit generate's ellipsoid, torus (--density gradient) and exp
at 0.1%, 0.3%, 1% (20,000 points, seed 27, every 4th evaluated) and, with
--pcpnet, PCPNet's armadillo100k at 0, 0.125%, 0.6%, 1.2% (numpy noise,
seed 7, as auto_agg.py; its 5000 .pidx points).  numpy only; about 6 min
for the generated clouds and 8 for the armadillo on one core.
"""
import argparse
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from auto_agg import armadillo, generated, kth_dist, neighbours, run  # noqa: E402

KS = [16, 24, 32, 48, 64, 96, 128, 160, 200, 256]


def pca_frames(P):
    """per row of P (n x m x 3): eigenvectors of the covariance, columns
    largest first (the last: the normal)"""
    C = P - P.mean(1, keepdims=True)
    return np.linalg.eigh(np.einsum("nki,nkj->nij", C, C))[1][:, :, ::-1]


def monomials(x, y, d):
    c = [np.ones_like(x), x, y, x * x, x * y, y * y]
    if d == 3:
        c += [x ** 3, x * x * y, x * y * y, y ** 3]
    return np.stack(c, -1)


def study(jetfit, cloud, work, I, T, name, frame, cyl, local=()):
    Y = np.loadtxt(cloud, comments="#")
    Q = Y[I]
    nb = neighbours(Y, Q, KS[-1] + 1)
    # the noise against the spacing: auto's sigma over the 16th nearest
    # distance (nb[:, 16]: p is nb[:, 0]), its median over the points
    rows, col = run(jetfit, cloud, "auto", os.path.join(work, "auto.xyz"))
    sr = rows[I, col["sigma"]] / kth_dist(rows, I, nb, np.full(len(I), 17))
    th = np.nanmedian(sr)
    VF = pca_frames(Y[nb[:, :32]] if frame == "k32" else Y[nb])
    if cyl:  # the same 257 points, ordered by planar distance in VF
        L = np.einsum("nki,nij->nkj", Y[nb] - Q[:, None, :], VF)
        nb = np.take_along_axis(nb, np.argsort(L[:, :, 0] ** 2 + L[:, :, 1] ** 2, axis=1, kind="stable"), 1)
    out, ang2, loo2 = [], [], []
    for d in (2, 3):
        for K in KS:
            P = Y[nb[:, :K + 1]]
            V = pca_frames(P) if frame == "own" else VF
            L = np.einsum("nki,nij->nkj", P - Q[:, None, :], V)
            r = np.sqrt((L[:, :, 0] ** 2 + L[:, :, 1] ** 2).max(1))  # x, y / r: conditioning (§2.3)
            M = monomials(L[:, :, 0] / r[:, None], L[:, :, 1] / r[:, None], d)
            Gi = np.linalg.inv(np.einsum("nka,nkb->nab", M, M))
            a = np.einsum("nab,nkb,nk->na", Gi, M, L[:, :, 2])
            loo = a[:, 0] / (1.0 - Gi[:, 0, 0])
            g = np.stack([-a[:, 1] / r, -a[:, 2] / r, np.ones(len(a))], -1)
            n = np.einsum("nij,nj->ni", V, g)
            n /= np.linalg.norm(n, axis=1, keepdims=True)
            ang = np.degrees(np.arccos(np.clip(np.abs((n * T).sum(1)), 0.0, 1.0)))
            out.append((d, K, np.sqrt((ang ** 2).mean()), np.mean(loo ** 2)))
            if d == 2:
                ang2.append(ang)
                loo2.append(loo ** 2)
    best = min(out, key=lambda t: t[2])
    pick = min(out, key=lambda t: t[3])
    pick2 = min((t for t in out if t[0] == 2), key=lambda t: t[3])
    for t in out:
        print("%s degree %d K %3d: normal %.3f, CV %.4g%s%s" % (name, *t, "  <- best" if t is best else "",
                                                             "  <- CV" if t is pick else ""))
    print("SUM %s: best %d/%d %.3f, CV picks %d/%d %.3f (%.3f x best), degree 2 alone K = %d; "
          "median sigma / r16 %.3f" % (name, best[0], best[1], best[2], pick[0], pick[1], pick[2],
                                       pick[2] / best[2], pick2[1], th), flush=True)
    if local:
        local_cv(name, Q, np.array(ang2), np.array(loo2), sr, local, min(t[2] for t in out if t[0] == 2))


def local_cv(name, Q, ang, loo2, sr, ms, best2):
    """per point, the degree-2 K of least CV over its m nearest evaluated
    points (their own leave-one-out residuals), and the RMS normal of the
    pure fit at that K; the same where the local median sigma / r16 is
    at most 0.4 (else K = 256: thick noise, where CV is biased to 16)"""
    nq = neighbours(Q, Q, max(ms))
    for m in ms:
        cv = loo2[:, nq[:, :m]].mean(2)  # K x points
        kp = np.argmin(cv, 0)
        a = ang[kp, np.arange(len(kp))]
        thin = np.nanmedian(sr[nq[:, :m]], 1) <= 0.4
        kt = np.where(thin, kp, len(KS) - 1)
        at = ang[kt, np.arange(len(kt))]
        hist = np.bincount(kp, minlength=len(KS)) / len(kp)
        print("LOCAL %s m %d: normal %.3f (%.3f x best degree-2 K), thin-gated %.3f (%.3f x), thin %.0f%%; K "
              "shares %s" % (name, m, np.sqrt((a ** 2).mean()), np.sqrt((a ** 2).mean()) / best2,
                             np.sqrt((at ** 2).mean()), np.sqrt((at ** 2).mean()) / best2, 100 * thin.mean(),
                             " ".join("%d:%.0f%%" % (K, 100 * h) for K, h in zip(KS, hist) if h >= 0.005)),
              flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("--pcpnet")
    ap.add_argument("--no-generated", action="store_true")
    ap.add_argument("--frame", choices=("own", "fixed", "k32"), default="own")
    ap.add_argument("--cyl", action="store_true")
    ap.add_argument("--local", default="", help="M,...: per point, CV over its M nearest evaluated points")
    a = ap.parse_args()
    jetfit = os.path.join(a.build, "jetfit")
    if not os.access(jetfit, os.X_OK):
        sys.exit("auto_cv: %s not built" % jetfit)
    if a.cyl and a.frame == "own":
        sys.exit("auto_cv: --cyl needs one frame for every K (--frame fixed or k32)")
    loc = [int(v) for v in a.local.split(",") if v]
    with tempfile.TemporaryDirectory() as work:
        for name, cloud, tr in () if a.no_generated else generated(jetfit, work, 20000, 27, "c.xyz"):
            I = np.arange(0, len(tr), 4)
            study(jetfit, cloud, work, I, tr[I, 3:6], name, a.frame, a.cyl, loc)
        for lev, Y, I, T in armadillo(a.pcpnet, (0.0, 0.00125, 0.006, 0.012)) if a.pcpnet else ():
            cloud = os.path.join(work, "a.xyz")
            np.savetxt(cloud, Y)
            study(jetfit, cloud, work, I, T, "armadillo %g" % lev, a.frame, a.cyl, loc)

if __name__ == "__main__":
    main()
