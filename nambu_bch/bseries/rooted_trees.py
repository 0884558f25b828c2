"""Rooted trees and the B-series of Runge--Kutta methods.

A rooted tree is its sorted tuple of subtrees: ``()`` is the single vertex ``•``,
``((),)`` is ``[•]``, ``((), ())`` is ``[•, •]``.  Sorting makes the tuple canonical,
so equal trees are equal tuples.  With the normalisation of Hairer--Lubich--Wanner
(Sect. III.1) a B-series is ``B(a, y) = a(∅) y + sum_t h^|t| / sigma(t) a(t) F(t)(y)``;
the Runge--Kutta map is ``B(Phi, y)`` with the elementary weights ``Phi(t)``
and the exact flow ``B(1/gamma, y)``, so order ``p`` means
``Phi(t) = 1/gamma(t)`` for ``|t| <= p`` (HLW Sect. III.1).

The modified equation is computed in the plain coefficients ``d(t) = a(t)/sigma(t)`` (the
coefficient of ``h^|t| F(t)``), where the Lie derivative needs no symmetry factors:
``F(t)'(y) F(s)(y) = sum_v F(t o_v s)(y)``, the sum over the vertices ``v`` of ``t`` of the
tree with ``s`` grafted onto ``v`` (:func:`graft`).

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, 2nd ed., Sects. III.1 and IX.9.
"""

from __future__ import annotations

import sys
from functools import lru_cache
from math import factorial

import sympy

from ..checks import check_int

LEAF = ()


def canonical(children) -> tuple:
    """The tree with the given subtrees (any order)."""
    return tuple(sorted(children))


@lru_cache(maxsize=None)
def order(t) -> int:
    """``|t|``, the number of vertices."""
    return 1 + sum(order(c) for c in t)


@lru_cache(maxsize=None)
def symmetry(t) -> int:
    """``sigma(t)``: ``prod sigma(t_i) * prod m_k!`` over the subtrees and their multiplicities."""
    value = 1
    for c in set(t):
        value *= factorial(t.count(c)) * symmetry(c) ** t.count(c)
    return value


@lru_cache(maxsize=None)
def density(t) -> int:
    """``gamma(t) = |t| prod gamma(t_i)``."""
    value = order(t)
    for c in t:
        value *= density(c)
    return value


@lru_cache(maxsize=None)
def trees(n: int) -> tuple:
    """All rooted trees with ``n`` vertices, once each (1, 1, 2, 4, 9, 20, 48, 115 for n = 1..8).

    >>> trees(3)
    (((), ()), (((),),))
    """
    n = check_int(n, "n", 1)
    if n == 1:
        return (LEAF,)
    return tuple(sorted(set(canonical(f) for f in _forests(n - 1, n - 1))))


def _forests(weight, largest):
    """Multisets of trees (as lists) of total order ``weight``, every tree of order ``<= largest``."""
    if weight == 0:
        yield []
        return
    for k in range(min(weight, largest), 0, -1):
        for t in trees(k):
            for rest in _forests(weight - k, k):
                yield [t] + rest


def graft(t, s) -> list:
    """The trees ``t o_v s``, one per vertex ``v`` of ``t`` (with repetitions): ``F(t)' F(s) = sum_v F(t o_v s)``."""
    out = [canonical(t + (s,))]
    for i, child in enumerate(t):
        rest = t[:i] + t[i + 1:]
        out += [canonical(rest + (g,)) for g in graft(child, s)]
    return out


def elementary_weight(t, tableau, _stages=None):
    """``Phi(t) = sum_i b_i Phi_i(t)``, ``Phi_i(t) = prod_children sum_j a_ij Phi_j(child)`` (HLW Sect. III.1), exact.

    ``_stages`` (internal): a dict shared by the calls of one tableau, ``{tree: (Phi_1(tree), ..)}``, so that the
    stage values of a subtree are computed once for all the trees that contain it.
    """
    A, b = tableau.A, tableau.b
    s = len(b)
    memo = {} if _stages is None else _stages

    def stage(tree):
        values = memo.get(tree)
        if values is None:
            values = [sympy.Integer(1)] * s
            for child in tree:
                inner = stage(child)
                # expanded at every level: the stage values stay short sums (a + b sqrt(3) for Gauss4) instead of
                # products nested |t| deep that one final expand has to multiply out; expand is canonical on
                # these sums, so the result is the expression the final expand alone gives
                values = [sympy.expand(v * sum(A[i][j] * inner[j] for j in range(s))) for i, v in enumerate(values)]
            memo[tree] = values
        return values

    return sympy.radsimp(sympy.expand(sum(bi * v for bi, v in zip(b, stage(t)))))


def rk_coefficients(tableau, upto: int) -> dict:
    """``{t: Phi(t)}`` for every tree with at most ``upto`` vertices."""
    stages: dict = {}
    return {t: elementary_weight(t, tableau, stages) for n in range(1, upto + 1) for t in trees(n)}


def error_coefficients(tableau, n: int) -> dict:
    """``{t: (Phi(t) - 1/gamma(t)) / sigma(t)}`` over the trees with ``n`` vertices: the coefficients of
    ``h^n F(t)(y)`` in the local error (numerical minus exact step), exact.

    For a method of order ``p`` the norm of the ``n = p + 1`` coefficients is Butcher's principal error measure
    ``A^(p+1)`` (Kennedy, Carpenter, Lewis, *Appl. Numer. Math.* 35 (2000) 177; the same coefficients as
    NodePy's ``error_coefficient``).  Hairer, Norsett, Wanner I, Sect. II.3 write them as ``alpha(t) e(t)/(p+1)!``
    with ``e(t) = 1 - gamma(t) Phi(t)`` and ``alpha(t) = (p+1)!/(sigma(t) gamma(t))``: the same up to sign.
    """
    stages: dict = {}
    return {t: sympy.radsimp(sympy.expand((elementary_weight(t, tableau, stages) - sympy.Rational(1, density(t)))
                                          / symmetry(t))) for t in trees(n)}


def _lie_derivative(series, field, upto, family):
    """``d`` applied as the Lie derivative ``(h f~ . d/dy)`` to a B-series function (plain coefficients), to ``upto``.

    ``series`` is ``(c0, {t: c(t)})`` for ``c0 y + sum h^|t| c(t) F(t)``; ``field`` is ``{s: d(s)}`` for
    ``h f~ = sum h^|s| d(s) F(s)``.  The result has ``c0 = 0``.
    """
    c0, coeffs = series
    out: dict = {}
    if c0:
        for s, ds in field.items():
            out[s] = out.get(s, 0) + c0 * ds
    for t, ct in coeffs.items():
        for s, ds in field.items():
            if family.order(t) + family.order(s) > upto or not ct or not ds:
                continue
            for tau in family.graft(t, s):
                out[tau] = out.get(tau, 0) + ct * ds
    return 0, out


def modified_coefficients(a: dict, upto: int, family=None) -> dict:
    """The modified equation of the B-series ``B(a, y)`` (``a(∅) = 1``): ``{t: b(t)}`` with
    ``f~ = sum_t h^(|t|-1) b(t)/sigma(t) F(t)``, defined by: the time-``h`` flow of ``f~`` has the
    B-series ``a`` (HLW Sect. IX.9, modified equations of B-series methods).

    Order by order in ``|t|``: with ``d = b/sigma`` and ``L`` the Lie derivative along ``h f~``,
    ``exp(h f~) y = sum_k L^k y / k!`` and ``L y = h f~``, so
    ``d(t) = a(t)/sigma(t) - [t] sum_{k>=2} L^k y / k!``, whose right side uses only ``d(s)`` with
    ``|s| < |t|`` (the recursion ``b = a - sum_{j>=2} (1/j!) ∂_b^{j-1} b`` of HLW Sect. IX.9, in plain
    coefficients).

    ``family`` (default: this module's rooted trees) is any set of trees with ``trees(n)``, ``order``, ``symmetry``
    and ``graft``: the coloured trees of P-series (:class:`nambu_bch.bseries.p_series.ColouredTrees`) take the same
    recursion, since ``F(t)' F(s) = sum_v F(t o_v s)`` holds for them too (HLW Sect. IX.10).
    """
    upto = check_int(upto, "upto", 1)
    family = sys.modules[__name__] if family is None else family
    d: dict = {}
    for n in range(1, upto + 1):
        # sum_{k>=2} L^k y / k! at order n, from the coefficients of lower orders
        power = _lie_derivative((1, {}), d, n, family)  # L y
        rest: dict = {}
        for k in range(2, n + 1):
            power = _lie_derivative(power, d, n, family)
            for t, v in power[1].items():
                if family.order(t) == n:
                    rest[t] = rest.get(t, 0) + sympy.Rational(1, factorial(k)) * v
        for t in family.trees(n):
            value = sympy.radsimp(sympy.expand(a[t] / family.symmetry(t) - rest.get(t, 0)))
            if value != 0:
                d[t] = value
    return {t: sympy.radsimp(sympy.expand(v * family.symmetry(t))) for t, v in d.items()}
