"""Output of the command line: the chosen ``--format``, ``--output`` written atomically, stdout written completely."""

from __future__ import annotations

import os
import sys

from ..errors import OutputError
from ._options import MAX_MESSAGE, one_line, shown


def say(line: str) -> None:
    """``line`` on stderr as one printable line (:func:`~nambu_bch.errors.one_line`).

    A closed or failing stderr loses the line, and it never goes to stdout: started with
    ``2>&-`` Python sets ``sys.stderr`` to ``None``, and ``print(file=None)`` would write to stdout.
    """
    stream = sys.stderr
    if stream is None:
        return
    try:
        print(one_line(line, MAX_MESSAGE + 100), file=stream)
        stream.flush()
    except (OSError, ValueError):
        pass


def stdout_closed() -> None:
    """After a failed write to stdout: point it at /dev/null so that the interpreter's final flush stays quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor (captured in tests)
        pass


def emit(args, *, latex=None, text=None, data=None, cache=None, system=None):
    """Print (or write to ``--output``) the result in the chosen ``--format``.

    ``latex`` / ``text`` are callables returning strings, ``data`` a callable
    returning the JSON-able dict; only the one needed is computed.  With ``cache``
    (a request tuple) the output is kept in :mod:`nambu_bch.cli.cache`.  With
    ``system`` the text and LaTeX start with the system analysed (name, bracket,
    coordinates, :func:`system_line`); the JSON names it in its own keys.
    """
    if system is not None:
        text = _headed(text, system_line(system)) if text is not None else None
        latex = _headed_latex(latex, system) if latex is not None else None
    if cache is not None:
        from .cache import cached_text

        out = cached_text((*cache, args.format, getattr(args, "standalone", False)), lambda: _formatted(args, latex, text, data))
    else:
        out = _formatted(args, latex, text, data)
    if args.output:
        from .. import render

        render.write_output(out, args.output)  # OutputError: one line naming the path
        say(f"wrote {shown(args.output, 300)}")
    else:
        write_stdout(out)


def system_line(system) -> str:
    """``"system ho3: nambu bracket on x1, x2, x3 (parameters m, omega)"``: what a result was computed for."""
    params = ", ".join(str(p) for p in system.parameters)
    coords = ", ".join(str(x) for x in system.coordinates)
    return f"system {system.name}: {system.bracket} bracket on {coords}" + (f" (parameters {params})" if params else "")


def system_latex(system) -> str:
    """:func:`system_line` as an ``aligned`` text row (names through :func:`~nambu_bch.printing.latex_text`)."""
    import sympy

    from ..printing import aligned, latex_text

    coords = ", ".join(sympy.latex(x) for x in system.coordinates)
    row = latex_text(f"system {system.name}: {system.bracket} bracket on") + rf"\ ({coords})"
    if system.parameters:
        row += latex_text(", parameters") + r"\ " + ", ".join(sympy.latex(p) for p in system.parameters)
    return aligned([("", "", [row])])


def _headed(text, head):
    return lambda: head + "\n" + text()


def _headed_latex(latex, system):
    def blocks():
        out = latex()
        return [system_latex(system), *([out] if isinstance(out, str) else out)]

    return blocks


def write_stdout(text: str) -> None:
    """Write ``text`` to stdout completely, as UTF-8.

    Through the file descriptor when there is one: a partial ``write`` (a reader
    that went away, ``PYTHONUNBUFFERED``) is continued or ends in
    ``BrokenPipeError``, never in silently truncated output.  Any other failure
    (``/dev/full``, the file-size limit of ``ulimit -f``, an I/O error) raises
    :class:`~nambu_bch.errors.OutputError`, one line and exit 2 like an
    unwritable ``--output``.
    """
    stream = sys.stdout
    if stream is None:  # started with stdout closed (nambu-bch ... >&-)
        raise BrokenPipeError("stdout is closed")
    try:
        fd = stream.fileno() if stream is sys.__stdout__ else None
    except (AttributeError, OSError, ValueError):
        fd = None
    try:
        if fd is None:  # a replaced stream (pytest capture, Jupyter, io.StringIO): its own write
            stream.write(text)
            stream.flush()
            return
        stream.flush()
        data = memoryview(text.encode("utf-8"))
        while data:
            data = data[os.write(fd, data):]
    except BrokenPipeError:
        raise
    except OSError as exc:
        stdout_closed()  # what is left in Python's buffer must not fail again at exit
        raise OutputError(f"cannot write the result to stdout ({exc.strerror or exc})") from None


def _formatted(args, latex, text, data) -> str:
    from .. import render

    fmt = args.format
    if fmt == "json":
        out = render.to_json(data())
    elif fmt == "latex" and latex is not None:
        out = render.latex_document(latex(), standalone=getattr(args, "standalone", False))
    elif text is not None:
        out = text()
        out = out if out.endswith("\n") else out + "\n"
    else:
        out = render.to_text(data())
    return out


def once(func):
    """``func()`` computed on the first call only (a result shared by the text, LaTeX and JSON printers)."""
    memo = []

    def wrapper():
        if not memo:
            memo.append(func())
        return memo[0]

    return wrapper
