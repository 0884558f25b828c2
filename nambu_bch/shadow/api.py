"""``shadow_hamiltonians``: the one entry point of the shadow package (both routes, one result type).

References
----------
Horikoshi, Sects. 4.2 and 5.2; Eqs. (L2), (SH12321c), (SG12321c).
"""

from __future__ import annotations

import sympy

from ..bch.backward import check_order
from ..errors import InvalidOrderError, NambuBCHError
from ..integrators.composition import composition as make_composition
from .direct_route import ALPHA, direct_route
from .family import ShadowFamily
from .fi_route import fi_route

ROUTES = ("direct", "fi")


def _system(system):
    if isinstance(system, str):
        from ..systems import model

        return model(system)
    if not hasattr(system, "hamiltonians") or not hasattr(system, "splitting"):
        raise NambuBCHError(f"system must be a System or a built-in model name, got {system!r}")
    return system


def _operator(n_hams: int) -> str:
    if n_hams == 1:
        return "X_{dH}"
    if n_hams == 2:
        return "X_{dH,G} + X_{H,dG}"
    return "sum_a X_{H_1..dH_a..H_" + str(n_hams) + "}"


def _obstruction_text(sol, n_hams: int = 2) -> str:
    terms = sorted(sol.certificate.items(), key=lambda kv: (str(kv[0][0]), sympy.default_sort_key(kv[0][1])))
    shown = " + ".join(f"({c})*[{mono}]Y^{x}" for (x, mono), c in terms[:6])
    more = f" + ... ({len(terms)} terms)" if len(terms) > 6 else ""
    return (
        f"at h^{sol.order} no polynomial corrections of degree <= {sol.degree} solve "
        f"{_operator(n_hams)} = Z_{sol.order} - (cross terms): the functional l(Y) = {shown}{more} "
        f"vanishes on every such field but l(RHS) = {sol.obstruction_value}"
    )


def shadow_hamiltonians(system, word, order: int = 2, route: str = "direct", degree=None) -> ShadowFamily:
    """Shadow Hamiltonians ``H_S, G_S`` of ``word`` on ``system`` through ``h^order``, as a family.

    Parameters
    ----------
    system : System or built-in model name
    word : composition spec (``"12321"``, ``"TVT"``, ``"lie-trotter"``, ...)
    order : int -- highest power of ``h`` kept in ``H_S, G_S``
    route : ``"direct"`` (order-by-order linear solve, any order) or ``"fi"``
        (representations of the BCH commutators by the fundamental identity; lowest correction only)
    degree : int, optional -- ansatz degree of the corrections (default: from the field)

    Returns
    -------
    ShadowFamily

    Examples
    --------
    >>> from nambu_bch import model
    >>> F = shadow_hamiltonians(model("ho3"), "12321")          # Eqs. (SH12321c), (SG12321c)
    >>> sympy.expand(F.H_S - model("ho3").H)
    alpha*h**2*m*omega**4*x1**2/12 + alpha*h**2*omega**2*x2**2/(12*m)
    >>> F.free_parameters
    ['alpha']
    """
    system = _system(system)
    if route not in ROUTES:
        raise NambuBCHError(f"route must be one of {', '.join(ROUTES)}, got {route!r}")
    order = check_order(order)
    if route == "fi" and getattr(system, "bracket", "nambu") in ("canonical", "triplets") and system.N > 2:
        raise NambuBCHError(
            f"the FI route needs the Nambu bracket (N - 1 Hamiltonians, the fundamental identity); {system.name} has the "
            f"{system.bracket} bracket on N = {system.N}: use route='direct'")
    comp = make_composition(word, len(system.splitting)).check(system.splitting)
    notes = []
    if route == "direct":
        R = direct_route(system, comp, order, degree)
        fam = ShadowFamily(system, comp, order, route, R.exists, details=R)
        for o in R.orders:
            if o.status == "vanishes":
                why = " (odd order of a symmetric word)" if comp.symmetric and o.order % 2 else ""
                notes.append(f"h^{o.order}: the correction vanishes{why}")
            elif o.status == "solved":
                fam.gauge[o.order] = o.gauge
                fam.corrections[o.order] = o.corrections
                fam.degree[o.order] = o.degree
            else:
                fam.degree[o.order] = o.degree
        if R.exists:
            fam.shadows = R.shadow()
        else:
            bad = R.orders[-1]
            fam.failed_order = bad.order
            fam.certificate = bad.certificate
            fam.obstruction = _obstruction_text(bad, len(system.hamiltonians))
    else:
        power = 2 if comp.symmetric else 1
        if order > power + (1 if comp.symmetric else 0):
            raise InvalidOrderError(
                f"the FI route solves the lowest correction only (h^{power} for {comp.name!r}); "
                f"got order={order}, use route='direct' for higher orders"
            )
        fam = ShadowFamily(system, comp, order, route, True)
        if order < power:
            fam.shadows = tuple(sympy.expand(Hk) for Hk in system.hamiltonians)
            notes.append(f"h^1: the correction vanishes (symmetric word)")
        else:
            R = fi_route(system, comp, power, degree)
            fam.details = R
            fam.exists = R.exists
            fam.degree[power] = R.degree
            if R.exists:
                fam.shadows = R.shadow()
                fam.corrections[power] = R.corrections
                fam.gauge[power] = R.kernel_corrections()
                if order > power:
                    notes.append(f"h^{order}: the correction vanishes (odd order of a symmetric word)")
            else:
                fam.failed_order = power
                fam.certificate = R.certificate
                fam.obstruction = (f"at h^{power} no affine combination of the FI representations equals "
                                   f"X_{{H,dG}} + X_{{dH,G}} with corrections of degree <= {R.degree}")
    fam.notes = notes
    if fam.exists and any(S.has(ALPHA) for S in fam.shadows):
        fam.free_parameters = ["alpha"]
    return fam
