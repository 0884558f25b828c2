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
checked against a LaTeX- and source-safe pattern.  Ctrl-C prints one line and
exits 130 (also during the imports); a reader that closes stdout early ends the
run quietly with status 141.  See ``docs/hardening.md``.  Any other exception
is a bug and propagates with its traceback (exit status 1).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from .errors import NambuBCHError


class _Lazy:
    """A module imported on first attribute access: ``--help`` and argument errors never import sympy."""

    def __init__(self, name):
        self._name = name

    def __getattr__(self, attr):
        return getattr(importlib.import_module(self._name), attr)


sympy = _Lazy("sympy")
render = _Lazy("nambu_bch.render")

PROG = "nambu-bch"
DEFAULT_MODEL = "ho3"
MAX_STEPS = 100_000_000
MAX_CLI_ORDER = 12
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
def _number(text, flag):
    from .model_file import parse_value

    return parse_value(text, flag)


def positive_float(text, flag="--h"):
    value = _number(text, flag)
    if not value.is_positive:
        raise NambuBCHError(f"{flag} {text!r} must be a positive number such as 0.1")
    out = float(value)
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
    from .systems.system import MAX_PARAMETERS, SYMBOL_NAME

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
            values[name] = _number(value.strip(), f"--param {name}")
    return names, values


def parse_x0(text, n):
    parts = [p for p in text.replace(",", " ").split()]
    if len(parts) != n:
        raise NambuBCHError(f"--x0 {text!r} gives {len(parts)} value(s); the system has {n} coordinates (e.g. --x0 {','.join(['1'] * n)})")
    out = []
    for p in parts:
        value = float(_number(p, "--x0"))
        if value != value or value in (float("inf"), float("-inf")):
            raise NambuBCHError(f"--x0 {text!r}: {p!r} is not finite")
        out.append(value)
    return out


# --------------------------------------------------------------------------------------------
# the system and the integrator from the flags
# --------------------------------------------------------------------------------------------
def system_from_args(args):
    """``(system, values)``: the built-in model, TOML file or flag-defined system, and parameter values."""
    from .model_file import load_system
    from .parsing import parse_expression
    from .systems import System, infer_bracket, model

    names, values = parse_params(getattr(args, "param", None))
    user_flags = [f for f, v in (("--H", args.H), ("--G", args.G), ("--coords", args.coords)) if v is not None]
    chosen = [f for f, v in (("--model", args.model), ("--system", args.system)) if v] + (["--H"] if user_flags else [])
    if len(chosen) > 1:
        raise NambuBCHError(f"{' and '.join(chosen)} both choose the system; give only one of --model, --system, --H/--G")
    if user_flags and args.H is None:
        raise NambuBCHError(f"{user_flags[0]} needs --H EXPR (the first Hamiltonian)")
    if args.H is not None:
        from .systems.system import MAX_COORDINATES, check_name

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
        from .systems.system import SYMBOL_NAME

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
            raise NambuBCHError(f"--param {extra[0]}: the system of {args.system} has parameters {_list(system.parameters)}")
        system = _with_flags(system, args)
        args.file_values = file_values  # numeric defaults for check / plot; not substituted symbolically
        return system, values
    system = model(args.model or DEFAULT_MODEL)
    extra = [n for n in names if n not in {p.name for p in system.parameters}]
    if extra:
        raise NambuBCHError(f"--param {extra[0]}: model {system.name} has parameters {_list(system.parameters)}")
    return _with_flags(system, args), values


def _with_flags(system, args):
    """``system`` with the --bracket and --split flags applied (a new System when they change it)."""
    changes = {}
    if args.bracket and args.bracket != system.bracket:
        changes["bracket"] = args.bracket
        changes["split"] = args.split  # the new bracket's default split unless given
    if args.split and args.split != system.split:
        changes["split"] = args.split
    return _with(system, **changes) if changes else system


def _list(symbols):
    return ", ".join(str(s) for s in symbols) or "none"


def _with(system, **changes):
    from .systems import System

    fields = dict(
        coordinates=system.coordinates, hamiltonians=system.hamiltonians, parameters=system.parameters,
        name=system.name, split=system.split, description=system.description, citation=system.citation,
        bracket=system.bracket,
    )
    fields.update(changes)
    return System(**fields)


def substituted(system, values):
    """The system with the given parameter values substituted exactly (symbolic subcommands)."""
    if not values:
        return system
    from .systems.system import SYSTEM_NAME

    subs = {p: values[p.name] for p in system.parameters if p.name in values}
    rest = tuple(p for p in system.parameters if p.name not in values)
    hams = tuple(sympy.sympify(H).subs(subs) for H in system.hamiltonians)
    label = ",".join(f"{k}={v}" for k, v in values.items())
    name = f"{system.name}[{label}]"
    if not SYSTEM_NAME.match(name):  # a long or unusual value: keep the name short and safe
        name = f"{system.name}[{','.join(values)} substituted]"
    return _with(system, hamiltonians=hams, parameters=rest, name=name)


def default_word(system) -> str:
    """The Strang word ``12..n..21`` of the system's splitting (``12321`` for ho3, ``121`` for ho)."""
    from .integrators import strang_word

    return strang_word(len(system.splitting))


def integrator_from_args(args, system):
    """``(word, Composition)`` checked against the system's splitting (:func:`~nambu_bch.integrators.composition_for`)."""
    from .integrators import composition_for

    word = args.integrator or default_word(system)
    comp = composition_for(word, system)
    return word, comp


# --------------------------------------------------------------------------------------------
# output
# --------------------------------------------------------------------------------------------
def emit(args, *, latex=None, text=None, data=None, cache=None):
    """Print (or write to ``--output``) the result in the chosen ``--format``.

    ``latex`` / ``text`` are callables returning strings, ``data`` a callable
    returning the JSON-able dict; only the one needed is computed.  With ``cache``
    (a request tuple) the output is kept in :mod:`nambu_bch.cli_cache`.
    """
    if cache is not None:
        from .cli_cache import cached_text

        out = cached_text((*cache, args.format, getattr(args, "standalone", False)), lambda: _formatted(args, latex, text, data))
    else:
        out = _formatted(args, latex, text, data)
    if args.output:
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


def _base(system, word, **extra):
    data = render.system_dict(system)
    data["integrator"] = word
    data.update(extra)
    return data


# --------------------------------------------------------------------------------------------
# subcommands
# --------------------------------------------------------------------------------------------
def cmd_models(args):
    chosen = any(v is not None for v in (args.model, args.system, args.H, args.G, args.coords, args.param, args.split, args.bracket, args.name))

    @_once
    def systems():
        from .systems import model, model_names

        if chosen:
            system, values = system_from_args(args)
            return [substituted(system, values)]
        return [model(name) for name in model_names()]

    def piece_dict(system, piece):
        return {
            "number": piece.number,
            "label": piece.label(),
            "moves": [str(system.coordinates[i]) for i in piece.moving],
            "field": [render.expression(c) for c in piece.field.to_sympy()],
        }

    def data():
        out = []
        for s in systems():
            d = render.system_dict(s)
            d.update(N=s.N, split=s.split, description=s.description, citation=s.citation,
                     pieces=[piece_dict(s, p) for p in s.splitting.pieces], default_integrator=default_word(s))
            out.append(d)
        return {"models": out}

    def text():
        lines = []
        for s in systems():
            lines.append(f"{s.name}  (N = {s.N}, bracket = {s.bracket}, split = {s.split}, default integrator {default_word(s)})")
            if s.description:
                lines.append(f"  {s.description}")
            lines.append(f"  coordinates: {_list(s.coordinates)};  parameters: {_list(s.parameters)}")
            for lab, H in zip(("H", "G", "H3", "H4"), s.hamiltonians):
                lines.append(f"  {lab} = {H}")
            for p in s.splitting.pieces:
                moves = ", ".join(str(s.coordinates[i]) for i in p.moving)
                comps = ", ".join(f"d{s.coordinates[i]}/dt = {p.field.to_sympy()[i]}" for i in p.moving)
                lines.append(f"  piece {p.number}: moves {moves}: {comps}")
            if s.citation:
                lines.append(f"  ref: {s.citation}")
        return "\n".join(lines)

    def latex():
        from .printing import aligned, latex_text

        blocks = []
        for s in systems():
            rows = [("", "", [latex_text(s.name) + ":"])]
            labels = ["H", "G"] if len(s.hamiltonians) == 2 else [f"H_{{{k + 1}}}" for k in range(len(s.hamiltonians))]
            rows += [(lab, "=", [sympy.latex(H)]) for lab, H in zip(labels[: len(s.hamiltonians)] or ["H"], s.hamiltonians)]
            rows += [(f"X_{{{p.number}}}", "=", [p.label(), "= " + p.field.to_latex()]) for p in s.splitting.pieces]
            blocks.append(aligned(rows))
        return blocks

    emit(args, latex=latex, text=text, data=data, cache=None if chosen else ("models",))


def _once(func):
    """``func()`` computed on the first call only."""
    memo = []

    def wrapper():
        if not memo:
            memo.append(func())
        return memo[0]

    return wrapper


def cmd_bch(args):
    from .bch import effective_field, formal_bch
    from .bch.lyndon import tree_to_latex

    system, values = system_from_args(args)
    system = substituted(system, values)
    word, comp = integrator_from_args(args, system)
    order = args.order if args.order is not None else 2
    series = formal_bch(comp, order + 1)

    field = effective_field(system.splitting, comp, order) if args.field else None
    expanded = None
    if args.terms:
        from .bch import expand_terms

        expanded = {d: expand_terms(series.terms(d), system.splitting) for d in series.degrees}

    def data():
        terms = [
            {"degree": d, "power_of_h": d - 1, "coefficient": render.expression(c), "bracket": render.bracket_text(t),
             "tree": render.bracket_tree(t)}
            for d in range(1, series.max_degree + 1) for c, t in series.terms(d)
        ]
        out = _base(system, word, order=order, max_degree=series.max_degree,
                    coefficients=[render.expression(c) for c in comp.coefficients],
                    pieces=list(comp.pieces), terms=terms)
        if field is not None:
            out["X_eff"] = [[render.expression(c) for c in Z.to_sympy()] for Z in field.coefficients]
        if expanded is not None:
            out["liouville_terms"] = [
                {"degree": d, "coefficient": render.expression(c), "bracket": render.bracket_text(t),
                 "tree": render.bracket_tree(t), "latex": tree_to_latex(t)}
                for d, items in expanded.items() for c, t in items
            ]
        return out

    def text():
        lines = [f"{comp.name}: Phi_h = " + " ".join(f"exp({'' if c == 1 else f'({c})*'}h*X{k})" for k, c in comp.factors())]
        lines.append(f"X_eff through h^{order} (formal BCH in the Lyndon basis):")
        for d in range(1, series.max_degree + 1):
            for c, t in series.terms(d):
                lines.append(f"  h^{d - 1}  {c}  {render.bracket_text(t)}")
        if field is not None:
            for j, Z in enumerate(field.coefficients):
                comps = ", ".join(str(c) for c in Z.to_sympy())
                lines.append(f"Z_{j} = ({comps})")
        if expanded is not None:
            lines.append("Liouville terms (zero brackets pruned):")
            for d, items in expanded.items():
                for c, t in items:
                    lines.append(f"  h^{d - 1}  {c}  {render.bracket_text(t)}")
        return "\n".join(lines)

    def latex():
        from .printing import aligned

        lhs, _, rhs = comp.to_latex().partition(" = ")
        blocks = [aligned([(lhs, "=", rhs.split(" "))]), series.to_latex()]
        if field is not None:
            blocks.append(field.to_latex())
        if expanded is not None:
            from .printing import bracket_sum

            blocks += [bracket_sum(rf"X_{{\rm eff}}\big|_{{h^{{{d - 1}}}}}", [(c, t, d - 1) for c, t in items])
                       for d, items in expanded.items()]
        return blocks

    emit(args, latex=latex, text=text, data=data)


def cmd_shadow(args):
    from .shadow import shadow_hamiltonians

    system, values = system_from_args(args)
    system = substituted(system, values)
    word, comp = integrator_from_args(args, system)
    order = args.order if args.order is not None else 2
    kwargs = {"order": order, "route": args.route, "existence": args.existence}
    if args.degree is not None:
        kwargs["degree"] = args.degree
    family = shadow_hamiltonians(system, comp, **kwargs)

    def data():
        out = _base(system, word, order=order, route=args.route)
        out.update(family.to_dict())
        out["model"], out["integrator"] = system.name, word
        return out

    def text():
        out = f"{word} on {system.name}, order {order}, route {args.route}\n" + family.to_text()
        if args.route == "fi" and hasattr(family.details, "to_text"):
            out += "\n" + family.details.to_text()  # each commutator's representations and weights
        return out

    emit(args, latex=family.to_latex, text=text, data=data)


def cmd_conserved(args):
    from .exact import conserved_quantities

    system, values = system_from_args(args)
    system = substituted(system, values)
    word, comp = integrator_from_args(args, system)
    result = conserved_quantities(system, comp, **({"degree": args.degree} if args.degree is not None else {}))

    def data():
        out = _base(system, word)
        out.update(result.to_dict())
        out["model"], out["integrator"] = system.name, word
        return out

    emit(args, latex=result.to_latex, text=result.to_text, data=data)


def cmd_exact(args):
    from .exact import exact_shadow_hamiltonians

    system, values = system_from_args(args)
    system = substituted(system, values)
    word, comp = integrator_from_args(args, system)
    result = exact_shadow_hamiltonians(system, comp)
    series = result.series(args.order) if args.order is not None else None

    def data():
        out = _base(system, word)
        out.update(result.to_dict())
        out["model"], out["integrator"] = system.name, word
        if series is not None:
            out.update(order=args.order, H_S_series=render.expression(series[0]), G_S_series=render.expression(series[1]))
            out.update({k: v for k, v in result.to_dict(order=args.order).items() if k in ("series", "remainder_power")})
        return out

    def latex():
        return result.to_latex(order=args.order)

    emit(args, latex=latex, text=lambda: result.to_text(order=args.order), data=data)




def _system_chosen(args) -> bool:
    return any((args.model, args.system, args.H, args.G, args.coords, args.param, args.split, args.bracket, args.integrator))


def fi_representations(system, comp):
    """``[(coefficient, (a, b, c), {label: [LiouvilleTerm, ...]})]`` for each non-zero ``h^2`` double commutator.

    The degree-3 part of the formal BCH series (Eq. BCH2) is expanded into Liouville
    terms with vanishing brackets pruned (Eqs. BCH3, BCH4); each ``[[a, b], c]`` is
    rewritten ``-[c, [a, b]]``, and each ``[X_a, [X_b, X_c]]`` is represented in the
    eight ways of Eqs. (1AX)-(2BY), vanishing Liouville terms dropped (as in Eqs. CL5-CL8).
    """
    from .bch import expand_terms, formal_bch
    from .bch.lyndon import is_bracket
    from .shadow.fundamental_identity import double_commutator_terms, labels

    series = formal_bch(comp, 3)
    out = []
    for c, tree in expand_terms(series.terms(3), system.splitting):
        if is_bracket(tree[1]):
            a, (b, d) = tree[0], tree[1]
        else:  # [[a, b], d] = -[d, [a, b]]
            (a, b), d, c = tree[0], tree[1], -c
            a, b, d = d, a, b
        reps = {}
        for label in labels(len(a)):
            terms = double_commutator_terms(system.algebra, a, b, d, label, c)
            reps[label] = [t for t in terms if not t.vanishes(system.coordinates)]
        out.append((c, (a, b, d), reps))
    return out


def _slots(term):
    """The slots of a LiouvilleTerm as sympy expressions."""
    exprs = getattr(term, "expressions", None)
    if exprs is None:
        return tuple(term.slots)
    return tuple(exprs() if callable(exprs) else exprs)


def cmd_fi(args):
    system, values = system_from_args(args)
    system = substituted(system, values)
    word, comp = integrator_from_args(args, system)
    if args.order is not None and args.order > (2 if comp.symmetric else 1):
        return _cmd_fi_nested(args, system, word, comp)
    reps = fi_representations(system, comp) if _system_chosen(args) else None

    def data():
        out = {"forms": [{"label": lab, "text": render.fi_form_text(lab), "latex": render.fi_form_latex(lab)} for lab in render.FI_LABELS]}
        if reps is not None:
            out = {**_base(system, word), **out}
            out["representations"] = [
                {
                    "coefficient": render.expression(c),
                    "commutator": [[render.expression(s) for s in t] for t in abd],
                    "forms": {lab: [{"coefficient": render.expression(t.coefficient), "slots": [render.expression(s) for s in _slots(t)]}
                                    for t in terms] for lab, terms in forms.items()},
                }
                for c, abd, forms in reps
            ]
        return out

    def text():
        lines = [f"{lab}: {render.fi_form_text(lab)}" for lab in render.FI_LABELS]
        for c, abd, forms in reps or ():
            a, b, d = ("X_{" + ", ".join(str(s) for s in t) + "}" for t in abd)
            lines.append(f"{c} [{a}, [{b}, {d}]] (h^2 term of {word} on {system.name}):")
            lines += [f"  {lab}: " + (" + ".join(str(t) for t in terms) or "0") for lab, terms in forms.items()]
        return "\n".join(lines)

    def latex():
        blocks = [render.fi_forms_latex()]
        blocks += [render.fi_representations_latex(f"{word} on {system.name}", c, abd, forms) for c, abd, forms in reps or ()]
        return blocks

    emit(args, latex=latex, text=text, data=data)


def _cmd_fi_nested(args, system, word, comp):
    """``fi --order K``: the brackets at ``h^K`` with the affine hulls of their FI representations (issue 13)."""
    from .shadow.fi_route import count_brackets, fi_brackets

    limit = positive_int(args.limit, "--limit", 10**6) if args.limit is not None else None
    total = count_brackets(system, comp, args.order)
    if limit is None and total > 2000:
        raise NambuBCHError(f"--order {args.order}: {total} brackets; pass --limit N to list the first N")
    shown = fi_brackets(system, comp, args.order, limit)
    more = f"... {total - len(shown)} more brackets (raise --limit)" if len(shown) < total else None
    head = f"h^{args.order} brackets of {word} on {system.name}: {total}"

    def data():
        return {**_base(system, word, order=args.order), "total": total,
                "brackets": [b.to_dict(limit) for b in shown]}

    def text():
        return "\n".join([head, *(b.to_text(limit) for b in shown), *([more] if more else [])])

    def latex():
        title = r"\text{" + f"{word} on {system.name}, {total} brackets at" + "} " + f"h^{{{args.order}}}"
        return " \\\\\n".join([title, *(b.to_latex(limit) for b in shown), *([r"\text{" + more + "}"] if more else [])])

    emit(args, latex=latex, text=text, data=data)


def numeric_inputs(args, system, values):
    from .integrators import parameter_values

    params = {k: float(v) for k, v in {**getattr(args, "file_values", {}), **values}.items()}
    parameter_values(system, params)  # raises naming an unknown parameter
    x0 = parse_x0(args.x0, system.N) if args.x0 is not None else [1.0] * system.N
    return params, x0


def cmd_check(args):
    from .numeric.diagnostics import check

    system, values = system_from_args(args)
    word, comp = integrator_from_args(args, system)
    params, x0 = numeric_inputs(args, system, values)
    order = args.order if args.order is not None else 2
    alpha = float(_number(args.alpha, "--alpha")) if args.alpha is not None else 0.5
    report = check(system, word, args.h, args.steps, x0, params=params, every=args.every, order=order, alpha=alpha)

    def data():
        out = render.system_dict(system)
        out.update(report.to_dict())
        out["model"], out["integrator"] = system.name, word
        return out

    emit(args, text=lambda: str(report), data=data)


def cmd_plot(args):
    outdir = args.outdir
    if not os.path.isdir(outdir):
        try:
            os.makedirs(outdir, exist_ok=True)
        except (OSError, ValueError) as exc:
            raise NambuBCHError(f"--outdir {outdir}: cannot create the directory ({exc.strerror or exc})") from None
    system, values = system_from_args(args)
    if args.integrator is None and system.name == "ho3":
        args.integrator = "32123"  # the paper's Figs. 1-4
    word, comp = integrator_from_args(args, system)
    params, x0 = numeric_inputs(args, system, values)
    kwargs = {"word": word, "h": args.h, "x0": tuple(x0), "params": params, "system": system, "fmt": args.fig_format}
    if args.steps is not None:
        kwargs["t_long"] = args.steps * args.h
    if args.short_steps is not None:
        kwargs["t_short"] = args.short_steps * args.h
    if args.every is not None:
        kwargs["every_long"] = args.every
    if args.dpi is not None:
        kwargs["dpi"] = args.dpi
    from .numeric.figures import paper_figures

    files = paper_figures(outdir, **kwargs)
    files = [os.fspath(f) for f in (files.values() if isinstance(files, dict) else files)]

    emit(args, text=lambda: "\n".join(files), data=lambda: {"outdir": os.fspath(outdir), "files": files})


# --------------------------------------------------------------------------------------------
# the parser
# --------------------------------------------------------------------------------------------
def _system_options(parser):
    group = parser.add_argument_group("system (one of --model, --system, --H)")
    group.add_argument("--model", metavar="NAME", help=f"built-in model (see nambu-bch models): ho, ho3, rigid-body, lotka-volterra, ho3-composite, pendulum, "
                       f"henon-heiles, fpu-beta, toda, exp-well, rational, rigid-body-lp, ho3-pair (default {DEFAULT_MODEL})")
    group.add_argument("--system", metavar="FILE", help="a TOML file defining the system (keys: coordinates, H, G, parameters, split)")
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


def _integrator_options(parser, order=False, default="the Strang word 12..n..21"):
    parser.add_argument("--integrator", metavar="WORD",
                        help="word over every piece such as 12321, alias (TVT/VTV for two pieces, lie-trotter, strang, "
                             "forest-ruth, yoshida, yoshida:WORD, suzuki) or 'piece:coeff,...' "
                             f"(default: {default})")
    if order:
        parser.add_argument("--order", metavar="K", type=str, help=f"highest power of h kept (default 2, at most {MAX_CLI_ORDER})")


def _output_options(parser, default, choices=_SYMBOLIC):
    parser.add_argument("--format", choices=choices, default=default, help=f"output format (default {default})")
    parser.add_argument("--output", metavar="FILE",
                        help="write the result to FILE instead of stdout (a regular file atomically, keeping its mode; "
                             "a device or FIFO as a stream)")
    if "latex" in choices:
        parser.add_argument("--standalone", action="store_true",
                            help="with --format latex: a complete LaTeX document (default: align* environments "
                                 "for the body of a document with amsmath)")


def _progress_option(parser):
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bars on stderr (default: shown for long runs on a terminal or in Jupyter)")


def _numeric_options(parser, defaults):
    parser.add_argument("--h", metavar="H", type=str, help=f"step size, e.g. 0.1 or 1/20 (default {defaults['h']})")
    parser.add_argument("--steps", metavar="N", type=str, help=f"number of steps (default {defaults['steps']})")
    parser.add_argument("--x0", metavar="X", help="initial state, comma separated, e.g. 1,1,1 (default 1,...,1)")
    parser.add_argument("--every", metavar="K", type=str, help=f"sample every K steps (default {defaults['every']})")


EXAMPLES = {
    "models": "examples:\n  nambu-bch models\n  nambu-bch models --model ho3 --format latex\n  nambu-bch models --H 'x2^2/2 + x1^4/4' --format json",
    "bch": "examples:\n  nambu-bch bch                          # Phi^{12321}, X_eff through h^2 (Eq. BCH2)\n"
           "  nambu-bch bch --model ho --integrator TVT --format text     # Eq. (BCH1)\n"
           "  nambu-bch bch --field --terms          # also Z_j on ho3 and the Liouville terms (Eq. BCH4)",
    "fi": "examples:\n  nambu-bch fi                           # the eight forms 1AX..2BY of [X_AB,[X_CD,X_EF]]\n"
          "  nambu-bch fi --model ho3 --integrator 12321   # + each h^2 double commutator of Eq. (BCH4) in the\n"
          "                                                 #   eight forms, vanishing terms dropped (Eqs. CL5-CL8)\n"
          "  nambu-bch fi --model ho3 --order 4 --limit 2 --format text   # h^4 brackets: FI hulls, labelled directions",
    "shadow": "examples:\n  nambu-bch shadow                       # alpha-family of Phi^{12321}, ho3, order 2 (Eqs. SH12321c, SG12321c)\n"
              "  nambu-bch shadow --integrator 32123 --format json\n"
              "  nambu-bch shadow --model ho --integrator TVT --order 4\n"
              "  nambu-bch shadow --H 'x2^2/(2*m) + m*x3/2' --G 'x3 - x1^2' --param m --route fi",
    "conserved": "examples:\n  nambu-bch conserved --integrator 31213   # a row of Table (table)\n  nambu-bch conserved --format json",
    "exact": "examples:\n  nambu-bch exact                        # F(omega h)^alpha H_c, F^(1-alpha) G_c (Eqs. ESH12321, ESG12321)\n"
             "  nambu-bch exact --model ho --integrator TVT",
    "check": "examples:\n  nambu-bch check --integrator 32123 --h 0.1 --steps 100000 --x0 1,1,1\n"
             "  nambu-bch check --model rigid-body --param I1=1 --param I2=2 --param I3=3 --format json",
    "plot": "examples:\n  nambu-bch plot --integrator 32123 --outdir figures    # Figs. 1-4 of the paper (h = 0.1)\n"
            "  nambu-bch plot --integrator 12321 --outdir /tmp/figs --steps 20000 --every 10",
}

HELP = {
    "models": "list the built-in systems and the pieces of their splittings",
    "bch": "the formal BCH series of a word, term by term (optionally evaluated on a system)",
    "fi": "the eight fundamental-identity forms of [X_AB,[X_CD,X_EF]] and their use on a system",
    "shadow": "the shadow-Hamiltonian family of a word at an order, or the obstruction",
    "conserved": "exact conserved quantities H_c, G_c of the integrator (Table (table))",
    "exact": "exact shadow Hamiltonians F^alpha H_c, F^(1-alpha) G_c (Eq. Xeff2)",
    "check": "iterate the integrator and report the conservation diagnostics",
    "plot": "regenerate the paper's Figs. 1-4 as PNG files",
}


def build_parser() -> argparse.ArgumentParser:
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
    from . import __version__

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="SUBCOMMAND", parser_class=_Parser)
    sub.required = True

    def add(name, func):
        p = sub.add_parser(name, help=HELP[name], description=HELP[name], epilog=EXAMPLES[name], formatter_class=_Formatter)
        p.set_defaults(func=func)
        return p

    p = add("models", cmd_models)
    _system_options(p)
    _output_options(p, "text")

    p = add("bch", cmd_bch)
    _system_options(p)
    _integrator_options(p, order=True)
    p.add_argument("--field", action="store_true", help="also evaluate X_eff = Z_0 + h Z_1 + ... on the system")
    p.add_argument("--terms", action="store_true", help="also expand into Liouville terms, zero brackets pruned (Eq. BCH4)")
    _output_options(p, "latex")

    p = add("fi", cmd_fi)
    _system_options(p)
    _integrator_options(p, order=True)
    p.add_argument("--limit", metavar="N", type=str, help="with --order K > 2: show at most N brackets and N directions each")
    _output_options(p, "latex")

    p = add("shadow", cmd_shadow)
    _progress_option(p)
    _system_options(p)
    _integrator_options(p, order=True)
    p.add_argument("--route", choices=("direct", "fi"), default="direct",
                   help="direct: order-by-order linear solve; fi: fundamental-identity representations (default direct)")
    p.add_argument("--degree", metavar="D", type=str, help="polynomial degree of the ansatz for H_S, G_S (default: the library's)")
    p.add_argument("--no-existence", dest="existence", action="store_false",
                   help="when no polynomial pair is found, do not decide existence by orbit averages (answer: undecided)")
    _output_options(p, "latex")

    p = add("conserved", cmd_conserved)
    _progress_option(p)
    _system_options(p)
    _integrator_options(p)
    p.add_argument("--degree", metavar="D", type=str,
                   help="total degree of the polynomial ansatz for invariants (default: that of the Hamiltonians)")
    _output_options(p, "latex")

    p = add("exact", cmd_exact)
    _system_options(p)
    _integrator_options(p)
    p.add_argument("--order", metavar="K", type=str,
                   help="also expand H_S^e, G_S^e through h^K (Eqs. ESH12321, ESG12321)")
    _output_options(p, "latex")

    p = add("check", cmd_check)
    _progress_option(p)
    _system_options(p)
    _integrator_options(p, order=True)
    _numeric_options(p, {"h": 0.1, "steps": 1000, "every": 1})
    p.add_argument("--alpha", metavar="A", help="value of the family parameter alpha in H_S, G_S (default 1/2)")
    _output_options(p, "text", choices=("text", "json"))

    p = add("plot", cmd_plot)
    _progress_option(p)
    _system_options(p)
    _integrator_options(p, default="32123 on ho3 (the paper's Figs. 1-4), else the Strang word 12..n..21")
    p.add_argument("--outdir", metavar="DIR", default=".", help="directory for fig1.png .. fig4.png (default .)")
    _numeric_options(p, {"h": 0.1, "steps": "200000 (t = 20000 at h = 0.1)", "every": 100})
    p.add_argument("--short-steps", metavar="N", help="steps of the Figs. 1-2 run (default 1000, t = 100 at h = 0.1)")
    p.add_argument("--dpi", metavar="DPI", help="resolution of the images (default 100)")
    p.add_argument("--fig-format", choices=("png", "pdf", "svg"), default="png", help="image format (default png)")
    _output_options(p, "text", choices=("text", "json"))

    from .cli_compare import add_compare_parser  # issue 15: work-precision comparison

    add_compare_parser(sub)
    return parser


def _normalise(args):
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
        from .systems.system import check_name

        check_name(args.name, "--name")  # LaTeX- and source-safe, before anything uses it
    return args


class _progress_off:
    """``--no-progress``: ``NAMBU_BCH_PROGRESS=0`` for the run (read by :mod:`nambu_bch.numeric.progress`), then restored."""

    def __enter__(self):
        self.saved = os.environ.get("NAMBU_BCH_PROGRESS")
        os.environ["NAMBU_BCH_PROGRESS"] = "0"

    def __exit__(self, *exc):
        if self.saved is None:
            os.environ.pop("NAMBU_BCH_PROGRESS", None)
        else:
            os.environ["NAMBU_BCH_PROGRESS"] = self.saved
        return False


def _stdout_closed() -> None:
    """After EPIPE: point stdout at /dev/null so that the interpreter's final flush stays quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor (captured in tests)
        pass


def _say(line: str) -> None:
    """One line on stderr; a closed stderr is ignored."""
    try:
        print(line, file=sys.stderr)
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


def main(argv=None) -> int:
    """Run the CLI on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    0 on success, 2 on bad input (one line on stderr), 130 on Ctrl-C (one line),
    141 quietly when stdout is closed early (``nambu-bch shadow | head -c1``),
    1 with one line when memory or the interpreter's recursion limit runs out.
    Nothing a user types produces a traceback; any other exception is a bug and
    propagates with its traceback.
    """
    from . import _startup

    _startup.cli_started()  # from here on Ctrl-C is a KeyboardInterrupt handled below
    prog = PROG
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        prog = f"{PROG} {args.command}"
        _normalise(args)
        if getattr(args, "no_progress", False):
            with _progress_off():
                args.func(args)
        else:
            args.func(args)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    except UsageError as exc:
        hint = exc.prog if exc.prog != PROG else PROG
        message = " ".join(str(exc).split())
        if len(message) > MAX_MESSAGE:
            message = message[: MAX_MESSAGE - 3] + "..."
        _say(f"{exc.prog}: error: {message}; see '{hint} --help'")
        return 2
    except NambuBCHError as exc:
        message = " ".join(str(exc).split())
        if len(message) > MAX_MESSAGE:  # a huge input echoed back: keep the line readable
            message = message[: MAX_MESSAGE - 3] + "..."
        _say(f"{prog}: error: {message}")
        return 2
    except KeyboardInterrupt:
        _say(f"{prog}: interrupted")
        return 130
    except BrokenPipeError:
        _stdout_closed()
        return 141  # as a shell reports a process ended by SIGPIPE; nothing printed
    except MemoryError:
        _say(f"{prog}: error: out of memory; the request is too large for this machine (reduce --order, --degree or --steps)")
        return 1
    except RecursionError:
        _say(f"{prog}: error: the input is nested too deeply to process (recursion limit)")
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
