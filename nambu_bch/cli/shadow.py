"""``nambu-bch shadow``: the shadow-Hamiltonian family of a word at an order, or the obstruction (Eq. Xeff2)."""

from __future__ import annotations

from ._options import (add_subcommand, integrator_from_args, integrator_options, output_options, progress_option,
                       runge_kutta_options, shown, symbolic_system, system_options)
from ._output import emit

HELP = "the shadow-Hamiltonian family of a word at an order, or the obstruction"
EXAMPLES = ("examples:\n  nambu-bch shadow                       # alpha-family of Phi^{12321}, ho3, order 2 (Eqs. SH12321c, SG12321c)\n"
            "  nambu-bch shadow --integrator 32123 --format json\n"
            "  nambu-bch shadow --model ho --integrator TVT --order 4\n"
            "  nambu-bch shadow --H 'x2^2/(2*m) + m*x3/2' --G 'x3 - x1^2' --param m --route fi\n"
            "  nambu-bch shadow --generic-separable --integrator 212 --order 4   # |p|^2/2 + V(q), V undefined\n"
            "  nambu-bch shadow --model rigid-body --integrator gauss4 --order 4   # Runge-Kutta: its modified field\n"
            "  nambu-bch shadow --model rigid-body --integrator kahan --density    # standard vs density bracket")


def register(sub) -> None:
    p = add_subcommand(sub, "shadow", HELP, EXAMPLES, run)
    progress_option(p)
    system_options(p)
    integrator_options(p, order=True)
    # Runge-Kutta and Kahan methods (the direct route on the modified field)
    runge_kutta_options(p)
    p.add_argument("--density", action="store_true",
                   help="with a method that keeps a modified measure dx/phi (Kahan's method on an Euler top such as "
                        "rigid-body): ask the question in the standard bracket and in {f,g,k}_rho = rho d(f,g,k)/dx "
                        "with rho = phi, and report which admits a pair (the certificate for the other)")
    p.add_argument("--route", choices=("direct", "fi"), default="direct",
                   help="direct: order-by-order linear solve; fi: fundamental-identity representations (default direct)")
    p.add_argument("--degree", metavar="D", type=str, help="polynomial degree of the ansatz for H_S, G_S (default: the library's)")
    p.add_argument("--no-existence", dest="existence", action="store_false",
                   help="when no polynomial pair is found, do not decide existence by orbit averages (answer: undecided)")
    generic_separable_options(p)
    output_options(p, "latex")


# the generic answer for H = |p|^2/2 + V(q): no system, only the word, the order and optionally d
def generic_separable_options(p) -> None:
    p.add_argument("--generic-separable", action="store_true",
                   help="the generic H_S for H = |p|^2/2 + V(q), V undefined, q in R^d, in tensor form "
                        "(V''(p,p), grad V.grad V, ...); piece 1 = T, piece 2 = V; takes no system options")
    p.add_argument("--dim", metavar="D", type=str, help="with --generic-separable: the dimension d shown (default: any d)")


def run_generic_separable(args) -> None:
    from ..errors import NambuBCHError
    from ..shadow.generic_separable import separable_shadow
    from ._options import positive_int

    system_flags = (("--model", "model"), ("--system", "system"), ("--H", "H"), ("--G", "G"), ("--param", "param"),
                    ("--degree", "degree"))
    given = [flag for flag, key in system_flags if getattr(args, key, None) is not None]
    given += ["--route fi"] if args.route != "direct" else []
    given += ["--density"] if args.density else []
    if given:
        raise NambuBCHError(f"--generic-separable is for H = |p|^2/2 + V(q) with V undefined and takes no {given[0]}")
    d = positive_int(args.dim, "--dim", 64) if args.dim is not None else None
    result = separable_shadow(args.integrator or "212", args.order if args.order is not None else 2, d)
    emit(args, latex=result.to_latex, text=result.to_text, data=result.to_dict)


def run_density(args, system, method, order) -> None:
    """``--density``: the shadow question in the standard and in the density bracket (:func:`density_brackets`)."""
    from ..errors import NambuBCHError
    from ..integrators.runge_kutta import TABLEAUX
    from ..shadow import density_brackets

    if method != TABLEAUX["kahan"]:  # the one method whose invariant density is known in closed form here
        raise NambuBCHError(f"--density takes --integrator kahan (its invariant measure dx/phi on an Euler top is "
                            f"known in closed form); got {shown(args.integrator or getattr(method, 'name', ''))}")
    if args.route != "direct":
        raise NambuBCHError("--density runs the direct route; --route fi reads a composition's BCH commutators")
    kwargs = {"degree": args.degree} if args.degree is not None else {}
    result = density_brackets(system, method, order, **kwargs)
    emit(args, latex=result.to_latex, text=result.to_text, data=result.to_dict, system=system)


def run(args):
    if args.generic_separable:
        return run_generic_separable(args)
    if args.dim is not None:
        from ..errors import NambuBCHError

        raise NambuBCHError("--dim is used with --generic-separable only")

    system = symbolic_system(args)
    word, comp = integrator_from_args(args, system, runge_kutta=True)
    order = args.order if args.order is not None else 2
    if args.density:
        return run_density(args, system, comp, order)
    kwargs = {"order": order, "route": args.route, "existence": args.existence}
    if args.degree is not None:
        kwargs["degree"] = args.degree
    from ..shadow import shadow_hamiltonians  # once the flags are read: bad input is refused without it

    family = shadow_hamiltonians(system, comp, **kwargs)

    def text():
        out = f"{word} on {system.name}, order {order}, route {args.route}\n" + family.to_text()
        if args.route == "fi" and hasattr(family.details, "to_text"):
            out += "\n" + family.details.to_text()  # each commutator's representations and weights
        return out

    emit(args, latex=family.to_latex, text=text, data=family.to_dict, system=system)

