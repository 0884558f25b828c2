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
    """Closed-form solution of ``x' = rhs(x)`` with a 2-d linear core and driven coordinates.

    The coefficients are computed as exact rational functions (:func:`_exact_parts`) and turned into sympy
    expressions once, each factored; the result is the expression that expanding and collecting the sympy
    sum gives (:func:`_closed_form_sympy`, still the route for coefficients outside ``Q(symbols)``), without
    the cost of ``expand``/``collect``/``cancel`` on the whole sum.
    """
    coords = system.coordinates
    x0 = tuple(sympy.Symbol(f"{c.name}_0") for c in coords)
    rhs = [sympy.expand(r) for r in rhs]
    lc = linear_core(coords, rhs, system.name)
    (i1, i2), driven, A, det, Omega = lc.core, lc.driven, lc.A, lc.det, lc.Omega
    y = (coords[i1], coords[i2])
    # work with a placeholder W for Omega so that coefficients factor cleanly, substitute at the end
    W = sympy.Dummy("Omega", positive=True)
    c1, s1 = sympy.cos(W * t), sympy.sin(W * t)
    c2, s2 = sympy.cos(2 * W * t), sympy.sin(2 * W * t)
    polys = [sympy.Poly(rhs[k], *y) for k in driven]
    data = [A[i, j] for i in range(2) for j in range(2)] + [det]
    data += [q.coeff_monomial(m) for q in polys for m in (y[0] ** 2, y[1] ** 2, y[0] * y[1], y[0], y[1], 1)]
    data += list(x0)
    parts = _exact_parts(data, len(polys), (i1, i2), driven, (c1, s1, c2, s2, t))
    if parts is None:  # coefficients outside Q(symbols) (e.g. 2**(1/3)): sympy's route below
        return _closed_form_sympy(coords, rhs, x0, lc, W, (c1, s1, c2, s2), y, t)
    out = [sympy.Add(*[(sympy.factor(a) + sympy.factor(b) * W) * key for key, (a, b) in coeffs.items()])
           for coeffs in parts]
    return tuple(e.subs(W, Omega) for e in out), x0, Omega


def _exact_parts(data, ndriven, core, driven, keys):
    """The coefficients of the closed form, exactly in ``Q(parameters, h, x_0)``, as ``{key: (a, b)}`` per coordinate.

    With ``W = Omega`` (``W**2 = det``), ``S = A C / W = W (A C)/det`` and ``1/W = W/det``, so every
    coefficient of ``1, t, cos(W t), sin(W t), cos(2 W t), sin(2 W t)`` is ``a + b W`` with ``a, b`` in
    the field, read off without expanding or collecting (Eqs. OHsol, CQsol):

    * core ``y(t) = C cos(W t) + (A C)/det * W sin(W t)``;
    * driven ``x_k' = y^T Q y + l y + c0``: with ``cqc = C^T Q C``, ``sqs = (AC)^T Q (AC)/det``,
      ``cqs = C^T Q (A C)/det``, the integral is
      ``((cqc + sqs)/2 + c0) t + (cqc - sqs)/(4 det) W sin(2Wt) - cqs/2 cos(2Wt) + cqs/2
      + (l C)/det W sin(Wt) - (l A C)/det cos(Wt) + (l A C)/det``.

    Returns ``None`` when the data are not rational functions over ``QQ`` (sympy's route is taken then).
    A key whose coefficient is zero is left out, as ``sympy.collect`` leaves it out of an expanded sum.
    """
    from sympy.polys.polyerrors import PolynomialError

    try:
        K, vals = sympy.sfield(data, domain=sympy.QQ)
    except (PolynomialError, sympy.CoercionFailed, ValueError, TypeError):
        return None
    if not all(isinstance(g, sympy.Symbol) for g in K.symbols):  # a radical taken as a generator: not a field of Q
        return None
    a11, a12, a21, a22, det = vals[:5]
    qs = vals[5:5 + 6 * ndriven]
    x0 = vals[5 + 6 * ndriven:]
    if det == 0:
        return None
    c1, s1, c2, s2, t = keys
    C = (x0[core[0]], x0[core[1]])
    AC = (a11 * C[0] + a12 * C[1], a21 * C[0] + a22 * C[1])
    zero = K.zero
    out = [None] * len(x0)
    out[core[0]] = {c1: (C[0], zero), s1: (zero, AC[0] / det)}
    out[core[1]] = {c1: (C[1], zero), s1: (zero, AC[1] / det)}

    def form(u, v, q11, q22, q12):
        return q11 * u[0] * v[0] + q22 * u[1] * v[1] + q12 * (u[0] * v[1] + u[1] * v[0]) / 2

    for n, k in enumerate(driven):
        q11, q22, q12, l1, l2, c0 = qs[6 * n: 6 * n + 6]
        cqc, sqs, cqs = form(C, C, q11, q22, q12), form(AC, AC, q11, q22, q12) / det, form(C, AC, q11, q22, q12) / det
        lC, lAC = l1 * C[0] + l2 * C[1], (l1 * AC[0] + l2 * AC[1]) / det
        out[k] = {sympy.S.One: (x0[k] + cqs / 2 + lAC, zero), t: ((cqc + sqs) / 2 + c0, zero),
                  s2: (zero, (cqc - sqs) / (4 * det)), c2: (-cqs / 2, zero),
                  s1: (zero, lC / det), c1: (-lAC, zero)}
    return [{key: (a.as_expr(), b.as_expr()) for key, (a, b) in coeffs.items() if a != 0 or b != 0} for coeffs in out]


def _closed_form_sympy(coords, rhs, x0, lc, W, trig, y, t):
    """The closed form by sympy expansion and collection (coefficients outside ``Q(symbols)``)."""
    (i1, i2), driven, A, det, Omega = lc.core, lc.driven, lc.A, lc.det, lc.Omega
    c1, s1, c2, s2 = trig
    C = sympy.Matrix([x0[i1], x0[i2]])
    S = A * C / W
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
