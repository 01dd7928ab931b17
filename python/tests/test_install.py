"""`cmake --install` puts the module in the prefix's site-packages: it
imports from there (not from the build tree) and gives the same bits."""
import os
import re
import subprocess
import sys

import pytest

from conftest import JETFIT_BIN

BUILD = os.path.dirname(os.path.abspath(JETFIT_BIN))
CACHE = os.path.join(BUILD, "CMakeCache.txt")


@pytest.mark.skipif(not os.path.exists(CACHE), reason="no CMake build beside $JETFIT_BIN")
def test_cmake_install_prefix(tmp_path):
    cache = open(CACHE).read()
    rel = re.search(r"^JF_PYTHON_INSTALL_DIR:\w+=(.*)$", cache, re.M).group(1)
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    site = tmp_path / rel
    assert (site / "jetfit" / "__init__.pyi").exists() and (site / "jetfit" / "py.typed").exists()
    code = ("import jetfit, numpy as np; p = np.random.default_rng(0).random((500, 3)); "
            "print(jetfit.__file__); "
            "print(jetfit.estimate(p, neighbors='knn:10').as_structured().tobytes().hex())")
    env = dict(os.environ, PYTHONPATH=str(site))
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True,
                         text=True, cwd=tmp_path).stdout.split()
    assert out[0].startswith(str(site))
    import jetfit
    import numpy as np
    p = np.random.default_rng(0).random((500, 3))
    assert out[1] == jetfit.estimate(p, neighbors="knn:10").as_structured().tobytes().hex()
