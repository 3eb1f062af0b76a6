#!/usr/bin/python3
"""Plots for `fiberlab compare --report DIR` and `fiberlab energy --report DIR`.

Usage: /usr/bin/python3 scripts/plot_report.py compare|energy DIR

Reads DIR/report_data.h5 (compare) or DIR/metrics.json (energy), writes PNGs
into DIR. Needs Debian's python3-matplotlib, python3-h5py and numpy (run it
with /usr/bin/python3, not a pyenv `python3`). Exit status 3 when those are
missing (the caller then reports "plots skipped"), 2 on bad arguments.

Figures have fixed pixel sizes (no tight bounding box), so tests can check
the PNG headers:
  compare_theta{T}_phi{P}_heatmaps.png   1200 x 1200: per lobe, simulated and predicted
                              density per solid angle (log10) and the
                              normalised residual (P_sim - P_model) / se
  compare_theta{T}_phi{P}_marginals.png  1200 x 1200: per lobe, theta_r and phi
                              marginals, simulation with error bars, model
  energy.png                  1200 x 800: total, R+TT+TRT and per-lobe
                              energy against theta_i for every source
  energy_roughness.png        1200 x 600: total energy against theta_i per
                              beta_long (only with --beta-sweep), as in
                              d'Eon et al. 2011 Fig. 3
"""
import json
import os
import sys

MAX_CONFIGS = 8  # incident directions plotted by `compare` (the rest are in the metrics)


def lobe_name(lobe, lobes):
    names = ["R", "TT", "TRT", "TRRT", "TR3T", "TR4T"]
    if lobe == lobes - 1 and lobes > 1:
        return "p>=%d" % lobe
    return names[lobe] if lobe < 6 else "p=%d" % lobe


def incidence_title(theta_i, phi_i):
    """theta_i = 30.0 deg, phi_i = 0.0 deg (phi_i uniform for a randomly rotated fiber)."""
    phi = "uniform" if phi_i != phi_i else "%.1f deg" % phi_i
    return "theta_i = %.1f deg, phi_i = %s" % (theta_i, phi)


def incidence_stem(theta_i, phi_i):
    """File-name part naming the incident direction: theta30.0_phi0.0 (phiuniform)."""
    phi = "uniform" if phi_i != phi_i else "%.1f" % phi_i
    return "theta%.1f_phi%s" % (theta_i, phi)


def plot_compare(d, np, plt, h5py):
    with h5py.File(os.path.join(d, "report_data.h5"), "r") as f:
        te = np.degrees(f["theta_edges"][...])
        pe = np.degrees(f["phi_edges"][...])
        omega = f["solid_angle"][...]
        theta_i = np.degrees(f["theta_i"][...])
        phi_i = np.degrees(f["phi_i"][...]) if "phi_i" in f else np.zeros_like(theta_i)
        sim_p = f["sim_p"][...]
        sim_se = f["sim_se"][...]
        model_p = f["model_p"][...]
        model = f.attrs["model"]
        model = model.decode() if isinstance(model, bytes) else str(model)
        c = int(f.attrs["plot_channel"])
    K, L = sim_p.shape[0], sim_p.shape[1]
    tc = 0.5 * (te[:-1] + te[1:])
    pc = 0.5 * (pe[:-1] + pe[1:])
    for k in range(min(K, MAX_CONFIGS)):
        where = incidence_title(theta_i[k], phi_i[k])
        stem = incidence_stem(theta_i[k], phi_i[k])
        fig, axes = plt.subplots(L, 3, figsize=(12, 12), dpi=100, squeeze=False)
        fig.suptitle("%s, channel %d: simulation | %s | (sim - model) / se" % (where, c, model))
        for l in range(L):
            s = sim_p[k, l, :, :, c]
            m = model_p[k, l, :, :, c]
            se = sim_se[k, l, :, :, c]
            ds, dm = s / omega, m / omega
            top = max(ds.max(), dm.max(), 1e-300)
            lo = top * 1e-4
            for j, (arr, title) in enumerate(((ds, "simulated"), (dm, "model"))):
                ax = axes[l, j]
                im = ax.pcolormesh(pe, te, np.log10(np.maximum(arr, lo)), vmin=np.log10(lo),
                                   vmax=np.log10(top), cmap="magma", shading="flat")
                ax.set_title("%s %s, log10 density" % (lobe_name(l, L), title), fontsize=9)
                fig.colorbar(im, ax=ax)
            res = np.where(se > 0, (s - m) / np.where(se > 0, se, 1.0), np.nan)
            ax = axes[l, 2]
            im = ax.pcolormesh(pe, te, res, vmin=-5, vmax=5, cmap="RdBu_r", shading="flat")
            ax.set_title("%s normalised residual" % lobe_name(l, L), fontsize=9)
            fig.colorbar(im, ax=ax)
            for ax in axes[l]:
                ax.set_ylabel("theta_r (deg)", fontsize=8)
                ax.tick_params(labelsize=7)
        for ax in axes[-1]:
            ax.set_xlabel("phi (deg)", fontsize=8)
        fig.savefig(os.path.join(d, "compare_%s_heatmaps.png" % stem), dpi=100)
        plt.close(fig)

        fig, axes = plt.subplots(L, 2, figsize=(12, 12), dpi=100, squeeze=False)
        fig.suptitle("%s, channel %d: marginals, simulation (points, 1 se) and %s (line)" % (where, c, model))
        for l in range(L):
            s = sim_p[k, l, :, :, c]
            m = model_p[k, l, :, :, c]
            var = sim_se[k, l, :, :, c] ** 2
            for j, (axis, centres, width, name) in enumerate(
                    ((1, tc, np.diff(te), "theta_r"), (0, pc, np.diff(pe), "phi"))):
                ax = axes[l, j]
                ax.errorbar(centres, s.sum(axis=axis) / width, yerr=np.sqrt(var.sum(axis=axis)) / width,
                            fmt=".", ms=3, lw=0.8, label="simulation")
                ax.plot(centres, m.sum(axis=axis) / width, "-", lw=1.0, label=model)
                ax.set_title("%s, %s marginal (probability per degree)" % (lobe_name(l, L), name), fontsize=9)
                ax.tick_params(labelsize=7)
                if l == L - 1:
                    ax.set_xlabel("%s (deg)" % name, fontsize=8)
                if l == 0:
                    ax.legend(fontsize=7)
        fig.savefig(os.path.join(d, "compare_%s_marginals.png" % stem), dpi=100)
        plt.close(fig)


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
    fig.savefig(os.path.join(d, "energy.png"), dpi=100)
    plt.close(fig)
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
        fig.savefig(os.path.join(d, "energy_roughness.png"), dpi=100)
        plt.close(fig)


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("compare", "energy"):
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
    else:
        plot_energy(d, np, plt)
    return 0


if __name__ == "__main__":
    sys.exit(main())
