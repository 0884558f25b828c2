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

from functools import cached_property

import sympy
from sympy.core.mul import _mulsort
from sympy.polys.domains import QQ
from sympy.polys.polyerrors import CoercionFailed, GeneratorsError, PolynomialError
from sympy.polys.polyutils import expr_from_dict
from sympy.polys.rings import PolyElement, ring

from ..errors import InvalidSystemError
from ..parsing import as_expression
from .zero import is_zero

_CONVERSION_ERRORS = (CoercionFailed, GeneratorsError, PolynomialError, ValueError, TypeError)


def _symbols(names) -> tuple[sympy.Symbol, ...]:
    return tuple(sympy.Symbol(n) if isinstance(n, str) else n for n in names)


def _symbol_powers(factors) -> dict | None:
    """``{symbol: exponent}`` of a product of powers of symbols with integer exponents, else ``None``."""
    out: dict = {}
    for f in factors:
        base, exp = f.as_base_exp() if isinstance(f, sympy.Basic) else (None, None)
        if not (isinstance(base, sympy.Symbol) and isinstance(exp, sympy.Integer)):
            return None
        out[base] = out.get(base, 0) + int(exp)
    return out


def _monomial_denominator_terms(c, gens, m, params, powers) -> list:
    """The terms of ``expand(c x^m prod(powers))`` for ``c = p / (d P^k)`` in ``QQ(params)``, a monomial denominator.

    Each term of ``p`` gives one product of a rational number and powers of distinct symbols (the
    parameters' exponents minus ``k``, the generators', ``powers``), which is how ``Mul`` flattens
    ``r P^e x^m / (d P^k)``: its canonical form is the coefficient (left out when it is one) followed
    by the powers sorted by ``Basic.compare`` (``sympy.core.mul._mulsort``), so the object is built
    directly with ``Mul._from_args`` -- the same expression, without ``Mul.flatten``.
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
        args = [s if k == 1 else sympy.Pow(s, k) for s, k in exps.items() if k]
        _mulsort(args)
        coeff = QQ.to_sympy(a / d)
        if coeff != 1:
            args.insert(0, coeff)
        out.append(args[0] if len(args) == 1 else sympy.Mul._from_args(args) if args else coeff)
    return out


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
        self.coordinates = _symbols(coordinates)
        self.parameters = _symbols(parameters)
        self.constants = _symbols(constants)
        self.extension = tuple(as_expression(e, (), "extension of a PolynomialAlgebra") for e in extension)
        clash = set(self.coordinates) & (set(self.parameters) | set(self.constants))
        if clash:
            raise InvalidSystemError(
                f"symbols {sorted(map(str, clash))} are used both as coordinates and as parameters/constants"
            )
        domain = QQ.algebraic_field(*self.extension) if self.extension else QQ
        if self.parameters:
            domain = domain.frac_field(*self.parameters)
        self.domain = domain
        self.ring, *gens = ring(list(self.coordinates + self.constants), domain)
        self.gens = tuple(gens)
        self.n = len(self.coordinates)

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
        try:
            return self.ring.from_expr(expr) if expr.free_symbols else self.ring(self.domain.from_sympy(expr))
        except _CONVERSION_ERRORS:
            return expr

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

    def expanded_terms(self, value, factors=()) -> list:
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
        powers = _symbol_powers(factors) if fraction and ground.is_QQ else None
        terms = []
        for m, c in value.items():
            if powers is not None and len(c.denom) == 1:
                terms.extend(_monomial_denominator_terms(c, gens, m, params, powers))
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

    def to_sympy_expanded(self, value, factors=()) -> sympy.Expr:
        """``sympy.expand(to_sympy(value) * prod(factors))``, identical, from :meth:`expanded_terms` (no ``expand``)."""
        return sympy.Add(*self.expanded_terms(value, factors))

    @cached_property
    def zero(self):
        return self.ring.zero

    # -- calculus ---------------------------------------------------------------
    def diff(self, value, index: int):
        """Partial derivative by coordinate number ``index`` (0-based)."""
        if isinstance(value, PolyElement):
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
        from .backend import PolynomialBackend

        return PolynomialBackend.on_ring(self)

    @cached_property
    def expression_backend(self):
        """The :class:`~nambu_bch.algebra.backend.ExpressionBackend` on these coordinates (sympy components)."""
        from .backend import ExpressionBackend

        return ExpressionBackend(self)

    def common(self, *values):
        """The values in one representation: all ring elements if possible, else all sympy."""
        if all(isinstance(v, PolyElement) for v in values):
            return values
        return tuple(self.to_sympy(v) for v in values)
