"""A tiny progress reporter for long runs: one self-overwriting line on stderr, only on a terminal.

Reporting is on when ``enabled=True``, or when ``enabled=None`` (automatic) and
the stream is a TTY and ``NAMBU_BCH_PROGRESS`` is not ``0``; it is never on in
pipes, files, CI logs or under pytest's capture.  Nothing is printed until a
run has lasted ``delay`` seconds, and the line is refreshed at most every
``interval`` seconds, so short runs stay silent.
"""

from __future__ import annotations

import os
import sys
import time


def progress_wanted(stream=None) -> bool:
    """Automatic decision: ``stream`` (stderr) is a terminal and ``NAMBU_BCH_PROGRESS`` is not ``0``."""
    if os.environ.get("NAMBU_BCH_PROGRESS", "").strip() in ("0", "false", "no", "off"):
        return False
    stream = sys.stderr if stream is None else stream
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class Progress:
    """``label  37%  3.7e+06/1.0e+07 steps  2.1 s, ~3.6 s left`` on one line.

    Parameters
    ----------
    total : int -- the amount of work (steps)
    label : str
    enabled : bool or None -- None decides automatically (:func:`progress_wanted`)
    stream : file, default ``sys.stderr``
    delay, interval : float -- seconds before the first line, and between refreshes

    Examples
    --------
    >>> import io
    >>> p = Progress(100, "run", enabled=True, stream=io.StringIO(), delay=0.0, interval=0.0)
    >>> p.update(50); p.close()
    >>> "50%" in p.stream.getvalue()
    True
    """

    def __init__(self, total, label="iterate", enabled=None, stream=None, delay=1.0, interval=0.5):
        self.total = max(int(total), 1)
        self.label = label
        self.stream = sys.stderr if stream is None else stream
        self.enabled = progress_wanted(self.stream) if enabled is None else bool(enabled)
        self.delay = delay
        self.interval = interval
        self.start = time.perf_counter()
        self._last = -float("inf")
        self._shown = False

    def update(self, done):
        """Report ``done`` units of work finished."""
        if not self.enabled:
            return
        now = time.perf_counter()
        elapsed = now - self.start
        if elapsed < self.delay or now - self._last < self.interval:
            return
        self._last = now
        frac = min(max(done / self.total, 0.0), 1.0)
        left = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        self.stream.write(f"\r{self.label}  {100 * frac:3.0f}%  {done:.1e}/{self.total:.1e} steps  "
                          f"{elapsed:.1f} s, ~{left:.1f} s left ")
        self.stream.flush()
        self._shown = True

    def close(self):
        """End the line (if anything was shown)."""
        if self.enabled and self._shown:
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
