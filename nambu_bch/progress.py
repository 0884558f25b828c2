"""Progress bars for long runs, drawn by tqdm (``tqdm.auto``: a text bar on a terminal, a widget in Jupyter).

The widget needs ipywidgets (``pip install nambu_bch[jupyter]``); without it the bar is tqdm's
plain text bar on stderr in Jupyter too, so a plain install prints no ``IProgress not found`` warning.

Reporting is on when ``enabled=True``, or when ``enabled=None`` (automatic) and
:func:`progress_wanted` says so: ``NAMBU_BCH_PROGRESS`` is not ``0`` and stderr is
a terminal or the code runs in a Jupyter kernel; it is off in pipes, files, CI
logs and under pytest's capture.  Nothing is drawn until a run has lasted
``delay`` seconds (tqdm's ``delay``), and the bar is refreshed at most every
``interval`` seconds, so short runs stay silent.  The CLI's ``--no-progress``
and the API's ``progress=False`` turn it off.

Two entry points: :class:`Progress` (a counter of work units, for numeric runs
in chunks) and :func:`stages` (an iterable of symbolic stages, e.g. the orders
of the direct route).
"""

from __future__ import annotations

import os
import sys

_OFF = ("0", "false", "no", "off")
#: Seconds a run must last before its bar appears (the default ``delay`` of :func:`stages`).
DELAY = 1.0


def _in_jupyter() -> bool:
    """A Jupyter (IPython kernel) session: tqdm.auto draws a widget there."""
    shell = sys.modules.get("IPython")
    if shell is None or "ipykernel" not in sys.modules:
        return False
    try:
        ip = shell.get_ipython()
    except Exception:  # noqa: BLE001 -- any failure means "not a kernel"
        return False
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def progress_wanted(stream=None) -> bool:
    """Automatic decision: ``NAMBU_BCH_PROGRESS`` is not ``0`` and ``stream`` (stderr) is a terminal or Jupyter's."""
    if os.environ.get("NAMBU_BCH_PROGRESS", "").strip().lower() in _OFF:
        return False
    stream = sys.stderr if stream is None else stream
    try:
        if stream.isatty():
            return True
    except (AttributeError, ValueError):
        return False
    return stream is sys.stderr and _in_jupyter()


def widgets_available() -> bool:
    """Is ipywidgets importable?  tqdm's Jupyter widget needs it; without it tqdm warns ``IProgress not found``."""
    from importlib.util import find_spec

    return find_spec("ipywidgets") is not None


def _bar(total, label, stream, delay, interval, unit):
    """A tqdm bar: ``tqdm.auto`` on the default stream when ipywidgets is installed (a widget in Jupyter), else
    plain tqdm (a text bar on stderr, also in Jupyter: the ``jupyter`` extra installs ipywidgets)."""
    if stream is None and widgets_available():
        from tqdm.auto import tqdm
    else:
        from tqdm import tqdm
    return tqdm(total=total, desc=label, file=stream, delay=delay, mininterval=interval, unit=unit,
                unit_scale=total >= 10_000, dynamic_ncols=True, leave=True)


class Progress:
    """A progress bar over ``total`` units of work: ``label  37%|###   | 3.7M/10.0M [00:02<00:03, 1.8Mstep/s]``.

    Parameters
    ----------
    total : int -- the amount of work (steps)
    label : str
    enabled : bool or None -- None decides automatically (:func:`progress_wanted`)
    stream : file, default ``sys.stderr`` (``tqdm.auto``: a widget in Jupyter)
    delay, interval : float -- seconds before the bar appears, and between refreshes

    Examples
    --------
    >>> import io
    >>> p = Progress(100, "run", enabled=True, stream=io.StringIO(), delay=0.0, interval=0.0)
    >>> p.update(50); p.close()
    >>> "50/100" in p.stream.getvalue()
    True
    """

    def __init__(self, total, label="iterate", enabled=None, stream=None, delay=1.0, interval=0.5, unit="step"):
        from .checks import check_flag, check_int, finite_float

        self.total = max(check_int(total, "total", 0), 1)
        self.label = label
        self.stream = stream
        enabled = check_flag(enabled, "enabled", none=True)
        self.enabled = progress_wanted(stream) if enabled is None else enabled
        self.delay = finite_float(delay, "delay")
        self.interval = finite_float(interval, "interval")
        self._bar = _bar(self.total, label, stream, self.delay, self.interval, unit) if self.enabled else None

    def update(self, done):
        """Report ``done`` units of work finished (a running total, not an increment)."""
        if self._bar is None:
            return
        done = min(max(int(done), 0), self.total)
        if done > self._bar.n:
            self._bar.update(done - self._bar.n)
            if done == self.total and self._bar.format_dict["elapsed"] >= self.delay:
                self._bar.refresh()  # show completion even between refresh intervals

    def close(self):
        """Finish the bar (left on its line if it was drawn)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def stages(items, label, enabled=None, stream=None, delay=None, unit="order"):
    """Iterate over ``items`` (symbolic stages such as orders ``1..k``) with a progress bar when enabled.

    ``enabled=None`` decides automatically (:func:`progress_wanted`); the bar appears only
    once the stages have taken ``delay`` seconds (default :data:`DELAY`), so quick computations print nothing.

    >>> import io
    >>> s = io.StringIO()
    >>> [k for k in stages(range(1, 4), "orders", enabled=True, stream=s, delay=0.0)]
    [1, 2, 3]
    >>> "3/3" in s.getvalue()
    True
    """
    items = list(items)
    delay = DELAY if delay is None else delay
    with Progress(len(items), label, enabled=enabled, stream=stream, delay=delay, interval=0.1, unit=unit) as bar:
        for k, item in enumerate(items, 1):
            yield item
            bar.update(k)
