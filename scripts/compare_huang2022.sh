#!/usr/bin/env bash
# How far Huang et al. 2022 (`--model huang2022`) is from the
# simulated microfacet fiber it describes: the simulator's `roughness:
# {model: ggx, alpha: A, masking: smith_g1}` (the paper's own ground truth:
# weight times G1, paths ending on the wrong side lost). Two fibers (a
# circle without tilt, an ellipse with tilt) x two roughnesses, at two
# incidences; prints `fiberlab compare` per lobe (energies, chi2/dof) for the
# model as published (flux=mesonormal) and with the projected width's flux
# (flux=macro, the simulator's). About 10 minutes on 2 cores (2^22 points:
# at 2^20 the quadrature alone lifts TT's chi2/dof by ~0.2 against 300k photons).
# Usage: scripts/compare_huang2022.sh [FIBERLAB] [OUTDIR]
set -euo pipefail
fiberlab=${1:-build/cli/fiberlab}
out=${2:-$(mktemp -d)}
mkdir -p "$out"
for fiber in "circle 1.0 0.0" "ellipse 0.8 2.0"; do
  read -r name ecc tilt <<<"$fiber"
  for alpha in 0.1 0.3; do
    cfg="$out/${name}_a${alpha}.yaml"
    cat >"$cfg" <<YAML
photons: 300000
seed: 7
output: $out/${name}_a${alpha}.h5
fiber:
  eta: 1.55
  eccentricity: $ecc
  scale_tilt: $tilt
  sigma_a: [0.3]
roughness:
  model: ggx
  alpha: $alpha
  masking: smith_g1
source:
  theta_i: [20.0, 50.0]
  phi_i: 30.0
tally:
  n_theta: 90
  n_phi: 90
  lobes: 4
YAML
    "$fiberlab" run "$cfg" --threads 2 >/dev/null
    for flux in mesonormal macro; do
      echo "== $name e=$ecc tilt=$tilt deg, ggx alpha=$alpha, masking smith_g1; huang2022 flux=$flux"
      "$fiberlab" compare "$out/${name}_a${alpha}.h5" --model huang2022 --set "roughness=$alpha" \
        --set "flux=$flux" --set quadrature_points=4194304 | grep -E '^ +-?[0-9]|^theta_i|judged' || true
    done
  done
done
