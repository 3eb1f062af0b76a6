"""fiberlab.compare(): is a prediction right for a simulated fiber, where, and
by how much? The statistics are compare/comparison.h's (chi-square with the
Monte Carlo's own standard errors over bins with S1^2/S2 >= 30, the rest
pooled; marginals; L1; centroids) and the verdict is compare/verdict.h's
(a judged lobe is accepted when chi2/dof <= 1 + 5 sqrt(2/dof), or
max_chi2), both computed by the C++ library as by `fiberlab compare`."""
import numpy as np

from . import _fiberlab
from ._checks import instance_argument, real_argument


def _same(a, b):
    return a is None or b is None or (np.shape(a) == np.shape(b) and np.allclose(a, b, equal_nan=True))


class Comparison:
    """accepted: every judged lobe accepted (the exit status 0 of `fiberlab
    compare`). records: one dict per (incident direction, lobe, channel),
    keyed as `fiberlab compare --report`'s metrics.json, with `verdict` the
    word the command prints: "accepted", "rejected" or "not judged" (a lobe
    with less than min_energy on both sides); `accepted` is true for judged,
    accepted lobes only. table: the records as a pandas DataFrame when
    pandas is installed, else the list itself."""

    def __init__(self, verdict, model):
        self.records = list(verdict["rows"])
        self.model = model
        self.judged = int(verdict["judged"])
        self.rejected_count = int(verdict["rejected"])
        self.accepted = bool(verdict["all_accepted"])
        self.criterion = verdict["criterion"]

    @property
    def table(self):
        try:
            import pandas
        except ImportError:
            return self.records
        return pandas.DataFrame.from_records(self.records)

    def _repr_html_(self):
        """The table in a notebook."""
        table = self.table
        return table.to_html() if hasattr(table, "to_html") else None

    @property
    def rejected(self):
        """The records of the judged lobes that were not accepted."""
        return [r for r in self.records if r["verdict"] == "rejected"]

    def __repr__(self):
        return "<fiberlab.Comparison %s: %d of %d judged lobes accepted (%s)>" % (
            self.model, self.judged - self.rejected_count, self.judged, self.criterion)


# The defaults of `fiberlab compare`'s flags (compare::Options, app::kFitIterations).
DEFAULTS = _fiberlab.comparison_defaults


def _options(max_chi2, min_effective, model_error, min_energy):
    return (None if max_chi2 is None else real_argument("max_chi2", max_chi2, "a number > 0, or None"),
            real_argument("min_effective", min_effective, "a number > 0"),
            real_argument("model_error", model_error, "a relative error >= 0"),
            real_argument("min_energy", min_energy, "a fraction in [0, 1)"))


def compare(result, prediction, max_chi2=None, min_effective=DEFAULTS["min_effective"],
            model_error=DEFAULTS["model_error"], min_energy=DEFAULTS["min_energy"]):
    """Compares a Result with a Prediction (or a bare probability array of the
    result's shape). max_chi2: accept a lobe when chi2/dof <= max_chi2 instead
    of the default 1 + 5 sqrt(2/dof); min_effective: S1^2/S2 a bin needs to be
    compared on its own; model_error: relative error assumed for the model's
    bin probabilities; min_energy: lobes with less energy on both sides are
    not judged (the flags of `fiberlab compare`, checked as it checks them)."""
    from .prediction import Prediction
    from .result import Result
    instance_argument("result", result, Result, "a fiberlab.Result (fiberlab.run or fiberlab.load)")
    if isinstance(prediction, Result):
        raise _fiberlab.Error("prediction must be a fiberlab.Prediction (fiberlab.predict) or a probability "
                              "array, not a Result")
    if not isinstance(prediction, Prediction):
        prediction = Prediction(prediction, like=result)
    for name in ("theta_edges", "phi_edges", "theta_i", "phi_i"):
        if not _same(getattr(prediction, name), getattr(result, name)):
            raise _fiberlab.Error("prediction %s differs from the result's: predict for this result "
                                  "(fiberlab.predict(result, ...))" % name)
    verdict = _fiberlab.compare(result._file, prediction.probability, list(np.radians(prediction.alpha)),
                                *_options(max_chi2, min_effective, model_error, min_energy))
    return Comparison(verdict, prediction.model)
