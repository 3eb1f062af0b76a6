#!/usr/bin/env bash
# Set up (Debian packages, build) and run the bundled default config:
# writes quickstart.h5 in the current folder and prints its lobe energies.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/setup.sh"
"$root/build/cli/fiberlab" run "$root/configs/quickstart.yaml" "$@"
