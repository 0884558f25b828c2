"""``shadow_hamiltonians``: the one entry point of the shadow package (both routes, one result type).

References
----------
Horikoshi, Sects. 4.2 and 5.2; Eqs. (L2), (SH12321c), (SG12321c).
"""

from __future__ import annotations

import sympy

from ..bch.backward import check_order
from ..checks import check_flag
from ..errors import NambuBCHError
from ..integrators.composition import composition_for
from ..integrators.runge_kutta import runge_kutta_method
from .direct_route import direct_route
from .family import ShadowFamily
from .fi_route import fi_route

ROUTES = ("direct", "fi")
#: Default ``max_unknowns``: above this many unknowns per order, or above the elimination cost budget
#: ``direct_route.SOLVE_COST`` (estimated from the block structure of the matrix), the exact solve is skipped and
#: existence decided by averages.  The bound is the direct route's own up-front limit
#: (``direct_route.MAX_UNKNOWNS``); below it the estimate from the built matrix decides --
#: its cost budget refuses what would hang, and the blocks it counts are the dense matrices the elimination
#: holds (at most ``elimination.FLINT_DENSE_LIMIT`` entries each).  The N = 4 single split at h^8 (3003 unknowns,
#: estimate 1.2e9, largest block 1140 x 792) is solved within 200 MB of peak RSS.
SOLVE_UNKNOWNS = 4000


def _system(system):
    from ..systems.spec import as_system

    return as_system(system)


def _decision(result, existence: bool, params):
    """The existence decision (orbit averages, docs/existence.md) of a direct result without a polynomial pair; None if not asked."""
    if not existence or result is None or result.exists:
        return None
    from .existence import decide

    return decide(result, params=params)


def shadow_hamiltonians(system, word, order: int = 2, route: str = "direct", degree=None, *,
                        existence: bool = True, params=None, max_unknowns: int | None = SOLVE_UNKNOWNS, progress=None) -> ShadowFamily:
    """Shadow Hamiltonians ``H_S, G_S`` of ``word`` on ``system`` through ``h^order``, as a family.

    Parameters
    ----------
    system : System or built-in model name
    word : composition spec (``"12321"``, ``"TVT"``, ``"lie-trotter"``, ...), or a Runge--Kutta method: a name of
        :data:`~nambu_bch.integrators.runge_kutta.TABLEAUX` (``"midpoint"``, ``"gauss4"``, ``"kahan"`` ...) or a
        :class:`~nambu_bch.integrators.runge_kutta.ButcherTableau`; the direct route then runs on the method's
        modified field (:func:`~nambu_bch.bseries.runge_kutta_shadow`, HLW Sect. IX.9), and the family's
        ``composition`` is the tableau
    order : int -- highest power of ``h`` kept in ``H_S, G_S``
    route : ``"direct"`` (order-by-order linear solve, any order) or ``"fi"``
        (affine hulls of the representations of the BCH commutators by the fundamental identity,
        through ``h^6``; :func:`~nambu_bch.shadow.fi_route.fi_route`)
    degree : int, optional -- ansatz degree of the corrections (default: from the field)
    existence : bool -- when no polynomial pair is found, decide existence in smooth functions by
        orbit averages (:mod:`nambu_bch.shadow.existence`); with False the answer stays undecided
    params : dict, optional -- parameter values for the orbit numerics (default: generic rationals)
    max_unknowns : int or None -- refuse the exact polynomial solve of an order with more unknowns, or with an
        elimination estimated above ``direct_route.SOLVE_COST`` (bounded work); None: no such limit
    progress : bool or None -- direct route: a progress bar over the orders; None: automatic
        (a terminal or Jupyter, shown once the run has lasted a second); False: never

    Returns
    -------
    ShadowFamily -- ``exists`` is True when a pair exists (``polynomial`` says whether the one found is),
    False only when non-existence is certified (non-zero orbit average, ``drift``), None when undecided.

    Examples
    --------
    >>> import sympy
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
    if not isinstance(route, str) or route not in ROUTES:
        raise NambuBCHError(f"route must be one of {', '.join(ROUTES)}, got {route!r}")
    order = check_order(order)
    check_flag(progress, "progress", none=True)
    if route == "fi" and getattr(system, "bracket", "nambu") in ("canonical", "triplets") and system.N > 2:
        raise NambuBCHError(
            f"the FI route needs the Nambu bracket (N - 1 Hamiltonians, the fundamental identity); {system.name} has the "
            f"{system.bracket} bracket on N = {system.N}: use route='direct'")
    tableau = runge_kutta_method(word)
    if tableau is not None:
        return _runge_kutta_family(system, tableau, order, route, degree, existence, params, max_unknowns)
    comp = composition_for(word, system.splitting)
    if comp.is_complex:
        _complex_supported(system, comp)
    if route == "direct":
        R = direct_route(system, comp, order, degree, max_unknowns, progress=progress)
        return ShadowFamily.from_direct(system, comp, order, R, _decision(R, existence, params), max_unknowns=max_unknowns)
    if order < (2 if comp.symmetric else 1):
        return ShadowFamily.unperturbed(system, comp, order)
    R = fi_route(system, comp, order, degree)
    # the FI ansatz failing is no certificate: the direct route and the orbit averages decide
    D = direct_route(system, comp, order, None, max_unknowns) if existence and not R.exists else None
    return ShadowFamily.from_fi(system, comp, order, R, _decision(D, existence, params), direct=D)


def _complex_supported(system, comp) -> None:
    """Complex coefficients reach the routes over ``QQ(i)(parameters)[x]``: polynomial Hamiltonians only.

    The non-polynomial routes (the extended ring of exp/trig/radical atoms, the generic BCH series on the pieces'
    Hamiltonians) keep rational scalars, so they are refused here in one line rather than failing inside.
    """
    alg = system.algebra
    bad = next((H for H in system.hamiltonians if not alg.is_polynomial(alg.convert(H))), None)
    if bad is not None:
        raise NambuBCHError(
            f"composition {comp.name[:60]!r} has complex coefficients; its shadow Hamiltonians are computed over "
            f"QQ(i) for polynomial Hamiltonians only, and {system.name} has {bad} (effective_field accepts it)")


def _runge_kutta_family(system, tableau, order, route, degree, existence, params, max_unknowns) -> ShadowFamily:
    """The family of a Runge--Kutta method: the direct route on its modified field (the same solver and decision)."""
    from ..bseries import runge_kutta_shadow

    if route != "direct":
        raise NambuBCHError(f"the FI route reads a composition's BCH commutators; the Runge-Kutta method {tableau.name} "
                            "has none: use route='direct'")
    R = runge_kutta_shadow(system, tableau, order, degree=degree, max_unknowns=max_unknowns)
    decision = _divergence_decision(system, R) if existence and not R.exists else None
    if decision is None:
        decision = _decision(R, existence, params)
    return ShadowFamily.from_direct(system, tableau, order, R, decision, max_unknowns=max_unknowns)


def _divergence_decision(system, result):
    """Certified non-existence when the modified field at the failed order has non-zero divergence, else None.

    Every ``X_{H_S,G_S}`` of the package's brackets is divergence-free (Liouville), and so are the cross terms of the
    lower, solved orders; a Runge--Kutta field need not be (implicit midpoint on the rigid body at ``h^2``,
    docs/runge_kutta.md).  The orbit averages of :mod:`~nambu_bch.shadow.existence` see only the drift of ``H, G``,
    which a method keeping quadratic invariants does not have, so this test comes first.
    """
    from .existence import Existence

    j = result.orders[-1].order
    Z = result.effective[j]
    div = Z.divergence()
    if Z.algebra.is_zero(div):
        return None
    shown = sympy.factor(Z.algebra.to_sympy(div))
    reason = (f"at h^{j} the modified field has divergence {shown} != 0, while every X_{{H_S,G_S}} (and every cross "
              "term of the solved orders) is divergence-free: no pair, polynomial or not")
    return Existence("none", False, j, method="divergence", reason=reason)
