#!/usr/bin/env python3
"""huang2022's quadrature error on an atlas config's fibers, in the standard
errors of the atlas's own simulations.

For each fiber of the atlas config's sweep (white fibers only with --white),
predicts huang2022's bins at --points and at --reference points (the same
model, its quadrature's error falling as 1/sqrt(points)), and prints per
lobe, over the bins holding at least 10 photons' weight (p N >= 10) and
for the worst colour channel: the mean of (error / SE)^2, its square root
(the RMS error in standard errors) and the largest |error| / SE. SE^2 =
(p2 - p^2) / N is the variance of a bin of probability p in the config's
N-photon simulation, whose photons carry their attenuation as weight (SPEC
s4): p2, the mean of their squared weights, is the bin's probability at
twice the absorption (the fiber predicted with sigma_a doubled); for a
white fiber p2 = p.

With `--points auto` the prediction is huang2022's default, sized for the
config's photons (docs/MODELS.md).

Usage: scripts/huang2022_quadrature_error.py CONFIG [--fiberlab BIN]
         [--points N|auto [...]] [--reference N] [--white] [--workdir DIR]
"""
import argparse
import itertools
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import yaml

LOBES = ["R", "TT", "TRT", "p>=3"]


def fibers(cfg, white):
    s = cfg["sweep"]
    for rough, absn, tilt, ecc in itertools.product(
            s["roughness"], s["absorption"], s.get("scale_tilt", [0]), s.get("eccentricity", [1.0])):
        if white and absn != {"sigma_a": 0.0}:
            continue
        fiber = {"eta": cfg.get("eta", 1.55), "eccentricity": ecc, "scale_tilt": tilt}
        fiber.update(absn)
        yield {"photons": cfg["photons"], "seed": 1, "fiber": fiber, "roughness": rough,
               "source": {"theta_i": s["theta_i"], "phi_i": 0.0},
               "tally": cfg["tally"]}


def points_arg(text):
    """A point count (an integer >= 1024) or `auto` (huang2022's default)."""
    if text == "auto":
        return text
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1024:
        raise argparse.ArgumentTypeError(f"{text!r}: give an integer >= 1024 or auto")
    return n


def predict(fiberlab, config, points, out, settings=()):
    sets = [x for kv in [f"quadrature_points={points}", *settings] for x in ("--set", kv)]
    subprocess.run([fiberlab, "predict", config, "--model", "huang2022", *sets, "-o", out], check=True,
                   stdout=subprocess.DEVNULL)
    with h5py.File(out) as f:
        return f["prediction/probability"][()]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("--fiberlab", default="build/cli/fiberlab")
    ap.add_argument("--points", type=points_arg, nargs="+", default=[1 << 18],
                    help="one or more point counts to measure, or auto (one reference each fiber)")
    ap.add_argument("--reference", type=int, default=1 << 22)
    ap.add_argument("--white", action="store_true", help="only the sweep's sigma_a 0 fibers")
    ap.add_argument("--workdir", default=None)
    a = ap.parse_args()
    with open(a.config) as f:
        cfg = yaml.safe_load(f)
    work = a.workdir or tempfile.mkdtemp()
    n = float(cfg["photons"])
    worst = {(p, l): [0.0, 0.0, 0.0] for p in a.points for l in LOBES}
    for k, fc in enumerate(fibers(cfg, a.white)):
        path = os.path.join(work, f"fiber{k}.yaml")
        fc["output"] = os.path.join(work, f"fiber{k}.h5")
        with open(path, "w") as f:
            yaml.safe_dump(fc, f)
        ref = predict(a.fiberlab, path, a.reference, os.path.join(work, f"fiber{k}_ref.h5"))
        # [direction, lobe, theta, phi, channel]; the second moments at twice the absorption.
        with h5py.File(os.path.join(work, f"fiber{k}_ref.h5")) as f:
            sigma_a = np.atleast_1d(f["prediction"].attrs["sigma_a"])
        doubled = ",".join(f"{2 * x:.17g}" for x in sigma_a)
        p2 = ref if not sigma_a.any() else predict(
            a.fiberlab, path, a.reference // 8, os.path.join(work, f"fiber{k}_squares.h5"), [f"sigma_a={doubled}"])
        for points in a.points:
            x = predict(a.fiberlab, path, points, os.path.join(work, f"fiber{k}_test.h5"))
            row = []
            for l, name in enumerate(LOBES[:ref.shape[1]]):
                ms, mx, any_bin = 0.0, 0.0, False
                for c in range(ref.shape[-1]):
                    r, y, q = ref[:, l, ..., c], x[:, l, ..., c], p2[:, l, ..., c]
                    m = (r * n >= 10) & (q > r * r)
                    if not m.any():
                        continue
                    any_bin = True
                    z = (y - r)[m] / np.sqrt((q[m] - r[m] ** 2) / n)
                    ms, mx = max(ms, float(np.mean(z ** 2))), max(mx, float(np.max(np.abs(z))))
                if not any_bin:
                    row.append(f"{name} -")
                    continue
                w = worst[(points, name)]
                w[0], w[1], w[2] = max(w[0], ms), max(w[1], np.sqrt(ms)), max(w[2], mx)
                row.append(f"{name} {ms:.3f}/{np.sqrt(ms):.3f}/{mx:.3f}")
            print(f"{points} {fc['roughness']} {fc['fiber']}: " + "  ".join(row), flush=True)
    for points in a.points:
        print(f"{points} points, largest over the fibers (mean squared / RMS / max |error| in SE): " +
              "  ".join(f"{l} {w[0]:.3f}/{w[1]:.3f}/{w[2]:.3f}" for (p, l), w in worst.items()
                        if p == points and w != [0.0, 0.0, 0.0]))


if __name__ == "__main__":
    sys.exit(main())
