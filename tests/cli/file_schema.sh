#!/usr/bin/env bash
# Every kind of file fiberlab writes, through each path that writes it,
# carries what docs/FILE_FORMAT.md promises (checked by file_schema.py with
# h5py alone), and `fiberlab info` summarises each kind (a file of unknown
# kind: one line, exit 2). Tiny photon counts and grids: seconds.
set -uo pipefail
fiberlab=$1 source_dir=$2 python_dir=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
py=/usr/bin/python3
fail=0
say_fail() { echo "FAIL: $*"; fail=1; }
run_ok() {  # WHAT COMMAND...: the command must exit 0
  local what=$1; shift
  "$@" >"$work/out" 2>"$work/err" || { say_fail "$what exited $?"; cat "$work/out" "$work/err"; }
}
export FIBERLAB_PYTHON=/nonexistent/python3  # reports without plots (the arrays are what is checked)

# A melanin fiber (channels R, G, B), two incident directions, 3 lobes.
cat >"$work/c.yaml" <<'YAML'
photons: 3000
seed: 1
fiber: {melanin: {eumelanin: 0.3, pheomelanin: 0.1}}
roughness: {model: gaussian, beta_long: 6}
source: {theta_i: [10, 40]}
tally: {n_theta: 6, n_phi: 8, lobes: 3}
YAML
run_ok "run" "$fiberlab" run "$work/c.yaml" -o "$work/run.h5" --threads 1 --quiet
run_ok "run seed 2" "$fiberlab" run "$work/c.yaml" -o "$work/run2.h5" --seed 2 --threads 1 --quiet
run_ok "merge" "$fiberlab" merge "$work/run.h5" "$work/run2.h5" -o "$work/merged.h5"
run_ok "predict" "$fiberlab" predict "$work/run.h5" --model deon2011 -o "$work/prediction.h5"
# (compare exits 1 when it rejects a lobe: deon2011's published approximations do here)
"$fiberlab" compare "$work/merged.h5" --model deon2011 --report "$work/compare_report" >"$work/out" 2>"$work/err"
got=$?
[ "$got" = 0 ] || [ "$got" = 1 ] || { say_fail "compare --report exited $got"; cat "$work/err"; }

# A run checkpoint: a run too long to finish, stopped by SIGTERM once its
# first periodic checkpoint exists (the signal writes the last one).
set -m
"$fiberlab" run "$work/c.yaml" -o "$work/long.h5" --photons 2000000000 --threads 1 --quiet \
  --checkpoint-every 0.05 >"$work/long.out" 2>"$work/long.err" &
pid=$!
set +m
for _ in $(seq 1 500); do
  [ -e "$work/long.checkpoint.h5" ] && break
  sleep 0.02
done
kill -TERM "$pid" 2>/dev/null
wait "$pid"
got=$?
[ "$got" = 143 ] || { say_fail "run stopped by SIGTERM exited $got (expected 143)"; cat "$work/long.err"; }
[ -e "$work/long.h5" ] && say_fail "the interrupted run wrote its output"

# An atlas (its report's report_data.h5 is a copy of it), and an atlas
# checkpoint: the same sweep with more photons, stopped by SIGTERM once its
# first fiber is saved.
cat >"$work/a.yaml" <<'YAML'
photons: 2000
seed: 3
tally: {n_theta: 6, n_phi: 8, lobes: 3}
sweep:
  roughness:
    - {model: exit_blur, beta_long: 8, beta_azim: 15}
    - {model: gaussian, beta_long: 10}
  absorption: [{sigma_a: 0.2}]
  theta_i: [30]
models: [exact, deon2011]
model_parameters: {deon2011: {quadrature_order: 8}}
fit: {max_iterations: 1}
YAML
run_ok "atlas" "$fiberlab" atlas "$work/a.yaml" -o "$work/atlas.h5" --threads 1
# The same with fit.per_lobe: the per-lobe fits' datasets too.
sed 's/fit: {max_iterations: 1}/fit: {max_iterations: 1, per_lobe: true}/' "$work/a.yaml" >"$work/a_lobes.yaml"
run_ok "atlas per_lobe" "$fiberlab" atlas "$work/a_lobes.yaml" -o "$work/atlas_lobes.h5" --threads 1
set -m
"$fiberlab" atlas "$work/a.yaml" -o "$work/atlas_long.h5" --photons 4000000 --threads 1 \
  >"$work/along.out" 2>"$work/along.err" &
pid=$!
set +m
for _ in $(seq 1 2500); do
  [ -e "$work/atlas_long.checkpoint.h5" ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.02
done
kill -TERM "$pid" 2>/dev/null
wait "$pid"
got=$?
[ "$got" = 143 ] || { say_fail "atlas stopped by SIGTERM exited $got (expected 143)"; cat "$work/along.err"; }

# Python's Result.save (when the module is built).
files=(result:"$work/run.h5" result:"$work/merged.h5" run_checkpoint:"$work/long.checkpoint.h5"
       prediction:"$work/prediction.h5" report_data:"$work/compare_report/report_data.h5"
       atlas:"$work/atlas.h5" atlas:"$work/atlas_report/report_data.h5" atlas:"$work/atlas_lobes.h5"
       atlas_checkpoint:"$work/atlas_long.checkpoint.h5")
if [ -n "$python_dir" ]; then
  run_ok "Python Result.save" env PYTHONPATH="$python_dir" "$py" -c \
    "import sys, fiberlab; fiberlab.run(sys.argv[1], progress=False).save(sys.argv[2])" \
    "$work/c.yaml" "$work/python.h5"
  files+=(python_result:"$work/python.h5")
else
  echo "note: the Python module is not built; Result.save not checked"
fi

# Every promise of docs/FILE_FORMAT.md, with h5py alone; its list of models
# is the registry's (`fiberlab models` starts each model's entry with NAME:).
models=$("$fiberlab" models | sed -n 's/^\([a-z0-9_]*\): .*/\1/p' | paste -sd, -)
"$py" "$source_dir/tests/cli/file_schema.py" "$source_dir/docs/FILE_FORMAT.md" "models=$models" "${files[@]}" \
  || fail=1

# `fiberlab info` reads every kind: exit 0 and its kind's first line.
for entry in "${files[@]}"; do
  kind=${entry%%:*} file=${entry#*:}
  case $kind in
    result|python_result) expect="fiberlab result" ;;
    run_checkpoint) expect="fiberlab run checkpoint" ;;
    prediction) expect="fiberlab prediction" ;;
    report_data) expect="fiberlab report data" ;;
    atlas) expect="fiberlab atlas (" ;;
    atlas_checkpoint) expect="fiberlab atlas checkpoint" ;;
  esac
  if ! "$fiberlab" info "$file" >"$work/info.out" 2>"$work/info.err"; then
    say_fail "info $file exited $?"; cat "$work/info.err"
  elif ! head -n 1 "$work/info.out" | grep -qF "$file: $expect"; then
    say_fail "info $file: first line is not '$file: $expect...'"; cat "$work/info.out"
  fi
done
# A file of unknown kind, and one that is not HDF5: one line, exit 2.
"$py" -c "import h5py, sys; h5py.File(sys.argv[1], 'w').attrs['format'] = 'something-else'" "$work/other.h5"
echo "not hdf5" >"$work/notes.txt"
for file in "$work/other.h5" "$work/notes.txt"; do
  "$fiberlab" info "$file" >"$work/info.out" 2>"$work/info.err"
  got=$?
  if [ "$got" != 2 ] || [ "$(wc -l <"$work/info.err")" != 1 ] || [ -s "$work/info.out" ] \
     || ! grep -qF "$file" "$work/info.err"; then
    say_fail "info $file: exit $got (expected 2 and one line naming the file)"; cat "$work/info.out" "$work/info.err"
  fi
done
[ "$fail" = 0 ] && echo "file_schema: every kind through every path keeps docs/FILE_FORMAT.md's promises"
exit "$fail"
