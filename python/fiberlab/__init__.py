"""fiberlab from Python: simulate a fiber, predict it with an analytic model,
compare the two, and read or write fiberlab's HDF5 files.

    import fiberlab
    result = fiberlab.run({"fiber": {"eta": 1.55, "sigma_a": 0.5},
                           "roughness": {"model": "smooth"},
                           "source": {"theta_i": [30]}}, photons=200_000, seed=1)
    result.mean, result.std_err        # (K, L, n_theta, n_phi, C): P = S1/N and its standard error
    pred = fiberlab.predict(result, "exact")
    cmp = fiberlab.compare(result, pred)
    cmp.accepted, cmp.table            # verdict, one row per (theta_i, phi_i, lobe, channel)
    fit = fiberlab.fit(result, "deon2011", ["beta_long"])

Every array is in the result file's index order (K incident directions, L
lobes, n_theta, n_phi, C channels); every angle a user passes or reads is in
degrees (as `fiberlab predict --set` and configs). The numbers come from the
C++ library (the same code as the `fiberlab` command); this package only
arranges them. Bad arguments, configs, files or parameters raise
fiberlab.Error (a ValueError) with a one-line message. The user guide is
docs/PYTHON.md.
"""
from ._fiberlab import Error, software_version
from .comparison import Comparison, compare
from .fit import Fit, fit
from .prediction import Prediction, predict
from .result import LobeEnergy, Marginals, Result, load, run

__version__ = software_version
__all__ = ["Error", "Result", "LobeEnergy", "Marginals", "Prediction", "Comparison", "Fit",
           "run", "load", "predict", "compare", "fit", "model_names", "__version__"]


def model_names():
    """The analytic models predict() knows: "exact", "deon2011", "marschner2003", ..."""
    from ._fiberlab import model_names as names
    return list(names())
