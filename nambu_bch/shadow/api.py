"""``shadow_hamiltonians``: the one entry point of the shadow package (both routes, one result type).

References
----------
Horikoshi, Sects. 4.2 and 5.2; Eqs. (L2), (SH12321c), (SG12321c).
"""

from __future__ import annotations

import sympy

from ..bch.backward import check_order
from ..errors import NambuBCHError
from ..integrators.composition import composition_for
from ..symbols import ALPHA
from .direct_route import direct_route
from .family import ShadowFamily
from .fi_route import fi_route

ROUTES = ("direct", "fi")
SOLVE_UNKNOWNS = 800  # default: above this many unknowns per order the exact solve is skipped and existence decided by averages


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


def _decide(fam, R, existence, params):
    """Set ``exists`` / ``drift`` / ``evidence`` of a family whose polynomial ansatz failed (issue 17)."""
    if not existence:
        fam.exists = None
        fam.evidence = {"outcome": "undecided", "order": fam.failed_order, "method": None,
                        "reason": "no polynomial pair; existence in smooth functions not decided (existence=False)"}
        return
    from .existence import decide

    dec = decide(R, params=params)
    fam.existence = dec
    fam.exists = dec.exists
    fam.drift = dec.drift_dict()
    fam.evidence = dec.evidence()


def shadow_hamiltonians(system, word, order: int = 2, route: str = "direct", degree=None, *,
                        existence: bool = True, params=None, max_unknowns: int | None = SOLVE_UNKNOWNS, progress=None) -> ShadowFamily:
    """Shadow Hamiltonians ``H_S, G_S`` of ``word`` on ``system`` through ``h^order``, as a family.

    Parameters
    ----------
    system : System or built-in model name
    word : composition spec (``"12321"``, ``"TVT"``, ``"lie-trotter"``, ...)
    order : int -- highest power of ``h`` kept in ``H_S, G_S``
    route : ``"direct"`` (order-by-order linear solve, any order) or ``"fi"``
        (affine hulls of the representations of the BCH commutators by the fundamental identity,
        through ``h^6``; :func:`~nambu_bch.shadow.fi_route.fi_route`)
    degree : int, optional -- ansatz degree of the corrections (default: from the field)
    existence : bool -- when no polynomial pair is found, decide existence in smooth functions by
        orbit averages (:mod:`nambu_bch.shadow.existence`); with False the answer stays undecided
    params : dict, optional -- parameter values for the orbit numerics (default: generic rationals)
    max_unknowns : int or None -- refuse the exact polynomial solve of an order with more unknowns (bounded work)
    progress : bool or None -- direct route: a progress bar over the orders; None: automatic
        (a terminal or Jupyter, shown once the run has lasted a second); False: never

    Returns
    -------
    ShadowFamily -- ``exists`` is True when a pair exists (``polynomial`` says whether the one found is),
    False only when non-existence is certified (non-zero orbit average, ``drift``), None when undecided.

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
    if not isinstance(existence, bool):
        raise NambuBCHError(f"existence must be True or False, got {existence!r}")
    if route not in ROUTES:
        raise NambuBCHError(f"route must be one of {', '.join(ROUTES)}, got {route!r}")
    order = check_order(order)
    if route == "fi" and getattr(system, "bracket", "nambu") in ("canonical", "triplets") and system.N > 2:
        raise NambuBCHError(
            f"the FI route needs the Nambu bracket (N - 1 Hamiltonians, the fundamental identity); {system.name} has the "
            f"{system.bracket} bracket on N = {system.N}: use route='direct'")
    comp = composition_for(word, system.splitting)
    notes = []
    if route == "direct":
        R = direct_route(system, comp, order, degree, max_unknowns, progress=progress)
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
            fam.polynomial = True
        else:
            bad = R.orders[-1]
            fam.failed_order = bad.order
            fam.polynomial = False
            if bad.status == "obstructed":
                fam.certificate = bad.certificate
                fam.obstruction = _obstruction_text(bad, len(system.hamiltonians))
            else:
                fam.obstruction = (f"at h^{bad.order} the polynomial ansatz of degree <= {bad.degree} has more than "
                                   f"max_unknowns={max_unknowns} unknowns: the exact solve was refused up front")
            _decide(fam, R, existence, params)
    else:
        power = 2 if comp.symmetric else 1
        fam = ShadowFamily(system, comp, order, route, True)
        if order < power:
            fam.shadows = tuple(sympy.expand(Hk) for Hk in system.hamiltonians)
            notes.append("h^1: the correction vanishes (symmetric word)")
        else:
            R = fi_route(system, comp, order, degree)
            fam.details = R
            fam.exists = R.exists
            fam.degree[power] = R.degree
            if R.certificate is not None:
                fam.failed_order = power
                fam.certificate = R.certificate
                fam.obstruction = (f"at h^{power} no affine combination of the FI representations equals "
                                   f"X_{{H,dG}} + X_{{dH,G}} with corrections of degree <= {R.degree}")
            else:
                fam.corrections[power] = R.corrections
                fam.gauge[power] = R.kernel_corrections()
                for o in R.orders:
                    if o.status == "vanishes":
                        why = " (odd order of a symmetric word)" if comp.symmetric and o.order % 2 else ""
                        notes.append(f"h^{o.order}: the correction vanishes{why}")
                        continue
                    fam.degree[o.order] = o.degree
                    if o.status == "solved":
                        fam.corrections[o.order] = o.corrections
                        fam.gauge[o.order] = list(o.kernel)
                    else:
                        fam.failed_order = o.order
                        fam.certificate = o.certificate
                        fam.obstruction = (f"at h^{o.order} no affine combination of the FI representations equals "
                                           f"X_{{H,dG}} + X_{{dH,G}} + (cross terms) with corrections of degree <= {o.degree}")
            if R.exists:
                fam.shadows = R.shadow()
                fam.polynomial = True
            else:
                # the FI ansatz failing is no certificate: the direct route and the orbit averages decide
                fam.polynomial = False
                if not existence:
                    _decide(fam, None, existence, params)
                else:
                    D = direct_route(system, comp, order, None, max_unknowns)
                    if D.exists:
                        fam.exists, fam.polynomial, fam.shadows = True, True, D.shadow()
                        notes.append("the FI ansatz failed; the shadows are the direct route's polynomial pair")
                    else:
                        _decide(fam, D, existence, params)
    fam.notes = notes
    if fam.exists and any(S.has(ALPHA) for S in fam.shadows):
        fam.free_parameters = ["alpha"]
    return fam
