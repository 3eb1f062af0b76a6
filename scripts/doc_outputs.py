#!/usr/bin/python3
"""Regenerate (--write) or check (--check) every output and table the docs show.

The docs mark each generated block with HTML comments, which Markdown does
not show:

    <!-- BEGIN generated: scripts/doc_outputs.py NAME -->
    ...the output of generator NAME...
    <!-- END generated -->

A generator runs the real program (`fiberlab`) and returns the block's text.
`--check` (the ctest test `docs_outputs`, label `docs`) re-runs every quick
generator and fails, showing the difference, when a doc's block is not
exactly what the program prints now: a stale number fails CI.

Blocks that take long to regenerate (the default atlas: about half an hour
on 2 cores) are marked

    <!-- BEGIN generated (long; run by hand): scripts/doc_outputs.py --long NAME -->

and `--check` only checks that NAME is one of the long generators below;
regenerate them with `scripts/doc_outputs.py --write --long NAME`.

Numbers that depend on the machine (speed) are marked

    <!-- BEGIN measured (by hand, not by the tests): COMMAND; COMMAND -->

and `--check` checks that every script or benchmark source such a COMMAND
names exists in the repository.

--check also checks that README.md has at most 200 lines and that no file
tells development history (numbered work periods, rounds of work, issue numbers).

Usage: doc_outputs.py [--fiberlab build/cli/fiberlab] (--check | --write) [--long] [--from DIR] [NAME ...]
"""
import argparse
import difflib
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = ["README.md", "configs/README.md"] + sorted(
    os.path.join("docs", f) for f in os.listdir(os.path.join(ROOT, "docs")) if f.endswith(".md"))

BEGIN = re.compile(r"<!-- BEGIN generated(?P<long> \(long; run by hand\))?: scripts/doc_outputs\.py "
                   r"(?:--long )?(?P<name>[\w.:-]+) -->\n")
END = "<!-- END generated -->"
MEASURED = re.compile(r"<!-- BEGIN measured \(by hand, not by the tests\): (?P<commands>.+?) -->")
MEASURED_END = "<!-- END measured -->"


class Runner:
    """Runs fiberlab in a scratch folder (so that printed file names are short)."""

    def __init__(self, fiberlab, reuse=None):
        self.fiberlab = os.path.abspath(fiberlab)
        self.reuse = reuse  # a folder holding atlas runs already made (--from)
        self.work = tempfile.mkdtemp(prefix="fiberlab-docs-")
        # The atlas's report figures are not part of any doc's text: skip the plotting.
        self.env = dict(os.environ, FIBERLAB_PYTHON="/bin/false")

    def __call__(self, *args):
        out = subprocess.run([self.fiberlab, *args], cwd=self.work, env=self.env, text=True,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        if out.returncode not in (0, 1):  # compare exits 1 when a lobe is rejected
            sys.exit(f"doc_outputs: fiberlab {' '.join(args)} failed ({out.returncode}):\n{out.stderr}")
        return out.stdout

    def config(self, name):
        return os.path.join(ROOT, "configs", name)

    def close(self):
        shutil.rmtree(self.work, ignore_errors=True)


def shown(command, output):
    """A terminal block: the command as a user types it, then what it prints."""
    return f"```\n$ {command}\n{output.rstrip()}\n```\n"


def gen_help(run):
    return {"help": shown("fiberlab --help", run("--help"))}


def without_timing(output):
    """Output without the times it reports (they vary from run to run): `run`'s
    last lines (its speed, the time to write) and the seconds `compare` took."""
    lines = [l for l in output.splitlines(True) if not re.match(r"\d+ photons in .* s on |wrote .* in [\d.]+ s$", l)]
    return re.sub(r"; [\d.]+ s$", "", "".join(lines), flags=re.M)


def gen_quickstart(run):
    out = run("run", run.config("quickstart.yaml"), "-o", "quickstart.h5")
    return {"quickstart": shown("fiberlab run configs/quickstart.yaml", without_timing(out))}


def gen_smooth_circle(run):
    run("run", run.config("smooth_circle.yaml"), "-o", "smooth_circle.h5", "--photons", "1000000", "--quiet")
    out = without_timing(run("compare", "smooth_circle.h5", "--model", "exact"))
    return {"smooth_circle": "```\n$ fiberlab run configs/smooth_circle.yaml --photons 1000000 --quiet\n"
                             + shown("fiberlab compare smooth_circle.h5 --model exact", out)[4:]}


def gen_models(run):
    return {"models": run("models", "--markdown").rstrip() + "\n"}


def gen_model_names(run):
    """One line per registered model, from the headings of `fiberlab models --markdown`."""
    names = re.findall(r"^### (`\w+`: .*)$", run("models", "--markdown"), re.M)
    return {"model_names": "".join(f"- {n}\n" for n in names)}


def atlas_tables(run, config, name):
    """The atlas report's two tables (OUT_report/atlas_tables.md), one block each.
    With --from DIR, the tables of a run already made in DIR (`fiberlab atlas
    configs/CONFIG -o NAME.h5` there, which also draws the report's figures)."""
    folder = run.reuse or run.work
    if not run.reuse:
        run("atlas", run.config(config), "-o", f"{name}.h5", "--threads", "2", "--quiet")
    text = open(os.path.join(folder, f"{name}_report", "atlas_tables.md")).read()
    headline, fibers = text.split("## Per fiber\n\n")
    headline = headline.replace("## Per model and lobe (median over fibers)\n\n", "")
    return {f"{name}:headline": headline.strip() + "\n", f"{name}:fibers": fibers.strip() + "\n"}


def gen_atlas_small(run):
    return atlas_tables(run, "atlas_small.yaml", "atlas_small")


def gen_atlas_medium(run):
    return atlas_tables(run, "atlas_medium.yaml", "atlas_medium")


def gen_atlas_default(run):
    return atlas_tables(run, "atlas.yaml", "atlas")


QUICK = {"help": gen_help, "quickstart": gen_quickstart, "smooth_circle": gen_smooth_circle,
         "models": gen_models, "model_names": gen_model_names,
         "atlas_small": gen_atlas_small}
LONG = {"atlas_medium": gen_atlas_medium, "atlas": gen_atlas_default}


def blocks(text):
    """(name, long, start, end) of each generated block: text[start:end] is its body."""
    for m in BEGIN.finditer(text):
        end = text.find(END, m.end())
        if end < 0:
            sys.exit(f"doc_outputs: block {m['name']} has no '{END}'")
        yield m["name"], bool(m["long"]), m.end(), end


def check_measured(path, text, problems):
    for m in MEASURED.finditer(text):
        if text.find(MEASURED_END, m.end()) < 0:
            problems.append(f"{path}: measured block '{m['commands']}' has no '{MEASURED_END}'")
        for word in re.findall(r"[\w./-]+", m["commands"]):
            if not word.startswith(("bench/", "scripts/", "configs/", "build/bench/")) or "NAME" in word:
                continue
            source = word
            if word.startswith("build/bench/"):  # a benchmark program: its source
                source = "bench/" + os.path.basename(word) + ".cpp"
            if not os.path.exists(os.path.join(ROOT, source)):
                problems.append(f"{path}: measured block names '{word}', which is not in the repository")


# Words that tell how the project was built rather than what it is: docs and
# comments state what is true now (development history lives in git).
HISTORY = re.compile(r"\b((first|second|third|\w+teenth|\w+tieth|fourth|fifth|sixth|seventh|eighth|ninth|tenth|"
                     r"eleventh|twelfth|\d+(st|nd|rd|th)|this|previous|last|next) ses{2}ions?|ses{2}ion by ses{2}ion|"
                     r"rounds? of work|the version before|previous build|issues? \d+)\b", re.I)
HISTORY_ALLOWED = ('scope="session"',)  # pytest's fixture scope
SOURCE_SUFFIXES = (".md", ".cpp", ".h", ".inc", ".py", ".sh", ".cmake", ".txt", ".yaml", ".ipynb")


def check_history(problems):
    for top, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith((".", "build"))]
        for f in files:
            if not f.endswith(SOURCE_SUFFIXES) or f == os.path.basename(__file__):
                continue
            path = os.path.join(top, f)
            with open(path, encoding="utf-8", errors="replace") as fh:
                for n, line in enumerate(fh, 1):
                    m = HISTORY.search(line)
                    if m and not any(a in line for a in HISTORY_ALLOWED):
                        problems.append(f"{os.path.relpath(path, ROOT)}:{n}: '{m[0]}' tells development "
                                        f"history; say what is true now")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fiberlab", default=os.path.join(ROOT, "build", "cli", "fiberlab"))
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true")
    mode.add_argument("--write", action="store_true")
    ap.add_argument("--long", action="store_true", help="also regenerate the long blocks (with --write)")
    ap.add_argument("--from", dest="reuse", metavar="DIR",
                    help="take the atlases' tables from runs already made in DIR (NAME_report/atlas_tables.md)")
    ap.add_argument("names", nargs="*", help="only these generators")
    args = ap.parse_args()

    generators = dict(QUICK, **(LONG if args.long else {}))
    if args.names:
        unknown = set(args.names) - set(QUICK) - set(LONG)
        if unknown:
            sys.exit(f"doc_outputs: unknown generator(s) {sorted(unknown)}; known: {sorted(QUICK) + sorted(LONG)}")
        generators = {n: g for n, g in dict(QUICK, **LONG).items() if n in args.names}

    run = Runner(args.fiberlab, args.reuse)
    outputs, problems, rewritten = {}, [], []
    readme_lines = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read().count("\n")
    if readme_lines > 200:
        problems.append(f"README.md has {readme_lines} lines: the front page holds at most 200 (the rest: docs/)")
    if args.check:
        check_history(problems)
    try:
        for path in DOCS:
            full = os.path.join(ROOT, path)
            text = open(full, encoding="utf-8").read()
            check_measured(path, text, problems)
            pieces, last = [], 0
            for name, is_long, start, end in blocks(text):
                base = name.split(":")[0]
                if base not in QUICK and base not in LONG:
                    problems.append(f"{path}: block '{name}': no such generator in scripts/doc_outputs.py")
                    continue
                if is_long != (base in LONG):
                    problems.append(f"{path}: block '{name}' is marked {'long' if is_long else 'quick'}, "
                                    f"its generator is not")
                    continue
                if base not in generators:
                    continue
                if base not in outputs:
                    print(f"doc_outputs: running {base}", file=sys.stderr, flush=True)
                    outputs[base] = generators[base](run)
                if name not in outputs[base]:
                    problems.append(f"{path}: block '{name}': generator {base} makes {sorted(outputs[base])}")
                    continue
                want, have = outputs[base][name], text[start:end]
                if want != have:
                    if args.write:
                        pieces += [text[last:start], want]
                        last = end
                    else:
                        diff = "".join(difflib.unified_diff(have.splitlines(True), want.splitlines(True),
                                                            f"{path} ({name})", "what the program prints now"))
                        problems.append(f"{path}: block '{name}' is stale; run "
                                        f"scripts/doc_outputs.py --write{' --long' if is_long else ''} {base}\n{diff}")
            if pieces:
                pieces.append(text[last:])
                with open(full, "w", encoding="utf-8") as f:
                    f.write("".join(pieces))
                rewritten.append(path)
        for base in generators:
            if base not in outputs and not args.names and base in QUICK:
                problems.append(f"generator {base} is used by no doc")
    finally:
        run.close()
    for p in rewritten:
        print(f"doc_outputs: rewrote {p}")
    if problems:
        print("\n".join(problems), file=sys.stderr)
        sys.exit(1)
    if args.check:
        print(f"doc_outputs: {len(outputs)} generators, every block current")


if __name__ == "__main__":
    main()
