"""One protocol for vector-field arithmetic, two exact implementations.

A *field backend* holds a set of vector fields ``X = X^i d/dx_i`` (the leaves:
pieces of a splitting, Liouville terms, ...) in an internal representation and
does, exactly, what the routes to ``X_eff`` and the shadow routes need:

* ``bracket(X, Y)``: ``[X, Y]^i = X(Y^i) - Y(X^i)``, the operator commutator (Eq. CL1);
* ``apply(X, f) = sum_i X^i D_i f`` and ``derivative(f, i) = D_i f`` (``D_i`` the algebra's
  derivative: ``d/dx_i``, or the total derivative on jets);
* ``combine(pairs) = sum c X`` and ``scaled_combine(den, pairs) = (1/den) sum n X``,
  returned as :class:`~nambu_bch.algebra.VectorField` (the sympy edge);
* ``is_zero(X)``, ``is_zero_function(f)``: exact zero tests;
* ``from_vector_field`` / ``to_vector_field`` / ``field(values)`` / ``values(X)``, ``function(expr)`` /
  ``function_to_sympy(f)``: conversions (the sympy edge);
* ``constants(numbers)``, ``rational(q)``: exact numbers as scalars of the backend.

:class:`PolynomialBackend` works on exact sparse polynomials over the parameter
field (sympy ``PolyElement``).  When every coefficient of every leaf divides
only by *monomials* in the parameters (``1/m``, ``1/I2 - 1/I3``: all built-in
models) it runs in Laurent polynomials: a parameter ``p`` becomes two ordinary
generators ``p``, ``p_inv`` over QQ (or ``QQ(2^(1/3))``), every product is
brought back to the canonical form in which no monomial holds both (Laurent
monomials are a basis, so the zero test stays structural), and, over QQ, each
field's denominators are cleared once so that nested brackets run over ZZ (the
product of the scales is carried along and divided out once in
:meth:`PolynomialBackend.combine`).  No rational-function gcd is ever taken.  With python-flint
(:mod:`nambu_bch.algebra._flint`) the integral brackets multiply on ``fmpz_mpoly`` and ``apply`` on
``fmpq_mpoly``: the same polynomials, products in C.
Otherwise (``1/(m + 1)``, or ``laurent=False``) it runs in the algebra's own
ring ``QQ(parameters)[x]`` -- which may be a :class:`~nambu_bch.shadow.jets.JetAlgebra`
or any ring offering ``ring``, ``n``, ``domain`` and ``diff(value, i)``.

:class:`ExpressionBackend` works on sympy expressions, for non-polynomial fields
(``cos(x1)``, undefined functions ``H1(x1)``, ``1/(1 + x1**2)``): brackets are
``diff`` followed by the normal form -- ``cancel`` (``p/q`` in lowest terms, a
canonical form) for rational functions, ``expand`` otherwise -- and the zero test
is structural after it.  It
never calls a non-zero field zero; an exotic zero that only ``simplify`` would
see (``sin^2 + cos^2 - 1``) is kept, which costs a term but never changes a value.

:func:`field_backend` picks the implementation.

References
----------
Horikoshi, Eq. (CL1) (bracket convention); Laurent polynomial rings as
localisations ``QQ[p, 1/p]``: Cox, Little, O'Shea, *Ideals, Varieties, and
Algorithms*, Sect. 3.2 (the ``p y - 1`` trick, here reduced explicitly);
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.1 and IX.4.
"""

from __future__ import annotations

from math import lcm
from typing import Protocol, runtime_checkable

import sympy
from sympy.polys.domains import ZZ
from sympy.polys.rings import PolyElement, ring

from ..checks import check_type
from ..errors import NambuBCHError
from . import _flint
from ._flint import exponents
from .fields import CoefficientField, number_field
from .ring import check_ring
from .vector_field import VectorField


@runtime_checkable
class FieldBackend(Protocol):
    """What the BCH route, backward error analysis and the shadow routes ask of vector-field arithmetic.

    ``fields`` maps each leaf key to its internal field; ``coordinates`` are the
    coordinate functions ``x_i``, ``zero``/``one`` the constant functions, all in
    the internal representation of functions.
    """

    algebra: object
    fields: dict
    coordinates: tuple
    zero: object
    one: object

    def bracket(self, X, Y): ...

    def apply(self, X, f): ...

    def derivative(self, f, i: int): ...

    def combine(self, pairs) -> VectorField: ...

    def scaled_combine(self, denominator: int, pairs) -> VectorField: ...

    def is_zero(self, X) -> bool: ...

    def is_zero_function(self, f) -> bool: ...

    def field(self, values): ...

    def values(self, X) -> tuple: ...

    def from_vector_field(self, V: VectorField): ...

    def function(self, expr): ...

    def function_to_sympy(self, f): ...

    def to_vector_field(self, X) -> VectorField: ...

    def constants(self, numbers) -> list: ...

    def rational(self, q): ...


class _Field:
    """A field of :class:`PolynomialBackend`: ``components / scale`` plus its value-ring components and
    derivatives, each computed once.

    In the integral Laurent case with python-flint (:attr:`PolynomialBackend.flint`) the components are also kept
    as flint ``fmpz_mpoly`` (``flint``); a field made by a flint bracket has only those, and its sympy
    ``components`` are built on first access."""

    __slots__ = ("_components", "scale", "_values", "_derivatives", "flint", "_backend", "flint_values")

    def __init__(self, components, scale=1, values=None, flint=None, backend=None):
        self._components = None if components is None else tuple(components)
        self.scale = scale
        self._values = values
        self._derivatives = None
        self.flint = flint
        self._backend = backend
        self.flint_values = None  # the value-ring components as fmpq_mpoly (PolynomialBackend._apply_flint)

    @property
    def components(self) -> tuple:
        if self._components is None:
            self._components = tuple(self._backend.from_flint(c) for c in self.flint)
        return self._components


def _new_derivatives(X: _Field, n: int) -> list:
    """An empty table ``[i][j] -> D_j X^i`` (``None``: not computed yet), kept with ``X``."""
    X._derivatives = [[None] * n for _ in range(n)]
    return X._derivatives


class PolynomialBackend:
    """Vector fields with exact sparse-polynomial components over the parameter field.

    Use :meth:`build` (or :func:`field_backend`).  ``laurent`` is ``True`` when the
    Laurent representation (module docstring) is in use.

    Examples
    --------
    >>> from nambu_bch import model
    >>> S = model("rigid-body").splitting
    >>> F = PolynomialBackend.build(S.system.algebra, {p.number: p.field for p in S.pieces})
    >>> F.laurent, F.ring.symbols[3:]
    (True, (h, I1, I1_inv, I2, I2_inv, I3, I3_inv))
    >>> F.combine([(1, F.bracket(F.fields[1], F.fields[2]))]) == S[1].field.bracket(S[2].field)
    True
    """

    def __init__(self, algebra, value_ring, bracket_ring, laurent_pairs, laurent: bool):
        self.algebra = algebra
        self.laurent = laurent
        self.ring = value_ring  # the values (rational coefficients)
        self.bracket_ring = bracket_ring  # over ZZ in the Laurent case over QQ: brackets of integral components
        self.domain = value_ring.domain
        self._pairs = laurent_pairs  # [(index of p, index of p_inv)] in the ring's generators
        self._integral = bracket_ring is not value_ring
        self.fields: dict = {}
        # the coordinate functions x_i (a ring without coordinate generators, such as a jet ring in one
        # variable per coordinate, has none)
        self.coordinates = tuple(value_ring.gens[: algebra.n]) if hasattr(algebra, "coordinates") else ()
        self.zero, self.one = value_ring.zero, value_ring.one
        self._bracket_coords = bracket_ring.gens[: algebra.n]
        self._value_coords = value_ring.gens[: algebra.n]
        self._monomials: dict = {}  # Laurent monomial -> its canonical QQ(parameters) coefficient
        self.flint = None  # flint's fmpz_mpoly context of the bracket ring, when brackets run there (_use_flint)
        self.flint_q = None  # flint's fmpq_mpoly context of the value ring, when apply runs there (_use_flint)
        self._exponents: dict = {}  # flint's exponent tuple (fmpz) -> the same as Python ints, for _apply_flint
        self._generators: dict = {}  # number field K -> the image in the domain of K's generator, for constants

    # -- construction -------------------------------------------------------------
    @classmethod
    def build(cls, algebra, fields: dict, laurent: bool = True):
        """Convert ``{key: VectorField}`` (polynomial components), ``None`` if some component is not a ring element.

        With ``laurent=True`` the Laurent representation is chosen when every
        coefficient divides only by monomials in the parameters; otherwise the
        algebra's own ring is used.
        """
        comps = [c for X in fields.values() for c in X.components]
        if not all(isinstance(c, PolyElement) and c.ring == algebra.ring for c in comps):
            return None
        if laurent:
            backend = cls._laurent(algebra, fields)
            if backend is not None:
                return backend
        return cls.on_ring(algebra, {k: X.components for k, X in fields.items()})

    @classmethod
    def on_ring(cls, algebra, fields: dict = None):
        """The backend on ``algebra``'s own ring (``algebra.ring``, ``algebra.n``, ``algebra.diff``), with
        ``fields`` given as ``{key: tuple of ring elements}``.  This is how a jet ring (total derivatives)
        gets the same arithmetic."""
        self = cls(algebra, algebra.ring, algebra.ring, [], False)
        for key, comps in (fields or {}).items():
            self.fields[key] = self.field(comps)
        return self

    @classmethod
    def _laurent(cls, algebra, fields):
        params = algebra.parameters
        base = CoefficientField.of(algebra.domain).ground
        names = [str(s) for s in algebra.coordinates + algebra.constants]
        for p in params:
            names += [str(p), f"{p}_inv"]
        if len(set(names)) != len(names):
            return None
        value_ring = ring(names, base)[0]
        first = algebra.n + len(algebra.constants)
        pairs = [(first + 2 * k, first + 2 * k + 1) for k in range(len(params))]
        # brackets are multilinear: over QQ, clear each field's denominators and bracket over ZZ (Python ints,
        # no rational normalisation), carrying the product of the scales along
        bracket_ring = ring(names, ZZ)[0] if base.is_QQ else value_ring
        self = cls(algebra, value_ring, bracket_ring, pairs, True)
        self._use_flint()
        for key, X in fields.items():
            parts = [self._from_algebra(c) for c in X.components]
            if any(p is None for p in parts):
                return None
            self.fields[key] = self.field(parts)
        return self

    def _from_algebra(self, poly):
        """An algebra element in the Laurent ring, ``None`` when a coefficient's denominator is not a monomial."""
        params = self.algebra.parameters
        out = {}
        for monom, coeff in poly.items():
            if not params:
                out[monom] = coeff
                continue
            numer, denom = coeff.numer, coeff.denom
            if len(denom) != 1:
                return None
            [(dexp, dcoeff)] = denom.items()
            for nexp, ncoeff in numer.items():
                lexp = []
                for a, b in zip(nexp, dexp):
                    k = a - b
                    lexp += [k, 0] if k >= 0 else [0, -k]
                key = monom + tuple(lexp)
                out[key] = out.get(key, 0) + ncoeff / dcoeff
        return self.ring.from_dict({k: v for k, v in out.items() if v})

    def field(self, values) -> _Field:
        """The internal field whose components are ``values`` (elements of :attr:`ring`)."""
        values = tuple(values)
        if not self._integral:
            return _Field(values, 1, values)
        scale = lcm(1, *(int(c.denominator) for part in values for c in part.coeffs()))
        parts = [self.bracket_ring.from_dict({m: ZZ(int(c * scale)) for m, c in part.items()}) for part in values]
        return _Field(parts, scale, values)

    def values(self, X: _Field) -> tuple:
        """The components of ``X`` as elements of :attr:`ring` (scale divided out)."""
        if X._values is None:
            k = self.domain.convert(sympy.Rational(1, X.scale))
            X._values = tuple(self.ring.from_dict({m: k * c for m, c in comp.items()}) for comp in X.components)
        return X._values

    def from_vector_field(self, V: VectorField) -> _Field:
        if not self.laurent:
            return self.field(V.components)
        parts = [self._from_algebra(c) for c in V.components]
        if any(p is None for p in parts):
            raise NambuBCHError(
                f"{V} has a coefficient whose denominator is not a monomial in the parameters; "
                "the Laurent backend accepts only monomial denominators (use laurent=False)")
        return self.field(parts)

    def to_vector_field(self, X: _Field) -> VectorField:
        return self.combine([(1, X)])

    def function(self, expr):
        """A polynomial function (sympy expression or algebra element) as an element of :attr:`ring`."""
        value = self.algebra.convert(expr)
        if not self.algebra.is_polynomial(value):
            raise NambuBCHError(f"{expr} is not a polynomial in {self.algebra.coordinates} over the parameter field")
        if not self.laurent:
            return value
        out = self._from_algebra(value)
        if out is None:
            raise NambuBCHError(f"{expr} has a denominator that is not a monomial in the parameters")
        return out

    def function_to_sympy(self, f):
        return self.algebra.to_sympy(self.to_algebra(self.reduce(f)))

    # -- flint ---------------------------------------------------------------------
    def _use_flint(self):
        """Brackets over ``ZZ`` (the integral Laurent ring) on flint's ``fmpz_mpoly`` when python-flint is available and
        the elimination's fast paths are on (``NAMBU_BCH_DISABLE_FLINT=1`` keeps sympy's ring): the same polynomials,
        products in C."""
        from .elimination import FAST_PATHS

        if self._integral and FAST_PATHS and _flint.available():
            self.flint = _flint.fmpz_mpoly_context(len(self.bracket_ring.symbols))  # the bracket ring's generators
            if _flint.qq_is_fmpq(self.domain.dtype):  # sympy's QQ is flint's fmpq: coefficients pass unconverted
                self.flint_q = _flint.fmpq_mpoly_context(len(self.ring.symbols))

    def to_flint(self, X: _Field) -> tuple:
        """The components of ``X`` as ``fmpz_mpoly`` (kept with ``X``)."""
        if X.flint is None:
            ctx = self.flint
            X.flint = tuple(ctx.from_dict({m: int(c) for m, c in comp.items()}) for comp in X.components)
        return X.flint

    def from_flint(self, p):
        """An ``fmpz_mpoly`` as an element of :attr:`bracket_ring`."""
        ring = self.bracket_ring
        ZZ_ = ring.domain
        return ring.dtype(zip(exponents(p), map(ZZ_.dtype, map(int, p.coeffs())))) if not p.is_zero() else ring.zero

    def holds_laurent_pairs(self, p) -> bool:
        """Whether a flint polynomial in the ring's generators holds some ``p`` and its ``p_inv`` (by its degrees):
        only then can a term need :meth:`reduce`."""
        degrees = p.degrees()
        return any(degrees[i] > 0 and degrees[j] > 0 for i, j in self._pairs)

    def _reduce_flint(self, p):
        """:meth:`reduce` of an ``fmpz_mpoly``: untouched unless some ``p`` and ``p_inv`` both occur (degrees)."""
        if not self.holds_laurent_pairs(p):
            return p
        poly = self.reduce(self.from_flint(p))
        return self.flint.from_dict({m: int(c) for m, c in poly.items()})

    def _bracket_flint(self, X: _Field, Y: _Field) -> _Field:
        """:meth:`bracket` on flint polynomials (derivatives kept with the fields, as there)."""
        n = self.algebra.n
        Xc, Yc = self.to_flint(X), self.to_flint(Y)
        dX = X._derivatives or _new_derivatives(X, n)
        dY = Y._derivatives or _new_derivatives(Y, n)
        zero = self.flint.from_dict({})
        comps = []
        for i in range(n):
            total = zero
            dXi, dYi = dX[i], dY[i]
            for j in range(n):
                if not Xc[j].is_zero():
                    d = dYi[j]
                    if d is None:
                        d = dYi[j] = Yc[i].derivative(j)
                    if not d.is_zero():
                        total = total + Xc[j] * d
                if not Yc[j].is_zero():
                    d = dXi[j]
                    if d is None:
                        d = dXi[j] = Xc[i].derivative(j)
                    if not d.is_zero():
                        total = total - Yc[j] * d
            comps.append(self._reduce_flint(total))
        return _Field(None, X.scale * Y.scale, flint=tuple(comps), backend=self)

    # -- calculus -----------------------------------------------------------------
    def reduce(self, poly):
        """Canonical Laurent form of a ring element: no monomial holds both ``p`` and ``p_inv`` (``p p_inv = 1``)."""
        pairs = self._pairs
        if not pairs or not any(m[i] and m[j] for m in poly.keys() for i, j in pairs):
            return poly
        out = {}
        for m, c in poly.items():
            m = list(m)
            for i, j in pairs:
                k = m[i] - m[j]
                m[i], m[j] = (k, 0) if k >= 0 else (0, -k)
            key = tuple(m)
            out[key] = out.get(key, 0) + c
        return poly.ring.from_dict({k: v for k, v in out.items() if v})

    def derivative(self, f, i: int):
        """``D_i f``: the coordinate derivative (Laurent) or the algebra's own ``diff`` (e.g. total derivative)."""
        if self.laurent:
            return f.diff(self._value_coords[i])
        return self.algebra.diff(f, i)

    def _diff(self, c, j: int):
        """``D_j c`` for a component in :attr:`bracket_ring`."""
        if self.laurent:
            return c.diff(self._bracket_coords[j])
        return self.algebra.diff(c, j)

    def bracket(self, X: _Field, Y: _Field) -> _Field:
        """``[X, Y]^i = X^j D_j Y^i - Y^j D_j X^i`` (operator commutator, Eq. CL1).

        The derivatives ``D_j X^i`` are computed when first needed (only where the other field's ``j``-th
        component is non-zero) and kept with the field: memoised leaves of a BCH series reuse them.
        """
        if self.flint is not None:
            return self._bracket_flint(X, Y)
        n = self.algebra.n
        Xc, Yc = X.components, Y.components
        dX = X._derivatives or _new_derivatives(X, n)
        dY = Y._derivatives or _new_derivatives(Y, n)
        zero = self.bracket_ring.zero
        comps = []
        for i in range(n):
            total = zero
            dXi, dYi = dX[i], dY[i]
            for j in range(n):
                if Xc[j]:
                    d = dYi[j]
                    if d is None:
                        d = dYi[j] = self._diff(Yc[i], j)
                    if d:
                        total = total + Xc[j] * d
                if Yc[j]:
                    d = dXi[j]
                    if d is None:
                        d = dXi[j] = self._diff(Xc[i], j)
                    if d:
                        total = total - Yc[j] * d
            comps.append(self.reduce(total))
        if self._integral:
            return _Field(comps, X.scale * Y.scale)
        return _Field(comps, 1, tuple(comps))

    def apply(self, X: _Field, f):
        """``X f = sum_i X^i D_i f`` for ``f`` in :attr:`ring`."""
        total = self.zero
        if not f:
            return total
        if self.flint_q is not None:
            return self._apply_flint(X, f)
        for i, c in enumerate(self.values(X)):
            if c:
                d = self.derivative(f, i)
                if d:
                    total = total + c * d
        return self.reduce(total)

    def _apply_flint(self, X: _Field, f):
        """:meth:`apply` with the products on flint's ``fmpq_mpoly`` (the value ring's generators, coefficients
        sympy's own ``fmpq``): the same polynomial, brought to the Laurent form by :meth:`reduce` as there.

        Backward error analysis over the parameters (the symbolic rigid body) multiplies Laurent polynomials
        of a few hundred terms; sympy's products are Python loops over the pairs of terms."""
        ctx = self.flint_q
        if X.flint_values is None:
            X.flint_values = tuple(ctx.from_dict(dict(c)) if c else None for c in self.values(X))
        total = flint_lie_derivative(X.flint_values, ctx.from_dict(dict(f)))
        if total is None:
            return self.zero
        # flint's exponents are fmpz, which must not reach sympy's ring; a series of backward error analysis meets
        # the same few thousand monomials again and again, and a dictionary lookup costs a fifth of converting them
        poly = self.ring.dtype(zip(exponents(total, self._exponents), total.coeffs()))
        # no term holds both p and p_inv unless both occur: then no reduction to do
        return self.reduce(poly) if self.holds_laurent_pairs(total) else poly

    @staticmethod
    def is_zero(X: _Field) -> bool:
        if X._components is None:
            return all(c.is_zero() for c in X.flint)
        return not any(X.components)

    @staticmethod
    def is_zero_function(f) -> bool:
        return not f

    # -- scalars and linear combinations --------------------------------------------
    def constants(self, numbers) -> list:
        """Exact sympy numbers as elements of the ring's domain (algebraic ones via one primitive element)."""
        numbers = list(numbers)
        if not numbers:
            return []
        K, elems = number_field(numbers)
        if K == self.domain:
            return list(elems)
        if K.is_ZZ or K.is_QQ:
            return [self.domain.convert_from(e, K) for e in elems]
        if K.is_GaussianField or K.is_AlgebraicField:
            return [self._from_number_field(K, e) for e in elems]
        return [self._constant(c) for c in numbers]

    def _from_number_field(self, K, e):
        """The element ``e`` of the number field ``K = QQ(theta)`` (sympy's ``QQ_I``, or ``QQ<theta>``) in the
        domain: ``sum_k c_k theta^k`` with ``theta``'s image converted once per field.  ``from_sympy`` per number
        recomputes the number's minimal polynomial and its place in the domain's field (a primitive-element
        computation, ~20 ms a number for ``1/4 + I/4`` in ``QQ<I>``)."""
        domain = self.domain
        theta = self._generators.get(K)
        if theta is None:
            theta = self._generators[K] = self._constant(sympy.I if K.is_GaussianField else K.ext.as_expr())
        if K.is_GaussianField:
            return domain.convert_from(e.x, K.dom) + domain.convert_from(e.y, K.dom) * theta
        value = domain.zero
        for c in e.to_list():  # the coefficients in theta, highest power first (Horner)
            value = value * theta + domain.convert_from(c, K.dom)
        return value

    def rational(self, q):
        return self.domain.convert(q)

    def _constant(self, c):
        if isinstance(c, (int, sympy.Basic)):
            return self.domain.from_sympy(sympy.sympify(c, strict=True))
        return c  # already an element of the ring's domain

    def combine(self, pairs) -> VectorField:
        """``sum c X`` (``c`` exact sympy numbers or domain elements) as a :class:`VectorField` of the algebra."""
        return self._combine([(self._constant(c), X) for c, X in pairs], self.domain.one)

    def scaled_combine(self, denominator: int, pairs) -> VectorField:
        """``(1/denominator) sum n X`` with integer (or domain-element) numerators ``n``: one division per field."""
        return self._combine(pairs, self.domain.convert(sympy.Rational(1, denominator)))

    def _combine(self, pairs, factor) -> VectorField:
        algebra = self.algebra
        if not pairs:
            return VectorField.zero(algebra)
        # accumulate monomial by monomial, one sum per scale (integers in the Laurent case over QQ): for the
        # many small fields of a series this beats ring arithmetic, and rationals appear once per monomial
        by_scale: dict = {}
        sums: dict = {}  # flint: scale -> the components' integer combination (fields made by flint brackets)
        for n, X in pairs:
            if X.flint is not None and X._components is None and isinstance(n, int):
                acc = sums.get(X.scale)
                sums[X.scale] = [c * n for c in X.flint] if acc is None else [a + c * n for a, c in zip(acc, X.flint)]
                continue
            totals = by_scale.setdefault(X.scale, [{} for _ in range(algebra.n)])
            for acc, comp in zip(totals, X.components):
                for monom, coeff in comp.items():
                    acc[monom] = acc.get(monom, 0) + coeff * n
        for scale, comps in sums.items():
            totals = by_scale.setdefault(scale, [{} for _ in range(algebra.n)])
            for acc, comp in zip(totals, comps):
                for monom, coeff in zip(exponents(comp), comp.coeffs()):
                    acc[monom] = acc.get(monom, 0) + ZZ(int(coeff))
        domain = self.domain
        out = [{} for _ in range(algebra.n)]
        for scale, totals in by_scale.items():
            k = factor * domain.convert(sympy.Rational(1, scale)) if scale != 1 else factor
            for acc, target in zip(totals, out):
                for monom, c in acc.items():
                    if c:
                        target[monom] = target.get(monom, 0) + k * c
        polys = [self.ring.from_dict({m: c for m, c in acc.items() if c}) for acc in out]
        return VectorField(algebra, [self.to_algebra(p) for p in polys])

    def vector_field(self, values) -> VectorField:
        """Components in :attr:`ring` (e.g. of a series computed with :meth:`apply`) as a :class:`VectorField`."""
        return VectorField(self.algebra, [self.to_algebra(self.reduce(c)) for c in values])

    def to_algebra(self, poly):
        """An element of :attr:`ring` back in the algebra's ring over ``QQ(parameters)``."""
        algebra = self.algebra
        if not self.laurent:
            return poly
        split = algebra.n + len(algebra.constants)
        if not algebra.parameters:
            return algebra.ring.from_dict(dict(poly.items())) if poly else algebra.ring.zero
        field = algebra.domain.field
        pring = field.ring
        groups: dict = {}
        for m, c in poly.items():
            groups.setdefault(m[:split], []).append((m[split:], c))
        out = {}
        base = pring.domain
        for head, items in groups.items():
            if len(items) == 1 and base.is_QQ:
                # one Laurent monomial r/s p^a q^-b: already canonical as (r p^a) / (s q^b), no gcd needed
                (lexp, c), = items
                key = (lexp, c.numerator, c.denominator)
                value = self._monomials.get(key)
                if value is None:
                    up, down = tuple(lexp[0::2]), tuple(lexp[1::2])
                    value = field.raw_new(
                        pring.from_dict({up: base(c.numerator)}), pring.from_dict({down: base(c.denominator)})
                    )
                    self._monomials[key] = value
                out[head] = value
                continue
            shift = [max((lexp[2 * k + 1] for lexp, _ in items), default=0) for k in range(len(algebra.parameters))]
            numer = {}
            for lexp, c in items:
                e = tuple(lexp[2 * k] - lexp[2 * k + 1] + shift[k] for k in range(len(shift)))
                numer[e] = numer.get(e, 0) + c
            num = pring.from_dict(numer)
            den = pring.from_dict({tuple(shift): pring.domain.one})
            out[head] = field.new(num, den)
        return algebra.ring.from_dict(out)


def flint_lie_derivative(values, g):
    """``X g = sum_i X^i d_i g`` on flint polynomials: ``values`` the field's components (``None`` for a zero one),
    ``g`` a polynomial of the same context; ``None`` when the result is zero.  Not brought to the Laurent form
    (:meth:`PolynomialBackend.holds_laurent_pairs` says whether it may need :meth:`PolynomialBackend.reduce`)."""
    total = None
    for i, c in enumerate(values):
        if c is not None:
            d = g.derivative(i)
            if not d.is_zero():
                total = c * d if total is None else total + c * d
    return None if total is None or total.is_zero() else total


def _normal(expr):
    """The normal form of a component: ``p/q`` cancelled for a rational function, else the expansion."""
    expr = sympy.sympify(expr, strict=True)
    if expr.is_rational_function() and not expr.is_polynomial():
        return sympy.cancel(expr)
    return sympy.expand(expr)


class ExpressionBackend:
    """Vector fields whose components are sympy expressions in normal form (non-polynomial Hamiltonians).

    Examples
    --------
    >>> import sympy
    >>> from nambu_bch import System
    >>> S = System("x1 x2", ["x2**2/2 - cos(x1)"], [], name="pendulum").splitting
    >>> E = ExpressionBackend(S.system.algebra, {p.number: p.field for p in S.pieces})
    >>> E.to_vector_field(E.bracket(E.fields[1], E.fields[2])).to_sympy()
    (sin(x1), -x2*cos(x1))
    """

    laurent = False
    domain = None  # scalars are sympy numbers

    def __init__(self, algebra, fields: dict = None):
        self.algebra = algebra
        self.coordinates = tuple(algebra.coordinates)
        self.zero, self.one = sympy.Integer(0), sympy.Integer(1)
        self.fields = {k: self.from_vector_field(X) for k, X in (fields or {}).items()}

    def from_vector_field(self, V: VectorField) -> tuple:
        return tuple(_normal(self.algebra.to_sympy(c)) for c in V.components)

    def to_vector_field(self, X) -> VectorField:
        return VectorField(self.algebra, X)

    def function(self, expr):
        return _normal(self.algebra.to_sympy(expr))

    @staticmethod
    def function_to_sympy(f):
        return f

    def field(self, values) -> tuple:
        return tuple(values)

    @staticmethod
    def values(X) -> tuple:
        return X

    def derivative(self, f, i: int):
        return sympy.diff(f, self.coordinates[i])

    def bracket(self, X, Y) -> tuple:
        """``[X, Y]^i = X^j d_j Y^i - Y^j d_j X^i`` (Eq. CL1), in normal form."""
        coords = self.coordinates
        out = []
        for i in range(len(coords)):
            total = sympy.Integer(0)
            for j, x in enumerate(coords):
                if X[j] != 0:
                    total += X[j] * sympy.diff(Y[i], x)
                if Y[j] != 0:
                    total -= Y[j] * sympy.diff(X[i], x)
            out.append(_normal(total))
        return tuple(out)

    def apply(self, X, f):
        """``X f = sum_i X^i d f / d x_i``, in normal form."""
        if f == 0:
            return self.zero
        return _normal(sum((c * sympy.diff(f, x) for c, x in zip(X, self.coordinates) if c != 0), self.zero))

    @staticmethod
    def is_zero(X) -> bool:
        return all(c == 0 for c in X)

    @staticmethod
    def is_zero_function(f) -> bool:
        return f == 0

    @staticmethod
    def constants(numbers) -> list:
        return [sympy.sympify(c, strict=True) for c in numbers]

    @staticmethod
    def rational(q):
        return q

    def combine(self, pairs) -> VectorField:
        totals = [sympy.Integer(0)] * self.algebra.n
        for c, X in pairs:
            totals = [t + sympy.sympify(c, strict=True) * comp for t, comp in zip(totals, X)]
        return VectorField(self.algebra, [_normal(t) for t in totals])

    def scaled_combine(self, denominator: int, pairs) -> VectorField:
        return self.combine([(sympy.Rational(sympy.sympify(n, strict=True), denominator), X) for n, X in pairs])

    def vector_field(self, values) -> VectorField:
        return VectorField(self.algebra, [_normal(c) for c in values])


def field_backend(algebra, fields: dict, laurent: bool = True) -> FieldBackend:
    """The exact backend for ``{key: VectorField}`` on ``algebra``.

    :class:`PolynomialBackend` when every component is a ring element (Laurent
    representation when possible and ``laurent`` is true, else the algebra's ring
    over ``QQ(parameters)``), :class:`ExpressionBackend` otherwise.

    >>> from nambu_bch import model
    >>> S = model("ho").splitting
    >>> B = field_backend(S.system.algebra, {p.number: p.field for p in S.pieces})
    >>> type(B).__name__, B.laurent
    ('PolynomialBackend', True)
    """
    check_ring(algebra, "algebra")
    check_type(fields, dict, "fields")
    backend = PolynomialBackend.build(algebra, fields, laurent)
    if backend is not None:
        return backend
    return ExpressionBackend(algebra, fields)
