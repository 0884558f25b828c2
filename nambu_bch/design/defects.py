"""The exact Lyndon coordinates of ``log Phi`` for a composition ``Phi``, and what the order analyses read from them.

Everything here depends only on a composition's pieces and exact coefficients, never on how it was named: the
coefficient field and its factors (:class:`_Exact`), the work bound of the defects (:func:`_check_work`), the RKN
ideal and the residual modulo it (:func:`rkn_ideal`, :func:`rkn_annihilator`, :func:`_residual`), the largest
residual a decimal table states (:func:`structured_bound`) and the result type :class:`ErrorConstant`.  The catalog
compositions of :mod:`nambu_bch.integrators.composition` state their accuracy with it, and
:mod:`.conditions`, :mod:`.structure` and :mod:`.generalized` build on it; it imports neither of them nor any
composition parser, so the catalog and the order analyses meet here without an import cycle.  The mathematics is
in the docstrings of :mod:`.conditions` (Lyndon defects, LEM) and :mod:`.structure` (RKN quotient).

References
----------
Blanes, Casas, Murua, Acta Numerica 33 (2024), Sect. 3; Reutenauer, *Free Lie Algebras*, Thm. 5.1.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from itertools import product
from math import factorial

import sympy
from sympy.polys.domains import QQ

from ..algebra.fields import number_field
from ..errors import InvalidOrderError
from .words import MAX_WORK, log_coefficients, lyndon_defect_words, lyndon_defects, work


def _check_work(parts, degree, n_factors, what):
    if work(parts, degree, n_factors) > MAX_WORK:
        raise InvalidOrderError(
            f"{what}: the Lyndon defects of degree {degree} in {parts} pieces with {n_factors} factors need "
            f"about {work(parts, degree, n_factors)} operations, more than the limit {MAX_WORK}; ask for a lower order"
        )


class _Exact:
    """The exact coefficient field of a composition (QQ or an algebraic field) and its factors in it."""

    def __init__(self, comp):
        K, elems = number_field(comp.coefficients)
        if K.is_ZZ:
            K, elems = QQ, [QQ.convert(e) for e in elems]
        self.K = K
        self.factors = list(zip(comp.pieces, elems))
        self._inverse_factorials = {}

    def inv(self, m):
        """``1/m!`` in ``K`` (memoised: converting a sympy number into an algebraic field is slow, and the
        defects ask for the same few ``m`` hundreds of thousands of times)."""
        value = self._inverse_factorials.get(m)
        if value is None:
            value = self._inverse_factorials[m] = self.K.convert(sympy.Rational(1, factorial(m)))
        return value

    def defects(self, parts, degree):
        return lyndon_defects(self.factors, parts, degree, self.K.one, self.K.zero, self.inv)


@dataclass(frozen=True)
class ErrorConstant:
    """The order ``p`` and local error measure of a composition (:mod:`nambu_bch.design.conditions`).

    Attributes
    ----------
    composition : Composition
    parts : int
    order : int               -- ``p``: all Lyndon defects of length ``<= p`` vanish exactly
    squared : sympy number    -- ``LEM^2``, exact
    defects : dict            -- ``{Lyndon word: exact defect}`` at length ``p + 1``
    tolerance : float         -- 0 (exact coefficients), or the stated ``error_bound`` of a
                                 composition with decimal coefficients below which defects count as zero
    structure : str           -- ``""``, or ``"rkn"``: order and constant on the RKN quotient
                                 (:mod:`nambu_bch.design.structure`)
    """

    composition: object  # a Composition (not imported: this module sits below the composition parser)
    parts: int
    order: int
    squared: object
    defects: dict
    tolerance: float = 0.0
    structure: str = ""

    @property
    def value(self) -> float:
        """``LEM`` as a float (from the exact square, 30 digits)."""
        return float(sympy.sqrt(self.squared).evalf(30))

    def __float__(self):
        return self.value

    def to_dict(self) -> dict:
        out = {"composition": str(self.composition), "parts": self.parts, "order": self.order,
               "error_constant": self.value, "error_constant_squared": str(self.squared), "tolerance": self.tolerance}
        if self.structure:
            out["structure"] = self.structure
        return out


def _bracket(x: dict, y: dict) -> dict:
    """``xy - yx`` in the free associative algebra (polynomials as ``{word tuple: int}``)."""
    out: dict = {}
    for u, a in x.items():
        for v, b in y.items():
            out[u + v] = out.get(u + v, 0) + a * b
            out[v + u] = out.get(v + u, 0) - a * b
    return {w: c for w, c in out.items() if c}


@lru_cache(maxsize=32)
def rkn_ideal(degree: int) -> tuple:
    """The Lyndon coordinates of a spanning set of ``I_q``, the ideal of ``[2,[2,[2,1]]]`` at degree ``q = degree``.

    Rows are integer tuples over :func:`~nambu_bch.design.words.lyndon_defect_words` ``(2, degree)``, reduced to a
    basis (row echelon form).  Empty below degree 4.
    """
    if degree < 4:
        return ()
    one, two = {(1,): 1}, {(2,): 1}
    relation = _bracket(two, _bracket(two, _bracket(two, one)))
    words = lyndon_defect_words(2, degree)
    rows = []
    for letters in product((one, two), repeat=degree - 4):
        element = relation
        for x in reversed(letters):
            element = _bracket(x, element)
        rows.append([element.get(w, 0) for w in words])
    if not rows:
        return ()
    M = sympy.Matrix(rows).rref()[0]
    basis = [tuple(int(x) for x in M.row(i)) for i in range(M.rows) if any(M.row(i))]
    return tuple(basis)


@lru_cache(maxsize=32)
def rkn_annihilator(degree: int) -> tuple:
    """Integer rows ``a`` with ``a . v(i) = 0`` for every ``i`` in ``I_q``: one per independent RKN order condition.

    Each row is labelled by the Lyndon word of its free column: ``((word, row), ...)``.
    """
    words = lyndon_defect_words(2, degree)
    ideal = rkn_ideal(degree)
    if not ideal:
        return tuple((w, tuple(int(i == j) for j in range(len(words)))) for i, w in enumerate(words))
    pivots = set(sympy.Matrix(ideal).rref()[1])
    free_columns = [j for j in range(len(words)) if j not in pivots]
    out = []
    for vec in sympy.Matrix(ideal).nullspace():  # one vector per free column, 1 there and 0 at the other free ones
        denominators = sympy.ilcm(*[sympy.Rational(x).q for x in vec])
        row = tuple(int(x * denominators) for x in vec)
        free = next(j for j in free_columns if row[j] != 0)
        out.append((words[free], row))
    out.sort(key=lambda item: item[0])
    return tuple(out)


def _log_vectors(field, degree):
    """``[(word, q! [word] log Phi)]`` over the Lyndon words of length ``degree`` (in ``field.K``)."""
    K = field.K
    coefficients = log_coefficients(field.factors, 2, degree, K.one, K.zero,
                                    lambda a, b: K.convert(sympy.Rational(a, b)))
    scale = K.convert(factorial(degree))
    return [(w, coefficients[w] * scale) for w in lyndon_defect_words(2, degree)]


def _residual(values: list, degree: int, structure: str) -> list:
    """``values`` (exact sympy numbers, Lyndon coordinates) minus their orthogonal projection on ``v(I_q)``."""
    if structure != "rkn" or not rkn_ideal(degree):
        return list(values)
    N = sympy.Matrix([row for _, row in rkn_annihilator(degree)])
    d = sympy.Matrix(values)
    y = N * d
    r = N.T * (N * N.T).inv() * y
    return [sympy.expand(x) for x in r]


def _squared_norm(values, is_complex) -> object:
    if is_complex:
        return sympy.expand(sum(v * sympy.conjugate(v) for v in values))
    return sympy.expand(sum(v * v for v in values))


def structured_bound(comp, order: int, structure: str) -> float:
    """The largest absolute residual Lyndon coordinate of ``log Phi`` at degrees ``1..order`` modulo ``structure``
    (the stated accuracy of a decimal table whose published order holds on that structure)."""
    field = _Exact(comp)
    worst = 0.0
    for degree in range(1, order + 1):
        exact = [field.K.to_sympy(v) for _, v in _log_vectors(field, degree)]
        worst = max([worst, *(abs(complex(x)) for x in _residual(exact, degree, structure))])
    return worst


def generalized_bound(comp, orders) -> float:
    """The largest absolute ``q! [w] log Phi`` over the Lyndon words ``w`` with ``m`` letters 2 and length
    ``2 <= q <= r_m``, ``(r_1, r_2, ...) = orders``: the stated accuracy of a decimal table whose published
    generalised order holds (the ``eps^m`` part of its error vanishes through degree ``r_m``)."""
    field = _Exact(comp)
    worst = 0.0
    for degree in range(2, max(orders) + 1):
        for w, v in _log_vectors(field, degree):
            m = w.count(2)
            if 1 <= m <= len(orders) and degree <= orders[m - 1]:
                worst = max(worst, abs(complex(field.K.to_sympy(v))))
    return worst
