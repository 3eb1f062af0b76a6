#!/usr/bin/python3
"""Open a fiberlab result file with h5py alone and check every name that
SPEC section 9 requires, with its shape. Usage: check_result.py RESULT.h5

Exit status 0 when the file follows the contract, 1 otherwise (each problem
printed on its own line)."""
import sys

import h5py
import numpy as np


def check(path):
    problems = []
    with h5py.File(path, "r") as f:
        for name in ("format", "format_version", "software_version", "created_utc", "seed",
                     "config_yaml"):
            if name not in f.attrs:
                problems.append(f"missing root attribute {name}")
        if f.attrs.get("format") != "fiber-histogram":
            problems.append("root attribute format is not 'fiber-histogram'")
        required = ["bins/theta_edges", "bins/phi_edges", "bins/solid_angle", "source/theta_i",
                    "source/phi_i", "tally/photons", "tally/weight_sum", "tally/weight_sq_sum",
                    "tally/count", "ledger/exited", "ledger/absorbed", "ledger/truncated"]
        missing = [n for n in required if n not in f]
        problems += [f"missing dataset /{n}" for n in missing]
        if missing:
            return problems
        nt = f["bins/theta_edges"].shape[0] - 1
        nph = f["bins/phi_edges"].shape[0] - 1
        K = f["source/theta_i"].shape[0]
        S1 = f["tally/weight_sum"]
        if S1.ndim != 5 or S1.shape[0] != K or S1.shape[2:4] != (nt, nph):
            problems.append(f"/tally/weight_sum has shape {S1.shape}")
            return problems
        L, C = S1.shape[1], S1.shape[4]
        expect = {"bins/solid_angle": (nt, nph), "source/phi_i": (K,), "tally/photons": (K,),
                  "tally/weight_sq_sum": (K, L, nt, nph, C), "tally/count": (K, L, nt, nph),
                  "ledger/exited": (K, L, C), "ledger/absorbed": (K, C),
                  "ledger/truncated": (K, C)}
        for name, shape in expect.items():
            if f[name].shape != shape:
                problems.append(f"/{name} has shape {f[name].shape}, expected {shape}")
        if f["tally/photons"].dtype != np.uint64 or f["tally/count"].dtype != np.uint64:
            problems.append("/tally/photons and /tally/count must be uint64")
        for group, attrs in {"fiber": ["eta", "eccentricity", "scale_tilt", "sigma_a"],
                             "roughness": ["model", "beta_long", "beta_azim"],
                             "source": ["max_segments", "polarization"]}.items():
            for a in attrs:
                if a not in f[group].attrs:
                    problems.append(f"missing attribute /{group}@{a}")
        if len(np.atleast_1d(f["fiber"].attrs.get("sigma_a", []))) != C:
            problems.append("/fiber@sigma_a does not have one value per channel")
        # The estimators of SPEC section 6 and the ledger of section 4.
        N = f["tally/photons"][:].astype(float)
        # /ledger/lost (weight removed by masking) is absent from older files: 0.
        lost = f["ledger/lost"][:] if "ledger/lost" in f else 0.0
        total = (f["ledger/exited"][:].sum(axis=1) + f["ledger/absorbed"][:]
                 + f["ledger/truncated"][:] + lost)
        if not np.allclose(total, N[:, None], rtol=1e-12, atol=0):
            problems.append("ledger: exited + absorbed + truncated + lost != photons")
        if not np.allclose(S1[:].sum(axis=(2, 3)), f["ledger/exited"][:], rtol=1e-9, atol=1e-9):
            problems.append("histogram sums differ from /ledger/exited")
        omega = f["bins/solid_angle"][:]
        if not np.isclose(omega.sum(), 4 * np.pi, rtol=1e-12):
            problems.append(f"solid angles sum to {omega.sum()}, not 4 pi")
    return problems


def main():
    if len(sys.argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    problems = check(sys.argv[1])
    for p in problems:
        print(f"{sys.argv[1]}: {p}")
    if not problems:
        print(f"{sys.argv[1]}: follows SPEC section 9")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
