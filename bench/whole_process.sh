#!/bin/bash
# Whole-process speed of `fiberlab run`: start-up,
# tallies, tracing, adding up and writing the HDF5 file, in photons per
# second per core, for the bench/configs cases.
#
#   bench/whole_process.sh [--build DIR] [--runs N] [--threads T] [CASE ...]
#
# For each case (default: b c) it prints
#   - the config's own run (its `photons`): the median wall time of N runs and
#     photons / (wall x threads);
#   - the slope from 4 M to 16 M photons: 12 M photons over the difference of
#     the two medians, per thread: the tracing rate without the fixed part;
# and, before and after, bench_sim's one-thread rate on case c, a copy per
# thread at once, as a check of the machine's speed at the time
# (machine_check below).
# The design targets (3.8 M/s per core for case b, 11 for case c) hold on
# machines with AVX-512; the script says which vector instructions this
# machine has, since rates on AVX2-only machines are about half.
# Wall times come from bash's EPOCHREALTIME (microseconds, read without
# starting a process) around each run: the run's own start-up (fork, exec,
# about 3 ms on these VMs) counts, a timer's does not (no `date` process
# per reading). The result files go to
# a temporary directory, removed at the end. Use an otherwise idle machine:
# the medians damp, not remove, other jobs' noise.
set -euo pipefail
[ -n "${EPOCHREALTIME:-}" ] || { echo "bench/whole_process.sh: needs bash 5 or later (EPOCHREALTIME)" >&2; exit 2; }

root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build"
runs=5
threads=2
cases=()
usage() {
  echo "usage: bench/whole_process.sh [--build DIR] [--runs N>=1] [--threads T>=1] [a|b|c ...]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --build) [ $# -ge 2 ] || usage; build="$2"; shift 2 ;;
    --runs) [ $# -ge 2 ] && [[ "$2" =~ ^[1-9][0-9]*$ ]] || usage; runs="$2"; shift 2 ;;
    --threads) [ $# -ge 2 ] && [[ "$2" =~ ^[1-9][0-9]*$ ]] || usage; threads="$2"; shift 2 ;;
    a|b|c) cases+=("$1"); shift ;;
    *) usage ;;
  esac
done
[ ${#cases[@]} -gt 0 ] || cases=(b c)
fiberlab="$build/cli/fiberlab"
if [ ! -x "$fiberlab" ]; then
  echo "bench/whole_process.sh: $fiberlab not found: build first (cmake --build $build --target fiberlab)" >&2
  exit 2
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Median wall seconds of `runs` runs of case $1 with photons $2 ("" = the config's).
median_wall() {
  local config="$root/bench/configs/case_$1.yaml" photons="$2" times=() i t0 t1
  local extra=()
  [ -n "$photons" ] && extra=(--photons "$photons")
  for ((i = 0; i < runs; ++i)); do
    t0=$EPOCHREALTIME
    "$fiberlab" run "$config" --threads "$threads" --quiet --output "$work/out.h5" "${extra[@]}"
    t1=$EPOCHREALTIME
    rm -f "$work/out.h5"
    times+=("$(( ${t1/[.,]/} - ${t0/[.,]/} ))")  # microseconds (either decimal sign)
  done
  printf '%s\n' "${times[@]}" | sort -n | awk '{t[NR] = $1} END {
    m = (NR % 2) ? t[(NR + 1) / 2] : (t[NR / 2] + t[NR / 2 + 1]) / 2; printf "%.4f\n", m / 1e6 }'
}

config_photons() {
  awk '$1 == "photons:" {print $2}' "$root/bench/configs/case_$1.yaml"
}

# The machine's own speed at the time (these VMs' hosts slow them by up to a
# fifth for minutes at a time, sometimes one core and not the other):
# bench_sim's one-thread tracing rate of case c, one copy per thread run at
# once (pinned to cores 0, 1, ... where taskset exists), before and after
# the runs, when bench_sim is built. On a quiet AVX-512 machine of the
# kind docs/PERFORMANCE.md describes each reads about 17 M photons/s;
# markedly less means the times below are slow too.
machine_check() {
  local bench="$build/bench/bench_sim" i rates=()
  [ -x "$bench" ] || return 0
  local copies=$threads
  [ "$copies" -gt "$(nproc)" ] && copies=$(nproc)
  for ((i = 0; i < copies; ++i)); do
    local pin=()
    command -v taskset >/dev/null && pin=(taskset -c "$i")
    "${pin[@]}" "$bench" --benchmark_filter='^trace/c_rough' --benchmark_min_time=1 \
      >"$work/check_$i" 2>/dev/null &
  done
  wait
  for ((i = 0; i < copies; ++i)); do
    rates+=("$(grep -o 'photons_per_s=[0-9.]*M' "$work/check_$i" | head -1 | tr -dc '0-9.')")
  done
  echo "machine check ($1): bench_sim case c, $copies copies at once, M photons/s each: ${rates[*]}"
}

simd="AVX2 or less"
grep -qw avx512f /proc/cpuinfo && simd="AVX-512"
echo "machine: $(nproc) cores, $simd; $threads threads, medians of $runs runs"
echo "design targets (AVX-512 machines): case b 3.8, case c 11 M photons/s per core"
machine_check before
for c in "${cases[@]}"; do
  n=$(config_photons "$c")
  t=$(median_wall "$c" "")
  t4=$(median_wall "$c" 4000000)
  t16=$(median_wall "$c" 16000000)
  awk -v c="$c" -v n="$n" -v t="$t" -v t4="$t4" -v t16="$t16" -v k="$threads" 'BEGIN {
    printf "case %s: config (%d photons) %.3f s, %.2f M photons/s per core; ", c, n, t, n / t / k / 1e6
    if (t16 > t4) printf "slope 4 M -> 16 M %.2f M/s per core (4 M %.3f s, 16 M %.3f s)\n",
                         12e6 / (t16 - t4) / k / 1e6, t4, t16
    else printf "slope undefined (4 M %.3f s, 16 M %.3f s)\n", t4, t16
  }'
done
machine_check after
