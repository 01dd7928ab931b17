#!/bin/sh
# bench_mpi.sh -- jetfit-mpi on one machine: np 1 vs np 2 (one OpenMP thread
# per rank) on N random samples of the exp surface (default 10^7), knn:16
# degree 2, with `jetfit estimate --threads 1` and `--threads 2` as peers
# measured in the same run.  Prints wall seconds, points/s, peak RSS of the
# largest rank (GNU time), the slowest rank's exchange / fit / write
# seconds and the halo, and checks that every output is byte-identical.
# A benchmark, not a test (docs/scale.md "How it works").
# Usage: sh tests/bench/bench_mpi.sh [BUILD_DIR] [N] [WORK_DIR]
set -u
top=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$top/build}
n=${2:-10000000}
work=${3:-$(mktemp -d /tmp/jf_bench_mpi.XXXXXX)}
jetfit=$build/jetfit jmpi=$build/jetfit-mpi
[ -x "$jmpi" ] || { echo "bench_mpi: $jmpi not built (MPI not found?)"; exit 2; }
command -v mpirun >/dev/null || { echo "bench_mpi: no mpirun"; exit 2; }
[ -x /usr/bin/time ] || { echo "bench_mpi: needs GNU time (/usr/bin/time)"; exit 2; }
mkdir -p "$work"
cloud=$work/exp_$n.ply
[ -f "$cloud" ] || "$jetfit" generate exp --n "$n" -o "$cloud" --seed 7 >/dev/null || exit 1
opts="--neighbors knn:16 --degree 2"
cores=$(nproc) # before OMP_NUM_THREADS, which nproc obeys
export OMP_NUM_THREADS=1
echo "# $n points (exp surface), $opts; $cores cores, machine shared"
printf '%-26s %8s %12s %10s  %s\n' run seconds points/s "RSS MiB" "exchange / fit / write s (slowest rank); halo"
run() { # NAME OUT COMMAND...
  name=$1 out=$2; shift 2
  rm -f "$out"
  t0=$(date +%s.%N)
  /usr/bin/time -f '%M' -o "$work/rss" "$@" >/dev/null 2>"$work/log" || {
    echo "$name FAILED"; cat "$work/log"; return 1; }
  t1=$(date +%s.%N)
  s=$(echo "$t1 - $t0" | bc -l)
  rss=$(tail -1 "$work/rss")
  detail=$(sed -n 's/^  exchange \(.*\) (slowest rank)/\1/p; s/^  halo: \(.*\)/halo \1/p' "$work/log" | tr '\n' ' ')
  printf '%-26s %8.2f %12.0f %10.0f  %s\n' "$name" "$s" "$(echo "$n / $s" | bc -l)" \
    "$(echo "$rss / 1024" | bc -l)" "$detail"
}
# GNU time on mpirun reports the largest of mpirun's children (one rank)
run "jetfit --threads 1" "$work/ref.ply" "$jetfit" estimate "$cloud" -o "$work/ref.ply" $opts --threads 1 --quiet
run "jetfit --threads 2" "$work/t2.ply" "$jetfit" estimate "$cloud" -o "$work/t2.ply" $opts --threads 2 --quiet
for np in 1 2; do
  run "jetfit-mpi -np $np" "$work/np$np.ply" mpirun --allow-run-as-root --oversubscribe \
    --bind-to core -np $np "$jmpi" estimate "$cloud" -o "$work/np$np.ply" $opts --threads 1
done
for f in t2 np1 np2; do
  cmp -s "$work/ref.ply" "$work/$f.ply" && echo "$f.ply: identical to jetfit --threads 1" ||
    echo "$f.ply: DIFFERS"
done
