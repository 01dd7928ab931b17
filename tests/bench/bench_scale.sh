#!/bin/sh
# bench_scale.sh -- issue 12.1: `jetfit estimate` on 10^8 points in bounded
# memory (a benchmark, not a test: minutes, ~45 GB of disk at 10^8).
#
#   tests/bench/bench_scale.sh [FOLDER] [N]
#
# FOLDER (default: a new mktemp folder under /tmp) receives the generated
# clouds, the outputs and the row spool; every big file is deleted at the
# end.  N (default 100000000) is the large run's point count.  Runs:
#   1. `jetfit generate exp --n 1000000` and `--n N` to binary PLY;
#   2. `jetfit estimate --neighbors knn:16 --degree 2` on each, binary PLY
#      out: wall time, points/s, points/s per thread, peak RSS (and bytes
#      per point); the ratio of the per-thread rates (goal: within 20%)
#      and the large run's peak against the 80 bytes/point bar;
#   3. 10^7 points estimated twice, unforced and with `--memory 256M`
#      (parts with halos), compared byte for byte with cmp.
# Peak RSS: /usr/bin/time -v when present, else Python's
# resource.getrusage(RUSAGE_CHILDREN).  Build first: cmake --build build.
#
#   tests/bench/bench_scale.sh --phases [FOLDER] [N]
#
# issue 28.3 instead: N (default 4000000) points of the same cloud as
# binary PLY and as .xyz, `jetfit estimate --neighbors knn:16 --degree 2`
# at 1 and $(nproc) threads (THREADS overrides N threads), inputs ply ->
# ply, xyz -> ply and xyz -> xyz: wall time and each phase's time from the
# summary's "phases" line (read, order or tree, fit, write: the command's
# progress hooks), then the end-to-end speed-ups 1 -> N threads and the
# time of .xyz over binary PLY input at N threads.  REPS (default 1): the
# best of that many runs of each.
set -eu
top=$(cd "$(dirname "$0")/../.." && pwd)
bin=${JETFIT:-$top/build/jetfit}
if [ "${1:-}" = "--phases" ]; then
    shift
    dir=${1:-}
    N=${2:-4000000}
    nt=${THREADS:-$(nproc)}
    reps=${REPS:-1}
    if [ -z "$dir" ]; then dir=$(mktemp -d /tmp/jf_phases.XXXXXX); fi
    mkdir -p "$dir"
    trap 'rm -f "$dir"/ph_*' EXIT
    [ -x "$bin" ] || { echo "bench_scale: $bin not built" >&2; exit 1; }
    echo "machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.1f GB", $2/1048576}' /proc/meminfo)," \
         "load $(cut -d' ' -f1-3 /proc/loadavg); jetfit $($bin --version 2>/dev/null | head -1)"
    "$bin" generate exp --n "$N" --seed 12 -o "$dir/ph_in.ply" >/dev/null
    "$bin" generate exp --n "$N" --seed 12 -o "$dir/ph_in.xyz" >/dev/null
    echo "N = $N points (ply $(du -m "$dir/ph_in.ply" | cut -f1) MB, xyz $(du -m "$dir/ph_in.xyz" | cut -f1) MB); best of $reps"
    printf "%-10s %7s %8s %7s %7s %7s %7s %7s\n" in-out threads wall read order tree fit write
    for io in ply-ply xyz-ply xyz-xyz; do
        for t in 1 "$nt"; do
            best=""
            r=0
            while [ "$r" -lt "$reps" ]; do
                s0=$(date +%s.%N)
                "$bin" estimate "$dir/ph_in.${io%-*}" -o "$dir/ph_out.${io#*-}" --neighbors knn:16 \
                    --degree 2 --threads "$t" 2>"$dir/ph_err" >/dev/null ||
                    { cat "$dir/ph_err" >&2; exit 1; }
                s1=$(date +%s.%N)
                line=$(awk -v w="$(awk -v a="$s0" -v b="$s1" 'BEGIN { print b - a }')" '/phases:/ {
                    sub(/.*phases: /, ""); n = split($0, f, ", ")
                    for (i = 1; i <= n; i++) { split(f[i], kv, " "); v[kv[1]] = kv[2] }
                    printf "%.2f %.2f %.2f %.2f %.2f %.2f", w, v["read"], v["order"], v["tree"],
                           v["fit"], v["write"] }' "$dir/ph_err")
                if [ -z "$best" ] || awk -v a="${line%% *}" -v b="${best%% *}" 'BEGIN { exit !(a < b) }'; then
                    best=$line
                fi
                r=$((r + 1))
            done
            set -- $best
            printf "%-10s %7s %8s %7s %7s %7s %7s %7s\n" "$io" "$t" "$1" "$2" "$3" "$4" "$5" "$6"
            eval "w_${io%-*}_${io#*-}_$t=$1"
        done
    done
    eval "a=\$w_ply_ply_1 b=\$w_ply_ply_$nt c=\$w_xyz_ply_1 d=\$w_xyz_ply_$nt e=\$w_xyz_xyz_1 f=\$w_xyz_xyz_$nt"
    echo "$a $b $c $d $e $f" | awk -v nt="$nt" '{
        printf "end to end 1 -> %d threads: ply -> ply %.2fx, xyz -> ply %.2fx, xyz -> xyz %.2fx (goal >= 1.75x on 2)\n", nt, $1 / $2, $3 / $4, $5 / $6
        printf ".xyz input / binary PLY input at %d threads: %.2fx (goal <= 1.1x)\n", nt, $4 / $2 }'
    exit 0
fi
dir=${1:-}
N=${2:-100000000}
threads=${THREADS:-$(nproc)}
if [ -z "$dir" ]; then dir=$(mktemp -d /tmp/jf_scale.XXXXXX); fi
mkdir -p "$dir"
trap 'rm -f "$dir"/scale_*.ply "$dir"/.scale_*' EXIT
[ -x "$bin" ] || { echo "bench_scale: $bin not built" >&2; exit 1; }

# run LABEL CMD...: prints "LABEL wall_s peak_kb" on stdout
run() {
    label=$1
    shift
    if [ -x /usr/bin/time ]; then
        /usr/bin/time -f "%e %M" -o "$dir/.scale_time" "$@" >/dev/null 2>"$dir/.scale_err" ||
            { cat "$dir/.scale_err" >&2; exit 1; }
        echo "$label $(cat "$dir/.scale_time")"
    else
        python3 - "$label" "$@" <<'EOF'
import resource, subprocess, sys, time
t = time.monotonic()
subprocess.run(sys.argv[2:], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
wall = time.monotonic() - t
print(sys.argv[1], "%.2f" % wall, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
EOF
    fi
}

echo "machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.1f GB", $2/1048576}' /proc/meminfo)," \
     "load $(cut -d' ' -f1-3 /proc/loadavg); jetfit $($bin --version 2>/dev/null | head -1)"
echo "folder: $dir ($(df -h "$dir" | awk 'NR==2 {print $4}') free); threads: $threads"

est() { # est LABEL N [extra options]
    label=$1 n=$2
    shift 2
    run "$label" "$bin" estimate "$dir/scale_in_$n.ply" -o "$dir/scale_out_$label.ply" \
        --neighbors knn:16 --degree 2 --threads "$threads" --quiet "$@"
}

report() { # report LINE N
    set -- $1 $2
    awk -v l="$1" -v w="$2" -v kb="$3" -v n="$4" -v t="$threads" 'BEGIN {
        printf "%-10s %12d points  wall %8.1f s  %10.0f points/s  %9.0f points/s/thread" \
               "  peak %8.1f MiB  %5.1f B/point\n", l, n, w, n / w, n / w / t, kb / 1024, kb * 1024 / n }'
}

for n in 1000000 "$N"; do
    run "gen_$n" "$bin" generate exp --n "$n" --seed 12 -o "$dir/scale_in_$n.ply" >/dev/null
done
small=$(est small 1000000)
report "$small" 1000000
rm -f "$dir/scale_out_small.ply" "$dir/scale_in_1000000.ply"
large=$(est large "$N")
report "$large" "$N"
rm -f "$dir/scale_out_large.ply" "$dir/scale_in_$N.ply"
echo "$small $large" | awk -v ns=1000000 -v nl="$N" '{
    rs = ns / $2; rl = nl / $5
    printf "per-thread rate, large / small: %.2f (goal >= 0.80)\n", rl / rs
    printf "large peak: %.1f bytes/point (goal <= 80)\n", $6 * 1024 / nl }'

# --memory 256M forces parts at 10^7 points: the same bytes
m=10000000
run "gen_$m" "$bin" generate exp --n "$m" --seed 13 -o "$dir/scale_in_$m.ply" >/dev/null
whole=$(est whole "$m")
report "$whole" "$m"
parts=$(est parts "$m" --memory 256M)
report "$parts" "$m"
if cmp "$dir/scale_out_whole.ply" "$dir/scale_out_parts.ply"; then
    echo "10^7 points: --memory 256M (parts) output identical to the unforced run (cmp)"
else
    echo "10^7 points: --memory 256M output DIFFERS from the unforced run" >&2
    exit 1
fi
