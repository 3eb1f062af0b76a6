"""The lobes of a fiber with a medulla (docs/FUR.md: the tally's lobes by p,
then `scattered`) are named everywhere as the result file's `lobe_names`
attribute names them: `fiberlab compare`'s table and --report, the fit lines
of --fit --per-lobe, the atlas's per-lobe lines and its fit.lobes, Python's
comparison records and fit tables. The oracle is the attribute itself, read
with h5py; none of the project's naming code is called to make the expected
names."""
import csv
import json
import os
import re
import subprocess

import h5py
import numpy as np
import pytest

import fiberlab

# A small rough fiber with a scattering medulla (tests/sim/test_medulla.cpp
# checks its physics); 4 tally lobes by p, so the file has 5.
FUR = """photons: 100000
seed: 3
fiber:
  eta: 1.55
  sigma_a: [0.2]
  medulla: {radius: 0.5, sigma_s: 4.0, sigma_a: [0.1], g: 0.5}
roughness: {model: gaussian, beta_long: 5.0}
source: {theta_i: [30]}
tally: {n_theta: 18, n_phi: 36, lobes: 4}
"""

ATLAS = """photons: 20000
seed: 1
eta: 1.55
tally: {n_theta: 18, n_phi: 36, lobes: 4}
sweep:
  roughness:
    - {model: gaussian, beta_long: 8}
  absorption:
    - {sigma_a: 0.3}
  medulla:
    - none
    - {radius: 0.5, sigma_s: 4, sigma_a: 0.2, g: 0.5}
  theta_i: [30]
models: [marschner2003]
fit: {max_iterations: 5, lobes: [R, TT, EXTRA], per_lobe: true}
"""


def attr_names(path):
    with h5py.File(path, "r") as f:
        names = f.attrs["lobe_names"]
    return (names.decode() if isinstance(names, bytes) else names).split(",")


@pytest.fixture(scope="module")
def fur(tmp_path_factory, fiberlab_binary):
    d = tmp_path_factory.mktemp("fur")
    (d / "fur.yaml").write_text(FUR)
    subprocess.run([fiberlab_binary, "run", str(d / "fur.yaml"), "-o", str(d / "fur.h5"), "--quiet"], check=True)
    names = attr_names(d / "fur.h5")
    # The file itself, independently of any naming code: 4 lobes by p, then scattered.
    assert len(names) == 5 and names[-1] == "scattered" and names[3] == "p>=3"
    return d, names


def test_compare_table_and_report_name_the_file_lobes(fur, fiberlab_binary):
    d, names = fur
    out = subprocess.run([fiberlab_binary, "compare", str(d / "fur.h5"), "--model", "marschner2003",
                          "--report", str(d / "report")], capture_output=True, text=True,
                         env=dict(os.environ, FIBERLAB_PYTHON="/nonexistent/python3"))  # the numbers, not the figures
    assert out.returncode in (0, 1), out.stderr
    rows = [line.split() for line in out.stdout.splitlines() if re.match(r"\s+30\.00\s+0\.00\s", line)]
    assert [r[2] for r in rows] == names
    with open(d / "report" / "metrics.csv") as f:
        records = list(csv.DictReader(f))
    assert [(int(r["lobe"]), r["lobe_name"]) for r in records] == list(enumerate(names))
    metrics = json.loads((d / "report" / "metrics.json").read_text())
    assert [(r["lobe"], r["lobe_name"]) for r in metrics["lobes"]] == list(enumerate(names))
    assert attr_names(d / "report" / "report_data.h5") == names
    report = (d / "report" / "report.md").read_text()
    assert "| scattered |" in report and "| p>=3 |" in report and "p>=4" not in report
    # `fiberlab info` on the report data names the lobes its attribute names.
    info = subprocess.run([fiberlab_binary, "info", str(d / "report" / "report_data.h5")], capture_output=True,
                          text=True, check=True).stdout
    energies = [line for line in info.splitlines() if line.startswith("theta_i")][0]
    assert re.findall(r"  (\S+) [0-9.]+/", energies) == names


def test_per_lobe_fit_lines_name_the_file_lobes(fur, fiberlab_binary):
    d, names = fur
    out = subprocess.run([fiberlab_binary, "compare", str(d / "fur.h5"), "--model", "marschner2003", "--fit",
                          "beta_long", "--per-lobe", "--report", str(d / "fit_report")],
                         capture_output=True, text=True)
    assert out.returncode in (0, 1), out.stderr
    assert re.findall(r"^per-lobe fit of (\S+):", out.stdout, re.M) == names
    # Each fitted lobe's before -> after line names that lobe; marschner2003
    # predicts nothing in p>=3 and `scattered`, whose fits say so (compare/fit.h NotFitted).
    for name in names:
        block = out.stdout.split("per-lobe fit of %s:" % name)[1].split("per-lobe fit of")[0]
        if name in (names[3], names[4]):
            assert block.startswith("\nnot fitted: no free parameter acts on this lobe ("), block
        else:
            assert re.findall(r"phi_i\s+\S+\s+(\S+) c0:", block) == [name]
    # The progress lines on stderr too.
    assert re.findall(r"^(\S+) fit: \d+ residuals", out.stderr, re.M) == names
    report = (d / "fit_report" / "report.md").read_text()
    assert re.findall(r"^### (\S+)$", report, re.M) == names


def test_python_records_and_fit_tables_name_the_file_lobes(fur):
    d, names = fur
    r = fiberlab.load(str(d / "fur.h5"))
    assert r.lobe_names == names
    # The model predicts the lobes by p; its `scattered` lobe is empty (docs/FUR.md).
    c = fiberlab.compare(r, fiberlab.predict(r, "marschner2003"))
    assert [(x["lobe"], x["lobe_name"]) for x in c.records] == list(enumerate(names))
    f = fiberlab.fit(r, "marschner2003", ["beta_long"], per_lobe=True)
    assert [(x["lobe"], x["lobe_name"]) for x in f.after.records] == list(enumerate(names))
    assert list(f.lobe_fits) == names
    assert [row["lobe_name"] for row in f.lobe_table.to_dict("records")] == names


def command_rows(stdout):
    """`fiberlab compare`'s table (compare/compare_report.cpp): per row the
    lobe name and E_sim, se, E_model, z, chi2/dof, dof and the verdict as printed."""
    rows = []
    for line in stdout.splitlines():
        f = line.split()
        if len(f) >= 18 and re.match(r"-?\d+\.\d\d$", f[0]) and f[5] == "+-":
            rows.append({"lobe_name": f[2], "channel": int(f[3]), "sim_energy": float(f[4]),
                         "sim_error": float(f[6]), "model_energy": float(f[7]), "energy_z": float(f[8]),
                         "chi2_per_dof": float(f[9]), "dof": int(f[10]), "verdict": " ".join(f[17:]).lower()})
    return rows


def test_python_predict_of_a_medullated_result_compares_as_the_command(fur, fiberlab_binary):
    # Python's predict() gives the result's lobe axis (the model's lobes by p,
    # then an empty `scattered`), so compare() takes it and its table is the
    # one `fiberlab compare --model` prints for the same file: the oracle is
    # the command's stdout, parsed here.
    d, names = fur
    r = fiberlab.load(str(d / "fur.h5"))
    pred = fiberlab.predict(r, "marschner2003")
    assert pred.probability.shape == r.mean.shape
    assert pred.lobe_names == names
    assert not pred.probability[:, -1].any()  # no model predicts `scattered`
    records = fiberlab.compare(r, pred).records
    out = subprocess.run([fiberlab_binary, "compare", str(d / "fur.h5"), "--model", "marschner2003"],
                         capture_output=True, text=True)
    assert out.returncode in (0, 1), out.stderr
    rows = command_rows(out.stdout)
    assert [row["lobe_name"] for row in rows] == names
    assert len(records) == len(rows)
    for rec, row in zip(records, rows):
        assert (rec["lobe_name"], rec["channel"], rec["dof"], rec["verdict"]) == \
            (row["lobe_name"], row["channel"], row["dof"], row["verdict"])
        # The printed digits: half a unit of the last one (and a relative 1e-9 for the chi-square).
        assert rec["sim_energy"] == pytest.approx(row["sim_energy"], abs=5e-7)
        assert rec["model_energy"] == pytest.approx(row["model_energy"], abs=5e-7)
        assert rec["energy_z"] == pytest.approx(row["energy_z"], abs=0.05 + 1e-9)
        assert rec["chi2_per_dof"] == pytest.approx(row["chi2_per_dof"], abs=5e-4 + 1e-9 * row["chi2_per_dof"])


def test_cli_prediction_file_of_a_medullated_config_names_scattered(fur, fiberlab_binary):
    # `fiberlab predict` pads the same lobe (app::predict): its file has the
    # result's lobe names (read with h5py) and `compare --prediction` takes it.
    d, names = fur
    subprocess.run([fiberlab_binary, "predict", str(d / "fur.yaml"), "--model", "marschner2003", "-o",
                    str(d / "pred.h5")], check=True, capture_output=True)
    assert attr_names(d / "pred.h5") == names
    with h5py.File(d / "pred.h5", "r") as f:
        p = f["prediction/probability"][...]
    assert p.shape[1] == len(names) and not p[:, -1].any()
    out = subprocess.run([fiberlab_binary, "compare", str(d / "fur.h5"), "--prediction", str(d / "pred.h5")],
                         capture_output=True, text=True)
    assert out.returncode in (0, 1), out.stderr
    assert [row["lobe_name"] for row in command_rows(out.stdout)] == names
    assert fiberlab.load(str(d / "pred.h5")).lobe_names == names


@pytest.fixture(scope="module")
def atlas(fur, fiberlab_binary):
    d, names = fur
    config = ATLAS.replace("EXTRA", "%s, scattered" % names[3])
    (d / "atlas.yaml").write_text(config)
    out = subprocess.run([fiberlab_binary, "atlas", str(d / "atlas.yaml"), "-o", str(d / "atlas.h5")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return d, attr_names(d / "atlas.h5"), out.stderr


def test_atlas_fits_and_names_the_scattered_lobe(atlas):
    d, names, stderr = atlas
    assert names[-1] == "scattered" and len(names) == 5
    # fit.lobes names `scattered`: only the medullated fiber (2) has it.
    fits = re.findall(r"^  marschner2003 per-lobe (\S+) fit: \d+ residuals", stderr, re.M)
    assert fits == ["R", "TT", names[3], "R", "TT", names[3], "scattered"]
    tables = (d / "atlas_report" / "atlas_tables.md").read_text()
    headline = re.findall(r"^\| marschner2003 \| 2 \| (\S+) \|", tables, re.M)
    assert headline == names
    # The per-fiber per-lobe lines name the lobes as the file does; no key of
    # marschner2003 acts on p>=3 or `scattered` (it predicts nothing there).
    not_fitted = "not fitted: no free parameter acts on this lobe"
    rows = [line for line in tables.splitlines() if re.match(r"\| \d+\. .* \| marschner2003 \|", line)]
    plain, medullated = [r for r in rows if "medulla" not in r], [r for r in rows if "medulla" in r]
    assert len(plain) == 1 and len(medullated) == 1
    assert "%s: %s" % (names[3], not_fitted) in plain[0] and "scattered" not in plain[0]
    assert "%s: %s; scattered: %s" % (names[3], not_fitted, not_fitted) in medullated[0]
    assert re.findall(r"^  marschner2003 (\S+): " + not_fitted, stderr, re.M) == [names[3], names[3], "scattered"]
    # The file's per-lobe status lines too.
    with h5py.File(d / "atlas.h5", "r") as f:
        lines = f["models/marschner2003"].attrs["lobe_fit_lines"]
    lines = lines.decode() if isinstance(lines, bytes) else lines
    assert lines.count(not_fitted) == 3


def test_atlas_fit_lobes_refuses_an_unknown_lobe(fur, fiberlab_binary):
    d, _ = fur
    (d / "bad_atlas.yaml").write_text(ATLAS.replace("EXTRA", "TRRT"))
    out = subprocess.run([fiberlab_binary, "atlas", str(d / "bad_atlas.yaml"), "-o", str(d / "bad.h5")],
                         capture_output=True, text=True)
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1
    assert "fit.lobes: unknown lobe 'TRRT' (allowed: R, TT, TRT, p>=3, scattered" in out.stderr.replace(",", ", ")
    assert not (d / "bad.h5").exists()


def test_atlas_fit_of_scattered_alone_skips_the_plain_fiber(fur, fiberlab_binary):
    # fit.lobes [scattered]: the fiber without a medulla has none of them and
    # says so; the medullated one is fitted (joint fit over `scattered`,
    # where no key acts: not fitted either, and says why).
    d, _ = fur
    (d / "only.yaml").write_text(ATLAS.replace("R, TT, EXTRA", "scattered").replace("per_lobe: true", "per_lobe: false"))
    out = subprocess.run([fiberlab_binary, "atlas", str(d / "only.yaml"), "-o", str(d / "only.h5")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    with h5py.File(d / "only.h5", "r") as f:
        status = f["models/marschner2003"].attrs["status"]
    status = (status.decode() if isinstance(status, bytes) else status).split("\n")
    assert status == ["not fitted: fit.lobes names none of the fiber's lobes (R,TT,TRT,p>=3)",
                      "not fitted: no free parameter acts on this lobe"], status
