"""``nambu-bch exact``: exact shadow Hamiltonians F^alpha H_c, F^(1-alpha) G_c (Eq. Xeff2), optionally as series in h."""

from __future__ import annotations

from ._options import add_subcommand, integrator_from_args, integrator_options, output_options, symbolic_system, system_options
from ._output import emit

HELP = "exact shadow Hamiltonians F^alpha H_c, F^(1-alpha) G_c (Eq. Xeff2)"
EXAMPLES = ("examples:\n  nambu-bch exact                        # F(omega h)^alpha H_c, F^(1-alpha) G_c (Eqs. ESH12321, ESG12321)\n"
            "  nambu-bch exact --model ho --integrator TVT")


def register(sub) -> None:
    p = add_subcommand(sub, "exact", HELP, EXAMPLES, run)
    system_options(p)
    integrator_options(p)
    p.add_argument("--order", metavar="K", type=str,
                   help="also expand H_S^e, G_S^e through h^K (Eqs. ESH12321, ESG12321)")
    output_options(p, "latex")


def run(args):
    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    from ..exact import exact_shadow_hamiltonians  # once the flags are read: bad input is refused without it

    result = exact_shadow_hamiltonians(system, comp)

    def data():
        return result.to_dict(order=args.order)

    def latex():
        return result.to_latex(order=args.order)

    emit(args, latex=latex, text=lambda: result.to_text(order=args.order), data=data, system=system)

