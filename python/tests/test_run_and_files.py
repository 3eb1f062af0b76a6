"""fiberlab.run from a dict, the estimators against the file's S1/S2, load/save."""
import h5py
import numpy as np
import pytest

import fiberlab
from conftest import SMOOTH_ABSORBING


def test_dict_config_runs_with_the_configs_settings(smooth_result):
    r = smooth_result
    assert r.mean.shape == (2, 4, 45, 72, 2)
    assert r.lobe_names == ["R", "TT", "TRT", "p>=3"]
    assert r.channel_names == ["c0", "c1"]
    np.testing.assert_allclose(r.theta_i, [0, 40])  # degrees
    assert list(r.photons) == [200_000, 200_000]
    assert r.config["fiber"]["sigma_a"] == [0.2, 0.5]
    assert r.seeds == [11]
    assert r.theta_edges.shape == (46,) and r.phi_edges.shape == (73,)


def test_estimators_equal_the_files_s1_s2(smooth_result, tmp_path):
    """mean, std_err, density and the lobe energies are SPEC s6's estimators
    of the saved file's S1, S2 and N, computed here with h5py alone."""
    path = tmp_path / "r.h5"
    smooth_result.save(path)
    with h5py.File(path, "r") as f:
        n = f["tally/photons"][:].astype(float)[:, None, None, None, None]
        s1, s2 = f["tally/weight_sum"][:], f["tally/weight_sq_sum"][:]
        omega = f["bins/solid_angle"][:][None, None, :, :, None]
        exited = f["ledger/exited"][:]
    p = s1 / n
    se = np.sqrt(np.maximum(s2 / n - p ** 2, 0) / (n - 1))
    np.testing.assert_allclose(smooth_result.mean, p, rtol=1e-14, atol=0)
    np.testing.assert_allclose(smooth_result.std_err, se, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(smooth_result.density, p / omega, rtol=1e-14)
    # Lobe energies: the ledger / N, errors from the lobe's summed S2.
    n3 = n[:, :, 0, 0, :]
    e = exited / n3
    se_lobe = np.sqrt(np.maximum(s2.sum(axis=(2, 3)) / n3 - e ** 2, 0) / (n3 - 1))
    np.testing.assert_allclose(smooth_result.energy.mean, e, rtol=1e-14)
    np.testing.assert_allclose(smooth_result.energy.std_err, se_lobe, rtol=1e-10)
    # Marginals: bin sums of S1 and S2 over the other angle.
    m = smooth_result.marginals
    np.testing.assert_allclose(m.theta, s1.sum(axis=3) / n[:, :, :, 0], rtol=1e-12)
    ps = s1.sum(axis=2) / n[:, :, 0]
    np.testing.assert_allclose(m.phi_std_err,
                               np.sqrt(np.maximum(s2.sum(axis=2) / n[:, :, 0] - ps ** 2, 0) / (n[:, :, 0] - 1)),
                               rtol=1e-10, atol=1e-300)


def test_ledger_balances(smooth_result):
    e = smooth_result.energy
    np.testing.assert_allclose(e.mean.sum(axis=1) + e.absorbed + e.truncated + e.lost, 1.0, rtol=1e-12)


def test_load_round_trips(smooth_result, tmp_path):
    path = tmp_path / "r.h5"
    smooth_result.save(path)
    back = fiberlab.load(path)
    for name in ("weight_sum", "weight_sq_sum", "count", "photons", "theta_edges", "phi_edges",
                 "theta_i", "phi_i", "mean", "std_err"):
        np.testing.assert_array_equal(getattr(back, name), getattr(smooth_result, name), err_msg=name)
    assert back.config == smooth_result.config
    assert back.seeds == smooth_result.seeds
    assert back.lobe_names == smooth_result.lobe_names


def test_saved_file_describes_itself(smooth_result, tmp_path):
    """docs/FILE_FORMAT.md: format, version, axis labels, units, names."""
    path = tmp_path / "r.h5"
    smooth_result.save(path)
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == "fiber-histogram"
        assert int(f.attrs["format_version"]) >= 1
        assert f.attrs["lobe_names"] == "R,TT,TRT,p>=3"
        assert f.attrs["channel_names"] == "c0,c1"
        assert f["tally/weight_sum"].attrs["dimensions"] == "incidence,lobe,theta,phi,channel"
        assert f["bins/theta_edges"].attrs["units"] == "radians"
        assert f["bins/solid_angle"].attrs["units"] == "steradians"


def test_run_is_reproducible_for_any_thread_count():
    small = dict(SMOOTH_ABSORBING, source={"theta_i": [30]})
    a = fiberlab.run(small, photons=20_000, seed=5, threads=1, progress=False)
    b = fiberlab.run(small, photons=20_000, seed=5, threads=2, progress=False)
    np.testing.assert_array_equal(a.weight_sum, b.weight_sum)


@pytest.mark.parametrize("config, words", [
    ({"fiber": {"eta": 0.5}}, ["fiber.eta", "must be in (1, 1e9]"]),
    ({"fibre": {}}, ["unknown key fibre"]),
    ({"source": {"theta_i": [95]}}, ["source.theta_i"]),
])
def test_bad_dict_config_raises_the_clis_one_line_message(config, words):
    with pytest.raises(ValueError) as e:
        fiberlab.run(config, photons=10, progress=False)
    assert isinstance(e.value, fiberlab.Error)
    for w in words:
        assert w in str(e.value)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("kwargs", [{"photons": 0}, {"photons": 1.5}, {"seed": -1}, {"threads": 0}])
def test_bad_run_arguments(kwargs):
    with pytest.raises(fiberlab.Error):
        fiberlab.run(SMOOTH_ABSORBING, progress=False, **kwargs)


def test_config_path_and_progress_callable(source_dir, tmp_path):
    calls = []
    r = fiberlab.run(f"{source_dir}/configs/smooth_circle.yaml", photons=2000, seed=1,
                     progress=lambda done, total: calls.append((done, total)))
    assert r.mean.shape[0] == 3
    assert calls[-1] == (6000, 6000)


def test_load_refuses_a_non_result(tmp_path):
    bad = tmp_path / "x.h5"
    bad.write_text("not hdf5")
    with pytest.raises(fiberlab.Error):
        fiberlab.load(bad)
