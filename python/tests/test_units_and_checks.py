"""One unit convention (degrees everywhere, ints for integers, integral floats
accepted as counts), the CLI's verdict words, Prediction's energy and
marginals, labelled arrays, and the CLI's checks on Python's arguments."""
import math

import numpy as np
import pytest

import fiberlab
from conftest import SMOOTH_ABSORBING, exact_prediction


# A rough, tilted fiber: every model's angles (widths, tilt shifts) are well
# away from their floors, so a unit slip (radians read as degrees) shows.
ROUGH_TILTED = {"fiber": {"eta": 1.55, "sigma_a": 0.4, "scale_tilt": 3},
                "roughness": {"model": "ggx", "alpha": [0.2, 0.2]},
                "source": {"theta_i": [30], "phi_i": 0}, "tally": {"n_theta": 18, "n_phi": 24, "lobes": 3}}


@pytest.mark.parametrize("model", fiberlab.model_names())
@pytest.mark.parametrize("fiber", ["smooth", "rough"])
def test_predict_with_a_predictions_own_params_reproduces_it(smooth_result, model, fiber):
    """Prediction.params are in predict()'s units (degrees, ints), so feeding
    them back gives the same prediction: for every model."""
    source = smooth_result if fiber == "smooth" else ROUGH_TILTED
    p = fiberlab.predict(source, model)
    q = fiberlab.predict(source, model, **p.params)
    assert q.params == pytest.approx(p.params, rel=1e-12)
    # Degrees -> radians -> degrees may move an angle by an ulp, which moves
    # a bin's quadrature by ~1e-18 (of a total probability 1); a unit slip
    # moves the lobes by percents.
    np.testing.assert_allclose(q.probability, p.probability, rtol=1e-9, atol=1e-15)
    for key, value in p.params.items():
        assert not isinstance(value, float) or math.isfinite(value), key


def test_angles_are_degrees_and_integers_are_ints(smooth_result):
    r = smooth_result
    np.testing.assert_allclose(r.theta_edges[[0, -1]], [-90, 90])
    np.testing.assert_allclose(r.phi_edges[[0, -1]], [-180, 180])
    np.testing.assert_allclose(r.phi_i, [0, 0])
    d = fiberlab.predict(r, "deon2011", beta_long=[5, 2.5, 10])
    assert d.params["lobes"] == 4 and isinstance(d.params["lobes"], int)
    np.testing.assert_allclose(d.params["beta_long"][:3], [5, 2.5, 10], rtol=1e-12)
    np.testing.assert_allclose(d.theta_edges, r.theta_edges)
    # Prediction and Result compute the same solid angles from degrees.
    np.testing.assert_allclose(d.solid_angle, r.solid_angle, rtol=1e-12)
    # The tilt shifts of SPEC s7 (R -2a, TT +a, TRT +4a) of a 3 deg scale tilt, in degrees.
    rough = fiberlab.predict(ROUGH_TILTED, "deon2011")
    np.testing.assert_allclose(rough.params["alpha"][:3], [-6, 3, 12], rtol=1e-12)
    np.testing.assert_allclose(rough.alpha[:3], [-6, 3, 12], rtol=1e-12)


def test_counts_accept_integral_floats_as_configs_do():
    small = dict(SMOOTH_ABSORBING, source={"theta_i": [30]})
    a = fiberlab.run(small, photons=2e3, seed=3.0, progress=False)
    b = fiberlab.run(small, photons=2000, seed=3, progress=False)
    assert list(a.photons) == [2000]
    np.testing.assert_array_equal(a.weight_sum, b.weight_sum)


@pytest.mark.parametrize("kwargs, words", [
    ({"photons": 1.5}, ["photons = 1.5", "not an integer"]),
    ({"photons": float("nan")}, ["photons", "not an integer"]),
    ({"photons": 1e300}, ["photons", "out of range"]),
    ({"photons": True}, ["photons", "not a number"]),
    ({"photons": 2 ** 63}, ["photons = 9223372036854775808 x 2 incident configurations", "2^64 - 1"]),
    ({"photons": "1000"}, ["photons", "not a number"]),
    ({"threads": 100000}, ["threads = 100000", "1 to 1024"]),
    ({"threads": 0}, ["threads = 0"]),
    ({"seed": -1}, ["seed = -1"]),
    ({"progress": 3}, ["progress"]),
])
def test_run_arguments_are_checked_as_the_cli_checks_its_flags(kwargs, words):
    with pytest.raises(fiberlab.Error) as e:
        fiberlab.run(SMOOTH_ABSORBING, **dict({"progress": False}, **kwargs))
    for w in words:
        assert w in str(e.value)


def test_paths_with_a_nul_byte_or_of_a_wrong_type_are_refused(smooth_result, tmp_path):
    path = str(tmp_path / "r.h5")
    smooth_result.save(path)
    for bad in (path + "\0ignored", path + "\0"):
        with pytest.raises(fiberlab.Error, match="NUL"):
            fiberlab.load(bad)
        with pytest.raises(fiberlab.Error, match="NUL"):
            smooth_result.save(bad)
        with pytest.raises(fiberlab.Error, match="NUL"):
            fiberlab.run(bad, progress=False)
    with pytest.raises(fiberlab.Error, match="path"):
        fiberlab.load(3)
    with pytest.raises(fiberlab.Error, match="path"):
        smooth_result.save(None)


def test_wrong_types_raise_fiberlab_error(smooth_result):
    pred = exact_prediction(smooth_result)
    with pytest.raises(fiberlab.Error, match="not a Result"):
        fiberlab.compare(smooth_result, smooth_result)
    with pytest.raises(fiberlab.Error, match="result must be a fiberlab.Result"):
        fiberlab.compare(pred, pred)
    with pytest.raises(fiberlab.Error, match="probability"):
        fiberlab.compare(smooth_result, "exact")
    with pytest.raises(fiberlab.Error, match="config must be"):
        fiberlab.run(42)
    with pytest.raises(fiberlab.Error, match="model must be"):
        fiberlab.predict(smooth_result, 7)
    with pytest.raises(fiberlab.Error, match="beta_long"):
        fiberlab.predict(smooth_result, "deon2011", beta_long={"a": 1})
    with pytest.raises(fiberlab.Error, match="max_chi2"):
        fiberlab.compare(smooth_result, pred, max_chi2="big")


@pytest.mark.parametrize("kwargs, word", [
    ({"max_chi2": float("nan")}, "max_chi2"), ({"max_chi2": -1}, "max_chi2"),
    ({"max_chi2": float("inf")}, "max_chi2"), ({"min_effective": 0}, "min_effective"),
    ({"model_error": -1}, "model_error"), ({"min_energy": float("inf")}, "min_energy"),
])
def test_compare_options_are_checked(smooth_result, kwargs, word):
    with pytest.raises(fiberlab.Error, match=word):
        fiberlab.compare(smooth_result, exact_prediction(smooth_result), **kwargs)


def test_negative_probabilities_are_refused(smooth_result):
    p = exact_prediction(smooth_result).probability.copy()
    p[0, 0, 0, 0, 0] = -1e-3
    with pytest.raises(fiberlab.Error, match="negative"):
        fiberlab.Prediction(p, like=smooth_result)


def test_table_carries_the_clis_verdict_words(smooth_result):
    """Judged lobes are "accepted" or "rejected" by compare::judge; a lobe
    under min_energy on both sides is "not judged" and not accepted."""
    pred = exact_prediction(smooth_result)
    # min_energy above every lobe's energy except the largest: some not judged.
    energies = sorted(r["sim_energy"] for r in fiberlab.compare(smooth_result, pred).records)
    c = fiberlab.compare(smooth_result, pred, min_energy=energies[len(energies) // 2])
    words = {r["verdict"] for r in c.records}
    assert words <= {"accepted", "rejected", "not judged"} and "not judged" in words
    for r in c.records:
        assert r["accepted"] == (r["verdict"] == "accepted")
        assert (r["verdict"] == "not judged") == (not r["judged"])
        if r["judged"]:
            assert (r["chi2_per_dof"] <= r["threshold"]) == r["accepted"]
    wrong = fiberlab.compare(smooth_result, exact_prediction(smooth_result, eta=1.45))
    assert "rejected" in {r["verdict"] for r in wrong.records}
    assert "1 + 5 sqrt(2/dof)" in repr(wrong)


def test_prediction_energy_and_marginals_are_the_bin_sums(smooth_result):
    p = exact_prediction(smooth_result)
    e, m = p.energy, p.marginals
    np.testing.assert_allclose(e.mean, p.probability.sum(axis=(2, 3)), rtol=1e-14)
    np.testing.assert_allclose(m.theta.sum(axis=2), e.mean, rtol=1e-12)
    np.testing.assert_allclose(m.phi.sum(axis=2), e.mean, rtol=1e-12)
    assert m.theta.shape == smooth_result.marginals.theta.shape
    assert m.phi.shape == smooth_result.marginals.phi.shape
    np.testing.assert_allclose(e.mean.sum(axis=1) + e.absorbed + e.truncated + e.lost, 1.0, rtol=1e-12)
    # The exact model's lobe energies agree with the simulation's within its errors
    # (SPEC s10: the exact smooth cylinder is an oracle), 5 standard errors.
    s = smooth_result.energy
    assert np.all(np.abs(e.mean - s.mean) <= 5 * s.std_err + 2e-4 * e.mean)


def test_to_xarray_has_named_dimensions_degrees_and_units(smooth_result):
    xarray = pytest.importorskip("xarray")
    ds = smooth_result.to_xarray()
    assert isinstance(ds, xarray.Dataset)
    assert ds["mean"].dims == ("incidence", "lobe", "theta_r", "phi", "channel")
    assert list(ds["lobe"].values) == ["R", "TT", "TRT", "p>=3"]
    assert list(ds["channel"].values) == ["c0", "c1"]
    np.testing.assert_allclose(ds["theta_i"].values, [0, 40])
    assert ds["theta_r"].attrs["units"] == "degree" and ds["phi"].attrs["units"] == "degree"
    np.testing.assert_allclose(ds["theta_r"].values[[0, -1]], [-88, 88])
    assert ds["density"].attrs["units"] == "sr^-1"
    np.testing.assert_array_equal(ds["mean"].values, smooth_result.mean)
    np.testing.assert_array_equal(ds["energy"].values, smooth_result.energy.mean)
    # Selection by label: TT's energy at theta_i = 40 deg, channel c1.
    tt = ds["energy"].where(ds["theta_i"] == 40, drop=True).sel(lobe="TT", channel="c1")
    assert float(tt) == smooth_result.energy.mean[1, 1, 1]
    p = exact_prediction(smooth_result).to_xarray()
    assert p["probability"].dims == ds["mean"].dims
    np.testing.assert_array_equal(p["theta_r"].values, ds["theta_r"].values)


def test_the_extension_itself_refuses_nul_bytes(smooth_result, tmp_path):
    """The compiled layer checks too (a caller of fiberlab._fiberlab)."""
    from fiberlab import _fiberlab
    path = str(tmp_path / "r.h5")
    smooth_result.save(path)
    for call in (lambda: _fiberlab.read_result(path + "\0x"), lambda: _fiberlab.load_settings(path + "\0x"),
                 lambda: smooth_result._file.save(path + "\0x")):
        with pytest.raises(fiberlab.Error, match="NUL"):
            call()
