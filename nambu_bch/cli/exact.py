"""``nambu-bch exact``: exact shadow Hamiltonians F^alpha H_c, F^(1-alpha) G_c (Eq. Xeff2), optionally as series in h."""

from __future__ import annotations

from ._options import add_subcommand, integrator_from_args, integrator_options, output_options, symbolic_system, system_options
from ._output import base_dict, emit

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
    from .. import render
    from ..exact import exact_shadow_hamiltonians

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system)
    result = exact_shadow_hamiltonians(system, comp)
    series = result.series(args.order) if args.order is not None else None

    def data():
        out = base_dict(system, word)
        out.update(result.to_dict())
        out["model"], out["integrator"] = system.name, word
        if series is not None:
            out.update(order=args.order, H_S_series=render.expression(series[0]), G_S_series=render.expression(series[1]))
            out.update({k: v for k, v in result.to_dict(order=args.order).items() if k in ("series", "remainder_power")})
        return out

    def latex():
        return result.to_latex(order=args.order)

    emit(args, latex=latex, text=lambda: result.to_text(order=args.order), data=data, system=system)

