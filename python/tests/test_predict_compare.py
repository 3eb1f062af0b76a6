"""predict + compare: the exact model is accepted on a smooth absorbing fiber,
a wrong eta is rejected, and a researcher's own NumPy prediction is judged."""
import numpy as np
import pytest

import fiberlab
from conftest import exact_prediction


def test_exact_model_is_accepted(smooth_result):
    pred = exact_prediction(smooth_result)
    assert pred.probability.shape == smooth_result.mean.shape
    assert pred.model == "exact"
    assert pred.params["eta"] == pytest.approx(1.55)
    c = fiberlab.compare(smooth_result, pred)
    judged = [r for r in c.records if r["judged"]]
    assert len(judged) == 16
    assert c.accepted, c.rejected
    # chi2 is a sum over dof terms: its total stays within dof + 5 sqrt(2 dof).
    chi2 = sum(r["chi2"] for r in judged)
    dof = sum(r["dof"] for r in judged)
    assert chi2 <= dof + 5 * np.sqrt(2 * dof)


def test_wrong_eta_is_rejected(smooth_result):
    c = fiberlab.compare(smooth_result, exact_prediction(smooth_result, eta=1.45))
    assert not c.accepted
    tt = [r for r in c.records if r["lobe_name"] == "TT"]
    assert all(not r["accepted"] for r in tt)


def test_table_is_a_dataframe_with_one_row_per_lobe_and_channel(smooth_result):
    pandas = pytest.importorskip("pandas")
    t = fiberlab.compare(smooth_result, exact_prediction(smooth_result)).table
    assert isinstance(t, pandas.DataFrame)
    assert len(t) == 2 * 4 * 2
    for column in ("theta_i_deg", "phi_i_deg", "lobe_name", "channel", "sim_energy", "sim_error",
                   "model_energy", "energy_z", "chi2_per_dof", "dof", "theta_chi2_per_dof",
                   "phi_chi2_per_dof", "measured_shift_deg", "accepted"):
        assert column in t.columns
    assert sorted(set(t["lobe_name"])) == sorted(["R", "TT", "TRT", "p>=3"])


def test_max_chi2_tightens_the_verdict(smooth_result):
    c = fiberlab.compare(smooth_result, exact_prediction(smooth_result), max_chi2=1e-3)
    assert not c.accepted


def test_own_numpy_prediction_is_judged(smooth_result):
    """A model computed in NumPy: the exact model's probabilities are
    accepted; with TT's phi distribution rotated by 5 deg, rejected."""
    p = exact_prediction(smooth_result).probability.copy()
    own = fiberlab.Prediction(probability=p, like=smooth_result)
    assert fiberlab.compare(smooth_result, own).accepted
    p[:, 1] = np.roll(p[:, 1], 1, axis=2)  # one 5-deg phi bin
    c = fiberlab.compare(smooth_result, fiberlab.Prediction(probability=p, like=smooth_result))
    assert not c.accepted
    assert {r["lobe_name"] for r in c.rejected} == {"TT"}


def test_own_prediction_of_the_wrong_shape_is_refused(smooth_result):
    with pytest.raises(fiberlab.Error, match="shape"):
        fiberlab.Prediction(probability=np.zeros((1, 4, 45, 72, 2)), like=smooth_result)
    with pytest.raises(fiberlab.Error, match="shape"):
        fiberlab.compare(smooth_result, np.zeros((2, 4, 45, 71, 2)))


def test_predict_from_a_config_dict_matches_predict_from_the_result(smooth_result):
    from conftest import SMOOTH_ABSORBING
    a = exact_prediction(smooth_result)
    b = fiberlab.predict(SMOOTH_ABSORBING, "exact", **({"absorption": a.params["absorption"]}
                                                      if "absorption" in a.params else {}))
    np.testing.assert_array_equal(a.probability, b.probability)


def test_unknown_model_or_parameter(smooth_result):
    with pytest.raises(fiberlab.Error, match="allowed"):
        fiberlab.predict(smooth_result, "no_such_model")
    with pytest.raises(fiberlab.Error, match="bogus"):
        fiberlab.predict(smooth_result, "exact", bogus=1)
    assert "exact" in fiberlab.model_names()


def test_cli_prediction_file_loads_and_describes_itself(smooth_result, fiberlab_binary, tmp_path):
    """A `fiberlab predict` file: load() gives the Prediction fiberlab.predict
    makes, and the file carries the schema's names and units."""
    import subprocess
    import h5py
    result = tmp_path / "r.h5"
    smooth_result.save(result)
    pred_path = tmp_path / "p.h5"
    out = subprocess.run([fiberlab_binary, "predict", str(result), "--model", "exact", "--set", "absorption=chord",
                          "-o", str(pred_path)], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    loaded = fiberlab.load(pred_path)
    assert isinstance(loaded, fiberlab.Prediction) and loaded.model == "exact"
    np.testing.assert_array_equal(loaded.probability, exact_prediction(smooth_result).probability)
    assert fiberlab.compare(smooth_result, loaded).accepted
    with h5py.File(pred_path, "r") as f:
        assert f.attrs["format"] == "fiber-prediction"
        assert f.attrs["lobe_names"] == "R,TT,TRT,p>=3"
        assert f.attrs["channel_names"] == "c0,c1"
        assert f["prediction/probability"].attrs["units"] == "probability"
        assert f["prediction/probability"].attrs["dimensions"] == "incidence,lobe,theta,phi,channel"
        assert f["bins/solid_angle"].attrs["units"] == "steradians"
