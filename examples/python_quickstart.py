#!/usr/bin/python3
"""fiberlab from Python in one page: simulate a small rough brown fiber,
predict it with d'Eon et al. 2011, compare, and plot the marginals.

    PYTHONPATH=build/python /usr/bin/python3 examples/python_quickstart.py [OUT_DIR]

Writes OUT_DIR/quickstart_marginals.png (default: the current folder) and
prints the per-lobe verdict. About ten seconds on two cores.
"""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import fiberlab

# The keys and units of a YAML config (configs/README.md): degrees, 1/R.
CONFIG = {
    "fiber": {"eta": 1.55, "sigma_a": [0.2, 0.4, 0.8]},
    # The exit blur is d'Eon's own roughness model (SPEC s3), so the model
    # should describe this fiber up to its documented approximations.
    "roughness": {"model": "exit_blur", "beta_long": [5, 2.5, 10], "beta_azim": [5, 2.5, 10]},
    "source": {"theta_i": [20, 50], "phi_i": 0},
    "tally": {"n_theta": 45, "n_phi": 72},
}


def main(out_dir):
    result = fiberlab.run(CONFIG, photons=200_000, seed=1)
    print(result)
    for k, theta_i in enumerate(result.theta_i):  # degrees
        energies = ", ".join("%s %.4f +- %.4f" % (name, result.energy.mean[k, l, 0], result.energy.std_err[k, l, 0])
                             for l, name in enumerate(result.lobe_names))
        print("theta_i %4.0f deg, channel %s: %s" % (theta_i, result.channel_names[0], energies))

    # d'Eon 2011 with the switches that make it the exit blur exactly (see
    # compare/model_defaults.h); drop them to see the published model's differences.
    prediction = fiberlab.predict(result, "deon2011", n_theta_d="specular", r_fresnel="per_h",
                                  absorption="chord")
    comparison = fiberlab.compare(result, prediction)
    table = comparison.table
    columns = ["theta_i_deg", "lobe_name", "channel", "sim_energy", "model_energy", "chi2_per_dof", "dof",
               "verdict"]
    print(table[columns].to_string() if hasattr(table, "to_string") else table)
    print(comparison)

    # theta_r marginal (log y, model as steps) and phi marginal per lobe, channel 0, first theta_i.
    k, c = 0, 0
    m = result.marginals
    width_t, width_p = np.diff(result.theta_edges), np.diff(result.phi_edges)  # degrees
    model_theta = prediction.marginals.theta  # (K, L, n_theta, C)
    model_phi = prediction.marginals.phi      # (K, L, n_phi, C)
    centres_t = 0.5 * (result.theta_edges[1:] + result.theta_edges[:-1])
    centres_p = 0.5 * (result.phi_edges[1:] + result.phi_edges[:-1])
    fig, axes = plt.subplots(2, len(result.lobe_names), figsize=(14, 6), dpi=80)
    for l, name in enumerate(result.lobe_names):
        ax = axes[0, l]
        ax.errorbar(centres_t, m.theta[k, l, :, c] / width_t, m.theta_std_err[k, l, :, c] / width_t,
                    fmt=".", ms=3, label="simulation")
        ax.stairs(model_theta[k, l, :, c] / width_t, result.theta_edges, label="deon2011")
        ax.set_yscale("log")
        ax.set_ylim(bottom=1e-6 * max(model_theta[k, l, :, c].max() / width_t.min(), 1e-300))
        ax.set_title("%s: theta_r marginal" % name)
        ax.set_xlabel("theta_r (deg)")
        ax = axes[1, l]
        ax.errorbar(centres_p, m.phi[k, l, :, c] / width_p, m.phi_std_err[k, l, :, c] / width_p, fmt=".", ms=3)
        ax.stairs(model_phi[k, l, :, c] / width_p, result.phi_edges)
        ax.set_title("%s: phi marginal" % name)
        ax.set_xlabel("phi (deg)")
    axes[0, 0].set_ylabel("probability per degree")
    axes[1, 0].set_ylabel("probability per degree")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("theta_i = %.0f deg, channel %s" % (result.theta_i[k], result.channel_names[c]))
    fig.tight_layout()
    path = os.path.join(out_dir, "quickstart_marginals.png")
    fig.savefig(path)
    print("wrote", path)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
