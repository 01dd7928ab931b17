#!/bin/sh
# test_pip.sh SRC JETFIT -- `pip install --no-build-isolation .` (pyproject.toml,
# setup.py) into a throwaway venv that sees Debian's numpy and setuptools
# (--system-site-packages), offline (--no-index); the installed module must
# give the command's bytes.  Skipped (77) without pip, venv or numpy.
set -eu
src=$1; jetfit=$2
py=/usr/bin/python3
[ -x "$py" ] || py=$(command -v python3)
"$py" -c 'import setuptools, pip, venv, numpy' 2>/dev/null || {
  echo "skipped: needs python3-pip, python3-venv, python3-numpy, python3-setuptools"; exit 77; }
tmp=$(mktemp -d /tmp/jf-pip.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "test_pip: $*"; exit 1; }
# a copy of the tree: the build leaves setuptools' files (build/, *.egg-info) beside the sources
mkdir "$tmp/src"
(cd "$src" && git ls-files -z 2>/dev/null | xargs -0 cp --parents -t "$tmp/src" 2>/dev/null) ||
  cp -r "$src/." "$tmp/src"
rm -rf "$tmp/src/build"
"$py" -m venv --system-site-packages "$tmp/venv" || fail "venv failed"
"$tmp/venv/bin/pip" install --no-build-isolation --no-index "$tmp/src" >"$tmp/pip.log" 2>&1 ||
  { tail -30 "$tmp/pip.log"; fail "pip install failed"; }
"$jetfit" generate torus --n 3000 --seed 5 -o "$tmp/t.xyz"
"$jetfit" estimate "$tmp/t.xyz" -o "$tmp/cmd.csv" --neighbors knn:12 --quiet
cd "$tmp" # not the source tree: the installed module must be the one imported
"$tmp/venv/bin/python" - "$tmp" <<'PY' || fail "the installed module"
import sys, jetfit
tmp = sys.argv[1]
assert jetfit.__file__.startswith(tmp + "/venv/"), jetfit.__file__
pts = jetfit.read(tmp + "/t.xyz")[0]
jetfit.write(tmp + "/py.csv", jetfit.estimate(pts, neighbors="knn:12"), points=pts)
assert open(tmp + "/py.csv", "rb").read() == open(tmp + "/cmd.csv", "rb").read(), "bytes differ"
print("test_pip: installed", jetfit.__version__, "at", jetfit.__file__, "- the command's bytes")
PY
