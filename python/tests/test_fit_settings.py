"""fiberlab.fit(fit_settings=...) is `compare --fit --fit-set` (compare/
fit_settings.h): the fit runs with the settings, every verdict and params
without them. Oracles: fiberlab.compare of the fitted values at the judged
quadrature gives fit.after; at the fit's quadrature it gives the fit's own
chi-square."""
import numpy as np
import pytest

import fiberlab

FIBER = {
    "fiber": {"eta": 1.55, "sigma_a": 0.2, "scale_tilt": 2},
    "roughness": {"model": "ggx", "alpha": 0.2},
    "source": {"theta_i": [40], "phi_i": 0},
    "tally": {"n_theta": 18, "n_phi": 24, "lobes": 4},
}
JUDGED, CHEAP = 65536, 4096


@pytest.fixture(scope="module")
def result():
    return fiberlab.run(FIBER, photons=40_000, seed=5, progress=False)


@pytest.fixture(scope="module")
def cheap_fit(result):
    return fiberlab.fit(result, "huang2022", ["roughness"], max_iterations=3, per_lobe=True,
                        fit_settings={"quadrature_points": CHEAP}, quadrature_points=JUDGED)


def chi2_at(result, points, **params):
    params = dict(params, quadrature_points=points)
    return fiberlab.compare(result, fiberlab.predict(result, "huang2022", **params)).records


def test_verdicts_are_at_the_judged_settings(result, cheap_fit):
    f = cheap_fit
    assert f.params["quadrature_points"] == JUDGED
    judged = chi2_at(result, JUDGED, **f.params)
    for a, b in zip(judged, f.after.records):
        assert a["chi2"] == pytest.approx(b["chi2"], rel=1e-9)


def test_the_fit_ran_at_the_fit_settings(result, cheap_fit):
    f = cheap_fit
    cheap = sum(r["chi2"] for r in chi2_at(result, CHEAP, roughness=f.values["roughness"]))
    judged = sum(r["chi2"] for r in f.after.records)
    assert f.chi2_after == pytest.approx(cheap, rel=1e-8)
    assert abs(judged - cheap) > 10  # the two quadratures differ on this fiber


def test_lobe_fits_are_judged_at_the_judged_settings(result, cheap_fit):
    trt = cheap_fit.lobe_fits["TRT"]
    assert trt.params["quadrature_points"] == JUDGED
    rows = [r for r in chi2_at(result, JUDGED, **trt.params) if r["lobe_name"] == "TRT"]
    after = [r for r in trt.after.records if r["lobe_name"] == "TRT"]
    assert rows and len(rows) == len(after)
    for a, b in zip(rows, after):
        assert a["chi2"] == pytest.approx(b["chi2"], rel=1e-9)


@pytest.mark.parametrize("settings, word", [
    ({"roughness": 0.1}, "is fitted"), ({"eta": 1.6}, "fiber's own"), ({"points": 4096}, "no key 'points'"),
    ({"quadrature_points": 12}, "quadrature_points"), ([("quadrature_points", 4096)], "fit_settings must be"),
])
def test_bad_fit_settings_are_refused(result, settings, word):
    with pytest.raises(fiberlab.Error, match=word):
        fiberlab.fit(result, "huang2022", ["roughness"], max_iterations=1, fit_settings=settings)
