"""Parsing helpers of the command line: the parser class, option groups, flag conversion, the system and integrator.

Every conversion raises :class:`~nambu_bch.errors.NambuBCHError` naming the flag
and what is accepted (printed on one line by :func:`nambu_bch.cli.main`, exit 2).
Nothing here imports sympy at module level: ``nambu-bch --help`` and argument
errors answer without it.
"""

from __future__ import annotations

import argparse
import functools
import sys

from ..checks import MAX_ORDER as MAX_CLI_ORDER  # the API's range of orders (light module: no sympy here)
from ..errors import MAX_MESSAGE, InvalidSystemError, NambuBCHError, one_line, shown  # noqa: F401 -- re-exported to the cli modules

PROG = "nambu-bch"
DEFAULT_MODEL = "ho3"
MAX_STEPS = 100_000_000
#: Largest ``fi --limit`` (brackets and directions listed).
MAX_LIMIT = 10**6
#: Longest accepted path (--system, --output, --outdir).
MAX_PATH = 4096
_SYMBOLIC = ("latex", "text", "json")


class UsageError(Exception):
    """An argparse error, reported on one line by :func:`main`."""

    def __init__(self, prog, message):
        super().__init__(message)
        self.prog = prog


class _Parser(argparse.ArgumentParser):
    """``argparse`` with one-line errors and no abbreviations (``--h`` is not ``--help``, ``--out`` not ``--output``)."""

    def __init__(self, *args, **kwargs):
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)

    def error(self, message):  # one line, no usage block
        raise UsageError(self.prog, message)

    def _check_value(self, action, value):
        # argparse's own message lists the choices; add the closest one (a subcommand, --format, --route ...)
        if action.choices is not None and value not in action.choices:
            from ..errors import did_you_mean

            choices = ", ".join(map(repr, action.choices))
            raise argparse.ArgumentError(
                action, f"invalid choice: {shown(value)}{did_you_mean(value, list(action.choices))} (choose from {choices})"
            )


def unknown_argument_message(parser, command, extras) -> str:
    """The one-line answer to arguments ``parse_known_args`` left over: the flag's subcommand or the closest flag."""
    from ..errors import did_you_mean

    first = next((e for e in extras if e.startswith("-")), extras[0])
    if not first.startswith("-"):
        return f"unrecognized argument {shown(first)}"
    flag = first.split("=", 1)[0]
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
    own = subparsers[command]._option_string_actions if command in subparsers else parser._option_string_actions
    where = f"nambu-bch {command}" if command else "nambu-bch"
    others = [f"nambu-bch {name}" for name, sub in subparsers.items() if name != command and flag in sub._option_string_actions]
    message = f"unrecognized argument {shown(flag)}"
    if others:
        shown_others = ", ".join(f"`{o}`" for o in others[:3]) + (", ..." if len(others) > 3 else "")
        message += f": that flag belongs to {shown_others}, not `{where}`"
    # a flag of another subcommand: suggest only the same name in other case (--h here, --H there)
    candidates = [o for o in own if o.startswith("--") and (not others or o.lower() == flag.lower())]
    hint = did_you_mean(flag, candidates)
    return message + ("; " + hint.strip(" ()") if hint else "")


class _Formatter(argparse.RawDescriptionHelpFormatter):
    pass


class _StoreOnce(argparse._StoreAction):
    """A flag with one value given twice is refused (argparse would keep the last one without a word)."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault("_given_once", {})
        if self.dest in given:
            raise argparse.ArgumentError(
                self, f"given twice ({shown(given[self.dest], 40)} and {shown(values, 40)}); give it once"
            )
        given[self.dest] = values
        super().__call__(parser, namespace, values, option_string)



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
    from ..systems.system import check_parameter_names

    names, values = [], {}
    for item in items or ():
        name, sep, value = item.partition("=")
        name = name.strip()
        check_parameter_names([name], f"--param {shown(item)}: ")
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
def system_spec(args):
    """The :class:`~nambu_bch.systems.spec.SystemSpec` of the system flags (with ``--param`` values)."""
    from ..systems.spec import SystemSpec

    names, values = parse_params(getattr(args, "param", None))
    user_flags = [f for f, v in (("--H", args.H), ("--G", args.G), ("--coords", args.coords)) if v is not None]
    if user_flags and args.H is None and not (args.model or args.system):
        raise InvalidSystemError(f"{user_flags[0]} needs --H EXPR (the first Hamiltonian)")
    texts = ([args.H] if args.H is not None else []) + list(args.G or [])
    labels = {"model": "--model", "file": "--system", "hamiltonians": "--H", "choice": "--model, --system, --H/--G",
              "parameters": "--param", "name": "--name", "count": f"--H and {len(texts) - 1} --G",
              "system": f"--coords {{coords}} with --H and {len(texts) - 1} --G"}
    coords = None
    if args.coords is not None:
        coords = tuple(args.coords.replace(",", " ").split())
        labels["coordinates"] = f"--coords {shown(args.coords)}"
    nothing_chosen = not (texts or coords is not None or args.system)
    return SystemSpec(
        model=args.model or (DEFAULT_MODEL if nothing_chosen else None), file=args.system,
        hamiltonians=tuple(zip(texts, ["--H"] + ["--G"] * (len(texts) - 1))), coordinates=coords,
        parameters=tuple(names), values=tuple(values.items()), split=args.split, bracket=args.bracket,
        name=args.name, labels=tuple(labels.items()),
    )


def system_from_args(args):
    """``(system, values)``: the built-in model, TOML file or flag-defined system, and the ``--param`` values.

    A TOML file's own parameter values are left in ``args.file_values`` (numeric defaults for check / plot;
    not substituted symbolically).
    """
    spec = system_spec(args)
    file_values: dict = {}
    system = spec.build(file_values)
    if spec.file:
        args.file_values = file_values
    return system, dict(spec.values)


def symbolic_system(args):
    """The system with the ``--param NAME=VALUE`` values substituted exactly (:meth:`System.substitute`)."""
    system, values = system_from_args(args)
    return system.substitute(values)


def names_of(symbols) -> str:
    """``"m, omega"`` (``"none"`` for no symbols)."""
    return ", ".join(str(s) for s in symbols) or "none"


def integrator_from_args(args, system, runge_kutta=False):
    """``(word, Composition)`` checked against the system's splitting (:func:`~nambu_bch.integrators.composition_for`).

    ``runge_kutta``: the subcommand also takes Runge--Kutta methods -- ``--integrator midpoint|gauss4|..|kahan`` or
    ``--tableau FILE.toml`` (:func:`~nambu_bch.integrators.tableau_file.load_tableau`) -- returned as
    ``(name, ButcherTableau)``; the partitioned pairs (``--integrator lobatto-iiia-iiib-3``) as
    ``(name, PartitionedTableau)``.
    """
    from ..integrators.composition import composition_for, strang_word

    if runge_kutta:
        from ..integrators.runge_kutta import runge_kutta_method

        tableau_file = getattr(args, "tableau", None)
        if tableau_file is not None:
            if args.integrator is not None:
                raise NambuBCHError("give either --integrator or --tableau, not both")
            from ..integrators.tableau_file import load_tableau

            tableau = load_tableau(tableau_file)
            return tableau.name, tableau
        tableau = runge_kutta_method(args.integrator)
        if tableau is not None:
            return tableau.name, tableau
    word = args.integrator or strang_word(len(system.splitting))
    return word, composition_for(word, system)


def runge_kutta_options(parser):
    """``--tableau FILE``: a Runge--Kutta method from a TOML tableau file (exact coefficients, claimed order checked)."""
    # the help names examples only: importing the tableaux (sympy) while the parser is built would slow every command
    parser.add_argument("--tableau", metavar="FILE",
                        help="a Runge-Kutta method from a TOML file (name, order, A, b, optional c and reference; "
                             "coefficients as exact strings); --integrator also takes built-in methods such as "
                             "midpoint, gauss4, gauss6, rk4 or kahan, and on canonical systems the partitioned "
                             "pairs lobatto-iiia-iiib-2 and lobatto-iiia-iiib-3")


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
    """Register subcommand ``name`` on the sub-parsers ``sub``; ``run(args)`` does the work.

    ``args.func`` calls ``nambu_bch.cli.<name>.run`` as that module holds it when the command runs (``run`` itself
    when there is no such module), not as it was when the parser was built: the parser of :func:`nambu_bch.cli.main`
    is built once per process, and a replaced ``run`` (a test's monkeypatch) must be the one called, as with a parser
    built per call.
    """
    p = sub.add_parser(name, help=help, description=help, epilog=examples, formatter_class=_Formatter)
    p.set_defaults(func=functools.partial(_run_current, f"{__package__}.{name}", run))
    return p


def _run_current(module: str, run, args):
    return getattr(sys.modules.get(module), "run", run)(args)


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
    if getattr(args, "limit", None) is not None:
        args.limit = positive_int(args.limit, "--limit", MAX_LIMIT)
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
    inapplicable(args)
    return args


def inapplicable(args) -> None:
    """Refuse a flag that the request would ignore (each flag either changes the result or is refused).

    Conditions that depend on the integrator (``fi --limit`` needs the nested listing) are
    checked by the subcommand once the composition is known.
    """
    if getattr(args, "standalone", False) and args.format != "latex":
        raise NambuBCHError(f"--standalone makes a complete LaTeX document; it applies only with --format latex, "
                            f"not --format {args.format}")
    if getattr(args, "name", None) is not None and getattr(args, "H", None) is None:
        chosen = "--system FILE (its 'name' key)" if getattr(args, "system", None) else "a built-in --model"
        raise NambuBCHError(f"--name {shown(args.name)} names a user system given by --H; {chosen} keeps its own name")


