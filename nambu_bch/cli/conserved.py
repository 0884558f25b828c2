"""``nambu-bch conserved``: exact conserved quantities H_c, G_c of an integrator (Table (table))."""

from __future__ import annotations

from ._options import (add_subcommand, integrator_from_args, integrator_options, output_options, progress_option,
                       symbolic_system, system_options)
from ._output import emit

HELP = "exact conserved quantities H_c, G_c of the integrator (Table (table))"
EXAMPLES = "examples:\n  nambu-bch conserved --integrator 31213   # a row of Table (table)\n  nambu-bch conserved --format json"


def register(sub) -> None:
    p = add_subcommand(sub, "conserved", HELP, EXAMPLES, run)
    progress_option(p)
    system_options(p)
    integrator_options(p)
    p.add_argument("--degree", metavar="D", type=str,
                   help="total degree of the polynomial ansatz for invariants (default: that of the Hamiltonians)")
    output_options(p, "latex")


def run(args):
    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    from ..exact import conserved_quantities  # once the flags are read: bad input is refused without it

    result = conserved_quantities(system, comp, **({"degree": args.degree} if args.degree is not None else {}))

    emit(args, latex=result.to_latex, text=result.to_text, data=result.to_dict, system=system)

