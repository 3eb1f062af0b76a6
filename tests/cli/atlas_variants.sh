#!/usr/bin/env bash
# `fiberlab atlas` with model variants (the same registered model under
# several names, each with its own fixed parameters) through the program.
# 1. configs/atlas_variants.yaml runs (fewer photons): its variant is named
#    in the file, the report and `fiberlab info`.
# 2. Oracles on one fiber: a variant with no parameters of its own is its
#    model, so its energies, fits and parameters equal the model's bit for
#    bit; chiang2016 with mp: pbrt_v4 differs from exact M_p (pbrt-v4's M_p
#    numerics differ by up to 1.3% in lobe energy: docs/MODELS.md) but by
#    less than 5%.
# 3. Bad variant entries: exit 2, one line naming the field, nothing written.
set -uo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots: their numbers are what is checked
fail=0

if ! "$fiberlab" atlas "$source_dir/configs/atlas_variants.yaml" -o "$work/v.h5" --photons 20000 --threads 2 --quiet \
     >"$work/out" 2>"$work/err"; then
  echo "FAIL: atlas configs/atlas_variants.yaml exited $?"; cat "$work/out" "$work/err"; exit 1
fi
grep -q "| chiang2016_pbrt | 2 | TT |" "$work/v_report/report.md" || { echo "FAIL: no chiang2016_pbrt row in report.md"; fail=1; }
grep -q "chiang2016_pbrt (chiang2016): mp=pbrt_v4" "$work/v_report/report.md" \
  || { echo "FAIL: report.md does not name the variant's parameters"; fail=1; }
"$fiberlab" info "$work/v.h5" >"$work/info" 2>&1
grep -q "model chiang2016_pbrt (chiang2016 mp=pbrt_v4): applicable to 2" "$work/info" \
  || { echo "FAIL: fiberlab info does not describe the variant"; cat "$work/info"; fail=1; }

cat >"$work/a.yaml" <<'YAML'
photons: 50000
seed: 2
tally: {n_theta: 18, n_phi: 24, lobes: 4}
sweep:
  roughness: [{model: gaussian, beta_long: 6}]
  absorption: [{sigma_a: 0.2}]
  scale_tilt: [2]
  theta_i: [30]
models:
  - {name: chiang2016_pbrt, model: chiang2016, parameters: {mp: pbrt_v4}}
  - chiang2016
  - {name: chiang2016_same, model: chiang2016}
fit: {max_iterations: 8}
YAML
if ! "$fiberlab" atlas "$work/a.yaml" -o "$work/a.h5" --threads 2 --quiet >"$work/out" 2>"$work/err"; then
  echo "FAIL: atlas exited $?"; cat "$work/out" "$work/err"; exit 1
fi
/usr/bin/python3 - "$work/a.h5" <<'PY' || fail=1
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1], "r")
text = lambda x: x.decode() if isinstance(x, bytes) else x
# A model's variants follow it, in the config's order.
assert text(f.attrs["models"]) == "chiang2016,chiang2016_pbrt,chiang2016_same", f.attrs["models"]
base, same, pbrt = f["models/chiang2016"], f["models/chiang2016_same"], f["models/chiang2016_pbrt"]
assert "model" not in base.attrs
assert text(pbrt.attrs["model"]) == "chiang2016" and text(pbrt.attrs["fixed_parameters"]) == "mp=pbrt_v4"
assert text(same.attrs["model"]) == "chiang2016" and text(same.attrs["fixed_parameters"]) == ""
for name in base:
    if name == "seconds":
        continue
    a, b = base[name][...], same[name][...]
    assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), name
for key in ("params_before", "params_after", "fit_keys"):
    assert base.attrs[key] == same.attrs[key], key
assert "mp=pbrt_v4" in text(pbrt.attrs["params_before"]), pbrt.attrs["params_before"]
assert "mp=pbrt_v4" not in text(base.attrs["params_before"]), base.attrs["params_before"]
e0, e1 = base["model_energy_before"][...], pbrt["model_energy_before"][...]
rel = np.abs(e1 - e0)[e0 > 1e-3] / e0[e0 > 1e-3]
print("chiang2016 pbrt_v4 / exact M_p, largest relative lobe energy difference:", rel.max())
assert 0 < rel.max() < 0.05, rel
print("ok: a variant without parameters is its model; pbrt_v4 M_p differs, slightly")
PY

bad() {  # bad DESCRIPTION PATTERN YAML: exit 2, one line matching PATTERN, no output
  local what=$1 pattern=$2
  printf '%s\n' "$3" >"$work/bad.yaml"
  rm -rf "$work/b.h5" "$work/b_report"
  "$fiberlab" atlas "$work/bad.yaml" -o "$work/b.h5" >"$work/out" 2>"$work/err"
  local got=$?
  if [ "$got" != 2 ] || [ "$(wc -l <"$work/err")" != 1 ] || ! grep -q -- "$pattern" "$work/err" \
     || [ -e "$work/b.h5" ] || [ -e "$work/b_report" ]; then
    echo "FAIL ($what): exit $got"; cat "$work/err"; fail=1
  else
    echo "ok ($what): $(cat "$work/err")"
  fi
}
base='photons: 1000
tally: {n_theta: 9, n_phi: 12}
sweep: {roughness: [{model: smooth}], theta_i: [10]}'
bad "variant without a name" "models\[1\].name = (nothing)" "$base
models: [chiang2016, {model: chiang2016, parameters: {mp: pbrt_v4}}]"
bad "variant named like a model" "models\[0\].name = deon2011 is a registered model's name" "$base
models: [{name: deon2011, model: chiang2016}]"
bad "variant name with a comma" "models\[0\].name = a,b must be" "$base
models: [{name: 'a,b', model: chiang2016}]"
bad "two variants of one name" "models\[1\].name = v is already an entry" "$base
models: [{name: v, model: chiang2016}, {name: v, model: deon2011}]"
bad "variant of an unknown model" "models\[0\].model = chiang2017 is not a registered model" "$base
models: [{name: v, model: chiang2017}]"
bad "unknown key of a variant" "unknown key models\[0\].params" "$base
models: [{name: v, model: chiang2016, params: {mp: pbrt_v4}}]"
bad "variant parameter value" "models\[0\].parameters.mp = pbrt_v5 is not allowed" "$base
models: [{name: v, model: chiang2016, parameters: {mp: pbrt_v5}}]"
bad "variant free parameter" "models\[0\].parameters.beta_m is a free parameter" "$base
models: [{name: v, model: chiang2016, parameters: {beta_m: 0.2}}]"
bad "variant parameters not a mapping" "models\[0\].parameters = \[1\] must be a mapping" "$base
models: [{name: v, model: chiang2016, parameters: [1]}]"
exit $fail
