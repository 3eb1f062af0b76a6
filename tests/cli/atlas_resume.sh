#!/usr/bin/env bash
# `fiberlab atlas` survives interrupts (docs/ATLAS.md "Interrupting and
# resuming"), through the real program on a 4-fiber sweep of about a second
# per fiber:
# 1. A reference run, uninterrupted.
# 2. SIGINT once the checkpoint exists (a fiber is finished): exit 130, one
#    line saying how many fibers are saved and the command that resumes,
#    the checkpoint kept, no OUT and no report.
# 3. Starting the same output again is refused (the checkpoint is pending);
#    a resume with a changed config, or with -o, is refused; each exit 2 with
#    one line naming the checkpoint, which is left unchanged.
# 4. The resume (CONFIG given, from another folder) says "resuming: k of 4"
#    and writes datasets bit-identical to the reference's (all but the wall
#    times), the same report tables, and removes the checkpoint.
# 5. SIGKILL (a killed process: no handler runs) after a checkpoint: the
#    resume without CONFIG gives the reference's results too, and no
#    temporary file is left. SIGTERM once OUT is written, during the
#    report: the resume restores all 4 fibers and runs none.
# 6. Damaged checkpoints (truncated, not HDF5, not a checkpoint, an index out
#    of range): exit 2, one line naming the file, nothing written, no crash.
# 7. SIGTERM before the first fiber is finished: exit 143, nothing written.
set -uo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
py=/usr/bin/python3
same_results="$source_dir/tests/cli/atlas_same_results.py"
cat >"$work/r.yaml" <<'YAML'
photons: 20000
seed: 7
tally: {n_theta: 12, n_phi: 12, lobes: 4}
sweep:
  roughness:
    - {model: exit_blur, beta_long: 8, beta_azim: 15}
    - {model: exit_blur, beta_long: 10, beta_azim: 20}
    - {model: exit_blur, beta_long: 6, beta_azim: 12}
    - {model: exit_blur, beta_long: 12, beta_azim: 10}
  absorption: [{sigma_a: 0.2}]
  theta_i: [30]
models: [exact, deon2011]
model_parameters: {deon2011: {quadrature_order: 16}}
fit: {max_iterations: 2}
YAML
say_fail() { echo "FAIL: $*"; fail=1; }
# No plots (seconds of Python per report) except where a signal must land
# while they are made (5b): report.md then says "plots skipped".
export FIBERLAB_PYTHON=/nonexistent/python3

# 1. The reference.
"$fiberlab" atlas "$work/r.yaml" -o "$work/ref.h5" --threads 2 >"$work/out" 2>"$work/err" \
  || { echo "FAIL: reference run exited $?"; cat "$work/err"; exit 1; }
[ -e "$work/ref.checkpoint.h5" ] && say_fail "the finished run left its checkpoint"

source "$source_dir/tests/cli/atlas_interrupt.sh"
# An atlas of r.yaml to OUT, sent SIGNAL once WAIT_FOR exists (OUT's
# checkpoint by default); sets `got` to its exit status.
interrupt_after_checkpoint() {  # OUT SIGNAL [WAIT_FOR]
  interrupt_atlas "$work/r.yaml" "$1" "$2" "${3:-}" --threads 2
}

# 2. SIGINT after the first fiber.
interrupt_after_checkpoint b INT
ck="$work/b.checkpoint.h5"
last=$(tail -n 1 "$work/b.err")
if [ "$got" != 130 ]; then
  say_fail "SIGINT: exit $got (the run ends before the signal if it printed 'wrote')"; cat "$work/b.err"
elif ! [[ "$last" =~ ^fiberlab:\ atlas\ interrupted\ by\ SIGINT:\ ([1-3])\ of\ 4\ fibers\ saved\ in\ $ck\;\ resume\ with:\ fiberlab\ atlas\ --resume\ $ck$ ]]; then
  say_fail "SIGINT: last line is: $last"
elif [ ! -s "$ck" ] || [ -e "$work/b.h5" ] || [ -e "$work/b_report" ] || ls -a "$work" | grep -q '\.tmp-'; then
  say_fail "SIGINT: want the checkpoint and nothing else"; ls -a "$work"
else
  saved=${BASH_REMATCH[1]}
  echo "ok (SIGINT): exit 130, $last"
fi
cp "$ck" "$work/saved.h5"
unchanged() { cmp -s "$ck" "$work/saved.h5" || say_fail "$1: the checkpoint was changed"; }

refused() {  # DESCRIPTION PATTERN COMMAND...: exit 2, one line matching PATTERN
  local what=$1 pattern=$2
  shift 2
  "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  if [ "$rc" != 2 ] || [ "$(wc -l <"$work/err")" != 1 ] || ! grep -q -- "$pattern" "$work/err"; then
    say_fail "$what: exit $rc"; cat "$work/err"
  else
    echo "ok ($what): $(cat "$work/err")"
  fi
}
# 3. Refusals, the checkpoint untouched.
refused "new run over a pending checkpoint" "$ck exists (an interrupted atlas of this output): resume it with" \
  "$fiberlab" atlas "$work/r.yaml" -o "$work/b.h5"
unchanged "new run"
sed 's/photons: 20000/photons: 30000/' "$work/r.yaml" >"$work/changed.yaml"
refused "resume with a changed config" \
  "$ck: the config $work/changed.yaml differs from the one this checkpoint was started with (first difference: \"photons: 30000\"" \
  "$fiberlab" atlas --resume "$ck" "$work/changed.yaml"
unchanged "changed config"
refused "resume with -o" "--resume: -o, --report and --photons are the checkpoint's" \
  "$fiberlab" atlas --resume "$ck" -o "$work/other.h5"
[ -e "$work/b.h5" ] || [ -e "$work/other.h5" ] && say_fail "a refused command wrote output"

# 4. The resume, from another folder, CONFIG given (the same).
if (cd / && "$fiberlab" atlas --resume "$ck" "$work/r.yaml" --threads 2 >"$work/out" 2>"$work/err"); then
  grep -qx "resuming: ${saved:-?} of 4 fibers from $ck" "$work/err" || say_fail "no 'resuming: ${saved:-?} of 4' line"
  "$py" "$same_results" "$work/ref.h5" "$work/b.h5" || say_fail "resumed results differ from the reference"
  cmp -s "$work/ref_report/atlas_tables.md" "$work/b_report/atlas_tables.md" || say_fail "report tables differ"
  [ -e "$ck" ] && say_fail "the checkpoint is left after the final write"
  [ -s "$work/b_report/report.md" ] || say_fail "no report after the resume"
  [ "$(grep -c '^fiber ' "$work/err")" = "$((4 - ${saved:-0}))" ] || say_fail "the resume did not run just the rest"
  echo "ok (resume): $(head -n 1 "$work/err"), the reference's results, checkpoint removed"
else
  say_fail "resume exited $?"; cat "$work/err"
fi

# 5. SIGKILL: no handler runs; the last checkpoint is all there is.
interrupt_after_checkpoint c KILL
if [ "$got" != 137 ] || [ ! -s "$work/c.checkpoint.h5" ]; then
  say_fail "SIGKILL: exit $got, want 137 and a checkpoint"
elif ! (cd "$work" && "$fiberlab" atlas --resume c.checkpoint.h5 --quiet >"$work/out" 2>"$work/err"); then
  say_fail "resume after SIGKILL exited $?"; cat "$work/err"
else
  "$py" "$same_results" "$work/ref.h5" "$work/c.h5" || say_fail "results after SIGKILL differ from the reference"
  ls -a "$work" | grep -q '\.tmp-' && say_fail "a temporary file is left after the resume"
  [ -e "$work/c.checkpoint.h5" ] && say_fail "the checkpoint is left after SIGKILL's resume"
  echo "ok (SIGKILL, then resume): the reference's results"
fi

# 5b. SIGTERM once OUT is written, while the report's plots are made (after
#     its copy of OUT: a signal during a file's write ends at once): exit
#     143, one line saying so; the checkpoint (removed only after the
#     report) has every fiber; the resume runs none and writes OUT and the
#     report again. Skipped when the run ends before the signal. The signal
#     goes once atlas_tables.md is written, the last file before the plots
#     (report_data.h5, the one before, was followed by that file's own
#     write: a signal landing in it ended the run without its line, once in
#     a loaded CI run).
FIBERLAB_PYTHON=/usr/bin/python3 interrupt_after_checkpoint n TERM n_report/atlas_tables.md
if [ "$got" = 0 ]; then
  echo "skipped (SIGTERM after OUT): the run finished before the signal"
elif [ "$got" != 143 ] || [ ! -s "$work/n.checkpoint.h5" ] || ! tail -n 1 "$work/n.err" | grep -qx \
     "fiberlab: atlas interrupted by SIGTERM while making its report: $work/n.h5 is written, the report may be incomplete; both are written again by: fiberlab atlas --resume $work/n.checkpoint.h5"; then
  say_fail "SIGTERM after OUT: exit $got, want 143, the line and a checkpoint"; tail -n 1 "$work/n.err"
elif ! "$fiberlab" atlas --resume "$work/n.checkpoint.h5" >"$work/out" 2>"$work/err"; then
  say_fail "resume of a complete checkpoint exited $?"; cat "$work/err"
else
  grep -qx "resuming: 4 of 4 fibers from $work/n.checkpoint.h5" "$work/err" || say_fail "no 'resuming: 4 of 4' line"
  grep -q "^fiber " "$work/err" && say_fail "a saved fiber was run again"
  "$py" "$same_results" "$work/ref.h5" "$work/n.h5" || say_fail "complete checkpoint: results differ"
  [ -s "$work/n_report/report.md" ] && [ ! -e "$work/n.checkpoint.h5" ] || say_fail "complete checkpoint: report or cleanup"
  echo "ok (SIGTERM after OUT, then resume): 4 of 4 fibers restored, the reference's results"
fi

# 6. Damaged checkpoints.
damaged() {  # DESCRIPTION PATTERN: resume $work/d.checkpoint.h5
  refused "$1" "$work/d.checkpoint.h5: .*$2" "$fiberlab" atlas --resume "$work/d.checkpoint.h5"
  [ -e "$work/d.h5" ] || [ -e "$work/d_report" ] && say_fail "$1: output written"
}
head -c 9000 "$work/saved.h5" >"$work/d.checkpoint.h5"
damaged "truncated checkpoint" "cannot open as an HDF5 file"
echo "not hdf5" >"$work/d.checkpoint.h5"
damaged "not an HDF5 file" "cannot open as an HDF5 file"
cp "$work/ref.h5" "$work/d.checkpoint.h5"
damaged "an atlas file, not a checkpoint" "not a fiberlab atlas checkpoint"
cp "$work/saved.h5" "$work/d.checkpoint.h5"
"$py" -c 'import sys, h5py; h5py.File(sys.argv[1], "r+")["comparisons"][0, 1] = 7' "$work/d.checkpoint.h5"
damaged "lobe index out of range" "(k, lobe, channel) = (0, 7, 0) is outside the fiber's 1 x 4 x 1"
cp "$work/saved.h5" "$work/d.checkpoint.h5"
"$py" -c 'import sys, h5py; del h5py.File(sys.argv[1], "r+")["sim_energy"]' "$work/d.checkpoint.h5"
damaged "missing dataset" "\(sim_energy\|attribute_digest\)"
cp "$work/saved.h5" "$work/d.checkpoint.h5"
"$py" -c 'import sys, h5py
f = h5py.File(sys.argv[1], "r+")
f.move("sim_energy", "x"); f.move("sim_error", "sim_energy"); f.move("x", "sim_error")' "$work/d.checkpoint.h5"
damaged "sim_energy and sim_error swapped" "\(dataset sim_energy does not hold the values written\|attribute_digest\)"

# 7. SIGTERM before any fiber is finished: nothing to keep.
set -m
"$fiberlab" atlas "$work/r.yaml" -o "$work/e.h5" --photons 20000000 >"$work/out" 2>"$work/err" &
pid=$!
set +m
# Once the first fiber has started (handlers installed), not after a fixed delay.
for _ in $(seq 300); do grep -q "fiber 1 /" "$work/err" 2>/dev/null && break; sleep 0.1; done
sleep 0.3
kill -TERM "$pid"
wait "$pid"
got=$?
if [ "$got" != 143 ] || [ -e "$work/e.h5" ] || [ -e "$work/e.checkpoint.h5" ] || [ -e "$work/e_report" ] \
   || ! tail -n 1 "$work/err" | grep -qx "fiberlab: atlas interrupted by SIGTERM before its first fiber was finished; nothing written"; then
  say_fail "SIGTERM before the first fiber: exit $got"; tail -n 2 "$work/err"
else
  echo "ok (SIGTERM before the first fiber): exit 143, nothing written"
fi
exit $fail
