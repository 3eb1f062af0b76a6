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


def test_parameter_values_without_type_names(plot_report):
    assert plot_report.param_text({"value": "chord", "unit": "choice"}) == "chord"
    assert plot_report.param_text({"value": "4", "unit": "integer"}) == "4"
    assert plot_report.param_text({"value": "0.3", "unit": "1/R"}) == "0.3 1/R"


def test_incidence_names(plot_report):
    assert plot_report.incidence_name(30.0, 0.0) == "theta_i = 30.00 deg, phi_i = 0.00 deg"
    assert "uniform" in plot_report.incidence_name(30.0, float("nan"))
    assert "uniform" in plot_report.incidence_name(30.0, None)


# ---------------------------------------------------------------------------
# Figure properties a reader relies on, checked on the matplotlib objects of
# figures drawn from small synthetic inputs (no simulation needed).

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import colors as mcolors  # noqa: E402
from matplotlib.collections import QuadMesh  # noqa: E402

LOBES = ["R", "TT", "TRT", "p>=3"]


def synthetic_compare(n_theta=24, n_phi=36, channels=3, photons=200_000, seed=1, theta_r=-30.0, width=8.0):
    """A compare report's arrays: four Gaussian lobes at theta_r, phi centres
    0, 180, 30, 120 deg, the simulation a Poisson draw of the model."""
    rng = np.random.default_rng(seed)
    te = np.linspace(-90, 90, n_theta + 1)
    pe = np.linspace(-180, 180, n_phi + 1)
    tc, pc = 0.5 * (te[1:] + te[:-1]), 0.5 * (pe[1:] + pe[:-1])
    omega = (np.sin(np.radians(te[1:])) - np.sin(np.radians(te[:-1])))[:, None] * np.radians(np.diff(pe))[None, :]
    model = np.zeros((1, 4, n_theta, n_phi, channels))
    for l, (centre, energy) in enumerate(zip((0, 180, 30, 120), (0.05, 0.5, 0.1, 0.03))):
        dphi = np.angle(np.exp(1j * np.radians(pc - centre)))
        g = np.exp(-0.5 * ((tc[:, None] - theta_r) / width) ** 2) * np.exp(-0.5 * (dphi[None, :] / 0.6) ** 2)
        for c in range(channels):
            model[0, l, :, :, c] = g / g.sum() * energy * (1 - 0.3 * c)
    sim = rng.poisson(model * photons) / photons
    rows = [{"k": 0, "lobe": l, "lobe_name": LOBES[l], "channel": c, "phi_i_deg": 0.0, "theta_i_deg": th,
             "sim_energy": 0.1 * (l + 1) + 0.001 * th + 0.01 * c, "sim_error": 0.002,
             "model_energy": 0.1 * (l + 1) + 0.0012 * th + 0.01 * c}
            for l in range(4) for c in range(channels) for th in (0.0, 20.0, 40.0, 60.0)]
    return {"te": te, "pe": pe, "omega": omega, "theta_i": np.array([30.0]), "phi_i": np.zeros(1),
            "sim_p": sim, "sim_se": np.sqrt(np.maximum(sim, 1.0 / photons) / photons), "model_p": model,
            "model": "deon2011", "channel": 0, "photons": np.array([photons]), "lobe_names": LOBES,
            "channel_names": ["R", "G", "B"][:channels], "metrics": {"lobes": rows}}


def energy_metrics(white=True, sweep=True):
    th = [0, 15, 30, 45, 60, 75]

    def curve(label, simulated, scale, beta=None):
        lobes = [[e * scale * (1 + 0.004 * t) for t in th] for e in (0.05, 0.6, 0.15, 0.2)]
        total = [sum(x[i] for x in lobes) for i in range(len(th))]
        return {"label": label, "simulated": simulated, "beta_long_deg": beta, "theta_i_deg": th,
                "lobe_names": LOBES, "lobes": lobes, "lobe_errors": [[0.001] * len(th)] * 4, "total": total,
                "total_error": [0.001] * len(th), "three_lobe": [t - x for t, x in zip(total, lobes[3])],
                "absorbed": [], "truncated": [], "lost": [], "ledger": []}
    curves = [curve("simulation", True, 1.0)] + [curve(m, False, s) for m, s in (
        ("exact", 1.0), ("deon2011", 0.95), ("marschner2003", 1.2), ("chiang2016", 0.97), ("huang2022", 0.9))]
    if sweep:
        curves += [curve("deon2011 beta_long=%g" % b, False, 1 - 0.01 * b, b) for b in (2, 5, 10, 20)]
    return {"kind": "energy", "input": "x.h5", "simulated": True, "white": white, "channel": 0, "curves": curves}


def synthetic_atlas(plot_atlas):
    rng = np.random.default_rng(2)
    F, K, L, C = 8, 3, 4, 3
    a = {"theta_i": np.array([15.0, 45.0, 75.0]), "roughness": np.array([4, 4, 10, 10, 0.1, 0.1, 0.3, 0.3]),
         "roughness_index": np.repeat(np.arange(4), 2), "rough_models": ["gaussian"] * 4 + ["ggx"] * 4,
         "sim_energy": rng.uniform(0.05, 0.5, (F, K, L, C)), "lobes": LOBES, "models": {},
         "config_yaml": "sweep:\n  roughness:\n    - {model: gaussian, beta_long: 4}\n"
                        "    - {model: gaussian, beta_long: 10}\n    - {model: ggx, alpha: 0.1}\n"
                        "    - {model: ggx, alpha: 0.3, masking: smith_g1}\n"}
    for name in ("exact", "deon2011", "huang2022"):
        shape = (F, K, L, C)
        a["models"][name] = {"model_energy_before": a["sim_energy"] + rng.normal(0, 0.1, shape),
                             "model_energy_after": a["sim_energy"] + rng.normal(0, 0.03, shape),
                             "chi2_before": rng.uniform(10, 1e4, shape), "dof_before": np.full(shape, 10.0),
                             "chi2_after": rng.uniform(10, 1e3, shape), "dof_after": np.full(shape, 10.0),
                             "applicable": np.ones(F)}
    return a


@pytest.fixture(scope="module")
def plot_atlas(source_dir):
    spec = importlib.util.spec_from_file_location("plot_atlas", os.path.join(source_dir, "scripts", "plot_atlas.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def extent(artist, fig):
    return artist.get_window_extent(fig.canvas.get_renderer())


def data_axes(fig):
    return [ax for ax in fig.axes if ax.get_label() != "<colorbar>" and ax.get_visible()]


def assert_legends_outside_axes(fig):
    fig.canvas.draw()
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    assert legends, "the figure has no legend"
    for legend in legends:
        box = extent(legend, fig)
        for ax in data_axes(fig):
            assert not box.overlaps(extent(ax, fig)), "legend over the panel %r" % ax.get_title()


def test_heatmap_panels_are_at_least_400_px_wide(plot_report):
    fig = plot_report.plot_heatmaps(synthetic_compare(), 0, np, plt, mcolors)
    fig.canvas.draw()
    meshes = [ax for ax in fig.axes if any(isinstance(ch, QuadMesh) for ch in ax.get_children())
              and ax.get_label() != "<colorbar>"]
    assert len(meshes) == 4 * 4  # simulated, model, residual, ratio per lobe
    for ax in meshes:
        assert extent(ax, fig).width >= 400, ax.get_title()
    assert fig.get_size_inches()[0] * fig.dpi == 1200
    plt.close(fig)


def test_marginals_are_log_scaled_steps_with_labelled_axes(plot_report):
    from matplotlib.patches import StepPatch
    r = synthetic_compare(n_theta=91, n_phi=72, width=0.3)  # one theta_r bin holds the lobe, as a smooth fiber's cone
    fig = plot_report.plot_theta_marginals(r, 0, np, plt)
    main = [ax for ax in fig.axes if ax.get_title()]
    assert len(main) == 4 * 2  # theta_r and phi per lobe
    for ax in main:
        assert ax.get_yscale() == "log", ax.get_title()  # no single-bin spike on a linear scale
        assert any(isinstance(p, StepPatch) for p in ax.patches), ax.get_title()  # the model over bins, not a line
        assert "per degree" in ax.get_ylabel()
    notes = [t.get_text() for ax in main for t in ax.texts]
    assert any("of the light in one bin" in n for n in notes)  # the one-bin lobe is named as such
    for ax in fig.axes:
        if not ax.get_title():
            assert "(deg)" in ax.get_xlabel()  # residual panels carry the axis
    assert_legends_outside_axes(fig)
    plt.close(fig)


def test_polar_plots_have_no_radial_labels_and_keep_every_line_inside(plot_report):
    r = synthetic_compare()
    r["sim_p"][0, 2, 10, 3, 0] *= 40  # one bright simulated bin must not squash the model lines
    fig = plot_report.plot_polar(r, 0, np, plt)
    fig.canvas.draw()
    polar = [ax for ax in fig.axes if ax.name == "polar"]
    assert len(polar) == 4
    for ax in polar:
        assert all(not t.get_text() for t in ax.get_yticklabels())  # nothing drawn over the curves
        models = [ln for ln in ax.get_lines() if ln.get_linestyle() == "-"]
        assert len(models) == 3  # a model line per channel
        for ln in ax.get_lines():
            assert np.nanmax(ln.get_ydata()) <= ax.get_rmax()  # not clipped
        for ln in models:
            assert np.nanmax(ln.get_ydata()) > 0.5 * ax.get_rmax()  # visible, not collapsed at the centre
    assert_legends_outside_axes(fig)
    plt.close(fig)


def distinct_colours(lines):
    return {mcolors.to_hex(ln.get_color()) for ln in lines}


def test_compare_energy_panels_one_colour_per_source_channels_by_style(plot_report):
    fig = plot_report.plot_energy_lobes(synthetic_compare(), np, plt)
    axes = data_axes(fig)
    assert len(axes) == 4
    for ax in axes:
        model = [ln for ln in ax.get_lines() if ln.get_linestyle() not in ("None", "none", "")]
        assert len(model) == 3 and len(distinct_colours(model)) == 1  # one colour for the model ...
        assert len({ln.get_linestyle() for ln in model}) == 3  # ... the channels by line style
        assert all(ln.get_marker() not in (None, "", "None") for ln in model)  # seen with a single theta_i too
        assert "(deg)" in ax.get_xlabel()
    assert "fraction of incident light" in axes[0].get_ylabel()
    assert_legends_outside_axes(fig)
    plt.close(fig)


def test_energy_report_lobes_have_their_own_panels_and_a_colour_per_source(plot_report):
    m = energy_metrics()
    fig = plot_report.energy_figure(m, np, plt)
    lobe_axes = [ax for ax in data_axes(fig) if ax.get_title().startswith("lobe ")]
    assert [ax.get_title() for ax in lobe_axes] == ["lobe " + n for n in LOBES]
    sources = 6  # simulation and five models (the beta sweep has its own figure)
    for ax in lobe_axes:
        lines = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 1]
        assert len(lines) == sources and len(distinct_colours(lines)) == sources
    for ax in data_axes(fig):
        assert "(deg)" in ax.get_xlabel()
    assert "fraction of incident light" in lobe_axes[0].get_ylabel()
    assert_legends_outside_axes(fig)
    plt.close(fig)
    for fig in (plot_report.plot_roughness_sweep([c for c in m["curves"] if c["beta_long_deg"] is not None], True,
                                                 np, plt),
                plot_report.plot_furnace(m["curves"], plot_report.source_colours(m["curves"], plt), np, plt)):
        assert_legends_outside_axes(fig)
        plt.close(fig)


def test_atlas_roughness_axis_is_categorical(plot_atlas):
    a = synthetic_atlas(plot_atlas)
    for chi2 in (False, True):
        fig = plot_atlas.error_vs_roughness(a, np, plt, chi2=chi2)
        axes = data_axes(fig)
        assert len(axes) == 3
        for ax in axes:
            points = 0
            for ln in ax.get_lines():
                x = np.asarray(ln.get_xdata(), dtype=float)
                if ln.get_marker() in (None, "", "None", "none"):
                    assert np.all(x == x[0]), "only vertical separators may be lines"
                    continue
                assert ln.get_linestyle() in ("None", "none", ""), "a line joins roughness categories"
                points += len(x)
                assert len(set(np.round(x).astype(int))) == len(x)  # one point per category and series
            assert points == 4 * 4 * 2  # categories x lobes x (before, after)
            labels = [t.get_text() for t in ax.get_xticklabels()]
            assert labels[0].startswith("gaussian 4") and "masking smith_g1" in labels[3]
        assert_legends_outside_axes(fig)
        plt.close(fig)
    fig = plot_atlas.error_vs_theta(a, np, plt)
    assert_legends_outside_axes(fig)
    plt.close(fig)


def write_compare_inputs(d, r):
    """report_data.h5 and metrics.json as `fiberlab compare --report` writes them."""
    import json
    h5py = pytest.importorskip("h5py")
    with h5py.File(d / "report_data.h5", "w") as f:
        f["theta_edges"] = np.radians(r["te"])
        f["phi_edges"] = np.radians(r["pe"])
        f["solid_angle"] = r["omega"]
        f["theta_i"] = np.radians(r["theta_i"])
        f["phi_i"] = np.radians(r["phi_i"])
        f["photons"] = r["photons"]
        for key in ("sim_p", "sim_se", "model_p"):
            f[key] = r[key]
        f.attrs["model"] = r["model"]
        f.attrs["plot_channel"] = 0
        f.attrs["lobe_names"] = ",".join(LOBES)
        f.attrs["channel_names"] = "R,G,B"
    rows = [dict(x, judged=True, accepted=True, energy_z=1.0, chi2_per_dof=1.0, dof=10, threshold=3.0,
                 theta_marginal_chi2_per_dof=1.0, phi_marginal_chi2_per_dof=1.0, l1=0.1, centroid_sim_deg=-30.0,
                 centroid_model_deg=-30.0, measured_shift_deg=0.0) for x in r["metrics"]["lobes"]]
    (d / "metrics.json").write_text(json.dumps({"result": "synthetic.h5", "params": {}, "criterion": "chi2/dof",
                                                "accepted": True, "lobes": rows}))


def run_script(source_dir, kind, d):
    import subprocess
    out = subprocess.run(["/usr/bin/python3", os.path.join(source_dir, "scripts", "plot_report.py"), kind, str(d)],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr


def test_every_png_has_an_svg_beside_it_and_the_page_links_it(source_dir, tmp_path):
    import json
    compare, energy = tmp_path / "compare", tmp_path / "energy"
    compare.mkdir()
    energy.mkdir()
    write_compare_inputs(compare, synthetic_compare())
    (energy / "metrics.json").write_text(json.dumps(energy_metrics()))
    run_script(source_dir, "compare", compare)
    run_script(source_dir, "energy", energy)
    for d, count in ((compare, 4), (energy, 3)):
        pngs = sorted(p.stem for p in d.glob("*.png"))
        assert len(pngs) == count, pngs
        assert pngs == sorted(p.stem for p in d.glob("*.svg"))
        page = (d / "report.html").read_text()
        for stem in pngs:
            assert (d / (stem + ".svg")).read_text().lstrip().startswith("<?xml")
            assert 'href="%s.svg"' % stem in page
