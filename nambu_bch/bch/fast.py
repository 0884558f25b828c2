"""A faster exact representation for brackets: Laurent polynomials in the parameters over QQ.

The system's ring has coefficients in the rational-function field
``QQ(m, omega, ...)``; every coefficient operation there normalises a fraction
with a polynomial gcd, which dominates the cost of nested brackets (the rigid
body, ``QQ(I1, I2, I3)``).  The fields of the built-in models only ever divide
by *monomials* in the parameters (``1/m``, ``1/I2 - 1/I3``), i.e. their
coefficients are Laurent polynomials.  Here a parameter ``p`` becomes two
ordinary ring generators ``p`` and ``p_inv`` over QQ (or QQ(2^(1/3))), and every
product is brought back to the canonical form in which no monomial contains
both (``p^a p_inv^b -> p^(a-b)`` or ``p_inv^(b-a)``).  Laurent monomials are a
basis, so the canonical form is unique and zero tests stay structural and
exact; the coefficient arithmetic is plain rationals, no gcds.  Derivatives are
taken only by coordinates, where ``p``, ``p_inv`` are constants.  Brackets are
multilinear, so each field's rational denominators are cleared once and nested
brackets run over ZZ (Python ints), the product of the scales carried along and
divided out once when a linear combination is converted back.

A field with a non-monomial denominator (``1/(m + 1)``) or a non-polynomial
component is not representable: :meth:`FastFields.build` returns ``None`` and
the caller keeps the system's own ring.

References
----------
Laurent polynomial rings as localisations ``QQ[p, 1/p]``: Cox, Little, O'Shea,
*Ideals, Varieties, and Algorithms*, Sect. 3.2 (the ``p y - 1`` trick, here
reduced explicitly); Horikoshi, Eq. (CL1) (bracket convention).
"""

from __future__ import annotations

from math import lcm

import sympy
from sympy.polys.constructor import construct_domain
from sympy.polys.domains import ZZ
from sympy.polys.rings import PolyElement, ring

from ..algebra import VectorField


class _Field:
    """``components / scale`` (integral components when the base is QQ) plus derivatives computed once."""

    __slots__ = ("components", "scale", "_derivatives")

    def __init__(self, components, scale=1):
        self.components = tuple(components)
        self.scale = scale
        self._derivatives = None

    def derivatives(self, gens):
        if self._derivatives is None:
            self._derivatives = tuple(tuple(c.diff(x) for x in gens) for c in self.components)
        return self._derivatives


class FastFields:
    """Vector fields on ``algebra``'s coordinates with Laurent-polynomial coefficients.

    Use :meth:`build`; then ``fields`` (piece number -> internal field),
    ``bracket``, ``is_zero`` and ``combination`` plug into
    :class:`~nambu_bch.bch.evaluation.BracketEvaluator`.

    Examples
    --------
    >>> from nambu_bch import model
    >>> S = model("rigid-body").splitting
    >>> F = FastFields.build(S.system.algebra, {p.number: p.field for p in S.pieces})
    >>> F.ring.symbols[3:]
    (h, I1, I1_inv, I2, I2_inv, I3, I3_inv)
    >>> Z = F.combination([(1, F.bracket(F.fields[1], F.fields[2]))])
    >>> Z == S[1].field.bracket(S[2].field)
    True
    """

    def __init__(self, algebra, ring_, laurent, fields):
        self.algebra = algebra
        self.ring = ring_  # over QQ (or QQ(2^(1/3))): the values, for rational arithmetic
        self.bracket_ring = ring_  # over ZZ when the base is QQ: brackets of integral components
        self._laurent = laurent  # [(index of p, index of p_inv)] in the ring's generators
        self.fields = fields
        self.rational_fields: dict = {}  # key -> components in ``ring`` (the actual values)
        self._monomials: dict = {}  # Laurent monomial -> its canonical QQ(parameters) coefficient
        self._coords = ring_.gens[: algebra.n]

    # -- construction -------------------------------------------------------------
    @classmethod
    def build(cls, algebra, fields: dict):
        """Convert ``{key: VectorField}``; ``None`` if some coefficient is not Laurent."""
        comps = [c for X in fields.values() for c in X.components]
        if not all(isinstance(c, PolyElement) and c.ring == algebra.ring for c in comps):
            return None
        params = algebra.parameters
        base = algebra.domain.field.domain if params else algebra.domain
        names = [str(s) for s in algebra.coordinates + algebra.constants]
        for p in params:
            names += [str(p), f"{p}_inv"]
        if len(set(names)) != len(names):
            return None
        ring_, *_ = ring(names, base)
        first = algebra.n + len(algebra.constants)
        laurent = [(first + 2 * k, first + 2 * k + 1) for k in range(len(params))]
        self = cls(algebra, ring_, laurent, {})
        if base.is_QQ:
            # brackets are multilinear: clear each field's denominators and bracket over ZZ (Python ints,
            # no rational normalisation), carrying the product of the scales along
            self.bracket_ring = ring(names, ZZ)[0]
            self._coords = self.bracket_ring.gens[: algebra.n]
        for key, X in fields.items():
            parts = [self._from_algebra(c) for c in X.components]
            if any(p is None for p in parts):
                return None
            self.rational_fields[key] = tuple(parts)
            if base.is_QQ:
                scale = lcm(1, *(int(c.denominator) for part in parts for c in part.coeffs()))
                parts = [self.bracket_ring.from_dict({m: ZZ(int(c * scale)) for m, c in part.items()}) for part in parts]
            else:
                scale = 1
            self.fields[key] = _Field(parts, scale)
        return self

    def _from_algebra(self, poly):
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

    # -- operations ---------------------------------------------------------------
    def reduce(self, poly):
        """Canonical Laurent form of a ring element: no monomial holds both ``p`` and ``p_inv`` (``p p_inv = 1``)."""
        pairs = self._laurent
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

    def bracket(self, X: _Field, Y: _Field) -> _Field:
        """``[X, Y]^i = X^j d_j Y^i - Y^j d_j X^i`` (operator commutator, Eq. CL1)."""
        gens = self._coords
        dX, dY = X.derivatives(gens), Y.derivatives(gens)
        zero = self.bracket_ring.zero
        comps = []
        for i in range(len(gens)):
            total = zero
            for j in range(len(gens)):
                if X.components[j] and dY[i][j]:
                    total = total + X.components[j] * dY[i][j]
                if Y.components[j] and dX[i][j]:
                    total = total - Y.components[j] * dX[i][j]
            comps.append(self.reduce(total))
        return _Field(comps, X.scale * Y.scale)

    def coefficients(self, numbers) -> list:
        """Exact sympy numbers as elements of the ring's domain (algebraic ones via one primitive element)."""
        K, elems = construct_domain(list(numbers), extension=True)
        domain = self.ring.domain
        if K == domain:
            return list(elems)
        if K.is_ZZ or K.is_QQ:
            return [domain.convert_from(e, K) for e in elems]
        return [self._coefficient(c) for c in numbers]

    @staticmethod
    def is_zero(X: _Field) -> bool:
        return not any(X.components)

    def _coefficient(self, c):
        if isinstance(c, (int, sympy.Basic)):
            return self.ring.domain.from_sympy(sympy.sympify(c))
        return c  # already an element of the ring's domain

    def combination(self, pairs) -> VectorField:
        """``sum c X`` (``c`` exact sympy numbers or domain elements) as a :class:`VectorField` of the algebra."""
        return self._combine([(self._coefficient(c), X) for c, X in pairs], self.ring.domain.one)

    def scaled_combination(self, denominator: int, pairs) -> VectorField:
        """``(1/denominator) sum n X`` with integer (or domain-element) numerators ``n``: one division per field."""
        return self._combine(pairs, self.ring.domain.convert(sympy.Rational(1, denominator)))

    def _combine(self, pairs, factor) -> VectorField:
        if not pairs:
            return VectorField.zero(self.algebra)
        # accumulate monomial by monomial, one integer sum per scale: for the many small fields of a
        # series this beats ring arithmetic, and rationals appear only once per monomial at the end
        by_scale: dict = {}
        for n, X in pairs:
            totals = by_scale.setdefault(X.scale, [{} for _ in range(self.algebra.n)])
            for acc, comp in zip(totals, X.components):
                for monom, coeff in comp.items():
                    acc[monom] = acc.get(monom, 0) + coeff * n
        domain = self.ring.domain
        out = [{} for _ in range(self.algebra.n)]
        for scale, totals in by_scale.items():
            k = factor * domain.convert(sympy.Rational(1, scale)) if scale != 1 else factor
            for acc, target in zip(totals, out):
                for monom, c in acc.items():
                    if c:
                        target[monom] = target.get(monom, 0) + k * c
        polys = [self.ring.from_dict({m: c for m, c in acc.items() if c}) for acc in out]
        return VectorField(self.algebra, [self.to_algebra(p) for p in polys])

    def to_algebra(self, poly):
        """A Laurent-ring element back in the algebra's ring over ``QQ(parameters)``."""
        algebra = self.algebra
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


class SympyFields:
    """Fallback for non-polynomial fields (``sin``, undefined functions ``H1(x1)``): expanded sympy expressions.

    Brackets are ``diff`` + ``expand``; the zero test is structural after
    ``expand`` (no ``simplify``).  It never calls a non-zero field zero; an
    exotic zero that only ``simplify`` would see (``sin^2 + cos^2 - 1``) is kept,
    which costs a term but never changes a value.
    """

    def __init__(self, algebra, fields: dict):
        self.algebra = algebra
        self.fields = {k: tuple(sympy.expand(algebra.to_sympy(c)) for c in X.components) for k, X in fields.items()}

    def bracket(self, X, Y):
        coords = self.algebra.coordinates
        out = []
        for i in range(len(coords)):
            total = sympy.Integer(0)
            for j, x in enumerate(coords):
                if X[j] != 0:
                    total += X[j] * sympy.diff(Y[i], x)
                if Y[j] != 0:
                    total -= Y[j] * sympy.diff(X[i], x)
            out.append(sympy.expand(total))
        return tuple(out)

    @staticmethod
    def is_zero(X) -> bool:
        return all(c == 0 for c in X)

    def combination(self, pairs) -> VectorField:
        totals = [sympy.Integer(0)] * self.algebra.n
        for c, X in pairs:
            totals = [t + sympy.sympify(c) * comp for t, comp in zip(totals, X)]
        return VectorField(self.algebra, [sympy.expand(t) for t in totals])


def field_backend(algebra, fields: dict, fast: bool = True):
    """The fastest exact backend for ``{key: VectorField}``: :class:`FastFields`, else :class:`SympyFields`.

    With ``fast=False`` (or when neither applies) ``None``: use the :class:`VectorField` methods.
    """
    if not fast:
        return None
    backend = FastFields.build(algebra, fields)
    if backend is not None:
        return backend
    comps = [c for X in fields.values() for c in X.components]
    if any(not isinstance(c, PolyElement) for c in comps):
        return SympyFields(algebra, fields)
    return None
