"""``nambu-bch check``: iterate the integrator and report the conservation diagnostics (:func:`nambu_bch.numeric.check`)."""

from __future__ import annotations

from ._options import (add_subcommand, integrator_from_args, integrator_options, number, numeric_inputs, numeric_options,
                       output_options, progress_option, runge_kutta_options, system_from_args, system_options)
from ._output import emit

HELP = "iterate the integrator and report the conservation diagnostics"
EXAMPLES = ("examples:\n  nambu-bch check --integrator 32123 --h 0.1 --steps 100000 --x0 1,1,1\n"
            "  nambu-bch check --model rigid-body --param I1=1 --param I2=2 --param I3=3 --format json\n"
            "  nambu-bch check --model henon-heiles --integrator 212 --x0 0.1,-0.2,0.3,0.25 --numerical-shadow 6\n"
            "  nambu-bch check --model rigid-body --integrator midpoint --h 0.1 --steps 2000   # Newton, compiled\n"
            "  nambu-bch check --model henon-heiles --integrator chin-4a --x0 0.1,-0.2,0.3,0.25 --h 0.2 --steps 50\n"
            "      # force-gradient (or takahashi-imada, processed): drift of H and H_S at h, h/2, h/4 and the slopes")


def register(sub) -> None:
    p = add_subcommand(sub, "check", HELP, EXAMPLES, run)
    progress_option(p)
    system_options(p)
    integrator_options(p, order=True)
    runge_kutta_options(p)
    numeric_options(p, {"h": 0.1, "steps": 1000, "every": 1})
    p.add_argument("--alpha", metavar="A", help="value of the family parameter alpha in H_S, G_S (default 1/2)")
    p.add_argument("--numerical-shadow", metavar="2K", dest="numerical_shadow",
                   help="also the Skeel-Hardy numerical shadow Hamiltonian of order 2K (2, 4, 6 or 8) along the run, "
                        "from the trajectory alone (canonical systems; every step sampled)")
    output_options(p, "text", choices=("text", "json"))


def run(args):
    from ..checks import finite_float

    system, values = system_from_args(args)
    if _gradient_method(args):
        _gradient_check(args, system, values)
        return
    word, comp = integrator_from_args(args, system, runge_kutta=True)
    params, x0 = numeric_inputs(args, system, values)
    order = args.order if args.order is not None else 2
    alpha = finite_float(number(args.alpha, "--alpha"), "--alpha") if args.alpha is not None else 0.5
    method = comp if args.tableau else word  # a tableau file's method is its tableau, not a name
    shadow_order = _numerical_shadow_order(args, system)
    from ..numeric.diagnostics import check  # once the flags are read: bad input is refused without it

    report = check(system, method, args.h, args.steps, x0, params=params, every=args.every, order=order, alpha=alpha)
    if shadow_order is None:
        emit(args, text=lambda: str(report), data=report.to_dict, system=system)
        return
    shadow = _numerical_shadow(system, word, args.h, args.steps, x0, params, shadow_order)
    emit(args, text=lambda: f"{report}\n{shadow}", data=lambda: {**report.to_dict(), "numerical_shadow": shadow.to_dict()},
         system=system)


def _numerical_shadow_order(args, system):
    """``--numerical-shadow`` as one of 2, 4, 6, 8, refused up front where the run could not give it."""
    from ..errors import NambuBCHError
    from ..numeric.skeel_hardy import ORDERS

    text = args.numerical_shadow
    if text is None:
        return None
    accepted = ", ".join(map(str, ORDERS))
    if text.strip() not in {str(k) for k in ORDERS}:
        raise NambuBCHError(f"--numerical-shadow {text[:40]!r} must be one of {accepted}")
    if system.bracket != "canonical":
        raise NambuBCHError(f"--numerical-shadow needs a canonical system (q, p halves); {system.name} has the "
                            f"{system.bracket} bracket (the Skeel-Hardy construction uses the symplectic form)")
    if args.every != 1:
        raise NambuBCHError(f"--numerical-shadow needs every step of the run; --every {args.every} skips steps")
    order = int(text)
    if args.steps < order + 2:  # 2k + 1 samples per value and three values for the drift fit
        raise NambuBCHError(f"--numerical-shadow {order} needs at least {order + 2} steps, got --steps {args.steps}")
    return order


def _numerical_shadow(system, word, h, steps, x0, params, order):
    """The Skeel-Hardy shadow Hamiltonian along the same run (:func:`nambu_bch.numeric.numerical_shadow`)."""
    from ..numeric import iterate, numerical_shadow

    x = iterate(system, word, h, steps, x0, params=params)
    d = system.N // 2
    return numerical_shadow(x[:, :d], x[:, d:], system, h, order=order, word=word, params=params)


def _gradient_method(args) -> bool:
    from ..numeric.force_gradient import is_gradient_method

    return args.integrator is not None and is_gradient_method(args.integrator)


def _gradient_check(args, system, values):
    """A force-gradient composition or a processed kernel (``chin-4a``, ``takahashi-imada``): the drift of ``H`` and of
    the truncated shadow Hamiltonian at ``h``, ``h/2``, ``h/4`` over the same time, with their slopes
    (:func:`nambu_bch.numeric.gradient_check`)."""
    from ..errors import NambuBCHError
    from ..numeric.gradient_check import gradient_check

    for flag, name in ((args.numerical_shadow, "--numerical-shadow"), (args.alpha, "--alpha"),
                       (getattr(args, "tableau", None), "--tableau"), (args.order, "--order")):
        if flag is not None:
            raise NambuBCHError(f"{name} does not apply to --integrator {args.integrator}: its check measures the drift "
                                f"of H and of its own shadow Hamiltonian at h, h/2, h/4")
    if args.every != 1:
        raise NambuBCHError(f"--every does not apply to --integrator {args.integrator}: every step is measured")
    params, x0 = numeric_inputs(args, system, values)
    report = gradient_check(system, args.integrator, args.h, args.steps, x0, params)
    emit(args, text=lambda: str(report), data=report.to_dict, system=system)
