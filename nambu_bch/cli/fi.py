"""``nambu-bch fi``: the eight fundamental-identity forms (Eqs. 1AX-2BY) and their use on a system's BCH terms."""

from __future__ import annotations

from ..errors import NambuBCHError
from ._options import (add_subcommand, integrator_from_args, integrator_options, output_options, positive_int,
                       symbolic_system, system_options)
from ._output import base_dict, emit

HELP = "the eight fundamental-identity forms of [X_AB,[X_CD,X_EF]] and their use on a system"
EXAMPLES = ("examples:\n  nambu-bch fi                           # the eight forms 1AX..2BY of [X_AB,[X_CD,X_EF]]\n"
            "  nambu-bch fi --model ho3 --integrator 12321   # + each h^2 double commutator of Eq. (BCH4) in the\n"
            "                                                 #   eight forms, vanishing terms dropped (Eqs. CL5-CL8)\n"
            "  nambu-bch fi --model ho3 --order 4 --limit 2 --format text   # h^4 brackets: FI hulls, labelled directions")


def register(sub) -> None:
    p = add_subcommand(sub, "fi", HELP, EXAMPLES, run)
    system_options(p)
    integrator_options(p, order=True)
    p.add_argument("--limit", metavar="N", type=str, help="with --order K > 2: show at most N brackets and N directions each")
    output_options(p, "latex")


def _system_chosen(args) -> bool:
    return any((args.model, args.system, args.H, args.G, args.coords, args.param, args.split, args.bracket, args.integrator))


def run(args):
    from .. import render
    from ..shadow.fundamental_identity import FI_LABELS, bch_double_commutators

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    if args.order is not None and args.order > (2 if comp.symmetric else 1):
        return _nested(args, system, word, comp)
    reps = bch_double_commutators(system, comp) if _system_chosen(args) else None

    def data():
        out = {"forms": [{"label": lab, "text": render.fi_form_text(lab), "latex": render.fi_form_latex(lab)} for lab in FI_LABELS]}
        if reps is not None:
            out = {**base_dict(system, word), **out}
            out["representations"] = [
                {
                    "coefficient": render.expression(c),
                    "commutator": [[render.expression(s) for s in t] for t in abd],
                    "forms": {lab: [{"coefficient": render.expression(t.coefficient), "slots": [render.expression(s) for s in t.expressions]}
                                    for t in terms] for lab, terms in forms.items()},
                }
                for c, abd, forms in reps
            ]
        return out

    def text():
        lines = [f"{lab}: {render.fi_form_text(lab)}" for lab in FI_LABELS]
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


def _nested(args, system, word, comp):
    """``fi --order K``: the brackets at ``h^K`` with the affine hulls of their FI representations (issue 13)."""
    from ..shadow.fi_route import count_brackets, fi_brackets

    limit = positive_int(args.limit, "--limit", 10**6) if args.limit is not None else None
    total = count_brackets(system, comp, args.order)
    if limit is None and total > 2000:
        raise NambuBCHError(f"--order {args.order}: {total} brackets; pass --limit N to list the first N")
    shown = fi_brackets(system, comp, args.order, limit)
    emit(args, latex=shown.to_latex, text=shown.to_text, data=shown.to_dict)

