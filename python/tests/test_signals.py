"""Signals in a Python process (common/interrupt.h, python/src/run_binding.cpp):
SIGINT stops fiberlab.run within a second with KeyboardInterrupt and nothing
on disk; after any call (run, save, load, an interrupted run) no handler of
fiberlab stays installed: Ctrl-C during time.sleep is a KeyboardInterrupt,
not an exit with status 130, and SIGTERM/SIGHUP keep their default action.

Each case runs in a child /usr/bin/python3 with SIGINT at Python's own
handler (ctest may start us with SIGINT ignored, which children inherit)."""
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

PRELUDE = textwrap.dedent("""
    import signal, sys, time
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGHUP, signal.SIG_DFL)

    def caught():
        '''Which of SIGHUP, SIGINT, SIGTERM have a handler in this process
        (/proc: SigCgt; glibc's own realtime signals for threads aside).'''
        for line in open("/proc/self/status"):
            if line.startswith("SigCgt:"):
                mask = int(line.split()[1], 16)
                return [s for s in (signal.SIGHUP, signal.SIGINT, signal.SIGTERM) if mask >> (s - 1) & 1]

    CAUGHT_AT_START = caught()
    import fiberlab
    BIG = {"fiber": {"eta": 1.55, "sigma_a": 0.5}, "roughness": {"model": "smooth"},
           "source": {"theta_i": [30]}, "tally": {"n_theta": 45, "n_phi": 72}}

    def say(*words):
        print(*words, flush=True)
""")


def start(body, tmp_path):
    import fiberlab  # the child imports the same module, from any folder
    env = dict(os.environ, OMP_NUM_THREADS="2",
               PYTHONPATH=os.path.dirname(os.path.dirname(os.path.abspath(fiberlab.__file__))))
    return subprocess.Popen([sys.executable, "-c", PRELUDE + textwrap.dedent(body)], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def wait_for(child, word, timeout=60):
    """Lines of the child's stdout up to one starting with `word`."""
    end = time.monotonic() + timeout
    lines = []
    while time.monotonic() < end:
        line = child.stdout.readline()
        if not line:
            break
        lines.append(line.strip())
        if line.startswith(word):
            return lines
    child.kill()
    pytest.fail("child never said %r; stdout %s; stderr %s" % (word, lines, child.stderr.read()))


def test_sigint_stops_a_run_within_two_seconds_with_keyboard_interrupt(tmp_path):
    child = start("""
        say("running")
        try:
            fiberlab.run(BIG, photons=10**10, seed=1, progress=False)
            say("finished")
        except KeyboardInterrupt:
            say("KeyboardInterrupt")
        # No handler of fiberlab is left: the mask is the one before import.
        say("caught", caught() == CAUGHT_AT_START)
        try:
            say("sleeping")
            time.sleep(60)
        except KeyboardInterrupt:
            say("KeyboardInterrupt again")
    """, tmp_path)
    wait_for(child, "running")
    time.sleep(1.5)  # well inside the run (10^10 photons: hours)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    wait_for(child, "KeyboardInterrupt")
    assert time.monotonic() - sent < 2.0
    assert wait_for(child, "caught")[-1] == "caught True"
    wait_for(child, "sleeping")
    child.send_signal(signal.SIGINT)
    wait_for(child, "KeyboardInterrupt again")
    assert child.wait(timeout=30) == 0
    assert list(tmp_path.iterdir()) == []  # nothing on disk


def test_sigint_after_save_and_load_is_a_keyboard_interrupt_not_exit_130(tmp_path):
    child = start("""
        r = fiberlab.run(BIG, photons=2000, seed=1, progress=False)
        r.save("r.h5")
        fiberlab.load("r.h5")
        try:
            say("saved", caught() == CAUGHT_AT_START)
            time.sleep(60)
        except KeyboardInterrupt:
            say("KeyboardInterrupt")
    """, tmp_path)
    assert wait_for(child, "saved")[-1] == "saved True"
    child.send_signal(signal.SIGINT)
    wait_for(child, "KeyboardInterrupt")
    assert child.wait(timeout=30) == 0


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_during_a_run_keep_their_default_action(tmp_path, sig):
    """Python leaves SIGTERM and SIGHUP at their default (the process ends):
    fiberlab stops the run, puts the default back and re-delivers the signal,
    so the process ends by that signal, promptly, as it would without fiberlab."""
    child = start("""
        say("running")
        fiberlab.run(BIG, photons=10**10, seed=1, progress=False)
        say("finished")
    """, tmp_path)
    wait_for(child, "running")
    time.sleep(1.5)
    child.send_signal(sig)
    assert child.wait(timeout=10) == -sig
    assert list(tmp_path.iterdir()) == []


def test_a_python_handler_for_sigterm_runs_and_the_run_raises(tmp_path):
    """A Python handler installed for SIGTERM gets the signal after the run
    stopped; a handler that does not raise leaves the run's own error."""
    child = start("""
        got = []
        signal.signal(signal.SIGTERM, lambda s, f: got.append(s))
        say("running")
        try:
            fiberlab.run(BIG, photons=10**10, seed=1, progress=False)
        except fiberlab.Error as e:
            say("Error", str(e))
        say("handler", got == [signal.SIGTERM])
    """, tmp_path)
    wait_for(child, "running")
    time.sleep(1.5)
    child.send_signal(signal.SIGTERM)
    lines = wait_for(child, "handler")
    assert lines[-1] == "handler True"
    assert any(l.startswith("Error run interrupted by SIGTERM") for l in lines), lines
    assert child.wait(timeout=30) == 0
