"""fiberlab.fit(): the fit of `fiberlab compare --fit` (compare/fit.h:
weighted least squares, Levenberg-Marquardt, on the comparison's normalised
residuals), run by the C++ library, with the verdicts before and after it."""
import dataclasses

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
    outcome: "converged", "at a bound" or "not converged"; stop_reason: the
    test that ended the fit, in one line (compare/fit.h)."""
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

    @property
    def chi2_per_dof(self):
        return self.chi2_after / self.dof if self.dof > 0 else 0.0

    @property
    def table(self):
        """The per-lobe table after the fit (self.after.table)."""
        return self.after.table

    def __repr__(self):
        values = ", ".join("%s = %.6g +- %.2g" % (k, self.values[k], self.errors[k]) for k in self.keys)
        return "<fiberlab.Fit %s: %s; chi2 %.6g -> %.6g (dof %d), %s>" % (
            self.model, values, self.chi2_before, self.chi2_after, self.dof,
            self.outcome)


def fit(result, model, keys, max_chi2=None, min_effective=DEFAULTS["min_effective"],
        model_error=DEFAULTS["model_error"], min_energy=DEFAULTS["min_energy"],
        max_iterations=DEFAULTS["max_iterations"], lobes=None, progress=None, **fixed):
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
    if progress is not None and not callable(progress):
        raise _fiberlab.Error("progress must be None or a callable(line)")
    d = _fiberlab.fit(result._file, model, list(keys), settings_overrides(fixed),
                      *_options(max_chi2, min_effective, model_error, min_energy), max_iterations, list(lobes),
                      progress)
    per_key = lambda name: dict(zip(d["keys"], d[name]))
    return Fit(model=model, keys=list(d["keys"]), values=per_key("value"), errors=per_key("error"),
               errors_unscaled=per_key("error_unscaled"), start=per_key("start"),
               at_bound=per_key("at_bound"), chi2_before=d["chi2_start"], chi2_after=d["chi2"],
               residuals=d["residuals"], dof=d["dof"], iterations=d["iterations"],
               evaluations=d["evaluations"], converged=d["converged"], outcome=d["outcome"],
               stop_reason=d["stop_reason"], params=dict(d["params"]),
               params_start=dict(d["params_start"]), before=Comparison(d["before"], model),
               after=Comparison(d["after"], model))
