"""``nambu-bch sample``: hybrid Monte Carlo with the integrator, accepting with H or the shadow H_S
(:func:`nambu_bch.numeric.hybrid_monte_carlo`)."""

from __future__ import annotations

from ._options import (add_subcommand, integrator_from_args, integrator_options, number, numeric_inputs, order_value,
                       output_options, positive_int, system_from_args, system_options)
from ._output import emit

HELP = "sample exp(-H) by hybrid Monte Carlo with the integrator (or the shadow exp(-H_S), reweighted)"
EXAMPLES = ("examples:\n  nambu-bch sample --model ho --integrator 212 --h 0.5 --steps 2 --seed 1\n"
            "  nambu-bch sample --H 'q^4/4 + p^2/2 + r^2/2' --G 'r + q^2/2' --coords 'q p r' --integrator 12321 \\\n"
            "      --refresh p,r --flip p --target H_S --h 0.25 --steps 4 --observable 'q^2' --format json")
#: Upper limits of the counts on the command line (the API refuses larger work up front as well).
MAX_CHAINS, MAX_ITERATIONS = 10**6, 10**5


def register(sub) -> None:
    p = add_subcommand(sub, "sample", HELP, EXAMPLES, run)
    system_options(p)
    integrator_options(p, order=True)
    p.add_argument("--h", metavar="H", type=str, help="step size, e.g. 0.1 or 1/4 (default 0.1)")
    p.add_argument("--steps", metavar="L", type=str, help="steps per trajectory (default 10)")
    p.add_argument("--x0", metavar="X", help="initial state of every chain, comma separated (default: the model's, "
                                             "else 1,...,1)")
    p.add_argument("--refresh", metavar="NAMES", help="coordinates drawn anew each iteration, comma separated "
                                                     "(default: the momenta of a canonical system)")
    p.add_argument("--flip", metavar="NAMES", help="coordinates negated by the reversing involution (default: --refresh)")
    p.add_argument("--target", choices=("H", "H_S"), default="H", help="sample exp(-H), or exp(-H_S) reweighted "
                                                                         "(default H)")
    p.add_argument("--alpha", metavar="A", help="value of the family parameter in H_S (default 1/2)")
    p.add_argument("--chains", metavar="C", type=str, help="independent chains (default 1000)")
    p.add_argument("--iterations", metavar="I", type=str, help="kept iterations (default 50)")
    p.add_argument("--burn", metavar="B", type=str, help="iterations discarded first (default 10)")
    p.add_argument("--seed", metavar="S", type=str, help="seed of the random numbers (default: fresh entropy)")
    p.add_argument("--observable", metavar="EXPR", action="append",
                   help="an expression in the coordinates and parameters whose expectation under exp(-H) is "
                        "reported, e.g. 'q^2'; repeatable (default: the square of each coordinate)")
    output_options(p, "text", choices=("text", "json"))


def run(args):
    from ..checks import finite_float
    from ..errors import NambuBCHError

    for flag, value in (("--alpha", args.alpha), ("--order", args.order)):
        if value is not None and args.target != "H_S":
            raise NambuBCHError(f"{flag} sets the shadow Hamiltonian H_S; it applies only with --target H_S")
    system, values = system_from_args(args)
    word, comp = integrator_from_args(args, system)
    params, x0 = numeric_inputs(args, system, values)
    steps = args.steps if args.steps is not None else 10
    alpha = finite_float(number(args.alpha, "--alpha"), "--alpha") if args.alpha is not None else 0.5
    order = args.order if args.order is not None else 4
    chains = positive_int(args.chains, "--chains", MAX_CHAINS) if args.chains is not None else 1000
    iterations = positive_int(args.iterations, "--iterations", MAX_ITERATIONS) if args.iterations is not None else 50
    burn = order_value(args.burn, "--burn", MAX_ITERATIONS) if args.burn is not None else 10
    seed = order_value(args.seed, "--seed", 2**63 - 1) if args.seed is not None else None
    observables = _observables(args.observable, system, params)
    from ..numeric.hmc import hybrid_monte_carlo  # once the flags are read: bad input is refused without it

    result = hybrid_monte_carlo(system, comp, args.h, steps, refresh=_names(args.refresh), flip=_names(args.flip),
                                target=args.target, order=order, alpha=alpha, chains=chains, iterations=iterations,
                                burn=burn, x0=x0, params=params, seed=seed)
    estimates = {label: result.expectation(f) for label, f in observables}
    lines = [str(result)] + [f"  <{label}> = {e.value:.6g} +- {e.error:.2g}" for label, e in estimates.items()]
    emit(args, text=lambda: "\n".join(lines),
         data=lambda: {**result.to_dict(), "expectations": {k: {"value": e.value, "error": e.error}
                                                            for k, e in estimates.items()}},
         system=system)


def _names(text):
    """A comma-separated list of coordinate names (the API checks them against the system), or None."""
    return None if text is None else [part.strip() for part in text.split(",")]


def _observables(texts, system, params):
    """``[(label, f)]``: each expression parsed by the whitelist parser, parameters at their values, lambdified."""
    import sympy

    from ..integrators import parameter_values
    from ..parsing import parse_expression

    symbols = {str(s): s for s in (*system.coordinates, *system.parameters)}
    exprs = [(t, parse_expression(t, symbols, "--observable")) for t in texts] if texts else \
        [(f"{c}^2", c**2) for c in system.coordinates]
    given = {p: sympy.Float(v) for p, v in parameter_values(system, params).items()}
    out = []
    for label, expr in exprs:
        fn = sympy.lambdify(system.coordinates, expr.xreplace(given), modules="numpy")
        out.append((label, lambda x, fn=fn: fn(*x) + 0.0 * x[0]))  # a constant broadcast to the samples' shape
    return out
