#!/usr/bin/env bash
# `compare --fit-set KEY=VALUE`: settings applied only while fitting
# (compare/fit_settings.h). huang2022 judged at 65536 quadrature points
# (--set) and fitted at 4096 (--fit-set). Oracles, from separate compares of
# the same result:
# - `compare --set` of the fitted values at 65536 points gives the reported
#   after-fit chi-square of every lobe (the verdict at the judged settings);
# - at 4096 points it gives the fit's own chi-square, and another after-fit
#   chi-square (the two quadratures differ here);
# - metrics.json lists the fit-only setting, params at the judged settings;
# - --per-lobe: each lobe's after-fit row equals a compare of its fitted
#   entry at 65536 points;
# - bad settings are refused in one line naming --fit-set, exit 2, no report.
set -uo pipefail
fiberlab=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
cd "$work" || exit 1
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots: their numbers are what is checked

cat >s.yaml <<'YAML'
photons: 40000
seed: 5
output: s.h5
fiber: {eta: 1.55, eccentricity: 1, scale_tilt: 2, sigma_a: 0.2}
roughness: {model: ggx, alpha: 0.2}
source: {theta_i: [40], phi_i: 0}
tally: {n_theta: 18, n_phi: 24, lobes: 4}
YAML
"$fiberlab" run s.yaml --threads 2 --quiet >/dev/null 2>&1 || { echo "FAIL: run exited $?"; exit 1; }
"$fiberlab" compare s.h5 --model huang2022 --set quadrature_points=65536 --fit roughness \
  --fit-set quadrature_points=4096 --per-lobe --report fit >out 2>err
[ -f fit/metrics.json ] || { echo "FAIL: compare --fit --fit-set wrote no report"; cat out err; exit 1; }
grep -q "fitted with quadrature_points=4096 (--fit-set)" out || { echo "FAIL: stdout does not name the fit-only setting"; fail=1; }
read -r roughness < <(/usr/bin/python3 -c "
import json
m = json.load(open('fit/metrics.json'))
print(repr(float(m['fit']['parameters'][0]['value'])))")
for points in 65536 4096; do
  "$fiberlab" compare s.h5 --model huang2022 --set "roughness=$roughness" --set quadrature_points=$points \
    --report "rep$points" >/dev/null 2>&1
  [ -f "rep$points/metrics.json" ] || { echo "FAIL: compare at $points points wrote no metrics"; exit 1; }
done
/usr/bin/python3 - <<'PY' || fail=1
import json, numpy as np
m = json.load(open("fit/metrics.json"))
after = {l["lobe"]: l for l in m["lobes"]}
judge = {l["lobe"]: l for l in json.load(open("rep65536/metrics.json"))["lobes"]}
cheap = {l["lobe"]: l for l in json.load(open("rep4096/metrics.json"))["lobes"]}
for lobe in judge:
    assert np.isclose(after[lobe]["chi2"], judge[lobe]["chi2"], rtol=1e-8, atol=0), (lobe, after[lobe]["chi2"], judge[lobe]["chi2"])
fit_chi2 = float(m["fit"]["chi2"])
cheap_sum, judge_sum = sum(cheap[l]["chi2"] for l in cheap), sum(judge[l]["chi2"] for l in judge)
assert np.isclose(fit_chi2, cheap_sum, rtol=1e-8), ("the fit ran at 4096 points", fit_chi2, cheap_sum)
assert abs(judge_sum - cheap_sum) > 10, ("the quadratures should differ here", judge_sum, cheap_sum)
assert m["fit"]["fit_only_settings"] == ["quadrature_points=4096"], m["fit"]["fit_only_settings"]
assert m["params"]["quadrature_points"]["value"] == "65536", m["params"]["quadrature_points"]
print(f"ok: after-fit chi2 {judge_sum:.2f} = compare at 65536 points; fit chi2 {fit_chi2:.2f} = compare at 4096 ({cheap_sum:.2f})")
PY
# --per-lobe: TRT's own fit (its own roughness entry? huang2022's roughness
# is one number: each lobe's fit moves it on that lobe's bins), judged at
# 65536 points: its after-fit TRT row equals a compare at its fitted value.
trt=$(grep -A3 "^per-lobe fit of TRT" out | sed -n 's/^  roughness *[0-9.e+-]* -> *\([0-9.e+-]*\) .*/\1/p' | head -1)
[ -n "$trt" ] || { echo "FAIL: no per-lobe fit of TRT in stdout"; cat out; exit 1; }
"$fiberlab" compare s.h5 --model huang2022 --set "roughness=$trt" --set quadrature_points=65536 --report trt >/dev/null 2>&1
/usr/bin/python3 - "$trt" <<'PY' || fail=1
import json, re, sys
text = open("out").read().split("per-lobe fit of TRT", 1)[1]
row = re.search(r"theta_i +40\.00 phi_i +\S+ +TRT c0: +\S+ -> +(\S+)", text)
assert row, text[:800]
own = {l["lobe"]: l for l in json.load(open("trt/metrics.json"))["lobes"]}[2]
printed = float(row.group(1))
# fit_text prints chi2/dof with 3 decimals.
assert abs(printed - own["chi2"] / own["dof"]) < 6e-4, (printed, own["chi2"] / own["dof"])
print(f"ok: TRT's per-lobe fit (roughness {sys.argv[1]}) judged at 65536 points: chi2/dof {printed}")
PY

refuse() {  # $1: what the error must name; the rest: compare's flags
  local want=$1; shift
  rm -rf bad
  "$fiberlab" compare s.h5 --model huang2022 "$@" --report bad >bout 2>berr
  local code=$?
  if [ $code -ne 2 ] || [ "$(wc -l <berr)" -ne 1 ] || ! grep -q -- "$want" berr || [ -e bad ]; then
    echo "FAIL: compare $* -> exit $code, stderr: $(cat berr)"; fail=1
  fi
}
refuse "need --fit" --fit-set quadrature_points=4096
refuse "is fitted" --fit roughness --fit-set roughness=0.1
refuse "fiber's own" --fit roughness --fit-set eta=1.6
refuse "no key 'points'" --fit roughness --fit-set points=4096
refuse "quadrature_points" --fit roughness --fit-set quadrature_points=12
refuse "KEY=VALUE" --fit roughness --fit-set quadrature_points
refuse "given twice" --fit roughness --fit-set quadrature_points=4096 --fit-set quadrature_points=8192
exit $fail
