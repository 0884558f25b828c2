"""Runge--Kutta methods as frozen data: Butcher tableaux with exact coefficients.

A tableau ``(A, b, c)`` defines the map ``y1 = y + h sum_i b_i f(Y_i)`` with stages
``Y_i = y + h sum_j a_ij f(Y_j)`` (explicit when ``A`` is strictly lower triangular).
Coefficients are sympy ``Rational`` numbers or exact radicals (Gauss--Legendre), never
floats; each tableau names its reference and its classical order, and the test suite
checks the order conditions ``Phi(t) = 1/gamma(t)`` on every rooted tree up to order 6
(:mod:`nambu_bch.bseries.rooted_trees`).

Kahan's method (Kahan--Hirota--Kimura) is not a Runge--Kutta method in general, but on
*quadratic* vector fields it coincides with the three-stage method
``(x' - x)/h = -f(x)/2 + 2 f((x + x')/2) - f(x')/2`` (Celledoni, McLachlan, Owren,
Quispel, "Geometric properties of Kahan's method", J. Phys. A 46 (2013) 025201);
the tableau ``"kahan"`` below is that method, and the modified
equation of :mod:`nambu_bch.bseries` refuses it on fields of higher degree.

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, 2nd ed., Sect. III.1 (order conditions);
Hairer, Wanner, *Solving ODEs II*, Sect. IV.5 (Gauss methods); Hairer, Norsett, Wanner,
*Solving ODEs I*, Sect. II.1 (classical RK4), II.7 (implicit Euler, trapezoidal rule).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from ..checks import show
from ..errors import InvalidCompositionError

R = sympy.Rational


@dataclass(frozen=True)
class ButcherTableau:
    """A Runge--Kutta method ``(A, b, c)`` with exact coefficients.

    Attributes
    ----------
    name : str -- the key of :data:`TABLEAUX`
    A : tuple of tuples, ``s x s``
    b, c : tuples of length ``s`` (``c_i = sum_j a_ij``)
    order : int -- the classical order (the largest ``p`` with every order condition of order ``<= p``)
    reference : str
    quadratic_only : bool -- the tableau is the method's B-series only on quadratic vector fields (Kahan)
    """

    name: str
    A: tuple
    b: tuple
    c: tuple
    order: int
    reference: str
    quadratic_only: bool = False

    @property
    def stages(self) -> int:
        return len(self.b)

    @property
    def is_explicit(self) -> bool:
        return all(self.A[i][j] == 0 for i in range(self.stages) for j in range(i, self.stages))

    @property
    def symmetric(self) -> bool:
        """``b_i = b_{s+1-i}`` and ``a_ij + a_{s+1-i,s+1-j} = b_j``: the method is symmetric (HLW Sect. V.2), so its
        modified field has only even powers of ``h`` (HLW Sect. IX.2).  Sufficient, decided exactly."""
        s, A, b = self.stages, self.A, self.b
        return all(sympy.expand(b[i] - b[s - 1 - i]) == 0 for i in range(s)) and all(
            sympy.expand(A[i][j] + A[s - 1 - i][s - 1 - j] - b[j]) == 0 for i in range(s) for j in range(s))

    def remainder_power(self, order: int) -> int:
        """The first power of ``h`` after ``h**order`` the modified field can contain (skips odd ones if symmetric)."""
        return order + 2 if self.symmetric and order % 2 == 0 else order + 1

    def __str__(self):
        return self.name


def _tableau(name, A, b, order, reference, quadratic_only=False) -> ButcherTableau:
    A = tuple(tuple(sympy.sympify(a, strict=True) for a in row) for row in A)
    b = tuple(sympy.sympify(x, strict=True) for x in b)
    c = tuple(sympy.radsimp(sympy.expand(sum(row, sympy.Integer(0)))) for row in A)
    return ButcherTableau(name, A, b, c, order, reference, quadratic_only)


_S3, _S15 = sympy.sqrt(3), sympy.sqrt(15)

#: The built-in tableaux, by the names the API accepts.
TABLEAUX = {
    t.name: t
    for t in (
        _tableau("euler", [[0]], [1], 1, "explicit Euler; Hairer-Lubich-Wanner Sect. IX.1"),
        _tableau("implicit-euler", [[1]], [1], 1, "implicit Euler; Hairer-Norsett-Wanner I, Sect. II.7"),
        _tableau("midpoint", [[R(1, 2)]], [1], 2, "implicit midpoint rule; Hairer-Lubich-Wanner Sect. I.1, IX.1"),
        _tableau("trapezoid", [[0, 0], [R(1, 2), R(1, 2)]], [R(1, 2), R(1, 2)], 2,
                 "trapezoidal rule (Lobatto IIIA, s = 2); Hairer-Lubich-Wanner Sect. II.1"),
        _tableau("rk4", [[0, 0, 0, 0], [R(1, 2), 0, 0, 0], [0, R(1, 2), 0, 0], [0, 0, 1, 0]],
                 [R(1, 6), R(1, 3), R(1, 3), R(1, 6)], 4, "classical Runge-Kutta; Hairer-Norsett-Wanner I, Sect. II.1"),
        _tableau("gauss4", [[R(1, 4), R(1, 4) - _S3 / 6], [R(1, 4) + _S3 / 6, R(1, 4)]], [R(1, 2), R(1, 2)], 4,
                 "Gauss-Legendre, s = 2; Hairer-Wanner II, Sect. IV.5"),
        _tableau("gauss6",
                 [[R(5, 36), R(2, 9) - _S15 / 15, R(5, 36) - _S15 / 30],
                  [R(5, 36) + _S15 / 24, R(2, 9), R(5, 36) - _S15 / 24],
                  [R(5, 36) + _S15 / 30, R(2, 9) + _S15 / 15, R(5, 36)]],
                 [R(5, 18), R(4, 9), R(5, 18)], 6, "Gauss-Legendre, s = 3; Hairer-Wanner II, Sect. IV.5"),
        _tableau("lobatto-iiib-2", [[R(1, 2), 0], [R(1, 2), 0]], [R(1, 2), R(1, 2)], 2,
                 "Lobatto IIIB, s = 2; Hairer-Lubich-Wanner Sect. II.2"),
        _tableau("lobatto-iiia-3", [[0, 0, 0], [R(5, 24), R(1, 3), R(-1, 24)], [R(1, 6), R(2, 3), R(1, 6)]],
                 [R(1, 6), R(2, 3), R(1, 6)], 4, "Lobatto IIIA, s = 3; Hairer-Lubich-Wanner Sect. II.2"),
        _tableau("lobatto-iiib-3", [[R(1, 6), R(-1, 6), 0], [R(1, 6), R(1, 3), 0], [R(1, 6), R(5, 6), 0]],
                 [R(1, 6), R(2, 3), R(1, 6)], 4, "Lobatto IIIB, s = 3; Hairer-Lubich-Wanner Sect. II.2"),
        _tableau("kahan", [[0, 0, 0], [R(-1, 4), 1, R(-1, 4)], [R(-1, 2), 2, R(-1, 2)]], [R(-1, 2), 2, R(-1, 2)], 2,
                 "Kahan's method on quadratic fields; Celledoni-McLachlan-Owren-Quispel, J. Phys. A 46 (2013) 025201",
                 quadratic_only=True),
    )
}


@dataclass(frozen=True)
class PartitionedTableau:
    """A partitioned Runge--Kutta pair for a canonical system ``q' = dH/dp, p' = -dH/dq`` (HLW Sect. II.2).

    The stages ``Q_i = q + h sum_j a_ij K_j``, ``P_i = p + h sum_j a^_ij L_j`` with ``K_j = dH/dp(Q_j, P_j)``,
    ``L_j = -dH/dq(Q_j, P_j)``; the step ``q1 = q + h sum_i b_i K_i``, ``p1 = p + h sum_i b^_i L_i``: the first
    tableau integrates ``q`` (the first ``d`` coordinates), the second ``p``.

    Attributes
    ----------
    name : str -- the key of :data:`PARTITIONED`
    q, p : ButcherTableau -- the tableaux of the ``q`` and of the ``p`` components (same number of stages)
    order : int
    reference : str
    """

    name: str
    q: ButcherTableau
    p: ButcherTableau
    order: int
    reference: str

    def __post_init__(self):
        if not (isinstance(self.q, ButcherTableau) and isinstance(self.p, ButcherTableau)):
            raise InvalidCompositionError(f"a partitioned pair takes two ButcherTableau, got {show(self.q)} and "
                                          f"{show(self.p)}")
        if self.q.stages != self.p.stages:
            raise InvalidCompositionError(f"the tableaux of a partitioned pair need the same number of stages, got "
                                          f"{self.q.stages} and {self.p.stages}")

    #: Kahan's restriction never applies to a pair (the attribute the entry points read off any tableau).
    quadratic_only = False

    @property
    def stages(self) -> int:
        return self.q.stages

    @property
    def is_explicit(self) -> bool:
        return self.q.is_explicit and self.p.is_explicit

    @property
    def symmetric(self) -> bool:
        """Both tableaux symmetric (``b_i = b_{s+1-i}``, ``a_ij + a_{s+1-i,s+1-j} = b_j``): the pair is a symmetric
        method (HLW Sect. V.2), so its modified field has only even powers of ``h``.  Sufficient, decided exactly."""
        return self.q.symmetric and self.p.symmetric

    def remainder_power(self, order: int) -> int:
        """The first power of ``h`` after ``h**order`` the modified field can contain (skips odd ones if symmetric)."""
        return order + 2 if self.symmetric and order % 2 == 0 else order + 1

    def per_coordinate(self, n: int) -> list:
        """The tableau of each of ``n = 2d`` canonical coordinates: ``q`` (the first ``d``) by :attr:`q`, ``p`` by
        :attr:`p`."""
        return [self.q] * (n // 2) + [self.p] * (n // 2)

    def __str__(self):
        return self.name


#: Partitioned pairs by name: Lobatto IIIA (for ``q``) with Lobatto IIIB (for ``p``), symplectic (HLW Sect. VI.4);
#: ``s = 2`` is the Stormer--Verlet method (HLW Sect. II.2), ``s = 3`` has order 4.
PARTITIONED = {
    t.name: t
    for t in (
        PartitionedTableau("lobatto-iiia-iiib-2", TABLEAUX["trapezoid"], TABLEAUX["lobatto-iiib-2"], 2,
                           "Lobatto IIIA-IIIB, s = 2 (Stormer-Verlet); Hairer-Lubich-Wanner Sect. II.2"),
        PartitionedTableau("lobatto-iiia-iiib-3", TABLEAUX["lobatto-iiia-3"], TABLEAUX["lobatto-iiib-3"], 4,
                           "Lobatto IIIA-IIIB, s = 3; Hairer-Lubich-Wanner Sects. II.2, III.2"),
    )
}


def partitioned_tableau(method) -> PartitionedTableau:
    """The :class:`PartitionedTableau` named ``method`` (one of :data:`PARTITIONED`), or ``method`` itself."""
    if isinstance(method, PartitionedTableau):
        return method
    if isinstance(method, str) and method in PARTITIONED:
        return PARTITIONED[method]
    raise InvalidCompositionError(
        f"unknown partitioned Runge-Kutta pair {show(method)}; accepted are {', '.join(PARTITIONED)} or a "
        f"PartitionedTableau")


def butcher_tableau(method) -> ButcherTableau:
    """The :class:`ButcherTableau` named ``method`` (one of :data:`TABLEAUX`), or ``method`` itself.

    >>> butcher_tableau("midpoint").A
    ((1/2,),)
    """
    if isinstance(method, ButcherTableau):
        return method
    if isinstance(method, str) and method in TABLEAUX:
        return TABLEAUX[method]
    raise InvalidCompositionError(
        f"unknown Runge-Kutta method {show(method)}; accepted are {', '.join(TABLEAUX)} or a ButcherTableau")


def runge_kutta_method(method):
    """The :class:`ButcherTableau` or :class:`PartitionedTableau` if ``method`` is one (or names one of
    :data:`TABLEAUX` or :data:`PARTITIONED`, any case), else None.

    The one test the entry points use to tell a Runge--Kutta method from a composition.

    >>> runge_kutta_method("Gauss4").name, runge_kutta_method("lobatto-iiia-iiib-3").order, runge_kutta_method("12321")
    ('gauss4', 4, None)
    """
    if isinstance(method, (ButcherTableau, PartitionedTableau)):
        return method
    if isinstance(method, str):
        key = method.strip().lower()
        if key in TABLEAUX:
            return TABLEAUX[key]
        if key in PARTITIONED:
            return PARTITIONED[key]
    return None
