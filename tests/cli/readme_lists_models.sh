#!/usr/bin/env bash
# Every registered model is named wherever the docs and the help texts list
# models: docs/MODELS.md holds `fiberlab models --markdown` (the models' own
# parameter tables), README.md names every model, and `predict --help`,
# `compare --help` and `energy --help` name every model (their lists come from
# analytic/model_registry, not from a hand-written list).
set -euo pipefail
fiberlab=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$fiberlab" models --markdown >"$work/tables"
for cmd in predict compare energy; do "$fiberlab" "$cmd" --help >"$work/help_$cmd"; done
/usr/bin/python3 - "$work" "$source_dir" <<'PY'
import os, re, sys
work, src = sys.argv[1:3]
tables = open(os.path.join(work, "tables")).read()
names = re.findall(r"^### `(\w+)`:", tables, re.M)
problems = []
if len(names) < 5:
    problems.append(f"`fiberlab models --markdown` lists {names}: expected every registered model (5 or more)")
if tables.strip() not in open(os.path.join(src, "docs", "MODELS.md")).read():
    problems.append("docs/MODELS.md: the tables differ from `fiberlab models --markdown` "
                    "(scripts/doc_outputs.py --write models)")
readme = open(os.path.join(src, "README.md")).read()
for n in names:
    if f"`{n}`" not in readme:
        problems.append(f"README.md does not name model `{n}`")
    for cmd in ("predict", "compare", "energy"):
        if not re.search(rf"\b{n}\b", open(os.path.join(work, "help_" + cmd)).read()):
            problems.append(f"`fiberlab {cmd} --help` does not name model {n}")
if problems:
    sys.exit("\n".join(problems))
print(f"models {', '.join(names)}: named in docs/MODELS.md, README.md and predict/compare/energy --help")
PY
