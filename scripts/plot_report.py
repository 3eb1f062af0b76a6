#!/usr/bin/python3
"""Plots and the HTML page for `fiberlab compare --report DIR` and
`fiberlab energy --report DIR`.

Usage: /usr/bin/python3 scripts/plot_report.py compare|energy|atlas DIR

Reads DIR/report_data.h5 and DIR/metrics.json (compare) or DIR/metrics.json
(energy), writes PNGs and DIR/report.html into DIR. report.html is one
self-contained file: every figure embedded as a base64 PNG, no script, no
external URL (its only links: to the SVGs beside it). Needs Debian's
python3-matplotlib, python3-h5py and numpy (run it with /usr/bin/python3,
not a pyenv `python3`). Exit status 3 when those
are missing (the caller then reports "plots skipped"), 2 on bad arguments.

Figures have fixed pixel sizes (no tight bounding box), so tests can check
the PNG headers; each is written as DIR/NAME.png (embedded in report.html at
its natural size, never scaled down) and DIR/NAME.svg beside it (vector,
linked from report.html). Legends stand outside the panels. Per incident
direction, named by theta_i and phi_i in degrees ({DIR} = theta30.0_phi0.0,
or theta30.0_phiuniform); L = lobes:
  compare_{DIR}_heatmaps.png  1200 x (150 + 550 L): per lobe two rows of two
                              panels (each >= 400 px wide): simulated and
                              predicted density (sr^-1, log colour scale),
                              the normalised residual (P_sim - P_model) / se
                              and log10(P_sim / P_model) (the colour bar's
                              end colours where only one side has light: the
                              simulation, or the model expecting >= 3
                              photons in the bin); grey = no data (no
                              simulated photon in the bin; for the ratio, no
                              light on either side); a lobe with 3/4 of its
                              light at |phi| > 90 deg (TT) is drawn on phi in
                              [0, 360) so it is not cut at +-180 deg
  compare_{DIR}_marginals.png 1200 x (125 + 350 L): per lobe, the theta_r
                              and the phi marginal (probability per degree,
                              log y: lobes span decades and a one-bin peak,
                              like a smooth fiber's specular cone, would
                              flatten the rest on a linear scale; simulation
                              with 1-se error bars, model as steps over the
                              bins) over their normalised residuals
  compare_{DIR}_polar.png     1200 x 450: per lobe, the phi marginal in polar
                              form for every channel, each scaled to its own
                              maximum (named under the panel); points:
                              simulation, lines: model
  compare_energy.png          1200 x (100 + 325 rows): per lobe, energy
                              against theta_i, simulation (black, 1 se) and
                              model (orange), channels by line style and
                              marker; a row per phi_i when there are several
  energy.png                  1200 x 800: total, R+TT+TRT and one panel per
                              lobe, energy against theta_i, a colour per
                              source
  energy_roughness.png        1200 x 600: total energy against theta_i per
                              beta_long (only with --beta-sweep), as in
                              d'Eon et al. 2011 Fig. 3
  energy_furnace.png          1200 x 400: white fibers only, |total - 1|
                              against theta_i per source (log scale)
  atlas_*.png                 `fiberlab atlas`: see scripts/plot_atlas.py
"""
import base64
import html
import json
import os
import sys

# Incident directions with figures (report.html names the ones left out);
# $FIBERLAB_REPORT_MAX_FIGURES overrides it (tests).
MAX_FIGURE_CONFIGS = int(os.environ.get("FIBERLAB_REPORT_MAX_FIGURES", "24"))
NO_DATA = "#b8b8b8"     # grey: no simulated photon in the bin (distinct from any colour-map value)


def lobe_name(lobe, lobes):
    names = ["R", "TT", "TRT", "TRRT", "TR3T", "TR4T"]
    if lobe == lobes - 1 and lobes > 1:
        return "p>=%d" % lobe
    return names[lobe] if lobe < 6 else "p=%d" % lobe


def text_attr(f, name, default):
    if name not in f.attrs:
        return default
    v = f.attrs[name]
    return v.decode() if isinstance(v, bytes) else str(v)


def incidence_name(theta_i_deg, phi_i_deg):
    # NaN (report_data.h5) or None (null in metrics.json): a randomly rotated fiber.
    uniform = phi_i_deg is None or phi_i_deg != phi_i_deg
    phi = "uniform (randomly rotated fiber)" if uniform else "%.2f deg" % phi_i_deg
    return "theta_i = %.2f deg, phi_i = %s" % (theta_i_deg, phi)


def incidence_stem(theta_i_deg, phi_i_deg):
    """File-name part naming the incident direction: theta30.0_phi0.0 (phiuniform)."""
    uniform = phi_i_deg is None or phi_i_deg != phi_i_deg
    return "theta%.1f_phi%s" % (theta_i_deg, "uniform" if uniform else "%.1f" % phi_i_deg)


def load_compare(d, np, h5py):
    """report_data.h5 and metrics.json as one dict of NumPy arrays (degrees)."""
    with h5py.File(os.path.join(d, "report_data.h5"), "r") as f:
        r = {
            "te": np.degrees(f["theta_edges"][...]),
            "pe": np.degrees(f["phi_edges"][...]),
            "omega": f["solid_angle"][...],
            "theta_i": np.degrees(f["theta_i"][...]),
            "sim_p": f["sim_p"][...],
            "sim_se": f["sim_se"][...],
            "model_p": f["model_p"][...],
            "model": text_attr(f, "model", "model"),
            "channel": int(f.attrs["plot_channel"]),
        }
        K, L, C = r["sim_p"].shape[0], r["sim_p"].shape[1], r["sim_p"].shape[4]
        r["phi_i"] = np.degrees(f["phi_i"][...]) if "phi_i" in f else np.zeros(K)
        r["photons"] = f["photons"][...] if "photons" in f else None
        lobes = text_attr(f, "lobe_names", "")
        r["lobe_names"] = lobes.split(",") if lobes else [lobe_name(l, L) for l in range(L)]
        channels = text_attr(f, "channel_names", "")
        r["channel_names"] = channels.split(",") if channels else ["c%d" % c for c in range(C)]
    path = os.path.join(d, "metrics.json")
    r["metrics"] = json.load(open(path)) if os.path.exists(path) else None
    return r


def centred_phi(np, arrays, pe, mass):
    """The lobe's arrays on phi in [0, 360) when 3/4 of its light lie at
    |phi| > 90 deg (TT: centred on 180 deg, not cut at the +-180 deg seam),
    else unchanged on [-180, 180). arrays: (n_theta, n_phi) each."""
    centres = 0.5 * (pe[:-1] + pe[1:])
    total = mass.sum()
    if total <= 0 or mass[:, np.abs(centres) > 90].sum() <= 0.75 * total:
        return arrays, pe
    half = len(centres) // 2
    shifted = [np.roll(a, -half, axis=1) for a in arrays]
    edges = np.concatenate([pe[half:], pe[1:half + 1] + 360.0])
    return shifted, edges


def shown_range(np, edges, rows):
    """The edges' span over the rows holding something, one bin of margin
    (theta_r axes are cropped to where the lobe has light)."""
    idx = np.flatnonzero(rows)
    if idx.size == 0:
        return edges[0], edges[-1]
    return edges[max(idx[0] - 1, 0)], edges[min(idx[-1] + 2, len(edges) - 1)]


def plot_heatmaps(r, k, np, plt, colors):
    """Per lobe two rows of two panels (simulated | model over residual |
    log ratio), each panel at least 400 px wide in a 1200 px figure so the
    bins stay legible in report.html (shown at its natural size)."""
    c = r["channel"]
    L = r["sim_p"].shape[1]
    height = 1.5 + 5.5 * L  # inches; quarter inches keep the pixel size exact
    fig, axes = plt.subplots(2 * L, 2, figsize=(12, height), dpi=100, squeeze=False)
    fig.suptitle("%s, channel %s:\nper lobe simulated and %s density, residual and log ratio"
                 % (incidence_name(r["theta_i"][k], r["phi_i"][k]), r["channel_names"][c], r["model"]), fontsize=12)
    magma = plt.get_cmap("magma").copy()
    magma.set_bad(NO_DATA)
    diverging = plt.get_cmap("RdBu_r").copy()
    diverging.set_bad(NO_DATA)
    ratio_map = plt.get_cmap("PuOr_r").copy()
    ratio_map.set_bad(NO_DATA)
    for l in range(L):
        s = r["sim_p"][k, l, :, :, c]
        m = r["model_p"][k, l, :, :, c]
        se = r["sim_se"][k, l, :, :, c]
        (s, m, se, omega), pe = centred_phi(np, [s, m, se, r["omega"]], r["pe"], s + m)
        te = r["te"]
        ds, dm = s / omega, m / omega
        top = max(ds.max(), dm.max(), 1e-300)
        lo = top * 1e-4
        norm = colors.LogNorm(vmin=lo, vmax=top)
        theta_range = shown_range(np, te, (s > 0).any(axis=1) | (dm >= lo).any(axis=1))
        # Simulation: bins without a photon are "no data" (grey); the model's
        # zero-probability bins take the bottom colour (below the range).
        sim_shown = np.ma.masked_where(s <= 0, np.maximum(ds, lo))
        panels = [(sim_shown, "simulated density", magma, norm, "density (sr$^{-1}$)", "min"),
                  (np.maximum(dm, lo), "%s density" % r["model"], magma, norm, "density (sr$^{-1}$)", "min")]
        with np.errstate(divide="ignore", invalid="ignore"):
            res = np.where(se > 0, (s - m) / se, np.nan)
            # Light on one side only: beyond the colour range (the bar's end
            # colours), not "no data", so that a model lighting bins the
            # simulation left empty shows, when it expects >= 3 photons there
            # (m N >= 3; photon weights <= 1 make that a lower bound).
            n = r["photons"][k] if r["photons"] is not None else np.inf
            ratio = np.where((s > 0) & (m > 0), np.log10(s / m),
                             np.where(m * n >= 3, -99.0, np.where(s > 0, 99.0, np.nan)))
        panels.append((np.ma.masked_invalid(res), "residual (sim - model) / se", diverging,
                       colors.Normalize(-5, 5), "standard errors", "both"))
        panels.append((np.ma.masked_invalid(ratio), "log10(sim / model)", ratio_map,
                       colors.Normalize(-1, 1), "log10 ratio", "both"))
        centred = pe[0] >= 0
        for j, (arr, title, cmap, nrm, unit, extend) in enumerate(panels):
            ax = axes[2 * l + j // 2, j % 2]
            ax.set_facecolor(NO_DATA)
            im = ax.pcolormesh(pe, te, arr, cmap=cmap, norm=nrm, shading="flat", rasterized=True)
            ax.set_title("%s: %s" % (r["lobe_names"][l], title), fontsize=10, loc="left")
            cb = fig.colorbar(im, ax=ax, extend=extend, fraction=0.05, pad=0.02)
            cb.set_label(unit, fontsize=9)
            cb.ax.tick_params(labelsize=8)
            ax.tick_params(labelsize=8)
            ax.set_xlim(pe[0], pe[-1])
            ax.set_ylim(*theta_range)
            if j % 2 == 0:
                ax.set_ylabel("theta_r (deg)", fontsize=9)
            ax.set_xlabel("phi (deg)%s" % (", centred on 180" if centred else ""), fontsize=9)
    from matplotlib.patches import Patch
    fig.legend(handles=[Patch(color=NO_DATA, label="grey: no data (no simulated photon in the bin)")],
               loc="lower center", fontsize=9, frameon=False)
    fig.subplots_adjust(left=0.06, right=0.95, top=1 - 1.15 / height, bottom=0.75 / height, hspace=0.45, wspace=0.22)
    return fig


def log_limits(np, sim, model):
    """y range of a log-scale marginal: down to a fifth of the smallest
    simulated value (the model's tails below what the simulation can see are
    cut), at most 7 decades below the top."""
    top = max(sim.max(), model.max())
    if top <= 0:
        return None
    floor = sim[sim > 0].min() * 0.2 if (sim > 0).any() else top * 1e-7
    return max(floor, top * 1e-7), top * 2


def marginal_panel(ax, axr, edges, s, se, m, np, label_model, xlabel, crop):
    """One marginal: simulation as points with 1-se bars, the model as steps
    (bins, not a line through bin centres), log y; its normalised residual
    below. A lobe with nearly all its light in one bin (a smooth fiber's
    specular cone) gets a note saying so, since the panel then shows a bar."""
    width = np.diff(edges)
    centres = 0.5 * (edges[:-1] + edges[1:])
    ok = s > 0
    ax.errorbar(centres[ok], s[ok] / width[ok], yerr=se[ok] / width[ok], fmt="o", ms=2.5, lw=0.8,
                color="k", label="simulation (1 se)", zorder=3)
    ax.stairs(m / width, edges, baseline=None, lw=1.3, color="C1", label=label_model, zorder=2)
    lim = log_limits(np, s / width, m / width)
    if lim:
        ax.set_yscale("log")
        ax.set_ylim(*lim)
        if crop:
            ax.set_xlim(*shown_range(np, edges, (s > 0) | (m / width >= lim[0])))
    total = s.sum()
    if total > 0 and s.max() >= 0.99 * total:
        i = int(np.argmax(s))
        ax.text(0.02, 0.95, "%.1f%% of the light in one bin, [%.1f, %.1f] deg" % (100 * s[i] / total, edges[i],
                                                                               edges[i + 1]),
                transform=ax.transAxes, fontsize=8, va="top")
    ax.set_ylabel("probability per degree", fontsize=9)
    ax.tick_params(labelsize=8, labelbottom=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        res = np.where(se > 0, (s - m) / se, np.nan)
    axr.axhline(0, color="gray", lw=0.6)
    axr.plot(centres, res, "o", ms=2.5, color="k")
    axr.set_ylabel("(sim - model) / se", fontsize=8)
    axr.set_xlabel(xlabel, fontsize=9)
    axr.tick_params(labelsize=8)
    big = np.nanmax(np.abs(res)) if np.isfinite(res).any() else 1.0
    axr.set_ylim(-max(3.0, big * 1.1), max(3.0, big * 1.1))


def plot_theta_marginals(r, k, np, plt):
    """Per lobe a row: the theta_r marginal (left) and the phi marginal
    (right), each over its normalised residual. Log y: the lobes span
    several decades (TT's forward peak against its tails; caustics), and on
    a linear scale a peak holding most of the light in one bin is all one
    sees."""
    c = r["channel"]
    L = r["sim_p"].shape[1]
    height = 1.25 + 3.5 * L
    fig = plt.figure(figsize=(12, height), dpi=100)
    fig.suptitle("%s, channel %s: theta_r and phi marginals per lobe\nsimulation (points, 1 se) and %s (steps)"
                 % (incidence_name(r["theta_i"][k], r["phi_i"][k]), r["channel_names"][c], r["model"]), fontsize=12)
    outer = fig.add_gridspec(L, 2, hspace=0.45, wspace=0.22, left=0.08, right=0.98,
                             top=1 - 1.25 / height, bottom=0.45 / height)
    handles = None
    for l in range(L):
        for j, axis in enumerate(("theta", "phi")):
            inner = outer[l, j].subgridspec(2, 1, height_ratios=[3, 1], hspace=0.06)
            ax = fig.add_subplot(inner[0])
            axr = fig.add_subplot(inner[1], sharex=ax)
            s2, se2, m2 = (r[key][k, l, :, :, c] for key in ("sim_p", "sim_se", "model_p"))
            if axis == "theta":
                edges, sum_axis, xlabel = r["te"], 1, "theta_r (deg)"
            else:  # TT whole on [0, 360), as in the heatmaps
                (s2, se2, m2), edges = centred_phi(np, [s2, se2, m2], r["pe"], s2 + m2)
                sum_axis, xlabel = 0, "phi (deg)%s" % (", centred on 180" if edges[0] >= 0 else "")
            s, m = s2.sum(axis=sum_axis), m2.sum(axis=sum_axis)
            se = np.sqrt((se2 ** 2).sum(axis=sum_axis))
            marginal_panel(ax, axr, edges, s, se, m, np, r["model"], xlabel, crop=axis == "theta")
            ax.set_title("%s: %s marginal" % (r["lobe_names"][l], "theta_r" if axis == "theta" else "phi"),
                         fontsize=10)
            if handles is None:
                handles = ax.get_legend_handles_labels()
    fig.legend(*handles, loc="upper center", fontsize=9, ncol=2, frameon=False, bbox_to_anchor=(0.5, 1 - 0.6 / height))
    return fig


def plot_polar(r, k, np, plt):
    """Per lobe, the phi marginal of every channel in polar form, each
    channel scaled to its own maximum (the channels' absolute levels differ
    by decades under absorption; the panels name the maxima). No radial tick
    labels over the curves: the rings are 0.5 and 1 of the maximum."""
    L, C = r["sim_p"].shape[1], r["sim_p"].shape[4]
    pe = np.radians(r["pe"])
    centres = 0.5 * (pe[:-1] + pe[1:])
    width = np.degrees(np.diff(pe))
    names = r["channel_names"]
    palette = {"R": "tab:red", "G": "tab:green", "B": "tab:blue"}
    fig, axes = plt.subplots(1, L, figsize=(12, 4.5), dpi=100, subplot_kw={"projection": "polar"}, squeeze=False)
    fig.suptitle("%s: phi marginals per lobe, each channel scaled to its maximum\n(points: simulation; lines: %s)"
                 % (incidence_name(r["theta_i"][k], r["phi_i"][k]), r["model"]), fontsize=11)
    closed = np.append(centres, centres[0] + 2 * np.pi)
    for l in range(L):
        ax = axes[0, l]
        maxima = []
        for c in range(C):
            color = palette.get(names[c], "C%d" % c)
            s = r["sim_p"][k, l, :, :, c].sum(axis=0) / width
            m = r["model_p"][k, l, :, :, c].sum(axis=0) / width
            top = max(s.max(), m.max())
            maxima.append("%s %.2g" % (names[c], top))
            scale = 1.0 / top if top > 0 else 1.0
            # The model line above the points: with many phi bins the points
            # would otherwise cover it.
            ax.plot(closed, np.append(m, m[0]) * scale, "-", lw=1.3, color=color, label="%s model" % names[c],
                    zorder=3)
            ax.plot(centres, s * scale, "o", ms=3, color=color, alpha=0.45, mew=0,
                    label="%s simulation" % names[c], zorder=2)
        ax.set_theta_zero_location("E")
        ax.set_rlim(0, 1.08)
        ax.set_rticks([0.5, 1.0])
        ax.set_yticklabels([])
        ax.set_thetagrids(range(0, 360, 45), ["0", "45", "90", "135", "±180", "-135", "-90", "-45"], fontsize=8)
        ax.set_title(r["lobe_names"][l], fontsize=11, pad=14)
        ax.text(0.5, -0.2, "max (per deg): %s" % ", ".join(maxima), transform=ax.transAxes, ha="center",
                fontsize=7.5)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(2 * C, 6), fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.02, right=0.98, top=0.78, bottom=0.22, wspace=0.35)
    return fig


CHANNEL_STYLES = [("-", "o"), ("--", "s"), (":", "^"), ("-.", "D")]


def plot_energy_lobes(r, np, plt):
    """Energy per lobe against theta_i: one panel per lobe (a row per phi_i
    when there are several), one colour per source (simulation black with
    1-se bars, the model orange), channels by line style and marker; the
    legend right of the panels."""
    from matplotlib.lines import Line2D
    L = r["sim_p"].shape[1]
    C = r["sim_p"].shape[4]
    rows = r["metrics"]["lobes"] if r["metrics"] else []
    phis = sorted({x["phi_i_deg"] for x in rows if x["phi_i_deg"] is not None}) or [None]
    height = 1.0 + 3.25 * len(phis)
    fig, axes = plt.subplots(len(phis), L, figsize=(12, height), dpi=100, squeeze=False)
    fig.suptitle("Energy per lobe against theta_i: simulation (1 se) and %s" % r["model"], fontsize=11)
    for i, phi in enumerate(phis):
        for l in range(L):
            ax = axes[i, l]
            for c in range(C):
                line, marker = CHANNEL_STYLES[c % len(CHANNEL_STYLES)]
                sel = sorted((x for x in rows if x["lobe"] == l and x["channel"] == c and x["phi_i_deg"] == phi),
                             key=lambda x: x["theta_i_deg"])
                th = [x["theta_i_deg"] for x in sel]
                # A wide dash marks each model value: with one theta_i there is no line to see.
                ax.plot(th, [x["model_energy"] for x in sel], line, marker="_", ms=16, mew=1.6, color="C1", lw=1.4,
                        zorder=2)
                ax.errorbar(th, [x["sim_energy"] for x in sel], yerr=[x["sim_error"] or 0 for x in sel],
                            fmt=marker, ms=4, color="k", mfc="white" if c else "k", zorder=3)
            title = r["lobe_names"][l] + ("" if phi is None or len(phis) == 1 else ", phi_i %g deg" % phi)
            ax.set_title(title, fontsize=10)
            ax.set_xlabel("theta_i (deg)", fontsize=9)
            ax.tick_params(labelsize=8)
            if l == 0:
                ax.set_ylabel("energy (fraction of incident light)", fontsize=9)
    handles = [Line2D([], [], color="k", marker="o", ls="none", label="simulation (1 se)"),
               Line2D([], [], color="C1", lw=1.4, marker="_", ms=16, mew=1.6, label=r["model"])]
    if C > 1:
        for c in range(C):
            line, marker = CHANNEL_STYLES[c % len(CHANNEL_STYLES)]
            handles.append(Line2D([], [], color="gray", ls=line, marker=marker, mfc="white" if c else "gray",
                                  label="channel %s" % r["channel_names"][c]))
    fig.legend(handles=handles, loc="center right", fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.07, right=0.84, top=1 - 0.7 / height, bottom=0.55 / height, wspace=0.38, hspace=0.5)
    return fig


def png_size(data):
    """(width, height) from a PNG's header."""
    import struct
    return struct.unpack(">II", data[16:24])


def save_figure(fig, d, stem, plt):
    """DIR/stem.png (fixed pixel size, embedded in report.html) and
    DIR/stem.svg beside it (vector, for papers); the PNG as base64."""
    png = os.path.join(d, stem + ".png")
    fig.savefig(png, dpi=100)
    fig.savefig(os.path.join(d, stem + ".svg"))
    plt.close(fig)
    with open(png, "rb") as f:
        return base64.b64encode(f.read()).decode("ascii")


def img(b64, alt, stem):
    """The PNG inline at its natural size (width and height attributes: never
    scaled down, a narrow window scrolls it) and a link to the SVG beside
    report.html."""
    w, h = png_size(base64.b64decode(b64[:64]))
    return ('<div class="fig"><img alt="%s" width="%d" height="%d" src="data:image/png;base64,%s"></div>'
            '<p class="svg"><a href="%s.svg">%s.svg</a> (vector)</p>'
            % (html.escape(alt), w, h, b64, html.escape(stem), html.escape(stem)))


PAGE_STYLE = """
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1240px; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; font-size: 0.8em; margin: 0.6em 0; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
th { background: #f0f0f0; } td.l { text-align: left; }
.ok { color: #176317; } .bad { color: #b00020; font-weight: bold; } .nj { color: #888; }
.fig { overflow-x: auto; margin: 0.5em 0; }
.fig img { display: block; max-width: none; }
p.svg { font-size: 0.8em; margin: 0 0 1em 0; }
.note { font-size: 0.85em; color: #555; }
"""


# Kinds a parameter table puts in its unit column (analytic/model_params.h)
# that are not units: the value alone is shown (`absorption = chord`).
NOT_UNITS = ("integer", "choice")


def param_text(v):
    """A metrics.json parameter: a number or list, or {"value": ..., "unit": ...}."""
    if isinstance(v, dict) and "value" in v:
        unit = v.get("unit") or ""
        return ("%s %s" % (v["value"], "" if unit in NOT_UNITS else unit)).strip()
    return str(v)


def verdict_cell(row):
    if not row["judged"]:
        return '<td class="l nj">not judged</td>'
    return '<td class="l ok">ok</td>' if row["accepted"] else '<td class="l bad">rejected</td>'


def fmt(v, spec):
    return "&ndash;" if v is None else spec % v


def rows_table(rows):
    head = ("<tr><th>lobe</th><th>channel</th><th>E_sim &plusmn; se</th><th>E_model</th><th>z</th>"
            "<th>chi2/dof (dof)</th><th>threshold</th><th>theta marg.</th><th>phi marg.</th><th>L1</th>"
            "<th>centroid sim / model (deg)</th><th>shift (deg)</th><th>verdict</th></tr>")
    body = []
    for x in rows:
        body.append("<tr><td class=\"l\">%s</td><td>%d</td><td>%s &plusmn; %s</td><td>%s</td><td>%s</td>"
                    "<td>%s (%d)</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s / %s</td><td>%s</td>%s</tr>"
                    % (html.escape(x["lobe_name"]), x["channel"], fmt(x["sim_energy"], "%.5f"),
                       fmt(x["sim_error"], "%.5f"), fmt(x["model_energy"], "%.5f"), fmt(x["energy_z"], "%.1f"),
                       fmt(x["chi2_per_dof"], "%.3f"), x["dof"], fmt(x["threshold"], "%.3f"),
                       fmt(x["theta_marginal_chi2_per_dof"], "%.3f"), fmt(x["phi_marginal_chi2_per_dof"], "%.3f"),
                       fmt(x["l1"], "%.3f"), fmt(x["centroid_sim_deg"], "%.2f"), fmt(x["centroid_model_deg"], "%.2f"),
                       fmt(x["measured_shift_deg"], "%.2f"), verdict_cell(x)))
    return "<table>%s%s</table>" % (head, "".join(body))


def write_html(path, title, parts):
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>%s</title>"
            "<style>%s</style></head><body>\n%s\n</body></html>\n" % (html.escape(title), PAGE_STYLE, "\n".join(parts)))
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, path)  # complete or absent


def plot_compare(d, np, plt, h5py):
    from matplotlib import colors
    r = load_compare(d, np, h5py)
    K = r["sim_p"].shape[0]
    metrics = r["metrics"]
    names = [incidence_name(r["theta_i"][k], r["phi_i"][k]) for k in range(K)]
    shown = list(range(min(K, MAX_FIGURE_CONFIGS)))
    left_out = list(range(len(shown), K))

    title = "%s against %s" % (metrics["result"] if metrics else "simulation", r["model"])
    parts = ["<h1>%s</h1>" % html.escape(title)]
    if metrics:
        params = ", ".join("%s = %s" % (key, param_text(v)) for key, v in (metrics["params"] or {}).items())
        judged = [x for x in metrics["lobes"] if x["judged"]]
        accepted = sum(1 for x in judged if x["accepted"])
        if params:
            parts.append("<p>Model parameters: <code>%s</code></p>" % html.escape(params))
        parts.append("<p>Criterion per lobe: %s. Verdict: <b class=\"%s\">%s</b> (%d of %d judged lobes accepted).</p>"
                     % (html.escape(metrics["criterion"]), "ok" if metrics["accepted"] else "bad",
                        "accepted" if metrics["accepted"] else "rejected", accepted, len(judged)))
    parts.append("<p class=\"note\">Angles in degrees; densities per steradian (sr<sup>-1</sup>) = bin "
                 "probability / solid angle; residuals in simulated standard errors; energies are fractions of "
                 "the incident light. Heatmaps and marginals show channel %s, the polar plots every channel; "
                 "grey bins hold no simulated photon (no data), the darkest colour is zero or below the colour "
                 "range. Every figure is also an SVG file beside this page (linked under it).</p>"
                 % html.escape(r["channel_names"][r["channel"]]))
    parts.append("<h2>Incident directions</h2><ol>%s</ol>" % "".join(
        '<li><a href="#k%d">%s</a>%s</li>' % (k, html.escape(names[k]), "" if k in shown else " (table only)")
        for k in range(K)))
    if left_out:
        parts.append("<p><b>Left out of the figures</b> (their rows are in the tables below and in metrics.csv): %s. "
                     "Reason: figures are drawn for the first %d incident directions only, to keep this page "
                     "small enough to open.</p>" % (html.escape("; ".join(names[k] for k in left_out)),
                                                    MAX_FIGURE_CONFIGS))
    if metrics:
        b64 = save_figure(plot_energy_lobes(r, np, plt), d, "compare_energy", plt)
        parts.append("<h2>Energy per lobe against theta_i</h2>" + img(b64, "energy per lobe against theta_i",
                                                                      "compare_energy"))
    for k in range(K):
        parts.append('<h2 id="k%d">%s</h2>' % (k, html.escape(names[k])))
        if r["photons"] is not None:
            parts.append("<p class=\"note\">%d photons launched.</p>" % r["photons"][k])
        if metrics:
            parts.append(rows_table([x for x in metrics["lobes"] if x["k"] == k]))
        if k not in shown:
            parts.append("<p class=\"note\">Figures left out (see above).</p>")
            continue
        figures = (("heatmaps", lambda: plot_heatmaps(r, k, np, plt, colors)),
                   ("marginals", lambda: plot_theta_marginals(r, k, np, plt)),
                   ("polar", lambda: plot_polar(r, k, np, plt)))
        for suffix, make in figures:
            stem = "compare_%s_%s" % (incidence_stem(r["theta_i"][k], r["phi_i"][k]), suffix)
            parts.append(img(save_figure(make(), d, stem, plt), "%s: %s" % (names[k], suffix), stem))
    write_html(os.path.join(d, "report.html"), title, parts)


MODEL_MARKERS = "sD^vPX<>ph"


def source_colours(curves, plt):
    """One style per source, the same in every figure of the page: the
    simulation black points, every model its own colour (tab10, tab20 past
    ten) and marker, drawn thinner than the one before it so that models
    giving the same curve show as nested stripes instead of hiding each
    other."""
    models = [c["label"] for c in curves if not c["simulated"]]
    cmap = plt.get_cmap("tab10" if len(models) <= 10 else "tab20")
    styles = {label: (cmap(i % cmap.N), MODEL_MARKERS[i % len(MODEL_MARKERS)], max(3.2 - 0.5 * i, 0.9))
              for i, label in enumerate(models)}
    styles.update({c["label"]: ("k", "o", 1.0) for c in curves if c["simulated"]})
    return styles


def draw_source(ax, c, th, y, err, style):
    colour, marker, width = style
    if c["simulated"]:
        ax.errorbar(th, y, yerr=err, fmt=marker, ms=4, color=colour, label=c["label"], zorder=3)
    else:
        ax.plot(th, y, "-", marker=marker, ms=3 + width, mfc="none", lw=width, color=colour, label=c["label"],
                zorder=2)


def plot_energy(d, np, plt):
    with open(os.path.join(d, "metrics.json")) as f:
        m = json.load(f)
    curves = m["curves"]
    swept = [c for c in curves if c["beta_long_deg"] is not None]
    figures = [("Energy against theta_i", "energy", energy_figure(m, np, plt))]
    if swept:
        figures.append(("Total energy per longitudinal roughness (cf. d'Eon et al. 2011 Fig. 3)", "energy_roughness",
                        plot_roughness_sweep(swept, m["white"], np, plt)))
    if m["white"]:
        figures.append(("White furnace: departure of the total from 1", "energy_furnace",
                        plot_furnace(curves, source_colours(curves, plt), np, plt)))
    write_energy_html(d, m, [(caption, save_figure(fig, d, stem, plt), stem) for caption, stem, fig in figures])


def energy_figure(m, np, plt):
    """energy.png: total and R+TT+TRT on top, one panel per lobe below; one
    colour per source (the simulation black with 1-se bars), the legend
    right of the panels."""
    curves = m["curves"]
    plain = [c for c in curves if c["beta_long_deg"] is None]
    shown = plain if plain else curves
    colours = source_colours(shown, plt)
    L = len(shown[0]["lobe_names"]) if shown else 0
    fig = plt.figure(figsize=(12, 8), dpi=100)
    fig.suptitle("Energy against theta_i (channel %d)%s" % (
        m["channel"], "; white fiber: 1 is the white furnace" if m["white"] else ""), fontsize=12)
    grid = fig.add_gridspec(2, max(L, 2), left=0.07, right=0.82, top=0.9, bottom=0.08, hspace=0.4, wspace=0.4)
    half = max(L, 2) // 2
    ax_total = fig.add_subplot(grid[0, :half])
    ax_three = fig.add_subplot(grid[0, half:])
    lobe_axes = [fig.add_subplot(grid[1, l]) for l in range(L)]
    for c in sorted(shown, key=lambda c: not c["simulated"]):
        th = np.array(c["theta_i_deg"], dtype=float)
        colour = colours[c["label"]]
        draw_source(ax_total, c, th, np.array(c["total"], dtype=float), c["total_error"] if c["simulated"] else None,
                    colour)
        draw_source(ax_three, c, th, np.array(c["three_lobe"], dtype=float), None, colour)
        errors = c.get("lobe_errors")
        for l, ax in enumerate(lobe_axes):
            err = errors[l] if c["simulated"] and errors else None
            draw_source(ax, c, th, np.array(c["lobes"][l], dtype=float), err, colour)
    if m["white"]:
        for ax in (ax_total, ax_three):
            ax.axhline(1.0, color="gray", lw=0.8, ls="--")
    ax_total.set_title("total (every lobe)", fontsize=10)
    ax_three.set_title("R + TT + TRT (what three-lobe models hold)", fontsize=10)
    for l, ax in enumerate(lobe_axes):
        ax.set_title("lobe %s" % shown[0]["lobe_names"][l], fontsize=10)
    for ax in [ax_total, ax_three] + lobe_axes:
        ax.set_xlabel("theta_i (deg)", fontsize=9)
        ax.tick_params(labelsize=8)
    ax_total.set_ylabel("energy (fraction of incident light)", fontsize=9)
    if lobe_axes:
        lobe_axes[0].set_ylabel("energy (fraction of incident light)", fontsize=9)
    fig.legend(*ax_total.get_legend_handles_labels(), loc="center right", fontsize=8, frameon=False,
               title="source", title_fontsize=9)
    return fig


def plot_roughness_sweep(swept, white, np, plt):
    """Total energy against theta_i, one panel per model, one line per
    beta_long in a sequential colour map (beta is ordered), the legend right
    of the panels (the same betas in every panel)."""
    labels = sorted({c["label"].rsplit(" beta_long=", 1)[0] for c in swept})
    betas = sorted({c["beta_long_deg"] for c in swept})
    cmap = plt.get_cmap("viridis")
    colour = {b: cmap(i / max(len(betas) - 1, 1) * 0.9) for i, b in enumerate(betas)}
    fig, axes = plt.subplots(1, len(labels), figsize=(12, 6), dpi=100, squeeze=False)
    fig.suptitle("Total energy against theta_i per longitudinal roughness (cf. d'Eon et al. 2011 Fig. 3)",
                 fontsize=12)
    for ax, label in zip(axes[0], labels):
        for c in swept:
            if c["label"].rsplit(" beta_long=", 1)[0] == label:
                ax.plot(c["theta_i_deg"], c["total"], "-", marker=".", color=colour[c["beta_long_deg"]],
                        label="beta_long = %g deg" % c["beta_long_deg"])
        if white:
            ax.axhline(1.0, color="gray", lw=0.8, ls="--")
        ax.set_title(label, fontsize=10)
        ax.set_xlabel("theta_i (deg)", fontsize=9)
        ax.tick_params(labelsize=8)
    axes[0, 0].set_ylabel("total energy (fraction of incident light)", fontsize=9)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="center right", fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.07, right=0.82, top=0.88, bottom=0.1, wspace=0.3)
    return fig


def plot_furnace(curves, colours, np, plt):
    """White furnace (d'Eon et al. 2011 s4, Figs. 3 and 5): a white fiber
    absorbs nothing, so every source's total energy should be 1. |total - 1|
    on a log scale against theta_i, the simulation with its standard error
    (its ledger balances to rounding, so this is the Monte Carlo noise)."""
    fig, ax = plt.subplots(figsize=(12, 4), dpi=100)
    fig.suptitle("White furnace: |total energy - 1| against theta_i (0 for an energy-conserving source)",
                 fontsize=11)
    floor = 1e-7
    for c in curves:
        th = np.array(c["theta_i_deg"], dtype=float)
        dev = np.maximum(np.abs(np.array(c["total"], dtype=float) - 1.0), floor)
        draw_source(ax, c, th, dev, c["total_error"] if c["simulated"] else None, colours[c["label"]])
    ax.set_yscale("log")
    ax.set_ylim(bottom=floor)
    ax.set_xlabel("theta_i (deg)", fontsize=9)
    ax.set_ylabel("|total - 1| (floored at 1e-7)", fontsize=9)
    ax.tick_params(labelsize=8)
    fig.legend(*ax.get_legend_handles_labels(), loc="center right", fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.07, right=0.78, top=0.88, bottom=0.14)
    return fig


def write_energy_html(d, m, figures):
    """report.html for `fiberlab energy --report`: the figures and the totals."""
    title = "Energy: %s" % m.get("input", "")
    parts = ["<h1>%s</h1>" % html.escape(title),
             "<p>Channel %d. %s</p>" % (m["channel"], "White fiber: the white furnace applies, every source's total "
                                        "should be 1." if m["white"] else "Absorbing fiber: no furnace test.")]
    for caption, b64, stem in figures:
        parts.append("<h2>%s</h2>%s" % (html.escape(caption), img(b64, caption, stem)))
    head = "<tr><th>source</th><th>theta_i (deg)</th><th>total</th><th>R+TT+TRT</th>%s</tr>" % (
        "<th>total - 1</th>" if m["white"] else "")
    body = []
    for c in m["curves"]:
        for i, th in enumerate(c["theta_i_deg"]):
            total = c["total"][i]
            body.append("<tr><td class=\"l\">%s</td><td>%.2f</td><td>%s</td><td>%s</td>%s</tr>" % (
                html.escape(c["label"]), th, fmt(total, "%.5f"), fmt(c["three_lobe"][i], "%.5f"),
                "<td>%s</td>" % fmt(None if total is None else total - 1.0, "%+.5f") if m["white"] else ""))
    parts.append("<h2>Totals</h2><table>%s%s</table>" % (head, "".join(body)))
    write_html(os.path.join(d, "report.html"), title, parts)


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("compare", "energy", "atlas"):
        print(__doc__.splitlines()[2])
        return 2
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
        import h5py
    except ImportError as e:
        print("python modules missing: %s" % e)
        return 3
    kind, d = sys.argv[1], sys.argv[2]
    if kind == "compare":
        plot_compare(d, np, plt, h5py)
    elif kind == "atlas":  # `fiberlab atlas`: scripts/plot_atlas.py
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import plot_atlas
        plot_atlas.plot_atlas(d, np, plt, h5py, save_figure, img, write_html)
    else:
        plot_energy(d, np, plt)
    return 0


if __name__ == "__main__":
    sys.exit(main())
