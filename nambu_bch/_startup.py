"""Ctrl-C while ``nambu-bch`` is still importing: one line and exit status 130, never a traceback.

Importing the package (sympy, numpy, numba) takes a noticeable time, and the
console script imports it before :func:`nambu_bch.cli.main` can catch anything.
When the process is the command line (``nambu-bch`` or ``python -m nambu_bch``),
the first statement of ``nambu_bch/__init__.py`` installs a SIGINT handler that
prints one line and exits with 130; :func:`cli_started` restores Python's own
handler (``KeyboardInterrupt``) once ``main`` runs and can handle it.  A library
import (``import nambu_bch`` in a program or notebook) is left untouched.
"""

# Only modules the interpreter has already loaded when the package starts: ``signal`` (the Python
# module) would import enum and functools first, a window in which Ctrl-C is still a traceback.
import _signal as signal
import os
import sys

_installed = False


def _is_cli() -> bool:
    argv0 = sys.argv[0] if getattr(sys, "argv", None) else ""
    # "-m" is argv[0] while ``python -m nambu_bch`` is still importing the package
    return os.path.basename(argv0) in ("nambu-bch", "nambu-bch.exe", "-m")


def _interrupted(signum, frame):  # pragma: no cover - exercised by a subprocess test
    try:
        os.write(2, b"nambu-bch: interrupted\n")
    finally:
        os._exit(130)


def install() -> None:
    """Install the import-time SIGINT handler if this process is the command line (main thread only)."""
    global _installed
    if not _is_cli():
        return
    try:
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, _interrupted)
            _installed = True
    except (ValueError, OSError):  # not the main thread, or no signals on this platform
        pass


def cli_started() -> None:
    """``main`` is running: Ctrl-C raises ``KeyboardInterrupt`` again (handled by ``main``)."""
    global _installed
    if _installed:
        try:
            signal.signal(signal.SIGINT, signal.default_int_handler)
        except (ValueError, OSError):
            pass
        _installed = False


install()
