#!/bin/sh
# test_mpi.sh JETFIT JETFIT_MPI WORKDIR MODE -- jetfit-mpi against jetfit
# estimate (registered by tests/mpi.cmake; exit 77 = skipped).
#   equal-knn, equal-more: `mpirun -np 1|2|3 jetfit-mpi estimate` writes the
#       same bytes (cmp) as `jetfit estimate` on the clouds of make_clouds.py
#       (part boundaries through a lattice's shared planes and ties,
#       duplicates straddling a cut, K above the parts' counts, an empty
#       part, NaN rows, big-endian floats with normals), for knn, radius,
#       knn+radius, every fit option, orientation none/input/viewpoint, and
#       the text outputs; auto's step 0 regimes, a range scan's among them.
#   full-disk: on a 2 MB tmpfs (skipped where it cannot be mounted) every
#       np ends with exit 1, one line, the old output intact, no temporary.
#   errors: refused options and inputs, bad files and a failing rank end
#       every rank with one line, exit 1, no output (an old one intact),
#       no temporary left.
set -u
jetfit=$1 jmpi=$2 work=$3 mode=$4
here=$(cd "$(dirname "$0")" && pwd)
command -v mpirun >/dev/null 2>&1 || { echo "SKIP: mpirun not found"; exit 77; }
command -v python3 >/dev/null 2>&1 || { echo "SKIP: python3 not found"; exit 77; }
[ -x "$jmpi" ] || { echo "SKIP: jetfit-mpi not built"; exit 77; }
d="$work/mpi-$mode"
rm -rf "$d" && mkdir -p "$d" && python3 "$here/make_clouds.py" "$d" || exit 1
export OMP_NUM_THREADS=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
mpi() { np=$1; shift; mpirun --allow-run-as-root --oversubscribe -q -np "$np" "$jmpi" "$@"; }
fail=0
bad() { echo "FAIL: $*"; fail=1; }

# same NPS CLOUD OUT-EXT [options]: every np in NPS gives jetfit's bytes
same() {
  nps=$1 cloud=$2 ext=$3; shift 3
  "$jetfit" estimate "$d/$cloud" -o "$d/ref.$ext" --quiet --threads 1 --keep none "$@" ||
    { bad "jetfit estimate $cloud $*"; return; }
  for np in $nps; do
    rm -f "$d/got.$ext"
    mpi "$np" estimate "$d/$cloud" -o "$d/got.$ext" --quiet "$@" ||
      { bad "np $np: jetfit-mpi estimate $cloud $* exited non-zero"; continue; }
    cmp -s "$d/ref.$ext" "$d/got.$ext" && echo "ok   np $np $cloud .$ext $*" ||
      bad "np $np: $cloud .$ext $*: output differs from jetfit estimate"
  done
}

# refused EXPECT-IN-MESSAGE NP [args]: exit 1, one line, no output
refused() {
  want=$1 np=$2; shift 2
  rm -f "$d/err.ply"
  mpi "$np" estimate "$@" 2>"$d/stderr" >/dev/null; rc=$?
  lines=$(grep -c . "$d/stderr")
  if [ $rc -ne 1 ] || [ "$lines" -ne 1 ] || ! grep -q -- "$want" "$d/stderr"; then
    bad "np $np $*: expected exit 1 and one line with '$want', got exit $rc:"; cat "$d/stderr"
  elif [ -e "$d/err.ply" ]; then bad "np $np $*: an output file was left"
  else echo "ok   refused: $(cat "$d/stderr")"; fi
}

case $mode in
equal-knn)
  same "1 2 3" lattice.ply ply --neighbors knn:16
  same "2 3" lattice.ply ply --neighbors knn:12 --scales 6,12 --degree 3
  same "3" lattice.ply ply --neighbors knn:24 --robust huber
  same "2" lattice.ply ply --neighbors knn:30 --degree 4 --monge-degree 4 --fit approx
  same "3" lattice.ply ply --neighbors knn:16 --degree-select 1 --dist-weight 0.5 \
       --orient viewpoint:0,0,10 --frame axis
  same "2 3" clusters.ply ply                       # knn:32, orient input (normals)
  # tiny.ply (no point can be fitted) is refused as jetfit estimate refuses
  # it (errors mode); few.ply: most points unfitted, jetfit's bytes and its
  # warning, and an empty part on 5 ranks (issues 31, 33.12)
  same "1 3 5" few.ply ply --neighbors knn:4 --degree 1
  "$jetfit" estimate "$d/few.ply" -o "$d/ref.ply" --quiet --keep none --neighbors knn:4 \
    --degree 1 2>"$d/want"
  for np in 1 5; do
    mpi "$np" estimate "$d/few.ply" -o "$d/got.ply" --quiet --neighbors knn:4 --degree 1 2>"$d/stderr"
    if [ "$(sed 's/^jetfit[^:]*: //' "$d/want")" = "$(sed 's/^jetfit[^:]*: //' "$d/stderr")" ] &&
       grep -q "5 of 9 points could not be fitted" "$d/stderr"; then
      echo "ok   np $np few.ply: $(cat "$d/stderr")"
    else bad "np $np few.ply: jetfit-mpi's warning '$(cat "$d/stderr")', jetfit's '$(cat "$d/want")'"; fi
  done
  same "3" ten.ply ply --neighbors knn:8 --fit interp --degree 2
  # LAS input: each rank decodes its byte range of the records (scale, offset)
  "$jetfit" estimate "$d/clusters.ply" -o "$d/clusters.las" --quiet --keep none ||
    bad "jetfit estimate clusters.ply -o clusters.las"
  same "1 2 3" clusters.las ply --neighbors knn:16
  same "2" clusters.las csv --neighbors knn:24,radius:0.01 --degree 3
  # LAZ input (issue 25.3): each rank decodes the chunks of its rows; our
  # writer's format 0, and a real 65-chunk COPC file (format 7)
  "$jetfit" estimate "$d/clusters.ply" -o "$d/clusters.laz" --quiet --keep none ||
    bad "jetfit estimate clusters.ply -o clusters.laz"
  same "1 2 3" clusters.laz ply --neighbors knn:16
  cp "$here/../data/laz/simple.copc.laz" "$d/copc.laz"
  same "1 2 3" copc.laz ply --neighbors knn:12
  ;;
equal-more)
  same "2 3" lattice.ply ply --neighbors radius:1.2
  same "1 3" lattice.ply ply --neighbors knn:20,radius:1.05 --degree 3
  same "3" clusters.ply ply --neighbors radius:0.004 --orient none --robust tukey
  same "2" clusters.ply ply --neighbors knn:10,radius:0.0005 --max-cond 100
  same "3" lattice.ply csv --neighbors knn:16
  same "2" lattice.ply xyz --neighbors knn:16 --monge-degree 3 --degree 3
  same "3" clusters.ply ply --ascii --neighbors knn:16
  same "2 3" clusters.ply csv --neighbors auto  # issue 27: per-point K and degree, sigma column
  # auto's step 0: a clean cloud is capped (K <= 24, status bit 18) by its
  # cross-validation, decided from every rank's share of the sample
  "$jetfit" generate ellipsoid -o "$d/clean.ply" --n 3000 --seed 27 >/dev/null ||
    bad "jetfit generate ellipsoid"
  same "2 3" clean.ply csv --neighbors auto
  capped=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "status") s = i; next }
                    int($s / 262144) % 2 { c++ } END { print c + 0 }' "$d/ref.csv")
  [ "$capped" -eq 3000 ] && echo "ok   auto capped: $capped of 3000 rows" ||
    bad "auto on a clean cloud: $capped of 3000 rows capped (want all)"
  # auto's step 0 bias test, decided from every rank's share of the sample:
  # a torus at 0.3% spreads the plain carry (bit 20) on part of its rows, an
  # exp patch at 0.05% weights every row's mean (bit 19)
  "$jetfit" generate torus -o "$d/spread.ply" --n 6000 --noise 0.003 --density gradient --seed 27 \
    >/dev/null || bad "jetfit generate torus"
  "$jetfit" generate exp -o "$d/weighted.ply" --n 4000 --noise 0.0005 --seed 27 >/dev/null ||
    bad "jetfit generate exp"
  for c in spread:1048576:600 weighted:524288:3999; do
    name=${c%%:*} rest=${c#*:} bit=${rest%%:*} least=${rest#*:}
    same "2 3" "$name.ply" csv --neighbors auto
    got=$(awk -F, -v b="$bit" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "status") s = i; next }
                              int($s / b) % 2 { c++ } END { print c + 0 }' "$d/ref.csv")
    [ "$got" -gt "$least" ] && echo "ok   auto $name: $got rows flagged $bit" ||
      bad "auto on $name.ply: $got rows flagged $bit (want more than $least)"
  done
  # a raw range scan (data/bun090.ply, made binary): step 0 caps K at 32
  # and weights every row's mean (bits 18 and 19), decided from the ranks'
  # shares of the sample
  "$jetfit" estimate "$here/../../data/bun090.ply" -o "$d/scan.ply" --keep none --quiet ||
    bad "jetfit estimate bun090.ply"
  same "2" scan.ply csv --neighbors auto --orient none
  got=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "status") s = i; next }
                 int($s / 262144) % 2 && int($s / 524288) % 2 { c++ } END { print c + 0 }' "$d/ref.csv")
  [ "$got" -eq 30379 ] && echo "ok   auto scan: $got rows capped and weighted" ||
    bad "auto on bun090: $got rows capped and weighted (want 30379)"
  # auto's halo balls overlap: each point is sent to a rank once (kept == fetched)
  mpi 3 estimate "$d/clusters.ply" -o "$d/got.csv" --neighbors auto 2>"$d/stderr" >/dev/null
  h=$(sed -n 's/^ *halo: \([0-9]*\) points kept, \([0-9]*\) fetched.*/\1 \2/p' "$d/stderr")
  set -- $h
  if [ -n "$h" ] && [ "$1" -gt 0 ] && [ "$1" = "$2" ]; then echo "ok   np 3 auto halo: $1 kept, $2 fetched"
  else bad "np 3 auto halo: '$h' (want N kept, N fetched)"; cat "$d/stderr"; fi
  # the summary's lines for the chosen K and step 0's decision: the
  # ranks' as the whole cloud's
  for c in clean spread scan; do
    "$jetfit" estimate "$d/$c.ply" -o "$d/ref.csv" --neighbors auto 2>"$d/want" >/dev/null
    mpi 2 estimate "$d/$c.ply" -o "$d/got.csv" --neighbors auto 2>"$d/stderr" >/dev/null
    for l in 'auto K' 'auto step 0'; do
      w=$(grep "^  $l: " "$d/want") g=$(grep "^  $l: " "$d/stderr")
      if [ -n "$w" ] && [ "$w" = "$g" ]; then echo "ok   np 2 $c: the same line:$w"
      else bad "np 2 $c: '$g', jetfit estimate's '$w'"; fi
    done
  done
  ;;
errors)
  refused "not supported in distributed runs" 2 "$d/lattice.ply" -o "$d/err.ply" --neighbors natural
  refused "not supported in distributed runs" 2 "$d/lattice.ply" -o "$d/err.ply" --orient mst
  refused "binary PLY and LAS only" 2 "$d/lattice.csv" -o "$d/err.ply"
  refused "No such file" 3 "$d/missing.ply" -o "$d/err.ply"
  refused "jetfit-mpi writes doubles" 2 "$d/lattice.ply" -o "$d/err.laz" --las-columns float
  printf 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n' >"$d/ascii.ply"
  refused "ascii PLY" 2 "$d/ascii.ply" -o "$d/err.ply"
  head -c 3000 "$d/lattice.ply" >"$d/cut.ply"
  refused "cut.ply" 3 "$d/cut.ply" -o "$d/err.ply"
  "$jetfit" estimate "$d/lattice.ply" -o "$d/lattice.las" --quiet --keep none
  head -c 5000 "$d/lattice.las" >"$d/cut.las" # past the VLRs, into the records
  refused "point record" 2 "$d/cut.las" -o "$d/err.ply"
  "$jetfit" estimate "$d/lattice.ply" -o "$d/lattice.laz" --quiet --keep none
  head -c 5000 "$d/lattice.laz" >"$d/cut.laz" # into the first chunk, the table gone
  refused "rebuilding it from the chunks failed" 2 "$d/cut.laz" -o "$d/err.ply"
  refused "err.ply" 2 "$d/lattice.ply" -o "$d/nodir/err.ply"
  # one fault, one message: jetfit estimate's words (issue 32.5, 33.8)
  printf 'ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nend_header\n' >"$d/xonly.ply"
  head -c 24 /dev/zero >>"$d/xonly.ply"
  printf 'ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >"$d/empty.ply"
  for f in xonly.ply empty.ply tiny.ply; do
    "$jetfit" estimate "$d/$f" -o "$d/err.ply" --quiet 2>"$d/want"; rc=$?
    want=$(sed 's/^jetfit[^:]*: //' "$d/want")
    [ $rc -eq 1 ] && [ -n "$want" ] || bad "jetfit estimate $f: exit $rc, '$want'"
    for np in 1 3; do refused "$want" $np "$d/$f" -o "$d/err.ply"; done
  done
  refused "no standard input or output" 2 - --input-format ply -o "$d/err.ply"
  # GNU conventions (issue 31): --version, and -oFILE / --opt=V as estimate takes them
  if "$jmpi" --version | grep -q "^jetfit-mpi .*" && "$jmpi" --version | grep -q "^MPI "; then
    echo "ok   jetfit-mpi --version: $("$jmpi" --version | head -1)"
  else bad "jetfit-mpi --version: $("$jmpi" --version 2>&1)"; fi
  mpi 2 estimate "$d/lattice.ply" "-o$d/gnu.ply" --neighbors=knn:16 --quiet
  "$jetfit" estimate "$d/lattice.ply" -o "$d/ref.ply" --neighbors knn:16 --quiet --keep none
  cmp -s "$d/gnu.ply" "$d/ref.ply" && echo "ok   -oFILE --neighbors=knn:16" || bad "-oFILE --opt=V: differs"
  # a rank that fails mid-run: one line, exit 1, the old output intact
  echo old >"$d/keep.ply"
  JETFIT_MPI_TEST_FAIL=2 mpirun --allow-run-as-root --oversubscribe -q -x JETFIT_MPI_TEST_FAIL \
    -np 3 "$jmpi" estimate "$d/lattice.ply" -o "$d/keep.ply" --quiet 2>"$d/stderr"; rc=$?
  if [ $rc -ne 1 ] || [ "$(grep -c . "$d/stderr")" -ne 1 ] || ! grep -q "rank 2" "$d/stderr"; then
    bad "failing rank: exit $rc:"; cat "$d/stderr"
  elif [ "$(cat "$d/keep.ply")" != old ]; then bad "failing rank: the old output was changed"
  else echo "ok   failing rank: $(cat "$d/stderr")"; fi
  left=$(ls -A "$d" | grep -c tmp)
  [ "$left" -eq 0 ] || bad "temporaries left: $(ls -A "$d")"
  ;;
full-disk)
  # a 2 MB tmpfs holding an old output: the 4 MB result cannot fit; every
  # np, binary and text output, with and without the up-front reservation
  # (JETFIT_MPI_TEST_NO_RESERVE reaches the checks after the MPI-IO writes)
  mnt=$(mktemp -d "$d/disk.XXXXXX")
  if ! mount -t tmpfs -o size=2m tmpfs "$mnt" 2>"$d/mount.err"; then
    echo "SKIP: cannot mount a 2 MB tmpfs for the full-disk case: $(cat "$d/mount.err")"
    rmdir "$mnt"; exit 77
  fi
  trap 'umount "$mnt"; rmdir "$mnt"' EXIT
  "$jetfit" generate torus -o "$d/torus.ply" --n 30000 --seed 3 || bad "jetfit generate"
  for np in 1 3; do for ext in ply csv; do for reserve in 0 1; do
    echo old >"$mnt/keep.$ext"
    JETFIT_MPI_TEST_NO_RESERVE=$reserve
    [ $reserve = 1 ] && export JETFIT_MPI_TEST_NO_RESERVE || unset JETFIT_MPI_TEST_NO_RESERVE
    mpirun --allow-run-as-root --oversubscribe -q $( [ $reserve = 1 ] && echo -x JETFIT_MPI_TEST_NO_RESERVE) \
      -np $np "$jmpi" estimate "$d/torus.ply" -o "$mnt/keep.$ext" --quiet --neighbors knn:12 \
      2>"$d/stderr" >/dev/null; rc=$?
    unset JETFIT_MPI_TEST_NO_RESERVE
    # Open MPI's own "mca_fbtl_posix_pwritev" lines are not ours to count
    ours=$(grep -c '^jetfit-mpi' "$d/stderr")
    what="np $np .$ext no-reserve=$reserve"
    if [ $rc -ne 1 ] || [ "$ours" -ne 1 ] || ! grep -q "keep.$ext" "$d/stderr"; then
      bad "$what: expected exit 1 and one line naming keep.$ext, got exit $rc:"; cat "$d/stderr"
    elif [ "$(cat "$mnt/keep.$ext")" != old ]; then bad "$what: the old output was changed"
    elif [ "$(ls -A "$mnt" | grep -vc '^keep\.')" -ne 0 ]; then bad "$what: left $(ls -A "$mnt")"
    else echo "ok   $what: $(grep '^jetfit-mpi' "$d/stderr")"; fi
  done; done; done
  ;;
*) echo "unknown mode $mode"; exit 2 ;;
esac
[ $fail -eq 0 ] && echo "test_mpi $mode: all passed"
exit $fail
