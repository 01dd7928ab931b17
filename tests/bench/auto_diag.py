#!/usr/bin/env python3
"""auto_diag.py -- reads bench_auto_diag's per-point files (one per cloud)
and prints, per file: auto's RMS normal error, each fixed candidate's
(K, degree), the per-point oracle (least error among the candidates), and
where auto's K sits against the oracle's (docs/robustness.md,
"Neighbourhood auto").  Pure Python (no numpy).

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


if __name__ == '__main__':
    for path in sys.argv[1:]:
        summary(path, load(path))
