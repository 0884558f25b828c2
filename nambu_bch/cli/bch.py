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


def run(args):
    from ..bch.report import bch_report

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    order = args.order if args.order is not None else 2
    report = bch_report(system, comp, order, field=args.field, terms=args.terms)
    emit(args, latex=report.to_latex, text=report.to_text, data=report.to_dict)
