"""Backward error analysis: the modified vector field of a composition, order by order.

The composition ``Phi_h = exp(c_1 h X_{k_1}) ... exp(c_s h X_{k_s})`` (operator
order, see :mod:`nambu_bch.integrators.composition`) pulls a function back by
``Phi_h^* f = f o Phi_h = exp(c_1 h X_{k_1})( ... exp(c_s h X_{k_s}) f)``, each
exponential a truncated Lie series ``sum_n (c h)^n / n! X^n``.  The modified
field ``X_eff = Z_0 + h Z_1 + h^2 Z_2 + ...`` is the one whose time-``h`` flow
reproduces the map, ``exp(h X_eff) x_i = Phi_h^* x_i``; comparing the
coefficients of ``h^{j+1}`` gives ``Z_j^i = [h^{j+1}] (Phi_h^* x_i - exp(h Z_{<j}) x_i)``.

This route never touches a free Lie algebra: it is the independent check of
the formal BCH series (Eqs. eL1, eL2) evaluated on concrete fields.

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.1;
Horikoshi, Eqs. (eL1), (eL2), (BCH1), (BCH2).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from ..algebra import VectorField
from ..algebra._flint import exponents
from ..algebra.backend import field_backend, flint_lie_derivative
from ..checks import MAX_ORDER, check_flag, check_int, show
from ..errors import InvalidOrderError
from ..integrators.composition import composition_for
from ..printing import Printable, aligned
from ..values import ValueEquality

H = sympy.Symbol("h")


def check_order(order, limit: int = MAX_ORDER) -> int:
    """``order`` as an int in ``0..limit`` (:data:`nambu_bch.checks.MAX_ORDER`), else :class:`InvalidOrderError`.

    Integral numbers (``2``, ``2.0``, ``sympy.Integer(2)``, numpy ints) are accepted;
    booleans, strings, fractions, ``nan`` and ``inf`` are not.

    >>> check_order(2.0)
    2
    """
    limit = check_int(limit, "limit", 0)
    if isinstance(order, (bool, str, bytes)) or order is None:
        raise InvalidOrderError(f"order must be a non-negative integer, got {show(order)}")
    if not isinstance(order, int):
        try:
            if float(order) != int(order):
                raise ValueError
            order = int(order)
        except (TypeError, ValueError, OverflowError):
            raise InvalidOrderError(f"order must be a non-negative integer, got {show(order)}") from None
    if order < 0 or order > limit:
        raise InvalidOrderError(f"order must be an integer between 0 and {limit}, got {order}")
    return order


class FieldSeries:
    """A vector field as a series ``sum_j h^j Z_j`` (``coefficients``: the ``Z_j`` as :class:`VectorField`)."""

    def __getitem__(self, j) -> VectorField:
        return self.coefficients[j]

    @property
    def field(self) -> VectorField:
        """``sum_j h^j Z_j`` as one field whose components are polynomials in ``h``."""
        total = VectorField.zero(self.coefficients[0].algebra)
        for j, Z in enumerate(self.coefficients):
            total = total + Z.scale(H**j)
        return total

    def to_sympy(self) -> tuple:
        return self.field.to_sympy()


@dataclass(frozen=True, eq=False)
class EffectiveField(FieldSeries, Printable, ValueEquality):
    """``X_eff = sum_{j=0}^{order} h^j Z_j`` of a composition.

    Attributes
    ----------
    coefficients : tuple of VectorField, ``Z_0 .. Z_order`` (``Z_0 = X_{H,G}``)
    order : int
    composition : Composition
    splitting : Splitting
    """

    coefficients: tuple
    order: int
    composition: object
    splitting: object

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the ``Z_j`` as ring elements, the composition, the splitting."""
        return self.coefficients, self.order, self.composition, self.splitting

    def to_latex(self) -> str:
        r"""``X_{\rm eff} &= (c_1)\partial_{x_1} + ... + h^{2}\Bigl(...\Bigr) + O(h^4)`` in an ``aligned`` block,
        one token per component, grouped by powers of ``h`` (Eq. BCH2 evaluated on the system)."""
        coords = self.coefficients[0].algebra.coordinates
        tokens = []
        for j, Z in enumerate(self.coefficients):
            comps = [(x, sympy.factor(c)) for x, c in zip(coords, Z.to_sympy()) if c != 0]
            if not comps:
                continue
            inner = [rf"\left({sympy.latex(c)}\right)\frac{{\partial}}{{\partial {sympy.latex(x)}}}" for x, c in comps]
            inner = [inner[0]] + ["+ " + t for t in inner[1:]]
            if j:
                step = "h" if j == 1 else f"h^{{{j}}}"
                inner[0] = rf"{step}\Bigl({inner[0]}"
                inner[-1] += r"\Bigr)"
            if tokens:
                inner[0] = "+ " + inner[0]
            tokens += inner
        tokens.append(rf"+ O(h^{{{self.composition.remainder_power(self.order)}}})")
        return aligned([(r"X_{\rm eff}", "=", tokens)])

    def to_text(self) -> str:
        """``X_eff = Z_0 + h^2 Z_2 + ... + O(h^4)``, one line per non-zero ``Z_j`` (components in the coordinates' order)."""
        lines = [f"Z_{j} = ({', '.join(str(c) for c in Z.to_sympy())})" for j, Z in enumerate(self.coefficients) if not Z.is_zero()]
        used = " + ".join(("" if j == 0 else ("h*" if j == 1 else f"h**{j}*")) + f"Z_{j}"
                          for j, Z in enumerate(self.coefficients) if not Z.is_zero())
        return "\n".join([f"X_eff = {used or '0'} + O(h^{self.composition.remainder_power(self.order)})", *lines])


def effective_field(splitting, comp, order: int = 2, fast: bool = True) -> EffectiveField:
    """``X_eff`` of ``comp`` on ``splitting`` through ``h**order`` by backward error analysis.

    Parameters
    ----------
    splitting : Splitting
    comp : Composition or word (``"12321"``)
    order : int
        Highest power of ``h`` kept in ``X_eff``.
    fast : bool
        Run the series (graded by powers of ``h``) in Laurent polynomials of the
        parameters over QQ when the fields allow it (:mod:`nambu_bch.algebra.backend`,
        no rational-function gcds); ``False`` runs it on the system's ring over
        ``QQ(parameters)``.  Non-polynomial fields run in expanded sympy
        expressions either way.  The result is the same exact field.

    Examples
    --------
    >>> from nambu_bch import model
    >>> X = effective_field(model("ho").splitting, "121", order=2)
    >>> X[2].to_sympy()    # Eq. (SHPV1): X_{H_S} - X_H at h^2
    (-omega**2*x2/(12*m), -m*omega**4*x1/6)
    """
    order = check_order(order)
    fast = check_flag(fast, "fast")
    comp = composition_for(comp, splitting)
    algebra = splitting.system.algebra.with_constants(H, extension=comp.extension)
    fields = [VectorField(algebra, p.field.to_sympy()) if comp.extension else p.field for p in splitting.pieces]
    backend = field_backend(algebra, dict(enumerate(fields, 1)), laurent=fast)
    return EffectiveField(_backward_graded(backend, comp, order), order, comp, splitting)


def _backward_graded(backend, comp, order) -> tuple:
    """``Z_0 .. Z_order`` by backward error analysis on a field backend, graded by powers of ``h``.

    Series in ``h`` are lists ``[f_0, ..., f_top]`` of ``h``-free elements, so no
    product ever produces a power of ``h`` that is thrown away.  The pull-back
    is ``[h^n] exp(c h X) f = sum_k c^k/k! X^k f_{n-k}``.  For the modified field,
    with ``U_k = (h Y)^k x`` and ``Y = sum_l h^l Z_l``,
    ``[h^n] U_k = sum_l Z_l [h^(n-1-l)] U_{k-1}`` involves only ``Z_l`` with
    ``l <= n - k``; so ``Z_j^i = [h^(j+1)] Phi^* x_i - sum_{k >= 2} [h^(j+1)] U_k / k!``
    and every ``[h^n] U_k`` is computed once (Hairer-Lubich-Wanner IX.1).
    """
    ops = _series_arithmetic(backend)
    zero = ops.zero
    top = order + 1
    one = backend.rational(sympy.Integer(1))

    def exp_pullback(field, c, series):
        out = [zero] * (top + 1)
        for m, f in enumerate(series):
            term, scale = f, one
            for k in range(0, top - m + 1):
                if k:
                    term = ops.apply(field, term)
                    scale = scale * c * backend.rational(sympy.Rational(1, k))
                if ops.is_zero_function(term):
                    break
                out[m + k] = out[m + k] + term * scale
        return out

    fields = {k: ops.field_of(X) for k, X in backend.fields.items()}
    pulled = []
    for x in backend.coordinates:
        series = [ops.load(x)] + [zero] * top
        for k, c in reversed(list(zip(comp.pieces, backend.constants(comp.coefficients)))):
            series = exp_pullback(fields[k], c, series)
        pulled.append([ops.unload(f) for f in series])
    return modified_field_of_map(backend, pulled, order)


def modified_field_of_map(backend, pulled, order) -> tuple:
    """``Z_0 .. Z_order`` of the field whose time-``h`` flow is the map with ``[h^m] Phi_h^* x_i = pulled[i][m]``.

    ``pulled[i]`` lists the ``h``-free coefficients ``m = 0 .. order + 1`` of the map's ``i``-th
    component (elements of ``backend``'s ring); any map ``x + O(h)`` given as a series in ``h``
    (a composition's pull-back, a Runge--Kutta step expanded by Taylor) has this modified field
    (Hairer-Lubich-Wanner IX.1).
    """
    ops = _series_arithmetic(backend)
    coords, zero = [ops.load(x) for x in backend.coordinates], ops.zero
    pulled = [[ops.load(f) for f in series] for series in pulled]
    n = len(coords)
    top = order + 1
    Z = []
    # U[i][k][m] = [h^m] (hY)^k x_i
    U = [[[x] + [zero] * top] + [[zero] * (top + 1) for _ in range(top)] for x in coords]
    inverse_factorial = [backend.rational(1 / sympy.factorial(k)) for k in range(top + 1)]
    # the l with Z_l != 0, increasing: a zero field adds nothing to a sum, and a symmetric composition has no odd
    # Z_l, so half of the O(order^3) applications below would apply a zero field
    live = []
    for j in range(order + 1):
        m = j + 1
        comps = []
        for i in range(n):
            Ui = U[i]
            rest = zero
            for k in range(2, m + 1):
                value = zero
                for l in live:
                    if l > m - k:
                        break
                    value = value + ops.apply(Z[l], Ui[k - 1][m - 1 - l])
                Ui[k][m] = value
                rest = rest + value * inverse_factorial[k]
            comps.append(pulled[i][m] - rest)
        Z.append(ops.field(comps))
        if not ops.is_zero(Z[j]):
            live.append(j)
        for i in range(n):
            U[i][1][m] = comps[i]
    return tuple(backend.vector_field([ops.unload(c) for c in ops.values(Zj)]) for Zj in Z)


def _series_arithmetic(backend):
    """The arithmetic of the series above: :class:`_FlintSeries` when ``backend`` applies fields on flint
    (the Laurent backend with python-flint), else :class:`_BackendSeries` (the backend's own ring)."""
    if getattr(backend, "flint_q", None) is not None:
        return _FlintSeries(backend)
    return _BackendSeries(backend)


class _BackendSeries:
    """Series coefficients as the backend's own functions, fields as its fields."""

    def __init__(self, backend):
        self.backend = backend
        self.zero = backend.zero

    def load(self, f):
        return f

    def unload(self, f):
        return f

    def field_of(self, X):
        return X

    def field(self, comps):
        return self.backend.field(comps)

    def values(self, X):
        return self.backend.values(X)

    def apply(self, X, f):
        return self.backend.apply(X, f)

    def is_zero(self, X) -> bool:
        return self.backend.is_zero(X)

    def is_zero_function(self, f) -> bool:
        return self.backend.is_zero_function(f)


class _FlintSeries:
    """Series coefficients as flint ``fmpq_mpoly`` in the Laurent value ring of ``backend``, between one
    :meth:`load` and one :meth:`unload`.

    Every coefficient of a series is met by several Lie derivatives and sums: kept in flint, it is converted to
    and from sympy's ring once (:meth:`load`, :meth:`unload`) instead of at every ``apply``, and its sums run in C.
    Products are brought to the canonical Laurent form (no term holding both ``p`` and ``p_inv``) exactly where
    the backend's own ``apply`` brings them there, so every coefficient is the same polynomial."""

    def __init__(self, backend):
        self.backend = backend
        self.ctx = backend.flint_q
        self.zero = self.ctx.from_dict({})
        self.memo: dict = {}  # flint's exponent tuples -> Python ints, shared by every conversion of the series

    def load(self, f):
        return self.ctx.from_dict(dict(f))

    def unload(self, f):
        if not f:
            return self.backend.zero
        return self.backend.ring.dtype(zip(exponents(f, self.memo), f.coeffs()))

    def field_of(self, X):
        """A backend field as the tuple of its value-ring components in flint (``None`` for a zero one)."""
        return tuple(self.load(c) if c else None for c in self.backend.values(X))

    def field(self, comps):
        return tuple(c if c else None for c in comps)

    def values(self, X):
        return [self.zero if c is None else c for c in X]

    @staticmethod
    def is_zero(X) -> bool:
        return all(c is None for c in X)

    @staticmethod
    def is_zero_function(f) -> bool:
        return not f

    def apply(self, X, f):
        """``X f = sum_i X^i D_i f`` in canonical Laurent form (as ``PolynomialBackend.apply``)."""
        total = flint_lie_derivative(X, f) if f else None
        if total is None:
            return self.zero
        if self.backend.holds_laurent_pairs(total):
            return self.load(self.backend.reduce(self.unload(total)))
        return total
