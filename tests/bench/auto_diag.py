#!/usr/bin/env python3
"""auto_diag.py -- reads bench_auto_diag's per-point files (one per cloud)
and prints, per file: auto's RMS normal error, each fixed candidate's
(K, degree), the per-point oracle (least error among the candidates),
where auto's K sits against the oracle's, the share of the squared error
in the worst 10 points, and, binned by cheap per-point quantities, the
fixed (K, degree) with the least squared error in each bin -- a quantity
that predicts the best K has bins whose best K differ, the same way on
every cloud (docs/robustness.md, "Neighbourhood auto").  Pure Python.

usage: python3 auto_diag.py FILE...
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


if __name__ == '__main__':
    for path in sys.argv[1:]:
        summary(path, load(path))
