"""``nambu-bch bch``: the formal BCH series of a word term by term (Eq. BCH2), optionally evaluated on a system."""

from __future__ import annotations

from ._options import add_subcommand, integrator_from_args, integrator_options, output_options, symbolic_system, system_options
from ._output import base_dict, emit

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


def run(args):
    from .. import render
    from ..bch import effective_field, formal_bch
    from ..bch.lyndon import tree_to_latex

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    order = args.order if args.order is not None else 2
    _check_size(comp, order)
    series = formal_bch(comp, order + 1)

    field = effective_field(system.splitting, comp, order) if args.field else None
    expanded = None
    if args.terms:
        from ..bch import expand_terms

        expanded = {d: expand_terms(series.terms(d), system.splitting) for d in series.degrees}

    def data():
        terms = [
            {"degree": d, "power_of_h": d - 1, "coefficient": render.expression(c), "bracket": render.bracket_text(t),
             "tree": render.bracket_tree(t)}
            for d in range(1, series.max_degree + 1) for c, t in series.terms(d)
        ]
        out = base_dict(system, word, order=order, max_degree=series.max_degree,
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
        from ..printing import aligned

        lhs, _, rhs = comp.to_latex().partition(" = ")
        blocks = [aligned([(lhs, "=", rhs.split(" "))]), series.to_latex()]
        if field is not None:
            blocks.append(field.to_latex())
        if expanded is not None:
            from ..printing import bracket_sum

            blocks += [bracket_sum(rf"X_{{\rm eff}}\big|_{{h^{{{d - 1}}}}}", [(c, t, d - 1) for c, t in items])
                       for d, items in expanded.items()]
        return blocks

    emit(args, latex=latex, text=text, data=data, system=system)

