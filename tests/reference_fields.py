"""Slow reference routes to ``X_eff``, kept as independent checks of the field backends.

Both run on :class:`~nambu_bch.algebra.VectorField` methods only (the system's
ring over ``QQ(parameters)``, or sympy expressions for non-polynomial fields),
never on :mod:`nambu_bch.algebra.backend`:

* :func:`effective_field_reference` -- backward error analysis by the plain
  recursion ``Z_j^i = [h^{j+1}] (Phi_h^* x_i - exp(h Z_{<j}) x_i)`` with truncated
  Lie series in ``h`` (Hairer, Lubich, Wanner, *Geometric Numerical Integration*,
  Sect. IX.1); this was ``effective_field(..., fast=False)`` before the backends.
* :func:`effective_field_bch_reference` -- the formal BCH series (Eq. BCH2)
  evaluated with ``VectorField.bracket`` and summed with ``VectorField`` arithmetic;
  this was ``effective_field_bch(..., fast=False)`` before the backends.

Import from a test with ``sys.path`` holding this directory (``--import-mode=importlib``).
"""

from __future__ import annotations

import sympy

from nambu_bch.algebra import VectorField
from nambu_bch.bch import BracketEvaluator, EffectiveField, check_order, formal_bch
from nambu_bch.integrators.composition import composition_for

H = sympy.Symbol("h")


class _HSeries:
    """Truncation and coefficient extraction in the step ``h`` for ring elements or sympy expressions."""

    def __init__(self, algebra):
        self.algebra = algebra
        self.index = algebra.n + algebra.constants.index(H)

    def truncate(self, value, degree):
        if self.algebra.is_polynomial(value):
            return value.ring.from_dict({m: c for m, c in value.items() if m[self.index] <= degree})
        poly = sympy.Poly(sympy.expand(value), H)
        return sum((c * H**k for (k,), c in poly.terms() if k <= degree), sympy.Integer(0))

    def coefficient(self, value, degree):
        if self.algebra.is_polynomial(value):
            i = self.index
            return value.ring.from_dict({m[:i] + (0,) + m[i + 1:]: c for m, c in value.items() if m[i] == degree})
        return sympy.expand(value).coeff(H, degree)


def _exp_apply(series, field, scale, value, degree):
    """``exp(scale * field) value`` truncated at ``h**degree`` (``scale`` carries the ``h``)."""
    algebra = series.algebra
    total, term = value, value
    for n in range(1, degree + 1):
        # non-polynomial fields (sin, H1(x1)) give sympy values: bring the factors to one kind
        s, applied, r = algebra.common(algebra.convert(scale), field.apply(term), algebra.convert(sympy.Rational(1, n)))
        term = series.truncate(s * applied * r, degree)
        if algebra.is_zero(term):
            break
        total, term = algebra.common(total, term)
        total = total + term
    return total


def _setup(splitting, comp):
    comp = composition_for(comp, splitting)
    algebra = splitting.system.algebra.with_constants(H, extension=comp.extension)
    fields = [VectorField(algebra, p.field.to_sympy()) if comp.extension else p.field for p in splitting.pieces]
    return comp, algebra, fields


def effective_field_reference(splitting, comp, order: int = 2) -> EffectiveField:
    """``X_eff`` through ``h**order`` by the ungraded backward-error recursion on ``VectorField`` methods.

    >>> from nambu_bch import model
    >>> effective_field_reference(model("ho").splitting, "121", 2)[2].to_sympy()    # Eq. (SHPV1)
    (-omega**2*x2/(12*m), -m*omega**4*x1/6)
    """
    order = check_order(order)
    comp, algebra, fields = _setup(splitting, comp)
    series = _HSeries(algebra)
    h = algebra.convert(H)
    top = order + 1
    coords = algebra.gens[: algebra.n]
    pulled = []
    for x in coords:
        value = x
        for k, c in reversed(comp.factors()):
            value = _exp_apply(series, fields[k - 1], h * algebra.convert(c), value, top)
        pulled.append(value)
    Z = []
    for j in range(order + 1):
        partial = VectorField.zero(algebra)
        for l, Zl in enumerate(Z):
            partial = partial + Zl.scale(H**l)
        comps = []
        for x, target in zip(coords, pulled):
            current = _exp_apply(series, partial, h, x, j + 1)
            target, current = algebra.common(target, current)
            comps.append(series.coefficient(target - current, j + 1))
        Z.append(VectorField(algebra, comps))
    return EffectiveField(tuple(Z), order, comp, splitting)


def effective_field_bch_reference(splitting, comp, order: int = 2) -> EffectiveField:
    """``X_eff`` through ``h**order`` from the formal BCH series with ``VectorField.bracket`` (Eq. BCH2).

    >>> from nambu_bch import model
    >>> effective_field_bch_reference(model("ho").splitting, "121", 2)[2].to_sympy()    # Eq. (SHPV1)
    (-omega**2*x2/(12*m), -m*omega**4*x1/6)
    """
    order = check_order(order)
    comp, algebra, fields = _setup(splitting, comp)
    series = formal_bch(comp, order + 1)
    evaluator = BracketEvaluator(dict(enumerate(fields, 1)))
    Z = []
    for j in range(order + 1):
        total = VectorField.zero(algebra)
        for c, tree in series.terms(j + 1):
            X = evaluator.value(tree)
            if X is not None:
                total = total + X.scale(sympy.sympify(c))
        Z.append(total)
    return EffectiveField(tuple(Z), order, comp, splitting)
