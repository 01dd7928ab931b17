#!/usr/bin/env python3
"""auto_agg.py -- issue 27 (docs/robustness.md, "Where step 6 does not
reach"): does aggregating the neighbours' jets beat the best fixed K where
one fit cannot?  Offline, from jetfit's own rows (the variants below are
applied to auto's rows as written: since step 6 shipped, on top of it;
the build before it gave the figures of that section's table).

usage: python3 tests/bench/auto_agg.py BUILD [--pcpnet DIR] [--f F,...]
       [--lepski TAU,...] [--gate LO:HI,...] [--sheet TAU,...]
       [--weights W,...] [--mixgate T,... [--border B,...]]
       [--biweight C,...] [--bulk] [--bulkgate B,...] [--no-generated]
       [--rows NB] [--levels L,...] [--n N] [--seed S]

At each point q, the jets of its m nearest points j (q itself first),
m = f x the K auto chose at q, each j's fit the row jetfit wrote:
  indiv  mean of n_j - W_j (q - j): each normal carried to q by its own
         shape operator W_j = k1 d1 d1^T + k2 d2 d2^T (a first-order
         Taylor step, §2's Monge form; signs aligned with n_q);
  mid    mean of n_j - (W_j + W)/2 (q - j), W the mean of the W_j: the
         step with the mean of its two ends' curvatures (trapezoid rule:
         no second-order error, W standing for q's own); also only where auto's K is its
         largest, 256 (elsewhere the row as auto wrote it);
  curvatures: the eigenvalues of W in the plane normal to the normal;
  with --lepski, indiv's m chosen per point up to f x K (lepski below);
  with --gate LO:HI, a per-point f by the noise over the fit's radius,
  s = sigma / r_K (r_K: the K-th distance): indiv, f = 1/16 where
  s <= LO, indiv, f = 1/2 where LO < s <= HI, mid, f = 1/2 above (normals);
  LO:HI:KMIN only where auto's K >= KMIN, LO:HI:KMIN:1 only quadric rows
  (each cloud's 10/50/90% of s on stderr);
  with --sheet TAU, indiv and mid again over only the j whose height off
  q's own osculating quadric is at most TAU x q's sigma (q's sheet);
  indiv3  indiv with the cubic's slope too (b0..b3 of the degree-3 rows);
  midq   mean of n_j - (W_j + W_q)/2 (q - j): the trapezoid with q's own
         shape operator W_q instead of the mean W;
  with --weights, weighted means: kern a biweight in q's distance, ivar
  1 / the variance of j's slope, K_j r_Kj^2 / sigma_j^2 (r_Kj read at q),
  ivarkern both, kw K_j, kge 1 where K_j >= K_q (else 0);
  with --mixgate T (f = 1/8): mid with ivar weights where s = sigma / r_K
  > T, plain indiv elsewhere (step 6 since 28 Nov 2026, T = 0.03); with
  --border B also where q's offset from its m nearest, |mean (q - j)| /
  rms |q - j|, exceeds B (each cloud's percentiles of s and the offset
  on stderr);
  with --biweight C, indiv and mid as Tukey biweighted means of the m
  carries (scale C x 1.4826 x their median deviation from the mean; mid's
  W the biweighted mean W_j): a robust mean, which a wild neighbour's fit
  does not move;
  with --bulk, on stderr, indiv's RMS normal at m = 1, 2, 4, ..., 64 over
  the rows whose K is 256 and degree 2 (the bulk) and over the others,
  from every neighbour and from the bulk's only;
  with --bulkgate B (and --mixgate T), weighted mid also on the rows
  whose K is 256 and degree 2 where beta < B (B = 0: all of them), beta
  = |b| r_K^2 / 10 over the slope's sd, b from the plain cubic on 257
  points (the slope bias a cubic term leaves in the quadric);
  with --no-generated, the PCPNet clouds only; with --levels, only those
  armadillo noise levels;
  with --rows knn:K, the same means over a fixed K's rows instead of
  auto's (m = f x K; no sigma, so ivar weights and gates do not apply).
The rows of a build configured with -DCMAKE_C_FLAGS=-DJF_STEP6_OFF are
steps 1-5's, on which "indiv, f = 1/16" is step 6 itself.
Printed against auto's own rows and the plain degree-2 jet on k + 1
points (CGAL's jet on the same points, docs/robustness.md), k in 18, 32,
64, 128, 256, the best k per column after seeing the truth: RMS normal
angle (deg) and median |dk1|, |dk2| (jetfit eval's conventions).
 1. jetfit generate ellipsoid, torus --density gradient, exp at noise
    0.1%, 0.3%, 1% (N points, seed S: study_auto.sh's clouds);
 2. with --pcpnet DIR: armadillo100k at Gaussian noise 0, 0.125%, 0.6%,
    1.2% of the bounding-box diagonal (numpy's draw, seed 7), normals on
    the 5000 .pidx points.
Neighbours by brute force (numpy): minutes, not a benchmark of speed.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

KS = (18, 32, 64, 128, 256)
KMAX = 256  # auto's largest candidate


def run(jetfit, cloud, nb, out, extra=()):
    subprocess.run([jetfit, "estimate", cloud, "-o", out, "--neighbors", nb, "--quiet"] + list(extra), check=True)
    with open(out) as fh:
        names = fh.readline().lstrip("#").split()
    rows = np.loadtxt(out, comments="#")
    return rows, {n: i for i, n in enumerate(names)}


def neighbours(Y, Q, m):
    """indices of the m nearest points of Y to each row of Q, nearest first"""
    nb = np.empty((len(Q), m), dtype=np.int64)
    for s in range(0, len(Q), 250):
        d = ((Q[s:s + 250, None, :] - Y[None, :, :]) ** 2).sum(-1)
        part = np.argpartition(d, m, axis=1)[:, :m]
        dd = np.take_along_axis(d, part, 1)
        nb[s:s + 250] = np.take_along_axis(part, np.argsort(dd, axis=1), 1)
    return nb


def shape_ops(a1, a2, D1, D2):
    """W = a1 d1 d1^T + a2 d2 d2^T per row (n x 3 x 3)"""
    return a1[:, None, None] * D1[:, :, None] * D1[:, None, :] + a2[:, None, None] * D2[:, :, None] * D2[:, None, :]


def kth_dist(rows, I, nb, K):
    """|q - its K-th nearest| at each row of I"""
    kth = nb[np.arange(len(I)), np.clip(K, 1, nb.shape[1]).astype(int) - 1]
    return np.linalg.norm(rows[kth, 0:3] - rows[I, 0:3], axis=1)


def aggregate(rows, col, I, nb, mq, sheet=None, weight=None):
    """(normal, k1, k2) per variant at rows I from the mq[i] first of nb[i],
    and (key "snaps") indiv's running sums and counts at m = 1, 2, 4, ...;
    with sheet = TAU only the j whose height off q's own osculating
    quadric, |n_q . (j - q) - (j - q)^T W_q (j - q) / 2|, is at most TAU
    sigma_q (q's `sigma`): the same sheet, not the other side of a thin
    part"""
    NI, PI, n = rows[I, col["nx"]:col["nx"] + 3], rows[I, 0:3], len(I)
    # a neighbour without a fit (NaN row) adds nothing: zeros, not NaN * 0
    good = np.isfinite(rows[:, 0:col["d2x"] + 3]).all(1)
    R = np.where(good[:, None], rows, 0.0)
    P = R[:, 0:3]
    N = R[:, col["nx"]:col["nx"] + 3]
    k1, k2 = R[:, col["k1"]], R[:, col["k2"]]
    D1 = R[:, col["d1x"]:col["d1x"] + 3]
    D2 = R[:, col["d2x"]:col["d2x"] + 3]
    snaps = {}
    cnt = np.zeros(n)
    mean_n, cen, ind = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    ind3 = np.zeros((n, 3))
    B = np.nan_to_num(R[:, col["b0"]:col["b0"] + 4]) if "b0" in col else np.zeros((len(R), 4))
    W = np.zeros((n, 3, 3))
    indq = np.zeros((n, 3))
    Wq = shape_ops(k1[I], k2[I], D1[I], D2[I])
    if sheet is not None:
        lim = sheet * R[I, col["sigma"]]
    for t in range(nb.shape[1]):
        j = nb[:, t]
        on = (t < mq) & good[j]
        if sheet is not None and t > 0:
            e = P[j] - PI
            h = (e * NI).sum(1) - 0.5 * np.einsum("ni,nij,nj->n", e, Wq, e)
            on &= np.abs(h) <= lim
        on = on.astype(float)
        if not on.any():
            break
        if weight is not None:
            on = on * weight(t, j)
        s = np.where((N[j] * NI).sum(1) < 0, -1.0, 1.0)
        nj = N[j] * s[:, None]
        a1, a2 = k1[j] * s, k2[j] * s
        Wj = shape_ops(a1, a2, D1[j], D2[j])
        d = PI - P[j]
        cnt += on
        mean_n += nj * on[:, None]
        cen += P[j] * on[:, None]
        W += Wj * on[:, None, None]
        ind += (nj - np.einsum("nij,nj->ni", Wj, d)) * on[:, None]
        indq += (nj - 0.5 * np.einsum("nij,nj->ni", Wj + Wq, d)) * on[:, None]
        # the cubic's slope too (Monge form, CGAL's b: z = (k1 u^2 + k2 v^2) / 2
        # + (b0 u^3 + 3 b1 u^2 v + 3 b2 u v^2 + b3 v^3) / 6)
        u, v = (d * D1[j]).sum(1), (d * D2[j]).sum(1)
        b = B[j] * s[:, None]
        fu = a1 * u + 0.5 * (b[:, 0] * u * u + 2 * b[:, 1] * u * v + b[:, 2] * v * v)
        fv = a2 * v + 0.5 * (b[:, 1] * u * u + 2 * b[:, 2] * u * v + b[:, 3] * v * v)
        ind3 += (nj - fu[:, None] * D1[j] - fv[:, None] * D2[j]) * on[:, None]
        if not t & (t + 1):  # t + 1 a power of two
            snaps[t + 1] = (ind.copy(), cnt.copy())
    cnt = np.maximum(cnt, 1.0)
    W /= cnt[:, None, None]
    mean_n /= cnt[:, None]
    cen /= cnt[:, None]
    ind /= cnt[:, None]
    ind3 /= cnt[:, None]
    indq /= cnt[:, None]
    # sum of n_j - W (q - j) over the m, divided by m: mean_n - W (q - cen)
    wbar = mean_n - np.einsum("nij,nj->ni", W, PI - cen)
    out = {"snaps": snaps}
    for name, v in (("indiv", ind), ("mid", (ind + wbar) / 2.0), ("indiv3", ind3), ("midq", indq)):
        nn = v / np.linalg.norm(v, axis=1)[:, None]
        Pm = np.eye(3)[None] - nn[:, :, None] * nn[:, None, :]
        ev, evec = np.linalg.eigh(Pm @ W @ Pm)
        along = np.argmax(np.abs((evec * nn[:, :, None]).sum(1)), axis=1)
        keep = np.array([[i for i in range(3) if i != a] for a in along])
        e = np.take_along_axis(ev, keep, 1)
        out[name] = (nn, e[:, 1], e[:, 0])
    return out


def errors(nrm, c1, c2, T, t1=None, t2=None):
    """RMS angle (deg, unoriented) and, with truth curvatures, median |dk1|, |dk2|"""
    dot = (nrm * T).sum(1) / np.linalg.norm(nrm, axis=1)
    ang = np.degrees(np.sqrt(np.nanmean(np.arccos(np.clip(np.abs(dot), 0, 1)) ** 2)))
    if t1 is None:
        return (ang,)
    f = dot < 0  # orient along the truth: the curvatures negate and swap
    e1, e2 = np.where(f, -c2, c1), np.where(f, -c1, c2)
    return ang, np.nanmedian(np.abs(e1 - t1)), np.nanmedian(np.abs(e2 - t2))


def study(jetfit, cloud, I, T, t1, t2, o, work):
    """one cloud: best fixed k, auto, auto aggregated per f (list of rows);
    o: the parsed options (main)"""
    fs, taus, gates, sheets, weights = o.fs, o.taus, o.gates, o.sheets, o.weights
    fixed = {}
    for k in KS:
        rows, col = run(jetfit, cloud, "knn:%d" % (k + 1), os.path.join(work, "f.xyz"))
        fixed[k] = errors(rows[I, col["nx"]:col["nx"] + 3], rows[I, col["k1"]], rows[I, col["k2"]], T, t1, t2)
    best = [min((fixed[k][c], k) for k in KS) for c in range(len(fixed[KS[0]]))]
    rows, col = run(jetfit, cloud, o.rows, os.path.join(work, "a.xyz"),
                    ["--degree", "3", "--monge-degree", "3"] if o.rows == "auto" else [])
    K = rows[I, col["neighbors"]]
    res = [("auto", errors(rows[I, col["nx"]:col["nx"] + 3], rows[I, col["k1"]], rows[I, col["k2"]], T, t1, t2))]
    nb = neighbours(rows[:, 0:3], rows[I, 0:3],
                    max(int(max(fs + ([0.5] if gates else [])) * K.max()) + 1,
                        KMAX + 1 if (taus or weights or o.mixgates) else 0, 65 if o.bulk else 0))
    dq = np.linalg.norm(rows[nb, 0:3] - rows[I, 0:3][:, None, :], axis=2)
    Kall = rows[:, col["neighbors"]].astype(int)
    sig = rows[:, col["sigma"]] if "sigma" in col else np.ones(len(rows))  # --rows knn:K: no sigma
    for f in fs:
        mq = np.maximum(1, np.round(f * K)).astype(int)
        ag = aggregate(rows, col, I, nb, mq)
        for name in ("indiv", "mid", "indiv3", "midq"):
            res.append(("%s f=%g" % (name, f), errors(*ag[name], T, t1, t2)))
        # only where auto's K reached its largest candidate (variance-bound)
        ag = aggregate(rows, col, I, nb, np.where(K >= KMAX, mq, 1))
        res.append(("indiv f=%g, K=%d only" % (f, KMAX), errors(*ag["indiv"], T, t1, t2)))
        res.append(("mid f=%g, K=%d only" % (f, KMAX), errors(*ag["mid"], T, t1, t2)))
        for wname in weights:
            wfun = weigher(wname, dq, Kall, sig, I, mq)
            ag = aggregate(rows, col, I, nb, mq, weight=wfun)
            for name in ("indiv", "mid"):
                res.append(("%s f=%g, weights %s" % (name, f, wname), errors(*ag[name], T, t1, t2)))
        for tau in sheets:
            ag = aggregate(rows, col, I, nb, mq, sheet=tau)
            for name in ("indiv", "mid"):
                res.append(("%s f=%g, sheet %g sigma" % (name, f, tau), errors(*ag[name], T, t1, t2)))
        for tau in taus:
            res.append(("indiv, Lepski tau=%g, m <= %g K" % (tau, f),
                        errors(lepski(rows, col, I, nb, K, mq, tau), None, None, T)))
        for c in o.biweights:
            for name, v in zip(("indiv", "mid"), biweight_means(rows, col, I, nb, mq, c)):
                res.append(("%s f=%g, biweight %g" % (name, f, c), errors(v, None, None, T)))
    if o.bulk:
        bulk_rms(rows, col, I, nb, T)
    if o.mixgates:
        s = noise_ratio(rows, col, I, nb, K)
        mq = np.maximum(1, np.round(K / 8.0)).astype(int)
        flat = aggregate(rows, col, I, nb, mq)
        iv = aggregate(rows, col, I, nb, mq, weight=weigher("ivar", dq, Kall, sig, I, mq))
        # the offset of q from its m nearest: |mean (q - j)| / rms |q - j| (a border)
        # borderk: the same over q's own K nearest (its fit's points)
        off = offset(rows, I, nb, K if o.borderk else mq)
        print("offset 10/50/90/99%%: %.3f %.3f %.3f %.3f" % tuple(np.nanpercentile(off, [10, 50, 90, 99])),
              file=sys.stderr, flush=True)
        lows = {"": flat}
        for lw in o.lowweights:
            lows[lw] = aggregate(rows, col, I, nb, mq, weight=weigher(lw, dq, Kall, sig, I, mq))
            res.append(("indiv weights %s" % lw, errors(*lows[lw]["indiv"], T, t1, t2)))
        for G in o.mixgates:
            for B in o.borders:
                for lw, lo in lows.items():
                    hi = ((s > G) | (off > B))[:, None]
                    pick = np.where(hi, iv["mid"][0], lo["indiv"][0])
                    res.append(("mixgate %g border %g low %s (%.0f%% mid)" % (G, B, lw or "plain", 100 * hi.mean()),
                                errors(pick, flat["indiv"][1], flat["indiv"][2], T, t1, t2)))
            if o.bulkgates:  # mid also on the K = 256 quadric rows, where beta < BETA
                beta = cubic_bias(jetfit, cloud, work, I, nb, K, rows[I, col["sigma"]])
                bulk = (K == KMAX) & (rows[I, col["degree"]] == 2)
                for bt in o.bulkgates:
                    hi = ((s > G) | (bulk & ((beta < bt) if bt > 0 else True)))[:, None]
                    pick = np.where(hi, iv["mid"][0], flat["indiv"][0])
                    res.append(("mixgate %g or bulk%s (%.0f%% mid)" % (G, ", beta < %g" % bt if bt > 0 else "", 100 * hi.mean()),
                                errors(pick, None, None, T)))
    if gates:
        s = noise_ratio(rows, col, I, nb, K)
        small = aggregate(rows, col, I, nb, np.maximum(1, np.round(K / 16.0)).astype(int))["indiv"][0]
        wide = aggregate(rows, col, I, nb, np.maximum(1, np.round(K / 2.0)).astype(int))
        for g in gates:
            lo, hi = g[0], g[1]
            ok = K >= (g[2] if len(g) > 2 else 0)
            if len(g) > 3 and g[3]:
                ok &= rows[I, col["degree"]] == 2
            pick = np.where((ok & (s > hi))[:, None], wide["mid"][0],
                            np.where((ok & (s > lo))[:, None], wide["indiv"][0], small))
            res.append(("gate sigma/r_K %s" % ":".join("%g" % v for v in g), errors(pick, None, None, T)))
    return best, res


def carries(rows, col, I, nb, mq):
    """each of q's mq nearest j (q first): its normal (signs on q's side),
    its shape operator W_j, q - j, 1 where it counts, and its normal
    carried to q, n_j - W_j (q - j) (n x L x ...)"""
    good = np.isfinite(rows[:, 0:col["d2x"] + 3]).all(1)
    R = np.where(good[:, None], rows, 0.0)
    N, D1, D2 = R[:, col["nx"]:col["nx"] + 3], R[:, col["d1x"]:col["d1x"] + 3], R[:, col["d2x"]:col["d2x"] + 3]
    NI, L, n = rows[I, col["nx"]:col["nx"] + 3], int(mq.max()), len(I)
    Nn, W, d, on = np.zeros((n, L, 3)), np.zeros((n, L, 3, 3)), np.zeros((n, L, 3)), np.zeros((n, L))
    for t in range(L):
        j = nb[:, t]
        s = np.where((N[j] * NI).sum(1) < 0, -1.0, 1.0)
        Nn[:, t], d[:, t] = N[j] * s[:, None], rows[I, 0:3] - R[j, 0:3]
        W[:, t] = shape_ops(R[j, col["k1"]] * s, R[j, col["k2"]] * s, D1[j], D2[j])
        on[:, t] = (t < mq) & good[j]
    return Nn, W, d, on, Nn - np.einsum("ntij,ntj->nti", W, d)


def biweight(C, on, c):
    """Tukey's biweights of the vectors C (n x L x 3) about their weighted
    mean, scale c x 1.4826 x the median deviation (twice)"""
    w = on.copy()
    U = C / np.linalg.norm(C, axis=2)[:, :, None]
    for _ in range(2):
        mu = (C * w[:, :, None]).sum(1)
        mu /= np.linalg.norm(mu, axis=1)[:, None]
        dev = np.linalg.norm(U - mu[:, None, :], axis=2)
        sc = 1.4826 * np.nanmedian(np.where(on > 0, dev, np.nan), axis=1)
        u = dev / np.maximum(c * sc, 1e-12)[:, None]
        w = on * np.clip(1.0 - u * u, 0.0, 1.0) ** 2
    return w


def biweight_means(rows, col, I, nb, mq, c):
    """indiv and mid (W: the biweighted mean W_j) as biweighted means"""
    Nn, W, d, on, ind = carries(rows, col, I, nb, mq)
    w = biweight(ind, on, c)
    Wb = (W * w[:, :, None, None]).sum(1) / np.maximum(w.sum(1), 1e-300)[:, None, None]
    mid = Nn - 0.5 * np.einsum("ntij,ntj->nti", W + Wb[:, None], d)
    return (ind * w[:, :, None]).sum(1), (mid * biweight(mid, on, c)[:, :, None]).sum(1)


def bulk_rms(rows, col, I, nb, T):
    """indiv's RMS normal angle at m = 1, 2, 4, ..., 64 over the rows of
    K = KMAX and degree 2 (the bulk) and the others, from every neighbour
    and from the bulk's only (stderr)"""
    bulk = (rows[:, col["neighbors"]] == KMAX) & (rows[:, col["degree"]] == 2)
    for m in (1, 2, 4, 8, 16, 32, 64):
        on, ind = carries(rows, col, I, nb, np.full(len(I), m))[3:]
        onb = on * bulk[nb[:, :m]]
        onb[:, 0] = on[:, 0]
        e = [errors((ind * w[:, :, None]).sum(1)[sel], None, None, T[sel])[0]
             for w in (on, onb) for sel in (bulk[I], ~bulk[I])]
        print("m=%2d: bulk (%d rows) %.4f, the rest %.4f; from bulk rows only %.4f, %.4f" %
              ((m, bulk[I].sum()) + tuple(e)), file=sys.stderr, flush=True)


def cubic_bias(jetfit, cloud, work, I, nb, K, sigma):
    """beta = |b| r_K^2 / 10 over the slope's sd 2 sqrt 2 sigma / (r_K sqrt K):
    the slope bias a cubic term b leaves in a quadric on a disk of radius
    r_K, against its noise; b from the plain cubic on 257 points"""
    rows, col = run(jetfit, cloud, "knn:%d" % (KMAX + 1), os.path.join(work, "cub.xyz"),
                    ["--degree", "3", "--monge-degree", "3"])
    b = np.linalg.norm(rows[I, col["b0"]:col["b0"] + 4], axis=1)
    rk = kth_dist(rows, I, nb, K)
    beta = b * rk * rk / 10.0 / np.maximum(2.0 * np.sqrt(2.0) * sigma / (rk * np.sqrt(K)), 1e-300)
    print("beta 10/50/90%%: %.2f %.2f %.2f" % tuple(np.nanpercentile(beta, [10, 50, 90])), file=sys.stderr, flush=True)
    return beta


def noise_ratio(rows, col, I, nb, K):
    """s = sigma / r_K at each row of I (r_K: the K-th distance), its
    10/50/90% on stderr"""
    s = rows[I, col["sigma"]] / kth_dist(rows, I, nb, K)
    print("sigma/r_K 10/50/90%%: %.4f %.4f %.4f" % tuple(np.nanpercentile(s, [10, 50, 90])),
          file=sys.stderr, flush=True)
    return s


def offset(rows, I, nb, cnt):
    """q's offset from its cnt[i] nearest, |mean (q - j)| / rms |q - j| (a border)"""
    L = min(int(cnt.max()), nb.shape[1])
    e = rows[nb[:, :L], 0:3] - rows[I, 0:3][:, None, :]
    on = (np.arange(L)[None, :] < cnt[:, None]).astype(float)
    c = on.sum(1)
    return np.linalg.norm((e * on[:, :, None]).sum(1), axis=1) / c / np.sqrt(((e * e).sum(2) * on).sum(1) / c)


def weigher(wname, dq, Kall, sig, I, mq):
    """a neighbour's weight at step t (j = nb[:, t]): "kern", a biweight in
    q's distance, zero at the (m+1)-th; "ivar", 1 / sd^2 of j's slope,
    K_j r_Kj^2 / sigma_j^2 (r_Kj read at q), relative to q's own"""
    at = np.arange(len(I))

    def wfun(t, j):
        w = np.ones(len(I))
        if "kern" in wname:
            u = dq[:, t] / np.maximum(dq[at, np.minimum(mq, dq.shape[1] - 1)], 1e-300)
            w = w * np.clip(1.0 - u * u, 0.0, 1.0) ** 2
        if wname == "kw":  # the fit's size alone
            w = w * Kall[j] / np.maximum(Kall[I], 1)
        if wname == "kge":  # only fits on at least q's own K points
            w = w * (Kall[j] >= Kall[I])
        if "ivar" in wname or wname == "ivfl":  # ivfl: sigma floored at 0.03 r_K (the gate's s)
            fl = 0.03 if wname == "ivfl" else 0.0
            kj, k0 = np.clip(Kall[j], 1, dq.shape[1]), np.clip(Kall[I], 1, dq.shape[1])
            r, r0 = dq[at, kj - 1], dq[at, k0 - 1]
            sj, s0 = np.maximum(np.maximum(sig[j], fl * r), 1e-12), np.maximum(np.maximum(sig[I], fl * r0), 1e-12)
            w = w * (kj * r * r / sj ** 2) / (k0 * r0 * r0 / s0 ** 2)
        return np.where(np.isfinite(w), w, 0.0)
    return wfun


def lepski(rows, col, I, nb, K, cap, tau):
    """indiv's normal at m chosen per point: m doubles from 1 up to cap
    while the mean carried normal stays within tau sd of the row's own,
    sd = 2 sqrt 2 sigma / (r_K sqrt K), the slope sd of a plane on K
    points spread over a disk of radius r_K (the K-th distance)"""
    snaps = aggregate(rows, col, I, nb, cap)["snaps"]
    n0 = rows[I, col["nx"]:col["nx"] + 3]
    rk = kth_dist(rows, I, nb, K)
    sd = 2.0 * np.sqrt(2.0) * rows[I, col["sigma"]] / (rk * np.sqrt(K))
    best, alive, m = snaps[1][0].copy(), np.ones(len(I), bool), 2
    while m in snaps:
        v = snaps[m][0]
        u = v / np.linalg.norm(v, axis=1)[:, None]
        alive &= (m <= cap) & (np.abs((u * n0).sum(1)) >= np.cos(np.minimum(tau * sd, np.pi / 2)))
        best[alive] = v[alive]
        m *= 2
    return best


def table(title, cells, curv):
    print("\n## " + title)
    cols = ["normal", "dk1", "dk2"][:3 if curv else 1]
    print("| cloud | estimate | " + " | ".join(cols) + " | / best fixed k |")
    print("|---|---|" + "---|" * (len(cols) + 1))
    for name, best, res in cells:
        print("| %s | best fixed (k) | %s | |" % (name, " | ".join("%.4g (%d)" % b for b in best)))
        for est, e in res:  # a normals-only row leaves the curvature cells empty
            e = e[:len(cols)]
            ratio = ", ".join("%.3f" % (e[c] / best[c][0]) for c in range(len(e)))
            cells_ = ["%.4g" % v for v in e] + [""] * (len(cols) - len(e))
            print("| | %s | %s | %s |" % (est, " | ".join(cells_), ratio))


def generated(jetfit, work, n, seed, fname):
    """study_auto.sh's clouds: jetfit generate's ellipsoid, torus (density
    gradient) and exp at noise 0.1%, 0.3%, 1% into work/fname; yields
    (name, cloud path, truth rows: x y z, normal, k1 k2, d1, d2)"""
    for surf in ("ellipsoid", "torus", "exp"):
        for lev in ("0.001", "0.003", "0.01"):
            cloud, truth = os.path.join(work, fname), os.path.join(work, "t.csv")
            extra = ["--density", "gradient"] if surf == "torus" else []
            subprocess.run([jetfit, "generate", surf, "-o", cloud, "--n", str(n), "--noise", lev,
                            "--seed", str(seed), "--truth", truth] + extra, check=True, stdout=subprocess.DEVNULL)
            yield "%s %s" % (surf, lev), cloud, np.loadtxt(truth, delimiter=",", skiprows=1)


def armadillo(d, levels):
    """PCPNet's armadillo100k (folder d) with Gaussian noise lev x its
    bounding-box diagonal (numpy's draw, seed 7); yields (lev, points,
    the .pidx indices, their truth normals)"""
    X = np.loadtxt(os.path.join(d, "armadillo100k.xyz"))
    T = np.loadtxt(os.path.join(d, "armadillo100k.normals"))
    I = np.loadtxt(os.path.join(d, "armadillo100k.pidx"), dtype=int)
    diag = np.linalg.norm(X.max(0) - X.min(0))
    for lev in levels:
        yield lev, X + np.random.default_rng(7).normal(0.0, lev * diag, X.shape) if lev > 0 else X, I, T[I]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("--pcpnet")
    ap.add_argument("--f", default="0.0625,0.125,0.25,0.5")
    ap.add_argument("--lepski", default="", help="taus of a per-point m rule (e.g. 1,2,4)")
    ap.add_argument("--gate", default="", help="LO:HI[:KMIN[:1]] bounds of sigma / r_K (e.g. 0.01:0.02)")
    ap.add_argument("--sheet", default="", help="TAUs of the same-sheet test (e.g. 2,3,4)")
    ap.add_argument("--weights", default="", help="weighted means: kern, ivar, ivarkern, kw, kge")
    ap.add_argument("--mixgate", default="", help="sigma / r_K above which mid with ivar weights, f = 1/8")
    ap.add_argument("--border", default="9", help="with --mixgate: mid also where q's offset from its m nearest exceeds B")
    ap.add_argument("--lowweight", default="", help="with --mixgate: weights of indiv below the gate (kw, ivfl)")
    ap.add_argument("--borderk", action="store_true", help="--border's offset over q's K nearest, not its m")
    ap.add_argument("--biweight", default="", help="Cs of the biweight mean of the carries (e.g. 3)")
    ap.add_argument("--bulk", action="store_true", help="indiv's RMS at m = 1..64 on the K = 256 quadric rows")
    ap.add_argument("--bulkgate", default="", help="with --mixgate: mid also on K = 256 quadric rows, beta < B (0: all)")
    ap.add_argument("--no-generated", action="store_true", help="the PCPNet clouds only")
    ap.add_argument("--rows", default="auto", help="the rows aggregated: auto, or a fixed knn:K (its own fits)")
    ap.add_argument("--levels", default="0,0.00125,0.006,0.012", help="the armadillo's noise levels (x diag)")
    ap.add_argument("--n", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=27)
    a = ap.parse_args()
    jetfit = os.path.join(a.build, "jetfit")
    if not os.access(jetfit, os.X_OK):
        sys.exit("auto_agg: %s not built" % jetfit)
    a.fs = [float(v) for v in a.f.split(",")]
    a.taus = [float(v) for v in a.lepski.split(",") if v]
    a.gates = [tuple(float(x) for x in v.split(":")) for v in a.gate.split(",") if v]
    a.sheets = [float(v) for v in a.sheet.split(",") if v]
    a.weights = [v for v in a.weights.split(",") if v]
    a.mixgates = [float(v) for v in a.mixgate.split(",") if v]
    a.borders = [float(v) for v in a.border.split(",") if v]
    a.lowweights = [v for v in a.lowweight.split(",") if v]
    a.biweights = [float(v) for v in a.biweight.split(",") if v]
    a.bulkgates = [float(v) for v in a.bulkgate.split(",") if v]
    with tempfile.TemporaryDirectory() as work:
        cells = []
        for name, cloud, tr in () if a.no_generated else generated(jetfit, work, a.n, a.seed, "c.ply"):
            I = np.arange(len(tr))
            if a.bulk:  # its lines on stderr, under the cloud's name
                print("%s:" % name, file=sys.stderr, flush=True)
            best, res = study(jetfit, cloud, I, tr[:, 3:6], tr[:, 6], tr[:, 7], a, work)
            cells.append((name, best, res))
            print("done %s" % name, file=sys.stderr, flush=True)
        if cells:
            table("jetfit generate, %d points, seed %d" % (a.n, a.seed), cells, True)
        if a.pcpnet:
            cells = []
            for lev, Y, I, T in armadillo(a.pcpnet, [float(v) for v in a.levels.split(",")]):
                cloud = os.path.join(work, "a_in.xyz")
                np.savetxt(cloud, Y)
                if a.bulk:
                    print("armadillo %g:" % lev, file=sys.stderr, flush=True)
                best, res = study(jetfit, cloud, I, T, None, None, a, work)
                cells.append(("armadillo %g" % lev, best, res))
                print("done armadillo %g" % lev, file=sys.stderr, flush=True)
            table("PCPNet armadillo100k, 5000 .pidx points (numpy noise, seed 7)", cells, False)


if __name__ == "__main__":
    main()
