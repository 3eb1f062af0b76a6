#!/usr/bin/python3
"""Error per second of `fiberlab run`, per lobe, for the bench/configs cases.

    /usr/bin/python3 bench/figure_of_merit.py [--before BIN] [--after BIN]
        [--cases b c ggx] [--repeats 3] [--threads 2] [--photons N]
        [--exit-normals LIST [LIST ...]]

For each case it runs, alternately and --repeats times over, the binary
--before (its default estimator) and the binary --after with
`estimator: analog` and with `estimator: expected_value` added to the
config (and, for each --exit-normals LIST such as "[16, 1]", with
`estimator: expected_value` and `exit_normals: LIST`), and prints per lobe
the figure of merit

    FOM = 1 / (sum over the lobe's bins and channels of SE_b^2  x  CPU seconds)

with SE_b = sqrt((S2_b/N - P_b^2)/(N - 1)), P_b = S1_b/N (SPEC section 6),
read from the result file with h5py, and CPU seconds the run's user + system
time (getrusage of the finished child: every thread, start-up and writing
the file included). It prints the median over repeats of each FOM and of the
photons per CPU second (per core), and the ratio of each to --before's. A
machine shared with other jobs slows every run about alike; alternating the
binaries spreads that over all of them, it does not remove it.
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LOBE_NAMES = ["R", "TT", "TRT"]


def cpu_seconds_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def squared_errors_per_lobe(path):
    """Sum over bins and channels of SE^2, per lobe (first incident configuration)."""
    with h5py.File(path, "r") as f:
        n = float(f["tally/photons"][0])
        s1 = f["tally/weight_sum"][0]
        s2 = f["tally/weight_sq_sum"][0]
    p = s1 / n
    var = (s2 / n - p * p) / (n - 1.0)
    return var.reshape(var.shape[0], -1).sum(axis=1), n


def run_once(binary, config_text, photons, threads, work):
    config = os.path.join(work, "config.yaml")
    with open(config, "w") as out:
        out.write(config_text)
    result = os.path.join(work, "out.h5")
    cmd = [binary, "run", config, "-o", result, "--threads", str(threads), "--quiet"]
    if photons:
        cmd += ["--photons", str(photons)]
    cpu = cpu_seconds_of(cmd)
    se2, n = squared_errors_per_lobe(result)
    os.remove(result)
    return cpu, se2, n


def lobe_name(p, lobes):
    if p == lobes - 1:
        return "p>=%d" % p
    return LOBE_NAMES[p] if p < len(LOBE_NAMES) else "p=%d" % p


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", required=True, help="fiberlab binary to compare against")
    ap.add_argument("--after", default=os.path.join(ROOT, "build", "cli", "fiberlab"))
    ap.add_argument("--cases", nargs="+", default=["b", "c", "ggx"])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--photons", type=int, default=0, help="override each config's photons")
    ap.add_argument("--exit-normals", nargs="+", default=[], metavar="LIST",
                    help='expected_value variants with exit_normals: LIST (e.g. "[16, 1]" or 8)')
    args = ap.parse_args()
    variants = [("before", args.before, ""), ("analog", args.after, "estimator: analog\n"),
                ("expected_value", args.after, "estimator: expected_value\n")]
    for k in args.exit_normals:
        variants.append(("ev " + k.replace(" ", ""), args.after,
                         "estimator: expected_value\nexit_normals: %s\n" % k))
    with tempfile.TemporaryDirectory() as work:
        for case in args.cases:
            base = open(os.path.join(ROOT, "bench", "configs", "case_%s.yaml" % case)).read()
            results = {name: [] for name, _, _ in variants}
            for _ in range(args.repeats):
                for name, binary, extra in variants:
                    results[name].append(run_once(binary, base + extra, args.photons, args.threads, work))
            lobes = len(results["before"][0][1])
            print("case %s (%s photons, %d threads, median of %d alternating runs)"
                  % (case, int(results["before"][0][2]), args.threads, args.repeats))
            header = "%-8s" % "lobe" + "".join("%16s" % name for name, _, _ in variants) + \
                "".join("%12s" % (name.split()[-1][:11] + "/b") for name, _, _ in variants[1:])
            print(header)
            fom = {}
            for name, _, _ in variants:
                fom[name] = [statistics.median(1.0 / (r[1][p] * r[0]) if r[1][p] > 0 else float("inf")
                                               for r in results[name]) for p in range(lobes)]
            for p in range(lobes):
                row = "%-8s" % lobe_name(p, lobes)
                row += "".join("%16.4g" % fom[name][p] for name, _, _ in variants)
                b = fom["before"][p]
                row += "".join("%12.3g" % (fom[name][p] / b) for name, _, _ in variants[1:])
                print(row)
            rate = {name: statistics.median(r[2] / r[0] / 1.0 for r in results[name])
                    for name, _, _ in variants}
            cpu = {name: statistics.median(r[0] for r in results[name]) for name, _, _ in variants}
            print("%-8s" % "ph/s/core" + "".join("%16.4g" % rate[name] for name, _, _ in variants))
            print("%-8s" % "cpu s" + "".join("%16.4g" % cpu[name] for name, _, _ in variants))
            print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
