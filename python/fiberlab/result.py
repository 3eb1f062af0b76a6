"""A simulation's result: fiberlab.run() and fiberlab.load() give one.

The estimators are those of SPEC section 6, computed by the C++ library
(sim::bin_estimate, sim::lobe_energy): P_b = S1_b / N, its standard error
sqrt((S2_b/N - P_b^2)/(N - 1)), and the density P_b / Omega_b per steradian.
Angles are in degrees (the files store radians; docs/FILE_FORMAT.md).
"""
import dataclasses
import functools

import numpy as np

from . import _fiberlab
from ._checks import count_argument, path_argument
from ._config import to_settings
from .labelled import to_xarray
from .progress import ProgressLine


@dataclasses.dataclass(frozen=True)
class LobeEnergy:
    """Fraction of the launched photons' weight per lobe (the ledger), with
    standard errors: mean and std_err (K, L, C); absorbed, truncated and lost
    (K, C). lost is the weight removed by masking (roughness.masking:
    smith_g1), 0 otherwise; roulette (K, C) is Russian roulette's signed term
    (estimator: expected_value; 0 otherwise); mean.sum(axis=1) + absorbed +
    truncated + lost - roulette = 1. With expected_value, std_err comes from
    the per-lobe S2 of photon totals (/tally/lobe_weight_sq_sum)."""
    mean: np.ndarray
    std_err: np.ndarray
    absorbed: np.ndarray
    truncated: np.ndarray
    lost: np.ndarray
    roulette: np.ndarray


@dataclasses.dataclass(frozen=True)
class Marginals:
    """Probability per theta_r bin (summed over phi; (K, L, n_theta, C)) and
    per phi bin (summed over theta_r; (K, L, n_phi, C)), with standard errors."""
    theta: np.ndarray
    theta_std_err: np.ndarray
    phi: np.ndarray
    phi_std_err: np.ndarray


def channel_names(settings):
    """"R", "G", "B" for a melanin fiber (d'Eon 2011 s6.1), else "c0", "c1", ..."""
    return list(_fiberlab.channel_names(settings))


class Result:
    """Histograms of one simulation (or of merged ones), as in its HDF5 file.

    Arrays are NumPy, index order (K, L, n_theta, n_phi, C): K incident
    directions (theta_i, phi_i), L lobes (lobe_names), theta_r bins
    (theta_edges), relative-azimuth bins (phi_edges), C colour channels.
    Angles in degrees.
    """

    def __init__(self, file):
        self._file = file  # a _fiberlab.ResultFile

    def _settings(self):
        return self._file.settings

    # --- what was simulated -------------------------------------------------
    @functools.cached_property
    def config(self):
        """The resolved configuration as a dict with the YAML's keys (degrees)."""
        return self._file.settings.config

    @property
    def config_yaml(self):
        return self._file.config_yaml

    @property
    def seeds(self):
        return list(self._file.seeds)

    @property
    def software_version(self):
        return self._file.software_version

    @functools.cached_property
    def theta_edges(self):
        """theta_r bin edges (n_theta + 1), degrees in [-90, 90]."""
        return np.degrees(self._file.theta_edges)

    @functools.cached_property
    def phi_edges(self):
        """Relative azimuth phi_r - phi_i bin edges (n_phi + 1), degrees in [-180, 180]."""
        return np.degrees(self._file.phi_edges)

    @functools.cached_property
    def solid_angle(self):
        """(n_theta, n_phi) steradians: (sin theta_hi - sin theta_lo)(phi_hi - phi_lo)."""
        return self._file.solid_angle

    @functools.cached_property
    def theta_i(self):
        """(K,) incident inclinations, degrees."""
        return np.degrees(self._file.theta_i)

    @functools.cached_property
    def phi_i(self):
        """(K,) incident azimuths, degrees (NaN for a randomly rotated fiber)."""
        return np.degrees(self._file.phi_i)

    @functools.cached_property
    def photons(self):
        """(K,) photons launched per incident direction."""
        return self._file.photons

    @functools.cached_property
    def lobe_names(self):
        return list(self._file.lobe_names)

    @functools.cached_property
    def channel_names(self):
        return channel_names(self._file.settings)

    # --- raw sums -------------------------------------------------------------
    @functools.cached_property
    def weight_sum(self):
        """S1 per bin, (K, L, n_theta, n_phi, C)."""
        return self._file.weight_sum

    @functools.cached_property
    def weight_sq_sum(self):
        """S2 per bin, (K, L, n_theta, n_phi, C)."""
        return self._file.weight_sq_sum

    @functools.cached_property
    def count(self):
        """Photons per bin, (K, L, n_theta, n_phi)."""
        return self._file.count

    # --- estimators (SPEC s6) ---------------------------------------------------
    @functools.cached_property
    def _estimators(self):
        return self._file.estimators()

    @property
    def mean(self):
        """Probability of each bin, P = S1/N, (K, L, n_theta, n_phi, C)."""
        return self._estimators[0]

    @property
    def std_err(self):
        """Standard error of mean, sqrt((S2/N - P^2)/(N - 1))."""
        return self._estimators[1]

    @property
    def density(self):
        """Probability per steradian, P / Omega (sr^-1)."""
        return self._estimators[2]

    @property
    def density_std_err(self):
        return self._estimators[3]

    @functools.cached_property
    def energy(self):
        """Lobe energies with standard errors, absorbed, truncated and lost fractions."""
        return LobeEnergy(**self._file.energy())

    @functools.cached_property
    def marginals(self):
        theta, theta_se = self._file.marginal("theta")
        phi, phi_se = self._file.marginal("phi")
        return Marginals(theta, theta_se, phi, phi_se)

    # --- files ------------------------------------------------------------------
    def to_xarray(self):
        """The estimators as an xarray.Dataset (Debian's python3-xarray):
        variables mean, std_err, density, density_std_err over dimensions
        (incidence, lobe, theta_r, phi, channel), coordinates theta_i, phi_i,
        theta_r, phi (bin centres, degrees, with their edges as attributes),
        lobe and channel names; the lobe energies as energy, energy_std_err."""
        e = self.energy
        return to_xarray(self, {"mean": (self.mean, "1", "probability of the bin, P = S1/N"),
                                "std_err": (self.std_err, "1", "standard error of mean"),
                                "density": (self.density, "sr^-1", "probability per steradian, P / Omega"),
                                "density_std_err": (self.density_std_err, "sr^-1", "standard error of density")},
                         {"energy": (e.mean, "1", "fraction of the launched weight in the lobe"),
                          "energy_std_err": (e.std_err, "1", "standard error of energy")},
                         {"photons": (self.photons, "1", "photons launched per incident direction")},
                         "fiberlab simulation result")

    def save(self, path):
        """Writes the result file (SPEC s9; written to a temporary name, then renamed)."""
        self._file.save(path_argument("path", path))

    def __repr__(self):
        K, L, T, P, C = self.weight_sum.shape
        return ("<fiberlab.Result: %d incident direction(s), lobes %s, %d x %d bins, %d channel(s), "
                "%s photons each>" % (K, ", ".join(self.lobe_names), T, P, C,
                                      ", ".join(str(int(n)) for n in np.unique(self.photons))))


MAX_THREADS = _fiberlab.max_threads  # sim/run/memory_budget.h kMaxThreads, the cap of `fiberlab run --threads`


def run(config, photons=None, seed=None, threads=None, progress=True):
    """Simulates a config: a YAML path, or a dict with the YAML's keys
    (degrees, as in the file; see configs/README.md). photons, seed override
    the config's (integers; an integral float such as 1e6 is accepted, as
    in configs); threads (1 to 1024) defaults to every core (the tallies do
    not depend on it). progress: True (a line on stderr after a second),
    False, or a callable(done, total). Returns a Result (not written to
    disk: save() it).

    Ctrl-C (SIGINT) stops the run within about a second and raises
    KeyboardInterrupt; nothing is kept.
    """
    settings = to_settings(config)
    photons = count_argument("photons", photons, 1)
    seed = count_argument("seed", seed, 0)
    threads = count_argument("threads", threads, 1, MAX_THREADS) or 0
    if progress is True:
        progress = ProgressLine()
    elif progress is False or progress is None:
        progress = None
    elif not callable(progress):
        raise _fiberlab.Error("progress must be True, False or a callable(done, total), not %s"
                              % type(progress).__name__)
    return Result(_fiberlab.run(settings, photons, seed, threads, progress))


def _file_format(path):
    """The root attribute `format` of an HDF5 file, None when unreadable
    (the C++ reader then says why)."""
    try:
        import h5py
        with h5py.File(path, "r") as f:
            value = f.attrs.get("format")
    except (ImportError, OSError):
        return None
    return value.decode() if isinstance(value, bytes) else value


def load(path):
    """Reads a result file (format "fiber-histogram") as a Result, or a
    prediction file of `fiberlab predict` ("fiber-prediction") as a
    Prediction (docs/FILE_FORMAT.md)."""
    path = path_argument("path", path)
    if _file_format(path) == "fiber-prediction":
        from .prediction import load_prediction
        return load_prediction(path)
    return Result(_fiberlab.read_result(path))
