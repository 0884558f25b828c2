"""``nambu-bch fi``: the eight fundamental-identity forms (Eqs. 1AX-2BY) and their use on a system's BCH terms."""

from __future__ import annotations

from ..errors import NambuBCHError
from ._options import (add_subcommand, integrator_from_args, integrator_options, output_options,
                       symbolic_system, system_options)
from ._output import emit

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
    return any((args.model, args.system, args.H, args.G, args.coords, args.param, args.split, args.bracket, args.integrator,
                args.order is not None))


def run(args):
    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    if args.order is not None and args.order < 2:
        raise NambuBCHError(f"--order {args.order}: fi shows the brackets at h^K for K >= 2 (the double commutators "
                            "start at h^2); give --order 2 or more")
    nested = args.order is not None and args.order > (2 if comp.symmetric else 1)
    if args.limit is not None and not nested:
        raise NambuBCHError(f"--limit {args.limit} applies to the listing of --order K > {2 if comp.symmetric else 1} "
                            f"for {word}, not to the h^2 brackets (all shown); add e.g. --order 4 or drop --limit")
    if nested:
        return _nested(args, system, word, comp)
    from ..shadow.fi_route import FIForms, fi_forms  # once the flags are read: bad input is refused without it

    result = fi_forms(system, comp) if _system_chosen(args) else FIForms(system, comp)
    emit(args, latex=result.to_latex, text=result.to_text, data=result.to_dict, system=system if _system_chosen(args) else None)


def _nested(args, system, word, comp):
    """``fi --order K``: the brackets at ``h^K`` with the affine hulls of their FI representations."""
    from ..shadow.fi_route import bracket_bound, fi_brackets

    limit = args.limit  # converted and bounded with every other flag (_options.MAX_LIMIT)
    # the size from the piece-level trees: counting exactly evaluates every term bracket (seconds at h^6), the work
    # the refusal is there to spare; the listing's work grows with the bound, not with the brackets that survive
    bound = bracket_bound(system, comp, args.order)
    if limit is None and bound > 2000:
        raise NambuBCHError(f"--order {args.order}: up to {bound} brackets; pass --limit N to list the first N")
    shown = fi_brackets(system, comp, args.order, limit)
    emit(args, latex=shown.to_latex, text=shown.to_text, data=shown.to_dict, system=system)

