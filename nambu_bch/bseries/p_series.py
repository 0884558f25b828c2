"""P-series: coloured rooted trees and the modified equation of a partitioned Runge--Kutta method, exactly.

A partitioned Runge--Kutta method integrates ``y' = f(y)`` with the coordinates split into blocks, block ``c`` staged
by its own tableau ``(A^c, b^c)`` (all with the same ``s``).  Writing ``f = sum_c f_c`` with ``f_c`` the field
restricted to block ``c`` (zero elsewhere), the stages are ``Y_i = y + h sum_c sum_j a^c_ij f_c(Y_j)`` and the step
``y + h sum_c sum_i b^c_i f_c(Y_i)``: an additive Runge--Kutta method, whose Taylor series is a P-series over
rooted trees with one colour per block (Hairer, Lubich, Wanner, *Geometric Numerical Integration* (HLW), Sect.
III.2; the coloured trees of BSeries.jl / RootedTrees.jl for additive methods, where a vertex's colour is the
field it stands for).  A coloured tree is ``(c, children)``, the children a sorted tuple of coloured trees; with
``F((c, (t_1..t_m))) = f_c^(m)(F(t_1), .., F(t_m))`` the numerical map is::

    y + sum_t h^|t| Phi(t)/sigma(t) F(t)(y),    Phi(t) = sum_i b^{c(t)}_i Phi_i(t),
    Phi_i((c, (t_1..t_m))) = prod_k sum_j a^{c(t_k)}_ij Phi_j(t_k)

(a child of colour ``c'`` enters through the block-``c'`` stage values, hence ``A^{c'}``), and the exact flow has
``Phi(t) = 1/gamma(t)`` with the uncoloured ``gamma``.  The Lie derivative of a P-series grafts exactly as for
B-series (``F(t)' F(s) = sum_v F(t o_v s)``), so the modified equation comes from the same recursion
(:func:`~nambu_bch.bseries.rooted_trees.modified_coefficients` with :class:`ColouredTrees`; HLW Sect. IX.10,
modified equations of partitioned methods).  For a canonical system ``q' = dH/dp, p' = -dH/dq`` colour 0 is ``q``
(the first half of the coordinates) and colour 1 is ``p``; a :class:`~nambu_bch.integrators.runge_kutta.PartitionedTableau`
gives ``A^0 = q.A``, ``A^1 = p.A``.

The route is checked exactly against the Taylor route of :func:`~nambu_bch.bseries.modified.modified_equation_by_taylor`
(both Lobatto IIIA-IIIB pairs) and against the BCH route (``212`` and ``121``, the two Stormer--Verlet pairs) in
``tests/test_p_series.py``.

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, 2nd ed., Sects. III.2 (P-series, bi-coloured trees) and
IX.10 (modified equations of partitioned methods); BSeries.jl / RootedTrees.jl documentation (coloured rooted trees
of additive Runge--Kutta methods).
"""

from __future__ import annotations

from math import factorial

import sympy

from ..bch.backward import check_order
from ..checks import check_int
from . import rooted_trees as T

#: Highest order of ``h`` the P-series route accepts: h^6 needs the 4116 bi-coloured trees of 7 vertices (and the
#: 916 of 6); each further order multiplies them by about 4.5.
MAX_P_ORDER = 6
#: Most vertices of the coloured trees listed (the modified field at h^MAX_P_ORDER needs MAX_P_ORDER + 1; with two
#: colours 4116 trees, 18996 at 8 vertices): larger requests are refused before any work.
MAX_VERTICES = MAX_P_ORDER + 1
#: Most colours (each multiplies the trees of n vertices by about colours^n).
MAX_COLOURS = 4


def leaf(colour: int) -> tuple:
    """The single vertex of ``colour``."""
    return (colour, ())


def order(t) -> int:
    """``|t|``, the number of vertices."""
    return 1 + sum(order(c) for c in t[1])


def symmetry(t) -> int:
    """``sigma(t) = prod sigma(t_i) * prod m_k!`` over the (coloured) subtrees and their multiplicities."""
    children = t[1]
    value = 1
    for c in set(children):
        value *= factorial(children.count(c)) * symmetry(c) ** children.count(c)
    return value


def density(t) -> int:
    """``gamma(t) = |t| prod gamma(t_i)`` (colours play no part)."""
    value = order(t)
    for c in t[1]:
        value *= density(c)
    return value


def graft(t, s) -> list:
    """The trees ``t o_v s``, one per vertex ``v`` of ``t``: ``F(t)' F(s) = sum_v F(t o_v s)``."""
    colour, children = t
    out = [(colour, tuple(sorted(children + (s,))))]
    for i, child in enumerate(children):
        rest = children[:i] + children[i + 1:]
        out += [(colour, tuple(sorted(rest + (g,)))) for g in graft(child, s)]
    return out


class ColouredTrees:
    """The rooted trees with vertices of ``colours`` colours (the tree family of :func:`rooted_trees.modified_coefficients`).

    >>> [len(ColouredTrees(2).trees(n)) for n in range(1, 6)]
    [2, 4, 14, 52, 214]
    """

    graft = staticmethod(graft)

    def __init__(self, colours: int = 2):
        self.colours = check_int(colours, "colours", 1, MAX_COLOURS)
        self._trees: dict = {}
        self._memo: dict = {}  # (function, tree) -> value: the recursion asks for the same trees many times

    def _memoised(self, function, t):
        key = (function, t)
        value = self._memo.get(key)
        if value is None:
            value = self._memo[key] = function(t)
        return value

    def order(self, t) -> int:
        return self._memoised(order, t)

    def symmetry(self, t) -> int:
        return self._memoised(symmetry, t)

    def density(self, t) -> int:
        return self._memoised(density, t)

    def trees(self, n: int) -> tuple:
        """All coloured trees with ``n`` vertices (``n <= MAX_VERTICES``), once each, in a fixed order."""
        n = check_int(n, "n", 1, MAX_VERTICES)
        if n not in self._trees:
            pool = [t for k in range(1, n) for t in self.trees(k)]
            forests = self._forests(n - 1, pool, 0)
            self._trees[n] = tuple(sorted({(c, tuple(sorted(f))) for c in range(self.colours) for f in forests}))
        return self._trees[n]

    def _forests(self, weight, pool, start) -> list:
        """The multisets of trees of ``pool[start:]`` of total order ``weight`` (each once: indices non-decreasing)."""
        if weight == 0:
            return [[]]
        out = []
        for i in range(start, len(pool)):
            k = self.order(pool[i])
            if k <= weight:
                out += [[pool[i]] + rest for rest in self._forests(weight - k, pool, i)]
        return out


def elementary_weight(t, tableaux):
    """``Phi(t)`` of the partitioned method with ``tableaux[c]`` for colour ``c`` (module docstring), exact."""
    s = len(tableaux[0].b)

    def stage(tree):
        values = [sympy.Integer(1)] * s
        for child in tree[1]:
            inner = stage(child)
            A = tableaux[child[0]].A
            values = [v * sum(A[i][j] * inner[j] for j in range(s)) for i, v in enumerate(values)]
        return values

    b = tableaux[t[0]].b
    return sympy.radsimp(sympy.expand(sum(bi * v for bi, v in zip(b, stage(t)))))


def p_series_coefficients(tableaux, upto: int) -> dict:
    """``{t: Phi(t)}`` for every tree with at most ``upto`` vertices coloured by ``range(len(tableaux))``."""
    family = ColouredTrees(len(tableaux))
    return {t: elementary_weight(t, tableaux) for n in range(1, upto + 1) for t in family.trees(n)}


def error_coefficients(tableaux, n: int) -> dict:
    """``{t: (Phi(t) - 1/gamma(t)) / sigma(t)}`` over the coloured trees with ``n`` vertices (colour ``c`` staged by
    ``tableaux[c]``): the coefficients of ``h^n F(t)`` in the local error of the partitioned method, exact (the
    P-series analogue of :func:`~nambu_bch.bseries.rooted_trees.error_coefficients`)."""
    family = ColouredTrees(len(tableaux))
    return {t: sympy.radsimp(sympy.expand((elementary_weight(t, tableaux) - sympy.Rational(1, family.density(t)))
                                          / family.symmetry(t))) for t in family.trees(n)}


def p_series_modified_equation(system, method, order: int = 2):
    """The modified field of a partitioned Runge--Kutta pair through ``h**order`` by P-series (bi-coloured trees).

    Parameters
    ----------
    system : a canonical System or model name (``q`` the first half of the coordinates, ``p`` the second)
    method : a name of :data:`~nambu_bch.integrators.runge_kutta.PARTITIONED` or a ``PartitionedTableau``
    order : int -- the highest power of ``h`` kept, at most :data:`MAX_P_ORDER`

    Returns
    -------
    ModifiedEquation -- ``Z_0 .. Z_order``; ``tree_coefficients`` holds ``b(t)`` of the coloured trees (HLW's
    normalisation, ``f~ = sum_t h^(|t|-1) b(t)/sigma(t) F(t)``).

    Examples
    --------
    >>> M = p_series_modified_equation("ho", "lobatto-iiia-iiib-2", 2)     # Stormer-Verlet, kick-drift-kick
    >>> [M[j].is_zero() for j in range(3)]
    [False, True, False]
    """
    from ..integrators.runge_kutta import partitioned_tableau
    from ..systems.spec import as_system
    from .modified import ModifiedEquation, _canonical_half, _polynomial_field, differentials, series_fields

    system = as_system(system)
    pair = partitioned_tableau(method)
    order = check_order(order, MAX_P_ORDER)
    d = _canonical_half(system, pair)
    f = _polynomial_field(system, pair.q)
    alg = f.algebra
    parts = {0: tuple(c if k < d else alg.zero for k, c in enumerate(f.components)),
             1: tuple(c if k >= d else alg.zero for k, c in enumerate(f.components))}
    family = ColouredTrees(2)
    b = T.modified_coefficients(p_series_coefficients((pair.q, pair.p), order + 1), order + 1, family)
    ordered = [t for n in range(1, order + 2) for t in family.trees(n)]
    F = differentials(alg, parts, ordered, lambda t: t)
    coefficients = series_fields(alg, b, F, family.trees, family.symmetry, order, pair.name, "P-series")
    return ModifiedEquation(tuple(coefficients), order, pair, system, b)
