#!/bin/sh
# bench_memory.sh -- issue 28.1/28.2/28.4: `jetfit estimate --memory SIZE`
# against the unbounded run on the same cloud, in the same minutes (a
# benchmark, not a test: minutes at 10^7, an hour or more at 10^8).
#
#   tests/bench/bench_memory.sh [FOLDER] [N ...]
#
# FOLDER (default: a new mktemp folder under /tmp) receives the clouds
# (`jetfit generate exp --n N`, binary PLY, kept for reruns) and outputs
# (deleted).  N (default 1000000 10000000).  For each N, knn:16 degree 2,
# THREADS (default 2) threads, binary PLY out:
#   1. in memory: wall, user+sys CPU, peak RSS (GNU time);
#   2. --memory SIZE, SIZE = a third of (1)'s peak, or, when the command
#      refuses it, the least that works (its message names it); at 10^8
#      also --memory 2G (MEM100M overrides); EXTRA="400M 1G": these too;
#   3. the ratios (time, CPU, peak), "budget ok" when peak <= SIZE + 64 MiB,
#      and the outputs' SHA-256 compared (identical required).
# The load average is printed before and after: the machine is shared.
set -eu
top=$(cd "$(dirname "$0")/../.." && pwd)
bin=${JETFIT:-$top/build/jetfit}
dir=${1:-}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- 1000000 10000000
threads=${THREADS:-2}
if [ -z "$dir" ]; then dir=$(mktemp -d /tmp/jf_memory.XXXXXX); fi
mkdir -p "$dir"
trap 'rm -f "$dir"/mem_out_*.ply "$dir"/.mem_*' EXIT
[ -x "$bin" ] || { echo "bench_memory: $bin not built" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "bench_memory: needs GNU time (/usr/bin/time)" >&2; exit 1; }

# est OUT [ARGS...]: runs the estimate; sets wall cpu peak_kb rc
est() {
    out=$1
    shift
    rc=0
    /usr/bin/time -f "%e %U %S %M" -o "$dir/.mem_time" "$bin" estimate "$cloud" -o "$out" \
        --neighbors knn:16 --degree 2 --threads "$threads" --quiet "$@" 2>"$dir/.mem_err" || rc=$?
    set -- $(tail -n 1 "$dir/.mem_time")
    wall=$1
    cpu=$(echo "$2 + $3" | bc)
    peak_kb=$4
}

echo "# $(date -u +%FT%TZ) $(nproc) cores, threads $threads, load: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-11s %-10s %9s %9s %9s %8s %8s %8s %s\n' points run SIZE_MiB wall_s cpu_s peak_MiB t_ratio \
    cpu_ratio "budget / output"
for n in "$@"; do
    cloud=$dir/mem_exp_$n.ply
    [ -s "$cloud" ] || "$bin" generate exp --n "$n" --seed 1 -o "$cloud"
    est "$dir/mem_out_whole.ply"
    [ "$rc" = 0 ] || { cat "$dir/.mem_err" >&2; exit 1; }
    w_wall=$wall w_cpu=$cpu w_peak=$peak_kb
    h_whole=$(sha256sum <"$dir/mem_out_whole.ply" | cut -d' ' -f1)
    printf '%-11s %-10s %9s %9s %9s %8d %8s %8s %s\n' "$n" memory - "$wall" "$cpu" $((peak_kb / 1024)) \
        1 1 -
    third=$((w_peak / 3 / 1024))
    sizes="${third}M ${EXTRA:-}"
    [ "$n" -ge 100000000 ] && sizes="$sizes ${MEM100M:-2G}"
    for size in $sizes; do
        label="--memory"
        est "$dir/mem_out_part.ply" --memory "$size"
        if [ "$rc" = 1 ] && grep -q "the least that works is" "$dir/.mem_err"; then
            least=$(sed -n 's/.*the least that works is --memory \([0-9]*[KM]\).*/\1/p' "$dir/.mem_err")
            echo "#   --memory $size refused: $(cat "$dir/.mem_err")"
            size=$least
            label="least"
            est "$dir/mem_out_part.ply" --memory "$size"
        fi
        [ "$rc" = 0 ] || { cat "$dir/.mem_err" >&2; exit 1; }
        case $size in
            *G) mib=$((${size%G} * 1024)) ;;
            *M) mib=${size%M} ;;
            *K) mib=$((${size%K} / 1024)) ;;
        esac
        ok=over
        [ $((peak_kb / 1024)) -le $((mib + 64)) ] && ok=ok
        same=DIFFERENT
        [ "$(sha256sum <"$dir/mem_out_part.ply" | cut -d' ' -f1)" = "$h_whole" ] && same=identical
        printf '%-11s %-10s %9s %9s %9s %8d %8.2f %8.2f %s / %s\n' "$n" "$label" "$mib" "$wall" "$cpu" \
            $((peak_kb / 1024)) "$(echo "$wall / $w_wall" | bc -l)" "$(echo "$cpu / $w_cpu" | bc -l)" \
            "$ok" "$same"
        echo "#   peak / in-memory peak: $(echo "$peak_kb / $w_peak" | bc -l | cut -c1-5)"
    done
done
echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)"
