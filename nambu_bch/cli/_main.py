"""The ``nambu-bch`` command line (also ``python -m nambu_bch``): a thin layer over the library.

Synopsis::

    nambu-bch models   [--model NAME] [--format text|latex|json]
    nambu-bch bch      [SYSTEM] [--integrator WORD] [--order K] [--field] [--terms]
    nambu-bch fi       [SYSTEM] [--integrator WORD] [--order K] [--limit N]
    nambu-bch shadow   [SYSTEM] [--integrator WORD] [--order K] [--route direct|fi] [--degree D]
    nambu-bch conserved [SYSTEM] [--integrator WORD]
    nambu-bch exact    [SYSTEM] [--integrator WORD]
    nambu-bch check    [SYSTEM] [--integrator WORD] [--h H] [--steps N] [--x0 X] [--every K] [--order K] [--alpha A]
    nambu-bch plot     [SYSTEM] [--integrator WORD] [--outdir DIR] [--h H] [--steps N] [--short-steps N]
                       [--x0 X] [--every K] [--dpi DPI] [--fig-format png|pdf|svg]
    nambu-bch compare  [SYSTEM] [--integrator WORD ...] [--t-end T] [--step-counts N,N,...] [--figure FILE]
    nambu-bch sample   [SYSTEM] [--integrator WORD] [--h H] [--steps L] [--refresh NAMES] [--flip NAMES]
                       [--target H|H_S] [--order K] [--alpha A] [--chains C] [--iterations I] [--burn B]
                       [--seed S] [--x0 X] [--observable EXPR ...]

    SYSTEM is one of   --model NAME                         (built-in; default ho3)
                       --system FILE.toml                   (see nambu_bch.model_file)
                       --H EXPR [--G EXPR ...] [--coords "x1 x2 x3"] [--param NAME ...] [--split full|single]
    --param NAME=VALUE sets a parameter's value: numeric subcommands use it (default 1 for
                       every parameter), symbolic ones substitute it exactly before the analysis.
    --format latex|text|json (default latex for symbolic results, text for models/check/plot),
    --output FILE      (a regular file is written atomically: temporary file in the same directory +
                       os.replace, keeping its mode; a symlink is followed; a device or FIFO such as
                       /dev/stdout is written through as a stream; see nambu_bch.atomic).
    --standalone       (LaTeX: a complete document; default: align* environments for a document body),
    --no-progress      (no progress bars on stderr for long runs; docs/latex.md).

With no options ``nambu-bch shadow`` prints the alpha-family of shadow
Hamiltonians of Phi^{12321} for the paper's N = 3 oscillator at order 2
(Horikoshi, Eqs. SH12321c, SG12321c) as LaTeX.

Bad input (an unknown model, a malformed word or expression, a word that
leaves out a piece of the splitting, a missing file, an invalid flag, a request
too large to finish) prints one line on stderr naming the input and what is
accepted, and exits with status 2; user expressions are parsed by
:func:`nambu_bch.parsing.parse_expression`, never evaluated, and names are
checked against a LaTeX- and source-safe pattern.  Flags are never abbreviated
(``--h`` is not ``--help``); an unknown flag is answered with the subcommand it
belongs to or the closest flag, a flag given twice or one the request would
ignore (``fi --limit`` without ``--order K > 2``, ``--standalone`` without
``--format latex``, ``--name`` with ``--model``) is refused.  Text the user gave
is echoed quoted and escaped (no newline, terminal escape or bidi mark reaches
the terminal).  An output that cannot be written (``--output`` or stdout: a
full disk, ``/dev/full``, the ``ulimit -f`` size limit) is one line and exit 2
as well.  Ctrl-C prints one line and exits 130 (also during the imports); a
reader that closes stdout early ends the run quietly with status 141; with
stderr closed the lines are lost, never written to stdout.  See
``docs/hardening.md``.  Any other exception is a bug and propagates with its
traceback (exit status 1).

The package: :mod:`._main` (this entry point, error handling and exit codes),
:mod:`._options` (option groups, flag conversion, the system and integrator from
the flags), :mod:`._output` (formats and writing), one module per subcommand
(``models``, ``bch``, ``fi``, ``shadow``, ``conserved``, ``exact``, ``check``,
``plot``, ``compare``, ``sample``, each with ``register(sub)`` and ``run(args)``) and
:mod:`.cache` (the ``models`` output cache).  Nothing is imported from sympy
before a subcommand runs: ``--help`` and argument errors answer at once.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from ..errors import NambuBCHError
from ._options import PROG, UsageError, _Formatter, _Parser, normalise, one_line, unknown_argument_message
from ._output import say, stdout_closed

#: The subcommands in the order of ``--help``: each module ``nambu_bch.cli.<name>`` has ``register(sub)``, ``run(args)``.
SUBCOMMANDS = ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot", "compare", "sample")


class _Version(argparse.Action):
    """``--version``: the installed version is looked up only when asked (importing ``importlib.metadata`` would
    otherwise cost every run of the command, ``--help`` and errors included)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from .. import __version__

        parser._print_message(f"{parser.prog} {__version__}\n", sys.stdout)
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    """The ``argparse`` parser of ``nambu-bch`` with every subcommand registered."""
    parser = _Parser(
        prog=PROG, formatter_class=_Formatter,
        description="Shadow Hamiltonians of splitting integrators in Nambu mechanics (Horikoshi).",
        epilog="the system: --model NAME (default ho3) | --system FILE.toml | --H EXPR [--G EXPR] [--coords ...] [--param NAME]\n"
               "parameter values: --param NAME=VALUE (exact, e.g. m=1/2): check/plot use them (default 1),\n"
               "  symbolic subcommands substitute them before the analysis\n"
               "bad input: one line on stderr, exit status 2; expressions are parsed by a whitelist, never eval-ed\n\n"
               "examples:\n  nambu-bch shadow            # the paper's alpha-family of Phi^{12321}, LaTeX\n"
               "  nambu-bch shadow --integrator 32123 --format json\n"
               "  nambu-bch models\n  nambu-bch SUBCOMMAND --help",
    )
    parser.add_argument("--version", action=_Version, nargs=0, help="show program's version number and exit")
    sub = parser.add_subparsers(dest="command", metavar="SUBCOMMAND", parser_class=_Parser)
    sub.required = True
    for name in SUBCOMMANDS:
        importlib.import_module(f"{__package__}.{name}").register(sub)
    return parser


_PARSER: list = []


def _parser() -> argparse.ArgumentParser:
    """The parser :func:`main` uses, built once per process.

    Building it registers the ten subcommands, about fifty times the CPU of a parse
    (``benchmarks/bench_cli_parser.py``); a parse leaves it unchanged (the values go to a fresh namespace, the
    ``append`` defaults are ``None`` and copied, ``_StoreOnce`` records its flags in the namespace), so an
    in-process caller of :func:`main` (a notebook, the test suite's hundreds of argv) need not rebuild it per call.
    :func:`build_parser` still returns a new parser, which its caller may change.
    """
    if not _PARSER:
        _PARSER.append(build_parser())
    return _PARSER[0]


class _progress_off:
    """``--no-progress``: ``NAMBU_BCH_PROGRESS=0`` for the run (read by :mod:`nambu_bch.progress`), then restored."""

    def __enter__(self):
        self.saved = os.environ.get("NAMBU_BCH_PROGRESS")
        os.environ["NAMBU_BCH_PROGRESS"] = "0"

    def __exit__(self, *exc):
        if self.saved is None:
            os.environ.pop("NAMBU_BCH_PROGRESS", None)
        else:
            os.environ["NAMBU_BCH_PROGRESS"] = self.saved
        return False


def _reserve_standard_descriptors() -> None:
    """Put ``/dev/null`` on a standard descriptor (0, 1, 2) that the process was started without.

    Started with ``2>&-``, the next file opened (an ``--output`` temporary, a cache file) would get
    descriptor 2, and anything written to "stderr" would land in it.  ``sys.stderr`` stays ``None``
    (messages are then lost, never sent to stdout); ``sys.stdout`` ``None`` still ends the run as a
    closed stdout (exit 141).
    """
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            try:
                null = os.open(os.devnull, os.O_RDWR)
                if null != fd:
                    os.dup2(null, fd)
                    os.close(null)
            except OSError:
                return


def main(argv=None) -> int:
    """Run the CLI on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    0 on success, 2 on bad input or an output that cannot be written (one line on
    stderr), 130 on Ctrl-C (one line), 141 quietly when stdout is closed early
    (``nambu-bch shadow | head -c1``), 1 with one line when memory or the
    interpreter's recursion limit runs out.
    Nothing a user types produces a traceback; any other exception is a bug and
    propagates with its traceback.
    """
    from .. import _startup

    _startup.cli_started()  # from here on Ctrl-C is a KeyboardInterrupt handled below
    prog = PROG
    try:
        _reserve_standard_descriptors()
        parser = _parser()
        args, extras = parser.parse_known_args(argv)
        if extras:
            command = getattr(args, "command", None)
            raise UsageError(f"{PROG} {command}" if command else PROG, unknown_argument_message(parser, command, extras))
        prog = f"{PROG} {args.command}"
        normalise(args)
        if getattr(args, "no_progress", False):
            with _progress_off():
                args.func(args)
        else:
            args.func(args)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    except UsageError as exc:
        say(f"{exc.prog}: error: {one_line(exc)}; see '{exc.prog} --help'")
        return 2
    except NambuBCHError as exc:  # includes OutputError: stdout or --output could not be written
        say(f"{prog}: error: {one_line(exc)}")
        return 2
    except KeyboardInterrupt:
        say(f"{prog}: interrupted")
        return 130
    except BrokenPipeError:
        stdout_closed()
        return 141  # as a shell reports a process ended by SIGPIPE; nothing printed
    except MemoryError:
        say(f"{prog}: error: out of memory; the request is too large for this machine (reduce --order, --degree or --steps)")
        return 1
    except RecursionError:
        say(f"{prog}: error: the input is nested too deeply to process (recursion limit)")
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
