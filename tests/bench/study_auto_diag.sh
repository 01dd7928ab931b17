#!/bin/sh
# study_auto_diag.sh -- per-point diagnosis of `--neighbors auto` (issue
# 27; docs/robustness.md, "Neighbourhood auto"): bench_auto_diag on the
# study's clouds, then auto_diag.py's summary per cloud (auto, every fixed
# candidate, the per-point oracle, the best fixed K per bin of cheap
# per-point quantities).
#
# usage: sh tests/bench/study_auto_diag.sh BUILD [PCPNET_DIR] [--keep DIR] [--knob NAME=V ...]
#   BUILD       a build folder configured with -DJF_BENCH=ON
#   PCPNET_DIR  folder holding armadillo100k.{xyz,normals,pidx} (noise 0,
#               0.125%, 0.6%, 1.2% of the diagonal: bench_pcpnet's draws)
#   --keep DIR  keep the per-point files there (for trying rules offline)
# The generated surfaces are study_auto.sh's (20,000 points, seed 27),
# every 4th point evaluated.
set -eu
B=${1:?usage: study_auto_diag.sh BUILD [PCPNET_DIR] [--keep DIR] [--knob NAME=V ...]}
shift
P=""
K=""
KN=""
while [ $# -gt 0 ]; do
    case $1 in
    --keep) K=$2; shift 2 ;;
    --knob) KN="$KN --knob $2"; shift 2 ;;
    *) P=$1; shift ;;
    esac
done
J=$B/jetfit
D=$B/tests/bench_auto_diag
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT INT TERM
O=${K:-$W}
mkdir -p "$O"
if [ -n "$P" ]; then
    for L in 0 0.00125 0.006 0.012; do
        # shellcheck disable=SC2086
        "$D" "$P/armadillo100k.xyz" "$P/armadillo100k.normals" "$O/arm_$L.txt" \
            --pidx "$P/armadillo100k.pidx" --noise "$L" $KN
    done
fi
for S in ellipsoid torus exp; do
    DEN=""
    [ "$S" = torus ] && DEN="--density gradient"
    for L in 0.001 0.003 0.01; do
        # shellcheck disable=SC2086
        "$J" generate "$S" -o "$W/c.ply" --n 20000 --noise "$L" $DEN --seed 27 --truth "$W/t.csv" >/dev/null
        # shellcheck disable=SC2086
        "$D" "$W/c.ply" "$W/t.csv" "$O/gen_${S}_$L.txt" --every 4 $KN
    done
done
python3 "$(dirname "$0")/auto_diag.py" "$O"/*.txt
