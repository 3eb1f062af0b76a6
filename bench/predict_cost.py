#!/usr/bin/python3
"""Time of `fiberlab predict` per model against the exact model, whole process.

    /usr/bin/python3 bench/predict_cost.py [--fiberlab BIN] [--model huang2022]
        [--repeats 8] [CONFIG ...]

For each config (default: configs/quickstart.yaml and the three
bench/configs/predict_*.yaml) it runs `fiberlab predict CONFIG --model MODEL`
and `--model exact` alternately, --repeats times each, and prints the median
wall time (perf_counter around the child) and CPU time (user + system of the
child, every thread) of each, and their ratios. The whole process is timed:
start-up, the model, the file; for the exact model start-up is most of it.
MODEL's own threads (huang2022's quadrature) run as OpenMP gives them
(OMP_NUM_THREADS). Measure on an idle machine (docs/PERFORMANCE.md).
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_CONFIGS = ["configs/quickstart.yaml", "bench/configs/predict_brown_18x36.yaml",
                   "bench/configs/predict_white_ggx_18x36.yaml", "bench/configs/predict_brown_ggx_3dirs.yaml"]


def timed(cmd):
    """(wall s, CPU s) of one child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("configs", nargs="*", default=DEFAULT_CONFIGS)
    ap.add_argument("--fiberlab", default=os.path.join(ROOT, "build", "cli", "fiberlab"))
    ap.add_argument("--model", default="huang2022")
    ap.add_argument("--repeats", type=int, default=8)
    args = ap.parse_args()
    if args.repeats < 1:
        ap.error("--repeats must be >= 1")
    models = [args.model, "exact"]
    print("%-48s %22s %22s %14s" % ("config", args.model + " wall (CPU) s", "exact wall (CPU) s", "ratio wall/CPU"))
    with tempfile.TemporaryDirectory() as work:
        for config in args.configs:
            path = config if os.path.isabs(config) else os.path.join(ROOT, config)
            times = {m: [] for m in models}
            for _ in range(args.repeats):
                for m in models:
                    times[m].append(timed([args.fiberlab, "predict", path, "--model", m,
                                           "-o", os.path.join(work, "p.h5")]))
            wall = {m: statistics.median(t[0] for t in times[m]) for m in models}
            cpu = {m: statistics.median(t[1] for t in times[m]) for m in models}
            print("%-48s %22s %22s %14s" % (
                config, "%.3f (%.3f)" % (wall[args.model], cpu[args.model]),
                "%.4f (%.4f)" % (wall["exact"], cpu["exact"]),
                "%.0f / %.0f" % (wall[args.model] / wall["exact"], cpu[args.model] / cpu["exact"])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
