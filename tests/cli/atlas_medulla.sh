#!/usr/bin/env bash
# `fiberlab atlas` sweeping fibers with and without a medulla, two channels:
# a medulla adds the lobe `scattered` (docs/FUR.md), so the file's lobe axis
# is the longest of any fiber (lobe_names ends with `scattered`) and a fiber
# without a medulla has NaN there. Checked in both sweep orders (medulla
# last and first): exit 0, the shapes, the NaN slots, and each fiber's
# simulated energies equal in both files (the order of a sweep changes
# nothing of a fiber); the energies of a fiber's lobes add up to at most 1.
set -uo pipefail
fiberlab=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots: their numbers are what is checked
for order in "none, {radius: 0.5, sigma_s: 3}" "{radius: 0.5, sigma_s: 3}, none"; do
  name=$([[ $order == none* ]] && echo last || echo first)
  cat >"$work/$name.yaml" <<YAML
photons: 3000
seed: 3
tally: {n_theta: 12, n_phi: 18, lobes: 4}
models: [exact]
sweep:
  roughness: [{model: gaussian, beta_long: 5}]
  theta_i: [30]
  absorption: [{sigma_a: [0.3, 0.05]}]
  medulla: [$order]
YAML
  if ! "$fiberlab" atlas "$work/$name.yaml" -o "$work/$name.h5" --threads 2 --report "$work/$name.report" \
      >"$work/$name.out" 2>&1; then
    echo "FAIL: atlas with the medulla $name exited $?"; tail -5 "$work/$name.out"; exit 1
  fi
done
/usr/bin/python3 - "$work/last.h5" "$work/first.h5" <<'PY'
import sys, h5py, numpy as np
last, first = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
ok = True
def check(cond, what):
    global ok
    if not cond:
        print("FAIL:", what); ok = False
for f, medulla_index in ((last, 1), (first, 0)):
    names = f.attrs["lobe_names"]
    names = names.decode() if isinstance(names, bytes) else str(names)
    check(names == "R,TT,TRT,p>=3,scattered", f"lobe_names {names}")
    e = f["fibers/sim_energy"][()]
    check(e.shape == (2, 1, 5, 2), f"sim_energy shape {e.shape}")
    plain = 1 - medulla_index
    check(np.all(np.isnan(e[plain, :, 4, :])), "the fiber without a medulla has NaN in `scattered`")
    check(np.all(np.isfinite(e[medulla_index])), "the medullated fiber has every lobe")
    check(np.all(np.isfinite(e[plain, :, :4, :])), "the plain fiber has its four lobes")
    check(np.all(np.nansum(e, axis=2) <= 1 + 1e-12), "lobe energies add up to at most 1")
e_last, e_first = last["fibers/sim_energy"][()], first["fibers/sim_energy"][()]
check(np.array_equal(e_last[[1, 0]], e_first, equal_nan=True), "each fiber's energies independent of the order")
sys.exit(0 if ok else 1)
PY
