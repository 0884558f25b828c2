"""Output of the command line: the chosen ``--format``, ``--output`` written atomically, stdout written completely."""

from __future__ import annotations

import os
import sys


def emit(args, *, latex=None, text=None, data=None, cache=None):
    """Print (or write to ``--output``) the result in the chosen ``--format``.

    ``latex`` / ``text`` are callables returning strings, ``data`` a callable
    returning the JSON-able dict; only the one needed is computed.  With ``cache``
    (a request tuple) the output is kept in :mod:`nambu_bch.cli.cache`.
    """
    if cache is not None:
        from .cache import cached_text

        out = cached_text((*cache, args.format, getattr(args, "standalone", False)), lambda: _formatted(args, latex, text, data))
    else:
        out = _formatted(args, latex, text, data)
    if args.output:
        from .. import render

        render.write_output(out, args.output)  # OutputError: one line naming the path
        print(f"wrote {args.output}", file=sys.stderr)
    else:
        write_stdout(out)


def write_stdout(text: str) -> None:
    """Write ``text`` to stdout completely, as UTF-8.

    Through the file descriptor when there is one: a partial ``write`` (a reader
    that went away, ``PYTHONUNBUFFERED``) is continued or ends in
    ``BrokenPipeError``, never in silently truncated output.
    """
    stream = sys.stdout
    if stream is None:  # started with stdout closed (nambu-bch ... >&-)
        raise BrokenPipeError("stdout is closed")
    try:
        fd = stream.fileno() if stream is sys.__stdout__ else None
    except (AttributeError, OSError, ValueError):
        fd = None
    if fd is None:  # a replaced stream (pytest capture, Jupyter, io.StringIO): its own write
        stream.write(text)
        stream.flush()
        return
    stream.flush()
    data = memoryview(text.encode("utf-8"))
    while data:
        data = data[os.write(fd, data):]


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
