"""The linear core of an oscillator-like vector field: ``y' = A y`` plus coordinates driven by ``y``.

The fields of Sect. 5.5 (Eqs. NambuOHeqs, NambuCQeqs, NambuSHeqs) all have the
shape

    (x1, x2)' = A (x1, x2),   tr A = 0,  det A = Omega^2 > 0,
    x_k'      = q_k(x1, x2),  q_k a polynomial of degree <= 2,

a harmonic core of frequency ``Omega`` and coordinates it drives (``x3 = q^2``
for ``ho3``).  :func:`linear_core` finds this structure or raises
:class:`~nambu_bch.errors.NoExactResultError`; the closed-form solutions
(:mod:`nambu_bch.exact.solutions`) and the frequency in ``F(Omega h)``
(:mod:`nambu_bch.exact.exact_shadow`) are built on it.

References
----------
Horikoshi, Eqs. (NambuOHeqs), (NambuCQeqs), (NambuSHeqs), (OHsol)-(SHsol).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from ..checks import show
from ..errors import NoExactResultError
from ..parsing import as_expression

H_STEP = sympy.Symbol("h")


def positive_sqrt(expr):
    """``sqrt(expr)`` for a rational function positive near ``h = 0``, parameters taken positive.

    Monomial square factors come out of the root and the rest is scaled to
    constant term 1 in ``h``.

    Examples
    --------
    >>> h, omega = sympy.symbols("h omega")
    >>> positive_sqrt(omega**2*(4 - h**2*omega**2)/4)
    omega*sqrt(-h**2*omega**2/4 + 1)
    """
    num, den = sympy.fraction(sympy.cancel(sympy.together(expr)))
    out, inside = sympy.Integer(1), sympy.Integer(1)
    for part, power in ((num, 1), (den, -1)):
        gens = sorted(part.free_symbols, key=str)
        if not gens:
            out *= sympy.sqrt(part) ** power
            continue
        mono, prim = sympy.Poly(part, *gens).terms_gcd()
        for g, e in zip(gens, mono):
            out *= g ** sympy.Rational(e * power, 2)
        prim_expr = prim.as_expr()
        const = prim_expr.subs(H_STEP, 0)
        if const == 0:
            const = sympy.Integer(1)
        out *= sympy.sqrt(const) ** power
        inside *= sympy.expand(prim_expr / const) ** power
    return out * sympy.sqrt(inside)


@dataclass(frozen=True)
class LinearCore:
    """``core`` (two 0-based indices), ``driven`` (the rest), ``A`` (2x2), ``det = Omega**2``, ``Omega``."""

    core: tuple
    driven: tuple
    A: sympy.Matrix
    det: sympy.Expr
    Omega: sympy.Expr


def linear_core(coordinates, rhs, name="system") -> LinearCore:
    """The harmonic core and driven coordinates of ``x' = rhs(x)``.

    Examples
    --------
    >>> x1, x2, x3, m, omega = sympy.symbols("x1 x2 x3 m omega")
    >>> linear_core((x1, x2, x3), (x2/m, -m*omega**2*x1, 2*x1*x2/m)).Omega   # Eq. (NambuOHeqs)
    omega
    """
    coords, rhs = _checked_equations(coordinates, rhs, name)
    fail = NoExactResultError(
        f"{name} has no harmonic core: the equations {tuple(rhs)} are not of the form (y1, y2)' = A y with "
        "tr A = 0, det A > 0 and the other coordinates driven by a quadratic in y (linear oscillators such as ho, ho3)"
    )
    try:
        polys = [sympy.Poly(r, *coords) for r in rhs]
    except sympy.PolynomialError:
        raise fail from None
    core, driven = _core_and_driven(polys, coords)
    if len(core) != 2 or any(any(polys[k].degree(coords[j]) > 0 for j in driven) or polys[k].total_degree() > 2
                             for k in driven):
        raise fail
    y = [coords[i] for i in core]
    A = sympy.Matrix([[rhs[i].coeff(yj) for yj in y] for i in core])
    if sympy.simplify(A.trace()) != 0:
        raise fail
    det = sympy.factor(A.det())
    if det.is_zero or det.is_negative or (det.is_number and not det > 0):
        raise fail
    return LinearCore(tuple(core), tuple(driven), A, det, positive_sqrt(det))


def _checked_equations(coordinates, rhs, name) -> tuple:
    """``(coordinates, expanded right-hand sides)``: distinct sympy symbols and one expression per coordinate (read
    by the whitelist parser when given as text), else :class:`NoExactResultError` naming the input."""
    if isinstance(coordinates, (str, bytes)) or not hasattr(coordinates, "__iter__"):
        raise NoExactResultError(f"the coordinates of {name} are a sequence of sympy symbols, got {show(coordinates)}")
    coords = tuple(coordinates)
    if not coords or not all(isinstance(c, sympy.Symbol) for c in coords) or len(set(coords)) != len(coords):
        raise NoExactResultError(f"the coordinates of {name} must be distinct sympy symbols, got {show(coordinates)}")
    if isinstance(rhs, (str, bytes)) or not hasattr(rhs, "__iter__") or len(rhs := tuple(rhs)) != len(coords):
        raise NoExactResultError(f"{name} needs one right-hand side per coordinate ({len(coords)}), got {show(rhs)}")
    return coords, [sympy.expand(as_expression(r, coords, f"right-hand side {i + 1} of {name}")) for i, r in enumerate(rhs)]


def _core_and_driven(polys, coords) -> tuple:
    """``(core, driven)`` index lists: the largest set of homogeneous linear equations that involve only each other,
    and the remaining coordinates."""
    n = len(coords)
    core = [i for i, p in enumerate(polys)
            if not p.is_zero and p.total_degree() == 1 and all(sum(m) == 1 for m in p.monoms())]
    while True:  # the linear equations that only involve each other
        keep = [i for i in core if all(polys[i].degree(coords[j]) <= 0 for j in range(n) if j not in core)]
        if keep == core:
            break
        core = keep
    return core, [i for i in range(n) if i not in core]
