#!/bin/sh
# study_natural_noise.sh -- issue 15.1: natural:N against knn:N on noisy
# `jetfit generate` clouds.  Per cell (surface, density, noise, N) prints the
# normal RMS error (degrees) and the median relative k1 error of knn:N,
# natural:N before (--normal poles, the old default) and after (the default,
# --normal auto), the after/knn ratios, the share of points whose plane
# came from the jet (status flag normal_jet), and the median relative k2
# error of knn:N and after with its ratio.  BEFORE=0 skips the poles run
# (its columns print as nan).  Usage: sh tests/bench/study_natural_noise.sh
# [BUILD_DIR] [N_POINTS] [NS...]   (defaults: build, 20000, 32 64 128 256).
# Environment: SURFS (ellipsoid exp sphere), NOISES (0.001 0.003 0.01),
# DENS (uniform gradient), DEG (2).
set -u
top=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$top/build}; [ $# -gt 0 ] && shift
np=${1:-20000}; [ $# -gt 0 ] && shift
ns=${*:-32 64 128 256}
jetfit=$build/jetfit
[ -x "$jetfit" ] || { echo "study_natural_noise: $jetfit not built"; exit 2; }
tmp=$(mktemp -d /tmp/jf_natnoise.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
# eval's table: quantity n nonfin rms mean median p95 max
get() { awk -v q="$2" -v c="$3" '$1 == q { print $c }' "$1"; }
printf '%-9s %-8s %6s %4s | %7s %7s %7s | %7s %7s %7s | %5s %5s %4s | %7s %7s %5s\n' surface density noise N \
  knn_deg before after knn_k1 before after r_nrm r_k1 jet knn_k2 after r_k2
for s in ${SURFS:-ellipsoid exp sphere}; do
 for d in ${DENS:-uniform gradient}; do
  for z in ${NOISES:-0.001 0.003 0.01}; do
   "$jetfit" generate "$s" -o "$tmp/c.ply" --truth "$tmp/t.csv" --n "$np" \
       --noise "$z" --density "$d" --seed 1 || exit 1
   for n in $ns; do
    ms="knn nat natpca"; [ "${BEFORE:-1}" = 0 ] && ms="knn natpca"
    for m in $ms; do
     case $m in
      knn) opt="--neighbors knn:$n" ;;
      nat) opt="--neighbors natural:$n --normal poles" ;;
      natpca) opt="--neighbors natural:$n" ;;
     esac
     "$jetfit" estimate "$tmp/c.ply" -o "$tmp/$m.csv" --degree "${DEG:-2}" $opt --quiet || exit 1
     "$jetfit" eval "$tmp/$m.csv" "$tmp/t.csv" > "$tmp/$m.ev" || exit 1
    done
    [ "${BEFORE:-1}" = 0 ] && printf 'normal_deg 0 0 nan\nk1_rel 0 0 0 0 nan\n' > "$tmp/nat.ev"
    a=$(get "$tmp/knn.ev" normal_deg 4); b=$(get "$tmp/nat.ev" normal_deg 4); c=$(get "$tmp/natpca.ev" normal_deg 4)
    e=$(get "$tmp/knn.ev" k1_rel 6); f=$(get "$tmp/nat.ev" k1_rel 6); g=$(get "$tmp/natpca.ev" k1_rel 6)
    h=$(get "$tmp/knn.ev" k2_rel 6); i=$(get "$tmp/natpca.ev" k2_rel 6)
    # the share of rows whose status has the normal_jet bit (32768)
    jet=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "status") col = i; next }
                   { n++; if (int($col / 32768) % 2) j++ } END { printf "%.2f", j / n }' "$tmp/natpca.csv")
    printf '%-9s %-8s %6s %4s | %7.3f %7.3f %7.3f | %7.4f %7.4f %7.4f | %5.2f %5.2f %4s | %7.4f %7.4f %5.2f\n' "$s" "$d" "$z" "$n" \
      "$a" "$b" "$c" "$e" "$f" "$g" "$(echo "$c / $a" | bc -l)" "$(echo "$g / $e" | bc -l)" "$jet" \
      "$h" "$i" "$(echo "$i / $h" | bc -l)"
   done
  done
 done
done
