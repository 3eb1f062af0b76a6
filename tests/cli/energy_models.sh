#!/usr/bin/env bash
# `fiberlab energy CONFIG` without --models: one row per registered model
# (`fiberlab models` names them), a circular-only model on an ellipse listed
# as "not applicable"; --set reaches the models that have the key and is
# refused when none has it. huang2022's quadrature is cut to its minimum
# here (--set quadrature_points=1024) to keep the test short.
set -euo pipefail
fiberlab=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
names=$("$fiberlab" models --markdown | sed -n 's/^### `\([a-z0-9]*\)`:.*/\1/p')
[ "$(echo "$names" | wc -l)" -ge 5 ] || { echo "FAIL: fiberlab models lists: $names"; exit 1; }
cat >"$work/circle.yaml" <<'YAML'
fiber: {eta: 1.55, sigma_a: [0.2]}
roughness: {model: gaussian, beta_long: 5}
source: {theta_i: [30]}
YAML
sed 's/sigma_a: \[0.2\]}/sigma_a: [0.2], eccentricity: 0.8}/' "$work/circle.yaml" >"$work/ellipse.yaml"
common=(--grid-theta 18 --grid-phi 9 --set quadrature_points=1024)
"$fiberlab" energy "$work/circle.yaml" "${common[@]}" >"$work/circle.out"
for n in $names; do
  grep -Eq "^  $n +[0-9]" "$work/circle.out" || { echo "FAIL: energy (circle) has no row for $n"; cat "$work/circle.out"; exit 1; }
done
"$fiberlab" energy "$work/ellipse.yaml" "${common[@]}" >"$work/ellipse.out"
grep -q "^exact: not applicable: " "$work/ellipse.out" || { echo "FAIL: ellipse: exact not listed as not applicable"; cat "$work/ellipse.out"; exit 1; }
grep -Eq "^  huang2022 +[0-9]" "$work/ellipse.out" || { echo "FAIL: ellipse: no huang2022 row"; cat "$work/ellipse.out"; exit 1; }
if "$fiberlab" energy "$work/circle.yaml" --set no_such_key=1 >"$work/bad.out" 2>&1; then
  echo "FAIL: --set no_such_key=1 accepted"; exit 1
fi
grep -q "no model of --models" "$work/bad.out" || { echo "FAIL: unclear error:"; cat "$work/bad.out"; exit 1; }
echo "energy: every model by default ($(echo $names | tr '\n' ' ')), not-applicable ones listed"
