"""fiberlab.fit(): the fit of `fiberlab compare --fit` (compare/fit.h:
weighted least squares, Levenberg-Marquardt, on the comparison's normalised
residuals), run by the C++ library, with the verdicts before and after it."""
import dataclasses

import numpy as np

from . import _fiberlab
from ._checks import count_argument, instance_argument
from .comparison import DEFAULTS, Comparison, _options
from .prediction import settings_overrides


@dataclasses.dataclass(frozen=True)
class Fit:
    """What `fiberlab compare --fit` prints, as values.

    values, errors, errors_unscaled, start, at_bound: {key: ...} in the
    key's units (degrees for angles). errors are scaled by
    sqrt(max(1, chi2/dof)) (compare/fit.h); at_bound: the value sits on an
    end of the key's range (its error is then the curvature's only).
    chi2_before, chi2_after: the fit's chi-square at the start and at the
    minimum, over `residuals` normalised residuals (dof = residuals - keys).
    params: every model parameter at the minimum, as predict() takes them
    (predict(result, model, **fit.params) is the fitted model).
    before, after: the per-lobe Comparisons with the start and the fitted
    parameters (their .table is the per-lobe table).
    outcome: "converged", "at a bound", "not converged" or "not fitted" (no
    key changes the fitted bins' prediction: values at their start, errors
    NaN, compare/fit.h NotFitted); stop_reason: the test that ended the fit,
    in one line.
    lobe_fits: with fit(..., per_lobe=True), each lobe's own fit as `compare
    --per-lobe` prints it, {lobe name: Fit} in lobe order (its keys the
    lobe's own, beta_long[p]; its before and after that lobe's rows); empty
    otherwise. lobe: the lobe index of a per-lobe Fit (None for the joint
    one). lobe_table: the per-lobe fits, one row per lobe and key."""
    model: str
    keys: list
    values: dict
    errors: dict
    errors_unscaled: dict
    start: dict
    at_bound: dict
    chi2_before: float
    chi2_after: float
    residuals: int
    dof: int
    iterations: int
    evaluations: int
    converged: bool
    outcome: str
    stop_reason: str
    params: dict
    params_start: dict
    before: Comparison
    after: Comparison
    lobe: int = None
    lobe_fits: dict = dataclasses.field(default_factory=dict)

    @property
    def chi2_per_dof(self):
        return self.chi2_after / self.dof if self.dof > 0 else 0.0

    @property
    def table(self):
        """The per-lobe table after the fit (self.after.table)."""
        return self.after.table

    @property
    def lobe_table(self):
        """The per-lobe fits (per_lobe=True), one row per lobe and fitted key
        (one row per lobe when one key is fitted): lobe, lobe_name, key (the
        lobe's own, e.g. beta_long[1]), start, value, error, error_unscaled,
        at_bound, chi2_before, chi2_after, residuals, dof, chi2_per_dof_before,
        chi2_per_dof_after, iterations, evaluations, converged, outcome,
        stop_reason. A pandas DataFrame when pandas is installed, else the
        list of dicts."""
        records = []
        for name, f in self.lobe_fits.items():
            for key in f.keys:
                records.append({
                    "lobe": f.lobe, "lobe_name": name, "key": key, "start": f.start[key],
                    "value": f.values[key], "error": f.errors[key], "error_unscaled": f.errors_unscaled[key],
                    "at_bound": f.at_bound[key], "chi2_before": f.chi2_before, "chi2_after": f.chi2_after,
                    "residuals": f.residuals, "dof": f.dof,
                    "chi2_per_dof_before": f.chi2_before / f.dof if f.dof > 0 else 0.0,
                    "chi2_per_dof_after": f.chi2_per_dof, "iterations": f.iterations,
                    "evaluations": f.evaluations, "converged": f.converged, "outcome": f.outcome,
                    "stop_reason": f.stop_reason})
        try:
            import pandas
        except ImportError:
            return records
        return pandas.DataFrame.from_records(records)

    def __repr__(self):
        values = ", ".join("%s = %.6g +- %.2g" % (k, self.values[k], self.errors[k]) for k in self.keys)
        of = "" if self.lobe is None else " of lobe %d" % self.lobe
        lobes = " (and %d per-lobe fits)" % len(self.lobe_fits) if self.lobe_fits else ""
        return "<fiberlab.Fit%s %s: %s; chi2 %.6g -> %.6g (dof %d), %s%s>" % (
            of, self.model, values, self.chi2_before, self.chi2_after, self.dof,
            self.outcome, lobes)


def _fit_from(d, model, lobe=None):
    """A Fit of the binding's dict (python/src/fit_binding.cpp)."""
    per_key = lambda name: dict(zip(d["keys"], d[name]))
    return Fit(model=model, keys=list(d["keys"]), values=per_key("value"), errors=per_key("error"),
               errors_unscaled=per_key("error_unscaled"), start=per_key("start"),
               at_bound=per_key("at_bound"), chi2_before=d["chi2_start"], chi2_after=d["chi2"],
               residuals=d["residuals"], dof=d["dof"], iterations=d["iterations"],
               evaluations=d["evaluations"], converged=d["converged"], outcome=d["outcome"],
               stop_reason=d["stop_reason"], params=dict(d["params"]),
               params_start=dict(d["params_start"]), before=Comparison(d["before"], model),
               after=Comparison(d["after"], model), lobe=lobe,
               lobe_fits={lf["lobe_name"]: _fit_from(lf, model, lf["lobe"]) for lf in d.get("lobe_fits", [])})


def fit(result, model, keys, max_chi2=None, min_effective=DEFAULTS["min_effective"],
        model_error=DEFAULTS["model_error"], min_energy=DEFAULTS["min_energy"],
        max_iterations=DEFAULTS["max_iterations"], lobes=None, progress=None, per_lobe=False,
        fit_settings=None, **fixed):
    """Fits `keys` of analytic model `model` to a Result, as `fiberlab compare
    RESULT --model MODEL --fit KEYS --set KEY=VALUE...` does. keys: a list
    (or a comma-separated string) of the model's numeric keys: eta,
    beta_long (one value for every lobe), beta_long[1] (one lobe's entry),
    scale_tilt, ...; `fiberlab models` lists them. **fixed: other
    parameters held at the given values (predict()'s keywords, degrees).
    max_chi2, min_effective, model_error, min_energy: as compare().
    lobes: the lobes whose bins the fit takes (names such as ["TRT"] or
    "R,TT", as `compare --fit-lobes`); None: every lobe.
    progress: a callable getting the CLI's line per iteration (None: quiet).
    per_lobe: True also fits each lobe (of `lobes`; every lobe when None)
    alone after the joint fit, from the same start, as `compare --fit KEYS
    --per-lobe`: a per-lobe key (beta_long, beta_azim, alpha, scale_tilt of a
    model with per-lobe shifts) becomes the lobe's own entry, scalars are
    fitted to that lobe's bins (compare/fit.h per_lobe_keys); the result's
    lobe_fits and lobe_table hold them.
    fit_settings: a dict of the model's parameters applied only while
    fitting, as `compare --fit-set KEY=VALUE` (e.g. {"quadrature_points":
    2**19} fits huang2022 at a cheap quadrature); params, before and after
    are at the judged parameters (without them), chi2_before and
    chi2_after are the fit's own (with them). A fitted key, a key the
    simulated fiber sets (eta, sigma_a, ...) or an unknown key is refused.
    Ctrl-C stops a fit at the next iteration (KeyboardInterrupt).
    """
    from .result import Result
    instance_argument("result", result, Result, "a fiberlab.Result (fiberlab.run or fiberlab.load)")
    if not isinstance(model, str):
        raise _fiberlab.Error("model must be a model name (%s), not %s"
                              % (", ".join(_fiberlab.model_names()), type(model).__name__))
    if isinstance(keys, str):
        keys = [k.strip() for k in keys.split(",")]
    if not isinstance(keys, (list, tuple)) or not all(isinstance(k, str) for k in keys):
        raise _fiberlab.Error("keys must be a list of the model's parameter names (e.g. [\"beta_long\"])")
    max_iterations = count_argument("max_iterations", max_iterations, 1, 10000)
    if lobes is None:
        lobes = []
    elif isinstance(lobes, str):
        lobes = [n.strip() for n in lobes.split(",")]
    if not isinstance(lobes, (list, tuple)) or not all(isinstance(n, str) for n in lobes):
        raise _fiberlab.Error("lobes must be None or a list of lobe names (e.g. [\"TRT\"])")
    if not isinstance(per_lobe, (bool, np.bool_)):
        raise _fiberlab.Error("per_lobe must be True or False, not %r" % (per_lobe,))
    if fit_settings is None:
        fit_settings = {}
    if not isinstance(fit_settings, dict) or not all(isinstance(k, str) for k in fit_settings):
        raise _fiberlab.Error("fit_settings must be None or a dict of the model's parameters "
                              "(e.g. {\"quadrature_points\": 524288}), not %r" % (fit_settings,))
    if progress is not None and not callable(progress):
        raise _fiberlab.Error("progress must be None or a callable(line)")
    d = _fiberlab.fit(result._file, model, list(keys), settings_overrides(fixed),
                      *_options(max_chi2, min_effective, model_error, min_energy), max_iterations, list(lobes),
                      bool(per_lobe), progress, settings_overrides(fit_settings))
    return _fit_from(d, model)
