"""Progress of a long run, for a terminal or a notebook (both show stderr)."""
import sys
import time


class ProgressLine:
    """Called with (done, total) photons; writes one line, rewritten in place
    ("\\r"), once the run has lasted a second (as `fiberlab run` does)."""

    def __init__(self, stream=None, delay=1.0):
        self.stream = stream or sys.stderr
        self.start = time.monotonic()
        self.delay = delay
        self.shown = False

    def __call__(self, done, total):
        elapsed = time.monotonic() - self.start
        if elapsed < self.delay and not self.shown:
            return
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = (total - done) / rate if rate > 0 else 0.0
        self.stream.write("\r%14d / %d photons  %8.3f M/s  ETA %6.0f s" % (done, total, rate * 1e-6, eta))
        if done >= total:
            self.stream.write("\n")
        self.stream.flush()
        self.shown = True
