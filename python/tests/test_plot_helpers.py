"""scripts/plot_report.py's choices that a reader of the figures relies on:
a lobe lying across the +-180 deg seam (TT) is drawn on [0, 360) whole, and
incident directions are named by theta_i and phi_i."""
import importlib.util
import os

import numpy as np
import pytest


@pytest.fixture(scope="module")
def plot_report(source_dir):
    spec = importlib.util.spec_from_file_location("plot_report", os.path.join(source_dir, "scripts", "plot_report.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_lobe_across_the_seam_is_centred_on_180(plot_report):
    pe = np.linspace(-180, 180, 73)  # 5-deg bins
    centres = 0.5 * (pe[1:] + pe[:-1])
    tt = np.exp(-0.5 * ((np.abs(centres) - 180) / 20) ** 2)[None, :].repeat(3, axis=0)  # peak at +-180
    (shifted,), edges = plot_report.centred_phi(np, [tt], pe, tt)
    assert edges[0] == 0 and edges[-1] == 360
    assert np.all(np.diff(edges) > 0)
    new_centres = 0.5 * (edges[1:] + edges[:-1])
    assert abs(new_centres[np.argmax(shifted[0])] - 180) < 5  # the peak in the middle
    np.testing.assert_array_equal(np.sort(shifted[0]), np.sort(tt[0]))  # nothing lost


def test_lobe_around_zero_stays_on_minus_180_180(plot_report):
    pe = np.linspace(-180, 180, 73)
    centres = 0.5 * (pe[1:] + pe[:-1])
    trt = np.exp(-0.5 * (centres / 20) ** 2)[None, :]
    (same,), edges = plot_report.centred_phi(np, [trt], pe, trt)
    np.testing.assert_array_equal(edges, pe)
    np.testing.assert_array_equal(same, trt)


def test_incidence_names(plot_report):
    assert plot_report.incidence_name(30.0, 0.0) == "theta_i = 30.00 deg, phi_i = 0.00 deg"
    assert "uniform" in plot_report.incidence_name(30.0, float("nan"))
    assert "uniform" in plot_report.incidence_name(30.0, None)
