#!/usr/bin/env bash
# fit.model_parameters: settings applied only while fitting (compare/
# atlas_config.h). huang2022 fitted at 4096 quadrature points, judged at
# 65536 (model_parameters). Oracles, from separate runs of the same fiber:
# - `fiberlab compare` of the simulated fiber with the fitted values at the
#   judging quadrature gives the atlas's "after fit" chi-square and energy
#   of every lobe; at the fitting quadrature it gives the fit's own
#   chi-square (fit_chi2) and a different after-fit chi-square;
# - the file's attributes and `fiberlab info` name both settings;
# - a fit-only setting of an unknown model or key, or of a key the fit
#   moves, is refused in one line naming the field, exit 2.
# Resume and mpirun with the key: tests/cli/atlas_mpi.sh.
set -uo pipefail
fiberlab=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
cd "$work" || exit 1
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots: their numbers are what is checked

cat >c.yaml <<'YAML'
photons: 40000
seed: 5
tally: {n_theta: 18, n_phi: 24, lobes: 4}
sweep:
  roughness: [{model: ggx, alpha: 0.2}]
  absorption: [{sigma_a: 0.2}]
  scale_tilt: [2]
  theta_i: [40]
models: [huang2022]
model_parameters:
  huang2022: {quadrature_points: 65536}
fit:
  max_iterations: 3
  model_parameters: {huang2022: {quadrature_points: 4096}}
YAML
# The same fiber as a simulator config (compare/atlas_config.cpp fiber_settings).
cat >s.yaml <<'YAML'
photons: 40000
seed: 5
output: s.h5
fiber: {eta: 1.55, eccentricity: 1, scale_tilt: 2, sigma_a: 0.2}
roughness: {model: ggx, alpha: 0.2}
source: {theta_i: [40], phi_i: 0}
tally: {n_theta: 18, n_phi: 24, lobes: 4}
YAML
"$fiberlab" atlas c.yaml -o c.h5 --threads 2 --quiet >out 2>err || { echo "FAIL: atlas exited $?"; cat out err; exit 1; }
"$fiberlab" run s.yaml --threads 2 --quiet >/dev/null 2>&1 || { echo "FAIL: run exited $?"; exit 1; }
read -r roughness tilt < <(/usr/bin/python3 -c "
import h5py
g = h5py.File('c.h5', 'r')['models/huang2022']
assert g.attrs['fit_keys'] in ('roughness,tilt', b'roughness,tilt'), g.attrs['fit_keys']
v = g['fit_value'][0]
print(repr(float(v[0])), repr(float(v[1])))")
for points in 65536 4096; do
  "$fiberlab" compare s.h5 --model huang2022 --set "roughness=$roughness" --set "tilt=$tilt" \
    --set quadrature_points=$points --report "rep$points" >/dev/null 2>&1
  [ -f "rep$points/metrics.json" ] || { echo "FAIL: compare at $points points wrote no metrics"; exit 1; }
done
/usr/bin/python3 - <<'PY' || fail=1
import json, h5py, numpy as np
g = h5py.File("c.h5", "r")["models/huang2022"]
text = lambda x: x.decode() if isinstance(x, bytes) else x
judge = {l["lobe"]: l for l in json.load(open("rep65536/metrics.json"))["lobes"]}
cheap = {l["lobe"]: l for l in json.load(open("rep4096/metrics.json"))["lobes"]}
chi2_after, energy_after = g["chi2_after"][0, 0, :, 0], g["model_energy_after"][0, 0, :, 0]
# metrics.json prints 10 significant digits.
for lobe in range(4):
    assert np.isclose(chi2_after[lobe], judge[lobe]["chi2"], rtol=1e-8, atol=0), (lobe, chi2_after[lobe], judge[lobe]["chi2"])
    assert np.isclose(energy_after[lobe], judge[lobe]["model_energy"], rtol=1e-8, atol=0), (lobe, energy_after[lobe])
# The fit ran at 4096 points: its chi-square is compare's there, not at 65536.
fit_chi2 = float(g["fit_chi2"][0])
cheap_sum, judge_sum = sum(cheap[l]["chi2"] for l in cheap), sum(judge[l]["chi2"] for l in judge)
assert np.isclose(fit_chi2, cheap_sum, rtol=1e-8), (fit_chi2, cheap_sum)
assert abs(judge_sum - cheap_sum) > 10, ("the quadratures should differ here", judge_sum, cheap_sum)
assert abs(chi2_after.sum() - cheap_sum) > 10, (chi2_after.sum(), cheap_sum)
assert "quadrature_points=65536" in text(g.attrs["params_after"]), g.attrs["params_after"]
assert text(g.attrs["fit_only_parameters"]) == "quadrature_points=4096", g.attrs["fit_only_parameters"]
assert text(g.attrs["fixed_parameters"]) == "quadrature_points=65536", g.attrs["fixed_parameters"]
print(f"ok: after-fit chi2 {chi2_after.sum():.2f} = compare at 65536 points ({judge_sum:.2f}); "
      f"fit chi2 {fit_chi2:.2f} = compare at 4096 points ({cheap_sum:.2f})")
PY
"$fiberlab" info c.h5 >info 2>&1
grep -q "fitted with quadrature_points=4096 on top of its fixed parameters; judged without them (quadrature_points=65536)" info \
  || { echo "FAIL: fiberlab info does not name both settings"; cat info; fail=1; }
grep -q "Fitted with (fit.model_parameters.*huang2022: quadrature_points=4096" c_report/report.md \
  || { echo "FAIL: the report does not name the fit-only settings"; fail=1; }

# Bad fit.model_parameters: one line naming the field, exit 2, no output.
refuse() {  # refuse NAME YAML_FIT_LINE EXPECTED_TEXT
  sed "s/^  model_parameters: {huang2022: {quadrature_points: 4096}}$/  model_parameters: $2/" c.yaml >"$1.yaml"
  "$fiberlab" atlas "$1.yaml" -o "$1.h5" --quiet >"$1.out" 2>"$1.err"
  local rc=$?
  if [ $rc != 2 ] || [ "$(wc -l <"$1.err")" != 1 ] || ! grep -qF "$3" "$1.err" || [ -e "$1.h5" ]; then
    echo "FAIL: $1: exit $rc, expected 2 and one line with \"$3\""; cat "$1.err"; fail=1
  fi
}
refuse unknown_model "{deon2011: {absorption: chord}}" "unknown key fit.model_parameters.deon2011"
refuse unknown_key "{huang2022: {quadrature: 4096}}" "unknown key fit.model_parameters.huang2022.quadrature"
refuse free_key "{huang2022: {roughness: 0.3}}" "fit.model_parameters.huang2022.roughness is a free parameter"
refuse bad_value "{huang2022: {quadrature_points: 12}}" "fit.model_parameters.huang2022.quadrature_points = 12 is not allowed"
refuse fiber_key "{huang2022: {eta: 1.6}}" "fit.model_parameters.huang2022.eta is each fiber's own"
refuse not_a_map "[4096]" "fit.model_parameters = [4096] must be a mapping"
[ $fail = 0 ] && echo "ok: fit-only settings fit, the judged ones judge; bad ones refused"
exit $fail
