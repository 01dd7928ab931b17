#!/usr/bin/env python3
"""auto_diag.py -- reads bench_auto_diag's per-point files (one per cloud)
and prints, per file: auto's RMS normal error, each fixed candidate's
(K, degree), the per-point oracle (least error among the candidates),
where auto's K sits against the oracle's, the share of the squared error
in the worst 10 points, and, binned by cheap per-point quantities, the
fixed (K, degree) with the least squared error in each bin -- a quantity
that predicts the best K has bins whose best K differ, the same way on
every cloud (docs/robustness.md, "Neighbourhood auto").  Pure Python.

With --sweep (needs numpy): auto's rule re-run on the candidates (it
reproduces the file's own choices: "rule matches") with Lepski's
threshold tau and a largest K, over a grid, and the best grid cell per
cloud -- an upper bound for any retuning of the rule's two knobs, even one
that knew each cloud's noise.

With --cap (needs numpy): one largest K for the whole cloud, the K of
least mean estimated squared error of the quadric's normal over the
file's points (bias^2 from the drift against K = 16 or 24 less what the
noise explains, plus sd^2), and the rule re-run under that cap -- what a
cloud-wide pass before the fits would buy.

usage: python3 auto_diag.py [--sweep | --cap] FILE...
"""
import math
import sys


W = 16  # numbers per candidate and degree


def load(path):
    pts = []
    with open(path) as f:
        for line in f:
            v = line.split()
            i, nc, ci, d = int(v[0]), int(v[1]), int(v[2]), int(v[3])
            s2, aerr = float(v[4]), float(v[5])
            tn = (float(v[6]), float(v[7]), float(v[8]))
            c = []
            for k in range(nc):
                row = []
                for e in range(2):
                    w = v[9 + (2 * k + e) * W: 9 + (2 * k + e + 1) * W]
                    row.append(dict(K=int(w[0]), ok=int(w[1]), tr=float(w[2]), h=float(w[3]),
                                    n=(float(w[4]), float(w[5]), float(w[6])), err=float(w[7]),
                                    dk1=float(w[8]), dk2=float(w[9]),
                                    rn=(float(w[10]), float(w[11]), float(w[12])),
                                    k1=float(w[13]), k2=float(w[14]), s2=float(w[15])))
                c.append(row)
            pts.append(dict(i=i, ci=ci, d=d, s2=s2, aerr=aerr, tn=tn, c=c))
    return pts


def rms(v):
    v = [90.0 if not math.isfinite(a) else a for a in v]
    return math.sqrt(sum(a * a for a in v) / len(v)) if v else float('nan')


def median(v):
    v = sorted(a for a in v if math.isfinite(a))
    n = len(v)
    if not n:
        return float('nan')
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def err_of(p, ci, e, key='err'):
    if ci < 0:
        return float('nan')
    return p['c'][ci][e][key]


def summary(path, pts):
    full = [p for p in pts if len(p['c']) == 10]
    print('## %s: %d points (%d with all 10 candidates)' % (path, len(pts), len(full)))
    print('auto rms %.3f' % rms([p['aerr'] for p in pts]))
    line = []
    for e in range(2):
        for k in range(10):
            K = full[0]['c'][k][e]['K']
            line.append('%d/%d %.3f' % (K, e + 2, rms([p['c'][k][e]['err'] for p in full])))
    print('fixed: ' + ', '.join(line))
    orc = [min(x['err'] for r in p['c'] for x in r if math.isfinite(x['err'])) for p in full]
    orc2 = [min(r[0]['err'] for r in p['c'] if math.isfinite(r[0]['err'])) for p in full]
    print('oracle rms %.3f (quadric only %.3f)' % (rms(orc), rms(orc2)))
    # auto's K index vs the oracle's (quadric and cubic pooled)
    lo = hi = eq = 0
    for p in full:
        best = min(((x['err'], k) for k, r in enumerate(p['c']) for x in r if math.isfinite(x['err'])))
        if p['ci'] < best[1]:
            lo += 1
        elif p['ci'] > best[1]:
            hi += 1
        else:
            eq += 1
    n = len(full)
    print('auto K below the oracle K %.0f%%, same %.0f%%, above %.0f%%' % (100 * lo / n, 100 * eq / n, 100 * hi / n))
    sq = sorted((p['aerr'] ** 2 for p in pts if math.isfinite(p['aerr'])), reverse=True)
    print('worst 10 points: %.0f%% of auto\'s squared error' % (100 * sum(sq[:10]) / sum(sq)))
    for name, feat, edges in FEATURES:
        acc = {}
        for p in full:
            b = sum(1 for e in edges if feat(p) > e)
            a = acc.setdefault(b, [0] + [0.0] * 20)
            a[0] += 1
            for k in range(10):
                for e in range(2):
                    a[1 + 2 * k + e] += p['c'][k][e]['err'] ** 2
        row = []
        for b in sorted(acc):
            a = acc[b]
            j = min(range(20), key=lambda t: a[1 + t])
            lo_e = edges[b - 1] if b > 0 else 0
            row.append('>%g: %d pts K%d/%d' % (lo_e, a[0], full[0]['c'][j // 2][0]['K'], 2 + j % 2))
        print('best fixed per bin of %s: %s' % (name, ', '.join(row)))


def _ang(a, b):
    return math.acos(min(1.0, abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])))


# (name, feature of a point with all 10 candidates, bin edges); candidate 2
# is K = 32, 4 K = 64, 6 K = 128; [0] the quadric, [1] the cubic
FEATURES = [
    ('noise / radius at K=32', lambda p: math.sqrt(p['s2']) / p['c'][2][1]['h'], [0.02, 0.04, 0.08, 0.16]),
    ('quadric residual var at K=128 / noise var', lambda p: p['c'][6][0]['s2'] / p['s2'], [1.1, 1.5, 2, 3, 5]),
    ('quadric-cubic angle at K=128 / cubic sd',
     lambda p: _ang(p['c'][6][0]['n'], p['c'][6][1]['n']) / math.sqrt(p['s2'] * p['c'][6][1]['tr'] + 1e-300),
     [0.5, 1, 2, 4]),
    ('max |k| x radius, quadric at K=64',
     lambda p: max(abs(p['c'][4][0]['k1']), abs(p['c'][4][0]['k2'])) * p['c'][4][1]['h'], [0.1, 0.2, 0.4, 0.8]),
    ('K auto chose', lambda p: p['c'][p['ci']][0]['K'] if p['ci'] >= 0 else 0, [32, 64, 128, 200]),
]


def _sweep_arrays(pts):
    import numpy as np
    full = [p for p in pts if len(p['c']) == 10]
    keys = ('ok', 'tr')
    A = {k: np.array([[[c[e][k] for e in range(2)] for c in p['c']] for p in full], float) for k in keys}
    A['n'] = np.array([[[c[e]['n'] for e in range(2)] for c in p['c']] for p in full], float)
    A['err'] = np.array([[[c[e]['err'] for e in range(2)] for c in p['c']] for p in full], float)
    A['s2'] = np.array([p['s2'] for p in full])
    A['auto'] = np.array([(p['ci'], p['d']) for p in full])
    A['K'] = [c[0]['K'] for c in full[0]['c']]
    return A


def _np_ang(a, b):
    import numpy as np
    c = np.abs((a * b).sum(-1)) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.arccos(np.clip(c, 0.0, 1.0))


def _np_lepski(A, e, tau, kmax, sdmax=0.3):
    """src/robust/auto_rule.c's chain for degree 2 + e, candidates 0..kmax"""
    import numpy as np
    ok = (A['ok'][:, :, e] > 0) & (np.arange(10) <= kmax)
    sd = np.sqrt(A['s2'][:, None] * A['tr'][:, :, e])
    n = A['n'][:, :, e]
    N = ok.shape[0]
    acc = np.zeros((N, 10), bool)
    alive = np.ones(N, bool)
    best = np.full(N, -1)
    for i in range(10):
        cand = alive & ok[:, i]
        fail = np.zeros(N, bool)
        for j in range(i):
            fail |= acc[:, j] & (sd[:, j] < sdmax) & (_np_ang(n[:, i], n[:, j]) > tau * (sd[:, i] + sd[:, j]))
        acc[:, i] = cand & ~fail
        alive &= ~(cand & fail)
        best = np.where(acc[:, i], i, best)
    return best, sd


def np_rule(A, tau=2.0, kmax=9):
    """auto's choice (candidate, degree) per point: the cubic's Lepski K
    unless the quadric, at the largest K of its chain where it agrees with
    the cubic, has the smaller sd"""
    import numpy as np
    b2, sd2 = _np_lepski(A, 0, tau, kmax)
    b3, sd3 = _np_lepski(A, 1, tau, kmax)
    N = b2.shape[0]
    d = np.where(b3 >= 0, 3, 2)
    ci = np.where(b3 >= 0, b3, b2)
    ok = A['ok'] > 0
    aqc = _np_ang(A['n'][:, :, 0], A['n'][:, :, 1])
    sdb3 = sd3[np.arange(N), np.maximum(b3, 0)]
    done = np.zeros(N, bool)
    for i in range(9, -1, -1):
        cand = (b3 >= 0) & ~done & (i <= b2) & ok[:, i, 0] & ok[:, i, 1] & ~(aqc[:, i] > tau * sd3[:, i])
        sw = cand & (sd2[:, i] < sdb3)
        d = np.where(sw, 2, d)
        ci = np.where(sw, i, ci)
        done |= cand
    return ci, d


def rule_rms(A, tau=2.0, kmax=9):
    """RMS normal error of np_rule's choices (no choice: 90 degrees)"""
    import numpy as np
    ci, d = np_rule(A, tau, kmax)
    return rms(list(np.where(ci < 0, 90.0, A['err'][np.arange(len(ci)), np.maximum(ci, 0), d - 2])))


def sweep(path, pts):
    A = _sweep_arrays(pts)
    N = len(A['s2'])
    ci, d = np_rule(A)
    print('## %s: rule matches %d of %d choices' % (path, int(((ci == A['auto'][:, 0]) & (d == A['auto'][:, 1])).sum()), N))
    fixed = min(rms(list(A['err'][:, k, e])) for k in range(10) for e in range(2))
    best = None
    for tau in (0.5, 1, 1.5, 2, 3, 4):
        for kmax in range(1, 10):
            r = rule_rms(A, tau, kmax)
            if best is None or r < best[0]:
                best = (r, tau, A['K'][kmax])
    print('best (tau, largest K) %.3f at tau %g, K <= %d; best fixed candidate %.3f: x%.3f' %
          (best[0], best[1], best[2], fixed, best[0] / fixed))


def cloud_cap(path, pts):
    import numpy as np
    A = _sweep_arrays(pts)
    fixed = min(rms(list(A['err'][:, k, e])) for k in range(10) for e in range(2))
    sd = np.sqrt(A['s2'][:, None] * A['tr'][:, :, 0])
    n = A['n'][:, :, 0]
    ok = (A['ok'][:, :, 0] > 0).all(1)
    r = rule_rms(A)
    out = ['rule %.3f (x%.3f)' % (r, r / fixed)]
    for ref, trim in ((0, 0), (1, 0), (0, 1), (1, 1)):
        cost = []
        for k in range(10):
            b2 = _np_ang(n[:, k], n[:, ref]) ** 2 - (sd[:, ref] ** 2 - sd[:, k] ** 2) if k > ref else 0.0 * sd[:, k]
            c = np.sort((b2 + sd[:, k] ** 2)[ok])
            cost.append(float(np.mean(c[: int(0.95 * len(c))]) if trim else np.median(c)))
        kc = int(np.argmin(cost))
        r = rule_rms(A, 2.0, kc)
        out.append('drift from K=%d, %s: cap K=%d %.3f (x%.3f)' %
                   (A['K'][ref], 'mean of 95%' if trim else 'median', A['K'][kc], r, r / fixed))
    print('## %s: best fixed candidate %.3f; %s' % (path, fixed, '; '.join(out)))


if __name__ == '__main__':
    mode = summary
    if '--sweep' in sys.argv[1:]:
        mode = sweep
    elif '--cap' in sys.argv[1:]:
        mode = cloud_cap
    for path in (a for a in sys.argv[1:] if a not in ('--sweep', '--cap')):
        mode(path, load(path))
