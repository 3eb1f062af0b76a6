"""A fiber with a medulla (docs/FUR.md) from Python: the extra lobe
`scattered` is named and shaped as the file holds it, the ledger closes, and
a bad medulla value is a fiberlab.Error naming the field."""
import h5py
import numpy as np
import pytest

import fiberlab

FUR = {
    "fiber": {"eta": 1.55, "sigma_a": [0.2, 0.5],
              "medulla": {"radius": 0.5, "sigma_s": 4.0, "sigma_a": [0.1, 0.3], "g": 0.5}},
    "roughness": {"model": "gaussian", "beta_long": 5.0},
    "source": {"theta_i": 30},
    "tally": {"n_theta": 18, "n_phi": 36, "lobes": 4},
}


def test_medulla_adds_the_scattered_lobe(tmp_path):
    r = fiberlab.run(FUR, photons=20_000, seed=3, progress=False)
    assert r.lobe_names == ["R", "TT", "TRT", "p>=3", "scattered"]
    assert r.mean.shape == (1, 5, 18, 36, 2)
    assert r.mean[0, 4].sum() > 0.05  # a medulla this size scatters much of TT
    path = tmp_path / "fur.h5"
    r.save(path)
    with h5py.File(path, "r") as f:
        assert f.attrs["lobe_names"] == "R,TT,TRT,p>=3,scattered"
        assert f["fiber/medulla"].attrs["radius"] == 0.5
        n = f["tally/photons"][0]
        total = f["ledger/exited"][0].sum(axis=0) + f["ledger/absorbed"][0] + f["ledger/truncated"][0]
        np.testing.assert_allclose(total, n, rtol=1e-12)


def test_bad_medulla_is_an_error_naming_the_field():
    bad = {**FUR, "fiber": {**FUR["fiber"], "medulla": {"radius": 1.5, "sigma_s": 1.0}}}
    with pytest.raises(fiberlab.Error, match=r"fiber\.medulla\.radius = 1\.5 is out of range"):
        fiberlab.run(bad, photons=10, progress=False)
