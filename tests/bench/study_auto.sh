#!/bin/sh
# study_auto.sh -- issue 27: `--neighbors auto` against the best fixed K
# chosen in hindsight (docs/robustness.md, "Neighbourhood auto").
#
# usage: sh tests/bench/study_auto.sh BUILD [PCPNET_DIR] [--n N] [--threads T]
#   BUILD       a build folder configured with -DJF_BENCH=ON (jetfit and
#               the bench_pcpnet program in its tests folder, CGAL as for
#               the reference harness)
#   PCPNET_DIR  folder holding armadillo100k.{xyz,normals,pidx}; without
#               it only the generated surfaces run
# Prints two tables:
#  1. PCPNet armadillo100k, Gaussian noise 0 / 0.125% / 0.6% / 1.2% of the
#     bounding-box diagonal (bench_pcpnet's own draws, fixed seed): RMS
#     normal angle on the 5000 .pidx points of auto, and of CGAL's
#     jet_estimate_normals (degree 2) at k = 18, 32, 64, 128, 256, its best
#     k picked after seeing the truth.
#  2. jetfit generate surfaces (ellipsoid, torus --density gradient, exp)
#     at noise 0.1%, 0.3%, 1%: RMS normal angle and median |dk1|, |dk2| of
#     auto and of the plain degree-2 jet on k + 1 points for k = 18, 32,
#     64, 128, 256 (the points CGAL's k takes; on the same points jetfit's
#     plain jet equals CGAL's, bench_pcpnet), the best k per column.
set -eu
B=${1:?usage: study_auto.sh BUILD [PCPNET_DIR] [--n N] [--threads T]}
shift
P=""
N=20000
T=1
while [ $# -gt 0 ]; do
    case $1 in
    --n) N=$2; shift 2 ;;
    --threads) T=$2; shift 2 ;;
    *) P=$1; shift ;;
    esac
done
J=$B/jetfit
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT INT TERM

if [ -n "$P" ]; then
    echo "## PCPNet armadillo100k: RMS normal angle (deg), 5000 .pidx points"
    "$B/tests/bench_pcpnet" "$P" --no-fixed --auto --sweep "" --cgal-ks 18,32,64,128,256 \
        --cgal-jet2 >"$W/pcpnet.txt"
    awk '
    /^# auto chose/ { # K/degree:points pairs of the next auto row
        n = small = big = cub = 0
        for (i = 5; i <= NF; i++) {
            if (split($i, a, "[/:;]") < 3) continue
            c = a[3] + 0; n += c
            if (a[1] <= 64) small += c
            if (a[1] == 256) big += c
            if (a[2] == 3) cub += c
        }
        ch = sprintf("K<=64 %.0f%%, K=256 %.0f%%, cubic %.0f%%", 100 * small / n, 100 * big / n, 100 * cub / n)
        next }
    /^#/ { next }
    $2 == "jetfit" && $3 == "auto" { auto[$1] = $6; chose[$1] = ch; lv[++nl] = $1 }
    $2 == "CGAL" { k = $4; r = $6; cg[$1, k] = r; if (!(k in seen)) { seen[k] = 1; ks[++nk] = k }
                   if (!($1 in best) || r < best[$1]) { best[$1] = r; bk[$1] = k } }
    END {
        printf "| noise (x diag) | auto | auto chose (share of the 5000 points) |"
        for (j = 1; j <= nk; j++) printf " CGAL k=%s |", ks[j]
        printf " CGAL best (k) | auto / best |\n|---|---|---|"
        for (j = 1; j <= nk; j++) printf "---|"
        printf "---|---|\n"
        for (i = 1; i <= nl; i++) { l = lv[i]
            printf "| %s | %.3f | %s |", l, auto[l], chose[l]
            for (j = 1; j <= nk; j++) printf " %.3f |", cg[l, ks[j]]
            printf " %.3f (%d) | %.3f |\n", best[l], bk[l], auto[l] / best[l] }
    }' "$W/pcpnet.txt"
    grep "auto chose" "$W/pcpnet.txt" | sed 's/^# /  /'
fi

echo
echo "## jetfit generate, $N points: auto vs the plain jet on k+1 points"
echo "| surface | noise | auto normal | best k | best normal | auto dk1 | best k | best dk1 | auto dk2 | best k | best dk2 | auto / best: normal, dk1, dk2 |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for S in ellipsoid torus exp; do
    DEN=""
    [ "$S" = torus ] && DEN="--density gradient"
    for L in 0.001 0.003 0.01; do
        # shellcheck disable=SC2086
        "$J" generate "$S" -o "$W/c.ply" --n "$N" --noise "$L" $DEN --seed 27 --truth "$W/t.csv" \
            >/dev/null
        row() { # neighbourhood -> "rms_normal median_dk1 median_dk2"
            "$J" estimate "$W/c.ply" -o "$W/r.ply" --neighbors "$1" --threads "$T" --quiet
            "$J" eval "$W/r.ply" "$W/t.csv" |
                awk '$1 == "normal_deg" { n = $4 } $1 == "k1_abs" { a = $6 } $1 == "k2_abs" { b = $6 }
                     END { print n, a, b }'
        }
        A=$(row auto)
        F=""
        for K in 18 32 64 128 256; do F="$F $K $(row knn:$((K + 1)))"; done
        echo "$S $L $A $F" | awk '{
            bn = bk1 = bk2 = 1e300
            for (i = 6; i <= NF; i += 4) {
                if ($(i+1) < bn) { bn = $(i+1); kn = $i }
                if ($(i+2) < bk1) { bk1 = $(i+2); kk1 = $i }
                if ($(i+3) < bk2) { bk2 = $(i+3); kk2 = $i }
            }
            printf "| %s | %s | %.3f | %d | %.3f | %.4g | %d | %.4g | %.4g | %d | %.4g | %.3f, %.3f, %.3f |\n",
                $1, $2, $3, kn, bn, $4, kk1, bk1, $5, kk2, bk2, $3 / bn, $4 / bk1, $5 / bk2 }'
    done
done
