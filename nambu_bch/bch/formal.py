"""The formal BCH series: log of a product of exponentials in the Lyndon basis.

For a composition ``Phi = exp(c_1 X_{k_1}) ... exp(c_s X_{k_s})`` (operator
order, :mod:`nambu_bch.integrators.composition`) with the pieces as free
generators, ``log Phi = sum_d L_d``, ``L_d`` a homogeneous Lie polynomial of
degree ``d``.  With the step, ``Phi_h = exp(h X_eff)`` and
``X_eff = sum_d h^(d-1) L_d``, so ``L_{j+1}`` is the coefficient ``Z_j``
(Eqs. eL1, eL2).

Table.  The two-generator products ``12``, ``21``, ``121`` and ``212`` (``log(e^A e^B)``, its reverse,
the symmetric series) are read from a verified table shipped with the package,
:mod:`nambu_bch.bch.table`, up to its top degree; the result is the engines' to the last numerator.  A plain
word (``"12"``, ``"TVT"``, ``"1:1/2,2:1,1:1/2"``) is read by :mod:`nambu_bch.bch.light` with ``Fraction``
coefficients, so that such a request imports neither sympy nor numpy: the result's
:attr:`FormalBCH.composition`, :meth:`FormalBCH.terms` and LaTeX build their sympy objects when first asked,
and each degree's ``(numerator, tree)`` pairs are built from the stored numerators when asked for.

Engines (exact, no floats).  Rational compositions run the sparse engine of
:mod:`nambu_bch.bch.modular`: coefficients of ``log Phi`` on Lyndon words only
(a walk of the prefix tree), a unitriangular solve per content class whose
entries ``<P_v, w>`` come from a compiled straight-line program, all modulo
primes, numerators rebuilt by the Chinese remainder theorem from a rigorous
bound (Casas & Murua 2009; Hofstätter's ``bch``).  Its size guard counts the top-degree
same-content Lyndon pairs of the solve.

The dense engine serves algebraic coefficients (triple jump, ``2**(1/3)``, run
with elements of ``QQ(2**(1/3))``) and numerators too large for the primes.
The product is expanded in the free associative algebra truncated at
``max_degree``, homogeneous part ``d`` stored as a dense vector over the
``g^d`` words (``g`` generators).  Clearing the common denominator ``q`` of the
``c_i`` and storing ``d! * (part d)`` keeps every product integral
(``d!/(a! b!)`` is a binomial coefficient), and
``log(1 + Q) = sum_k (-1)^(k+1) Q^k / k`` adds one factor ``lcm(1..n)``.  Each
``L_d`` is then written in the Lyndon basis ``P_w`` by a triangular solve
(``P_w = w + larger words``, :mod:`nambu_bch.bch.lyndon`); the residual after
the solve must vanish, which checks that the logarithm is a Lie element.  For
small degrees the inverse of that unitriangular system is tabulated once
(int64, overflow-checked) and the solve is one matrix-vector product.  Both
engines give the same numerators over the same denominators
``D_d = d! lcm(1..n) q^d``.

References
----------
Horikoshi, Eqs. (eL1), (BCH1), (eL2), (BCH2); Hairer, Lubich, Wanner,
*Geometric Numerical Integration*, Sect. III.4 (BCH formula) and Sect. III.5
(symmetric compositions have odd-degree series); Reutenauer, *Free Lie
Algebras*, Thm. 5.1 (Lyndon basis); Casas & Murua, J. Math. Phys. 50 (2009)
033513 (BCH series in a Hall-Lyndon basis).
"""

from __future__ import annotations

import sys
from fractions import Fraction
from functools import lru_cache
from math import comb, factorial, gcd, lcm

# numpy and sympy are imported where the engines and the sympy views need them: a series served from the table
# (a word read by .light, its numerators by .table) imports neither (most of a fresh process's time and memory)
from ..checks import check_int
from ..errors import InvalidCompositionError, InvalidOrderError
from ..printable import Printable
from ..values import ValueEquality
from . import table as _table
from .collector import no_full_collection
from .light import Word, parse_word
from .lyndon import (
    divisors,
    lyndon_expansion,
    mobius,
    lyndon_words,
    standard_bracketing,
    tree_leaves,
    witt_dimension,
    word_index,
)

#: Largest number of words ``g^max_degree`` of the top degree that the dense engine accepts.
MAX_WORDS = 600_000
#: Largest total size ``sum_d dim L_d 2^(d-1)`` of the Lyndon-basis expansions the dense projection walks.
MAX_EXPANSION = 15_000_000
#: Largest number of same-content Lyndon pairs ``(v, w)`` of the top degree the sparse (modular) engine's solve may visit.
MAX_PAIRS = 2_500_000_000
_HARD_DEGREE = 64  # beyond this not even the estimate is computed


@lru_cache(maxsize=4096)
def _class_pairs(g: int, d: int) -> int:
    """``sum_c m_c (m_c - 1) / 2`` over the letter contents ``c`` of degree ``d``, ``m_c`` Lyndon words of content ``c``.

    ``m_c = (1/d) sum_{e | gcd(c)} mu(e) (d/e)! / prod (c_i/e)!`` (necklaces of fixed content,
    Reutenauer Cor. 4.14 refined by multidegree)."""
    total = 0
    for c in _contents(g, d):
        gc = 0
        for ci in c:
            gc = gcd(gc, ci)
        m = 0
        for e in divisors(gc):
            mult = factorial(d // e)
            for ci in c:
                mult //= factorial(ci // e)
            m += mobius(e) * mult
        m //= d
        total += m * (m - 1) // 2
    return total


def _contents(g: int, d: int):
    if g == 1:
        yield (d,)
        return
    for first in range(d + 1):
        for rest in _contents(g - 1, d - first):
            yield (first,) + rest


def estimate_size(n_generators: int, max_degree: int) -> dict:
    """Sizes of the BCH computation: Lyndon basis elements (Witt), words, expansion entries, solve pairs.

    ``lyndon`` (Witt's formula) sizes the sparse engine's tables; ``pairs`` (same-content Lyndon
    pairs of the top degree: the unitriangular solve of :mod:`nambu_bch.bch.modular` walks only
    the content classes of the top degree, the lower degrees ride along its ``ad_a`` chains)
    bounds its work;
    ``words``/``top_words``/``expansion`` size the dense engine (associative words, and
    ``P_w`` of a word of length ``d`` has at most ``2^(d-1)`` terms).

    >>> estimate_size(3, 7)["lyndon"], estimate_size(3, 9)["expansion"], estimate_size(2, 4)["pairs"]
    (508, 687417, 0)
    """
    # the content enumeration recurses on the number of letters: it needs at least one
    g = check_int(n_generators, "n_generators", 1)
    max_degree = check_int(max_degree, "max_degree", 1, _HARD_DEGREE)
    return {
        "lyndon": sum(witt_dimension(g, d) for d in range(1, max_degree + 1)),
        "words": sum(g**d for d in range(1, max_degree + 1)),
        "top_words": g**max_degree,
        "expansion": sum(witt_dimension(g, d) * 2 ** (d - 1) for d in range(1, max_degree + 1)),
        "pairs": _class_pairs(g, max_degree),
    }


#: Rational series use the sparse modular engine from this degree on, when the dense engine would walk more than
#: :data:`DENSE_COLD_WORDS` top-degree words, or once the compiled engine has run in this process.  Below that a
#: fresh process answers faster with the dense engine: the sparse one first imports numba (about 0.2 s) and starts
#: it (about 0.1 s).  Once numba is up the sparse engine is faster at every size (docs/history/performance.md, Sect. 1:
#: fresh process, ``12`` degree 14: dense 0.19 s, sparse 0.28 s; ``12321`` degree 9: 0.15 s against 0.27 s;
#: numba started: 0.005 s and 0.007 s sparse).
SPARSE_FROM_DEGREE = 32
#: Largest ``g^n`` the dense engine takes in a process where the sparse engine has not run yet (``3^9``).
DENSE_COLD_WORDS = 19683


@lru_cache(maxsize=1024)
def _fits_dense(g: int, n: int) -> bool:
    if n > _HARD_DEGREE:
        return False
    if g <= 1:
        return True
    if g**n > MAX_WORDS:
        return False
    return estimate_size(g, n)["expansion"] <= MAX_EXPANSION


@lru_cache(maxsize=1024)
def _fits(g: int, n: int) -> bool:
    """The sparse engine finishes: at most :data:`MAX_PAIRS` solve pairs, word codes fit int64."""
    if n > _HARD_DEGREE:
        return False
    if g <= 1:
        return True
    if g**n >= 2**56 or n > 31:  # word codes in int64; int32 program values (modular._solve)
        return False
    return estimate_size(g, n)["pairs"] <= MAX_PAIRS


def check_degree(max_degree, n_generators: int, dense: bool = False) -> int:
    """``max_degree`` as an int ``>= 1`` whose computation fits the size limits, else :class:`InvalidOrderError`.

    The size is estimated up front from the algorithm that will run: for the sparse
    engine (rational coefficients) the number of Lyndon words (Witt's formula) and of
    same-content Lyndon pairs of the solve; for the dense engine (``dense=True``,
    algebraic coefficients) the ``g^n`` associative words and the Lyndon expansions.  An
    order too high to finish is refused instead of hanging.
    """
    max_degree = _positive_degree(max_degree)
    g = n_generators
    fits = _fits_dense if dense else _fits
    if not fits(g, max_degree):
        if max_degree <= _HARD_DEGREE:
            size = estimate_size(g, max_degree)
            if dense:
                detail = (
                    f"{size['lyndon']} Lyndon basis elements (Witt's formula), {size['top_words']} words of top "
                    f"degree and {size['expansion']} expansion terms (algebraic coefficients use the dense engine)"
                )
            else:
                detail = (
                    f"{size['lyndon']} Lyndon basis elements (Witt's formula) and {size['pairs']} same-content "
                    f"Lyndon pairs in the triangular solve (at most {MAX_PAIRS})"
                )
        else:
            detail = f"more than {_HARD_DEGREE} degrees"
        best = 1
        while fits(g, best + 1):
            best += 1
        raise InvalidOrderError(
            f"BCH to degree {max_degree} in {g} generators needs {detail}, too many to finish in reasonable time; "
            f"the largest accepted degree for {g} generators is {best} (X_eff to h^{best - 1})"
        )
    return max_degree


def _positive_degree(max_degree) -> int:
    """``max_degree`` as an int ``>= 1`` (an int, numpy or sympy integer), else :class:`InvalidOrderError`."""
    # a numpy or sympy integer exists only once its module is imported: looked up, never imported here
    sympy, np = sys.modules.get("sympy"), sys.modules.get("numpy")
    if sympy is not None and isinstance(max_degree, sympy.Integer):
        max_degree = int(max_degree)
    integer = isinstance(max_degree, int) or (np is not None and isinstance(max_degree, np.integer))
    if isinstance(max_degree, bool) or not integer:
        raise InvalidOrderError(f"BCH degree must be a positive integer, got {max_degree!r}")
    max_degree = int(max_degree)
    if max_degree < 1:
        raise InvalidOrderError(f"BCH degree must be a positive integer (1 = X_1 + X_2 + ...), got {max_degree}")
    return max_degree


class _Scalars:
    """Coefficient arithmetic: python ints (rational compositions) or a sympy algebraic field."""

    def __init__(self, coefficients):
        import sympy
        from sympy.polys.constructor import construct_domain
        from sympy.polys.domains import QQ

        if all(getattr(c, "is_Rational", False) for c in coefficients):
            K = QQ  # the usual case, without construct_domain's algebraic-field search (about 1 ms a call)
        else:
            K, elems = construct_domain(list(coefficients), extension=True)
        if K.is_ZZ or K.is_QQ:
            fracs = [sympy.Rational(c) for c in coefficients]
            self.q = lcm(*(int(f.q) for f in fracs))
            self.values = [int(f.p) * (self.q // int(f.q)) for f in fracs]
            self.K = None
            self.zero, self.one = 0, 1
        else:
            self.q = 1
            self.values = list(elems)
            self.K = K
            self.zero, self.one = K.zero, K.one



def _element_to_sympy(K):
    import sympy

    if K is None:
        return lambda e: sympy.Rational(int(e.numerator), int(e.denominator))
    return K.to_sympy


@lru_cache(maxsize=1024)
def _lyndon_trees(g: int, d: int, generators: tuple) -> tuple:
    """Standard bracketings of the degree-``d`` Lyndon words (table order), leaves named by ``generators``."""
    return tuple(standard_bracketing(w, generators) for w in lyndon_words(g, d))


_INT64_LIMIT = 2.0**60  # int64 run allowed when every intermediate magnitude is bounded by this


def _log_of_product(letters, scalars: _Scalars, g: int, n: int):
    """Numerators ``N_d`` (arrays over the ``g^d`` words) and denominators of ``log prod exp``.

    Rational compositions run in int64 when a float64 run on absolute values (an upper bound of
    every intermediate magnitude) stays below ``2^60``: then no int64 operation can overflow and
    the result is exact.  Otherwise (and for algebraic coefficients) Python ints / field elements.
    """
    import numpy as np

    big = lcm(*range(1, n + 1))
    dens = [factorial(d) * big * scalars.q**d for d in range(n + 1)]
    if scalars.K is None:
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow here only means "too large for int64"
            _, largest = _log_arrays(letters, [float(abs(c)) for c in scalars.values], np.float64, 0.0, 1.0, g, n, big, True)
        if largest < _INT64_LIMIT:
            L, _ = _log_arrays(letters, scalars.values, np.int64, 0, 1, g, n, big, False)
            return L, dens
    L, _ = _log_arrays(letters, scalars.values, object, scalars.zero, scalars.one, g, n, big, False)
    return L, dens


def _log_arrays(letters, values, dtype, zero, one, g, n, big, bounding):
    """The log's arrays and, when ``bounding`` (non-negative floats), the largest magnitude met."""
    import numpy as np

    largest = [0.0]

    def zeros(size):
        a = np.empty(size, dtype=dtype)
        a.fill(zero)
        return a

    def track(a):
        if bounding and a.size:
            largest[0] = max(largest[0], float(a.max()))

    # P_d scaled by d!; degree 0 is the unit
    P = [zeros(g**d) for d in range(n + 1)]
    P[0][0] = one
    for a, c in zip(letters, values):
        new = [zeros(g**d) for d in range(n + 1)]
        powers = [one]
        for _ in range(n):
            powers.append(powers[-1] * c)
        for d in range(n + 1):
            for b in range(d + 1):
                col = word_index((a,) * b, g)
                view = new[d].reshape(g ** (d - b), g**b)
                factor = comb(d, b) * powers[b]
                if bounding:
                    largest[0] = max(largest[0], float(factor))
                view[:, col] += P[d - b] * factor
            track(new[d])
        P = new
    Q = P
    Q[0] = zeros(1)
    L = [zeros(g**d) for d in range(n + 1)]
    R = Q
    for k in range(1, n + 1):
        if k > 1:
            R = [_graded_product_part(R, Q, d, k, g, zeros) if d >= k else zeros(g**d) for d in range(n + 1)]
            for v in R:
                track(v)
        sign = 1 if (k % 2 or bounding) else -1
        for d in range(k, n + 1):
            L[d] += R[d] * (sign * (big // k))
            track(L[d])
    return L, largest[0]


_PATTERN_CACHE: dict = {}
_PATTERN_CACHE_SIZE = 64


def _pattern_log(pattern: tuple, coefficients: tuple, g: int, n: int):
    """Cached ``(scalars, numerators, denominators)`` of the log for a letter pattern (read-only arrays)."""
    key = (pattern, coefficients, n)
    hit = _PATTERN_CACHE.get(key)
    if hit is None:
        scalars = _Scalars(coefficients)
        hit = (scalars, *_log_of_product(list(pattern), scalars, g, n))
        if len(_PATTERN_CACHE) >= _PATTERN_CACHE_SIZE:
            _PATTERN_CACHE.pop(next(iter(_PATTERN_CACHE)))
        _PATTERN_CACHE[key] = hit
    return hit


def clear_cache() -> None:
    """Forget cached associative logarithms (benchmarks call this between timed runs)."""
    _PATTERN_CACHE.clear()


def _permute_letters(vector, d: int, g: int, rank):
    """The same element with letter ``a`` renamed ``rank[a]`` (a permutation of base-``g`` digits)."""
    if d == 0:
        return vector
    import numpy as np

    out = np.empty_like(vector)
    out[_digit_permutation(d, g, tuple(rank))] = vector
    return out


@lru_cache(maxsize=256)
def _digit_permutation(d: int, g: int, rank: tuple):
    import numpy as np

    index = np.arange(g**d, dtype=np.int64)
    new_index = np.zeros_like(index)
    perm = np.asarray(rank, dtype=np.int64)
    place = 1
    for _ in range(d):
        new_index += perm[index % g] * place
        index //= g
        place *= g
    return new_index


def _graded_product_part(R, Q, d, k, g, zeros):
    """Part ``d`` of ``R * Q`` (both scaled by degree factorials), ``R`` of min degree ``k - 1``."""
    import numpy as np

    out = zeros(g**d)
    for a in range(k - 1, d):
        b = d - a
        out += np.multiply.outer(R[a], Q[b]).ravel() * comb(d, a)
    return out


_TUPLE_TABLE_DEGREE = 8  # up to this degree expansions are kept as Python tuples (fast loops, more memory)


@lru_cache(maxsize=None)
def _lyndon_table(g: int, d: int) -> tuple:
    """``((word, index, expansion), ...)`` in lexicographic order; the expansion of ``P_w`` as
    ``((index, coefficient), ...)`` (small degrees) or as ``(indices, coefficients)`` int64 arrays."""
    table = []
    for w in lyndon_words(g, d):
        idx, coef = lyndon_expansion(w, g)
        expansion = tuple(zip(idx.tolist(), coef.tolist())) if d <= _TUPLE_TABLE_DEGREE else (idx, coef)
        table.append((w, word_index(w, g), expansion))
    return tuple(table)


_INVERSE_LIMIT = 400  # largest Witt dimension for which the inverse of the triangular system is kept


@lru_cache(maxsize=None)
def _lyndon_inverse(g: int, d: int):
    """``(Lyndon word indices, T)`` with ``T`` (int64) inverting the unitriangular system, or ``None``.

    ``M[w', w]`` = coefficient of the Lyndon word ``w'`` in ``P_w`` is unit lower triangular in
    lexicographic order, and ``L[w'] = sum_w c_w M[w', w]`` on Lyndon words, so ``c = M^{-1} L``.
    Built once per (generators, degree); ``None`` when too large or when int64 would overflow.
    """
    import numpy as np

    table = _lyndon_table(g, d)
    n = len(table)
    if n > _INVERSE_LIMIT:
        return None
    position = {i: k for k, (_, i, _) in enumerate(table)}
    M = np.zeros((n, n), dtype=np.int64)
    for col, (_, _, expansion) in enumerate(table):
        for j, a in expansion if d <= _TUPLE_TABLE_DEGREE else zip(expansion[0].tolist(), expansion[1].tolist()):
            row = position.get(j)
            if row is not None:
                M[row, col] = a
    T = np.eye(n, dtype=np.int64)
    Tf = np.eye(n)
    for i in range(1, n):  # forward substitution, row by row, tracked in float to detect overflow
        T[i, :i] = -(M[i, :i] @ T[:i, :i])
        Tf[i, :i] = -(M[i, :i].astype(float) @ Tf[:i, :i])
    if not np.all(np.abs(Tf) < 2.0**52):
        return None
    return np.array([i for _, i, _ in table], dtype=np.int64), T


def _lyndon_coordinates(vector, d: int, g: int):
    """Coordinates ``[(position in the Lyndon table, numerator), ...]`` of a homogeneous Lie element."""
    import numpy as np

    if not vector.any():
        return []
    inverse = _lyndon_inverse(g, d)
    if inverse is not None and vector.dtype == np.int64:
        rows, T = inverse
        values = vector[rows]
        bound = int(np.abs(values).max()) * int(np.abs(T).max()) * len(values)
        if bound < 2**62:
            return [(k, c) for k, c in enumerate((T @ values).tolist()) if c]
    residual = vector.tolist()  # plain Python list: short scattered updates are cheaper than numpy object ops
    coords = []
    as_tuples = d <= _TUPLE_TABLE_DEGREE
    for k, (w, i, expansion) in enumerate(_lyndon_table(g, d)):
        c = residual[i]
        if c:
            coords.append((k, c))
            for j, a in expansion if as_tuples else zip(expansion[0].tolist(), expansion[1].tolist()):
                residual[j] -= a * c
    if any(residual):
        raise ArithmeticError(f"internal error: the degree-{d} part of the BCH logarithm is not a Lie element")
    return coords


class FormalBCH(Printable, ValueEquality):
    """``log(exp(c_1 X_{k_1}) ... exp(c_s X_{k_s}))`` through ``max_degree`` in the Lyndon basis.

    A series served from the table holds the word as read without sympy (:class:`~nambu_bch.bch.light.Word`)
    and its numerators as the table stores them: :attr:`composition`, :meth:`terms` and :meth:`to_latex` build
    the sympy objects when first asked; :meth:`scaled_terms`, :meth:`to_text`, :attr:`degrees` and ``len``
    need none.

    Attributes
    ----------
    composition : Composition
    generators : tuple of int
        The distinct piece numbers, in increasing order: the ordered alphabet of
        the Lyndon basis (piece ``k`` is the generator ``X_k``).
    max_degree : int
    """

    # A plain class with the fields of a frozen dataclass: importing dataclasses (inspect, ast, dis, ...) costs a
    # fresh process that serves a series from the table more than reading the series.
    def __init__(self, _composition, generators, max_degree, _scaled, _domain=None, _sympy=None, _cache=None):
        put = object.__setattr__
        put(self, "_composition", _composition)  # Composition, or the light Word it is built from when asked
        put(self, "generators", generators)
        put(self, "max_degree", max_degree)
        # degree -> (denominator, ((numerator: int or field element, tree), ...)); table.Served: built when asked
        put(self, "_scaled", _scaled)
        put(self, "_domain", _domain)  # None: QQ; else the algebraic field of the coefficients
        put(self, "_sympy", {} if _sympy is None else _sympy)  # degree -> ((sympy coefficient, tree), ...), lazily
        put(self, "_cache", {} if _cache is None else _cache)

    def __setattr__(self, name, value):
        raise AttributeError(f"cannot assign to field {name!r}: a FormalBCH is immutable")

    def __delattr__(self, name):
        raise AttributeError(f"cannot delete field {name!r}: a FormalBCH is immutable")

    @property
    def composition(self):
        """The :class:`~nambu_bch.integrators.composition.Composition` (built from the word on first use)."""
        comp = self._composition
        if isinstance(comp, Word):
            comp = comp.composition()
            object.__setattr__(self, "_composition", comp)
        return comp

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): per degree the common denominator and ``(numerator, tree)`` pairs."""
        return self.composition, self.generators, self.max_degree, dict(self._scaled), str(self.domain)

    def scaled_terms(self, degree: int):
        """``(D, [(n, tree), ...])`` with coefficients ``n / D``: ``n`` a Python int (rational series) or an
        element of the algebraic field :attr:`domain`, ``D`` a positive int common to the degree."""
        den, items = self._scaled.get(degree, (1, ()))
        return den, list(items)

    def scaled_words(self, degree: int):
        """``(D, [(n, word), ...])``: :meth:`scaled_terms` with each bracket tree replaced by its Lyndon word (the
        tree's leaves, a tuple of piece numbers; ``P_w`` is the standard bracketing of ``w``).

        >>> formal_bch("12", 3).scaled_words(3)
        (36, [(3, (1, 1, 2)), (3, (1, 2, 2))])
        """
        den, items = self.iter_scaled_words(degree)
        return den, list(items)

    def iter_scaled_words(self, degree: int):
        """``(D, iterator of (n, word))``: :meth:`scaled_words` one pair at a time (a long series written out
        without holding a degree's pairs at once).

        A series served from the table builds each word from the table's standard factors, one concatenation
        of two shorter words, without building or walking a tree.
        """
        scaled = self._scaled
        if isinstance(scaled, _table.Served):
            return scaled.words(degree) if degree in scaled else (1, iter(()))
        den, items = scaled.get(degree, (1, ()))
        return den, ((n, tree_leaves(t)) for n, t in items)

    @property
    def domain(self):
        """The coefficient field: ``QQ``, or ``QQ(2^(1/3))`` etc. for algebraic compositions."""
        from sympy.polys.domains import QQ

        return self._domain if self._domain is not None else QQ

    @property
    def _elements(self) -> dict:
        if "elements" not in self._cache:
            import sympy
            from sympy.polys.domains import QQ

            K = self.domain
            out = {}
            for d, (den, items) in self._scaled.items():
                if self._domain is None:
                    out[d] = tuple((QQ(int(n), den), t) for n, t in items)
                else:
                    inv = K.convert(sympy.Rational(1, den))
                    out[d] = tuple((n * inv, t) for n, t in items)
            self._cache["elements"] = out
        return self._cache["elements"]

    @property
    def _terms(self) -> dict:
        for d, items in self._elements.items():
            if d not in self._sympy:
                to_sympy = _element_to_sympy(self._domain)
                self._sympy[d] = tuple((to_sympy(c), t) for c, t in items)
        return self._sympy

    def terms(self, degree: int) -> list:
        """``[(coefficient, tree), ...]`` of the degree-``degree`` part, Lyndon words in lexicographic order.

        ``coefficient`` is an exact sympy number; ``tree`` a generator (piece
        number) or a 2-tuple ``(left, right)`` = ``[left, right]``.
        """
        if not isinstance(degree, int) or degree < 1 or degree > self.max_degree:
            raise InvalidOrderError(f"degree must be an integer in 1..{self.max_degree} (the computed range), got {degree!r}")
        if degree not in self._scaled:
            return []
        return list(self._terms[degree])

    def words(self, degree: int) -> list:
        """``[(coefficient, lyndon_word), ...]`` with words as tuples of piece numbers."""
        return [(c, tree_leaves(t)) for c, t in self.terms(degree)]

    @property
    def degrees(self) -> tuple:
        """Degrees ``1..max_degree`` whose part is non-zero (odd only for a symmetric composition)."""
        return tuple(d for d in range(1, self.max_degree + 1) if d in self._scaled)

    def all_terms(self) -> list:
        """``[(coefficient, tree), ...]`` over all degrees, lowest first."""
        return [t for d in range(1, self.max_degree + 1) for t in self._terms.get(d, ())]

    def __len__(self):
        scaled = self._scaled
        if isinstance(scaled, _table.Served):  # counted without building the terms
            return sum(scaled.count(d) for d in scaled)
        return sum(len(v[1]) for v in scaled.values())

    def to_latex(self, names=None, step="h") -> str:
        r"""The series term by term in an ``aligned`` block, e.g. ``X_{\rm eff} &= X_{1} + X_{2} - \frac{h^{2}}{24}[...] ...``.

        Long series continue on ``&\quad`` lines (see :mod:`nambu_bch.printing`).

        Parameters
        ----------
        names : dict or callable, optional
            LaTeX name of each generator (default ``X_{k}``).
        step : str or None
            With a step symbol the series is printed as ``X_eff`` (degree ``d`` carries
            ``step^(d-1)``, Eq. BCH2); with ``None`` as ``log Phi`` of the bare generators.
        """
        import sympy

        from ..printing import bracket_sum

        items = [(c, tree, d - 1 if step else 0) for d in range(1, self.max_degree + 1) for c, tree in self._terms.get(d, ())]
        lhs = r"X_{\rm eff}" if step else r"\log \Phi"
        remainder = self._composition.remainder_power(self.max_degree - 1) if step else None
        return bracket_sum(lhs, items, names, remainder, sympy.Symbol(step or "h"))

    def to_text(self) -> str:
        """``X_eff = X1 + X2 + (-1/24)*h**2*[X1,[X1,X2]] + ... + O(h^4)``, one term per Lyndon bracket.

        >>> print(formal_bch("TVT", 3))                                           # Eq. (BCH1)
        X_eff = X1 + X2 + (-1/24)*h**2*[X1,[X1,X2]] + (1/12)*h**2*[[X1,X2],X2] + O(h^4)
        """

        def bracket(tree):
            return f"[{bracket(tree[0])},{bracket(tree[1])}]" if isinstance(tree, tuple) else f"X{tree}"

        parts = []
        for d in range(1, self.max_degree + 1):
            if self._domain is None:  # rationals: a Fraction prints as the sympy Rational does, without sympy
                den, items = self._scaled.get(d, (1, ()))
                terms = [(Fraction(n, den), tree) for n, tree in items]
            else:
                terms = self._terms.get(d, ())
            for c, tree in terms:
                factor = "" if d == 1 else ("h*" if d == 2 else f"h**{d - 1}*")
                parts.append(("" if c == 1 else f"({c})*") + factor + bracket(tree))
        tail = f" + O(h^{self._composition.remainder_power(self.max_degree - 1)})"
        return "X_eff = " + (" + ".join(parts) or "0") + tail

    def __repr__(self):
        return f"FormalBCH({self._composition.name!r}, max_degree={self.max_degree}, terms={len(self)})"


def formal_bch(comp, max_degree: int, n_pieces: int | None = None) -> FormalBCH:
    """The BCH series ``log(prod_j exp(c_j X_{k_j}))`` through ``max_degree``, exact, in the Lyndon basis.

    Parameters
    ----------
    comp : Composition, word, alias or ``"k:c,..."`` spec
        The pieces act as free generators, named by their 1-based numbers.
    max_degree : int
        Highest degree kept (``X_eff`` through ``h^(max_degree - 1)``).
    n_pieces : int, optional
        Needed only by ``lie-trotter`` / ``strang`` specs.

    Returns
    -------
    FormalBCH

    Examples
    --------
    Eq. (BCH1) for position Verlet ``e^{hX_T/2} e^{hX_V} e^{hX_T/2}`` (T = 1, V = 2):

    >>> B = formal_bch("121", 3)
    >>> B.degrees
    (1, 3)
    >>> B.terms(3)
    [(-1/24, (1, (1, 2))), (1/12, ((1, 2), 2))]
    >>> formal_bch("12", 2).terms(2)     # Lie-Trotter: X_1 + X_2 + [X_1, X_2]/2
    [(1/2, (1, 2))]
    """
    # a plain word with rational coefficients is read without sympy: the table's series need nothing more
    word = parse_word(comp, n_pieces) if isinstance(comp, str) else None
    if word is not None:
        served = _from_table(word, [c.numerator for c in word.coefficients],
                             [c.denominator for c in word.coefficients], max_degree)
        if served is not None:
            return served
        comp = word.composition()
    else:
        from ..integrators.composition import Composition
        from ..integrators.composition import composition as make_composition

        comp = make_composition(comp, n_pieces)
        if not isinstance(comp, Composition) or not comp.pieces:
            raise InvalidCompositionError(f"formal_bch needs a composition with at least one factor, got {comp!r}")
    return _formal(comp, max_degree, True)


def _formal_engine(comp, max_degree: int) -> FormalBCH:
    """:func:`formal_bch` computed by the engines, never read from the table (the table's tool and tests)."""
    return _formal(comp, max_degree, False)


def _from_table(comp, numerators, denominators, max_degree):
    """The series from the shipped table (:mod:`nambu_bch.bch.table`), or ``None`` where it is not served.

    ``comp`` is a Composition or a :class:`~nambu_bch.bch.light.Word`; its coefficients are the rationals
    ``numerators[i] / denominators[i]``.  The table holds the two-generator products of two or three
    factors; a degree it holds is served whatever the engines' size limits (without numba the dense engine
    stops at degree 19)."""
    pieces = comp.pieces
    if len(pieces) > 3:
        return None
    generators = tuple(sorted(set(pieces)))
    if len(generators) != 2:
        return None
    n = _positive_degree(max_degree)
    if n > _table.max_degree():
        return None
    q = lcm(*denominators)
    values = [a * (q // b) for a, b in zip(numerators, denominators)]
    dens = [lcm(*range(1, n + 1))]  # D_d = d! lcm(1..n) q^d, as the engines have it (_formal)
    for d in range(1, n + 1):
        dens.append(dens[-1] * d * q)
    letters = [generators.index(k) for k in pieces]
    served = _table.serve(letters, values, q, generators, n, dens)
    return None if served is None else FormalBCH(comp, generators, n, served, None)


def _formal(comp, max_degree, use_table: bool) -> FormalBCH:
    generators = tuple(sorted(set(comp.pieces)))
    g = len(generators)
    scalars = _Scalars(tuple(comp.coefficients))
    if use_table and scalars.K is None:
        served = _from_table(comp, scalars.values, [scalars.q] * len(scalars.values), max_degree)
        if served is not None:
            return served
    from ..compiled import numba_available  # the engines' concern: a served series does not look for numba

    sparse = scalars.K is None and numba_available()
    n = check_degree(max_degree, g, dense=not sparse)
    # low degrees: the dense engine answers in milliseconds without loading numba (~0.4 s in a fresh process)
    sparse = sparse and (
        n >= SPARSE_FROM_DEGREE or g**n > DENSE_COLD_WORDS or _sparse_engine_loaded() or not _fits_dense(g, n)
    )
    if sparse:
        from .modular import lyndon_numerators  # compiled (numba); without it the dense engine below

        big = lcm(*range(1, n + 1))
        dens = [factorial(d) * big * scalars.q**d for d in range(n + 1)]
        letters = [generators.index(k) for k in comp.pieces]
        with no_full_collection():
            numerators = lyndon_numerators(letters, scalars.values, scalars.q, g, n, dens)
            if numerators is not None:
                trees = _duval_trees(g, n, generators)
                elements = {}
                for d, items in numerators.items():
                    index, values = zip(*items)
                    elements[d] = (dens[d], tuple(zip(values, map(trees.__getitem__, index))))
                return FormalBCH(comp, generators, n, elements, None)
        check_degree(n, g, dense=True)  # coefficients too large for the primes: Python ints, dense engine
    return _formal_dense(comp, generators, n)


def _sparse_engine_loaded() -> bool:
    """The compiled engine has run in this process (numba's start-up is paid)."""
    modular = sys.modules.get("nambu_bch.bch.modular")
    return modular is not None and modular.runs > 0


def _formal_dense(comp, generators: tuple, n: int) -> FormalBCH:
    """The dense engine: associative log over all ``g^d`` words, then the Lyndon projection (module docstring)."""
    g = len(generators)
    # the associative log depends on the word only up to renaming letters (the six paper words are one
    # scheme): compute it once per pattern, letters numbered by first appearance, then permute the digits
    first = list(dict.fromkeys(comp.pieces))
    pattern = tuple(first.index(k) for k in comp.pieces)
    scalars, L, dens = _pattern_log(pattern, tuple(comp.coefficients), g, n)
    rank = [generators.index(k) for k in first]
    if rank != sorted(rank):
        L = [_permute_letters(v, d, g, rank) for d, v in enumerate(L)]
    elements = {}
    for d in range(1, n + 1):
        coords = _lyndon_coordinates(L[d], d, g)
        if coords:
            trees = _lyndon_trees(g, d, generators)
            elements[d] = (dens[d], tuple((c, trees[k]) for k, c in coords))
    return FormalBCH(comp, generators, n, elements, scalars.K)


@lru_cache(maxsize=32)
def _duval_trees(g: int, n: int, generators: tuple) -> tuple:
    """Standard bracketings of all Lyndon words of length ``<= n``, in the Duval order of
    :func:`~nambu_bch.bch.modular.lyndon_table` (children are shorter: built by length)."""
    import numpy as np

    from .modular import lyndon_table

    words, lengths, left, right = lyndon_table(g, n)
    first, left, right = words[:, 0].tolist(), left.tolist(), right.tolist()
    trees = [None] * len(first)
    for i in np.argsort(lengths, kind="stable").tolist():
        trees[i] = generators[first[i]] if right[i] < 0 else (trees[left[i]], trees[right[i]])
    return tuple(trees)
