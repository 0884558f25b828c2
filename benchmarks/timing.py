"""Shared timing helper of the benchmark scripts (run as ``python benchmarks/<script>.py``)."""

import time


def cpu(fn, repeat=3):
    """``(best process CPU seconds over repeat calls, last result)``: both sides of a ratio are timed alike."""
    best, out = None, None
    for _ in range(repeat):
        t = time.process_time()
        out = fn()
        dt = time.process_time() - t
        best = dt if best is None else min(best, dt)
    return best, out
