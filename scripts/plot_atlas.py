"""Figures and the HTML page of `fiberlab atlas` (called by plot_report.py
with kind "atlas"; reads DIR/report_data.h5, format fiber-atlas, and
DIR/atlas_tables.md written by the command).

Figures (fixed pixel sizes):
  atlas_error_vs_roughness.png  one panel per model: per lobe, the largest
                                |E_model - E_sim| over theta_i and channels
                                (physical defaults: solid; fitted: dashed),
                                against the fiber's roughness (the sweep's
                                roughness entries in order, labelled; the
                                median over the other sweep axes)
  atlas_error_vs_theta_i.png    one panel per model: per lobe, |E_model -
                                E_sim| against theta_i (median over fibers
                                and channels; solid before, dashed after)
  atlas_chi2_vs_roughness.png   as the first, for chi2/dof (log scale)
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
             "models": {}}
        for name in text_attr(f, "/", "models").split(","):
            g = f["models/" + name]
            a["models"][name] = {k: g[k][...] for k in ("model_energy_before", "model_energy_after", "chi2_before",
                                                          "dof_before", "chi2_after", "dof_after", "applicable")}
    return a


def roughness_axis(a, np):
    """x positions (the sweep's roughness entries in order) and tick labels."""
    idx = a["roughness_index"]
    entries = sorted(set(int(i) for i in idx))
    labels = []
    for e in entries:
        f = int(np.flatnonzero(idx == e)[0])
        model = a["rough_models"][f] if f < len(a["rough_models"]) else "?"
        r = a["roughness"][f]
        labels.append(model if model == "smooth" else
                      ("%s %g°" % (model, r) if model in ("gaussian", "exit_blur") else "%s α %g" % (model, r)))
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


def panels(plt, n):
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(12, 4 * rows), dpi=100, squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, axes.flat


def error_vs_roughness(a, np, plt, chi2=False):
    entries, labels = roughness_axis(a, np)
    names = list(a["models"])
    fig, axes = panels(plt, len(names))
    colours = plt.get_cmap("tab10")
    for ax, name in zip(axes, names):
        m = a["models"][name]
        for l, lobe in enumerate(a["lobes"]):
            for which, style in (("before", "-"), ("after", "--")):
                if chi2:
                    c2 = np.nansum(m["chi2_" + which][:, :, l, :], axis=(1, 2))
                    dof = np.nansum(m["dof_" + which][:, :, l, :], axis=(1, 2))
                    with np.errstate(all="ignore"):
                        per_fiber = np.where(dof > 0, c2 / np.maximum(dof, 1), np.nan)
                else:
                    err = np.abs(m["model_energy_" + which][:, :, l, :] - a["sim_energy"][:, :, l, :])
                    per_fiber = nanmax(np, err.reshape(err.shape[0], -1), 1)
                y = [nanmedian(np, per_fiber[a["roughness_index"] == e], 0) for e in entries]
                ax.plot(range(len(entries)), y, style, marker="o", color=colours(l),
                        label="%s %s" % (lobe, which))
        ax.set_title(name, fontsize=10)
        ax.set_xticks(range(len(entries)))
        ax.set_xticklabels(labels, fontsize=7, rotation=20)
        ax.set_yscale("log")
        ax.set_ylabel("chi2/dof" if chi2 else "max |E_model - E_sim|", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=6, ncol=2)
    fig.suptitle("%s per lobe against roughness (solid: physical defaults, dashed: fitted)"
                 % ("chi2/dof" if chi2 else "energy error"), fontsize=11)
    fig.subplots_adjust(left=0.07, right=0.98, top=0.9, bottom=0.12, wspace=0.3, hspace=0.45)
    return fig


def error_vs_theta(a, np, plt):
    names = list(a["models"])
    fig, axes = panels(plt, len(names))
    colours = plt.get_cmap("tab10")
    for ax, name in zip(axes, names):
        m = a["models"][name]
        for l, lobe in enumerate(a["lobes"]):
            for which, style in (("before", "-"), ("after", "--")):
                err = np.abs(m["model_energy_" + which][:, :, l, :] - a["sim_energy"][:, :, l, :])  # F K C
                y = nanmedian(np, err.transpose(1, 0, 2).reshape(err.shape[1], -1), 1)
                ax.plot(a["theta_i"], y, style, marker="o", color=colours(l), label="%s %s" % (lobe, which))
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("theta_i (deg)", fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel("|E_model - E_sim|", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=6, ncol=2)
    fig.suptitle("energy error per lobe against theta_i (median over fibers; solid: physical defaults, "
                 "dashed: fitted)", fontsize=11)
    fig.subplots_adjust(left=0.07, right=0.98, top=0.9, bottom=0.1, wspace=0.3, hspace=0.45)
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


def plot_atlas(d, np, plt, h5py, save_png, img, write_html):
    a = load(d, np, h5py)
    figures = [("Energy error per lobe against roughness", "atlas_error_vs_roughness.png", error_vs_roughness(a, np, plt)),
               ("chi2/dof per lobe against roughness", "atlas_chi2_vs_roughness.png",
                error_vs_roughness(a, np, plt, chi2=True)),
               ("Energy error per lobe against theta_i", "atlas_error_vs_theta_i.png", error_vs_theta(a, np, plt))]
    parts = ["<h1>fiberlab atlas</h1>"]
    tables = os.path.join(d, "atlas_tables.md")
    body = md_tables_to_html(open(tables, encoding="utf-8").read()) if os.path.exists(tables) else ""
    for caption, name, fig in figures:
        parts.append("<h2>%s</h2>%s" % (html.escape(caption), img(save_png(fig, os.path.join(d, name), plt), caption)))
    parts.append(body)
    write_html(os.path.join(d, "report.html"), "fiberlab atlas", parts)
