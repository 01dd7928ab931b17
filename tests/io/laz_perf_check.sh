#!/bin/sh
# laz_perf_check.sh DUMP TESTS_DIR WORK JETFIT -- laz-perf (lazperf_dump.js
# under node), an independent LAZ decoder, against jetfit's reader and
# writer, byte for byte:
#  1. every LAZ file of tests/data/laz: jetfit's records (DUMP at 1 and 2
#     threads) = laz-perf's;
#  2. the same file through `jetfit estimate -o out.laz` (and -o out.las):
#     laz-perf decodes out.laz (`--las-columns compact`, the .laz default)
#     to the records of `-o out.las --las-columns compact`, whose first
#     bytes are the input's records as laz-perf decodes them (every original
#     attribute intact); its floats are Math.fround of out.las's doubles,
#     nx ... d2z the nearest multiples of 2^-16, its other bytes out.las's
#     (lazperf_floats.js); so for `--las-columns float` (every float the
#     fround); `--las-columns double` gives out.las's records;
#  3. generated LAS files (laz_gen.h: formats 0-3 and 6-8 with extra bytes,
#     100,001 points: two full chunks and one of a single point, scanner
#     channels switching, GPS sequences) through jetfit's writer to .laz
#     at 1 and 2 threads: the same file; laz-perf gives the records back.
# Exit 77 (skip) with the reason when node or laz-perf is missing.
set -eu
dump=$1 tests=$2 work=$3 jetfit=$4
modules=${JF_LAZPERF_MODULES:-$tests/node_modules}
node=$(command -v node || command -v nodejs || true)
if [ -z "$node" ]; then
  echo "SKIP: no node/nodejs (apt-get install nodejs; .ci/install-deps)"; exit 77
fi
if [ ! -f "$modules/laz-perf/package.json" ]; then
  echo "SKIP: no laz-perf in $modules (npm install --prefix $tests laz-perf@0.0.7; .ci/install-deps)"
  exit 77
fi
lp() { "$node" "$tests/io/lazperf_dump.js" "$modules" "$@"; }
# the record length of a LAS/LAZ file (header bytes 105-106)
reclen() { od -An -tu2 -j105 -N2 "$1" | tr -d ' '; }
mkdir -p "$work"
n=0
for f in "$tests"/data/laz/*.laz; do
  b=$(basename "$f")
  lp "$f" "$work/$b.lazperf"
  "$dump" "$f" "$work/$b.jetfit1" 1
  "$dump" "$f" "$work/$b.jetfit2" 2
  cmp "$work/$b.lazperf" "$work/$b.jetfit1"
  cmp "$work/$b.jetfit1" "$work/$b.jetfit2"
  "$jetfit" estimate "$f" -o "$work/$b.out.laz" >/dev/null 2>&1
  "$jetfit" estimate "$f" -o "$work/$b.out.las" >/dev/null 2>&1
  "$jetfit" estimate "$f" -o "$work/$b.outc.las" --las-columns compact >/dev/null 2>&1
  "$jetfit" estimate "$f" -o "$work/$b.outf.laz" --las-columns float >/dev/null 2>&1
  "$jetfit" estimate "$f" -o "$work/$b.outd.laz" --las-columns double >/dev/null 2>&1
  lp "$work/$b.out.laz" "$work/$b.out.lazperf"
  "$dump" "$work/$b.outc.las" "$work/$b.out.jetfit"
  cmp "$work/$b.out.lazperf" "$work/$b.out.jetfit"
  "$node" "$tests/io/lazperf_floats.js" "$modules" "$work/$b.out.laz" "$work/$b.out.las" \
    compact >/dev/null
  "$node" "$tests/io/lazperf_floats.js" "$modules" "$work/$b.outf.laz" "$work/$b.out.las" >/dev/null
  lp "$work/$b.outd.laz" "$work/$b.outd.lazperf"
  "$dump" "$work/$b.out.las" "$work/$b.outd.jetfit"
  cmp "$work/$b.outd.lazperf" "$work/$b.outd.jetfit"
  lp "$work/$b.out.laz" "$work/$b.out.kept" "$(reclen "$f")"
  cmp "$work/$b.lazperf" "$work/$b.out.kept"
  n=$((n + 1))
done
[ "$n" -gt 0 ] || { echo "no LAZ files in $tests/data/laz"; exit 1; }
for fmt in 0 1 2 3 6 7 8; do
  g=$work/gen$fmt
  "$dump" -g $fmt 7 100001 $((fmt + 11)) "$g.las"
  "$dump" -w "$g.las" "$g.1.laz" 1
  "$dump" -w "$g.las" "$g.2.laz" 2
  cmp "$g.1.laz" "$g.2.laz"
  "$dump" "$g.las" "$g.rec"
  lp "$g.1.laz" "$g.lazperf"
  cmp "$g.rec" "$g.lazperf"
done
echo "laz_perf_check: $n files (and their estimate -o .laz), 7 generated formats: jetfit = laz-perf"
