"""``nambu-bch check``: iterate the integrator and report the conservation diagnostics (:func:`nambu_bch.numeric.check`)."""

from __future__ import annotations

from ._options import (add_subcommand, integrator_from_args, integrator_options, number, numeric_inputs, numeric_options,
                       output_options, progress_option, runge_kutta_options, system_from_args, system_options)
from ._output import emit

HELP = "iterate the integrator and report the conservation diagnostics"
EXAMPLES = ("examples:\n  nambu-bch check --integrator 32123 --h 0.1 --steps 100000 --x0 1,1,1\n"
            "  nambu-bch check --model rigid-body --param I1=1 --param I2=2 --param I3=3 --format json\n"
            "  nambu-bch check --model rigid-body --integrator midpoint --h 0.1 --steps 2000   # Newton, compiled")


def register(sub) -> None:
    p = add_subcommand(sub, "check", HELP, EXAMPLES, run)
    progress_option(p)
    system_options(p)
    integrator_options(p, order=True)
    runge_kutta_options(p)
    numeric_options(p, {"h": 0.1, "steps": 1000, "every": 1})
    p.add_argument("--alpha", metavar="A", help="value of the family parameter alpha in H_S, G_S (default 1/2)")
    output_options(p, "text", choices=("text", "json"))


def run(args):
    from ..checks import finite_float
    from ..numeric.diagnostics import check

    system, values = system_from_args(args)
    word, comp = integrator_from_args(args, system, runge_kutta=True)
    params, x0 = numeric_inputs(args, system, values)
    order = args.order if args.order is not None else 2
    alpha = finite_float(number(args.alpha, "--alpha"), "--alpha") if args.alpha is not None else 0.5
    method = comp if args.tableau else word  # a tableau file's method is its tableau, not a name
    report = check(system, method, args.h, args.steps, x0, params=params, every=args.every, order=order, alpha=alpha)

    emit(args, text=lambda: str(report), data=report.to_dict, system=system)
