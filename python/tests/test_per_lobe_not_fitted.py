"""A per-lobe fit whose keys cannot move its lobe's prediction is not a fit
(compare/fit.h FitOutcome::NotFitted): marschner2003 models R, TT and TRT
only (Marschner et al. 2003 s4; its p >= 3 is zero), so on a 4-lobe fiber
the per-lobe fit of p>=3 says "not fitted: no free parameter acts on this
lobe", with its start value and no error, in `compare --per-lobe`, its
report and Python; R, TT and TRT are fitted as before."""
import math
import re
import subprocess

import numpy as np
import pytest

import fiberlab

FIBER = {
    "fiber": {"eta": 1.55, "sigma_a": [0.2]},
    "roughness": {"model": "gaussian", "beta_long": 6.0},
    "source": {"theta_i": [30]},
    "tally": {"n_theta": 18, "n_phi": 36, "lobes": 4},
}
NOT_FITTED = "no free parameter acts on this lobe"


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    r = fiberlab.run(FIBER, photons=100_000, seed=5, progress=False)
    path = tmp_path_factory.mktemp("plain") / "plain.h5"
    r.save(path)
    return r, path


def test_the_model_predicts_nothing_in_p3_whatever_its_widths(result):
    # The oracle that no key acts: p>=3's prediction is exactly 0 for any
    # beta_long, while TRT's moves with it.
    r, _ = result
    a = fiberlab.predict(r, "marschner2003", beta_long=[3, 3, 3, 3]).probability
    b = fiberlab.predict(r, "marschner2003", beta_long=[9, 9, 9, 9]).probability
    assert r.lobe_names[3] == "p>=3"
    assert not a[:, 3].any() and not b[:, 3].any()
    assert not np.array_equal(a[:, 2], b[:, 2])


def test_compare_per_lobe_says_not_fitted(result, fiberlab_binary, tmp_path):
    _, path = result
    out = subprocess.run([fiberlab_binary, "compare", str(path), "--model", "marschner2003", "--fit",
                          "beta_long,scale_tilt", "--per-lobe", "--report", str(tmp_path / "rep")],
                         capture_output=True, text=True)
    assert out.returncode in (0, 1), out.stderr
    blocks = dict(re.findall(r"^per-lobe fit of (\S+):\n(.*?)(?=^per-lobe fit of|\n\d+ of \d+ judged)", out.stdout,
                             re.M | re.S))
    assert list(blocks) == ["R", "TT", "TRT", "p>=3"]
    assert blocks["p>=3"].startswith("not fitted: %s (" % NOT_FITTED)
    assert "beta_long[3]" in blocks["p>=3"] and "alpha[3]" in blocks["p>=3"]
    assert "no step lowers chi2" not in blocks["p>=3"]
    for name in ("R", "TT", "TRT"):
        assert blocks[name].startswith("fit ("), blocks[name]
    assert "p>=3 fit: " in out.stderr and "not fitted: %s" % NOT_FITTED in out.stderr
    report = (tmp_path / "rep" / "report.md").read_text()
    assert report.count("Not fitted: %s" % NOT_FITTED) == 1


def test_python_lobe_table_says_not_fitted(result):
    r, _ = result
    f = fiberlab.fit(r, "marschner2003", ["beta_long"], per_lobe=True)
    p3 = f.lobe_fits["p>=3"]
    assert p3.outcome == "not fitted" and p3.stop_reason == NOT_FITTED and not p3.converged
    assert p3.iterations == 0 and math.isnan(p3.errors["beta_long[3]"])
    assert p3.values["beta_long[3]"] == p3.start["beta_long[3]"]
    assert p3.chi2_after == p3.chi2_before and p3.dof == p3.residuals
    for name in ("R", "TT", "TRT"):
        assert f.lobe_fits[name].outcome != "not fitted"
        assert math.isfinite(f.lobe_fits[name].errors["beta_long[%d]" % ["R", "TT", "TRT"].index(name)])
    rows = {row["lobe_name"]: row for row in f.lobe_table.to_dict("records")}
    assert rows["p>=3"]["outcome"] == "not fitted" and rows["p>=3"]["stop_reason"] == NOT_FITTED
