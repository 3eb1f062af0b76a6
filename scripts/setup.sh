#!/usr/bin/env bash
# Installs what fiberlab needs from Debian's packages (only those missing),
# then configures and builds it in ./build. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config ccache
  libeigen3-dev libhdf5-dev libdeflate-dev libyaml-cpp-dev libcli11-dev libfmt-dev libxsimd-dev
  googletest libgtest-dev libbenchmark-dev libboost-dev libboost-math-dev
  python3 python3-dev python3-h5py python3-numpy python3-matplotlib python3-yaml
  pybind11-dev python3-pybind11 python3-pytest python3-pandas
  python3-xarray python3-nbclient python3-nbformat python3-ipykernel
  python3-setuptools python3-pip python3-venv
  libopenmpi-dev openmpi-bin
  chromium                  # renders report.html in python/tests/test_report_html.py (skipped without it)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi

build_dir=${FIBERLAB_BUILD_DIR:-build}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
