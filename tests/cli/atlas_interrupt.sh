# Sourced by the atlas tests that interrupt a run and resume it
# (atlas_resume.sh, atlas_per_lobe.sh, atlas_medulla_resume.sh); uses their
# $fiberlab and $work.
#
# interrupt_atlas CONFIG OUT SIGNAL [WAIT_FOR [FLAGS...]]: starts
# `fiberlab atlas CONFIG -o $work/OUT.h5 FLAGS...` in the background, its
# stdout and stderr in $work/OUT.out and $work/OUT.err; waits until
# $work/WAIT_FOR exists (default OUT.checkpoint.h5: a fiber is saved) or the
# run ends, at most two minutes; sends SIGNAL; sets `got` to the run's exit
# status. set -m: a background job started without job control ignores
# SIGINT.
interrupt_atlas() {
  local config=$1 out=$2 sig=$3 wait_for=${4:-$2.checkpoint.h5} pid
  shift $(($# < 4 ? $# : 4))
  set -m
  "$fiberlab" atlas "$config" -o "$work/$out.h5" "$@" >"$work/$out.out" 2>"$work/$out.err" &
  pid=$!
  set +m
  for _ in $(seq 1 6000); do
    [ -e "$work/$wait_for" ] && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.02
  done
  kill "-$sig" "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  got=$?
}
