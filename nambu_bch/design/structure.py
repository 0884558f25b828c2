"""Order and error constants of two-part splittings whose pieces have structure: RKN and near-integrable.

Coordinates.  A Lie polynomial ``P`` of degree ``q`` in the pieces is determined by its coefficients ``[w] P`` on the
Lyndon words ``w`` of length ``q`` (``P_w = w + larger words``, Reutenauer, Thm. 5.1), so ``v(P) = ([w] P)_w`` is an
isomorphism of the degree-``q`` part ``L_q`` of the free Lie algebra onto ``K^(Lyndon words)``.  For a composition
``Phi = exp(h X_1 + h X_2 + sum_q h^q E_q)`` the error term ``E_q`` has the coordinates ``q! [w] log Phi``; at the
first non-vanishing degree these are the Lyndon defects of :mod:`.words` and their 2-norm is the LEM of
:func:`~nambu_bch.design.error_constant`.

RKN structure (``structure="rkn"``).  For ``H = T(p) + V(q)`` with ``T`` quadratic in the momenta, piece 1 the
kinetic part ``T`` (a drift) and piece 2 the potential ``V`` (a kick) -- the package's convention of ``TVT = 121``
and of the ``A``/``B`` of Blanes & Moan -- the bracket ``{V, {V, {V, T}}}`` vanishes: ``{V, T}`` is linear in the
momenta, ``{V, {V, T}} = |grad V|^2`` depends on positions only.  So ``[X_2, [X_2, [X_2, X_1]]] = 0`` and with it
the whole Lie ideal ``I`` it generates; the flow of an RKN problem sees only ``L / I`` (the RKN Lie algebra of
Blanes, Casas & Murua; McLachlan 1995).  ``I_q`` is spanned by ``ad_{x_1} ... ad_{x_{q-4}} [2,[2,[2,1]]]`` over all
letters.  The method has RKN order ``p`` iff ``E_q`` lies in ``I_q`` for ``q <= p``: ``dim L_q - dim I_q`` conditions
at degree ``q`` (2, 1, 2, 2, 4, 5, 10, 15 for ``q = 1..8`` against 2, 1, 2, 3, 6, 9, 18, 30 in general).  The RKN
error constant is the distance of ``v(E_{p+1})`` from ``v(I_{p+1})`` in the 2-norm,

    LEM_rkn = min_{i in I_{p+1}} || (p+1)! (v(E_{p+1}) - v(i)) ||_2,

the smallest LEM of any error term the RKN problem cannot tell from ``E_{p+1}``; it equals the LEM where
``I_{p+1} = 0`` (degrees below 4) and is computed exactly (orthogonal projection with a rational Gram matrix).

Near-integrable structure.  For ``H = A + eps B`` (piece 1 the integrable ``A``, piece 2 the perturbation
``eps B``), a Lyndon word with ``m`` letters 2 carries ``eps^m``; the Lyndon basis is graded by the letters, so
``E_q`` splits into its ``eps^m`` parts exactly.  The *generalised order* ``(r_1, r_2, ...)`` has ``r_m`` = (the first
degree whose ``eps^m`` part does not vanish) - 1: the local error is ``O(eps h^(r_1 + 1) + eps^2 h^(r_2 + 1) + ...)``,
the notation ``(s, r)`` of Laskar & Robutel and ``ABA864`` (= (8, 6, 4)) of Blanes et al. 2013.

References
----------
Blanes, Casas, Murua, *Splitting methods for differential equations*, Acta Numerica 33 (2024) 1-161, and
*Splitting and composition methods in the numerical integration of differential equations*, Bol. Soc. Esp. Mat.
Apl. 45 (2008) 89-145 (arXiv:0812.0377), Sect. 3 (RKN conditions, near-integrable systems);
McLachlan, *Composition methods in the presence of small parameters*, BIT 35 (1995) 258-268;
Laskar & Robutel, *High order symplectic integrators for perturbed Hamiltonian systems*, Celest. Mech. Dyn. Astr.
80 (2001) 39-62; Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313-330; Reutenauer, *Free Lie Algebras*, Thm. 5.1.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from itertools import product
from math import factorial

import sympy

from ..errors import InvalidCompositionError, InvalidOrderError
from .words import log_coefficients, lyndon_defect_words

#: The structures :func:`structured_analysis` and ``order_conditions(..., structure=)`` accept.
STRUCTURES = ("rkn",)
#: Highest degree searched for the order of a structured composition (the RKN error constant of order 8 needs 9).
MAX_STRUCTURED_DEGREE = 11


def check_structure(structure) -> str:
    """``structure`` if it is one of :data:`STRUCTURES` (``None`` and ``""`` mean no structure and give ``""``)."""
    if structure in (None, ""):
        return ""
    if not isinstance(structure, str) or structure.strip().lower() not in STRUCTURES:
        raise InvalidCompositionError(
            f"structure must be one of {', '.join(repr(s) for s in STRUCTURES)} or None, got {structure!r}")
    return structure.strip().lower()


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


def condition_counts(max_degree: int, structure=None) -> tuple:
    """The number of independent order conditions at degrees ``1..max_degree`` of a two-part splitting.

    ``structure=None``: the Witt dimensions 2, 1, 2, 3, 6, 9, 18, 30, ...; ``"rkn"``: ``dim L_q - dim I_q``,
    2, 1, 2, 2, 4, 5, 10, 15, ... (16 conditions for order 6 against 23 in general; the counts of the RKN Lie
    algebra, Blanes, Casas & Murua, Acta Numerica 33 (2024), Sect. 3), computed here from the ideal.
    """
    if not isinstance(max_degree, int) or isinstance(max_degree, bool) or not 1 <= max_degree <= MAX_STRUCTURED_DEGREE:
        raise InvalidOrderError(f"max_degree must be an integer in 1..{MAX_STRUCTURED_DEGREE}, got {max_degree!r}")
    structure = check_structure(structure)
    counts = []
    for q in range(1, max_degree + 1):
        n = len(lyndon_defect_words(2, q))
        counts.append(n - len(rkn_ideal(q)) if structure == "rkn" else n)
    return tuple(counts)


def _check_two_pieces(comp, what):
    if set(comp.pieces) != {1, 2}:
        raise InvalidCompositionError(
            f"{what} is defined for two pieces (1 = T or A, 2 = V or eps B); composition {comp.name!r} uses pieces "
            f"{sorted(set(comp.pieces))}")


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


def structured_analysis(spec, structure="rkn"):
    """Order and error constant of a two-part composition on the quotient of the free Lie algebra by ``structure``.

    ``structure="rkn"``: piece 1 is the kinetic energy ``T(p)`` (quadratic in the momenta), piece 2 the potential
    ``V(q)``; the order is the largest ``p`` with ``E_q`` in the RKN ideal ``I_q`` for ``q <= p``, and the error
    constant ``LEM_rkn`` the 2-norm of ``(p+1)! v(E_{p+1})`` minus its orthogonal projection on ``v(I_{p+1})``
    (module docstring).  Decimal tables keep their stated ``error_bound``: residual entries below it count as zero.

    Returns
    -------
    ErrorConstant with ``structure="rkn"``; ``defects`` are the residual Lyndon coordinates at degree ``p + 1``.

    References
    ----------
    Blanes, Casas & Murua, Acta Numerica 33 (2024), Sect. 3; Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313.
    """
    from ..integrators.composition import composition as make_composition
    from .conditions import ErrorConstant, _check_work, _Exact

    structure = check_structure(structure)
    comp = make_composition(spec, 2)
    _check_two_pieces(comp, f"structure {structure!r}")
    field = _Exact(comp)
    bound = float(getattr(comp, "error_bound", 0.0) or 0.0)
    for degree in range(1, MAX_STRUCTURED_DEGREE + 1):
        _check_work(2, degree, len(comp.pieces), f"{structure} order of {comp.name!r}")
        pairs = _log_vectors(field, degree)
        exact = [field.K.to_sympy(v) for _, v in pairs]
        residual = _residual(exact, degree, structure)
        if bound:
            vanishes = all(abs(complex(x)) <= bound for x in residual)
        else:
            vanishes = all(x == 0 for x in residual)
        if not vanishes:
            if degree == 1:
                raise InvalidCompositionError(f"composition {comp.name!r} is not consistent")
            squared = _squared_norm(residual, comp.is_complex)
            defects = {w: x for (w, _), x in zip(pairs, residual)}
            return ErrorConstant(comp, 2, degree - 1, squared, defects, bound, structure)
    raise InvalidOrderError(
        f"composition {comp.name!r} has {structure} order >= {MAX_STRUCTURED_DEGREE}; structured error constants "
        f"are computed up to order {MAX_STRUCTURED_DEGREE - 1}")


def structured_bound(comp, order: int, structure: str) -> float:
    """The largest absolute residual Lyndon coordinate of ``log Phi`` at degrees ``1..order`` modulo ``structure``
    (the stated accuracy of a decimal table whose published order holds on that structure)."""
    from .conditions import _Exact

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
    from .conditions import _Exact

    field = _Exact(comp)
    worst = 0.0
    for degree in range(2, max(orders) + 1):
        for w, v in _log_vectors(field, degree):
            m = w.count(2)
            if 1 <= m <= len(orders) and degree <= orders[m - 1]:
                worst = max(worst, abs(complex(field.K.to_sympy(v))))
    return worst


# ---------------------------------------------------------------------------------------------
# near-integrable splittings A + eps B


@dataclass(frozen=True)
class GeneralizedOrder:
    """The generalised order of a splitting of ``A + eps B`` (piece 1 = ``A``, piece 2 = ``eps B``).

    Attributes
    ----------
    composition : Composition
    orders : tuple    -- ``(r_1, r_2, ...)``: the ``eps^m`` part of ``log Phi - h(A + eps B)`` is ``O(h^(r_m + 1))``;
                         ``None`` where it vanishes through ``max_degree`` (then ``r_m >= max_degree``)
    constants : tuple -- per ``m``: the exact squared 2-norm of ``(r_m + 1)! [w] log Phi`` over the Lyndon words
                         ``w`` of length ``r_m + 1`` with ``m`` letters 2 (``None`` with ``orders``)
    max_degree : int
    """

    composition: object
    orders: tuple
    constants: tuple
    max_degree: int

    @property
    def order(self) -> int:
        """The classical order: the smallest ``r_m`` found."""
        return min(r for r in self.orders if r is not None)

    def constant(self, m: int) -> float:
        """The ``eps^m`` error constant as a float."""
        value = self.constants[m - 1]
        return None if value is None else float(sympy.sqrt(value).evalf(30))

    def to_dict(self) -> dict:
        return {"composition": str(self.composition), "generalized_order": list(self.orders),
                "error_constants": [None if c is None else self.constant(m + 1) for m, c in enumerate(self.constants)],
                "max_degree": self.max_degree}


#: Largest degree :func:`generalized_order` computes (the Lyndon words of length 11 over two letters: 186).
MAX_NEAR_INTEGRABLE_DEGREE = 11


def generalized_order(spec, powers: int = 2, max_degree: int = 9) -> GeneralizedOrder:
    """The generalised order ``(r_1, ..., r_powers)`` of a two-part splitting of ``A + eps B``, exactly.

    Counts the letters 2 (``eps B``) of each Lyndon word of ``q! [w] log Phi`` (module docstring): the ``eps^m`` part
    of the error is the set of words with ``m`` letters 2.  A symmetric composition has no even degrees in ``log Phi``
    (Hairer, Lubich, Wanner, Thm. IX.3.2), which are skipped.  Decimal tables count coordinates below their stated
    ``error_bound`` as zero.

    Parameters
    ----------
    spec : composition of the pieces 1 (``A``) and 2 (``eps B``)
    powers : int -- how many powers of ``eps`` (``m = 1..powers``)
    max_degree : int -- the highest degree ``q`` computed (at most :data:`MAX_NEAR_INTEGRABLE_DEGREE`)

    Examples
    --------
    Laskar & Robutel's SABA_2 has generalised order (4, 2):

    >>> generalized_order("saba2").orders
    (4, 2)

    References
    ----------
    Laskar & Robutel, Celest. Mech. Dyn. Astr. 80 (2001) 39; McLachlan, BIT 35 (1995) 258; Blanes et al.,
    Appl. Numer. Math. 68 (2013) 58.
    """
    from ..checks import is_int
    from ..integrators.composition import composition as make_composition
    from .conditions import _check_work, _Exact

    if not is_int(powers, 1, 8):
        raise InvalidOrderError(f"powers must be an integer in 1..8 (powers of eps), got {powers!r}")
    if not is_int(max_degree, 2, MAX_NEAR_INTEGRABLE_DEGREE):
        raise InvalidOrderError(f"max_degree must be an integer in 2..{MAX_NEAR_INTEGRABLE_DEGREE}, got {max_degree!r}")
    comp = make_composition(spec, 2)
    _check_two_pieces(comp, "a near-integrable splitting A + eps B")
    field = _Exact(comp)
    bound = float(getattr(comp, "error_bound", 0.0) or 0.0)
    orders: list = [None] * powers
    constants: list = [None] * powers
    for degree in range(2, max_degree + 1):
        if all(r is not None for r in orders):
            break
        if comp.symmetric and degree % 2 == 0:
            continue
        _check_work(2, degree, len(comp.pieces), f"generalised order of {comp.name!r}")
        by_power: dict = {}
        for w, v in _log_vectors(field, degree):
            by_power.setdefault(w.count(2), []).append(field.K.to_sympy(v))
        for m in range(1, powers + 1):
            if orders[m - 1] is not None or m not in by_power:
                continue
            values = by_power[m]
            if any((abs(complex(x)) > bound) if bound else x != 0 for x in values):
                orders[m - 1] = degree - 1
                constants[m - 1] = _squared_norm(values, comp.is_complex)
    return GeneralizedOrder(comp, tuple(orders), tuple(constants), max_degree)
