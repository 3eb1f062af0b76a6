"""Labelled arrays (xarray, Debian's python3-xarray) for results and
predictions: named dimensions, coordinates in degrees, units as attributes
(the names and units of docs/FILE_FORMAT.md)."""
import numpy as np

from . import _fiberlab

BIN_DIMS = ("incidence", "lobe", "theta_r", "phi", "channel")
LOBE_DIMS = ("incidence", "lobe", "channel")


def _centres(edges):
    return 0.5 * (edges[1:] + edges[:-1])


def to_xarray(source, bin_vars, lobe_vars, incidence_vars, title):
    """An xarray.Dataset of `source` (a Result or a Prediction: theta_i,
    phi_i, theta_edges, phi_edges in degrees, lobe_names, channel_names).
    bin_vars, lobe_vars, incidence_vars: {name: (array, units, meaning)} over
    BIN_DIMS, LOBE_DIMS and (incidence,)."""
    try:
        import xarray
    except ImportError:
        raise _fiberlab.Error("to_xarray needs xarray (Debian: apt-get install python3-xarray)") from None
    theta_edges, phi_edges = np.asarray(source.theta_edges), np.asarray(source.phi_edges)
    coords = {
        "theta_i": ("incidence", np.asarray(source.theta_i), {"units": "degree", "long_name": "incident inclination"}),
        "phi_i": ("incidence", np.asarray(source.phi_i),
                  {"units": "degree", "long_name": "incident azimuth (NaN: randomly rotated fiber)"}),
        "lobe": ("lobe", list(source.lobe_names), {"long_name": "lobe: path count p (R p=0, TT p=1, TRT p=2, ...)"}),
        "theta_r": ("theta_r", _centres(theta_edges),
                    {"units": "degree", "long_name": "exit inclination theta_r (bin centre)",
                     "edges": theta_edges}),
        "phi": ("phi", _centres(phi_edges),
                {"units": "degree", "long_name": "relative azimuth phi_r - phi_i (bin centre)", "edges": phi_edges}),
        "channel": ("channel", list(source.channel_names), {"long_name": "colour channel"}),
    }
    data = {}
    for dims, group in ((BIN_DIMS, bin_vars), (LOBE_DIMS, lobe_vars), (("incidence",), incidence_vars)):
        for name, (array, units, meaning) in group.items():
            data[name] = (dims, np.asarray(array), {"units": units, "long_name": meaning})
    return xarray.Dataset(data, coords=coords, attrs={"title": title})
