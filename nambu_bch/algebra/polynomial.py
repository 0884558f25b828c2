"""Exact sparse polynomials in the phase-space coordinates.

Coefficients live in the field of rational functions of the parameters
(``QQ(m, omega)``, so ``1/m`` is exact), optionally extended by algebraic
numbers such as ``2**(1/3)`` for triple-jump coefficients.  The ring may carry
extra *constant* generators (the step ``h``, the family parameter ``alpha``)
that are never differentiated.  Polynomials are sympy ``PolyElement``s: dicts
from exponent tuples to coefficients, as in ``sympy/polys/rings.py``.

Anything that is not a polynomial in this ring (``sin(x1)``, ``exp(h*x1)``)
stays a general sympy expression; :class:`PolynomialAlgebra` offers the same
operations (``diff``, ``is_zero``, ``to_sympy``) on both kinds so that callers
never need to ask which one they hold.
"""

from __future__ import annotations

from functools import cached_property, lru_cache

import sympy
from sympy.polys.domains import QQ, ZZ, FractionField
from sympy.polys.fields import FracElement, FracField
from sympy.polys.polyerrors import CoercionFailed, GeneratorsError, PolynomialError
from sympy.polys.polyutils import expr_from_dict
from sympy.polys.orderings import lex
from sympy.polys.rings import PolyElement, PolyRing

from ..checks import check_sequence
from ..errors import InvalidSystemError
from ..parsing import as_expression, as_symbols
from .backend import ExpressionBackend, PolynomialBackend
from .canonical import _NoKey, canonical_add, product_key, sort_key
from .fields import CoefficientField
from .ring import declare
from .zero import is_zero

_CONVERSION_ERRORS = (CoercionFailed, GeneratorsError, PolynomialError, ValueError, TypeError)


def _symbols(names, what="symbols") -> tuple[sympy.Symbol, ...]:
    return as_symbols(names, what, names=True)


def _symbol_powers(factors) -> dict | None:
    """``{symbol: exponent}`` of a product of powers of symbols with integer exponents, else ``None``."""
    out: dict = {}
    for f in factors:
        base, exp = f.as_base_exp() if isinstance(f, sympy.Basic) else (None, None)
        if not (isinstance(base, sympy.Symbol) and isinstance(exp, sympy.Integer)):
            return None
        out[base] = out.get(base, 0) + int(exp)
    return out


def _monomial_denominator_terms(c, gens, m, params, powers, memo, factors) -> list:
    """The terms of ``expand(c x^m prod(powers))`` for ``c = p / (d P^k)`` in ``QQ(params)``, a monomial denominator.

    Each term of ``p`` gives one product of a rational number and powers of distinct symbols (the
    parameters' exponents minus ``k``, the generators', ``powers``), which is how ``Mul`` flattens
    ``r P^e x^m / (d P^k)``: its canonical form is the coefficient (left out when it is one) followed
    by the powers sorted by ``Basic.compare`` (``sympy.core.mul._mulsort``; here by the equivalent key), so the
    object is built directly with ``Mul._from_args`` -- the same expression, without ``Mul.flatten``
    (:func:`_rational_term`; ``memo``, ``factors`` its memos).
    """
    [(dexp, d)] = c.denom.items()
    base = dict(powers)
    for s, e in zip(gens, m):
        if e:
            base[s] = base.get(s, 0) + e
    out = []
    for e, a in c.numer.items():
        exps = dict(base)
        for s, k, j in zip(params, e, dexp):
            if k != j:
                exps[s] = exps.get(s, 0) + k - j
        out.append(_rational_term(QQ.to_sympy(a / d), exps, memo, factors))
    return out


def _rational_term(coeff, exps: dict, memo: dict, factors: dict):
    """``coeff * prod(s^k)`` (a sympy rational, ``{symbol: integer exponent}``) as ``Mul`` keeps it: the coefficient
    (left out when it is one) followed by the powers in the order of ``Basic.compare``, without ``Mul.flatten``.

    The order is that of the powers' :func:`~nambu_bch.algebra.canonical.sort_key`; the term's own key (the
    product's class, its number of arguments, the arguments' keys) is recorded in ``memo`` (the sort-key memo of
    :func:`~nambu_bch.algebra.canonical.canonical_add`), and ``factors`` keeps ``(s, k) -> (key, power)``.
    """
    pairs = _power_pairs(exps, memo, factors)
    if coeff is not sympy.S.One:
        pairs.insert(0, (sort_key(coeff, memo), coeff))
    if not pairs:
        return coeff
    if len(pairs) == 1:
        return pairs[0][1]
    term = sympy.Mul._from_args([f for _, f in pairs], True)  # the ring's generators and parameters commute
    memo[term] = product_key(term, [k for k, _ in pairs])
    return term


def _first(pair):
    return pair[0]


def _power_pairs(exps: dict, memo: dict, factors: dict) -> list:
    """``[(sort key, s^k)]`` of ``{symbol: exponent}`` (zero exponents left out) in the order of ``Basic.compare``;
    ``factors`` memoises ``(s, k) -> (key, power)``."""
    pairs = []
    for s, k in exps.items():
        if k:
            power = factors.get((s, k))
            if power is None:
                value = s if k == 1 else sympy.Pow(s, k)
                power = factors[(s, k)] = (sort_key(value, memo), value)
            pairs.append(power)
    pairs.sort(key=_first)
    return pairs


def _keyed_term(q, pairs: list, memo: dict, numbers: dict) -> tuple:
    """``(sort key, q * prod(powers))`` for a rational ``q`` of ``QQ`` and the sorted :func:`_power_pairs` of the
    powers: :func:`_rational_term`'s product with its key returned instead of recorded (no hash of the new
    product), the number and its key memoised in ``numbers`` by numerator and denominator."""
    ident = (q.numerator, q.denominator)
    hit = numbers.get(ident)
    if hit is None:
        coeff = QQ.to_sympy(q)
        hit = numbers[ident] = (sort_key(coeff, memo), coeff)
    if hit[1] is not sympy.S.One or not pairs:
        pairs = [hit, *pairs]
    if len(pairs) == 1:
        return pairs[0]
    term = sympy.Mul._from_args([f for _, f in pairs], True)  # the ring's generators and parameters commute
    return product_key(term, [k for k, _ in pairs]), term


# -- pickling -----------------------------------------------------------------------------
# sympy's own pickling of rings and rational-function fields fails (PolyRing.__getstate__ deletes keys of the
# dict it iterates, sympy 1.14) and would tie a pickle to sympy's and the ground types' internals.  The rings
# and coefficient fields built here therefore pickle as a plain description instead: generator names with
# their assumptions, the coefficient field (extension numbers, parameters), and each element's terms as
# exponent tuples with exact rational coefficients in Python ints.  Subclasses carry this, so sympy's own
# classes (and a user's own rings) are untouched; every operation is sympy's.

def _symbol_description(s) -> tuple:
    # the assumptions as given (what sympy's own pickle of a Symbol keeps): Symbol("x", commutative=True) equals
    # Symbol("x") but is another object, which sympy's cache would then hand to unrelated expressions
    (name,), assumptions = s.__getnewargs_ex__()
    return (name, tuple(sorted(assumptions.items())))


def _symbol_from(description) -> sympy.Symbol:
    name, assumptions = description
    return sympy.Symbol(name, **dict(assumptions))


def _ground(domain):
    return domain.domain if getattr(domain, "is_FractionField", False) else domain


def _ground_description(ground):
    """``()`` for ``QQ``, ``"ZZ"`` for ``ZZ`` (a ring's ``clone`` may pass to it), the extension numbers (sympy
    expressions such as ``2**(1/3)``) for ``QQ<ext>``."""
    if ground.is_QQ or ground.is_ZZ:
        return () if ground.is_QQ else "ZZ"
    if not ground.is_AlgebraicField:
        raise TypeError(f"polynomials over {ground} do not pickle (QQ, ZZ and algebraic number fields do)")
    return tuple(ground.orig_ext)


def _ground_from(description):
    if description == "ZZ":
        return ZZ
    return QQ.algebraic_field(*description) if description else QQ


def _domain_from(extension, parameters):
    """``QQ``, ``QQ<extension>``, ``QQ(parameters)`` or ``QQ<extension>(parameters)``, the fraction field picklable."""
    ground = QQ.algebraic_field(*extension) if extension else QQ
    return FractionField(_PicklableField(tuple(parameters), ground)) if parameters else ground


def _primitive(ground):
    """The primitive element in which algebraic numbers are written, a sympy expression (``None`` over ``QQ``)."""
    return ground.ext.as_expr() if ground.is_AlgebraicField else None


def _rational(c) -> tuple:
    return (int(QQ.numer(c)), int(QQ.denom(c)))


def _ground_codec(ground, primitive=None):
    """``(describe, rebuild)``: an element of ``QQ``, ``ZZ`` or ``QQ<a>`` (dense in ``a``) as ints, and back.

    ``primitive`` is the writer's primitive element; if this sympy chose another one, numbers go through sympy.
    """
    if ground.is_QQ:
        return _rational, lambda d: QQ(*d)
    if ground.is_ZZ:
        return int, ZZ
    if primitive is not None and primitive != ground.ext.as_expr():
        return None, lambda d: ground.from_sympy(sympy.Add(*(sympy.Rational(*c) * primitive**k
                                                             for k, c in enumerate(reversed(d)))))
    return (lambda c: tuple(map(_rational, c.to_list())),
            lambda d: ground.new([QQ(*c) for c in d]))


def _terms(p, describe) -> tuple:
    return tuple((m, describe(c)) for m, c in p.items())


def _ring_from(symbols, ground):
    """The polynomial ring described by :meth:`_PicklableRing.__reduce__`."""
    return _PicklableRing(tuple(map(_symbol_from, symbols)), _ground_from(ground))


def _ring_over_field_from(symbols, field):
    """A polynomial ring over a rational-function field described by :meth:`_PicklableRing.__reduce__`."""
    return _PicklableRing(tuple(map(_symbol_from, symbols)), FractionField(field))


def _polynomial_from(ring, terms, primitive=None):
    """The polynomial described by :meth:`_PicklablePolynomial.__reduce__`."""
    domain = ring.domain
    if getattr(domain, "is_FractionField", False):
        field, codec = domain.field, _ground_codec(domain.domain, primitive)[1]
        return ring.dtype({m: _fraction(field, numer, denom, codec) for m, (numer, denom) in terms})
    rebuild = _ground_codec(domain, primitive)[1]
    return ring.dtype({m: rebuild(c) for m, c in terms})


def _fraction(field, numer, denom, rebuild):
    new = field.ring.from_dict
    return field.raw_new(new({m: rebuild(a) for m, a in numer}), new({m: rebuild(a) for m, a in denom}))


def _fraction_from(field, numer, denom, primitive=None):
    """The rational function described by :meth:`_PicklableFraction.__reduce__`."""
    return _fraction(field, numer, denom, _ground_codec(field.domain, primitive)[1])


def _field_from(symbols, ground):
    """The rational-function field described by :meth:`_PicklableField.__reduce__`."""
    return _PicklableField(tuple(map(_symbol_from, symbols)), _ground_from(ground))


class _PicklablePolynomial(PolyElement):
    """sympy's ``PolyElement`` (every operation inherited) that pickles as exponent tuples and exact coefficients."""

    def __reduce__(self):
        domain = self.ring.domain
        ground = _ground(domain)
        describe = _ground_codec(ground)[0]
        if ground is domain:
            terms = _terms(self, describe)
        else:
            terms = tuple((m, (_terms(c.numer, describe), _terms(c.denom, describe))) for m, c in self.items())
        return _polynomial_from, (self.ring, terms, _primitive(ground))


class _PicklableRing(PolyRing):
    """sympy's lexicographic ``PolyRing`` whose elements are :class:`_PicklablePolynomial` and which pickles as
    its generators' names and its coefficient domain's description."""

    def __new__(cls, symbols, domain, order=lex):
        obj = super().__new__(cls, symbols, domain, order)
        # hash like sympy's ring of the same content, which it equals
        obj._hash_tuple = ("PolyRing", *obj._hash_tuple[1:])
        obj._hash = hash(obj._hash_tuple)
        obj.dtype = _PicklablePolynomial(obj, ()).new
        obj.gens = obj._gens()
        obj._gens_set = set(obj.gens)
        for symbol, generator in zip(obj.symbols, obj.gens):
            if isinstance(symbol, sympy.Symbol) and isinstance(getattr(obj, symbol.name, None), PolyElement):
                setattr(obj, symbol.name, generator)
        return obj

    def __reduce__(self):
        if self.order != lex:
            raise TypeError(f"only lexicographic polynomial rings pickle, not {self.order}")
        symbols = tuple(map(_symbol_description, self.symbols))
        if getattr(self.domain, "is_FractionField", False):
            return _ring_over_field_from, (symbols, _picklable_field(self.domain.field))
        return _ring_from, (symbols, _ground_description(self.domain))


class _PicklableFraction(FracElement):
    """sympy's ``FracElement`` that pickles as its numerator's and denominator's terms."""

    def __reduce__(self):
        ground = self.field.domain
        describe = _ground_codec(ground)[0]
        return _fraction_from, (self.field, _terms(self.numer, describe), _terms(self.denom, describe), _primitive(ground))


class _PicklableField(FracField):
    """sympy's lexicographic ``FracField`` whose elements are :class:`_PicklableFraction` and which pickles as its
    generators' names and its ground field's description."""

    def __new__(cls, symbols, domain, order=lex):
        obj = super().__new__(cls, symbols, domain, order)
        obj._hash_tuple = ("FracField", *obj._hash_tuple[1:])
        obj._hash = hash(obj._hash_tuple)
        obj.dtype = _PicklableFraction(obj, obj.ring.zero).raw_new
        obj.zero, obj.one = obj.dtype(obj.ring.zero), obj.dtype(obj.ring.one)
        obj.gens = obj._gens()
        for symbol, generator in zip(obj.symbols, obj.gens):
            if isinstance(symbol, sympy.Symbol) and isinstance(getattr(obj, symbol.name, None), FracElement):
                setattr(obj, symbol.name, generator)
        return obj

    def __reduce__(self):
        if self.order != lex:
            raise TypeError(f"only lexicographic rational-function fields pickle, not {self.order}")
        return _field_from, (tuple(map(_symbol_description, self.symbols)), _ground_description(self.domain))


def _picklable_field(field):
    return field if isinstance(field, _PicklableField) else _PicklableField(field.symbols, field.domain, field.order)


@lru_cache(maxsize=4096)
def _converted(algebra, expr):
    """``expr`` (a sympy expression) as an element of ``algebra``'s ring, else ``expr`` itself.

    Memoised: brackets and Liouville fields convert the same Hamiltonians, pieces and slots again and again (the FI
    route's terms, the exact solutions' fields; ~60 % of the conversions of test_fi_route, test_shadow and
    test_exact_solutions repeat one), and ``ring.from_expr`` walks the whole expression each time.
    """
    try:
        return algebra.ring.from_expr(expr) if expr.free_symbols else algebra.ring(algebra.domain.from_sympy(expr))
    except _CONVERSION_ERRORS:
        return expr


@lru_cache(maxsize=65536, typed=True)
def _times(domain, coefficient, k: int):
    """``coefficient * k`` in ``domain`` (``k >= 2`` an exponent brought down by a derivative), memoised.

    In ``QQ(parameters)`` the product is a fraction-field multiplication with a polynomial gcd (~0.5 ms for the
    rigid body's coefficients); a derivative of the same Hamiltonians, slots and corrections brings down the same
    exponents over the same coefficients again and again.  The key holds the domain: equal constants of two fields
    are not interchangeable.
    """
    return domain.convert(coefficient * k)


def _poly_diff(value, index: int):
    """``d value / d x_index`` of a ring element: the ring's own ``diff`` (the same dict, term by term), without its
    search of the generator by comparison and with the coefficient products memoised (:func:`_times`)."""
    ring = value.ring
    domain = ring.domain
    out = ring.zero
    for expv, coefficient in value.items():
        k = expv[index]
        if k:
            m = list(expv)
            m[index] = k - 1
            out[tuple(m)] = coefficient if k == 1 else _times(domain, coefficient, k)
    return out


@declare()
class PolynomialAlgebra:
    """Polynomials in ``coordinates`` (and ``constants``) over ``QQ(parameters)``.

    Parameters
    ----------
    coordinates : sequence of sympy Symbols
        The phase-space variables, the only ones :meth:`diff` differentiates by.
    parameters : sequence of sympy Symbols
        Symbols allowed in denominators (``m``, ``omega``, ``I1`` ...).
    constants : sequence of sympy Symbols
        Extra polynomial generators that are never differentiated (``h``).
    extension : sequence of sympy numbers
        Algebraic numbers adjoined to QQ (e.g. ``cbrt(2)``).

    Examples
    --------
    >>> import sympy
    >>> x1, x2, m = sympy.symbols("x1 x2 m")
    >>> A = PolynomialAlgebra([x1, x2], [m])
    >>> A.to_sympy(A.diff(A.convert(x2**2 / (2*m)), 1))
    x2/m
    """

    def __init__(self, coordinates, parameters=(), constants=(), extension=()):
        self.coordinates = _symbols(coordinates, "coordinates")
        if not self.coordinates:
            raise InvalidSystemError("a PolynomialAlgebra needs at least one coordinate, got none")
        self.parameters = _symbols(parameters, "parameters")
        self.constants = _symbols(constants, "constants")
        self.extension = tuple(as_expression(e, (), "extension of a PolynomialAlgebra")
                               for e in check_sequence(extension, "extension", "algebraic numbers"))
        clash = set(self.coordinates) & (set(self.parameters) | set(self.constants))
        if clash:
            raise InvalidSystemError(
                f"symbols {sorted(map(str, clash))} are used both as coordinates and as parameters/constants"
            )
        self.domain = domain = _domain_from(self.extension, self.parameters)
        self.ring = _PicklableRing(self.coordinates + self.constants, domain)
        self.gens = self.ring.gens
        self.n = len(self.coordinates)

    def _key(self) -> tuple:
        return (self.coordinates, self.parameters, self.constants, self.extension)

    def __eq__(self, other):
        # two algebras built from the same description are the same algebra (and share content-keyed caches)
        if not isinstance(other, PolynomialAlgebra):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self):
        return hash(self._key())

    def __reduce__(self):
        """Pickle as the description: symbol names with assumptions, and the extension numbers."""
        symbols = tuple(tuple(map(_symbol_description, group)) for group in self._key()[:3])
        return _algebra_from, (*symbols, self.extension)

    def __repr__(self):
        return f"PolynomialAlgebra(coordinates={self.coordinates}, parameters={self.parameters}, constants={self.constants})"

    def with_constants(self, *constants, extension=()) -> "PolynomialAlgebra":
        """The same algebra with more constant generators / algebraic numbers."""
        new = tuple(c for c in _symbols(constants) if c not in self.constants)
        ext = self.extension + tuple(e for e in extension if e not in self.extension)
        if not new and ext == self.extension:
            return self
        return PolynomialAlgebra(self.coordinates, self.parameters, self.constants + new, ext)

    # -- conversion -------------------------------------------------------------
    def convert(self, expr):
        """``expr`` as a ring element when it is a polynomial here, else a sympy expression."""
        if isinstance(expr, PolyElement) and expr.ring == self.ring:
            return expr
        if isinstance(expr, PolyElement):  # another ring's element
            expr = expr.as_expr()
        elif not isinstance(expr, sympy.Expr):  # text is parsed with this algebra's symbols, never sympified
            expr = as_expression(expr, self.symbol_table, "expression")
        value = _converted(self, expr)
        # a ring element is a dict: each caller gets its own copy of the memoised one
        return value.copy() if isinstance(value, PolyElement) else value

    @cached_property
    def symbol_table(self) -> dict:
        """Name -> Symbol of the coordinates, parameters and constants (what a text expression may use)."""
        return {s.name: s for s in (*self.coordinates, *self.parameters, *self.constants)}

    def is_polynomial(self, value) -> bool:
        return isinstance(value, PolyElement) and value.ring == self.ring

    def to_sympy(self, value, memo: dict | None = None) -> sympy.Expr:
        """A sympy expression (polynomials are expanded, coefficients as rational functions).

        ``memo`` (a dict the caller keeps, e.g. for the polynomials of one solve) remembers the
        coefficients already converted: the same expression as ``value.as_expr()``, each distinct
        coefficient converted once.
        """
        if isinstance(value, PolyElement):
            if memo is None:
                return value.as_expr()
            to_sympy = value.ring.domain.to_sympy
            coefficients = {}
            for m, c in value.items():
                e = memo.get(c)
                if e is None:
                    e = memo[c] = to_sympy(c)
                coefficients[m] = e
            return expr_from_dict(coefficients, *value.ring.symbols)
        return as_expression(value, self.symbol_table, "expression")

    def expanded_terms(self, value, factors=(), memo=None) -> list:
        """The terms of ``sympy.expand(to_sympy(value) * factors[0] * ...)``, built without ``expand``.

        A coefficient ``c = p/q`` of the monomial ``x^m`` (``p, q`` polynomials in the
        parameters, coprime, as the field keeps them) expands to
        ``sum_e p_e P^e x^m / q``: one term per term ``p_e P^e`` of the numerator, the
        denominator ``q`` as sympy writes it (``Pow(q, -1)``; a monomial ``q`` is split
        into powers; the denominator ``s`` of a rational coefficient ``r/s`` of ``p`` joins a whole
        ``q`` as ``r/(s q)``).  This is exactly what ``Mul._eval_expand_mul`` produces for
        ``x^m p/q`` (it distributes the numerator over the other factors and keeps the
        denominator whole), and ``Mul``'s canonical flattening gives the same objects, so
        ``sympy.Add(*terms)`` is identical to the expanded expression.  The terms of
        distinct monomials never combine (their powers of the generators differ), so
        nothing else is to be collected.  ``factors`` are extra factors of every term
        (powers of symbols, e.g. ``h**j``).  A sympy expression (not a ring element) is
        expanded by sympy.

        Parameters
        ----------
        value : ring element or sympy expression
        factors : sequence of sympy expressions -- powers of symbols multiplying every term
        memo : dict, optional -- receives the sort keys of the terms built directly (the memo of
            :func:`~nambu_bch.algebra.canonical.canonical_add`, which then sorts them without recomputing)

        Returns
        -------
        list of sympy expressions -- ``sympy.Add(*terms) == sympy.expand(to_sympy(value) * prod(factors))``

        Examples
        --------
        >>> import sympy
        >>> x, m, k = sympy.symbols("x m k")
        >>> A = PolynomialAlgebra([x], [m, k])
        >>> p = A.convert(x**2 * (m + 1) / (2 * m * (m - k)))
        >>> sympy.Add(*A.expanded_terms(p)) == sympy.expand(A.to_sympy(p))
        True
        """
        if not isinstance(value, PolyElement):
            return list(sympy.Add.make_args(sympy.expand(sympy.Mul(sympy.sympify(value, strict=True), *factors))))
        domain = value.ring.domain
        gens = value.ring.symbols
        factors = list(factors)
        fraction = getattr(domain, "is_FractionField", False)
        if fraction:
            ground, params = domain.domain, domain.field.ring.symbols
            inverses: dict = {}
            wholes: dict = {}
        powers = _symbol_powers(factors) if (ground if fraction else domain).is_QQ else None
        terms = []
        memo = {} if memo is None else memo
        built: dict = {}  # (symbol, exponent) -> (sort key, power), for _rational_term
        for m, c in value.items():
            if powers is not None and not fraction:  # a rational times a monomial: one term
                exps = dict(powers)
                for s, e in zip(gens, m):
                    if e:
                        exps[s] = exps.get(s, 0) + e
                terms.append(_rational_term(QQ.to_sympy(c), exps, memo, built))
                continue
            if powers is not None and len(c.denom) == 1:
                terms.extend(_monomial_denominator_terms(c, gens, m, params, powers, memo, built))
                continue
            mono = [s**e for s, e in zip(gens, m) if e] + factors
            if not fraction:
                terms.extend(sympy.Add.make_args(sympy.expand(sympy.Mul(domain.to_sympy(c), *mono))))
                continue
            den = c.denom
            key = tuple(sorted(den.items()))
            if key not in wholes:
                expanded = sympy.expand(den.as_expr())  # e.g. (1 + 2^(1/3)) b + 1 -> b + 2^(1/3) b + 1
                wholes[key] = expanded.is_Add  # a denominator sympy keeps whole, not split into powers
                inverses[(key, 1)] = 1 / expanded
            whole = wholes[key]
            for e, a in c.numer.items():
                # an algebraic ground coefficient a + b 2^(1/3) + ... distributes over its terms, as expand does
                for part in sympy.Add.make_args(ground.to_sympy(a)):
                    q = 1
                    if whole:
                        # expand's fixed point moves the denominator q of a rational coefficient p/q into
                        # the whole denominator: p/(q d), with q d expanded
                        r, rest = part.as_coeff_Mul()
                        if r.q != 1:
                            q, part = r.q, sympy.Integer(r.p) * rest
                    inv = inverses.get((key, q))
                    if inv is None:
                        inv = inverses[(key, q)] = 1 / sympy.expand(q * den.as_expr())
                    terms.append(sympy.Mul(part, *[s**k for s, k in zip(params, e) if k], *mono, inv))
        return terms

    def expanded_sum(self, parts, memo=None) -> sympy.Expr:
        """``sympy.expand(sum_k to_sympy(value_k) * prod(factors_k))`` for ``parts = [(value_k, factors_k)]``, identical.

        The terms are :meth:`expanded_terms`'; when every value is a ring element over ``QQ`` or ``QQ(params)``,
        every factor a power of a symbol other than the parameters, and the monomials of the parts times their
        factors pairwise distinct, no two terms share their non-numeric part (distinct powers of the generators
        and the factors' symbols, then of the parameters; a coefficient with a sum in its denominator gives
        products with a power of that sum, distinct by their powers of the parameters), so ``Add`` would keep
        every term as it is, in the order of ``Basic.compare``: the sum is built from the terms' sort keys
        (:func:`~nambu_bch.algebra.canonical.sort_key`'s order), computed with the terms of monomial denominators,
        the numbers summed in front (``sympy.core.add.Add.flatten``).  Otherwise
        :func:`~nambu_bch.algebra.canonical.canonical_add` of the terms.

        Parameters
        ----------
        parts : sequence of ``(value, factors)`` -- a ring element or sympy expression, and a sequence of sympy
            expressions multiplying each of its terms
        memo : dict, optional -- :func:`~nambu_bch.algebra.canonical.sort_key`'s memo, shared between sums

        Returns
        -------
        sympy.Expr

        Examples
        --------
        >>> x, m, h = sympy.symbols("x m h")
        >>> A = PolynomialAlgebra([x], [m])
        >>> p, q = A.convert(x**2 / (2 * m) + 3), A.convert(-x / m**2 + m * x)
        >>> A.expanded_sum([(p, ()), (q, (h,))]) == sympy.expand(A.to_sympy(p) + A.to_sympy(q) * h)
        True
        """
        parts = list(parts)
        memo = {} if memo is None else memo
        keyed = self._keyed_terms(parts, memo)
        if keyed is None:
            return canonical_add([t for p, f in parts for t in self.expanded_terms(p, f, memo)], memo)
        number = sympy.S.Zero
        rest = []
        for key, term in keyed:
            if term.is_Number:
                number += term
            else:
                rest.append((key, term))
        rest.sort(key=_first)  # distinct terms have distinct keys: the terms themselves are never compared
        ordered = [term for _, term in rest]
        if number:
            ordered.insert(0, number)
        if len(ordered) <= 1:
            return ordered[0] if ordered else sympy.S.Zero
        return sympy.Add._from_args(ordered, True)

    def _keyed_terms(self, parts, memo):
        """``[(sort key, term)]`` of :meth:`expanded_sum`'s parts when its conditions hold, else ``None``."""
        ring = self.ring
        if not all(isinstance(p, PolyElement) and p.ring == ring for p, _ in parts):
            return None
        domain = ring.domain
        fraction = getattr(domain, "is_FractionField", False)
        if not (domain.domain.is_QQ if fraction else domain.is_QQ):
            return None
        gens = ring.symbols
        params = domain.field.ring.symbols if fraction else ()
        powers = [_symbol_powers(f) for _, f in parts]
        if any(w is None for w in powers):
            return None
        if any(s in params for w in powers for s in w) or set(params) & set(gens):
            return None
        place = {s: i for i, s in enumerate(gens)}
        outside = sorted({s for w in powers for s in w if s not in place}, key=str)
        seen: set = set()  # the exponents of the generators and outside symbols of every (part, monomial)
        for (p, _), w in zip(parts, powers):
            shift = [0] * len(gens)
            for s, k in w.items():
                if s in place:
                    shift[place[s]] += k
            extra = tuple(w.get(s, 0) for s in outside)
            for m in p.keys():
                seen.add((tuple(e + k for e, k in zip(m, shift)), extra))
        if len(seen) != sum(len(p) for p, _ in parts):
            return None
        built: dict = {}  # (symbol, exponent) -> (sort key, power)
        numbers: dict = {}  # (numerator, denominator) -> (sort key, sympy number)
        by_shift: dict = {}  # exponents of the parameters -> their sorted power pairs
        out = []
        for (p, f), w in zip(parts, powers):
            for m, c in p.items():
                if fraction and len(c.denom) != 1:  # a sum in the denominator, kept whole: expanded_terms' terms
                    for t in self.expanded_terms(ring({m: c}), f, memo):
                        # the terms canonical_add keeps as they are (products with a power of the sum)
                        if not (t.is_Mul and t.is_commutative):
                            return None
                        try:
                            out.append((sort_key(t, memo), t))
                        except _NoKey:
                            return None
                    continue
                base = dict(w)
                for s, e in zip(gens, m):
                    if e:
                        base[s] = base.get(s, 0) + e
                mono = _power_pairs(base, memo, built)
                if not fraction:
                    out.append(_keyed_term(c, mono, memo, numbers))
                    continue
                [(dexp, d)] = c.denom.items()
                for e, a in c.numer.items():
                    shift = tuple(k - j for k, j in zip(e, dexp))
                    own = by_shift.get(shift)
                    if own is None:
                        own = by_shift[shift] = _power_pairs(dict(zip(params, shift)), memo, built)
                    # the parameters are not among the other symbols: the two sorted runs merge into one
                    out.append(_keyed_term(a / d, sorted(mono + own, key=_first) if own else mono, memo, numbers))
        return out

    def to_sympy_expanded(self, value, factors=()) -> sympy.Expr:
        """``sympy.expand(to_sympy(value) * prod(factors))``, identical, from :meth:`expanded_sum` (no ``expand``)."""
        return self.expanded_sum([(value, factors)])

    @cached_property
    def coefficient_field(self) -> CoefficientField:
        """The field of the coefficients, ``QQ``, ``QQ(parameters)``, ``QQ(theta)`` or ``QQ(theta)(parameters)``
        (:class:`~nambu_bch.algebra.fields.CoefficientField`)."""
        return CoefficientField.of(self.domain)

    @cached_property
    def zero(self):
        return self.ring.zero

    # -- calculus ---------------------------------------------------------------
    def diff(self, value, index: int):
        """Partial derivative by coordinate number ``index`` (0-based)."""
        if isinstance(value, PolyElement):
            if value.ring is self.ring:
                return _poly_diff(value, index)
            return value.diff(self.gens[index])
        return sympy.diff(value, self.coordinates[index])

    def is_zero(self, value) -> bool:
        """Exact zero test: structural for polynomials, :func:`nambu_bch.algebra.zero.is_zero` for the rest."""
        if isinstance(value, PolyElement):
            return not value
        return is_zero(value)

    @cached_property
    def ring_backend(self):
        """The :class:`~nambu_bch.algebra.backend.PolynomialBackend` on this ring (``diff`` as derivative):
        the arithmetic behind :class:`~nambu_bch.algebra.VectorField` for polynomial components."""
        return PolynomialBackend.on_ring(self)

    @cached_property
    def expression_backend(self):
        """The :class:`~nambu_bch.algebra.backend.ExpressionBackend` on these coordinates (sympy components)."""
        return ExpressionBackend(self)

    def from_terms(self, terms: dict):
        """The polynomial ``sum c x^e`` of ``{exponent tuple: coefficient}`` (exponents over all generators)."""
        return self.ring.from_dict(terms) if terms else self.zero

    @staticmethod
    def terms(value) -> dict:
        """``{exponent tuple: coefficient}`` of a polynomial (sympy's polynomials are such dicts already)."""
        return value

    def common(self, *values):
        """The values in one representation: all ring elements if possible, else all sympy."""
        if all(isinstance(v, PolyElement) for v in values):
            return values
        return tuple(self.to_sympy(v) for v in values)


def _algebra_from(coordinates, parameters, constants, extension) -> PolynomialAlgebra:
    """The algebra described by :meth:`PolynomialAlgebra.__reduce__`."""
    return PolynomialAlgebra(*(map(_symbol_from, group) for group in (coordinates, parameters, constants)), extension)
