#!/usr/bin/env bash
# Issue 7: the README's model tables are `fiberlab models --markdown`, the
# models' own parameter tables (regenerate the section when a table changes).
set -euo pipefail
fiberlab=$1 source_dir=$2
tables=$(mktemp)
trap 'rm -f "$tables"' EXIT
"$fiberlab" models --markdown >"$tables"
/usr/bin/python3 - "$tables" "$source_dir/README.md" <<'PY'
import sys
tables, readme = (open(p).read() for p in sys.argv[1:3])
if tables not in readme:
    sys.exit("README.md: the 'Models and their parameters' tables differ from `fiberlab models --markdown`")
PY
