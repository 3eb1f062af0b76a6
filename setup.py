"""Builds the Python module `fiberlab` for pip (pyproject.toml).

The compiled extension _fiberlab comes from the project's CMake build
(python/CMakeLists.txt): setup.py configures the source tree into
FIBERLAB_BUILD_DIR (default: build/, the folder scripts/setup.sh uses; an
existing build is reused and only brought up to date) and builds the target
_fiberlab, then installs it beside the pure-Python package python/fiberlab.
Needs what scripts/setup.sh installs (Debian packages only); nothing is
downloaded.
"""
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(HERE, "CMakeLists.txt")) as f:
        return re.search(r"project\(fiberlab VERSION ([0-9.]+)", f.read()).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Runs CMake instead of compiling sources itself, then copies the built
    extension to where setuptools installs it from."""

    def build_extension(self, ext):
        build_dir = os.path.abspath(os.environ.get("FIBERLAB_BUILD_DIR", os.path.join(HERE, "build")))
        built = self._built_extension(build_dir)
        if built is None or not os.environ.get("FIBERLAB_REUSE_BUILD"):
            configure = ["cmake", "-S", HERE, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release"]
            # A new build is made for this interpreter; an existing one keeps its
            # own (a venv's python has the same extension suffix as the Python
            # it was made from, which is all that must match: checked below).
            if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
                configure.append("-DPython_EXECUTABLE=" + sys.executable)
            subprocess.check_call(configure)
            jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
            subprocess.check_call(["cmake", "--build", build_dir, "--target", "_fiberlab", "-j", jobs])
            built = self._built_extension(build_dir)
        if built is None:
            raise RuntimeError("no _fiberlab%s in %s/python/fiberlab: pybind11-dev or python3-dev missing "
                               "(scripts/setup.sh), or that build is for another Python (set "
                               "FIBERLAB_BUILD_DIR to a new folder)"
                               % (sysconfig.get_config_var("EXT_SUFFIX"), build_dir))
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)

    @staticmethod
    def _built_extension(build_dir):
        folder = os.path.join(build_dir, "python", "fiberlab")
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        path = os.path.join(folder, "_fiberlab" + suffix)
        return path if os.path.exists(path) else None


setup(
    version=version(),
    packages=["fiberlab"],
    package_dir={"fiberlab": "python/fiberlab"},
    ext_modules=[CMakeExtension("fiberlab._fiberlab")],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    # setuptools' own scratch space, inside the CMake build folder (ignored by git).
    options={"build": {"build_base": os.path.join("build", "setuptools")},
             "egg_info": {"egg_base": os.path.join("build", "setuptools")}},
)
