"""Parsing helpers of the command line: the parser class, option groups, flag conversion, the system and integrator.

Every conversion raises :class:`~nambu_bch.errors.NambuBCHError` naming the flag
and what is accepted (printed on one line by :func:`nambu_bch.cli.main`, exit 2).
Nothing here imports sympy at module level: ``nambu-bch --help`` and argument
errors answer without it.
"""

from __future__ import annotations

import argparse

from ..checks import MAX_ORDER as MAX_CLI_ORDER  # the API's range of orders (light module: no sympy here)
from ..errors import NambuBCHError

PROG = "nambu-bch"
DEFAULT_MODEL = "ho3"
MAX_STEPS = 100_000_000
#: Longest error line printed (a huge input echoed back is shortened).
MAX_MESSAGE = 600
#: Longest accepted path (--system, --output, --outdir).
MAX_PATH = 4096
_SYMBOLIC = ("latex", "text", "json")


class UsageError(Exception):
    """An argparse error, reported on one line by :func:`main`."""

    def __init__(self, prog, message):
        super().__init__(message)
        self.prog = prog


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, no usage block
        raise UsageError(self.prog, message)


class _Formatter(argparse.RawDescriptionHelpFormatter):
    pass



# --------------------------------------------------------------------------------------------
# input conversion (each raises NambuBCHError naming the flag)
# --------------------------------------------------------------------------------------------
def number(text, flag):
    from ..model_file import parse_value

    return parse_value(text, flag)


def positive_float(text, flag="--h"):
    from ..checks import finite_float

    value = number(text, flag)
    if not value.is_positive:
        raise NambuBCHError(f"{flag} {text!r} must be a positive number such as 0.1")
    out = finite_float(value, f"{flag} {text!r}")
    if not 0.0 < out < float("inf"):
        raise NambuBCHError(f"{flag} {text!r} is out of range; give a positive finite number such as 0.1")
    return out


def _ascii_int(text):
    """``int(text)`` for ASCII digits only (Python's ``int`` also reads '３' and '٣')."""
    if not isinstance(text, str) or not text.strip().lstrip("+-").isdigit() or not text.isascii() or len(text) > 30:
        raise ValueError(text)
    return int(text, 10)


def positive_int(text, flag, limit):
    try:
        value = _ascii_int(text)
    except (TypeError, ValueError):
        raise NambuBCHError(f"{flag} {text!r} must be a positive integer such as 1000") from None
    if not 1 <= value <= limit:
        raise NambuBCHError(f"{flag} {value} must be between 1 and {limit}")
    return value


def order_value(text, flag="--order", limit=MAX_CLI_ORDER, low=0):
    try:
        value = _ascii_int(text)
    except (TypeError, ValueError):
        raise NambuBCHError(f"{flag} {text!r} must be an integer between {low} and {limit}") from None
    if not low <= value <= limit:
        raise NambuBCHError(f"{flag} {value} must be between {low} and {limit}")
    return value


def parse_params(items):
    """``--param NAME`` / ``--param NAME=VALUE`` -> ``(names in order, {name: exact value})``."""
    from ..systems.system import MAX_PARAMETERS, SYMBOL_NAME

    names, values = [], {}
    if len(items or ()) > MAX_PARAMETERS:
        raise NambuBCHError(f"--param is given {len(items)} times; at most {MAX_PARAMETERS} parameters are accepted")
    for item in items or ():
        name, sep, value = item.partition("=")
        name = name.strip()
        if not SYMBOL_NAME.match(name):
            raise NambuBCHError(
                f"--param {item!r}: {name!r} is not a parameter name; write --param m (declare) or --param m=1 (value)"
            )
        if name in ("h", "alpha"):
            raise NambuBCHError(f"--param {item!r}: {name!r} is reserved (the step is --h, alpha is the family parameter)")
        if name not in names:
            names.append(name)
        if sep:
            values[name] = number(value.strip(), f"--param {name}")
    return names, values


def parse_x0(text, n):
    parts = [p for p in text.replace(",", " ").split()]
    if len(parts) != n:
        raise NambuBCHError(f"--x0 {text!r} gives {len(parts)} value(s); the system has {n} coordinates (e.g. --x0 {','.join(['1'] * n)})")
    from ..checks import finite_float

    return [finite_float(number(p, "--x0"), f"--x0 {p!r}") for p in parts]



# --------------------------------------------------------------------------------------------
# the system and the integrator from the flags
# --------------------------------------------------------------------------------------------
def system_from_args(args):
    """``(system, values)``: the built-in model, TOML file or flag-defined system, and parameter values."""
    import sympy

    from ..model_file import load_system
    from ..parsing import parse_expression
    from ..systems import System, infer_bracket, model
    from ..systems.system import MAX_COORDINATES, SYMBOL_NAME, check_name

    names, values = parse_params(getattr(args, "param", None))
    user_flags = [f for f, v in (("--H", args.H), ("--G", args.G), ("--coords", args.coords)) if v is not None]
    chosen = [f for f, v in (("--model", args.model), ("--system", args.system)) if v] + (["--H"] if user_flags else [])
    if len(chosen) > 1:
        raise NambuBCHError(f"{' and '.join(chosen)} both choose the system; give only one of --model, --system, --H/--G")
    if user_flags and args.H is None:
        raise NambuBCHError(f"{user_flags[0]} needs --H EXPR (the first Hamiltonian)")
    if args.H is not None:
        hams = [args.H] + list(args.G or [])
        if len(hams) > MAX_COORDINATES - 1:  # before any parsing: the bracket of n Hamiltonians has (n+1)! terms
            raise NambuBCHError(
                f"--H and {len(hams) - 1} --G give {len(hams)} Hamiltonians; at most {MAX_COORDINATES - 1} are accepted "
                f"(a system on at most {MAX_COORDINATES} coordinates)"
            )
        name = check_name(args.name, "--name") if args.name else "custom"
        if args.coords:
            coords = args.coords.replace(",", " ").split()
        else:
            coords = [f"x{i}" for i in range(1, (len(hams) + 1 if len(hams) > 1 else 2) + 1)]
        if len(coords) > MAX_COORDINATES:
            raise NambuBCHError(f"--coords gives {len(coords)} coordinates; at most {MAX_COORDINATES} are accepted")
        for c in coords:
            if not SYMBOL_NAME.match(c):
                raise NambuBCHError(f"--coords {args.coords!r}: {c!r} is not a symbol name; write e.g. --coords 'x1 x2 x3'")
            if c in ("h", "alpha"):
                raise NambuBCHError(f"--coords {args.coords!r}: {c!r} is reserved (the step h, the family parameter alpha)")
        if len(coords) >= 2:
            try:
                infer_bracket(len(coords), len(hams), args.bracket)
            except NambuBCHError as exc:
                raise NambuBCHError(f"--coords {' '.join(coords)!r} with --H and {len(hams) - 1} --G: {exc}") from None
        symbols = [sympy.Symbol(s) for s in (*coords, *names)]
        flags = ["--H"] + ["--G"] * (len(hams) - 1)
        parsed = [parse_expression(text, symbols, what=flag) for text, flag in zip(hams, flags)]
        system = System(coords, parsed, names, name=name, split=args.split, bracket=args.bracket)
        return system, values
    if args.system:
        file_values: dict = {}
        system = load_system(args.system, file_values)
        extra = [n for n in names if n not in {p.name for p in system.parameters}]
        if extra:
            raise NambuBCHError(f"--param {extra[0]}: the system of {args.system} has parameters {names_of(system.parameters)}")
        system = _with_flags(system, args)
        args.file_values = file_values  # numeric defaults for check / plot; not substituted symbolically
        return system, values
    system = model(args.model or DEFAULT_MODEL)
    extra = [n for n in names if n not in {p.name for p in system.parameters}]
    if extra:
        raise NambuBCHError(f"--param {extra[0]}: model {system.name} has parameters {names_of(system.parameters)}")
    return _with_flags(system, args), values


def _with_flags(system, args):
    """``system`` with the --bracket and --split flags applied (a new System when they change it)."""
    if args.bracket:
        return system.with_bracket(args.bracket, args.split)
    return system.with_split(args.split) if args.split else system


def symbolic_system(args):
    """The system with the ``--param NAME=VALUE`` values substituted exactly (:meth:`System.substitute`)."""
    system, values = system_from_args(args)
    return system.substitute(values)


def names_of(symbols) -> str:
    """``"m, omega"`` (``"none"`` for no symbols)."""
    return ", ".join(str(s) for s in symbols) or "none"


def integrator_from_args(args, system):
    """``(word, Composition)`` checked against the system's splitting (:func:`~nambu_bch.integrators.composition_for`)."""
    from ..integrators.composition import composition_for, strang_word

    word = args.integrator or strang_word(len(system.splitting))
    return word, composition_for(word, system)


def numeric_inputs(args, system, values):
    """``(params, x0)`` as floats for the numeric subcommands: ``--param`` values over the file's, default 1 each;
    ``x0`` None when ``--x0`` is not given (the API then takes the model's documented default)."""
    from ..checks import finite_float
    from ..integrators import parameter_values

    params = {k: finite_float(v, f"parameter {k}") for k, v in {**getattr(args, "file_values", {}), **values}.items()}
    parameter_values(system, params)  # raises naming an unknown parameter
    x0 = parse_x0(args.x0, system.N) if args.x0 is not None else None  # None: the model's default (the API's)
    return params, x0

# --------------------------------------------------------------------------------------------
# option groups
# --------------------------------------------------------------------------------------------
def system_options(parser):
    group = parser.add_argument_group("system (one of --model, --system, --H)")
    group.add_argument("--model", metavar="NAME", help="built-in model (see nambu-bch models): ho, ho3, rigid-body, lotka-volterra, "
                       "ho3-composite, pendulum, henon-heiles, fpu-beta, toda, exp-well, rational, rigid-body-lp, ho3-pair "
                       f"(default {DEFAULT_MODEL})")
    group.add_argument("--system", metavar="FILE", help="a TOML file defining the system (keys: coordinates, H, G, parameters, split, bracket)")
    group.add_argument("--H", metavar="EXPR", help="first Hamiltonian of a user system, e.g. 'x2^2/2 + x1^2/2'")
    group.add_argument("--G", metavar="EXPR", action="append", help="second Hamiltonian (N = 3); repeat for N >= 4")
    group.add_argument("--coords", metavar="NAMES", help="coordinates of a user system, e.g. 'x1 x2 x3' (default x1..xN)")
    group.add_argument("--param", metavar="NAME[=VALUE]", action="append",
                       help="declare a parameter (user system) and/or set its value, e.g. --param m=1; repeatable")
    group.add_argument("--split", choices=("full", "single", "fine"),
                       help="split every Hamiltonian (full) or only H (single); canonical: T|V (full) or independent parts (fine)")
    group.add_argument("--bracket", choices=("canonical", "nambu", "triplets", "lie-poisson"),
                       help="the bracket (default inferred: 1 Hamiltonian on N = 2d canonical, N - 1 Nambu, 2 on N = 3n "
                            "triplets); lie-poisson: 1 Hamiltonian on N = 3 with the Casimir |x|^2/2")
    group.add_argument("--name", metavar="NAME", help="name of a user system in the output (default custom)")


def integrator_options(parser, order=False, default="the Strang word 12..n..21"):
    parser.add_argument("--integrator", metavar="WORD",
                        help="word over every piece such as 12321, alias (TVT/VTV for two pieces, lie-trotter, strang, "
                             "forest-ruth, yoshida, yoshida:WORD, suzuki) or 'piece:coeff,...' "
                             f"(default: {default})")
    if order:
        parser.add_argument("--order", metavar="K", type=str, help=f"highest power of h kept (default 2, at most {MAX_CLI_ORDER})")


def output_options(parser, default, choices=_SYMBOLIC):
    parser.add_argument("--format", choices=choices, default=default, help=f"output format (default {default})")
    parser.add_argument("--output", metavar="FILE",
                        help="write the result to FILE instead of stdout (a regular file atomically, keeping its mode; "
                             "a device or FIFO as a stream)")
    if "latex" in choices:
        parser.add_argument("--standalone", action="store_true",
                            help="with --format latex: a complete LaTeX document (default: align* environments "
                                 "for the body of a document with amsmath)")


def progress_option(parser):
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bars on stderr (default: shown for long runs on a terminal or in Jupyter)")


def numeric_options(parser, defaults):
    parser.add_argument("--h", metavar="H", type=str, help=f"step size, e.g. 0.1 or 1/20 (default {defaults['h']})")
    parser.add_argument("--steps", metavar="N", type=str, help=f"number of steps (default {defaults['steps']})")
    parser.add_argument("--x0", metavar="X", help="initial state, comma separated, e.g. 1,1,1 (default: the model's, else 1,...,1)")
    parser.add_argument("--every", metavar="K", type=str, help=f"sample every K steps (default {defaults['every']})")

def add_subcommand(sub, name: str, help: str, examples: str, run):
    """Register subcommand ``name`` on the sub-parsers ``sub``; ``run(args)`` does the work."""
    p = sub.add_parser(name, help=help, description=help, epilog=examples, formatter_class=_Formatter)
    p.set_defaults(func=run)
    return p


def normalise(args):
    """Convert the numeric string flags, each error naming its flag."""
    if getattr(args, "order", None) is not None:
        args.order = order_value(args.order)
    if getattr(args, "degree", None) is not None:
        args.degree = order_value(args.degree, "--degree", limit=12, low=1)
    if hasattr(args, "h"):
        args.h = positive_float(args.h, "--h") if args.h is not None else 0.1
    if hasattr(args, "steps"):
        default_steps = 1000 if args.command == "check" else None
        args.steps = positive_int(args.steps, "--steps", MAX_STEPS) if args.steps is not None else default_steps
    if hasattr(args, "every"):
        default_every = 1 if args.command == "check" else None
        args.every = positive_int(args.every, "--every", MAX_STEPS) if args.every is not None else default_every
    if getattr(args, "short_steps", None) is not None:
        args.short_steps = positive_int(args.short_steps, "--short-steps", MAX_STEPS)
    if getattr(args, "dpi", None) is not None:
        args.dpi = positive_int(args.dpi, "--dpi", 1200)
    if getattr(args, "every", None) and getattr(args, "steps", None) and args.every > args.steps:
        raise NambuBCHError(f"--every {args.every} is larger than --steps {args.steps}")
    for flag in ("output", "outdir", "system"):
        value = getattr(args, flag, None)
        if value is not None and not value.strip():
            raise NambuBCHError(f"--{flag} is empty; give a file or directory path")
        if value is not None and ("\x00" in value or len(value) > MAX_PATH):
            raise NambuBCHError(f"--{flag} {value[:40]!r}...: a path has no NUL character and at most {MAX_PATH} characters")
    for flag in ("integrator", "coords", "name", "model"):
        value = getattr(args, flag, None)
        if value is not None and (not value.strip() or len(value) > 200):
            raise NambuBCHError(f"--{flag} {value[:40]!r} must be a non-empty string of at most 200 characters")
    if getattr(args, "name", None) is not None:
        from ..systems.system import check_name

        check_name(args.name, "--name")  # LaTeX- and source-safe, before anything uses it
    return args


