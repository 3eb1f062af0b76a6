#!/usr/bin/env bash
# `fiberlab atlas --resume` of a sweep with a medullated fiber and
# fit.per_lobe, through the real program. A medulla adds the lobe
# `scattered` after the tally's lobes (docs/FUR.md), so the medullated
# fiber's results have tally.lobes + 1 lobes and, fitted lobe by lobe over
# every lobe, one lobe fit more than the tally's lobe count. The checkpoint
# must give them back as written:
# 1. A reference run, uninterrupted; it must hold a per-lobe fit of the
#    medullated fiber's `scattered` lobe (else this test checks nothing).
# 2. For each sweep order (medulla first: the checkpoint holds the
#    medullated fiber; medulla last: the plain one): SIGINT once a fiber is
#    saved (exit 130, "1 of 2 fibers saved"), then --resume: the same
#    results as the uninterrupted run of that order, bit for bit
#    (tests/cli/atlas_same_results.py).
# 3. mpirun -np 2 (when installed; a fiber run on another rank comes back
#    through the checkpoint's reader): the same results as one process.
set -uo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
source "$source_dir/tests/cli/atlas_interrupt.sh"
same_results="$source_dir/tests/cli/atlas_same_results.py"
export FIBERLAB_PYTHON=/nonexistent/python3  # no plots: the report's numbers are the point
say_fail() { echo "FAIL: $*"; fail=1; }

for order in "{radius: 0.5, sigma_s: 3}, none" "none, {radius: 0.5, sigma_s: 3}"; do
  name=$([[ $order == none* ]] && echo last || echo first)
  # Enough photons that every lobe of both fibers has the bins a two-key
  # per-lobe fit needs (with fewer, p>=3's fit is refused for want of
  # residuals and the fiber has no lobe fits at all).
  cat >"$work/$name.yaml" <<YAML
photons: 100000
seed: 5
tally: {n_theta: 18, n_phi: 24, lobes: 4}
sweep:
  roughness: [{model: gaussian, beta_long: 6}]
  absorption: [{sigma_a: 0.05}]
  medulla: [$order]
  theta_i: [30]
models: [exact, marschner2003]
fit: {max_iterations: 8, per_lobe: true}
YAML
  if ! "$fiberlab" atlas "$work/$name.yaml" -o "$work/$name.h5" --threads 1 --quiet >"$work/$name.out" 2>&1; then
    echo "FAIL: atlas ($name) exited $?"; cat "$work/$name.out"; exit 1
  fi
  medulla_index=$([[ $name == first ]] && echo 0 || echo 1)
  /usr/bin/python3 - "$work/$name.h5" "$medulla_index" <<'PY' || say_fail "$name: the reference has no per-lobe fit of 'scattered'"
import sys, h5py
f, m = h5py.File(sys.argv[1], "r"), int(sys.argv[2])
names = f.attrs["lobe_names"]
names = names.decode() if isinstance(names, bytes) else str(names)
fitted = f["models/marschner2003/lobe_fitted"][...]
lines = f["models/marschner2003"].attrs["lobe_fit_lines"]
lines = (lines.decode() if isinstance(lines, bytes) else str(lines)).split("\n")
print(f"lobe_names {names}; marschner2003 lobe_fitted per fiber {fitted.tolist()}")
assert names.split(",")[-1] == "scattered", names
# Every lobe of the fiber has its per-lobe fit's line; marschner2003 predicts
# nothing in p>=3 and `scattered`, so those say "not fitted" (lobe_fitted 0).
assert len(lines) == 10 and all(lines[5 * m:5 * m + 5]) and all(lines[5 * (1 - m):5 * (1 - m) + 4]), lines
assert not lines[5 * (1 - m) + 4], lines
assert lines[5 * m + 4] == "not fitted: no free parameter acts on this lobe", lines
assert fitted.shape == (2, 5) and fitted[:, :3].all() and not fitted[:, 3:].any(), fitted
PY
  interrupt_atlas "$work/$name.yaml" "$name.res" INT "" --threads 1
  if [ "$got" != 130 ] || ! tail -n 1 "$work/$name.res.err" | grep -q ": 1 of 2 fibers saved in"; then
    say_fail "$name: SIGINT gave exit $got (want 130, one fiber saved)"; tail -n 2 "$work/$name.res.err"
  elif ! "$fiberlab" atlas --resume "$work/$name.res.checkpoint.h5" --threads 1 --quiet \
         >"$work/$name.res2.out" 2>"$work/$name.res2.err"; then
    say_fail "$name: the resume failed: $(cat "$work/$name.res2.err")"
  elif /usr/bin/python3 "$same_results" "$work/$name.h5" "$work/$name.res.h5"; then
    echo "ok ($name): medulla $name, interrupted after fiber 1 and resumed: the uninterrupted run's results"
  else
    say_fail "$name: the resumed results differ from the uninterrupted run's"
  fi
  if mpirun=$(command -v mpirun); then
    "$mpirun" --allow-run-as-root --oversubscribe -np 2 "$fiberlab" atlas "$work/$name.yaml" -o "$work/$name.two.h5" \
      --threads 1 --quiet >"$work/$name.two.out" 2>&1
    code=$?
    if [ "$code" != 0 ]; then
      say_fail "$name: mpirun -np 2 exited $code"; grep "error" "$work/$name.two.out"
    else
      /usr/bin/python3 "$same_results" "$work/$name.h5" "$work/$name.two.h5" \
        && echo "ok ($name): two ranks give one process's results" \
        || say_fail "$name: two ranks differ from one process"
    fi
  fi
done
[ -n "${mpirun:-}" ] || echo "mpirun not installed: the two-rank checks are skipped"
exit $fail
