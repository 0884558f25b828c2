"""The shadow question in the Nambu bracket with a density: ``{f, g, k}_rho = rho d(f, g, k)/d(x1, x2, x3)``.

A Nambu field of that bracket is ``X^rho_{H,G} = rho X_{H,G}`` (``X^i = rho {x_i, H, G}``).  Since
``div(X_{H,G}) = 0``, it keeps the measure ``dx / rho``, not ``dx``.  A method that keeps a modified measure
``dx / phi`` -- Kahan's method on quadratic fields (Celledoni--McLachlan--Owren--Quispel 2013) -- has a modified
field ``f~`` with ``div(f~ / phi) = 0`` at every order, and cannot be a standard ``X_{H_S,G_S}`` when ``f~`` itself
has a divergence; the question is then whether

    f~ = rho X_{H_S, G_S} + O(h^{order+1}),   rho = phi (the density of the bracket is the *inverse* of the
                                                      measure's: dx / phi is kept iff rho = phi)

order by order.  Dividing by ``rho`` turns it into the standard question for the field ``f~ / rho``: with
``rho = 1 + O(h)`` a polynomial in ``x`` and ``h``, ``1/rho = sum_k (1 - rho)^k`` is a power series in ``h``
with polynomial coefficients, and ``[h^j](f~ / rho)`` is polynomial; the direct route
(:func:`~nambu_bch.shadow.direct_route.direct_route`, its ``effective=`` argument) answers the question with its
family and, where there is none, its certificate.  Any other density ``rho F(H_S, G_S)`` gives the same answer
(``F(H_S, G_S) X_{H_S,G_S}`` is again a Nambu field ``X_{Psi, G_S}`` with ``d Psi / d H_S = F``), so fixing
``rho`` to the invariant measure's ``phi`` loses nothing up to that gauge.

References
----------
E. Celledoni, R. I. McLachlan, B. Owren, G. R. W. Quispel, *Geometric properties of Kahan's method*,
J. Phys. A 46 (2013) 025201 (modified measures); Horikoshi, Eq. (L2) (the direct route); Hairer, Lubich,
Wanner, *Geometric Numerical Integration*, Sect. IX.9 (modified equations of B-series methods).
"""

from __future__ import annotations

import sympy

from ..algebra import VectorField, liouville_field
from ..errors import NambuBCHError

H = sympy.Symbol("h")


def _density_in(algebra, density, name: str):
    """``density`` as an element of ``algebra`` (a polynomial in the coordinates and ``h``, equal to 1 at ``h = 0``)."""
    value = algebra.convert(density)
    if not algebra.is_polynomial(value):
        raise NambuBCHError(f"the density must be a polynomial in {', '.join(map(str, algebra.coordinates))} and h "
                            f"over the parameters of {name}, got {sympy.sstr(value)[:80]}")
    k = algebra.n + algebra.constants.index(H)
    at_zero = algebra.ring.from_dict({m: c for m, c in value.items() if m[k] == 0}) if value else value
    if at_zero != algebra.ring.one:
        raise NambuBCHError(f"the density must be 1 at h = 0 (the bracket is the standard one there), got "
                            f"{sympy.sstr(algebra.to_sympy(value))[:80]}")
    return value


def density_field(algebra, hamiltonian, casimir, density) -> VectorField:
    """``rho X_{H,G}``: the Nambu field of ``H, G`` in the bracket ``{f, g, k}_rho = rho d(f, g, k)/d(x)``."""
    X = liouville_field(algebra, algebra.convert(hamiltonian), algebra.convert(casimir))
    rho = algebra.convert(density)
    return VectorField(algebra, [rho * c for c in X.components])


def divided_by_density(effective, density, order: int, name: str = "the system") -> tuple:
    """``[h^j](f~ / rho)`` for ``j = 0 .. order``: the field whose standard shadow question is the density one.

    ``effective[j]`` are the coefficients ``Z_j`` of ``f~ = sum_j h^j Z_j`` (VectorFields on an algebra with the
    constant ``h``); ``1/rho = sum_k (1 - rho)^k`` truncated after ``h^order`` (``1 - rho = O(h)``).
    """
    alg = effective[0].algebra
    if H not in alg.constants:
        raise NambuBCHError("the modified field's algebra has no constant h")
    rho = _density_in(alg, density, name)
    k = alg.n + alg.constants.index(H)

    def cut(p):
        return alg.ring.from_dict({m: c for m, c in p.items() if m[k] <= order}) if p else p

    r = alg.ring.one - rho
    inverse, term = alg.ring.one, alg.ring.one
    for _ in range(order):  # (1 - rho)^k = O(h^k): order terms suffice
        term = cut(term * r)
        inverse = inverse + term
    series = [alg.zero] * (order + 1)  # [h^j] of 1/rho, coefficients free of h
    for m, c in inverse.items():
        if m[k] <= order:
            series[m[k]] = series[m[k]] + alg.ring.from_dict({m[:k] + (0,) + m[k + 1:]: c})
    out = []
    for j in range(order + 1):
        comps = [alg.zero] * alg.n
        for i in range(j + 1):
            if series[i]:
                comps = [c + series[i] * z for c, z in zip(comps, effective[j - i].components)]
        out.append(VectorField(alg, comps))
    return tuple(out)


def density_shadow(system, method, density, order: int = 2, degree=None, max_unknowns=None):
    """Whether the modified field of a Runge--Kutta method is ``rho X_{H_S, G_S}`` order by order.

    Parameters
    ----------
    system : System or model name (three coordinates, two Hamiltonians ``H, G``)
    method : a Runge--Kutta method (:func:`nambu_bch.bseries.modified_equation`'s names or a tableau)
    density : ``rho``, a polynomial in the coordinates and ``h`` (ring element, sympy expression or text in the
        system's symbols and ``h``) with ``rho = 1`` at ``h = 0``; for Kahan's method on the Euler top the
        invariant measure's ``phi`` (:func:`nambu_bch.bseries.kahan.euler_top_closed_forms`)
    order, degree, max_unknowns : as for :func:`~nambu_bch.shadow.direct_route.direct_route`

    Returns
    -------
    DirectResult -- of the direct route on ``f~ / rho``: ``.exists``, ``.shadow()`` (``H_S, G_S`` with
    ``f~ = rho X_{H_S,G_S} + O(h^{order+1})``), per order the solution or the certificate.

    Examples
    --------
    >>> from nambu_bch import model
    >>> R = density_shadow(model("ho3"), "midpoint", 1, 2)     # rho = 1: the standard question
    >>> R.exists
    True
    """
    from ..bseries.modified import modified_equation
    from ..systems.spec import as_system
    from .direct_route import direct_route

    system = as_system(system)
    if system.N != 3 or len(system.hamiltonians) != 2:
        raise NambuBCHError(f"the density bracket is the three-bracket {{f, g, k}}_rho on three coordinates; "
                            f"{system.name} has {system.N} coordinates and {len(system.hamiltonians)} Hamiltonians")
    M = modified_equation(system, method, order)
    fields = divided_by_density(M.coefficients, density, M.order, system.name)
    return direct_route(system, M.method, M.order, degree=degree, max_unknowns=max_unknowns, progress=False,
                        effective=fields)
