#!/usr/bin/env bash
# The sanitizer job: a second build in ./build-asan with
# AddressSanitizer and UndefinedBehaviorSanitizer (float-cast-overflow
# included), running the test subset labelled "sanitize" (tests/sim and
# tests/robustness: the simulator, the settings, the command line and the
# hostile-input corpus) with the sanitized `fiberlab`. Any report fails the run.
# The build targets x86-64-v3 (AVX2: 4 lanes of doubles), not the machine's
# AVX-512 (8 lanes) the Release build uses, so the batched photon life's
# 4-lane path is tested too: the batched-against-scalar equivalence, the
# lane trigonometry and exit bins, and bit-identity across thread counts run
# here (a lane-width bug, e.g. finished-lane flags read 8 at a time, shows
# only in a 4-lane build).
# Assumes scripts/setup.sh has installed the packages (scripts/test.sh runs it).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
flags="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer"
arch="-march=x86-64-v3"
start=$(date +%s)
cmake -S "$root" -B "$root/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS="$flags $arch" -DFIBERLAB_NATIVE=OFF \
  -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" \
  -DFIBERLAB_BUILD_BENCH=OFF >/dev/null
cmake --build "$root/build-asan" -j"$(nproc)" --target fiberlab test_sim test_robustness
built=$(date +%s)
# Leak checking is off: HDF5's exit-time cleanup is turned off on purpose
# (common/h5_file.h, prepare_hdf5), so its library state is still allocated at exit.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=0:halt_on_error=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
cd "$root/build-asan"
# The physics tests (minutes each under ASan) are left to the normal build:
# here the hostile inputs, signals, command line and settings, and the
# lane-width tests (seconds each).
ctest --output-on-failure -j"$(nproc)" -L sanitize \
  -R "Hostile|Interrupt|Cli\.|Settings\.|BatchTracer\.|LifeTrig\.|ExitBins\.|Reproducibility\." "$@"
echo "sanitizer job: build $((built - start)) s, tests $(( $(date +%s) - built )) s"
