#!/usr/bin/python3
"""Plots and the HTML page for `fiberlab compare --report DIR` and
`fiberlab energy --report DIR`.

Usage: /usr/bin/python3 scripts/plot_report.py compare|energy|atlas DIR

Reads DIR/report_data.h5 and DIR/metrics.json (compare) or DIR/metrics.json
(energy), writes PNGs and DIR/report.html into DIR. report.html is one
self-contained file: every figure embedded as a base64 PNG, no script, no
external URL. Needs Debian's python3-matplotlib, python3-h5py and numpy (run
it with /usr/bin/python3, not a pyenv `python3`). Exit status 3 when those
are missing (the caller then reports "plots skipped"), 2 on bad arguments.

Figures have fixed pixel sizes (no tight bounding box), so tests can check
the PNG headers. Per incident direction, named by theta_i and phi_i in
degrees ({DIR} = theta30.0_phi0.0, or theta30.0_phiuniform):
  compare_{DIR}_heatmaps.png  1200 x 1200: per lobe, simulated and predicted
                              density (sr^-1, log colour scale), the
                              normalised residual (P_sim - P_model) / se and
                              log10(P_sim / P_model) (the colour bar's end
                              colours where only one side has light: the
                              simulation, or the model expecting >= 3
                              photons in the bin); grey = no data (no
                              simulated photon in the bin; for the ratio, no
                              light on either side); a lobe with 3/4 of its
                              light at |phi| > 90 deg (TT) is drawn on phi in
                              [0, 360) so it is not cut at +-180 deg
  compare_{DIR}_marginals.png 1200 x 1200: per lobe, the theta_r marginal
                              (probability per degree, log y; simulation with
                              1-se error bars, model as steps) over its
                              normalised residual
  compare_{DIR}_polar.png     1200 x 400: per lobe, the phi marginal in polar
                              form for every channel (points: simulation,
                              lines: model)
  compare_energy.png          1200 x 400: per lobe, energy against theta_i,
                              simulation (1 se) and model, channel shown
  energy.png                  1200 x 800: total, R+TT+TRT and per-lobe
                              energy against theta_i for every source
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
    c = r["channel"]
    L = r["sim_p"].shape[1]
    fig, axes = plt.subplots(L, 4, figsize=(12, 12), dpi=100, squeeze=False)
    fig.suptitle("%s, channel %s: simulation | %s | residual | log ratio"
                 % (incidence_name(r["theta_i"][k], r["phi_i"][k]), r["channel_names"][c], r["model"]), fontsize=11)
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
        panels = [(sim_shown, "simulated", magma, norm, "density (sr$^{-1}$)"),
                  (np.maximum(dm, lo), r["model"], magma, norm, "density (sr$^{-1}$)")]
        with np.errstate(divide="ignore", invalid="ignore"):
            res = np.where(se > 0, (s - m) / se, np.nan)
            # Light on one side only: beyond the colour range (the bar's end
            # colours), not "no data", so that a model lighting bins the
            # simulation left empty shows, when it expects >= 3 photons there
            # (m N >= 3; photon weights <= 1 make that a lower bound).
            n = r["photons"][k] if r["photons"] is not None else np.inf
            ratio = np.where((s > 0) & (m > 0), np.log10(s / m),
                             np.where(m * n >= 3, -99.0, np.where(s > 0, 99.0, np.nan)))
        panels.append((np.ma.masked_invalid(res), "(sim - model) / se", diverging,
                       colors.Normalize(-5, 5), "standard errors"))
        panels.append((np.ma.masked_invalid(ratio), "log10(sim / model)", ratio_map,
                       colors.Normalize(-1, 1), "log10 ratio"))
        for j, (arr, title, cmap, nrm, unit) in enumerate(panels):
            ax = axes[l, j]
            ax.set_facecolor(NO_DATA)
            im = ax.pcolormesh(pe, te, arr, cmap=cmap, norm=nrm, shading="flat", rasterized=True)
            ax.set_title("%s: %s" % (r["lobe_names"][l], title), fontsize=9)
            cb = fig.colorbar(im, ax=ax, extend="both" if j >= 2 else "min")
            cb.set_label(unit, fontsize=7)
            cb.ax.tick_params(labelsize=6)
            ax.tick_params(labelsize=7)
            ax.set_xlim(pe[0], pe[-1])
            ax.set_ylim(*theta_range)
            if j == 0:
                ax.set_ylabel("theta_r (deg)", fontsize=8)
            if l == L - 1 or pe[0] >= 0:
                ax.set_xlabel("phi (deg)%s" % (", centred on 180" if pe[0] >= 0 else ""), fontsize=8)
    from matplotlib.patches import Patch
    fig.legend(handles=[Patch(color=NO_DATA, label="no data (no simulated photon)")], loc="lower center",
               fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.06, right=0.97, top=0.93, bottom=0.07, hspace=0.45, wspace=0.35)
    return fig


def plot_theta_marginals(r, k, np, plt):
    c = r["channel"]
    L = r["sim_p"].shape[1]
    te = r["te"]
    width = np.diff(te)
    centres = 0.5 * (te[:-1] + te[1:])
    fig = plt.figure(figsize=(12, 12), dpi=100)
    fig.suptitle("%s, channel %s: theta_r marginals, simulation (points, 1 se) and %s (steps)"
                 % (incidence_name(r["theta_i"][k], r["phi_i"][k]), r["channel_names"][c], r["model"]), fontsize=11)
    cols = 2
    rows = (L + cols - 1) // cols
    outer = fig.add_gridspec(rows, cols, hspace=0.35, wspace=0.25, left=0.07, right=0.98, top=0.93, bottom=0.06)
    for l in range(L):
        inner = outer[l // cols, l % cols].subgridspec(2, 1, height_ratios=[3, 1], hspace=0.05)
        ax = fig.add_subplot(inner[0])
        axr = fig.add_subplot(inner[1], sharex=ax)
        s = r["sim_p"][k, l, :, :, c].sum(axis=1)
        se = np.sqrt((r["sim_se"][k, l, :, :, c] ** 2).sum(axis=1))
        m = r["model_p"][k, l, :, :, c].sum(axis=1)
        ok = s > 0
        ax.errorbar(centres[ok], s[ok] / width[ok], yerr=se[ok] / width[ok], fmt=".", ms=3, lw=0.8,
                    label="simulation")
        ax.stairs(m / width, te, lw=1.0, label=r["model"])
        top = max((s / width).max(), (m / width).max())
        if top > 0:
            # Down to a fifth of the smallest simulated value (the model's tails
            # below what the simulation can see are cut), at most 7 decades.
            ax.set_yscale("log")
            floor = (s / width)[s > 0].min() * 0.2 if ok.any() else top * 1e-7
            bottom = max(floor, top * 1e-7)
            ax.set_ylim(bottom, top * 2)
            ax.set_xlim(*shown_range(np, te, (s > 0) | (m / width >= bottom)))
        ax.set_title("%s" % r["lobe_names"][l], fontsize=10)
        ax.set_ylabel("probability per degree", fontsize=8)
        ax.tick_params(labelsize=7, labelbottom=False)
        if l == 0:
            ax.legend(fontsize=7)
        with np.errstate(divide="ignore", invalid="ignore"):
            res = np.where(se > 0, (s - m) / se, np.nan)
        axr.axhline(0, color="gray", lw=0.6)
        axr.plot(centres, res, ".", ms=3, color="C0")
        axr.set_ylabel("(sim-model)/se", fontsize=7)
        axr.set_xlabel("theta_r (deg)", fontsize=8)
        axr.tick_params(labelsize=7)
        lim = np.nanmax(np.abs(res)) if np.isfinite(res).any() else 1.0
        axr.set_ylim(-max(3.0, lim * 1.1), max(3.0, lim * 1.1))
    return fig


def plot_polar(r, k, np, plt):
    L, C = r["sim_p"].shape[1], r["sim_p"].shape[4]
    pe = np.radians(r["pe"])
    centres = 0.5 * (pe[:-1] + pe[1:])
    width = np.degrees(np.diff(pe))
    names = r["channel_names"]
    palette = {"R": "tab:red", "G": "tab:green", "B": "tab:blue"}
    fig, axes = plt.subplots(1, L, figsize=(12, 4), dpi=100, subplot_kw={"projection": "polar"}, squeeze=False)
    fig.suptitle("%s: phi marginals per lobe (probability per degree; points simulation, lines %s)"
                 % (incidence_name(r["theta_i"][k], r["phi_i"][k]), r["model"]), fontsize=10)
    closed = np.append(centres, centres[0] + 2 * np.pi)
    for l in range(L):
        ax = axes[0, l]
        for c in range(C):
            color = palette.get(names[c], "C%d" % c)
            s = r["sim_p"][k, l, :, :, c].sum(axis=0) / width
            m = r["model_p"][k, l, :, :, c].sum(axis=0) / width
            ax.plot(centres, s, ".", ms=2.5, color=color, label="%s sim" % names[c])
            ax.plot(closed, np.append(m, m[0]), "-", lw=0.9, color=color, label="%s model" % names[c])
        ax.set_theta_zero_location("E")
        ax.yaxis.set_major_locator(plt.MaxNLocator(3))
        ax.set_rlabel_position(60)
        ax.yaxis.get_offset_text().set_fontsize(6)
        ax.set_title(r["lobe_names"][l], fontsize=10, pad=12)
        ax.tick_params(labelsize=6)
        if l == L - 1:
            ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.05, 1.0))
    fig.subplots_adjust(left=0.03, right=0.9, top=0.8, bottom=0.05, wspace=0.45)
    return fig


def plot_energy_lobes(r, np, plt):
    """Energy per lobe against theta_i: one panel per lobe, simulation with
    error bars and the model, one series per phi_i (from metrics.json)."""
    L = r["sim_p"].shape[1]
    c = r["channel"]
    rows = [x for x in r["metrics"]["lobes"] if x["channel"] == c] if r["metrics"] else []
    fig, axes = plt.subplots(1, L, figsize=(12, 4), dpi=100, squeeze=False)
    fig.suptitle("Energy per lobe against theta_i, channel %s: simulation (1 se) and %s"
                 % (r["channel_names"][c], r["model"]), fontsize=10)
    phis = sorted({x["phi_i_deg"] for x in rows if x["phi_i_deg"] is not None}) or [None]
    for l in range(L):
        ax = axes[0, l]
        for i, phi in enumerate(phis):
            sel = sorted((x for x in rows if x["lobe"] == l and x["phi_i_deg"] == phi),
                         key=lambda x: x["theta_i_deg"])
            th = [x["theta_i_deg"] for x in sel]
            tag = "" if phi is None or len(phis) == 1 else " phi_i %g" % phi
            ax.errorbar(th, [x["sim_energy"] for x in sel], yerr=[x["sim_error"] for x in sel], fmt="o", ms=4,
                        color="C%d" % i, label="simulation" + tag)
            ax.plot(th, [x["model_energy"] for x in sel], "-", color="C%d" % i, lw=1.2,
                    label=r["model"] + tag)
        ax.set_title(r["lobe_names"][l], fontsize=10)
        ax.set_xlabel("theta_i (deg)", fontsize=8)
        ax.tick_params(labelsize=7)
        if l == 0:
            ax.set_ylabel("energy (fraction of incident)", fontsize=8)
            ax.legend(fontsize=6)
    fig.subplots_adjust(left=0.06, right=0.98, top=0.85, bottom=0.14, wspace=0.3)
    return fig


def save_png(fig, path, plt):
    fig.savefig(path, dpi=100)
    plt.close(fig)
    with open(path, "rb") as f:
        return base64.b64encode(f.read()).decode("ascii")


def img(b64, alt):
    return '<img alt="%s" src="data:image/png;base64,%s">' % (html.escape(alt), b64)


PAGE_STYLE = """
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1240px; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; font-size: 0.8em; margin: 0.6em 0; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
th { background: #f0f0f0; } td.l { text-align: left; }
.ok { color: #176317; } .bad { color: #b00020; font-weight: bold; } .nj { color: #888; }
img { max-width: 100%; display: block; margin: 0.5em 0; }
.note { font-size: 0.85em; color: #555; }
"""


def param_text(v):
    """A metrics.json parameter: a number or list, or {"value": ..., "unit": ...}."""
    if isinstance(v, dict) and "value" in v:
        return ("%s %s" % (v["value"], v.get("unit") or "")).strip()
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
                 "the incident light. Heatmaps and theta marginals show channel %s; grey bins hold no simulated "
                 "photon (no data), the darkest colour is zero or below the colour range.</p>"
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
        b64 = save_png(plot_energy_lobes(r, np, plt), os.path.join(d, "compare_energy.png"), plt)
        parts.append("<h2>Energy per lobe against theta_i</h2>" + img(b64, "energy per lobe against theta_i"))
    for k in range(K):
        parts.append('<h2 id="k%d">%s</h2>' % (k, html.escape(names[k])))
        if r["photons"] is not None:
            parts.append("<p class=\"note\">%d photons launched.</p>" % r["photons"][k])
        if metrics:
            parts.append(rows_table([x for x in metrics["lobes"] if x["k"] == k]))
        if k not in shown:
            parts.append("<p class=\"note\">Figures left out (see above).</p>")
            continue
        for suffix, fig in (("heatmaps", plot_heatmaps(r, k, np, plt, colors)),
                            ("marginals", plot_theta_marginals(r, k, np, plt)),
                            ("polar", plot_polar(r, k, np, plt))):
            stem = incidence_stem(r["theta_i"][k], r["phi_i"][k])
            b64 = save_png(fig, os.path.join(d, "compare_%s_%s.png" % (stem, suffix)), plt)
            parts.append(img(b64, "%s: %s" % (names[k], suffix)))
    write_html(os.path.join(d, "report.html"), title, parts)


def plot_energy(d, np, plt):
    with open(os.path.join(d, "metrics.json")) as f:
        m = json.load(f)
    curves = m["curves"]
    plain = [c for c in curves if c["beta_long_deg"] is None]
    swept = [c for c in curves if c["beta_long_deg"] is not None]
    fig, axes = plt.subplots(1, 3, figsize=(12, 8), dpi=100)
    fig.suptitle("Energy against theta_i (channel %d)%s" % (
        m["channel"], ", white fiber: 1 is the white furnace" if m["white"] else ""))
    shown = plain if plain else curves
    for c in shown:
        th = np.array(c["theta_i_deg"])
        tot = np.array(c["total"], dtype=float)
        if c["simulated"]:
            axes[0].errorbar(th, tot, yerr=c["total_error"], fmt="ko", ms=4, label=c["label"])
            axes[1].errorbar(th, c["three_lobe"], fmt="ks", ms=4, label=c["label"])
        else:
            axes[0].plot(th, tot, "-", label=c["label"])
            axes[1].plot(th, c["three_lobe"], "-", label=c["label"])
        for l, name in enumerate(c["lobe_names"]):
            y = np.array(c["lobes"][l], dtype=float)
            style = "o" if c["simulated"] else "-"
            axes[2].plot(th, y, style, ms=3, lw=1, label="%s %s" % (c["label"], name))
    if m["white"]:
        for ax in axes[:2]:
            ax.axhline(1.0, color="gray", lw=0.8, ls="--")
    axes[0].set_title("total (every lobe)", fontsize=10)
    axes[1].set_title("R + TT + TRT (three-lobe models)", fontsize=10)
    axes[2].set_title("per lobe", fontsize=10)
    axes[2].set_yscale("log")
    for ax in axes:
        ax.set_xlabel("theta_i (deg)")
        ax.legend(fontsize=6)
    figures = [("Energy against theta_i", save_png(fig, os.path.join(d, "energy.png"), plt))]
    if swept:
        labels = sorted({c["label"].rsplit(" beta_long=", 1)[0] for c in swept})
        fig, axes = plt.subplots(1, len(labels), figsize=(12, 6), dpi=100, squeeze=False)
        fig.suptitle("Total energy against theta_i per longitudinal roughness (cf. d'Eon et al. 2011 Fig. 3)")
        for ax, label in zip(axes[0], labels):
            for c in swept:
                if c["label"].rsplit(" beta_long=", 1)[0] == label:
                    ax.plot(c["theta_i_deg"], c["total"], "-", label="beta = %g deg" % c["beta_long_deg"])
            if m["white"]:
                ax.axhline(1.0, color="gray", lw=0.8, ls="--")
            ax.set_title(label, fontsize=9)
            ax.set_xlabel("theta_i (deg)")
            ax.legend(fontsize=7)
        figures.append(("Total energy per longitudinal roughness (cf. d'Eon et al. 2011 Fig. 3)",
                        save_png(fig, os.path.join(d, "energy_roughness.png"), plt)))
    if m["white"]:
        figures.append(("White furnace: departure of the total from 1",
                        save_png(plot_furnace(curves, np, plt), os.path.join(d, "energy_furnace.png"), plt)))
    write_energy_html(d, m, figures)


def plot_furnace(curves, np, plt):
    """White furnace (d'Eon et al. 2011 s4, Figs. 3 and 5): a white fiber
    absorbs nothing, so every source's total energy should be 1. |total - 1|
    on a log scale against theta_i, the simulation with its standard error
    (its ledger balances to rounding, so this is the Monte Carlo noise)."""
    fig, ax = plt.subplots(figsize=(12, 4), dpi=100)
    fig.suptitle("White furnace: |total energy - 1| against theta_i (0 for an energy-conserving source)",
                 fontsize=10)
    floor = 1e-7
    for c in curves:
        th = np.array(c["theta_i_deg"], dtype=float)
        dev = np.abs(np.array(c["total"], dtype=float) - 1.0)
        label = c["label"]
        if c["simulated"]:
            ax.errorbar(th, np.maximum(dev, floor), yerr=c["total_error"], fmt="ko", ms=4, label=label)
        else:
            ax.plot(th, np.maximum(dev, floor), "-", lw=1.2, label=label)
    ax.set_yscale("log")
    ax.set_ylim(bottom=floor)
    ax.set_xlabel("theta_i (deg)")
    ax.set_ylabel("|total - 1| (floored at 1e-7)")
    ax.legend(fontsize=6, ncol=2)
    fig.subplots_adjust(left=0.07, right=0.98, top=0.88, bottom=0.14)
    return fig


def write_energy_html(d, m, figures):
    """report.html for `fiberlab energy --report`: the figures and the totals."""
    title = "Energy: %s" % m.get("input", "")
    parts = ["<h1>%s</h1>" % html.escape(title),
             "<p>Channel %d. %s</p>" % (m["channel"], "White fiber: the white furnace applies, every source's total "
                                        "should be 1." if m["white"] else "Absorbing fiber: no furnace test.")]
    for caption, b64 in figures:
        parts.append("<h2>%s</h2>%s" % (html.escape(caption), img(b64, caption)))
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
        plot_atlas.plot_atlas(d, np, plt, h5py, save_png, img, write_html)
    else:
        plot_energy(d, np, plt)
    return 0


if __name__ == "__main__":
    sys.exit(main())
