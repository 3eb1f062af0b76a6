#!/usr/bin/env bash
# `mpirun -np 2 fiberlab atlas` equals one process: every dataset and
# attribute of the atlas file but wall times, creation time and version
# (tests/cli/atlas_same_results.py), and the tables it prints. Three fibers
# on two ranks: a full round and a round with an idle rank. Then resume: a
# checkpoint of one process's first fiber finished by two ranks. The fits
# run with fit-only settings (fit.model_parameters; for chiang2016_pbrt,
# through its model), so a resumed fit is rebuilt at the judged settings.
# Skipped (77) without mpirun.
set -uo pipefail
fiberlab=$1 source_dir=$2
mpirun=$(command -v mpirun) || { echo "SKIPPED: mpirun is not installed (openmpi-bin)"; exit 77; }
launch=("$mpirun" --allow-run-as-root --oversubscribe -np 2)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
cat >"$work/a.yaml" <<'YAML'
photons: 30000
seed: 4
tally: {n_theta: 18, n_phi: 24, lobes: 4}
sweep:
  roughness: [{model: gaussian, beta_long: 5}, {model: gaussian, beta_long: 9}, {model: gaussian, beta_long: 14}]
  absorption: [{sigma_a: 0.2}]
  scale_tilt: [2]
  theta_i: [30]
models: [deon2011, {name: chiang2016_pbrt, model: chiang2016, parameters: {mp: pbrt_v4}}]
fit:
  max_iterations: 8
  model_parameters: {deon2011: {absorption: chord}, chiang2016: {mp: exact}}
YAML
"$fiberlab" atlas "$work/a.yaml" -o "$work/one.h5" --threads 1 --quiet >"$work/one.out" 2>"$work/one.err" \
  || { echo "FAIL: one process exited $?"; cat "$work/one.err"; exit 1; }
"${launch[@]}" "$fiberlab" atlas "$work/a.yaml" -o "$work/two.h5" --threads 1 --quiet >"$work/two.out" 2>"$work/two.err" \
  || { echo "FAIL: mpirun -np 2 exited $?"; cat "$work/two.out" "$work/two.err"; exit 1; }
/usr/bin/python3 "$source_dir/tests/cli/atlas_same_results.py" "$work/one.h5" "$work/two.h5" || fail=1
# The tables (the file name aside) are the same.
diff <(sed 's/one\.h5//; s/one_report//g' "$work/one.out") <(sed 's/two\.h5//; s/two_report//g' "$work/two.out") \
  || { echo "FAIL: the printed tables differ"; fail=1; }
[ -e "$work/two.checkpoint.h5" ] && { echo "FAIL: the checkpoint was left"; fail=1; }
# Resume across launchers: one process saves fiber 1 (SIGINT once it is
# saved), two ranks finish fibers 2 and 3.
set -m
"$fiberlab" atlas "$work/a.yaml" -o "$work/res.h5" --threads 1 >"$work/res.out" 2>"$work/res.err" &
pid=$!
set +m
for _ in $(seq 600); do [ -e "$work/res.checkpoint.h5" ] && break; sleep 0.1; done
kill -INT "$pid"; wait "$pid"
"${launch[@]}" "$fiberlab" atlas --resume "$work/res.checkpoint.h5" --threads 1 --quiet >"$work/res2.out" 2>"$work/res2.err" \
  || { echo "FAIL: mpirun resume exited $?"; cat "$work/res2.err"; exit 1; }
/usr/bin/python3 "$source_dir/tests/cli/atlas_same_results.py" "$work/one.h5" "$work/res.h5" || fail=1
[ $fail = 0 ] && echo "ok: mpirun -np 2 atlas and its resume equal one process"
exit $fail
