"""Shared fixtures: a small smooth absorbing circular fiber, simulated once.

Run with Debian's Python and the built module on the path:
    PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests -q
(ctest does this; FIBERLAB_BINARY names the command for the CLI checks).
"""
import os

import pytest

import fiberlab

# Smooth circle, sigma_a per channel, two incident directions. 45 theta bins
# of 4 deg put the specular cone theta_r = -theta_i (0 and -40 deg) inside a
# bin, never on an edge (SPEC s10).
SMOOTH_ABSORBING = {
    "fiber": {"eta": 1.55, "eccentricity": 1.0, "sigma_a": [0.2, 0.5]},
    "roughness": {"model": "smooth"},
    "source": {"theta_i": [0, 40], "phi_i": 0},
    "tally": {"n_theta": 45, "n_phi": 72, "lobes": 4},
}


@pytest.fixture(scope="session")
def smooth_result():
    return fiberlab.run(SMOOTH_ABSORBING, photons=200_000, seed=11, progress=False)


@pytest.fixture(scope="session")
def fiberlab_binary():
    path = os.environ.get("FIBERLAB_BINARY", "")
    if not path or not os.path.exists(path):
        pytest.skip("FIBERLAB_BINARY (the fiberlab command) not set")
    return path


@pytest.fixture(scope="session")
def source_dir():
    return os.environ.get("FIBERLAB_SOURCE_DIR",
                          os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def exact_prediction(result, **params):
    """The exact smooth-cylinder model with chord (3D path) absorption, the
    simulator's: passed explicitly while `exact` defaults to the published
    2D rule, accepted either way once chord is the default."""
    try:
        return fiberlab.predict(result, "exact", absorption="chord", **params)
    except fiberlab.Error as e:
        if "absorption" not in str(e):
            raise
        return fiberlab.predict(result, "exact", **params)
