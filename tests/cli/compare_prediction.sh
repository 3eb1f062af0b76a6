#!/usr/bin/env bash
# Honest comparisons through the real program, and the fit's lobe choices
# (--fit-lobes / --per-lobe).
# 1. A smooth *absorbing* circle against `--model exact` with no --set is
#    accepted (the exact model uses the chord by default); a wrong index, or
#    the published attenuation, is rejected (exit 1).
# 2. A prediction written by h5py alone (tests/cli/write_exact_prediction.py,
#    an independent numpy implementation of SPEC s7) is judged by
#    `compare --prediction`: right model accepted (0), wrong eta rejected (1),
#    mismatched bins or incident directions refused (2, naming the mismatch).
set -uo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots: their numbers are what is checked
fail=0
expect() {  # expect STATUS DESCRIPTION -- COMMAND...
  local want=$1 what=$2; shift 3
  "$@" >"$work/out" 2>"$work/err"
  local got=$?
  if [ "$got" != "$want" ]; then
    echo "FAIL ($what): exit $got, expected $want: $*"; cat "$work/out" "$work/err"; fail=1
  else
    echo "ok ($what): exit $got"; grep -E "TT|judged lobes|error" "$work/out" "$work/err" | head -8
  fi
}
cat >"$work/c.yaml" <<'YAML'
photons: 400000
seed: 7
fiber: {eta: 1.55, sigma_a: [0.3, 1.0]}
roughness: {model: smooth}
source: {theta_i: [35, 71]}
tally: {n_theta: 91, n_phi: 90}
YAML
"$fiberlab" run "$work/c.yaml" -o "$work/r.h5" --quiet || { echo "run failed"; exit 1; }

expect 0 "exact, defaults" -- "$fiberlab" compare "$work/r.h5" --model exact
expect 1 "exact, eta 1.45" -- "$fiberlab" compare "$work/r.h5" --model exact --set eta=1.45
expect 1 "exact, published attenuation" -- "$fiberlab" compare "$work/r.h5" --model exact --set absorption=published
expect 2 "a key exact does not have" -- "$fiberlab" compare "$work/r.h5" --model exact --set k_g=5
grep -q "k_g" "$work/err" || { echo "FAIL: the error does not name k_g"; fail=1; }
expect 2 "a fit key exact does not have" -- "$fiberlab" compare "$work/r.h5" --model exact --fit k_g
expect 2 "one alpha for every lobe" -- "$fiberlab" compare "$work/r.h5" --model deon2011 --fit alpha
[ -s "$work/out" ] && { echo "FAIL: output before the --fit error"; fail=1; }
# A fit of one lobe (the right model: eta 1.55 is recovered from TRT alone),
# and each lobe alone after it; the outcome of each fit is printed.
expect 0 "fit eta on TRT, per lobe" -- "$fiberlab" compare "$work/r.h5" --model exact --set eta=1.5 --fit eta \
  --fit-lobes TRT --per-lobe
grep -q "per-lobe fit of TRT" "$work/out" || { echo "FAIL: no per-lobe fit of TRT"; fail=1; }
grep -q "per-lobe fit of TT" "$work/out" && { echo "FAIL: a per-lobe fit of a lobe not asked for"; fail=1; }
grep -Eq "iterations, [0-9]+ model evaluations, converged: " "$work/out" || { echo "FAIL: no fit outcome"; fail=1; }
expect 2 "an unknown lobe" -- "$fiberlab" compare "$work/r.h5" --model exact --fit eta --fit-lobes TX
grep -q "unknown lobe 'TX' (allowed: R,TT,TRT,p>=3" "$work/err" || { echo "FAIL: the error does not list the lobes"; fail=1; }
expect 2 "--per-lobe without --fit" -- "$fiberlab" compare "$work/r.h5" --model exact --per-lobe

py=/usr/bin/python3
$py "$source_dir/tests/cli/write_exact_prediction.py" "$work/r.h5" "$work/right.h5" || exit 1
$py "$source_dir/tests/cli/write_exact_prediction.py" "$work/r.h5" "$work/wrong.h5" --eta 1.45 || exit 1
$py "$source_dir/tests/cli/write_exact_prediction.py" "$work/r.h5" "$work/bins.h5" --n-phi 60 || exit 1
$py - "$work/right.h5" "$work/dirs.h5" <<'PY' || exit 1
import shutil, sys, h5py
shutil.copy(sys.argv[1], sys.argv[2])
with h5py.File(sys.argv[2], "r+") as f:
    f["source/theta_i"][1] += 0.01
PY
expect 0 "h5py prediction, right model" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/right.h5"
expect 1 "h5py prediction, wrong eta" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/wrong.h5"
expect 2 "h5py prediction, other phi bins" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/bins.h5"
grep -q "phi bins" "$work/err" || { echo "FAIL: the error does not name the phi bins"; fail=1; }
expect 2 "h5py prediction, other theta_i" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/dirs.h5"
grep -q "incident direction 1" "$work/err" || { echo "FAIL: the error does not name the direction"; fail=1; }
expect 2 "prediction and model together" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/right.h5" --model exact
expect 2 "a result as prediction" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/r.h5"
expect 0 "info reads a prediction" -- "$fiberlab" info "$work/right.h5"
# fiberlab's own predictions are judged the same way (with a report).
expect 0 "predict writes" -- "$fiberlab" predict "$work/r.h5" --model exact -o "$work/own.h5"
expect 0 "predict's file, judged" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/own.h5" --report "$work/rep"
[ -f "$work/rep/metrics.csv" ] || { echo "FAIL: no report for --prediction"; fail=1; }
expect 2 "--set with --prediction" -- "$fiberlab" compare "$work/r.h5" --prediction "$work/own.h5" --set eta=1.5
# Every model's own file is judged (accepted or rejected, never refused as
# bad input): marschner2003's bins hold roundings below zero (about -1e-11,
# compare/prediction_file.h kProbabilityRounding).
for m in deon2011 marschner2003 chiang2016; do
  expect 0 "predict --model $m writes" -- "$fiberlab" predict "$work/r.h5" --model "$m" -o "$work/own_$m.h5"
  "$fiberlab" compare "$work/r.h5" --prediction "$work/own_$m.h5" >"$work/out" 2>"$work/err"
  got=$?
  if [ "$got" = 0 ] || [ "$got" = 1 ]; then echo "ok ($m's own file judged): exit $got"
  else echo "FAIL ($m's own file judged): exit $got"; cat "$work/err"; fail=1; fi
done
exit $fail
