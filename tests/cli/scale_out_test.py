#!/usr/bin/python3
"""Runs split over MPI ranks, interrupted and resumed, split by
incident direction and merged, or stopped at a target error, give the same
bits as one uninterrupted process. Compares runs against runs (never against
stored numbers): every /tally and /ledger array, and the exact sums.

usage: scale_out_test.py FIBERLAB CASE   (CASE: mpi | signal | merge | target)
Exit 0: passed; 1: failed; 77: skipped (said why).
"""
import os
import shutil
import signal
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ARRAYS = ["tally/photons", "tally/weight_sum", "tally/weight_sq_sum", "tally/count",
          "ledger/exited", "ledger/absorbed", "ledger/truncated", "ledger/lost",
          "exact/weight_sum_residual", "exact/weight_sq_sum_residual", "exact/exited", "exact/absorbed", "exact/truncated", "exact/lost"]

CONFIG = """photons: {photons}
seed: 5
fiber: {{eta: 1.55, scale_tilt: 3, sigma_a: [0.1, 0.4]}}
roughness: {{model: gaussian, beta_long: 6}}
source: {{theta_i: {theta}, phi_i: 7}}
tally: {{n_theta: 18, n_phi: 36}}
"""


def fail(msg):
    print("FAILED:", msg)
    sys.exit(1)


def run(args, **kw):
    p = subprocess.run(args, capture_output=True, text=True, **kw)
    return p


def must(args, **kw):
    p = run(args, **kw)
    if p.returncode != 0:
        fail(f"{' '.join(args)} -> {p.returncode}\n{p.stdout}\n{p.stderr}")
    return p


def same(a, b):
    """Every tally and ledger array bit-identical."""
    with h5py.File(a) as fa, h5py.File(b) as fb:
        for name in ARRAYS:
            x, y = fa[name][()], fb[name][()]
            if x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
                fail(f"{name} differs between {a} and {b}")
        for name in ["source/theta_i", "source/phi_i"]:
            if fa[name][()].tobytes() != fb[name][()].tobytes():
                fail(f"{name} differs between {a} and {b}")


def write_config(d, name, photons, theta):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        f.write(CONFIG.format(photons=photons, theta=theta))
    return path


def case_mpi(fl, d):
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        print("SKIPPED: mpirun is not installed (openmpi-bin)")
        return 77
    cfg = write_config(d, "c.yaml", 30000, "[20, 35]")
    ref = os.path.join(d, "one.h5")
    must([fl, "run", cfg, "-o", ref, "--threads", "2", "--quiet"])
    probe = run([mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "2", fl, "run", cfg,
                 "-o", os.path.join(d, "probe.h5"), "--threads", "1", "--quiet"])
    if "built without MPI" in probe.stderr:
        print("SKIPPED: fiberlab was built without MPI (" + probe.stderr.strip() + ")")
        return 77
    for ranks, threads in [(2, 1), (3, 1), (2, 2)]:
        out = os.path.join(d, f"mpi{ranks}x{threads}.h5")
        p = must([mpirun, "--allow-run-as-root", "--oversubscribe", "-np", str(ranks), fl, "run",
                  cfg, "-o", out, "--threads", str(threads)])
        same(ref, out)
        if p.stdout.count("wrote ") != 1:
            fail(f"{ranks} ranks: expected one summary (rank 0 only), got:\n{p.stdout}")
        left = sorted(f for f in os.listdir(d) if f.startswith(f"mpi{ranks}x{threads}") or ".tmp" in f)
        if left != [f"mpi{ranks}x{threads}.h5"]:
            fail(f"{ranks} ranks: expected one output file, found {left}")
    # SIGTERM to mpirun (forwarded to every rank): rank 0 saves a checkpoint;
    # one process with 2 threads finishes it, bit-identical.
    big = write_config(d, "big.yaml", 40000000, "[20, 35]")
    must([fl, "run", big, "-o", os.path.join(d, "big_ref.h5"), "--threads", "2", "--quiet"])
    out, nxt = interrupted_then_resumed(
        fl, d, big, signal.SIGTERM, "mpiterm",
        launcher=(mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "2"))
    print(f"mpirun SIGTERM: checkpoint at photons {list(nxt)}; resumed output identical")
    same(os.path.join(d, "big_ref.h5"), out)
    # One rank's failure stops all: rank 1 cannot write here, rank 0 reports once.
    bad = run([mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "2", fl, "run", cfg,
               "-o", os.path.join(d, "no", "such", "dir.h5"), "--quiet"])
    if bad.returncode == 0 or bad.stderr.count("fiberlab: error") != 1:
        fail(f"bad output under MPI: status {bad.returncode}, stderr:\n{bad.stderr}")
    return 0


def signal_when_tracing(command, sig, tag):
    """Starts `command` (default signal dispositions, not those of a background
    shell), waits for its first progress line (it is tracing), sends `sig`;
    returns (status, stderr)."""
    p = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         preexec_fn=lambda: (signal.signal(signal.SIGINT, signal.SIG_DFL),
                                             signal.signal(signal.SIGTERM, signal.SIG_DFL)))
    seen = b""
    while b"photons" not in seen:
        byte = p.stderr.read(1)
        if not byte:
            fail(f"{tag}: the run ended before showing progress; make it longer: {seen}")
        seen += byte
    p.send_signal(sig)
    _, err = p.communicate(timeout=120)
    return p.returncode, (seen + err).decode()


def interrupted_then_resumed(fl, d, cfg, sig, tag, launcher=(), resume_threads="2"):
    out = os.path.join(d, f"{tag}.h5")
    ck = os.path.join(d, f"{tag}.checkpoint.h5")
    status, err = signal_when_tracing([*launcher, fl, "run", cfg, "-o", out, "--threads", "1"],
                                      sig, tag)
    if not launcher and status != 128 + sig:
        fail(f"{tag}: status {status}, expected {128 + sig}; stderr: {err}")
    if launcher and status == 0:
        fail(f"{tag}: status 0 after a signal under mpirun; stderr: {err}")
    if "--resume" not in err or not os.path.exists(ck) or os.path.exists(out):
        fail(f"{tag}: expected a checkpoint, no output and a resume command; stderr: {err}")
    with h5py.File(ck) as f:
        nxt = f["checkpoint/next_photon"][()]
    if nxt.sum() == 0:
        fail(f"{tag}: checkpoint holds no progress")
    must([fl, "run", "--resume", ck, "--threads", resume_threads, "--quiet"])
    if os.path.exists(ck) or not os.path.exists(out):
        fail(f"{tag}: resume left the checkpoint or wrote no output")
    return out, nxt


def case_signal(fl, d):
    cfg = write_config(d, "c.yaml", 30000000, "[20, 35]")
    ref = os.path.join(d, "ref.h5")
    must([fl, "run", cfg, "-o", ref, "--threads", "2", "--quiet"])
    for sig, tag in [(signal.SIGINT, "int"), (signal.SIGTERM, "term")]:
        out, nxt = interrupted_then_resumed(fl, d, cfg, sig, tag)
        print(f"{tag}: interrupted at photons {list(nxt)}; resumed output identical")
        same(ref, out)
    # A fresh run over a pending checkpoint, and a changed config, are refused.
    ck_out = os.path.join(d, "x.h5")
    signal_when_tracing([fl, "run", cfg, "-o", ck_out, "--threads", "1"], signal.SIGINT, "x")
    ck = os.path.join(d, "x.checkpoint.h5")
    again = run([fl, "run", cfg, "-o", ck_out, "--quiet"])
    if again.returncode != 2 or "--resume" not in again.stderr:
        fail(f"run over a checkpoint: {again.returncode} {again.stderr}")
    other = write_config(d, "other.yaml", 30000000, "[20, 36]")
    changed = run([fl, "run", "--resume", ck, other, "--quiet"])
    if changed.returncode != 2 or changed.stderr.count("\n") != 1 or "differs" not in changed.stderr:
        fail(f"changed config accepted: {changed.returncode} {changed.stderr}")
    with h5py.File(ck, "r+") as f:
        f.attrs["software_version"] = "0.0.1"
        del f.attrs["attribute_digest"]  # as an older version wrote it: without one
    old = run([fl, "run", "--resume", ck, "--quiet"])
    if old.returncode != 2 or old.stderr.count("\n") != 1 or "0.0.1" not in old.stderr:
        fail(f"checkpoint of another version accepted: {old.returncode} {old.stderr}")
    return 0


def case_merge(fl, d):
    whole = write_config(d, "whole.yaml", 20000, "[20, 35]")
    a = write_config(d, "a.yaml", 20000, "[20]")
    b = write_config(d, "b.yaml", 20000, "[35]")
    must([fl, "run", whole, "-o", os.path.join(d, "whole.h5"), "--quiet"])
    must([fl, "run", a, "-o", os.path.join(d, "a.h5"), "--quiet"])
    must([fl, "run", b, "-o", os.path.join(d, "b.h5"), "--quiet"])
    must([fl, "merge", os.path.join(d, "b.h5"), os.path.join(d, "a.h5"), "-o",
          os.path.join(d, "ab.h5")])
    same(os.path.join(d, "whole.h5"), os.path.join(d, "ab.h5"))
    # The same direction with the same seed: refused, nothing written.
    p = run([fl, "merge", os.path.join(d, "a.h5"), os.path.join(d, "whole.h5"), "-o",
             os.path.join(d, "dup.h5")])
    if p.returncode != 2 or "seed" not in p.stderr or os.path.exists(os.path.join(d, "dup.h5")):
        fail(f"same direction and seed: {p.returncode} {p.stderr}")
    # Three inputs (two seeds of the sweep, one of a direction) in two orders.
    must([fl, "run", whole, "-o", os.path.join(d, "s7.h5"), "--seed", "7", "--quiet"])
    must([fl, "run", a, "-o", os.path.join(d, "a9.h5"), "--seed", "9", "--quiet"])
    names = [os.path.join(d, n) for n in ["whole.h5", "s7.h5", "a9.h5"]]
    must([fl, "merge", *names, "-o", os.path.join(d, "m1.h5")])
    must([fl, "merge", *reversed(names), "-o", os.path.join(d, "m2.h5")])
    same(os.path.join(d, "m1.h5"), os.path.join(d, "m2.h5"))
    with h5py.File(os.path.join(d, "m1.h5")) as f:
        if list(f["tally/photons"][()]) != [60000, 40000]:
            fail(f"photons after merge: {f['tally/photons'][()]}")
        # float64 sums are the exact integers / 2^60, rounded once (Python's
        # int-to-float conversion rounds to nearest, ties to even); the exact
        # integer is the float64 sum x 2^60 plus the residual (format 2).
        v, r = f["tally/weight_sum"][()], f["exact/weight_sum_residual"][()]
        exact = [int(a * 2.0**60) + int(b) for a, b in zip(v.ravel(), r.ravel())]
        approx = np.array([float(e) / 2**60 for e in exact]).reshape(v.shape)
        if not np.array_equal(approx, v) or not np.any(r != 0):
            fail("weight_sum is not the exact sum / 2^60 rounded once (or no residual to check)")
    # Merging a merge with one of its inputs repeats seeds: refused.
    p = run([fl, "merge", os.path.join(d, "m1.h5"), os.path.join(d, "s7.h5"), "-o",
             os.path.join(d, "rep.h5")])
    if p.returncode != 2 or "seed 7" not in p.stderr:
        fail(f"merge repeating a merged seed: {p.returncode} {p.stderr}")
    return 0


def case_target(fl, d):
    cfg = write_config(d, "c.yaml", 2000000, "[20, 35]")
    target = 0.02
    out = os.path.join(d, "t.h5")
    p = must([fl, "run", cfg, "-o", out, "--target-error", str(target), "--threads", "2"])
    with h5py.File(out) as f:
        n = [int(x) for x in f["tally/photons"][()]]
        s1 = f["ledger/exited"][()]                      # K x L x C
        s2 = f["tally/weight_sq_sum"][()].sum(axis=(2, 3))  # K x L x C
    for k in range(len(n)):
        if n[k] % 65536 != 0 or n[k] >= 2000000:
            fail(f"direction {k} stopped at {n[k]} photons, not a multiple of 65536 below the limit")
        mean = s1[k] / n[k]
        se = np.sqrt(np.maximum(s2[k] / n[k] - mean**2, 0) / (n[k] - 1))
        rel = (se / mean)[mean > 0]
        if rel.max() >= target:
            fail(f"direction {k}: relative error {rel.max()} not below {target}")
        # The stop is the first boundary that reaches it: one batch fewer did not.
        if n[k] > 65536:
            cap = os.path.join(d, f"cap{k}.h5")
            must([fl, "run", cfg, "-o", cap, "--photons", str(n[k] - 65536), "--quiet"])
            with h5py.File(cap) as f:
                m = n[k] - 65536
                c1 = f["ledger/exited"][k]
                c2 = f["tally/weight_sq_sum"][k].sum(axis=(1, 2))
            mean = c1 / m
            rel = (np.sqrt(np.maximum(c2 / m - mean**2, 0) / (m - 1)) / mean)[mean > 0]
            if rel.max() < target:
                fail(f"direction {k}: {m} photons already reached {target}; stopped late at {n[k]}")
    if "reached" not in p.stdout:
        fail("run does not report the error it reached:\n" + p.stdout)
    # Reproducible: the same stop with other thread counts.
    out1 = os.path.join(d, "t1.h5")
    must([fl, "run", cfg, "-o", out1, "--target-error", str(target), "--threads", "1", "--quiet"])
    same(out, out1)
    return 0


def main():
    fl, case = sys.argv[1], sys.argv[2]
    d = tempfile.mkdtemp(prefix=f"fiberlab_scale_{case}_")
    try:
        status = {"mpi": case_mpi, "signal": case_signal, "merge": case_merge,
                  "target": case_target}[case](fl, d)
    finally:
        shutil.rmtree(d, ignore_errors=True)
    if status == 0:
        print("passed")
    sys.exit(status)


if __name__ == "__main__":
    main()
