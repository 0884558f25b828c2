"""Exact polynomial invariants ``I(Phi_h(x)) = I(x)`` of a composed map.

Method.  Take the ansatz ``I = sum_mu c_mu x^mu`` over all monomials of total
degree ``1..d`` in the coordinates (constants are trivially invariant and left
out: :class:`~nambu_bch.algebra.ansatz.Ansatz` with ``lowest=1``, graded order),
with unknown coefficients ``c_mu`` in the field ``K = QQ(parameters, h)``.
Substituting the exact composed map (:func:`~nambu_bch.integrators.composed_map`)
makes ``I(Phi_h(x)) - I(x)`` a polynomial in ``x`` whose coefficients are
linear in the ``c_mu``; setting them to zero is a linear system over ``K``,
solved exactly by a Gauss-Jordan nullspace over ``K`` (:mod:`nambu_bch.algebra.elimination`).  Its
rows span *all* invariants of degree ``<= d`` (modulo constants).  Maps with
exponentials (Lotka-Volterra) are handled by treating the combined
exponential of each term as one more generator, which finds ``G = x1 x2 x3``
there (sound; identities between different exponentials are not used).

Shortcuts, same results.  "No invariant of degree ``<= d``" is certified by the matrix's full column rank at
one rational point of ``(parameters, h)``, built over ``QQ`` before any image over ``K``
(:func:`_no_invariant_at_a_point`; the rigid body's answer); a map ``x_i -> x_i exp(a_i)`` (Lotka-Volterra) has
``x^mu`` invariant exactly when ``<mu, a> = 0``, read off the exponents without expanding images.

Normalisation.  The invariants form a ``K``-vector space ``V`` of dimension
``r``, so "the" conserved quantity that tends to ``H`` as ``h -> 0`` is fixed
only by a rule.  For each target ``T`` (``H``, then ``G``) we take every
``I`` in ``V`` that agrees with ``T`` exactly on ``r`` monomials (these
determine ``I``), keep those with ``I -> T`` as ``h -> 0``, and choose the one
whose correction ``I - T``

1. has the fewest terms (the sparsest correction),
2. is polynomial in ``h`` of the lowest degree (no ``1/(1 - omega^2 h^2/4)``),
3. sits on the highest-degree monomials (the low-degree part of ``T``, such as
   the ``x3`` of ``G = x3 - x1^2``, is kept), then a fixed monomial order.

This rule reproduces every choice of the paper: Eq. (CQPV) for position
Verlet on ``ho``, Eqs. (CQ12321H), (CQ12321G) and each row of Table (table) for
the six words on ``ho3``; these are exactly the normalisations for which
``X_eff = F(omega h) X_{H_c,G_c}`` (Eq. Xeff2) holds.  It is deliberately not the
shadow routes' canonical-member rule (:mod:`nambu_bch.algebra.ansatz`): that one
fixes a member of an affine family modulo a gauge, this one a vector of ``V``
against a target, with ``h``-dependent coefficients.

References
----------
Horikoshi, Eqs. (CQPV), (CQ12321H), (CQ12321G), Table (table); Kobayashi (2021).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from itertools import combinations
from math import comb, prod

import sympy
from sympy.polys.domains import QQ
from sympy.polys.rings import PolyRing

from ..algebra import PolynomialAlgebra
from ..systems.spec import as_system
from ..algebra.ansatz import Ansatz, Rows
from ..algebra.zero import is_zero
from ..algebra.elimination import SparseMatrix, nullspace, rank, solve_affine
from ..errors import InvalidOrderError, InvalidSystemError, NoExactResultError, ResourceLimitError
from ..integrators import composed_map, composition_for
from ..integrators.flows import exact_flow
from ..parsing import as_expression
from ..printing import Printable, aligned, series_text, series_tokens
from ..values import ValueEquality

H_STEP = sympy.Symbol("h")
#: Most candidate pivot sets (r-subsets of monomials, in graded order) tried by the normalisation.
_MAX_CANDIDATES = 4000
#: Largest ansatz degree accepted (the ansatz has C(N + d, d) unknowns).
MAX_DEGREE = 8
#: Most terms, summed over the ansatz monomials, of the images ``x^mu(Phi_h(x))``, bounded from the sub-flows
#: before the map is composed (:func:`composed_map_shape`, :func:`image_terms`): ho3's 12321 at degree 8 is at most 35 141
#: (34 265 on the composed map, 15 s), the rigid body's 12321 at degree 3 at most 39 616 (28 963, 13 s), at
#: degree 4 at most 153 723 (142 455, 200 s) and is refused.
MAX_IMAGE_TERMS = 40_000


def _word_name(comp) -> str:
    return comp.name or "".join(map(str, comp.pieces))


def _total_degree(expr, coords) -> int:
    try:
        return sympy.Poly(sympy.expand(expr), *coords).total_degree()
    except sympy.PolynomialError as exc:
        raise InvalidSystemError(f"{expr} is not a polynomial in {coords}; polynomial invariants need polynomial Hamiltonians") from exc


class _Setup:
    """The ring ``K[x]`` with ``K = QQ<ext>(parameters, h)`` and the map in it, for an ansatz of ``degree``."""

    def __init__(self, system, comp, degree):
        self.system = system
        self.coords = system.coordinates
        # the package's exact ring, with h among the parameters: K = QQ<ext>(parameters, h)
        algebra = PolynomialAlgebra(self.coords, (*system.parameters, H_STEP), extension=comp.extension)
        self.K, self.R, self.gens = algebra.domain, algebra.ring, algebra.gens
        flows = [exact_flow(system.splitting[k], self.coords) for k, _ in comp.factors()]
        if any(e.has(sympy.sin, sympy.cos, sympy.tan) for f in flows for e in f.expressions):
            # rotations (Lie-Poisson rigid body): powers of the composed cos/sin expressions blow up and the
            # exponential-generator bookkeeping of _exp_images does not apply; refused before composing (bounded work)
            raise NoExactResultError(
                f"the composed map on {system.name} has trigonometric sub-flows (rotations); "
                "polynomial invariants are not searched for it")
        if all(f.polynomial for f in flows):
            # bounded work: the images' size is bounded from the sub-flows before the map is composed (composing
            # the rigid body's 12321 alone takes ~0.5 s, and a longer word or a larger system is the hang itself)
            counts, degrees = composed_map_shape(flows, self.coords)
            size = image_terms(counts, degrees, self.monomials(degree))
            if size > MAX_IMAGE_TERMS:
                raise ResourceLimitError(
                    f"an invariant ansatz of degree {degree} on {system.name} with the word {_word_name(comp)} "
                    f"needs images of up to {size} terms, estimated from the word's {len(flows)} sub-flows "
                    f"(at most {MAX_IMAGE_TERMS}); lower the degree or shorten the word"
                )
        self.polynomial = all(f.polynomial for f in flows)
        phi = composed_map(system.splitting, comp)
        self.phi_exprs = tuple(sympy.sympify(e, strict=True) for e in phi)

    @cached_property
    def phi(self):
        """The map in ``K[x]``, or ``None`` when it is not polynomial there (exp(...) flows: :func:`_exp_images`).

        Converted on first use: a search that :func:`_no_invariant_at_a_point` settles never needs it."""
        try:
            return tuple(self.R.from_expr(e) for e in self.phi_exprs)
        except Exception:  # CoercionFailed & co: exp(...) flows (Lotka-Volterra), see _exp_images
            return None

    def monomials(self, degree):
        """The ansatz's monomials: total degree ``1..degree``, graded (:mod:`nambu_bch.algebra.ansatz`)."""
        return list(Ansatz(len(self.coords), degree, lowest=1, order="graded").monomials)


def composed_map_shape(flows, coords) -> tuple:
    """Upper bounds ``(counts, degrees)`` on the number of terms and the total degree in ``coords`` of each
    component of the composition of the polynomial ``flows`` (applied first to last), without composing them.

    Composing ``f`` after a map whose component ``j`` has at most ``t_j`` terms of degree at most ``d_j`` gives
    ``f_i(x)`` with, per monomial ``x^m`` of ``f_i``, at most ``min(prod_j t_j^m_j, C(N + <m, d>, N))`` terms of
    degree at most ``<m, d>``; summing over the monomials (and capping by ``C(N + deg, N)``) bounds the terms of
    ``f_i``.  The bounds ignore cancellation, so they are never below the composed map's true shape.
    """
    n = len(coords)
    counts, degrees = [1] * n, [1] * n  # the identity map
    monomials = {}  # a word repeats its pieces: each flow's monomials are read once
    for flow in flows:
        if id(flow) not in monomials:
            monomials[id(flow)] = [sympy.Poly(sympy.expand(e), *coords).monoms() for e in flow.expressions]
        new_counts, new_degrees = [], []
        for monos in monomials[id(flow)]:
            count, degree = 0, 0
            for m in monos:
                d = sum(k * dj for k, dj in zip(m, degrees))
                count += min(prod(t**k for t, k in zip(counts, m)), comb(n + d, n))
                degree = max(degree, d)
            new_counts.append(min(count, comb(n + degree, n)))
            new_degrees.append(degree)
        counts, degrees = new_counts, new_degrees
    return counts, degrees


def image_terms(counts, degrees, monos) -> int:
    """An upper bound on the terms of all images ``x^mu(Phi_h(x))`` when component ``i`` of ``Phi_h`` has at most
    ``counts[i]`` terms of total degree at most ``degrees[i]``: per ``mu`` the smaller of the product of the
    components' term counts and the number of monomials of the image's degree."""
    n = len(counts)
    return sum(min(prod(t**k for t, k in zip(counts, mu)), comb(n + sum(k * d for k, d in zip(mu, degrees)), n))
               for mu in monos)


def _ring_images(R, phi, monos):
    """``{monomial: coefficient}`` of ``x^mu(Phi_h(x)) - x^mu`` for each ``mu``, in the sparse ring ``R``."""
    powers = [[R.one] for _ in phi]

    def power(i, k):
        while len(powers[i]) <= k:
            powers[i].append(powers[i][-1] * phi[i])
        return powers[i][k]

    columns = []
    for mu in monos:
        image = R.one
        for i, k in enumerate(mu):
            if k:
                image = image * power(i, k)
        columns.append(dict(image - R({mu: R.domain.one})))
    return columns


def _exp_images(setup: _Setup, monos):
    """The same for a map with exponentials (Lotka-Volterra): exponential factors are combined per term
    (``exp(a) exp(b) -> exp(a + b)``) and then treated as independent generators.  A vanishing result is
    therefore an exact identity (the search is sound); an invariant that needs an identity between
    different exponentials would be missed."""
    coords = setup.coords
    columns = []
    for mu in monos:
        image = sympy.Integer(1)
        for e, k in zip(setup.phi_exprs, mu):
            image *= e**k
        diff = sympy.expand(sympy.powsimp(image, combine="exp"), power_exp=False) - sympy.Mul(
            *[c**k for c, k in zip(coords, mu)])
        column: dict = {}
        for term in sympy.Add.make_args(sympy.expand(diff, power_exp=False)):
            term = sympy.powsimp(term, combine="exp")
            coeff, xs, exps = sympy.Integer(1), [0] * len(coords), sympy.Integer(1)
            for f in sympy.Mul.make_args(term):
                base, e = f.as_base_exp()
                if base in coords and e.is_Integer:
                    xs[coords.index(base)] += int(e)
                elif f.has(*coords):
                    exps *= f
                else:
                    coeff *= f
            key = (tuple(xs), exps)
            try:
                value = setup.K.from_sympy(coeff)
            except Exception as exc:  # noqa: BLE001 - an exotic coefficient: give up on this map
                raise NoExactResultError(
                    f"the composed map on {setup.system.name} is neither polynomial nor a product of "
                    "exponentials; polynomial invariants are not searched for it"
                ) from exc
            column[key] = column.get(key, setup.K.zero) + value
        columns.append({k: v for k, v in column.items() if v})
    return columns


#: The rational points ``(parameters..., h)`` at which :func:`_no_invariant_at_a_point` specialises the map, in order.
_POINTS = ((3, 5, 7, 11, 13, 17, 19, 23, 29, 31), (37, 41, 43, 47, 53, 59, 61, 67, 71, 73))


def _no_invariant_at_a_point(setup: _Setup, monos) -> bool:
    """``True`` when the map has no polynomial invariant on ``monos`` (the ansatz), certified at one rational point.

    The search's matrix ``M`` (column ``mu``: the coefficients of ``x^mu(Phi_h(x)) - x^mu``) has entries in
    ``K = QQ(parameters, h)``, each an integer polynomial in the coefficients of the map ``Phi_h``.  At a
    rational point ``a`` of ``(parameters, h)`` where no denominator of the map vanishes, evaluation is a
    ring homomorphism from the rational functions defined at ``a`` to ``QQ``, so the matrix built from the
    specialised map ``Phi_a`` is ``M(a)``, and every minor of ``M(a)`` is the value at ``a`` of the same minor of
    ``M``.  If ``M(a)`` has full column rank, some maximal minor of ``M`` is non-zero, ``M`` has full column rank
    over ``K`` and its nullspace, the space of invariants of the ansatz, is ``{0}``.  Specialising can only lower
    the rank, so a rank-deficient ``M(a)`` proves nothing: the caller then eliminates over ``K``.  (The same
    argument as :func:`nambu_bch.algebra.elimination.rank`'s full-rank test at a point, applied before the
    images are built: over ``QQ`` they cost no polynomial gcds.)

    The specialised map is evaluated node by node from its sympy form in exact arithmetic (:func:`_at_point`); a
    point where some node divides by zero is not used (the next one is).  ``False`` (no certificate) when no
    point qualifies or the map is not built from rational numbers, symbols, sums, products and integer powers
    (an algebraic number such as ``2**(1/3)``, a constant such as ``exp(2)``).
    """
    symbols = (*setup.system.parameters, H_STEP)
    ring = PolyRing(setup.coords, QQ)
    for point in _POINTS:
        if len(symbols) > len(point):
            return False
        values = {s: ring.ground_new(QQ(v)) for s, v in zip(symbols, point)}
        values.update(zip(setup.coords, ring.gens))
        try:
            phi = tuple(_at_point(e, values, ring) for e in setup.phi_exprs)
        except ZeroDivisionError:
            continue  # a denominator vanishes here: the next point
        except _NotRational:
            return False
        rows = Rows()
        vectors = [rows.vector(c) for c in _ring_images(ring, phi, monos)]
        return bool(len(rows)) and rank(SparseMatrix.from_columns(vectors, len(rows), QQ)) == len(monos)
    return False


class _NotRational(Exception):
    """A node that is not a rational number, a symbol, a sum, a product or an integer power."""


def _at_point(expr, values, ring):
    """``expr`` in ``ring`` (a polynomial ring over ``QQ``) with the symbols replaced by ``values`` (ring elements).

    Evaluated node by node: ``ZeroDivisionError`` when a negative power's base is zero at the point, so a value
    returned is the value there of the rational function ``expr`` (each node's); :class:`_NotRational` for any
    other kind of node."""
    if expr.is_Symbol:
        if expr not in values:
            raise _NotRational(expr)
        return values[expr]
    if expr.is_Rational:
        return ring.ground_new(QQ(int(expr.p), int(expr.q)))
    if expr.is_Add or expr.is_Mul:
        parts = [_at_point(a, values, ring) for a in expr.args]
        out = parts[0]
        for part in parts[1:]:
            out = out + part if expr.is_Add else out * part
        return out
    if expr.is_Pow and expr.exp.is_Integer:
        base, k = _at_point(expr.base, values, ring), int(expr.exp)
        if k >= 0:
            return base**k
        if not base.is_ground:
            raise _NotRational(expr)  # a coordinate in a denominator: not a polynomial map
        return ring.ground_new(QQ.one / base.LC) ** -k  # QQ raises ZeroDivisionError at a zero base
    raise _NotRational(expr)


def _exponents(setup: _Setup):
    """``(a_1, ..., a_N)`` when each component of the map is ``x_i`` times exponentials, ``x_i exp(a_i)`` (the
    Lotka-Volterra pieces ``X_{x_i, G}`` compose to such maps), else ``None``."""
    exponents = []
    for x, e in zip(setup.coords, setup.phi_exprs):
        factors = sympy.Mul.make_args(e)
        if [f for f in factors if not isinstance(f, sympy.exp)] != [x]:
            return None
        exponents.append(sympy.Add(*[f.args[0] for f in factors if f != x]))
    return exponents


def _invariant_basis(setup: _Setup, degree: int):
    """Polynomials (ring elements) spanning the invariants of degree ``1..degree``."""
    monos = setup.monomials(degree)
    if setup.polynomial and _no_invariant_at_a_point(setup, monos):
        return []
    R, phi = setup.R, setup.phi
    exponents = _exponents(setup) if phi is None else None
    if exponents is not None:
        # x^mu(Phi_h(x)) - x^mu = x^mu (exp(<mu, a>) - 1): a column of _exp_images is zero when <mu, a> expands to
        # zero and otherwise alone on its row (x^mu, 1), a pivot; the nullspace is the zero columns' unit vectors.
        # expand is additive, so each a_i is expanded once and <mu, a> is their sum with integer weights.
        expanded = [sympy.expand(a, power_exp=False) for a in exponents]
        return [R({mu: setup.K.one}) for mu in monos if sympy.Add(*[k * a for k, a in zip(mu, expanded)]) == 0]
    columns = _ring_images(R, phi, monos) if phi is not None else _exp_images(setup, monos)
    rows = Rows()
    vectors = [rows.vector(diff) for diff in columns]
    if not len(rows):  # the map is the identity: every monomial is invariant
        return [R({mu: setup.K.one}) for mu in monos]
    kernel = nullspace(SparseMatrix.from_columns(vectors, len(rows), setup.K))
    return [R({monos[c]: v for c, v in sorted(vec.items()) if v}) for vec in kernel]


def _vanishes_at_h0(K, c) -> bool:
    """``c`` in ``K = QQ(params, h)`` is regular at ``h = 0`` and vanishes there (``h`` is the last generator)."""
    hidx = len(K.gens) - 1
    num_at_0 = any(m[hidx] == 0 for m in c.numer.keys())
    den_at_0 = any(m[hidx] == 0 for m in c.denom.keys())
    return den_at_0 and not num_at_0


def _h_degrees(K, c):
    hidx = len(K.gens) - 1
    dnum = max((m[hidx] for m in c.numer.keys()), default=0)
    dden = max((m[hidx] for m in c.denom.keys()), default=0)
    return dden, dnum


def _normalise(setup: _Setup, basis, target):
    """The invariant ``I`` in span(basis) with ``I -> target`` as ``h -> 0`` (rule in the module docstring)."""
    R, K = setup.R, setup.K
    r = len(basis)
    if r == 0:
        return None
    T = R.from_expr(target)
    support = sorted(set().union(*(set(b.keys()) for b in basis), set(T.keys())),
                     key=lambda m: (sum(m), m))
    best, best_score = None, None
    count = 0
    for S in combinations(support, r):
        count += 1
        if count > _MAX_CANDIDATES:
            break
        columns = [{i: b.get(mu, K.zero) for i, mu in enumerate(S)} for b in basis]
        sol = solve_affine(SparseMatrix.from_columns(columns, r, K), [{i: T.get(mu, K.zero) for i, mu in enumerate(S)}],
                           certificate=False)
        if sol.kernel:  # the r x r minor on S is singular
            continue
        coeffs = [sol.particular[0].get(j, K.zero) for j in range(r)]
        I = R.zero
        for c, b in zip(coeffs, basis):
            I = I + b * c
        D = I - T
        if not I or not all(_vanishes_at_h0(K, c) for c in D.values()):
            continue
        degs = [_h_degrees(K, c) for c in D.values()]
        score = (
            len(D),
            sum(d for d, _ in degs),
            max((n for _, n in degs), default=0),
            -sum(sum(m) for m in D.keys()),
            sorted(D.keys()),
        )
        if best_score is None or score < best_score:
            best, best_score = I, score
    return best


def has_radicals(expr) -> bool:
    """``expr`` contains an algebraic number such as ``2**(1/3)`` (triple-jump coefficients)."""
    return any(p.base.is_Number and not p.exp.is_Integer for p in expr.atoms(sympy.Pow))


def _clean(expr, coords=()):
    """The expanded sympy form (what ``to_dict`` prints and ``sympify`` reads back).

    Coefficients in ``QQ<2**(1/3)>(params, h)`` come out of the ring as sums of
    fractions with radicals in the denominators; they are rationalised and
    factored monomial by monomial.
    """
    expr = sympy.expand(expr)
    if not coords or not has_radicals(expr):
        return expr
    poly = sympy.Poly(expr, *coords)
    return sympy.Add(*[sympy.factor(sympy.radsimp(sympy.together(c))) * sympy.Mul(*[x**k for x, k in zip(coords, mon)])
                       for mon, c in poly.terms()])


@dataclass(frozen=True, eq=False)
class ConservedQuantities(Printable, ValueEquality):
    """Exact polynomial invariants of a composed map, normalised to the Hamiltonians.

    Attributes
    ----------
    H_c, G_c : sympy expressions in the coordinates, parameters and ``h``
        (``G_c`` is ``None`` for N = 2; either is ``None`` when no invariant of
        the ansatz degree tends to ``H`` / ``G``).
    hamiltonians_c : tuple, one normalised invariant per Hamiltonian (N > 3 too)
    quantities : tuple of sympy expressions, a basis of all invariants found
        (constants excluded), starting with the normalised ones
    degree : int, the ansatz degree
    system, word : what they were computed for
    exact : ``(quantities, normalised)`` as elements of the exact ring ``QQ<ext>(parameters, h)[coordinates]``
        (``normalised``: one per Hamiltonian, ``None`` where none tends to it), or None; when given, the sympy
        forms above are converted from them on first access (:func:`_sympy_forms`)
    """

    H_c: object
    G_c: object
    quantities: tuple
    degree: int
    system: object = field(repr=False)
    word: str = ""
    hamiltonians_c: tuple = ()
    exact: tuple | None = field(default=None, repr=False)

    #: the sympy forms, converted from ``exact`` on first access and not pickled
    _TRANSIENT = ("_value_cache", "_sympy")

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the ring elements when there are, else the invariants (expanded); the
        degree, the system and the word."""
        if self.exact is not None:
            return self.exact, self.degree, self.system, self.word
        return self.H_c, self.G_c, self.quantities, self.degree, self.system, self.word, self.hamiltonians_c

    def _forms(self) -> tuple:
        """``(quantities, hamiltonians_c)`` as sympy expressions, converted from :attr:`exact` once."""
        forms = self.__dict__.get("_sympy")
        if forms is None:
            forms = self.__dict__["_sympy"] = _sympy_forms(*self.exact, self.system.coordinates)
        return forms

    def to_dict(self) -> dict:
        """``{"H_c": str, "G_c": str, "series": {"H_c": {"0": str, "2": str}, ...}}`` (``sympy.sympify`` reads them back;
        ``None`` where absent; a series is ``None`` when the invariant is not polynomial in ``h``), after the system's
        part (:func:`nambu_bch.render.result_head`): ``nambu-bch conserved --format json`` prints exactly this dict."""
        from ..render import result_head

        out = result_head(self.system, self.word)
        out.update(H_c=None if self.H_c is None else str(self.H_c), G_c=None if self.G_c is None else str(self.G_c))
        out["series"] = {name: None if coefficients is None else {str(k): str(c) for k, c in coefficients.items()}
                         for name, coefficients in self.series().items()}
        return out

    def _pairs(self):
        """``[(latex name, text name, invariant or None, Hamiltonian)]``, one per Hamiltonian."""
        hams = self.system.hamiltonians
        values = self.hamiltonians_c or (self.H_c, self.G_c)[: len(hams)]
        if len(hams) <= 2:
            names = [("H", "H"), ("G", "G")][: len(hams)]
        else:
            names = [(f"H_{{{a + 1}}}", f"H{a + 1}") for a in range(len(hams))]
        return [(lx, tx, v, H) for (lx, tx), v, H in zip(names, values, hams)]

    def to_latex(self) -> str:
        r"""``H_c &= H + h^2(...)`` per Hamiltonian as the rows of Table (table), then ``H &= ...``."""
        coords = self.system.coordinates
        rows = []
        for lx, _, value, base in self._pairs():
            if value is None:
                rows.append((f"{lx}_{{c}}", ":", [rf"\text{{no polynomial invariant of degree }} \le {self.degree}"
                                                   rf"\text{{ tends to }} {lx}"]))
            else:
                rows.append((f"{lx}_{{c}}", "=", series_tokens(lx, value, base, coords)))
        rows += [(lx, "=", series_tokens("0", base, 0, coords)) for lx, _, _, base in self._pairs()]
        for row in rows[:-1]:
            row[2][-1] += ","
        return aligned(rows)

    def to_text(self) -> str:
        """``H_c = H + h**2*(...)`` per Hamiltonian, then the definitions."""
        coords = self.system.coordinates
        lines = [f"{tx}_c = " + (series_text(tx, value, base, coords) if value is not None
                                 else f"(no polynomial invariant of degree <= {self.degree} tends to {tx})")
                 for _, tx, value, base in self._pairs()]
        lines.append(", ".join(f"{tx} = {base}" for _, tx, _, base in self._pairs()))
        return "\n".join(lines)

    def series(self) -> dict:
        """``{"H_c": {k: c_k}, ...}``: the coefficient of ``h^k`` of each invariant (``None`` if not polynomial in h)."""
        from ..printing import h_coefficients

        out = {}
        for _, tx, value, _ in self._pairs():
            if value is not None:
                coefficients = h_coefficients(value, 0, self.system.coordinates)
                out[f"{tx}_c"] = None if coefficients is None else {k: sympy.expand(c) for k, c in coefficients}
        return out

    def check(self) -> bool:
        """Every quantity is exactly invariant under the composed map (re-derived by substitution)."""
        return all(is_invariant(self.system, self.word, q) for q in self.quantities)


def is_invariant(system, word, quantity) -> bool:
    """``I(Phi_h(x)) - I(x) == 0`` exactly, by substituting the composed map.

    ``quantity`` is a sympy expression or a string in the system's symbols and ``h``
    (read by :func:`~nambu_bch.parsing.parse_expression`, never evaluated).

    Examples
    --------
    >>> from nambu_bch import model
    >>> x1, x2, m, omega, h = sympy.symbols("x1 x2 m omega h")
    >>> H = x2**2/(2*m) + m*omega**2*x1**2/2
    >>> is_invariant(model("ho"), "121", H - omega**2*h**2*x2**2/(8*m))   # Eq. (CQPV)
    True
    """
    system = as_system(system)
    quantity = as_expression(quantity, system.symbols(), "quantity")
    phi = composed_map(system.splitting, word)
    image = quantity.subs(dict(zip(system.coordinates, phi)), simultaneous=True)
    return is_zero(image - quantity)


def conserved_quantities(system, word, degree=None) -> ConservedQuantities:
    """The exact polynomial conserved quantities of ``word`` on ``system``.

    Parameters
    ----------
    system : System
    word : str or Composition (``"12321"``, ``"121"``, ...)
    degree : int, optional
        Total degree of the ansatz in the coordinates; by default the largest
        degree of the Hamiltonians (2 for ``ho`` and ``ho3``).

    Returns
    -------
    ConservedQuantities with ``H_c -> H``, ``G_c -> G`` as ``h -> 0``,
    normalised by the rule in :mod:`nambu_bch.exact.invariants`.

    References
    ----------
    Horikoshi, Eqs. (CQPV), (CQ12321H), (CQ12321G), Table (table).

    Examples
    --------
    >>> from nambu_bch import model
    >>> conserved_quantities(model("ho"), "121").H_c          # Eq. (CQPV)
    -h**2*omega**2*x2**2/(8*m) + m*omega**2*x1**2/2 + x2**2/(2*m)
    >>> d = conserved_quantities(model("ho3"), "12321").to_dict()  # Eqs. (CQ12321H), (CQ12321G)
    >>> {k: d[k] for k in ("H_c", "G_c", "series")}
    {'H_c': 'm*omega**2*x3/2 + x2**2/(2*m)', 'G_c': 'h**2*x2**2/(4*m**2) - x1**2 + x3',
     'series': {'H_c': {'0': 'm*omega**2*x3/2 + x2**2/(2*m)'}, 'G_c': {'0': '-x1**2 + x3', '2': 'x2**2/(4*m**2)'}}}
    >>> print(conserved_quantities(model("ho3"), "12321"))        # as Table (table) writes it
    H_c = H
    G_c = G + h**2*x2**2/(4*m**2)
    H = m*omega**2*x3/2 + x2**2/(2*m), G = -x1**2 + x3
    """
    from ..systems.spec import as_system

    system = as_system(system)
    comp = composition_for(word, system)
    name = word if isinstance(word, str) else _word_name(comp)
    auto = max(_total_degree(Hk, system.coordinates) for Hk in system.hamiltonians)
    if degree is None:
        degree = auto
    if isinstance(degree, bool) or not isinstance(degree, int) or not 1 <= degree <= MAX_DEGREE:
        raise InvalidOrderError(f"degree of the invariant ansatz must be an integer in 1..{MAX_DEGREE}, got {degree!r}")
    return _conserved(system, name, comp, degree, auto)


@lru_cache(maxsize=64)
def _conserved(system, name, comp, degree, auto):
    setup = _Setup(system, comp, degree)
    basis = _invariant_basis(setup, degree)
    # the normalised H_c, G_c are looked for among the invariants of the Hamiltonians' degree
    low = basis if degree <= auto else _invariant_basis(setup, auto)
    normalised = tuple(_normalise(setup, low, Hk) for Hk in system.hamiltonians)
    chosen = [I for I in normalised if I is not None]
    # a basis that starts with the normalised quantities
    quantities = list(chosen)
    for b in basis:
        if _rank(setup, quantities + [b]) > len(quantities):
            quantities.append(_primitive(b))
    # the ring elements are the result; H_c, G_c, ... are their sympy forms, converted on first access
    return ConservedQuantities(None, None, (), degree, system, name, (), exact=(tuple(quantities), normalised))


def _sympy_forms(quantities, normalised, coordinates) -> tuple:
    """``(quantities, hamiltonians_c)``: the expanded sympy forms of exact invariants (:func:`_clean`)."""
    return (tuple(_clean(q.as_expr(), coordinates) for q in quantities),
            tuple(None if I is None else _clean(I.as_expr(), coordinates) for I in normalised))


def _form(name):
    """A field of :class:`ConservedQuantities` read from the sympy forms of its exact data when it has them."""

    def get(self):
        if self.__dict__.get("exact") is None:
            return self.__dict__["_" + name]
        quantities, hams = self._forms()
        return {"quantities": quantities, "hamiltonians_c": hams, "H_c": hams[0],
                "G_c": hams[1] if len(hams) > 1 else None}[name]

    def put(self, value):
        self.__dict__["_" + name] = value  # the frozen dataclass's __init__ assigns through object.__setattr__

    return property(get, put, doc=f"``{name}`` as sympy expressions (from :attr:`ConservedQuantities.exact`)")


# after @dataclass: the generated __init__ assigns through the properties (the defaults stay the fields' own)
for _name in ("H_c", "G_c", "quantities", "hamiltonians_c"):
    setattr(ConservedQuantities, _name, _form(_name))
del _name


def _rank(setup, polys) -> int:
    monos = sorted(set().union(*(set(p.keys()) for p in polys)))
    if not monos:
        return 0
    index = {m: j for j, m in enumerate(monos)}
    return rank(SparseMatrix.from_rows([{index[m]: c for m, c in p.items()} for p in polys], len(monos), setup.K))


def _primitive(p):
    """``p`` times the lcm of its coefficients' denominators, divided by their numerators' gcd."""
    K = p.ring.domain
    dom = K.get_ring()
    den, num = dom.one, dom.zero
    for c in p.values():
        den = dom.lcm(den, c.denom)
    for c in p.values():
        num = dom.gcd(num, (c * den).numer)
    scaled = p * K.convert(den) * (K.one / K.convert(num))
    lead = max(scaled.keys(), key=lambda m: (sum(m), m))
    return -scaled if K.numer(scaled[lead]).LC < 0 else scaled
