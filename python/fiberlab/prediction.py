"""A model's bin probabilities for a result's (or a config's) histogram:
fiberlab.predict() for the analytic models, Prediction(probability=...,
like=result) for a researcher's own model computed in NumPy."""
import numpy as np

from . import _fiberlab
from ._config import to_settings


def _set_value(value):
    """A keyword parameter in the `fiberlab predict --set KEY=VALUE` syntax."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        raise _fiberlab.Error("parameter value %r: give the option's name (e.g. absorption='chord')" % value)
    if np.ndim(value) == 0:
        return repr(float(value)) if not isinstance(value, (int, np.integer)) else str(int(value))
    return ",".join(_set_value(v) for v in np.asarray(value).ravel().tolist())


class Prediction:
    """Bin probabilities, (K, L, n_theta, n_phi, C) in the result's order.

    Prediction(probability=ARRAY, like=result) wraps a model of your own:
    ARRAY must have result.mean's shape and hold each bin's probability
    (the integral of your density over the bin, not the density itself).
    """

    def __init__(self, probability, like=None, model="user", params=None, alpha=None,
                 theta_i=None, phi_i=None, theta_edges=None, phi_edges=None):
        probability = np.ascontiguousarray(probability, dtype=np.float64)
        if like is not None:
            shape = like.mean.shape
            if probability.shape != shape:
                raise _fiberlab.Error("probability has shape %s, the result's histogram %s "
                                      "(K, lobes, n_theta, n_phi, channels)" % (probability.shape, shape))
            theta_i, phi_i = like.theta_i, like.phi_i
            theta_edges, phi_edges = like.theta_edges, like.phi_edges
        elif probability.ndim != 5:
            raise _fiberlab.Error("probability must be 5-dimensional (K, lobes, n_theta, n_phi, channels)")
        self.probability = probability
        self.model = model
        self.params = dict(params or {})
        self.alpha = list(alpha) if alpha is not None else [0.0]  # theta_r shift per lobe, radians
        self.theta_i, self.phi_i = theta_i, phi_i
        self.theta_edges, self.phi_edges = theta_edges, phi_edges

    @property
    def lobe_names(self):
        return list(_fiberlab.lobe_names(self.probability.shape[1]))

    @property
    def density(self):
        """Probability per steradian (needs the bin edges)."""
        omega = (np.diff(np.sin(self.theta_edges))[:, None] * np.diff(self.phi_edges)[None, :])
        return self.probability / omega[None, None, :, :, None]

    def __repr__(self):
        return "<fiberlab.Prediction %s, shape %s>" % (self.model, self.probability.shape)


def predict(result_or_config, model, **params):
    """The bin probabilities of analytic model `model` ("exact", "deon2011",
    "marschner2003"; see fiberlab.model_names()) for the histogram of a Result
    or a config (path or dict). Parameters default to the fiber's
    (compare/model_defaults.h); keyword arguments override them with the keys
    and units of `fiberlab predict --set` (angles in degrees, lists per lobe),
    e.g. predict(result, "deon2011", beta_long=[5, 2.5, 10], absorption="chord").
    """
    settings = to_settings(result_or_config)
    sets = ["%s=%s" % (key, _set_value(value)) for key, value in params.items()]
    d = _fiberlab.predict(settings, model, sets)
    return Prediction(d["probability"], model=model, params=d["params"], alpha=d["alpha"],
                      theta_i=d["theta_i"], phi_i=d["phi_i"], theta_edges=d["theta_edges"],
                      phi_edges=d["phi_edges"])


SUPPORTED_FORMAT_VERSION = 2  # common/result_layout.h kFormatVersion (2 changed result files only)


def load_prediction(path):
    """A `fiberlab predict` file (docs/FILE_FORMAT.md) as a Prediction."""
    import h5py
    with h5py.File(path, "r") as f:
        version = int(f.attrs.get("format_version", 0))
        if version < 1 or version > SUPPORTED_FORMAT_VERSION:
            raise _fiberlab.Error("%s: format_version %d is not supported (this fiberlab reads 1 to %d)"
                                  % (path, version, SUPPORTED_FORMAT_VERSION))
        if "prediction/probability" not in f:
            raise _fiberlab.Error("%s: no /prediction/probability dataset" % path)
        group = f["prediction"]
        text = lambda v: v.decode() if isinstance(v, bytes) else v
        params = {k: (text(v) if isinstance(v, (bytes, str)) else np.asarray(v).tolist())
                  for k, v in group.attrs.items() if k not in ("model",)}
        alpha = np.atleast_1d(group.attrs["alpha"]).tolist() if "alpha" in group.attrs else [0.0]
        return Prediction(group["probability"][...], model=text(group.attrs.get("model", "unknown")),
                          params=params, alpha=alpha, theta_i=f["source/theta_i"][...],
                          phi_i=f["source/phi_i"][...], theta_edges=f["bins/theta_edges"][...],
                          phi_edges=f["bins/phi_edges"][...])
