"""setup.py -- builds the extension jetfit._jetfit with the project's own
CMake build (python/CMakeLists.txt: the library's objects, the CGAL bridge
and the OpenMP runtime the module links), for the interpreter running pip,
then lets setuptools package it with python/jetfit/.  pyproject.toml holds
the metadata."""
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

TOP = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(TOP, "CMakeLists.txt"), encoding="utf-8") as f:
        return re.search(r"project\(jetfit VERSION ([0-9.]+)", f.read()).group(1)


class CMakeBuild(build_ext):
    """One extension, built by CMake's target jetfit_python."""

    def build_extension(self, ext):
        tmp = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        os.makedirs(tmp, exist_ok=True)
        cfg = ["cmake", "-S", TOP, "-B", tmp, "-DCMAKE_BUILD_TYPE=Release",
               "-DJF_TESTS=OFF", "-DJF_BENCH=OFF", "-DJF_PYTHON=ON",
               "-DPython3_EXECUTABLE=" + sys.executable]
        subprocess.run(cfg, check=True)
        jobs = str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", tmp, "--target", "jetfit_python", "-j", jobs],
                       check=True)
        built = os.path.join(tmp, "python", "jetfit",
                             "_jetfit" + sysconfig.get_config_var("EXT_SUFFIX"))
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copyfile(built, dest)


setup(version=version(), ext_modules=[Extension("jetfit._jetfit", sources=[])],
      cmdclass={"build_ext": CMakeBuild})
