"""`pip install --no-build-isolation --no-index .` installs the module into a
venv made with --system-site-packages (Debian's numpy, h5py, setuptools;
nothing downloaded) and `import fiberlab` then works outside the source and
build trees. The venv installs the extension of this build
(FIBERLAB_BUILD_DIR, FIBERLAB_REUSE_BUILD: setup.py skips CMake), from a
copy of the packaging files and python/ (the source tree stays untouched)."""
import os
import shutil
import subprocess
import sys

import pytest


def test_pip_installs_an_importable_module(source_dir, tmp_path):
    import fiberlab
    build_dir = os.path.dirname(os.path.dirname(os.path.abspath(fiberlab._fiberlab.__file__)))
    build_dir = os.path.dirname(build_dir)  # build/python/fiberlab/_fiberlab*.so -> build
    if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
        pytest.skip("not run from a CMake build (fiberlab imported from %s)" % fiberlab.__file__)
    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "setup.py", "CMakeLists.txt"):
        shutil.copy(os.path.join(source_dir, name), src / name)
    shutil.copytree(os.path.join(source_dir, "python", "fiberlab"), src / "python" / "fiberlab",
                    ignore=shutil.ignore_patterns("__pycache__"))
    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)], check=True,
                   timeout=120)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(FIBERLAB_BUILD_DIR=build_dir, FIBERLAB_REUSE_BUILD="1", PIP_NO_INDEX="1")
    out = subprocess.run([str(venv / "bin" / "pip"), "install", "--no-build-isolation", "--no-index", str(src)],
                         capture_output=True, text=True, env=env, timeout=300, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    check = ("import fiberlab, numpy; print(fiberlab.__file__); "
             "r = fiberlab.run({'source': {'theta_i': [30]}, 'tally': {'n_theta': 9, 'n_phi': 12}}, "
             "photons=1000, seed=1, progress=False); print(r.mean.shape, fiberlab.__version__)")
    out = subprocess.run([str(venv / "bin" / "python"), "-c", check], capture_output=True, text=True, env=env,
                         timeout=120, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    where, shape = out.stdout.splitlines()
    assert where.startswith(str(venv)), where
    assert shape.startswith("(1, ")
