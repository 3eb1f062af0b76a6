#!/usr/bin/env bash
# huang2022 as Cycles' eval() computes it (`form: cycles_eval`) as an atlas
# variant beside the paper's form with Cycles' masking and residual, on a
# tilted fiber at theta_i 60 deg:
# - the variant is named in the file, the report and `fiberlab info`;
# - oracle: the two differ only in the transport of the inner chords, the
#   exit tests and Cycles' clamp of the impact parameter to |h| <= 0.999,
#   which removes nothing here (with tilt 3 and theta_i 60 the mesonormal
#   faces away from the light beyond |h| = 0.996 already). So the p >= 3
#   energies (Cycles' eval residual, computed from the entry and the second
#   interface) are equal bit for bit, R (exit tests only) within 1e-3, and TT
#   and TRT higher by the cosine ratios (2-30%; tests/analytic/
#   test_huang2022.cpp has the closed forms).
set -uo pipefail
fiberlab=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots: their numbers are what is checked
fail=0

cat >"$work/c.yaml" <<'YAML'
photons: 50000
seed: 3
tally: {n_theta: 18, n_phi: 24, lobes: 4}
sweep:
  roughness: [{model: ggx, alpha: 0.2}]
  absorption: [{sigma_a: 0.2}]
  scale_tilt: [3]
  theta_i: [60]
models:
  - {name: huang2022_parts, model: huang2022, parameters: {masking: correlated, residual: cycles_eval}}
  - {name: huang2022_cycles, model: huang2022, parameters: {form: cycles_eval}}
model_parameters:
  huang2022: {quadrature_points: 65536}
fit: {max_iterations: 2}
YAML
if ! "$fiberlab" atlas "$work/c.yaml" -o "$work/c.h5" --threads 2 --quiet >"$work/out" 2>"$work/err"; then
  echo "FAIL: atlas exited $?"; cat "$work/out" "$work/err"; exit 1
fi
grep -q "| huang2022_cycles | 1 | TT |" "$work/c_report/report.md" || { echo "FAIL: no huang2022_cycles row"; fail=1; }
"$fiberlab" info "$work/c.h5" >"$work/info" 2>&1
grep -q "model huang2022_cycles (huang2022 quadrature_points=65536 form=cycles_eval)" "$work/info" \
  || { echo "FAIL: fiberlab info does not describe the variant"; cat "$work/info"; fail=1; }
/usr/bin/python3 - "$work/c.h5" <<'PY' || fail=1
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1], "r")
text = lambda x: x.decode() if isinstance(x, bytes) else x
parts, cycles = f["models/huang2022_parts"], f["models/huang2022_cycles"]
assert "masking=correlated" in text(cycles.attrs["params_before"]), cycles.attrs["params_before"]
assert "residual=cycles_eval" in text(cycles.attrs["params_before"]), cycles.attrs["params_before"]
a, b = parts["model_energy_before"][0, 0, :, 0], cycles["model_energy_before"][0, 0, :, 0]
print("lobe energies, paper form with Cycles' masking and residual:", a)
print("lobe energies, form=cycles_eval:                            ", b)
assert a[3] == b[3], ("p >= 3", a[3], b[3])
assert abs(b[0] / a[0] - 1) < 1e-3, ("R", a[0], b[0])
for lobe, name in ((1, "TT"), (2, "TRT")):
    assert 1.02 < b[lobe] / a[lobe] < 1.3, (name, a[lobe], b[lobe])
print("ok: form=cycles_eval changes TT and TRT only, by the inner cosine ratios")
PY
exit $fail
