#!/bin/sh
# test_install.sh SRC BUILD -- libjetfit as another program sees it:
# `cmake --install` into a temporary prefix, then examples/normals.c built
# against the installed package twice (pkg-config on a plain cc line, and
# CMake's find_package(jetfit)); both must run on the bundled scan and print
# the same first normal and curvatures as `jetfit estimate` writes.  Also:
# the static library through jetfit-static.pc (no libjetfit.so needed), and
# a program built without rpath, run under LD_LIBRARY_PATH (docs/library.md).
# Skipped (77) in a sanitizer build: its libjetfit needs the ASan runtime
# loaded first, which a plain cc program does not do.
set -eu
src=$1; build=$2
if grep -q '^JF_SANITIZE:BOOL=ON' "$build/CMakeCache.txt"; then
  echo "skipped: sanitizer build (an uninstrumented program cannot load an ASan libjetfit)"; exit 77
fi
tmp=$(mktemp -d /tmp/jf-install.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "test_install: $*"; exit 1; }
cmake --install "$build" --prefix "$tmp/p" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; fail "cmake --install failed"; }
p=$tmp/p
[ -x "$p/bin/jetfit" ] || fail "bin/jetfit not installed"
[ -f "$p/include/jetfit.h" ] || fail "include/jetfit.h not installed"
[ ! -e "$p/include/cgal_bridge.h" ] || fail "cgal_bridge.h must not be installed"
[ -f "$p/share/man/man1/jetfit.1" ] || fail "man page not installed"
pc=$(find "$p" -name jetfit.pc | head -1); [ -n "$pc" ] || fail "jetfit.pc not installed"
lib=$(find "$p" -name 'libjetfit.so.*.*' | head -1); [ -n "$lib" ] || fail "libjetfit.so not installed"
soname=$(objdump -p "$lib" | awk '/SONAME/ {print $2}')
[ "$soname" = "libjetfit.so.0" ] || fail "soname is '$soname', expected libjetfit.so.0"
# only the public API is exported: no CGAL, GSL or bridge symbol
bad=$(nm -D --defined-only "$lib" | awk '$2 ~ /[TDBRW]/ && $3 !~ /^jf_/ {print $3}' | head -5)
[ -z "$bad" ] || fail "libjetfit exports non-jf_ symbols: $bad"

ex=$src/examples
libdir=$(dirname "$lib")
# 1. pkg-config on a plain cc command line
PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --exists jetfit || fail "pkg-config cannot find jetfit"
cc "$ex/normals.c" $(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --cflags --libs jetfit) -lm \
   -Wl,-rpath,"$libdir" -o "$tmp/normals-pc" || fail "build with pkg-config failed"
# 2. find_package(jetfit) from a separate CMake project
cmake -S "$ex" -B "$tmp/b" -DCMAKE_PREFIX_PATH="$p" -DCMAKE_BUILD_RPATH="$libdir" >"$tmp/cm.log" 2>&1 \
  || { cat "$tmp/cm.log"; fail "find_package(jetfit) configure failed"; }
cmake --build "$tmp/b" >"$tmp/cb.log" 2>&1 || { cat "$tmp/cb.log"; fail "find_package build failed"; }

# 3. the static library (JF_STATIC_LIB): no libjetfit.so needed at run time,
# through jetfit-static.pc as docs/library.md says (jetfit.pc's -ljetfit
# would take the shared library)
if [ -f "$libdir/libjetfit.a" ]; then
  cc "$ex/normals.c" $(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --cflags --libs jetfit-static) \
     -o "$tmp/normals-static" || fail "build with pkg-config jetfit-static failed"
  ldd "$tmp/normals-static" | grep -q libjetfit && fail "the static build needs libjetfit.so"
fi
# 4. a custom prefix without an rpath: the loader does not look in P/lib;
# LD_LIBRARY_PATH (docs/library.md) or -Wl,-rpath (above) finds it
cc "$ex/normals.c" $(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --cflags --libs jetfit) \
   -o "$tmp/normals-norpath" || fail "build without rpath failed"
if env -u LD_LIBRARY_PATH "$tmp/normals-norpath" "$src/data/bun090.ply" >/dev/null 2>&1; then
  ldd "$tmp/normals-norpath" | grep -q "libjetfit.so.0 => $libdir" ||
    echo "note: libjetfit.so.0 found elsewhere than $libdir (a system-wide install?)"
fi
LD_LIBRARY_PATH=$libdir "$tmp/normals-norpath" "$src/data/bun090.ply" >"$tmp/ld.out" ||
  fail "LD_LIBRARY_PATH=$libdir did not make the program run"

scan=$src/data/bun090.ply
"$tmp/normals-pc" "$scan" >"$tmp/pc.out" || fail "normals (pkg-config) failed"
"$tmp/b/normals" "$scan" >"$tmp/cm.out" || fail "normals (find_package) failed"
cmp -s "$tmp/pc.out" "$tmp/cm.out" || fail "the two builds disagree"
cmp -s "$tmp/pc.out" "$tmp/ld.out" || fail "the LD_LIBRARY_PATH run disagrees"
if [ -x "$tmp/normals-static" ]; then
  "$tmp/normals-static" "$scan" >"$tmp/st.out" || fail "normals (static) failed"
  cmp -s "$tmp/pc.out" "$tmp/st.out" || fail "the static build disagrees"
fi
grep -q ': 30379 points, 30379 fitted$' "$tmp/pc.out" || { cat "$tmp/pc.out"; fail "wrong summary"; }
# the installed command's first row, formatted as the example prints it
"$p/bin/jetfit" estimate "$scan" -o "$tmp/r.csv" --quiet || fail "installed jetfit failed"
want=$(awk -F, 'NR == 2 { printf "point 0: normal %.6f %.6f %.6f  k1 %.6g  k2 %.6g\n", $4, $5, $6, $7, $8 }' "$tmp/r.csv")
got=$(sed -n 2p "$tmp/pc.out")
[ "$got" = "$want" ] || fail "library '$got' != command '$want'"
echo "test_install: installed, built with pkg-config, find_package and the static library, same numbers as the command"
