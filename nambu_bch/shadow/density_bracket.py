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

from dataclasses import dataclass

import sympy

from ..algebra import VectorField, liouville_field
from ..errors import NambuBCHError
from ..printing import Printable
from ..values import ValueEquality

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


@dataclass(frozen=True, eq=False)
class DensityBrackets(Printable, ValueEquality):
    """The shadow question of one method in two Nambu brackets: the standard one and ``{f, g, k}_rho``.

    Attributes
    ----------
    system : System
    method : the method's tableau
    order : int
    density : sympy expression -- ``rho`` (for Kahan's method on an Euler top, the ``phi`` of its invariant measure
        ``dx / phi``)
    standard : ShadowFamily -- ``f~ = X_{H_S,G_S} + O(h^{order+1})``: the family, or the certificate
    weighted : ShadowFamily -- ``f~ = rho X_{H_S,G_S} + O(h^{order+1})``: the family, or the certificate
    """

    system: object
    method: object
    order: int
    density: object
    standard: object
    weighted: object

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the system, method, order, density and the two families."""
        return self.system, self.method, self.order, self.density, self.standard, self.weighted

    @property
    def admits(self) -> tuple:
        """The brackets with a pair through the order: a subset of ``("standard", "density")``."""
        return tuple(name for name, family in (("standard", self.standard), ("density", self.weighted))
                     if family.exists)

    def _headline(self) -> str:
        return ("a pair in " + " and ".join(f"the {name} bracket" for name in self.admits) if self.admits
                else "a pair in neither bracket")

    def to_text(self) -> str:
        """Both answers, the density, and which bracket admits a pair."""
        name = self.method.name
        return "\n".join([
            f"{name} on {self.system.name}, order {self.order}: {self._headline()}",
            f"density rho = {self.density}  ({{f, g, k}}_rho = rho d(f, g, k)/d(x); the method keeps dx/rho)",
            "standard bracket:", self.standard.to_text(),
            "density bracket (f~ = rho X_{H_S,G_S}):", self.weighted.to_text()])

    def to_latex(self) -> str:
        r"""The two families' ``aligned`` blocks under a ``gathered`` headline (display math, amsmath)."""
        from ..printing import latex_text

        return "\n".join([
            r"\begin{gathered}",
            latex_text(f"{self.method.name} on {self.system.name}: {self._headline()}") + r" \\",
            r"\text{standard bracket:} \\", self.standard.to_latex() + r" \\",
            r"\text{density bracket } \{f, g, k\}_{\rho} = \rho\, \partial(f, g, k)/\partial(x),\ \rho = "
            + sympy.latex(self.density) + r": \\",
            self.weighted.to_latex(),
            r"\end{gathered}"])

    def to_dict(self) -> dict:
        """JSON-ready (docs/json.md, ``$defs/density_bracket``): ``kind``, ``model``, ``integrator``, ``order``,
        ``density``, ``admits`` and the two families' shadow documents under ``brackets``."""
        return {"kind": "density-bracket", "model": self.system.name, "integrator": self.method.name,
                "order": self.order, "density": str(self.density), "admits": list(self.admits),
                "brackets": {"standard": self.standard.to_dict(), "density": self.weighted.to_dict()}}

    def __repr__(self):
        return f"DensityBrackets({self.method.name!r}, order={self.order}, system={self.system.name!r})"


def density_brackets(system, method="kahan", order: int = 2, density=None, degree=None,
                     max_unknowns=None) -> DensityBrackets:
    """Which Nambu bracket admits a pair for the modified field of ``method``: standard, or with density ``rho``.

    The standard question is :func:`~nambu_bch.shadow.shadow_hamiltonians` (with its divergence test for
    non-existence); the density one is :func:`density_shadow` on ``f~ / rho``, whose non-existence is certified the
    same way (every ``X_{H,G}`` is divergence-free, so ``div(Z_j / rho)_j != 0`` at the failed order rules out every
    pair, polynomial or not) or by the direct route's functional.

    Parameters
    ----------
    system : System or model name (three coordinates, two Hamiltonians)
    method : a Runge--Kutta method (name or tableau); default Kahan's
    order : int
    density : ``rho`` (as :func:`density_shadow` takes it); default the method's invariant density where it is
        known: Kahan's method on an Euler top ``x_i' = a_i x_j x_k``
        (:func:`~nambu_bch.bseries.kahan.euler_top_density`)
    degree, max_unknowns : as for the direct route

    Returns
    -------
    DensityBrackets -- ``.admits``, ``.standard`` and ``.weighted`` (ShadowFamily each, with the certificate where
    there is no pair)

    Examples
    --------
    >>> density_brackets("rigid-body", "kahan", 2).admits      # docs/runge_kutta.md, the density bracket
    ('density',)
    """
    from ..bseries.kahan import euler_top_density
    from ..integrators.runge_kutta import TABLEAUX, butcher_tableau
    from ..systems.spec import as_system
    from .api import _divergence_decision, shadow_hamiltonians
    from .family import ShadowFamily

    system = as_system(system)
    tableau = butcher_tableau(method.strip().lower() if isinstance(method, str) else method)
    if density is None:
        if tableau != TABLEAUX["kahan"]:
            raise NambuBCHError(f"the invariant density of {tableau.name} is not known here (it is for Kahan's method "
                                f"on an Euler top); pass density=")
        density = euler_top_density(system)
    standard = shadow_hamiltonians(system, tableau, order=order, degree=degree, max_unknowns=max_unknowns)
    R = density_shadow(system, tableau, density, order, degree=degree, max_unknowns=max_unknowns)
    # where the polynomial solve fails, a non-zero divergence of Z_j / rho rules out every pair; otherwise the
    # direct route's functional is the certificate (the orbit averages measure drift in the standard bracket only)
    decision = None if R.exists else _divergence_decision(system, R)
    weighted = ShadowFamily.from_direct(system, tableau, R.order, R, decision, max_unknowns=max_unknowns)
    alg = R.effective[0].algebra
    return DensityBrackets(system, tableau, R.order, sympy.expand(alg.to_sympy(alg.convert(density))), standard,
                           weighted)
