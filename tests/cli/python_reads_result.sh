#!/usr/bin/env bash
# A result file is readable by Debian's Python with h5py and
# no project code, and holds every SPEC section 9 name.
set -euo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/c.yaml" <<'YAML'
photons: 20000
fiber: {eta: 1.55, sigma_a: [0.2, 0.4, 0.8], scale_tilt: 3}
roughness: {model: gaussian, beta_long: 5}
source: {theta_i: [15, 45], phi_i: 10}
tally: {n_theta: 30, n_phi: 60}
YAML
"$fiberlab" run "$work/c.yaml" -o "$work/r.h5" --quiet
/usr/bin/python3 "$source_dir/scripts/check_result.py" "$work/r.h5"
