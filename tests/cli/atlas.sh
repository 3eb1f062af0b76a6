#!/usr/bin/env bash
# `fiberlab atlas` through the real program, on a sweep small enough for seconds.
# 1. Two exit_blur fibers (beta 8 and 12 deg, azimuthal 15 deg, no tilt,
#    white): d'Eon's M_p and Gaussian detector are then the simulator's exit
#    blur (SPEC s3), so the fitted common beta_long of deon2011 must come back
#    to the simulated one (within 0.5 deg: the fit's own error here is
#    ~0.1 deg, and the model's published R Fresnel departs slightly from the
#    simulator's), beta_azim within 1.5 deg, scale_tilt within 0.5 deg of 0;
#    the fiber-atlas file, report.md, report.html and the figures are written.
#    model_parameters reach the model (params_before) and the report.
# 2. Bad configs: exit 2, one line naming the entry, nothing written.
# 3. SIGINT during the first fiber: exit 130, nothing written, no checkpoint
#    (checkpoints and --resume: tests/cli/atlas_resume.sh).
set -uo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
cat >"$work/a.yaml" <<'YAML'
photons: 200000
seed: 3
tally: {n_theta: 30, n_phi: 24, lobes: 4}
sweep:
  roughness:
    - {model: exit_blur, beta_long: 8, beta_azim: 15}
    - {model: exit_blur, beta_long: 12, beta_azim: 15}
  absorption: [{sigma_a: 0.0}]
  scale_tilt: [0]
  theta_i: [25]
models: [exact, deon2011]
model_parameters: {deon2011: {quadrature_order: 40}}
fit: {max_iterations: 10}
YAML
if ! "$fiberlab" atlas "$work/a.yaml" -o "$work/a.h5" --threads 2 >"$work/out" 2>"$work/err"; then
  echo "FAIL: atlas exited $?"; cat "$work/out" "$work/err"; exit 1
fi
cat "$work/out"
for f in a.h5 a_report/report.md a_report/report.html a_report/report_data.h5 \
         a_report/atlas_error_vs_roughness.png a_report/atlas_error_vs_theta_i.png \
         a_report/atlas_error_vs_roughness.svg a_report/atlas_error_vs_theta_i.svg; do
  [ -s "$work/$f" ] || { echo "FAIL: $f missing"; fail=1; }
done
grep -q "| deon2011 | 2 | TT |" "$work/a_report/report.md" || { echo "FAIL: no headline row in report.md"; fail=1; }
grep -q "Fixed model parameters (not fitted; the config's model_parameters): deon2011: quadrature_order=40." \
  "$work/a_report/report.md" || { echo "FAIL: report.md does not name the fixed parameters"; fail=1; }
cmp -s "$work/a.h5" "$work/a_report/report_data.h5" || { echo "FAIL: report_data.h5 is not the atlas file"; fail=1; }
/usr/bin/python3 - "$work/a.h5" <<'PY' || fail=1
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1], "r")
assert f.attrs["format"] in ("fiber-atlas", b"fiber-atlas"), f.attrs["format"]
g = f["models/deon2011"]
keys = g.attrs["fit_keys"]
keys = (keys.decode() if isinstance(keys, bytes) else keys).split(",")
v, e = g["fit_value"][...], g["fit_error"][...]
print("deon2011", keys, v.tolist(), e.tolist())
assert keys == ["beta_long", "beta_azim", "scale_tilt"], keys
for i, truth in enumerate([8.0, 12.0]):
    assert abs(v[i, 0] - truth) < 0.5, ("beta_long", i, v[i, 0], truth)
    assert abs(v[i, 1] - 15.0) < 1.5, ("beta_azim", i, v[i, 1])
    assert abs(v[i, 2]) < 0.5, ("scale_tilt", i, v[i, 2])
    assert 0 < e[i, 0] < 0.5, e[i]
assert g["fitted"][...].tolist() == [1, 1]
before = g.attrs["params_before"]
before = (before.decode() if isinstance(before, bytes) else before).split("\n")
assert all("quadrature_order=40" in b for b in before), before  # model_parameters reach the model
assert f["models/exact/fitted"][...].tolist() == [0, 0]
assert f["fibers/sim_energy"].shape == (2, 1, 4, 1), f["fibers/sim_energy"].shape
print("ok: the fitted widths are the simulated ones")
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
tally: {n_theta: 9, n_phi: 12}'
bad "unknown key" "unknown key sweep.tilt" "$base
sweep: {roughness: [{model: smooth}], tilt: [1]}"
bad "bad theta_i" "theta_i" "$base
sweep: {roughness: [{model: smooth}], theta_i: [95]}"
bad "bad roughness value" "roughness\[1\]" "$base
sweep: {roughness: [{model: smooth}, {model: gaussian, beta_long: -3}], theta_i: [10]}"
bad "unknown model" "models\[0\] = huang1999" "$base
sweep: {roughness: [{model: smooth}], theta_i: [10]}
models: [huang1999]"
bad "absorption both" "both sigma_a and melanin" "$base
sweep: {roughness: [{model: smooth}], absorption: [{sigma_a: 1, melanin: {eumelanin: 1}}], theta_i: [10]}"
bad "model parameter value" "model_parameters.deon2011.quadrature_order = 0 is not allowed" "$base
sweep: {roughness: [{model: smooth}], theta_i: [10]}
model_parameters: {deon2011: {quadrature_order: 0}}"
bad "missing photons" "photons is missing" "sweep: {roughness: [{model: smooth}], theta_i: [10]}"
# Ctrl-C: a sweep of several seconds, interrupted after one.
cat >"$work/long.yaml" <<'YAML'
photons: 2000000
tally: {n_theta: 30, n_phi: 24}
sweep: {roughness: [{model: gaussian, beta_long: 5}, {model: gaussian, beta_long: 9}], theta_i: [10, 40, 70]}
models: [chiang2016]
YAML
set -m
"$fiberlab" atlas "$work/long.yaml" -o "$work/long.h5" --threads 1 >"$work/out" 2>"$work/err" &
pid=$!
set +m
# Interrupt once the first fiber has started (its progress line is out, so
# the handlers are installed), not after a fixed delay: under load a fixed
# 1.5 s could land before the handlers or after the first fiber.
for _ in $(seq 300); do grep -q "fiber 1 /" "$work/err" 2>/dev/null && break; sleep 0.1; done
sleep 0.3
kill -INT "$pid"
wait "$pid"
got=$?
if [ "$got" != 130 ] || [ -e "$work/long.h5" ] || [ -e "$work/long_report" ] || [ -e "$work/long.checkpoint.h5" ] \
   || ! tail -n 1 "$work/err" | grep -q "before its first fiber was finished; nothing written"; then
  echo "FAIL (SIGINT): exit $got"; cat "$work/err"; fail=1
else
  echo "ok (SIGINT): exit 130, nothing written"
fi
exit $fail
