"""The modified Nambu equations and their exact solutions x^o, x^c, x^s.

Three vector fields are compared with the integrator (Sect. 5.5):

* ``kind="o"`` -- the original Hamiltonians, ``dx/dt = X_{H,G}`` (Eq. NambuOHeqs);
* ``kind="c"`` -- the conserved quantities, ``dx/dt = X_{H_c,G_c}`` (Eq. NambuCQeqs;
  for ``32123`` on ``ho3``: ``x1' = x2/m``, ``x2' = -m omega^2 a^2 x1``,
  ``x3' = 2 b^2 x1 x2/m`` with ``a = sqrt(1 - omega^2 h^2/4)``, ``b = sqrt(1 - omega^2 h^2/2)``);
* ``kind="s"`` -- the exact shadow Hamiltonians, ``dx/dt = F(omega h) X_{H_c,G_c}`` (Eq. NambuSHeqs).

Closed-form solution.  Each field has a *linear core*: two coordinates
``y = (x1, x2)`` with ``y' = A y``, ``tr A = 0``, ``det A = Omega^2 > 0``
(``Omega = omega`` for "o", ``tilde omega = a omega`` for "c"), so

    y(t) = cos(Omega t) y0 + sin(Omega t)/Omega A y0,

and the remaining coordinates are *driven*, ``x_k' = q_k(y)`` with ``q_k`` a
polynomial of degree <= 2, integrated in closed form (the ``cos 2 Omega t``,
``sin 2 Omega t`` terms of Eqs. OHsol, CQsol).  The shadow solution is the
conserved-quantity solution at the stretched time ``tilde t = F(omega h) t``
(Eq. SHsol).  At ``t = h`` the shadow solution *is* the map:
``tilde omega tilde t = 2 asin(omega h / 2)`` (tested exactly).

Parameters are taken positive (``m, omega > 0``) when ``Omega`` is extracted
from ``Omega^2``.

References
----------
Horikoshi, Eqs. (NambuOHeqs), (NambuCQeqs), (NambuSHeqs), (OHsol), (CQsol), (SHsol), Figs. 3-4.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import sympy

from ..algebra import liouville_field
from ..errors import NambuBCHError, NoExactResultError, UnstableStepError
from ..integrators import composition_for
from ..integrators.step import parameter_values
from ..parsing import as_expression
from .exact_shadow import OMEGA, exact_shadow_hamiltonians, frequency
from .invariants import conserved_quantities
from .linear_core import linear_core
from ..symbols import STEP
from ..values import ValueEquality

TIME = sympy.Symbol("t")
KINDS = ("o", "c", "s")


def _check_kind(kind):
    if not isinstance(kind, str) or kind not in KINDS:
        raise NambuBCHError(f"kind must be one of 'o' (original), 'c' (conserved), 's' (exact shadow), got {kind!r}")


def _word(system, word) -> str:
    from ..systems.spec import as_system

    system = as_system(system)
    comp = composition_for(word, system)
    return word if isinstance(word, str) else (comp.name or "".join(map(str, comp.pieces)))


def _conserved_field(system, word) -> tuple:
    cq = conserved_quantities(system, word)
    if any(Ic is None for Ic in cq.hamiltonians_c):
        raise NoExactResultError(
            f"{word!r} on {system.name} has no polynomial conserved quantity for each Hamiltonian, "
            "so the equations with the conserved quantities (Eq. NambuCQeqs) are not defined"
        )
    return liouville_field(system.algebra, *cq.hamiltonians_c).to_sympy()


def modified_equations(system, word, kind) -> tuple:
    """Right-hand sides ``dx_i/dt`` of the Nambu equations with H,G / H_c,G_c / H_S^e,G_S^e.

    Parameters
    ----------
    system : System
    word : str or Composition
    kind : ``"o"`` (Eq. NambuOHeqs), ``"c"`` (Eq. NambuCQeqs) or ``"s"`` (Eq. NambuSHeqs)

    Returns
    -------
    tuple of sympy expressions, one per coordinate (``"s"`` contains ``F(omega h)`` exactly).

    Examples
    --------
    >>> from nambu_bch import model
    >>> modified_equations(model("ho3"), "32123", "c")          # Eq. (NambuCQeqs)
    (x2/m, h**2*m*omega**4*x1/4 - m*omega**2*x1, -h**2*omega**2*x1*x2/m + 2*x1*x2/m)
    """
    from ..systems.spec import as_system

    _check_kind(kind)
    system = as_system(system)
    word = _word(system, word)
    if kind == "o":
        return tuple(system.vector_field.to_sympy())
    if kind == "c":
        return tuple(_conserved_field(system, word))
    shadow = exact_shadow_hamiltonians(system, word)
    return tuple(shadow.factor * c for c in _conserved_field(system, word))


def _tidy(expr, atoms, W, det):
    """Collect over the trig atoms and ``t``; each coefficient as ``a + b W`` (``W**2 = det``), factored."""
    parts = sympy.collect(sympy.expand(expr), atoms, evaluate=False)

    def reduce(v):
        num, den = sympy.fraction(sympy.cancel(sympy.together(v)))
        rem = lambda p: sympy.Poly(p, W).rem(sympy.Poly(W**2 - det, W)).all_coeffs()[::-1] + [0]  # noqa: E731
        p0, p1 = rem(num)[:2]
        q0, q1 = rem(den)[:2]
        # (p0 + p1 W) / (q0 + q1 W) with one of q0, q1 zero (den is a monomial in W times a rational function)
        if q1 == 0:
            a, b = p0 / q0, p1 / q0
        else:
            a, b = p1 / q1, p0 / (q1 * det)
        return sympy.factor(a) + sympy.factor(b) * W

    return sympy.Add(*[reduce(v) * k for k, v in parts.items()])


def _closed_form(system, rhs, t):
    """Closed-form solution of ``x' = rhs(x)`` with a 2-d linear core and driven coordinates."""
    coords = system.coordinates
    x0 = tuple(sympy.Symbol(f"{c.name}_0") for c in coords)
    rhs = [sympy.expand(r) for r in rhs]
    lc = linear_core(coords, rhs, system.name)
    (i1, i2), driven, A, det, Omega = lc.core, lc.driven, lc.A, lc.det, lc.Omega
    y = (coords[i1], coords[i2])
    # work with a placeholder W for Omega so that coefficients factor cleanly, substitute at the end
    W = sympy.Dummy("Omega", positive=True)
    C = sympy.Matrix([x0[i1], x0[i2]])
    S = A * C / W
    c1, s1 = sympy.cos(W * t), sympy.sin(W * t)
    c2, s2 = sympy.cos(2 * W * t), sympy.sin(2 * W * t)
    out = [None] * len(coords)
    yt = C * c1 + S * s1
    out[i1], out[i2] = yt[0], yt[1]
    for k in driven:
        q = sympy.Poly(rhs[k], *y)
        Q = sympy.Matrix(2, 2, lambda a, b: q.coeff_monomial(y[a] ** 2) if a == b else q.coeff_monomial(y[0] * y[1]) / 2)
        lvec = sympy.Matrix([[q.coeff_monomial(y[0]), q.coeff_monomial(y[1])]])
        c0 = q.coeff_monomial(1)
        CQC, SQS, CQS = (C.T * Q * C)[0], (S.T * Q * S)[0], (C.T * Q * S)[0]
        integral = ((CQC + SQS) / 2 * t + (CQC - SQS) / (4 * W) * s2 + CQS / (2 * W) * (1 - c2)
                    + (lvec * C)[0] * s1 / W + (lvec * S)[0] * (1 - c1) / W + c0 * t)
        out[k] = x0[k] + integral
    return tuple(_tidy(e, [c1, s1, c2, s2, t], W, det).subs(W, Omega) for e in out), x0, Omega


@dataclass(frozen=True, eq=False)
class ModifiedSolution(ValueEquality):
    """The exact solution of the modified Nambu equations of one ``kind``.

    Attributes
    ----------
    expressions : tuple of sympy expressions in ``t``, the initial values ``x1_0, x2_0, ...``,
        the parameters and ``h``
    initial_symbols : tuple of Symbols ``x1_0, x2_0, ...``
    frequency : sympy expression, ``Omega`` of the linear core in ``t`` (``omega``,
        ``tilde omega = a omega``, or ``F(omega h) tilde omega``)
    equations : the right-hand sides it solves (:func:`modified_equations`)
    kind, word, system
    """

    expressions: tuple
    initial_symbols: tuple
    frequency: object
    equations: tuple
    kind: str
    word: str
    system: object = field(repr=False)
    time: sympy.Symbol = TIME
    step_frequency: object = OMEGA

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the closed-form solution, its frequency, equations, kind, word, system."""
        return (self.expressions, self.initial_symbols, self.frequency, self.equations, self.kind, self.word, self.system,
                self.time, self.step_frequency)

    def numeric(self, params=None, h=0.1):
        """``f(t, x0) -> array (N, len(t))``, the solution lambdified once for float ``t`` arrays.

        Raises UnstableStepError if ``|omega h| >= 2`` (kinds "c", "s": ``a`` would be imaginary).
        """
        from ..checks import finite_float
        from ..numeric.guards import finite_array

        values = parameter_values(self.system, params)
        h = finite_float(h, "h")
        if self.kind != "o":
            x = complex(sympy.sympify(self.step_frequency, strict=True).subs(values)) * h
            if abs(x.imag) > 0 or abs(x.real) >= 2:
                raise UnstableStepError(f"the modified solution {self.kind!r} needs |omega h| < 2, got omega h = {x.real!r}")
        args = (self.time, *self.initial_symbols, *values, STEP)
        fn = _lambdify(args, self.expressions)
        pvals = tuple(values.values())
        n = len(self.initial_symbols)

        def solution(t, x0):
            t, x0 = finite_array(t, "t"), finite_array(x0, "x0").reshape(-1)
            if x0.shape != (n,):
                raise NambuBCHError(f"initial state must have {n} components, got shape {x0.shape}")
            res = fn(t, *x0, *pvals, h)
            return np.array([np.broadcast_to(np.asarray(r, dtype=float), t.shape) for r in res])

        return solution

    def at(self, x0=None, t=None):
        """The expressions with the initial values (and optionally ``t``) substituted."""
        subs = {} if x0 is None else dict(zip(self.initial_symbols, (as_expression(v, (), "x0") for v in x0)))
        if t is not None:
            subs[self.time] = as_expression(t, (), "t")
        return tuple(sympy.sympify(e, strict=True).subs(subs) for e in self.expressions)


@lru_cache(maxsize=64)
def _lambdify(args, expressions):
    """One numpy function per (arguments, expressions), reused by every ``numeric()`` call."""
    return sympy.lambdify(args, list(expressions), modules="numpy", cse=True)


def modified_solution(system, word, kind) -> ModifiedSolution:
    """The exact solution ``x^o``, ``x^c`` or ``x^s`` of the modified Nambu equations, for any initial state.

    Parameters
    ----------
    system : System (``ho``, ``ho3`` or another linear oscillator)
    word : str or Composition
    kind : ``"o"`` (Eq. OHsol), ``"c"`` (Eq. CQsol) or ``"s"`` (Eq. SHsol)

    Returns
    -------
    ModifiedSolution

    References
    ----------
    Horikoshi, Eqs. (OHsol), (CQsol), (SHsol).

    Examples
    --------
    >>> from nambu_bch import model
    >>> modified_solution(model("ho"), "121", "o").expressions[0]
    x1_0*cos(omega*t) + x2_0*sin(omega*t)/(m*omega)
    """
    from ..systems.spec import as_system

    _check_kind(kind)
    system = as_system(system)
    return _solution(system, _word(system, word), kind)


@lru_cache(maxsize=64)
def _solution(system, word, kind):
    eqs = modified_equations(system, word, kind)
    if kind == "s":
        # Eq. (SHsol): x^s(t) = x^c(F t), so the closed form of kind "c" (cached) is stretched, not solved again
        conserved = _solution(system, word, "c")
        shadow = exact_shadow_hamiltonians(system, word)
        exprs = tuple(e.subs(TIME, shadow.factor * TIME) for e in conserved.expressions)
        return ModifiedSolution(exprs, conserved.initial_symbols, shadow.factor * conserved.frequency, eqs, kind, word,
                                system, step_frequency=shadow.frequency)
    exprs, x0, Omega = _closed_form(system, eqs, TIME)
    omega = frequency(system) if kind == "c" else Omega
    return ModifiedSolution(exprs, x0, Omega, eqs, kind, word, system, step_frequency=omega)
