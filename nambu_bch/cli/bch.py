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


def run(args):
    from ..bch.report import bch_report

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    order = args.order if args.order is not None else 2
    _check_size(comp, order)
    report = bch_report(system, comp, order, field=args.field, terms=args.terms)
    emit(args, latex=report.to_latex, text=report.to_text, data=report.to_dict, system=system)
