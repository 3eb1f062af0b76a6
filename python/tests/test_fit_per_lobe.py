"""fiberlab.fit(..., per_lobe=True) is `fiberlab compare --fit KEYS
--per-lobe` (app/fit.h fit_each_lobe), bound, not a second fit: on a fiber
whose lobes have different widths it recovers each lobe's own width where
one joint width cannot fit them all, and it gives the numbers the command
prints for the same file, lobe by lobe."""
import re
import subprocess

import numpy as np
import pytest

import fiberlab

# The exit blur with a width per lobe (SPEC s3: "beta_long and beta_azim may
# be lists indexed by p"; lobe p's theta-marginal is exactly d'Eon's
# M_p(v_p, ...)): with these switches deon2011 is this fiber's exact model
# when each lobe has its own beta_long[p].
WIDTHS = [4.0, 7.0, 10.0]
BLUR = {
    "fiber": {"eta": 1.55, "sigma_a": 0.4},
    "roughness": {"model": "exit_blur", "beta_long": WIDTHS, "beta_azim": [6, 6, 6]},
    "source": {"theta_i": [30], "phi_i": 0},
    "tally": {"n_theta": 45, "n_phi": 36, "lobes": 3},
}
SWITCHES = {"n_theta_d": "specular", "r_fresnel": "per_h", "absorption": "chord"}
START = 9.0


@pytest.fixture(scope="module")
def widths_result():
    return fiberlab.run(BLUR, photons=100_000, seed=4, progress=False)


@pytest.fixture(scope="module")
def widths_fit(widths_result):
    return fiberlab.fit(widths_result, "deon2011", ["beta_long"], beta_long=START, per_lobe=True, **SWITCHES)


def test_each_lobe_recovers_its_own_width(widths_fit):
    f = widths_fit
    assert list(f.lobe_fits) == ["R", "TT", "p>=2"]
    for p, (name, lf) in enumerate(f.lobe_fits.items()):
        key = "beta_long[%d]" % p
        assert lf.lobe == p and lf.keys == [key]
        assert lf.converged and not lf.at_bound[key]
        assert lf.start[key] == pytest.approx(START)  # from the joint fit's start, as --per-lobe
        # Five standard errors (plus the model's 1e-4 relative quadrature error).
        assert abs(lf.values[key] - WIDTHS[p]) <= 5 * lf.errors[key] + 1e-3, (name, lf)
        # The fitted model's width of lobe p (a list's last entry applies to
        # every larger p) is the fitted value.
        widths = lf.params["beta_long"]
        assert widths[min(p, len(widths) - 1)] == pytest.approx(lf.values[key])
        # Its verdicts are that lobe's rows only; the model is accepted there.
        assert {r["lobe"] for r in lf.before.records} == {p} == {r["lobe"] for r in lf.after.records}
        assert lf.after.accepted
    # One width for every lobe cannot be all three: the joint fit is rejected.
    assert not f.after.accepted


def test_a_lobe_fits_params_predict_its_lobe_as_fitted_and_the_others_as_the_start(widths_result, widths_fit):
    """The start has one beta_long for every lobe (START); each lobe fit's
    params hold the full per-lobe list (compare/fit.h fit_each_lobe), so
    predict(**lf.params) is the fitted model on that lobe (its chi-square is
    the fit's after-fit one, lobe by lobe) and the start on every other lobe."""
    start = fiberlab.predict(widths_result, "deon2011", **widths_fit.params_start).probability
    for name, lf in widths_fit.lobe_fits.items():
        p = lf.lobe
        assert len(lf.params["beta_long"]) == len(WIDTHS), (name, lf.params["beta_long"])
        fitted = fiberlab.predict(widths_result, "deon2011", **lf.params)
        others = [q for q in range(len(WIDTHS)) if q != p]
        assert np.array_equal(fitted.probability[:, others], start[:, others]), name
        assert not np.array_equal(fitted.probability[:, p], start[:, p]), name  # the fit moved its lobe
        rows = [r for r in fiberlab.compare(widths_result, fitted).records if r["lobe"] == p]
        assert [(r["k"], r["channel"], r["dof"]) for r in rows] == \
            [(r["k"], r["channel"], r["dof"]) for r in lf.after.records]
        assert [r["chi2"] for r in rows] == pytest.approx([r["chi2"] for r in lf.after.records], rel=1e-9)


def test_lobe_table_has_a_row_per_lobe(widths_fit):
    table = widths_fit.lobe_table
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    assert [r["lobe_name"] for r in rows] == ["R", "TT", "p>=2"]
    for p, r in enumerate(rows):
        lf = widths_fit.lobe_fits[r["lobe_name"]]
        assert r["lobe"] == p and r["key"] == "beta_long[%d]" % p
        assert (r["value"], r["error"], r["dof"], r["outcome"]) == (lf.values[r["key"]], lf.errors[r["key"]],
                                                                   lf.dof, lf.outcome)
        assert r["chi2_per_dof_after"] == pytest.approx(lf.chi2_after / lf.dof)
        assert r["stop_reason"] == lf.stop_reason


def command_lobe_fits(stdout):
    """The numbers `compare --per-lobe` prints per lobe (compare/fit_text.cpp)."""
    fits = {}
    for name, text in re.findall(r"^per-lobe fit of (\S+):\n(.*?)(?=^per-lobe fit of |^\d+ of \d+ judged)",
                                 stdout, re.S | re.M):
        head = re.search(r"^fit \((\d+) residuals, (\d+) iterations, (\d+) model evaluations, "
                         r"(converged|at a bound|not converged): (.*)\):$", text, re.M)
        chi2 = re.search(r"chi2/dof (\S+) -> (\S+) \(dof (\d+)\)", text)
        keys = re.findall(r"^  (\S+)\s+(\S+) ->\s+(\S+) \+- (\S+) \S* ?\(unscaled (\S+)\)$", text, re.M)
        rows = re.findall(r"^  theta_i .* c\d: +(\S+) -> +(\S+)$", text, re.M)
        assert head and chi2 and keys and rows, text
        fits[name] = dict(residuals=int(head[1]), iterations=int(head[2]), evaluations=int(head[3]),
                          outcome=head[4], stop_reason=head[5], chi2_per_dof=(float(chi2[1]), float(chi2[2])),
                          dof=int(chi2[3]), keys=[(k, *map(float, v)) for k, *v in keys],
                          rows=[tuple(map(float, r)) for r in rows])
    return fits


def assert_same_as_command(fit, printed):
    assert list(printed) == list(fit.lobe_fits)
    for name, lf in fit.lobe_fits.items():
        c = printed[name]
        assert (c["residuals"], c["iterations"], c["evaluations"], c["dof"]) == \
            (lf.residuals, lf.iterations, lf.evaluations, lf.dof), name
        assert (c["outcome"], c["stop_reason"]) == (lf.outcome, lf.stop_reason), name
        assert c["chi2_per_dof"] == pytest.approx((lf.chi2_before / lf.dof, lf.chi2_per_dof), abs=6e-5, rel=1e-4)
        assert [k[0] for k in c["keys"]] == lf.keys
        for key, start, value, error, unscaled in c["keys"]:
            assert start == pytest.approx(lf.start[key], rel=1e-5)
            assert value == pytest.approx(lf.values[key], rel=1e-5)
            assert error == pytest.approx(lf.errors[key], rel=6e-3)
            assert unscaled == pytest.approx(lf.errors_unscaled[key], rel=6e-3)
        judged = [x for r, a in zip(lf.before.records, lf.after.records) if r["verdict"] != "not judged"
                  for x in (r["chi2_per_dof"], a["chi2_per_dof"])]
        assert [x for row in c["rows"] for x in row] == pytest.approx(judged, abs=6e-4, rel=1e-5), name


@pytest.mark.parametrize("lobes", [None, ["TT", "R"]])
def test_per_lobe_fit_gives_what_the_command_prints(widths_result, fiberlab_binary, tmp_path, lobes):
    path = tmp_path / "widths.h5"
    widths_result.save(path)
    sets = sum((["--set", "%s=%s" % kv] for kv in dict(SWITCHES, beta_long=START).items()), [])
    flags = [] if lobes is None else ["--fit-lobes", ",".join(lobes)]
    out = subprocess.run([fiberlab_binary, "compare", str(path), "--model", "deon2011", "--fit", "beta_long",
                          "--per-lobe"] + flags + sets, capture_output=True, text=True, timeout=300)
    assert out.returncode in (0, 1), out.stderr
    fit = fiberlab.fit(widths_result, "deon2011", ["beta_long"], beta_long=START, per_lobe=True, lobes=lobes,
                       **SWITCHES)
    assert list(fit.lobe_fits) == (lobes or ["R", "TT", "p>=2"])
    assert_same_as_command(fit, command_lobe_fits(out.stdout))


def test_without_per_lobe_there_are_no_lobe_fits(widths_result):
    f = fiberlab.fit(widths_result, "deon2011", ["beta_long"], beta_long=START, max_iterations=1, **SWITCHES)
    assert f.lobe_fits == {} and f.lobe is None
    assert len(f.lobe_table) == 0


@pytest.mark.parametrize("bad", ["yes", 1, 0, None, [True], 1.0])
def test_bad_per_lobe_is_refused(widths_result, bad):
    with pytest.raises(fiberlab.Error, match=r"^per_lobe must be True or False, not "):
        fiberlab.fit(widths_result, "deon2011", ["beta_long"], per_lobe=bad)


def test_a_lobe_fit_that_cannot_run_names_its_lobe(widths_result):
    """With min_effective above every bin's S1^2/S2, each lobe's bins pool
    into one residual per (direction, lobe, channel): the joint fit has three
    for its one key, the per-lobe fit of R one, too few, and says so (as the
    command does: "per-lobe fit of R: ...")."""
    with pytest.raises(fiberlab.Error, match=r"^per-lobe fit of R: .*1 residuals for 1 parameters"):
        fiberlab.fit(widths_result, "deon2011", ["beta_long"], beta_long=START, per_lobe=True,
                     min_effective=1e12, **SWITCHES)


def test_progress_names_each_lobe_and_an_exception_in_it_stops_the_per_lobe_fits(widths_result):
    """The per-lobe fits' progress lines start with the lobe's name, as the
    command's; an exception raised in progress during them (as Ctrl-C's
    KeyboardInterrupt) ends the whole fit with it."""
    lines = []
    fiberlab.fit(widths_result, "deon2011", ["beta_long"], beta_long=START, per_lobe=True, lobes=["TT"],
                 progress=lines.append, **SWITCHES)
    assert any(line.startswith("TT fit: iteration 1,") for line in lines), lines

    class Stop(Exception):
        pass

    def stop_in_lobe_fits(line):
        if line.startswith("TT "):
            raise Stop(line)

    with pytest.raises(Stop, match="^TT fit: "):
        fiberlab.fit(widths_result, "deon2011", ["beta_long"], beta_long=START, per_lobe=True,
                     progress=stop_in_lobe_fits, **SWITCHES)
