#!/bin/sh
# bench_scans.sh -- `jetfit estimate` on real scans: the ten raw Stanford
# bunny range scans (ASCII PLY with range_grid elements, CRLF) and the
# LAS-derived LiDAR .xyz clouds (georeferenced, coordinates ~1e5-1e6).
# Checks: exit status 0, one row per input point, no NaN/Inf in a row not
# flagged failed or non-finite (but for what its degree leaves unknown: b,
# c, and k1, k2 of a plane); prints per file: points, seconds, status counts.
# Usage: sh tests/bench/bench_scans.sh BUILD_DIR DATA [-- extra estimate options]
# DATA holds scans/stanford_bunny/data/*.ply and scans/lidar_laspy/*.xyz
# (default: $JF_DATA).
set -u
top=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$top/build}
[ $# -gt 0 ] && shift
root=${JF_DATA:-}
if [ $# -gt 0 ] && [ "$1" != "--" ]; then root=$1; shift; fi
[ "${1:-}" = "--" ] && shift
jetfit=$build/jetfit
data=$(cd "$root/scans" 2>/dev/null && pwd) || {
  echo "bench_scans: give the data folder (argument or JF_DATA): it must hold scans/stanford_bunny/data/*.ply and/or scans/lidar_laspy/*.xyz"; exit 2; }
[ -x "$jetfit" ] || { echo "bench_scans: $jetfit not built"; exit 2; }
tmp=$(mktemp -d /tmp/jf_scans.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fail=0
printf '%-44s %8s %8s  %s\n' file points seconds "status counts (value: rows)"
for f in "$data"/stanford_bunny/data/*.ply "$data"/lidar_laspy/*.xyz; do
  [ -f "$f" ] || continue
  out=$tmp/out.csv
  t0=$(date +%s.%N)
  if ! "$jetfit" estimate "$f" -o "$out" --quiet "$@" 2>"$tmp/err"; then
    printf '%-44s FAILED: %s\n' "${f#$data/}" "$(head -1 "$tmp/err")"
    fail=1
    continue
  fi
  t1=$(date +%s.%N)
  # a row without the failed (16) or non-finite (32) flag must be finite,
  # but for what its degree leaves unknown (NaN by design): the Monge b
  # and c columns, and k1, k2 of a plane (degree lowered to 1)
  awk -F, -v name="${f#$data/}" -v secs="$(echo "$t1 - $t0" | bc)" '
    NR == 1 { for (i = 1; i <= NF; i++) {
                if ($i == "status") sc = i; if ($i == "degree") dc = i
                skip[i] = $i ~ /^[bc][0-9]$/; curv[i] = $i ~ /^k[12]$/ }
              next }
    { n++; s = $sc + 0; cnt[s]++
      plane = dc && $dc + 0 < 2
      if (int(s / 16) % 4 == 0) for (i = 1; i <= NF; i++) {
        v = tolower($i); if (!skip[i] && !(plane && curv[i]) && v ~ /nan|inf/) { bad++; break } } }
    END {
      line = ""
      for (s in cnt) line = line sprintf("%s%d: %d", line == "" ? "" : ", ", s, cnt[s])
      printf "%-44s %8d %8.2f  %s\n", name, n, secs, line
      if (bad) { printf "  ERROR: %d rows not flagged failed hold NaN/Inf\n", bad; exit 1 }
    }' "$out" || fail=1
  # one row per input point (PLY header count, or the lines of the .xyz)
  case $f in
    *.ply) want=$(grep -a -m1 '^element vertex' "$f" | tr -d '\r' | awk '{print $3}') ;;
    *) want=$(grep -c -v '^[[:space:]]*\(#\|$\)' "$f") ;;
  esac
  got=$(($(wc -l < "$out") - 1))
  [ "$got" = "$want" ] || { echo "  ERROR: $got rows for $want points"; fail=1; }
done
[ $fail -eq 0 ] && echo "bench_scans: all files ok" || echo "bench_scans: FAILURES"
exit $fail
