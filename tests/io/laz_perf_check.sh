#!/bin/sh
# laz_perf_check.sh DUMP TESTS_DIR WORK -- every LAZ file of
# tests/data/laz decoded by jetfit (DUMP, at 1 and 2 threads) and by
# laz-perf (lazperf_dump.js under node): the same point records, byte for
# byte.  Exit 77 (skip) with the reason when node or laz-perf is missing.
set -eu
dump=$1 tests=$2 work=$3
modules=${JF_LAZPERF_MODULES:-$tests/node_modules}
node=$(command -v node || command -v nodejs || true)
if [ -z "$node" ]; then
  echo "SKIP: no node/nodejs (apt-get install nodejs; .ci/install-deps)"; exit 77
fi
if [ ! -f "$modules/laz-perf/package.json" ]; then
  echo "SKIP: no laz-perf in $modules (npm install --prefix $tests laz-perf@0.0.7; .ci/install-deps)"
  exit 77
fi
mkdir -p "$work"
n=0
for f in "$tests"/data/laz/*.laz; do
  b=$(basename "$f")
  "$node" "$tests/io/lazperf_dump.js" "$modules" "$f" "$work/$b.lazperf"
  "$dump" "$f" "$work/$b.jetfit1" 1
  "$dump" "$f" "$work/$b.jetfit2" 2
  cmp "$work/$b.lazperf" "$work/$b.jetfit1"
  cmp "$work/$b.jetfit1" "$work/$b.jetfit2"
  n=$((n + 1))
done
[ "$n" -gt 0 ] || { echo "no LAZ files in $tests/data/laz"; exit 1; }
echo "laz_perf_check: $n files, jetfit's records = laz-perf's"
