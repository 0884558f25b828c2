"""Exact shadow Hamiltonians ``H_S^e = F(omega h)^alpha H_c``, ``G_S^e = F(omega h)^(1-alpha) G_c``.

For the oscillators the composed map is linear in ``(x1, x2)`` (position or
velocity Verlet, Eqs. equiv1, equiv2), a rotation by ``theta = 2 asin(omega h/2)``
in scaled variables, so its effective field is the field of the conserved
quantities stretched by ``F(omega h)`` (Eqs. Xeff1, Xeff2):

    X_eff = F(omega h) X_{H_c}            (N = 2),    H_S^e = F(omega h) H_c,
    X_eff = F(omega h) X_{H_c, G_c}       (N = 3).

The Nambu bracket is linear in each slot, so every split of the factor,
``X_{F^alpha H_c, F^(1-alpha) G_c} = F X_{H_c,G_c}``, gives shadow Hamiltonians:
the alpha-family of Eqs. (ESH12321), (ESG12321) and Table (table).

Which systems qualify.  The form is *checked*, never assumed: the system must
have a parameter ``omega`` (or a harmonic core whose frequency plays its part), polynomial conserved quantities
(:func:`~nambu_bch.exact.conserved_quantities`), and the BCH effective field
(:func:`~nambu_bch.bch.effective_field`) must equal ``F(omega h) X_{H_c,G_c}``
through ``h^CHECK_ORDER``; otherwise :class:`~nambu_bch.errors.NoExactResultError`
is raised.  (Exactness to all orders for ``ho``/``ho3``: the time-``h`` flow of
``F X_{H_c,G_c}`` reproduces ``Phi_h`` exactly, see
:mod:`nambu_bch.exact.solutions` and ``tests/test_exact_solutions.py``.)

References
----------
Horikoshi, Eqs. (Xeff1), (SHPV2), (Xeff2), (ESH12321), (ESG12321), Table (table).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import sympy

from ..algebra import liouville_field
from ..algebra.zero import is_zero
from ..bch import effective_field
from ..errors import NoExactResultError
from .factor import F, F_series
from .invariants import ConservedQuantities, conserved_quantities
from .linear_core import linear_core
from ..printing import Printable, aligned, series_text, series_tokens
from ..values import ValueEquality
from ..symbols import ALPHA, STEP

OMEGA = sympy.Symbol("omega")
#: Order in h through which X_eff = F(omega h) X_{H_c,G_c} is verified before an ExactShadow is returned.
CHECK_ORDER = 8


def truncate_h(expr, order: int, h=STEP):
    """``expr`` (a polynomial in ``h``) without the powers of ``h`` above ``order``."""
    expr = sympy.expand(expr)
    return sympy.Add(*[t for t in sympy.Add.make_args(expr) if sympy.degree(t, h) <= order])


def factor_power_series(exponent, order: int, x=None):
    """``F(x)^exponent`` expanded through ``h^order``, ``x = omega h`` by default (binomial series of ``(1 + u)^a``).

    Examples
    --------
    >>> factor_power_series(ALPHA, 2)
    alpha*h**2*omega**2/6 + 1
    """
    x = OMEGA * STEP if x is None else x
    u = F_series(x, order) - 1
    total, term = sympy.Integer(1), sympy.Integer(1)
    for k in range(1, order // 2 + 1):
        term = truncate_h(term * u * (exponent - k + 1) / k, order)
        total += term
    return sympy.expand(total)


@dataclass(frozen=True, eq=False)
class ExactShadow(Printable, ValueEquality):
    """The alpha-family of exact shadow Hamiltonians of a linear oscillator.

    Attributes
    ----------
    H_S, G_S : sympy expressions containing ``F(omega h)`` exactly and ``alpha``
        (``G_S`` is ``None`` and ``H_S = F H_c`` for N = 2)
    factor : sympy expression, ``F(omega h)`` in closed form
    frequency : sympy expression, the ``omega`` of ``F(omega h)`` (the frequency of the
        harmonic core of ``X_{H,G}``; the parameter ``omega`` for ``ho``, ``ho3``)
    alpha : Symbol("alpha")
    conserved : ConservedQuantities (``H_c``, ``G_c``)
    verified_order : int, ``X_eff = F X_{H_c,G_c}`` was checked through this power of ``h``
    """

    H_S: object
    G_S: object
    factor: object
    conserved: ConservedQuantities = field(repr=False)
    verified_order: int = CHECK_ORDER
    frequency: object = OMEGA
    alpha: sympy.Symbol = ALPHA

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the conserved quantities, the frequency and the verified order
        determine the closed forms ``F^alpha H_c``, ``F^(1-alpha) G_c``."""
        return self.conserved, self.frequency, self.verified_order, self.G_S is None, self.alpha

    @property
    def H_c(self):
        return self.conserved.H_c

    @property
    def G_c(self):
        return self.conserved.G_c

    def series(self, order: int) -> tuple:
        """``(H_S, G_S)`` expanded through ``h^order`` (``G_S`` is ``None`` for N = 2).

        Eqs. (ESH12321), (ESG12321) are ``series(2)`` for ``ho3`` and ``12321``.
        """
        x = self.frequency * STEP
        if self.G_S is None:
            return (truncate_h(factor_power_series(1, order, x) * self.H_c, order), None)
        H = truncate_h(factor_power_series(ALPHA, order, x) * self.H_c, order)
        G = truncate_h(factor_power_series(1 - ALPHA, order, x) * self.G_c, order)
        return (sympy.collect(H, STEP), sympy.collect(G, STEP))

    def remainder_power(self, order: int) -> int:
        """The power ``p`` of the remainder ``O(h^p)`` after ``series(order)``: ``order + 2`` when the
        ``h^(order+1)`` coefficients vanish (checked exactly; an even series such as ho3's), else ``order + 1``."""
        nxt = self.series(order + 1)
        zero = all(S is None or sympy.expand(S).coeff(STEP, order + 1) == 0 for S in nxt)
        return order + 2 if zero else order + 1

    def _rows(self):
        """``[(latex name, text name, exact, invariant, Hamiltonian, exponent)]``."""
        hams = self.conserved.system.hamiltonians
        if self.G_S is None:
            return [("H", "H", self.H_S, self.H_c, hams[0], None)]
        return [("H", "H", self.H_S, self.H_c, hams[0], r"\alpha"), ("G", "G", self.G_S, self.G_c, hams[1], r"1-\alpha")]

    def _factor_latex(self, exponent):
        arg = r"\omega h" if self.frequency == OMEGA else rf"\left({sympy.latex(self.frequency * STEP)}\right)"
        return f"F({arg})" + ("" if exponent is None else f"^{{{exponent}}}")

    def to_latex(self, order=None) -> str:
        r"""``H_S^e = F(\omega h)^\alpha H_c``, ``G_S^e = F(\omega h)^{1-\alpha} G_c`` (Eq. Xeff2), ``H_c``, ``G_c`` as
        ``H + h^2(...)`` (Table (table)) and ``F(x)``; with ``order`` also the expansions through ``h^order``
        (Eqs. ESH12321, ESG12321), their remainder ``O(h^p)`` checked (:meth:`remainder_power`)."""
        coords = self.conserved.system.coordinates
        rows = [(rf"{lx}_{{S}}^{{e}}", "=", [self._factor_latex(e) + rf"\, {lx}_{{c}}"]) for lx, _, _, _, _, e in self._rows()]
        rows += [(rf"{lx}_{{c}}", "=", series_tokens(lx, Ic, H, coords)) for lx, _, _, Ic, H, _ in self._rows()]
        rows.append(("F(x)", "=", [r"\frac{2\arcsin(x/2)}{x\sqrt{1 - x^2/4}}"]))
        if order is not None:
            power = self.remainder_power(order)
            rows += [(rf"{lx}_{{S}}^{{e}}", "=", series_tokens(lx, S, H, coords, power))
                     for (lx, _, _, _, H, _), S in zip(self._rows(), self.series(order))]
        rows += [(lx, "=", series_tokens("0", H, 0, coords)) for lx, _, _, _, H, _ in self._rows()]
        for row in rows[:-1]:
            row[2][-1] += ","
        return aligned(rows)

    def to_text(self, order=None) -> str:
        """Plain-text twin of :meth:`to_latex`."""
        coords = self.conserved.system.coordinates
        arg = "omega*h" if self.frequency == OMEGA else f"{self.frequency * STEP}"
        lines = [f"{tx}_S^e = F({arg})" + ("" if e is None else f"**({e.replace(chr(92), '')})") + f" * {tx}_c"
                 for _, tx, _, _, _, e in self._rows()]
        lines += [f"{tx}_c = " + series_text(tx, Ic, H, coords) for _, tx, _, Ic, H, _ in self._rows()]
        lines.append("F(x) = 2*asin(x/2)/(x*sqrt(1 - x**2/4))")
        if order is not None:
            power = self.remainder_power(order)
            lines += [f"{tx}_S^e = " + series_text(tx, S, H, coords, power)
                      for (_, tx, _, _, H, _), S in zip(self._rows(), self.series(order))]
        lines.append(", ".join(f"{tx} = {H}" for _, tx, _, _, H, _ in self._rows()))
        return "\n".join(lines)

    def to_dict(self, order=None) -> dict:
        """JSON-ready dict; with ``order`` also the truncated series (``H_S_series``, ``G_S_series``) and ``series``
        ``{"H_S": {"0": ..., "2": ...}, ...}`` through ``h^order``.

        The system's part comes first (:func:`nambu_bch.render.result_head`); ``nambu-bch exact --format json``
        prints exactly this dict.
        """
        from ..render import expression, result_head

        cq = self.conserved
        out = result_head(cq.system, cq.word)
        out.update({"H_S": str(self.H_S), "G_S": None if self.G_S is None else str(self.G_S),
                    "H_c": str(self.H_c), "G_c": None if self.G_c is None else str(self.G_c),
                    "free_parameters": [] if self.G_S is None else ["alpha"]})
        if order is not None:
            series = self.series(order)
            out.update(order=order, H_S_series=expression(series[0]), G_S_series=expression(series[1]))
            names = [f"{tx}_S" for _, tx, *_ in self._rows()]
            out["series"] = {name: {str(k): str(S.coeff(STEP, k)) for k in range(order + 1) if S.coeff(STEP, k) != 0}
                             for name, S in zip(names, (sympy.expand(S) for S in series if S is not None))}
            out["remainder_power"] = self.remainder_power(order)
        return out


def exact_shadow_hamiltonians(system, word) -> ExactShadow:
    """The exact shadow Hamiltonians ``F^alpha H_c``, ``F^(1-alpha) G_c`` of ``word`` on ``system``.

    Parameters
    ----------
    system : System with a parameter ``omega`` (``ho``, ``ho3`` or a user-defined oscillator like them)
    word : str or Composition

    Returns
    -------
    ExactShadow

    Raises
    ------
    NoExactResultError if the system has no ``omega``, no polynomial conserved
    quantities, or its effective field is not ``F(omega h) X_{H_c,G_c}``
    (e.g. ``rigid-body``, ``lotka-volterra``, ``ho3-composite``).

    References
    ----------
    Horikoshi, Eqs. (Xeff1), (SHPV2), (Xeff2), (ESH12321), (ESG12321), Table (table).

    Examples
    --------
    >>> from nambu_bch import model
    >>> exact_shadow_hamiltonians(model("ho3"), "12321").series(2)[0]     # Eq. (ESH12321)
    h**2*(alpha*m*omega**4*x3/12 + alpha*omega**2*x2**2/(12*m)) + m*omega**2*x3/2 + x2**2/(2*m)
    """
    from ..systems.spec import as_system

    system = as_system(system)
    frequency(system)  # cheap structural check first: no omega and no harmonic core -> no factor form
    cq = conserved_quantities(system, word)
    return _exact_shadow(system, cq.word, cq)


@lru_cache(maxsize=64)
def _exact_shadow(system, word, cq):
    what = f"{word!r} on {system.name}"
    omega = frequency(system)
    if system.N > 3 or any(Ic is None for Ic in cq.hamiltonians_c):
        raise NoExactResultError(
            f"no exact factor form F(omega h) for {what}: no polynomial conserved quantity tends to each Hamiltonian"
        )
    X = effective_field(system.splitting, word, CHECK_ORDER)
    Xc = [_taylor_in_h(c, CHECK_ORDER) for c in liouville_field(system.algebra, *cq.hamiltonians_c).to_sympy()]
    Fs = F_series(omega * STEP, CHECK_ORDER)
    for j, Z in enumerate(X.coefficients):
        for zc, xc in zip(Z.to_sympy(), Xc):
            if not is_zero(sympy.expand(Fs * xc).coeff(STEP, j) - zc):
                raise NoExactResultError(
                    f"no exact factor form for {what}: X_eff differs from F(omega h) X_(H_c,G_c) at order h^{j} "
                    "(exact shadow Hamiltonians exist here only for linear oscillators such as ho and ho3)"
                )
    Fx = F(omega * STEP)
    if system.N == 2:
        return ExactShadow(Fx * cq.H_c, None, Fx, cq, frequency=omega)
    return ExactShadow(Fx**ALPHA * cq.H_c, Fx ** (1 - ALPHA) * cq.G_c, Fx, cq, frequency=omega)


def _taylor_in_h(expr, order):
    """``expr`` through ``h^order``: itself if polynomial in ``h``, else its Taylor polynomial at ``h = 0``
    (conserved quantities of triple-jump compositions are rational in ``h``)."""
    expr = sympy.expand(expr)
    if all(not sympy.fraction(sympy.together(t))[1].has(STEP) for t in sympy.Add.make_args(expr)):
        return truncate_h(expr, order)
    return sympy.expand(sympy.series(expr, STEP, 0, order + 1).removeO())


def frequency(system):
    """The ``omega`` of ``F(omega h)``: the parameter ``omega`` if the system has one, else the
    frequency of the harmonic core of ``X_{H,G}`` (:func:`~nambu_bch.exact.linear_core.linear_core`)."""
    if OMEGA in system.parameters:
        return OMEGA
    try:
        return linear_core(system.coordinates, system.vector_field.to_sympy(), system.name).Omega
    except NoExactResultError:
        raise NoExactResultError(
            f"no exact factor form F(omega h) for {system.name}: it has no parameter 'omega' and its equations "
            "have no harmonic core (exact shadow Hamiltonians exist here only for linear oscillators such as ho and ho3)"
        ) from None
