"""Checks fiberlab files against docs/FILE_FORMAT.md with h5py alone.

Usage: file_schema.py FILE_FORMAT.md [models=NAME,...] KIND:FILE ...
KIND: result, python_result, run_checkpoint, prediction, report_data, atlas,
atlas_checkpoint. Everything promised is read from the page itself: the root
attributes of its "Root attributes" table, the dataset attributes of its
"Dataset attributes" table (and the dimension names listed there), each
kind's datasets and units from its section's tables, and its "Reading one"
example, run as printed on every result-kind file. models=: the registry's
model names, which the page's list of /prediction@model must equal.
"""
import contextlib
import io
import posixpath
import re
import sys

import h5py
import numpy as np

FORMAT = {"result": "fiber-histogram", "python_result": "fiber-histogram", "run_checkpoint": "fiber-histogram",
          "prediction": "fiber-prediction", "report_data": "fiber-report-data", "atlas": "fiber-atlas",
          "atlas_checkpoint": "fiber-atlas-checkpoint"}

failures = []


def fail(path, what):
    failures.append("%s: %s" % (path, what))


def sections(doc):
    """'## ' heading -> its text (subsections '### ' stay inside)."""
    out, heading = {}, None
    for line in doc.splitlines():
        if line.startswith("## "):
            heading = line[3:]
            out[heading] = []
        elif heading is not None:
            out[heading].append(line)
    return {h: "\n".join(lines) for h, lines in out.items()}


def section(doc_sections, start):
    found = [text for h, text in doc_sections.items() if h.startswith(start)]
    assert len(found) == 1, "FILE_FORMAT.md: no single section starting %r" % start
    return found[0]


def table_rows(text):
    """Each Markdown table row as {header: cell}."""
    rows, header = [], None
    for line in text.splitlines():
        if not line.startswith("|"):
            header = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if header is None:
            header = cells
        elif not set(line) <= set("|-: "):
            rows.append(dict(zip(header, cells)))
    return rows


def documented_datasets(text):
    """name -> units of every dataset in the section's tables ('models/M/x' for a model group)."""
    out = {}
    for row in table_rows(text):
        cell = row.get("name", "")
        if "attribute" in cell or cell.startswith("root") or "units" not in row:
            continue
        tokens = re.findall(r"`([^`]+)`", cell)
        parent = None
        for t in tokens:
            if "/" in t:
                name = t.lstrip("/")
                parent = posixpath.dirname(name)
            else:
                name = posixpath.join(parent, t) if parent else t
            out[name] = row["units"]
    return out


def doc_promises(doc):
    s = sections(doc)
    shared = section(s, "Conventions shared by every kind")
    root = [re.findall(r"`([^`]+)`", r["attribute"])[0]
            for r in table_rows(shared.split("### Root attributes")[1].split("###")[0])]
    dataset_rows = table_rows(shared.split("### Dataset attributes")[1])
    dataset_attrs = [re.findall(r"`([^`]+)`", r["attribute"])[0] for r in dataset_rows]
    dims_row = [r for r in dataset_rows if r["attribute"] == "`dimensions`"][0]
    dimension_names = set(re.findall(r"`([^`]+)`", dims_row["meaning"]))
    histogram = documented_datasets(section(s, "`fiber-histogram`"))
    prediction = {k: v for k, v in histogram.items() if k.startswith(("bins/", "source/"))}
    prediction.update(documented_datasets(section(s, "`fiber-prediction`")))
    kinds = {"result": histogram, "python_result": histogram, "run_checkpoint": histogram,
             "prediction": prediction,
             "report_data": documented_datasets(section(s, "`fiber-report-data`")),
             "atlas": documented_datasets(section(s, "`fiber-atlas` ")),
             "atlas_checkpoint": documented_datasets(section(s, "`fiber-atlas-checkpoint`"))}
    model_row = [r for r in table_rows(section(s, "`fiber-prediction`")) if r["name"] == "`/prediction` attributes"]
    models = re.findall(r"`([^`]+)`", model_row[0]["meaning"].split("`model` (")[1].split(":")[0])
    reading = re.search(r"```python\n(.*?)```", section(s, "Reading one"), re.S).group(1)
    return root, dataset_attrs, dimension_names, kinds, models, reading


def text(value):
    return value.decode() if isinstance(value, bytes) else value


def required(kind, documented, f):
    """The documented datasets this file must hold."""
    names = set(documented)
    if kind in ("result", "python_result", "run_checkpoint"):
        names -= {n for n in names if n.startswith("merge/")}  # only merges of several seeds
        if kind != "run_checkpoint":
            names -= {n for n in names if n.startswith("checkpoint/")}
        if kind == "python_result":
            names -= {n for n in names if n.startswith("exact/")}  # float64 sums only (the page says so)
        # Russian roulette's ledger term and the lobes' photon S2: expected_value files only.
        if "source" not in f or text(f["source"].attrs.get("estimator", "analog")) != "expected_value":
            names -= {"ledger/roulette", "exact/roulette", "tally/lobe_weight_sq_sum",
                      "exact/lobe_weight_sq_sum"}
    if kind == "atlas":
        models = text(f.attrs["models"]).split(",")
        # The per-lobe fits' datasets only with fit.per_lobe (its groups then carry lobe_fit_status).
        names = {n for n in names if not n.startswith("models/M/")} | {
            n.replace("models/M/", "models/%s/" % m) for n in names if n.startswith("models/M/") for m in models
            if "lobe_fit" not in n or "lobe_fit_status" in f["models/" + m].attrs}
    if kind == "atlas_checkpoint" and "lobe_fit_status" not in f.attrs:
        names = {n for n in names if "lobe_fit" not in n}
    return names


def check_file(kind, path, promises):
    root, dataset_attrs, dimension_names, kinds, models, reading = promises
    documented = kinds[kind]
    with h5py.File(path, "r") as f:
        for name in root:
            if name not in f.attrs:
                fail(path, "root attribute %s missing" % name)
        if failures and failures[-1].startswith(path):
            return
        if text(f.attrs["format"]) != FORMAT[kind]:
            fail(path, "format %r, expected %r" % (f.attrs["format"], FORMAT[kind]))
        if not isinstance(f.attrs["format_version"], (int, np.integer)) or f.attrs["format_version"] not in (1, 2):
            fail(path, "format_version %r is not the integer 1 or 2" % f.attrs["format_version"])
        for name in ("software_version", "config_yaml", "lobe_names", "channel_names"):
            if not isinstance(f.attrs[name], str) or not f.attrs[name]:
                fail(path, "root attribute %s is not a non-empty string: %r" % (name, f.attrs[name]))
        if not re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", text(f.attrs["created_utc"])):
            fail(path, "created_utc %r is not ISO 8601 UTC" % f.attrs["created_utc"])
        lobes = f.attrs["lobe_names"].split(",")
        channels = f.attrs["channel_names"].split(",")
        if lobes != ["R", "TT", "p>=2"]:  # every config of the test has 3 lobes
            fail(path, "lobe_names %r, expected R,TT,p>=2" % f.attrs["lobe_names"])
        expected_channels = ["c0"] if kind.startswith("atlas") else ["R", "G", "B"]  # melanin fiber in run configs
        if channels != expected_channels:
            fail(path, "channel_names %r, expected %s" % (f.attrs["channel_names"], ",".join(expected_channels)))

        datasets = {}
        f.visititems(lambda name, obj: datasets.__setitem__(name, obj) if isinstance(obj, h5py.Dataset) else None)
        for name, d in datasets.items():
            missing = [a for a in dataset_attrs if a not in d.attrs]
            if missing:
                fail(path, "/%s lacks %s" % (name, ", ".join(missing)))
                continue
            if not all(isinstance(d.attrs[a], str) for a in dataset_attrs) or not d.attrs["description"]:
                fail(path, "/%s: dimensions, units and description must be strings (a description not empty)" % name)
                continue
            dims = d.attrs["dimensions"].split(",")
            if len(dims) != d.ndim or not set(dims) <= dimension_names:
                fail(path, "/%s: dimensions %r for a %d-dimensional dataset (names from %s)"
                     % (name, d.attrs["dimensions"], d.ndim, sorted(dimension_names)))
            for axis, names in (("lobe", lobes), ("channel", channels)):
                if axis in dims and d.shape[dims.index(axis)] != len(names):
                    fail(path, "/%s: its %s axis has %d entries, %s_names %d"
                         % (name, axis, d.shape[dims.index(axis)], axis, len(names)))
            key = re.sub(r"^models/[^/]+/", "models/M/", name)
            if key not in documented:
                fail(path, "/%s is not in docs/FILE_FORMAT.md's tables for its kind" % name)
            elif d.attrs["units"] != documented[key]:
                fail(path, "/%s: units %r, the page says %r" % (name, d.attrs["units"], documented[key]))
        for name in sorted(required(kind, documented, f) - set(datasets)):
            fail(path, "/%s (docs/FILE_FORMAT.md) is missing" % name)
        if kind == "prediction" and text(f["prediction"].attrs["model"]) not in models:
            fail(path, "/prediction@model %r is not in the page's list %s" % (f["prediction"].attrs["model"], models))

    if kind in ("result", "python_result", "run_checkpoint"):
        # The page's own example, as printed (a checkpoint's unstarted directions divide 0 by 0).
        out = io.StringIO()
        with contextlib.redirect_stdout(out), np.errstate(invalid="ignore", divide="ignore"):
            namespace = {}
            exec(reading.replace('"result.h5"', repr(path)), namespace)
        if out.getvalue().strip() != "incidence,lobe,theta,phi,channel" or namespace["lobes"] != lobes:
            fail(path, "the page's reading example printed %r, lobes %r" % (out.getvalue(), namespace.get("lobes")))


def main():
    doc = open(sys.argv[1]).read()
    promises = doc_promises(doc)
    entries = sys.argv[2:]
    if entries[0].startswith("models="):
        registry = entries.pop(0)[len("models="):].split(",")
        if promises[4] != registry:
            failures.append("FILE_FORMAT.md: /prediction@model lists %s; the registry (`fiberlab models`) has %s"
                            % (promises[4], registry))
    for entry in entries:
        kind, path = entry.split(":", 1)
        try:
            check_file(kind, path, promises)
        except Exception as e:  # a missing file or dataset: report it with the others
            fail(path, "%s: %s" % (type(e).__name__, e))
    for line in failures:
        print("FAIL:", line)
    if not failures:
        print("checked %d files of %d kinds against docs/FILE_FORMAT.md"
              % (len(entries), len({e.split(":")[0] for e in entries})))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
