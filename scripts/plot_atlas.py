"""Figures and the HTML page of `fiberlab atlas` (called by plot_report.py
with kind "atlas"; reads DIR/report_data.h5, format fiber-atlas, and
DIR/atlas_tables.md written by the command).

Figures (fixed pixel sizes; each also as .svg beside the .png):
  atlas_error_vs_roughness.png  one panel per model: per lobe, the largest
                                |E_model - E_sim| over theta_i and channels
                                against the fiber's roughness (the sweep's
                                roughness entries in order, labelled; the
                                median over the other sweep axes). The
                                entries are categories: a dot plot, the
                                lobes side by side in each, physical
                                defaults filled and fitted values open, no
                                line joining categories
  atlas_error_vs_theta_i.png    one panel per model: per lobe, |E_model -
                                E_sim| against theta_i (median over fibers
                                and channels; solid before, dashed after)
  atlas_chi2_vs_roughness.png   as the first, for chi2/dof (log scale)
Legends stand right of the panels, outside the data.
"""
import html
import os


def text_attr(f, obj, name, default=""):
    a = f[obj].attrs if obj != "/" else f.attrs
    if name not in a:
        return default
    v = a[name]
    return v.decode() if isinstance(v, bytes) else str(v)


def load(d, np, h5py):
    with h5py.File(os.path.join(d, "report_data.h5"), "r") as f:
        a = {"theta_i": np.degrees(f["theta_i"][...]),
             "roughness": f["fibers/roughness"][...],
             "roughness_index": f["fibers/roughness_index"][...],
             "rough_models": text_attr(f, "fibers", "roughness_models").split("\n"),
             "sim_energy": f["fibers/sim_energy"][...],
             "lobes": text_attr(f, "/", "lobe_names").split(","),
             "config_yaml": text_attr(f, "/", "config_yaml"),
             "models": {}}
        for name in text_attr(f, "/", "models").split(","):
            g = f["models/" + name]
            a["models"][name] = {k: g[k][...] for k in ("model_energy_before", "model_energy_after", "chi2_before",
                                                          "dof_before", "chi2_after", "dof_after", "applicable")}
    return a


def roughness_extras(config_yaml):
    """Per sweep.roughness entry, its keys other than model and size (ggx's
    masking, ...), so that two entries of one model are told apart on the
    axis. Empty when the config cannot be read (python3-yaml missing)."""
    try:
        import yaml
        entries = yaml.safe_load(config_yaml)["sweep"]["roughness"]
        return [", ".join("%s %s" % (k, v) for k, v in e.items() if k not in ("model", "beta_long", "alpha"))
                for e in entries]
    except Exception:  # optional decoration only: the label keeps model and size
        return []


def roughness_axis(a, np):
    """x positions (the sweep's roughness entries in order) and tick labels."""
    idx = a["roughness_index"]
    entries = sorted(set(int(i) for i in idx))
    extras = roughness_extras(a.get("config_yaml", ""))
    labels = []
    for e in entries:
        f = int(np.flatnonzero(idx == e)[0])
        model = a["rough_models"][f] if f < len(a["rough_models"]) else "?"
        r = a["roughness"][f]
        label = (model if model == "smooth" else
                 ("%s %g°" % (model, r) if model in ("gaussian", "exit_blur") else "%s α %g" % (model, r)))
        extra = extras[e] if e < len(extras) else ""
        labels.append(label + ("\n" + extra if extra else ""))
    return entries, labels


def nanmedian(np, x, axis):
    with np.errstate(all="ignore"):
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return np.nanmedian(x, axis=axis)


def nanmax(np, x, axis):
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.nanmax(x, axis=axis)


def panels(plt, n, legend_width=0.0):
    """One panel per model, up to 3 a row; legend_width (figure fraction)
    kept free on the right for the legend, outside every panel."""
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    height = 0.9 + 3.8 * rows
    fig, axes = plt.subplots(rows, cols, figsize=(12, height), dpi=100, squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    fig.subplots_adjust(left=0.07, right=0.98 - legend_width, top=1 - 0.75 / height, bottom=1.05 / height,
                        wspace=0.42, hspace=0.62)
    return fig, axes.flat


def lobe_legend(fig, lobes, colours, before_after):
    """The figure's legend right of the panels: a colour per lobe, then
    filled / open markers for physical defaults / fitted."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=colours(l), marker="o", ls="none", label=lobe) for l, lobe in enumerate(lobes)]
    handles += [Line2D([], [], color="gray", marker="o", ls=before_after[0], label="physical defaults"),
                Line2D([], [], color="gray", marker="o", mfc="white", ls=before_after[1], label="fitted")]
    fig.legend(handles=handles, loc="center right", fontsize=8, frameon=False, title="lobe", title_fontsize=9)


LEGEND_WIDTH = 0.13


def readable_log_axis(ax, plt):
    """Log y axis whose ticks carry numbers even when the data span less
    than a decade (ticks at 1, 2, 5 x 10^n then, two significant digits)."""
    lo, hi = ax.get_ylim()
    if lo > 0 and hi / lo < 30:
        from matplotlib import ticker
        ax.yaxis.set_major_locator(ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: "%g" % float("%.2g" % v)))
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())


def error_vs_roughness(a, np, plt, chi2=False):
    """A dot plot: the roughness entries are categories (gaussian 10 deg and
    ggx alpha 0.1 are different fibers, not points of one curve), so no line
    joins them; per category the lobes side by side (a colour each), the
    physical defaults filled and the fitted values open."""
    entries, labels = roughness_axis(a, np)
    names = list(a["models"])
    fig, axes = panels(plt, len(names), LEGEND_WIDTH)
    colours = plt.get_cmap("tab10")
    L = len(a["lobes"])
    slot = 0.8 / (2 * L)  # each lobe a pair of slots (before, after) within +-0.4 of the category
    for ax, name in zip(axes, names):
        m = a["models"][name]
        for l in range(L):
            for j, which in enumerate(("before", "after")):
                if chi2:
                    c2 = np.nansum(m["chi2_" + which][:, :, l, :], axis=(1, 2))
                    dof = np.nansum(m["dof_" + which][:, :, l, :], axis=(1, 2))
                    with np.errstate(all="ignore"):
                        per_fiber = np.where(dof > 0, c2 / np.maximum(dof, 1), np.nan)
                else:
                    err = np.abs(m["model_energy_" + which][:, :, l, :] - a["sim_energy"][:, :, l, :])
                    per_fiber = nanmax(np, err.reshape(err.shape[0], -1), 1)
                y = [nanmedian(np, per_fiber[a["roughness_index"] == e], 0) for e in entries]
                x = np.arange(len(entries)) - 0.4 + slot * (2 * l + j + 0.5)
                ax.plot(x, y, ls="none", marker="o", ms=5, color=colours(l), mfc=colours(l) if j == 0 else "white",
                        mew=1.2)
        for i in range(1, len(entries)):
            ax.axvline(i - 0.5, color="0.85", lw=0.8, zorder=0)
        ax.set_title(name, fontsize=10)
        ax.set_xlim(-0.5, len(entries) - 0.5)
        ax.set_xticks(range(len(entries)))
        ax.set_xticklabels(labels, fontsize=8, rotation=20, ha="right")
        ax.set_yscale("log")
        ax.set_xlabel("fiber roughness (sweep entry)", fontsize=8)
        ax.set_ylabel("median chi$^2$/dof" if chi2 else "median max $|E_{model} - E_{sim}|$", fontsize=8)
        ax.tick_params(labelsize=8)
        ax.grid(axis="y", which="major", color="0.92", lw=0.6)
        readable_log_axis(ax, plt)
    lobe_legend(fig, a["lobes"], colours, ("none", "none"))
    fig.suptitle("%s per lobe and roughness, median over the other sweep axes (filled: physical defaults, open: "
                 "fitted)" % ("chi2/dof" if chi2 else "energy error (fraction of incident light)"), fontsize=11)
    return fig


def error_vs_theta(a, np, plt):
    names = list(a["models"])
    fig, axes = panels(plt, len(names), LEGEND_WIDTH)
    colours = plt.get_cmap("tab10")
    for ax, name in zip(axes, names):
        m = a["models"][name]
        for l, lobe in enumerate(a["lobes"]):
            for which, style in (("before", "-"), ("after", "--")):
                err = np.abs(m["model_energy_" + which][:, :, l, :] - a["sim_energy"][:, :, l, :])  # F K C
                y = nanmedian(np, err.transpose(1, 0, 2).reshape(err.shape[1], -1), 1)
                ax.plot(a["theta_i"], y, style, marker="o", ms=4, color=colours(l),
                        mfc=colours(l) if which == "before" else "white", label="%s %s" % (lobe, which))
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("theta_i (deg)", fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel("median $|E_{model} - E_{sim}|$", fontsize=8)
        ax.tick_params(labelsize=8)
        ax.grid(axis="y", which="major", color="0.92", lw=0.6)
        readable_log_axis(ax, plt)
    lobe_legend(fig, a["lobes"], colours, ("-", "--"))
    fig.suptitle("energy error per lobe against theta_i, median over fibers and channels (solid, filled: physical "
                 "defaults; dashed, open: fitted)", fontsize=11)
    return fig


def md_tables_to_html(text):
    """The pipe tables and headings of atlas_tables.md as HTML."""
    out, rows = [], []

    def flush():
        if rows:
            head, body = rows[0], [r for r in rows[2:]]
            out.append("<table><tr>%s</tr>%s</table>" % (
                "".join("<th>%s</th>" % html.escape(c) for c in head),
                "".join("<tr>%s</tr>" % "".join('<td class="l">%s</td>' % html.escape(c) for c in r) for r in body)))
            rows.clear()

    for line in text.splitlines():
        if line.startswith("|"):
            rows.append([c.strip().replace("\\|", "|") for c in line.strip().strip("|").split(" | ")])
            continue
        flush()
        if line.startswith("## "):
            out.append("<h2>%s</h2>" % html.escape(line[3:]))
        elif line.strip():
            out.append("<p>%s</p>" % html.escape(line))
    flush()
    return "\n".join(out)


def plot_atlas(d, np, plt, h5py, save_figure, img, write_html):
    a = load(d, np, h5py)
    figures = [("Energy error per lobe against roughness", "atlas_error_vs_roughness",
                lambda: error_vs_roughness(a, np, plt)),
               ("chi2/dof per lobe against roughness", "atlas_chi2_vs_roughness",
                lambda: error_vs_roughness(a, np, plt, chi2=True)),
               ("Energy error per lobe against theta_i", "atlas_error_vs_theta_i", lambda: error_vs_theta(a, np, plt))]
    parts = ["<h1>fiberlab atlas</h1>"]
    tables = os.path.join(d, "atlas_tables.md")
    body = md_tables_to_html(open(tables, encoding="utf-8").read()) if os.path.exists(tables) else ""
    for caption, stem, make in figures:
        parts.append("<h2>%s</h2>%s" % (html.escape(caption), img(save_figure(make(), d, stem, plt), caption, stem)))
    parts.append(body)
    write_html(os.path.join(d, "report.html"), "fiberlab atlas", parts)
