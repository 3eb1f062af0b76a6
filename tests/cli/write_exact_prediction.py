#!/usr/bin/python3
"""Write a prediction file with h5py and numpy alone (no fiberlab code): the
exact smooth circular cylinder of SPEC s7 for the fiber, bins and incident
directions of a result file, computed independently of analytic/ by
midpoint sampling over h. Used by tests/cli/compare_prediction.sh to show
that `fiberlab compare --prediction` judges any writer's file.

Usage: write_exact_prediction.py RESULT.h5 OUT.h5 [--eta X] [--n-phi N]
(--eta: a wrong index for the "wrong model"; --n-phi: a different phi grid
for the mismatch check)."""
import argparse

import h5py
import numpy as np


def fresnel(cos_i, eta):
    """Unpolarised dielectric reflectance, light entering a medium of relative index eta."""
    sin2_t = (1.0 - cos_i**2) / eta**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs**2 + rp**2)


def exact_phi_bins(eta, sigma_a, theta_i, lobes, phi_edges, samples=200000, max_p=200):
    """(lobes, n_phi, C): (1/2) int A(p, h) dh over the h whose exit azimuth falls in each bin."""
    h = (np.arange(samples) + 0.5) / samples * 2.0 - 1.0
    w = 1.0 / samples
    gamma_i = np.arcsin(h)
    eta_p = np.sqrt(eta**2 - np.sin(theta_i) ** 2) / np.cos(theta_i)
    gamma_t = np.arcsin(h / eta_p)
    f = fresnel(np.cos(theta_i) * np.cos(gamma_i), eta)
    cos_theta_t = np.sqrt(1.0 - (np.sin(theta_i) / eta) ** 2)
    n_phi = len(phi_edges) - 1
    out = np.zeros((lobes, n_phi, len(sigma_a)))
    for c, s in enumerate(sigma_a):
        T = np.exp(-s / cos_theta_t * 2.0 * np.cos(gamma_t))
        for p in range(max_p + 1):
            A = f if p == 0 else (1 - f) ** 2 * f ** (p - 1) * T**p
            if p >= lobes and A.sum() * w < 1e-10:
                break  # every further order carries less (f T < 1)
            phi = 2 * p * gamma_t - 2 * gamma_i + p * np.pi
            phi = (phi + np.pi) % (2 * np.pi) - np.pi
            hist, _ = np.histogram(phi, bins=phi_edges, weights=A * w)
            out[min(p, lobes - 1), :, c] += hist
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("result")
    ap.add_argument("out")
    ap.add_argument("--eta", type=float, default=None)
    ap.add_argument("--n-phi", type=int, default=None)
    a = ap.parse_args()
    with h5py.File(a.result, "r") as r:
        theta_edges = r["bins/theta_edges"][:]
        phi_edges = r["bins/phi_edges"][:]
        theta_i = r["source/theta_i"][:]
        phi_i = r["source/phi_i"][:]
        lobes = r["tally/weight_sum"].shape[1]
        eta = float(r["fiber"].attrs["eta"]) if a.eta is None else a.eta
        sigma_a = np.atleast_1d(r["fiber"].attrs["sigma_a"])
    if a.n_phi is not None:
        phi_edges = np.linspace(-np.pi, np.pi, a.n_phi + 1)
    nt, nph = len(theta_edges) - 1, len(phi_edges) - 1
    prob = np.zeros((len(theta_i), lobes, nt, nph, len(sigma_a)))
    for k, ti in enumerate(theta_i):
        i = np.searchsorted(theta_edges, -ti, side="right") - 1  # the specular cone's bin
        prob[k, :, i, :, :] = exact_phi_bins(eta, sigma_a, ti, lobes, phi_edges)
    with h5py.File(a.out, "w") as f:
        f.attrs["format"] = "fiber-prediction"
        f["bins/theta_edges"] = theta_edges
        f["bins/phi_edges"] = phi_edges
        f["source/theta_i"] = theta_i
        f["source/phi_i"] = phi_i
        f["prediction/probability"] = prob
        f["prediction"].attrs["model"] = "numpy exact cylinder, eta %g" % eta


if __name__ == "__main__":
    main()
