#!/bin/sh
# bench_auto.sh -- issue 27's cost target: `--neighbors auto` against the
# default knn:32 degree 2 on the same cloud, in the same run.
#
#   sh tests/bench/bench_auto.sh [BUILD] [N] [ROUNDS]
#   EXTRA="knn:256 knn:512" sh tests/bench/bench_auto.sh ...
#   SURF=ellipsoid NOISE=0.001 sh tests/bench/bench_auto.sh ...
#
# BUILD (default: build) holds the jetfit command; N (default 100000) is
# the point count of a `jetfit generate torus --density gradient --noise
# 0.003` cloud (binary PLY; SURF and NOISE: another surface of `jetfit
# generate`, uniform, or noise; step 6 reads 32 records a row, from the
# 32 nearest on the torus, up to the 128th where its carry is spread);
# ROUNDS (default 5) rounds each run knn:32 then
# auto, one thread, binary PLY out.  The machine may be shared: each
# setting's time is its least CPU time (user + system) over the rounds,
# the two alternating so that both see the same load.  Prints per setting
# that time, points/s and peak RSS, then the ratios auto / knn:32 (goal:
# time <= 3, memory <= 1.5).  EXTRA: more --neighbors settings timed in
# the same rounds, each with its ratio to knn:32 (the plain fits at the
# K the accuracy target would need, docs/robustness.md).  Needs python3
# (resource.getrusage of the run: CPU to the microsecond).
set -eu
B=${1:-build}
N=${2:-100000}
R=${3:-5}
J=$B/jetfit
[ -x "$J" ] || { echo "bench_auto: $J not built" >&2; exit 1; }
# the system's python3 first: a wrapper's (pyenv's) adds to its child's CPU time
PY=/usr/bin/python3
[ -x "$PY" ] || PY=$(command -v python3) || { echo "bench_auto: needs python3 (the rusage of each run)" >&2; exit 1; }
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT INT TERM

S=${SURF:-torus}
D=uniform
[ "$S" = torus ] && D=gradient
"$J" generate "$S" -o "$W/in.ply" --n "$N" --noise "${NOISE:-0.003}" --density "$D" --seed 27 >/dev/null
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); $S, noise ${NOISE:-0.003}, $D; $N points, $R rounds, 1 thread"

one() { # one NB -> "cpu_seconds peak_kb" (the child's rusage, to the microsecond:
    # GNU time prints 10 ms steps, 4% of knn:32 at 10^5)
    "$PY" -c 'import resource, subprocess, sys
subprocess.run(sys.argv[1:], check=True)
r = resource.getrusage(resource.RUSAGE_CHILDREN)
print("%.4f %d" % (r.ru_utime + r.ru_stime, r.ru_maxrss))' \
        "$J" estimate "$W/in.ply" -o "$W/out.ply" --neighbors "$1" --threads 1 --quiet
}

: >"$W/runs"
i=0
while [ "$i" -lt "$R" ]; do
    for nb in knn:32 auto ${EXTRA:-}; do echo "$nb $(one $nb)" >>"$W/runs"; done
    i=$((i + 1))
done
awk -v n="$N" -v list="knn:32 auto ${EXTRA:-}" '
{ if (!($1 in t) || $2 < t[$1]) t[$1] = $2; if ($3 > m[$1]) m[$1] = $3 }
END {
    printf "| setting | CPU s (least of rounds) | points/s | peak RSS (MB) |\n|---|---|---|---|\n"
    ns = split(list, s, " ")
    for (i = 1; i <= ns; i++)
        printf "| %s | %.3f | %.0f | %.1f |\n", s[i], t[s[i]], n / t[s[i]], m[s[i]] / 1024
    printf "auto / knn:32: time %.2fx, memory %.2fx\n", t["auto"] / t["knn:32"], m["auto"] / m["knn:32"]
    for (i = 3; i <= ns; i++)
        printf "%s / knn:32: time %.2fx, memory %.2fx\n", s[i], t[s[i]] / t["knn:32"], m[s[i]] / m["knn:32"]
}' "$W/runs"
