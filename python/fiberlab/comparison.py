"""fiberlab.compare(): is a prediction right for a simulated fiber, where, and
by how much? The statistics are compare/comparison.h's (chi-square with the
Monte Carlo's own standard errors over bins with S1^2/S2 >= 30, the rest
pooled; marginals; L1; centroids), computed by the C++ library; a lobe is
accepted when chi2/dof <= 1 + 5 sqrt(2/dof) (or max_chi2), as by
`fiberlab compare`."""
import numpy as np

from . import _fiberlab


def _same(a, b):
    return a is None or b is None or (np.shape(a) == np.shape(b) and np.allclose(a, b, equal_nan=True))


class Comparison:
    """accepted: every judged lobe accepted. records: one dict per
    (incident direction, lobe, channel), keyed as `fiberlab compare
    --report`'s metrics.json. table: the records as a pandas DataFrame when
    pandas is installed, else the list itself."""

    def __init__(self, records, model):
        self.records = records
        self.model = model
        self.accepted = all(r["accepted"] for r in records)

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
        return [r for r in self.records if r["judged"] and not r["accepted"]]

    def __repr__(self):
        judged = sum(r["judged"] for r in self.records)
        return "<fiberlab.Comparison %s: %d of %d judged lobes accepted>" % (
            self.model, judged - len(self.rejected), judged)


def compare(result, prediction, max_chi2=None, min_effective=30.0, model_error=1e-4, min_energy=1e-4):
    """Compares a Result with a Prediction (or a bare probability array of the
    result's shape). max_chi2: accept a lobe when chi2/dof <= max_chi2 instead
    of the default 1 + 5 sqrt(2/dof); min_effective: S1^2/S2 a bin needs to be
    compared on its own; model_error: relative error assumed for the model's
    bin probabilities; min_energy: lobes with less energy on both sides are
    not judged."""
    from .prediction import Prediction
    if not isinstance(prediction, Prediction):
        prediction = Prediction(prediction, like=result)
    for name in ("theta_edges", "phi_edges", "theta_i", "phi_i"):
        if not _same(getattr(prediction, name), getattr(result, name)):
            raise _fiberlab.Error("prediction %s differs from the result's: predict for this result "
                                  "(fiberlab.predict(result, ...))" % name)
    records = _fiberlab.compare(result._file, prediction.probability, prediction.alpha,
                                None if max_chi2 is None else float(max_chi2), float(min_effective),
                                float(model_error), float(min_energy))
    return Comparison(list(records), prediction.model)
