"""fiberlab.fit is `fiberlab compare --fit` (compare/fit.h), bound, not a
second fit: it recovers a known width from a fiber d'Eon 2011 describes
exactly, and gives the numbers the command prints for the same file."""
import re
import subprocess

import numpy as np
import pytest

import fiberlab

# The exit blur is d'Eon 2011's own roughness (SPEC s3): with the switches
# below, deon2011 is this fiber's exact model, so the fitted beta_long must
# land on the configured 6 deg within its error.
BLUR = {
    "fiber": {"eta": 1.55, "sigma_a": 0.4},
    "roughness": {"model": "exit_blur", "beta_long": [6, 6, 6], "beta_azim": [6, 6, 6]},
    "source": {"theta_i": [30], "phi_i": 0},
    "tally": {"n_theta": 45, "n_phi": 36, "lobes": 3},
}
SWITCHES = {"n_theta_d": "specular", "r_fresnel": "per_h", "absorption": "chord"}


@pytest.fixture(scope="module")
def blur_result():
    return fiberlab.run(BLUR, photons=100_000, seed=4, progress=False)


@pytest.fixture(scope="module")
def blur_fit(blur_result):
    return fiberlab.fit(blur_result, "deon2011", ["beta_long"], beta_long=9, **SWITCHES)


def test_fit_recovers_the_configured_width(blur_fit):
    f = blur_fit
    assert f.converged
    assert f.keys == ["beta_long"]
    assert f.start["beta_long"] == pytest.approx(9)
    # Five standard errors (plus the model's 1e-4 relative quadrature error).
    assert abs(f.values["beta_long"] - 6.0) <= 5 * f.errors["beta_long"] + 1e-3
    assert f.chi2_after < f.chi2_before
    assert f.dof == f.residuals - 1
    np.testing.assert_allclose(f.params["beta_long"], [f.values["beta_long"]] * len(f.params["beta_long"]))
    assert isinstance(f.params["lobes"], int)
    assert not f.at_bound["beta_long"]
    # The per-lobe verdict after the fit accepts the model.
    assert f.after.accepted
    assert {r["verdict"] for r in f.table.to_dict("records")} <= {"accepted", "not judged"}
    assert not f.before.accepted  # 9 deg instead of 6 is seen


def test_fitted_params_feed_predict(blur_result, blur_fit):
    """predict(result, model, **fit.params) is the fitted model: its
    comparison is fit.after."""
    c = fiberlab.compare(blur_result, fiberlab.predict(blur_result, "deon2011", **blur_fit.params))
    for a, b in zip(c.records, blur_fit.after.records):
        assert a["chi2"] == pytest.approx(b["chi2"], rel=1e-9)


def test_fit_gives_what_the_command_prints(blur_result, blur_fit, fiberlab_binary, tmp_path):
    path = tmp_path / "blur.h5"
    blur_result.save(path)
    sets = sum((["--set", "%s=%s" % kv] for kv in dict(SWITCHES, beta_long=9).items()), [])
    out = subprocess.run([fiberlab_binary, "compare", str(path), "--model", "deon2011", "--fit", "beta_long"] + sets,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode in (0, 1), out.stderr
    m = re.search(r"^\s+beta_long\s+(\S+) ->\s+(\S+) \+- (\S+)", out.stdout, re.M)
    assert m, out.stdout
    start, value, error = map(float, m.groups())
    assert start == pytest.approx(9)
    assert value == pytest.approx(blur_fit.values["beta_long"], rel=1e-5)
    assert error == pytest.approx(blur_fit.errors["beta_long"], rel=1e-2)
    m = re.search(r"chi2/dof (\S+) -> (\S+) \(dof (\d+)\)", out.stdout)
    assert int(m.group(3)) == blur_fit.dof
    assert float(m.group(2)) == pytest.approx(blur_fit.chi2_per_dof, rel=1e-3)


@pytest.mark.parametrize("keys, word", [
    (["beta_long", "beta_long"], "twice"), ([], "at least one"), (["bogus"], "bogus"),
    ("alpha", "alpha"), ([3], "keys must be"),
])
def test_bad_fit_keys_are_refused(blur_result, keys, word):
    with pytest.raises(fiberlab.Error, match=word):
        fiberlab.fit(blur_result, "deon2011", keys)


def test_fit_refuses_a_non_result(blur_fit):
    with pytest.raises(fiberlab.Error, match="Result"):
        fiberlab.fit(blur_fit, "deon2011", ["beta_long"])


def test_progress_gets_the_commands_lines_and_an_exception_in_it_stops_the_fit(blur_result):
    """An exception in progress (as a KeyboardInterrupt from Ctrl-C, which is
    checked at the same point of every iteration) ends the fit with it."""
    lines = []
    fiberlab.fit(blur_result, "deon2011", ["beta_long"], beta_long=9, progress=lines.append, **SWITCHES)
    assert lines and all(isinstance(line, str) for line in lines)

    class Stop(Exception):
        pass

    def stop(line):
        raise Stop(line)

    with pytest.raises(Stop):
        fiberlab.fit(blur_result, "deon2011", ["beta_long"], beta_long=9, progress=stop, **SWITCHES)


def test_a_fit_of_one_lobe_takes_that_lobes_bins_and_recovers_the_width(blur_result, blur_fit):
    """lobes=["TT"] is `compare --fit-lobes TT`: the fit sees TT's bins alone
    (fewer residuals than the joint fit), still recovers the configured
    6 deg (the model is exact for this fiber in every lobe), and says how it
    stopped."""
    f = fiberlab.fit(blur_result, "deon2011", ["beta_long"], beta_long=9, lobes=["TT"], **SWITCHES)
    assert 0 < f.residuals < blur_fit.residuals
    assert abs(f.values["beta_long"] - 6.0) <= 5 * f.errors["beta_long"] + 1e-3
    assert f.outcome in ("converged", "at a bound", "not converged")
    assert f.converged == (f.outcome != "not converged")
    assert f.stop_reason


@pytest.mark.parametrize("lobes", [["TX"], [1], "p>=9"])
def test_bad_fit_lobes_are_refused(blur_result, lobes):
    with pytest.raises(fiberlab.Error, match="lobe"):
        fiberlab.fit(blur_result, "deon2011", ["beta_long"], lobes=lobes)
