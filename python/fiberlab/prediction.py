"""A model's bin probabilities for a result's (or a config's) histogram:
fiberlab.predict() for the analytic models, Prediction(probability=...,
like=result) for a researcher's own model computed in NumPy. Angles in
degrees, as everywhere in the package."""
import numbers

import numpy as np

from . import _fiberlab
from ._checks import path_argument
from ._config import to_settings
from .labelled import to_xarray


def _set_value(key, value):
    """A keyword parameter in the `fiberlab predict --set KEY=VALUE` syntax
    (repr of a float: the shortest text that reads back as the same double)."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        raise _fiberlab.Error("parameter %s = %r: give the option's name (e.g. absorption='chord')" % (key, value))
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    try:
        items = np.asarray(value).ravel().tolist()
    except Exception:
        items = None
    if not items or np.ndim(value) == 0 or any(isinstance(v, (str, bool, list)) for v in items):
        raise _fiberlab.Error("parameter %s = %r: must be a number, a list of numbers or an option's name"
                              % (key, value))
    return ",".join(_set_value(key, v) for v in items)


def settings_overrides(params):
    """keyword arguments -> ["KEY=VALUE", ...] as --set takes them."""
    return ["%s=%s" % (key, _set_value(key, value)) for key, value in params.items()]


class Prediction:
    """Bin probabilities, (K, L, n_theta, n_phi, C) in the result's order.

    Prediction(probability=ARRAY, like=result) wraps a model of your own:
    ARRAY must have result.mean's shape and hold each bin's probability
    (the integral of your density over the bin, not the density itself);
    alpha: the per-lobe theta_r shift of your model, degrees (used for the
    centroid columns of compare()).
    """

    def __init__(self, probability, like=None, model="user", params=None, alpha=None,
                 theta_i=None, phi_i=None, theta_edges=None, phi_edges=None, channel_names=None,
                 lobe_names=None, _from_model=False):
        try:
            probability = np.ascontiguousarray(probability, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise _fiberlab.Error("probability must be an array of numbers: %s" % e) from None
        if like is not None:
            if not hasattr(like, "mean") or not hasattr(like, "theta_edges"):
                raise _fiberlab.Error("like must be a fiberlab.Result, not %s" % type(like).__name__)
            shape = like.mean.shape
            if probability.shape != shape:
                raise _fiberlab.Error("probability has shape %s, the result's histogram %s "
                                      "(K, lobes, n_theta, n_phi, channels)" % (probability.shape, shape))
            theta_i, phi_i = like.theta_i, like.phi_i
            theta_edges, phi_edges = like.theta_edges, like.phi_edges
            channel_names = like.channel_names
            lobe_names = like.lobe_names
        elif probability.ndim != 5:
            raise _fiberlab.Error("probability must be 5-dimensional (K, lobes, n_theta, n_phi, channels)")
        if not np.all(np.isfinite(probability)):
            raise _fiberlab.Error("probability holds a NaN or infinite value")
        # A probability of your own must not be negative (as a --prediction
        # file's); an analytic model's bins are taken as the model gives them,
        # as `fiberlab compare --model` does.
        # Down to -probability_rounding is rounding (compare/prediction_file.h).
        if not _from_model and np.any(probability < -_fiberlab.probability_rounding):
            raise _fiberlab.Error("probability holds a negative value (a bin's probability is >= 0; down to "
                                  "-%g is taken as rounding)" % _fiberlab.probability_rounding)
        self.probability = probability
        self.model = model
        self.params = dict(params or {})
        self.alpha = [float(a) for a in np.atleast_1d(alpha)] if alpha is not None else [0.0]
        self.theta_i, self.phi_i = theta_i, phi_i
        self.theta_edges, self.phi_edges = theta_edges, phi_edges
        C = probability.shape[4]
        self.channel_names = list(channel_names) if channel_names is not None else ["c%d" % c for c in range(C)]
        L = probability.shape[1]
        if lobe_names is not None and len(lobe_names) != L:
            raise _fiberlab.Error("lobe_names has %d names, probability %d lobes" % (len(lobe_names), L))
        self._lobe_names = list(lobe_names) if lobe_names is not None else list(_fiberlab.lobe_names(L))

    @property
    def lobe_names(self):
        """R, TT, ..., p>=N; `scattered` last for a fiber with a medulla (docs/FUR.md)."""
        return list(self._lobe_names)

    @property
    def solid_angle(self):
        """(n_theta, n_phi) steradians: (sin theta_hi - sin theta_lo)(phi_hi - phi_lo)."""
        t, p = np.radians(self.theta_edges), np.radians(self.phi_edges)
        return np.diff(np.sin(t))[:, None] * np.diff(p)[None, :]

    @property
    def density(self):
        """Probability per steradian (needs the bin edges)."""
        return self.probability / self.solid_angle[None, None, :, :, None]

    @property
    def energy(self):
        """Lobe energies as Result.energy has them (a LobeEnergy): mean (K, L, C)
        is the sum of the lobe's bin probabilities; std_err is 0 (no Monte
        Carlo noise); absorbed = 1 - the lobes' sum (what the model absorbs,
        or does not place in any lobe); truncated, lost and roulette are 0 (a
        model traces no paths)."""
        from .result import LobeEnergy
        mean = self.probability.sum(axis=(2, 3))
        absorbed = 1.0 - mean.sum(axis=1)
        zero = np.zeros_like(absorbed)
        return LobeEnergy(mean, np.zeros_like(mean), absorbed, zero, zero.copy(), zero.copy())

    @property
    def marginals(self):
        """The theta_r and phi marginals as Result.marginals has them (a
        Marginals, standard errors 0)."""
        from .result import Marginals
        theta = self.probability.sum(axis=3)
        phi = self.probability.sum(axis=2)
        return Marginals(theta, np.zeros_like(theta), phi, np.zeros_like(phi))

    def to_xarray(self):
        """probability and density over (incidence, lobe, theta_r, phi,
        channel) and the lobe energies, labelled as Result.to_xarray()."""
        return to_xarray(self, {"probability": (self.probability, "1", "the model's probability of the bin"),
                                "density": (self.density, "sr^-1", "probability per steradian")},
                         {"energy": (self.energy.mean, "1", "the model's fraction of the weight in the lobe")},
                         {}, "fiberlab prediction, model %s" % self.model)

    def __repr__(self):
        return "<fiberlab.Prediction %s, shape %s>" % (self.model, self.probability.shape)


def predict(result_or_config, model, **params):
    """The bin probabilities of analytic model `model` (fiberlab.model_names())
    for the histogram of a Result or a config (path or dict). Parameters
    default to the fiber's (compare/model_defaults.h); keyword arguments
    override them with the keys and units of `fiberlab predict --set`
    (angles in degrees, lists per lobe), e.g.
    predict(result, "deon2011", beta_long=[5, 2.5, 10], absorption="chord").
    Prediction.params holds every parameter in the same units, so
    predict(result, model, **prediction.params) gives the same prediction.
    For a fiber with a medulla the last lobe is `scattered`, which no model
    predicts: its bins are zero, as in `fiberlab predict` and `fiberlab
    compare --model` (docs/FUR.md), so compare(result, predict(result, ...)) works.
    """
    if not isinstance(model, str):
        raise _fiberlab.Error("model must be a model name (%s), not %s"
                              % (", ".join(_fiberlab.model_names()), type(model).__name__))
    settings = to_settings(result_or_config)
    d = _fiberlab.predict(settings, model, settings_overrides(params))
    from .result import channel_names
    return Prediction(d["probability"], model=model, params=d["params"], alpha=np.degrees(d["alpha"]),
                      theta_i=np.degrees(d["theta_i"]), phi_i=np.degrees(d["phi_i"]),
                      theta_edges=np.degrees(d["theta_edges"]), phi_edges=np.degrees(d["phi_edges"]),
                      channel_names=channel_names(settings), lobe_names=d["lobe_names"], _from_model=True)


SUPPORTED_FORMAT_VERSION = 2  # common/result_layout.h kFormatVersion (2 changed result files only)


def _params_in_set_units(model, attrs):
    """A prediction file's parameter attributes (radians, docs/FILE_FORMAT.md)
    in predict()'s units: degrees for angles, int for integers."""
    try:
        units = dict(_fiberlab.param_units(model))
    except _fiberlab.Error:
        units = {}
    out = {}
    for key, value in attrs.items():
        if isinstance(value, bytes):
            value = value.decode()
        if isinstance(value, str):
            out[key] = value
            continue
        x = np.asarray(value)
        if units.get(key) == "deg":
            x = np.degrees(x)
        if units.get(key) == "integer" and x.size == 1:
            out[key] = int(x.ravel()[0])
        else:
            out[key] = x.tolist()
    return out


def load_prediction(path):
    """A `fiberlab predict` file (docs/FILE_FORMAT.md) as a Prediction."""
    import h5py
    path = path_argument("path", path)
    with h5py.File(path, "r") as f:
        version = int(f.attrs.get("format_version", 0))
        if version < 1 or version > SUPPORTED_FORMAT_VERSION:
            raise _fiberlab.Error("%s: format_version %d is not supported (this fiberlab reads 1 to %d)"
                                  % (path, version, SUPPORTED_FORMAT_VERSION))
        if "prediction/probability" not in f:
            raise _fiberlab.Error("%s: no /prediction/probability dataset" % path)
        group = f["prediction"]
        text = lambda v: v.decode() if isinstance(v, bytes) else v
        model = text(group.attrs.get("model", "unknown"))
        params = _params_in_set_units(model, {k: v for k, v in group.attrs.items() if k != "model"})
        alpha = np.degrees(np.atleast_1d(group.attrs["alpha"])) if "alpha" in group.attrs else [0.0]
        channels = text(f.attrs["channel_names"]).split(",") if "channel_names" in f.attrs else None
        lobes = text(f.attrs["lobe_names"]).split(",") if "lobe_names" in f.attrs else None
        return Prediction(group["probability"][...], model=model, params=params, alpha=alpha,
                          theta_i=np.degrees(f["source/theta_i"][...]), phi_i=np.degrees(f["source/phi_i"][...]),
                          theta_edges=np.degrees(f["bins/theta_edges"][...]),
                          phi_edges=np.degrees(f["bins/phi_edges"][...]), channel_names=channels,
                          lobe_names=lobes, _from_model=True)
