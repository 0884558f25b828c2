"""``nambu-bch bch``: the formal BCH series of a word term by term (Eq. BCH2), optionally evaluated on a system."""

from __future__ import annotations

from ._options import add_subcommand, integrator_from_args, integrator_options, output_options, symbolic_system, system_options
from ._output import emit

HELP = "the formal BCH series of a word, term by term (optionally evaluated on a system)"
EXAMPLES = ("examples:\n  nambu-bch bch                          # Phi^{12321}, X_eff through h^2 (Eq. BCH2)\n"
            "  nambu-bch bch --model ho --integrator TVT --format text     # Eq. (BCH1)\n"
            "  nambu-bch bch --field --terms          # also Z_j on ho3 and the Liouville terms (Eq. BCH4)")


def register(sub) -> None:
    p = add_subcommand(sub, "bch", HELP, EXAMPLES, run)
    system_options(p)
    integrator_options(p, order=True)
    p.add_argument("--field", action="store_true", help="also evaluate X_eff = Z_0 + h Z_1 + ... on the system")
    p.add_argument("--terms", action="store_true", help="also expand into Liouville terms, zero brackets pruned (Eq. BCH4)")
    output_options(p, "latex")


#: Most Lyndon basis elements (through degree K + 1) that ``bch --order K`` lists: about 3 MB of text.  ho3's
#: 12321 at order 10 has 25486 (1.3 MB printed, 4 s); order 12 would have 192346 (12 MB, 18 s, 300 MB).
MAX_LISTED = 50_000


def _check_size(comp, order) -> None:
    """Refuse, before any work, a series too long to print: its size is the number of Lyndon words (Witt's formula)."""
    from ..bch.formal import estimate_size
    from ..errors import ResourceLimitError

    pieces = len(set(comp.pieces))
    size = estimate_size(pieces, order + 1)["lyndon"]
    if size <= MAX_LISTED:
        return
    best = order
    while best > 0 and estimate_size(pieces, best + 1)["lyndon"] > MAX_LISTED:
        best -= 1
    raise ResourceLimitError(
        f"--order {order}: the BCH series of {comp.name or 'the word'} in {pieces} pieces has up to {size} terms "
        f"(Lyndon words of length 1..{order + 1}, Witt's formula), more than the {MAX_LISTED} this command prints; "
        f"the largest --order for {pieces} pieces is {best} (nambu_bch.formal_bch computes further without printing)"
    )


#: The built-in models of two pieces as ``bch`` prints them (the system's line, the system part of the JSON,
#: :func:`~nambu_bch.cli._output.system_line` and :func:`~nambu_bch.render.system_dict`), so that a series the BCH
#: table serves is printed without building the model (sympy); tests/test_bch_cold.py checks them against the models.
LIGHT_MODELS = {
    "ho": ("system ho: canonical bracket on x1, x2 (parameters m, omega)",
        {"model": "ho", "coordinates": ["x1", "x2"], "parameters": ["m", "omega"],
         "H": "m*omega**2*x1**2/2 + x2**2/(2*m)", "G": None, "bracket": "canonical"}),
    "ho3-composite": ("system ho3-composite: nambu bracket on x1, x2, x3 (parameters m, omega)",
        {"model": "ho3-composite", "coordinates": ["x1", "x2", "x3"], "parameters": ["m", "omega"],
         "H": "m*omega**2*x1/2 + x2/(2*m)", "G": "-2*x1*x2 + 2*x3**2", "bracket": "nambu"}),
    "pendulum": ("system pendulum: canonical bracket on x1, x2",
        {"model": "pendulum", "coordinates": ["x1", "x2"], "parameters": [], "H": "x2**2/2 - cos(x1)", "G": None,
         "bracket": "canonical"}),
    "henon-heiles": ("system henon-heiles: canonical bracket on q1, q2, p1, p2",
        {"model": "henon-heiles", "coordinates": ["q1", "q2", "p1", "p2"], "parameters": [],
         "H": "p1**2/2 + p2**2/2 + q1**2*q2 + q1**2/2 - q2**3/3 + q2**2/2", "G": None, "bracket": "canonical"}),
    "fpu-beta": ("system fpu-beta: canonical bracket on q1, q2, q3, p1, p2, p3 (parameters beta)",
        {"model": "fpu-beta", "coordinates": ["q1", "q2", "q3", "p1", "p2", "p3"], "parameters": ["beta"],
         "H": "beta*q1**4/4 + beta*q3**4/4 + beta*(-q1 + q2)**4/4 + beta*(-q2 + q3)**4/4 + p1**2/2 + p2**2/2 + "
              "p3**2/2 + q1**2/2 + q3**2/2 + (-q1 + q2)**2/2 + (-q2 + q3)**2/2",
         "G": None, "bracket": "canonical"}),
    "toda": ("system toda: canonical bracket on q1, q2, q3, p1, p2, p3",
        {"model": "toda", "coordinates": ["q1", "q2", "q3", "p1", "p2", "p3"], "parameters": [],
         "H": "p1**2/2 + p2**2/2 + p3**2/2 + exp(-q1 + q3) + exp(q1 - q2) + exp(q2 - q3)", "G": None,
         "bracket": "canonical"}),
    "exp-well": ("system exp-well: canonical bracket on x1, x2",
        {"model": "exp-well", "coordinates": ["x1", "x2"], "parameters": [], "H": "-x1 + x2**2/2 + exp(x1)",
         "G": None, "bracket": "canonical"}),
    "rational": ("system rational: canonical bracket on x1, x2",
        {"model": "rational", "coordinates": ["x1", "x2"], "parameters": [], "H": "x2**2/2 - 1/(x1**2 + 1)",
         "G": None, "bracket": "canonical"}),
    "kepler": ("system kepler: canonical bracket on q1, q2, p1, p2 (parameters mu)",
        {"model": "kepler", "coordinates": ["q1", "q2", "p1", "p2"], "parameters": ["mu"],
         "H": "-mu/sqrt(q1**2 + q2**2) + p1**2/2 + p2**2/2", "G": None, "bracket": "canonical"}),
    "kepler-3d": ("system kepler-3d: canonical bracket on q1, q2, q3, p1, p2, p3 (parameters mu)",
        {"model": "kepler-3d", "coordinates": ["q1", "q2", "q3", "p1", "p2", "p3"], "parameters": ["mu"],
         "H": "-mu/sqrt(q1**2 + q2**2 + q3**2) + p1**2/2 + p2**2/2 + p3**2/2", "G": None, "bracket": "canonical"}),
    "morse": ("system morse: canonical bracket on x1, x2",
        {"model": "morse", "coordinates": ["x1", "x2"], "parameters": [], "H": "x2**2/2 + (1 - exp(-x1))**2",
         "G": None, "bracket": "canonical"}),
    "lennard-jones": ("system lennard-jones: canonical bracket on x1, x2",
        {"model": "lennard-jones", "coordinates": ["x1", "x2"], "parameters": [],
         "H": "x2**2/2 - 4/x1**6 + 4/x1**12", "G": None, "bracket": "canonical"}),
}


def _light(args):
    """The text or JSON of ``bch`` without sympy or numpy, or ``None`` when the request needs the full path.

    Taken only when nothing but the word and the order matter: a built-in model of two pieces
    (:data:`LIGHT_MODELS`) without ``--param``, ``--split`` or ``--bracket``, no ``--field`` or ``--terms``, text
    or JSON, and a plain word over both pieces (:func:`~nambu_bch.bch.light.parse_word`) whose series the BCH
    table serves.  The output is the full path's, byte for byte (tests/test_bch_cold.py)."""
    if args.format not in ("text", "json") or args.field or args.terms:
        return None
    if any(getattr(args, flag, None) is not None for flag in ("system", "H", "G", "coords", "param", "split", "bracket",
                                                              "name")):
        return None
    known = LIGHT_MODELS.get(args.model)
    if known is None:
        return None
    from ..bch import formal
    from ..bch.light import parse_word

    word = parse_word(args.integrator or "121", 2)  # "121": the Strang word of two pieces, the full path's default
    if word is None or set(word.pieces) != {1, 2}:  # every piece used: Composition.check passes
        return None
    order = args.order if args.order is not None else 2
    _check_size(word, order)
    series = formal._from_table(word, [c.numerator for c in word.coefficients],
                                [c.denominator for c in word.coefficients], order + 1)
    if series is None:
        return None
    from ..bch.report import series_heading, series_lines, series_terms, word_line

    line, head = known
    if args.format == "text":
        lines = [line, word_line(word.name, zip(word.pieces, word.coefficients)), series_heading(order),
                 *series_lines(series)]
        return "\n".join(lines) + "\n"
    import json

    data = {**head, "integrator": word.name, "order": order, "max_degree": series.max_degree,
            "coefficients": [str(c) for c in word.coefficients], "pieces": list(word.pieces),
            "terms": series_terms(series)}
    return json.dumps(data, indent=2) + "\n"


def run(args):
    out = _light(args)
    if out is not None:
        from ._output import say, shown, write_stdout

        if args.output:
            from ..atomic import write_output

            write_output(args.output, out)  # OutputError: one line naming the path
            say(f"wrote {shown(args.output, 300)}")
        else:
            write_stdout(out)
        return
    from ..bch.report import bch_report

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    order = args.order if args.order is not None else 2
    _check_size(comp, order)
    report = bch_report(system, comp, order, field=args.field, terms=args.terms)
    emit(args, latex=report.to_latex, text=report.to_text, data=report.to_dict, system=system)
