"""Orbit averages along the periodic orbits of ``X_{H,G}``: the solvability test of the homological equation.

The problem.  Suppose ``H', G'`` (the Hamiltonians plus their corrections below
``h^j``) are conserved by the effective field ``X_eff`` of a splitting method up
to ``O(h^j)``, and write ``X_eff = X_{H',G'} + h^j R_j + O(h^{j+1})`` (``R_j``
is the right-hand side of the direct route's Eq. (*), ``Z_j`` minus the cross
terms).  A corrected ``H'' = H' + h^j a`` is conserved to ``O(h^{j+1})`` iff

    X_{H,G}(a) = - R_j . grad H       (the homological equation; same for G with b)   (HE)

because ``X_{H',G'}(H') = 0`` exactly.  Integrating (HE) along a periodic orbit
``gamma`` of ``X_{H,G}`` of period ``T`` kills the left side (``a`` is single-valued), so

    <R_j . grad H>_gamma := (1/T) int_0^T (R_j . grad H)(x(t)) dt = 0                   (AV)

is necessary; on a region foliated by periodic orbits with smooth period it is
also sufficient (``a(x) = -int_0^{t(x)} R_j.grad H`` from a transversal section,
which closes up by (AV)).  This is the homological equation of averaging
(Hairer, Lubich, Wanner, *Geometric Numerical Integration*, 2nd ed., Ch. XI,
Sect. XI.2 (the averaged / "linearised" equations of reversible perturbation
theory); Arnold, *Mathematical Methods of Classical Mechanics*, Sect. 52).
Every conserved quantity to ``O(h^j)`` is ``Phi(H', G'; h)``, so a conserved
pair at ``h^j`` needs ``Phi_H <g_H> + Phi_G <g_G> = 0`` for two independent
``Phi``: the vector of averages must vanish.  A non-zero average is a
certificate of non-existence (see :mod:`nambu_bch.shadow.existence`) and the
slow dynamics of ``H'`` is ``dH'/dt = h^j <R_j . grad H> + ...``: a secular
drift at that rate.

This module computes the averages **numerically**: the orbit of ``X_{H,G}``
through ``x0`` is integrated with an embedded Dormand--Prince 5(4) pair with
step-size control (Hairer, Norsett, Wanner, *Solving ODEs I*, Sect. II.5,
Table 5.2), the integrals ``int g_a dt`` are carried as extra components, and
the period is the first return to the section ``{X(x0).(x - x0) = 0}`` near
``x0``, located by regula falsi on single Runge--Kutta steps.  Each average is
computed at two tolerances; their difference is the error estimate (this is an
*estimate*, not an interval bound: the module says "numerical" wherever it is
used).  The fields are compiled once with ``sympy.lambdify``; no sympy runs
per step.

References
----------
Hairer, Lubich, Wanner, Geometric Numerical Integration (2006), Ch. XI;
Hairer, Norsett, Wanner, Solving Ordinary Differential Equations I, Sect. II.5 (Dormand--Prince 5(4)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import sympy

from ..checks import is_int
from ..parsing import as_expression
from ..errors import NambuBCHError

# Dormand--Prince 5(4) (HNW I, Table II.5.2), FSAL
_C = (0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0)
_A = (
    (),
    (1 / 5,),
    (3 / 40, 9 / 40),
    (44 / 45, -56 / 15, 32 / 9),
    (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
    (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656),
    (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84),
)
_B5 = np.array(_A[6] + (0.0,))
_E = _B5 - np.array((5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40))

MAX_STEPS = 200_000  # per orbit and tolerance: the up-front bound of the work


@dataclass
class OrbitFunctions:
    """``X_{H,G}``, the integrands ``g_a`` and the Hamiltonians, compiled once for numpy.

    ``rhs(x)`` returns ``(X(x), g(x))`` concatenated; ``hamiltonians(x)`` the values ``H_a(x)``
    (numpy arrays).  ``values(x)`` and ``levels(x)`` are the same functions on plain lists of floats, what the
    integrator below steps with.
    """

    n: int
    m: int
    rhs: object
    hamiltonians: object
    integrand_names: tuple
    values: object = None
    levels: object = None
    source: tuple = field(default=None, repr=False, compare=False)

    def __reduce__(self):
        """Pickle as the arguments of :func:`orbit_functions` (the compiled functions are local to this process)."""
        if self.source is None:
            raise TypeError("OrbitFunctions built without their source (orbit_functions' arguments) do not pickle")
        return orbit_functions, self.source


def orbit_functions(system, integrands, params: dict, names=None) -> OrbitFunctions:
    """Compile ``X_{H,G}`` of ``system`` and the integrands (sympy, in the coordinates) at parameter values.

    Parameters
    ----------
    system : System
    integrands : sequence of sympy expressions in the coordinates (and the system's parameters)
    params : dict ``Symbol -> number`` -- a value for every parameter of the system
    names : optional labels of the integrands

    Returns
    -------
    OrbitFunctions
    """
    coords = system.coordinates
    subs = {p: sympy.nsimplify(as_expression(params[p], (), f"params[{p}]")) for p in system.parameters}
    field_ = [sympy.expand(sympy.sympify(c, strict=True).subs(subs)) for c in system.equations_of_motion()]
    ints = [sympy.expand(as_expression(g, system.symbols(), "integrand").subs(subs)) for g in integrands]
    hams = [sympy.expand(H.subs(subs)) for H in system.hamiltonians]
    for e in field_ + ints + hams:
        stray = e.free_symbols - set(coords)
        if stray:
            raise NambuBCHError(f"orbit averages need numeric values for {sorted(map(str, stray))}; pass params=")
    f = sympy.lambdify([coords], field_ + ints, modules="math", cse=True)
    H = sympy.lambdify([coords], hams, modules="math", cse=True)
    n = len(coords)
    return OrbitFunctions(
        n, len(ints),
        lambda x: np.array(f(x[:n]), dtype=float),
        lambda x: np.array(H(x[:n]), dtype=float),
        tuple(names) if names else tuple(f"g{a}" for a in range(len(ints))),
        lambda x: [float(v) for v in f(x[:n])],
        lambda x: [float(v) for v in H(x[:n])],
        (system, tuple(integrands), dict(params), names),
    )


# The integrator steps with plain Python floats: the state has a handful of components, where numpy's per-call
# overhead was most of the time.  Every sum is formed in the order the numpy version formed it (the stage sums
# left to right from 0; numpy 2's reductions and BLAS dot products of fewer than 8 resp. 16 terms are sequential,
# longer ones fall back to numpy), so the orbits, periods and averages are bit for bit those of the numpy version
# (checked on every orbit of the test suite and the notebooks; tests/test_existence.py pins the step).
_AN = tuple((tuple(float(a) for a in row if a), tuple(i for i, a in enumerate(row) if a)) for row in _A)
_EN = (tuple(float(e) for e in _E if e), tuple(i for i, e in enumerate(_E) if e))


def _combine(y, dt, coefficients, columns):
    """``y + dt * (0 + c_1 k_1 + c_2 k_2 + ...)`` componentwise, the sum left to right (as ``sum`` on arrays did)."""
    c, k = coefficients, columns
    if len(c) == 1:
        return [yj + dt * (0 + c[0] * a) for yj, a in zip(y, *k)]
    if len(c) == 2:
        return [yj + dt * (0 + c[0] * a + c[1] * b) for yj, a, b in zip(y, *k)]
    if len(c) == 3:
        return [yj + dt * (0 + c[0] * a + c[1] * b + c[2] * d) for yj, a, b, d in zip(y, *k)]
    if len(c) == 4:
        return [yj + dt * (0 + c[0] * a + c[1] * b + c[2] * d + c[3] * e) for yj, a, b, d, e in zip(y, *k)]
    if len(c) == 5:
        return [yj + dt * (0 + c[0] * a + c[1] * b + c[2] * d + c[3] * e + c[4] * f) for yj, a, b, d, e, f in zip(y, *k)]
    return [dt * (0 + c[0] * a + c[1] * b + c[2] * d + c[3] * e + c[4] * f + c[5] * g)  # the error: no y, six terms
            for a, b, d, e, f, g in zip(*k)]


def _rk_step(F, y, k1, dt):
    """One Dormand--Prince 5(4) step of ``y' = F(y)`` from ``y`` (``k1 = F(y)``): ``(y_new, error, F(y_new))``.

    ``F`` maps a list of floats to a list of floats (:attr:`OrbitFunctions.values`); ``y`` and ``k1`` are sequences
    of floats; lists are returned.  The method is FSAL: the last stage is evaluated at ``y_new`` (its
    coefficients are the fifth-order weights ``_B5``).
    """
    ks = [k1]
    y_new = y
    for i in range(1, 7):
        cs, idx = _AN[i]
        y_new = _combine(y, dt, cs, [ks[j] for j in idx])
        ks.append(F(y_new))
    err = _combine(None, dt, _EN[0], [ks[j] for j in _EN[1]])
    return y_new, err, ks[6]


def _list_functions(F: OrbitFunctions):
    """``(values, levels)`` of ``F`` on lists of floats (from ``rhs``, ``hamiltonians`` if built without them)."""
    if F.values is not None and F.levels is not None:
        return F.values, F.levels
    return (lambda x: [float(v) for v in F.rhs(np.asarray(x, float))],
            lambda x: [float(v) for v in F.hamiltonians(np.asarray(x, float))])


def _dot(a, b):
    """``a . b`` as numpy's ``@`` forms it (sequential below 16 terms)."""
    if len(a) >= 16:
        return float(np.asarray(a, float) @ np.asarray(b, float))
    acc = 0.0
    for x, y in zip(a, b):
        acc += x * y
    return acc


def _norm(a) -> float:
    """``numpy.linalg.norm(a)`` of a vector: ``sqrt(a . a)``."""
    return math.sqrt(_dot(a, a))


def _rms(err, sc):
    """``sqrt(mean((err / sc)**2))`` as numpy forms it (the reduction is sequential below 8 terms)."""
    if len(err) >= 8:
        return float(np.sqrt(np.mean((np.asarray(err) / np.asarray(sc)) ** 2)))
    q = [(e / s) * (e / s) for e, s in zip(err, sc)]
    acc = q[0]
    for v in q[1:]:
        acc += v
    return math.sqrt(acc / len(q))


@dataclass
class OrbitAverage:
    """One periodic orbit of ``X_{H,G}`` and the averages of the integrands on it.

    Attributes
    ----------
    x0 : tuple -- the starting point
    closed : bool -- the orbit returned to its section within the step budget
    period : float
    averages : tuple -- ``<g_a>`` (the finer tolerance)
    errors : tuple -- ``|<g_a>(tol) - <g_a>(tol/100)|``, the error estimate
    scales : tuple -- ``max |g_a|`` on the orbit (what "small" is measured against)
    hamiltonians : tuple -- ``H_a(x0)``, the orbit's level
    drift_H : float -- ``max |H_a(x(t)) - H_a(x0)|`` along the orbit (integration accuracy)
    fix_crossings : dict ``coordinate index -> number of sign changes`` along the orbit
    steps : int
    reason : str -- why ``closed`` is false
    """

    x0: tuple
    closed: bool
    period: float = float("nan")
    averages: tuple = ()
    errors: tuple = ()
    scales: tuple = ()
    hamiltonians: tuple = ()
    drift_H: float = float("nan")
    fix_crossings: dict = None
    steps: int = 0
    reason: str = ""

    def significant(self, factor: float = 100.0) -> tuple:
        """Per integrand: ``|<g>| > factor * error`` and ``|<g>| > 1e-8 * scale`` (numerically non-zero)."""
        return tuple(abs(a) > factor * e and abs(a) > 1e-8 * s for a, e, s in zip(self.averages, self.errors, self.scales))

    def negligible(self, rel: float = 1e-7) -> tuple:
        """Per integrand: ``|<g>| <= rel * scale + 10 * error`` (numerically zero)."""
        return tuple(abs(a) <= rel * s + 10 * e for a, e, s in zip(self.averages, self.errors, self.scales))

    def to_dict(self) -> dict:
        out = {"x0": [float(v) for v in self.x0], "closed": self.closed}
        if self.closed:
            out.update(period=self.period, averages=list(self.averages), errors=list(self.errors),
                       scales=list(self.scales), levels=list(self.hamiltonians), conservation_error=self.drift_H)
        else:
            out["reason"] = self.reason
        return out


def _crossing(rhs, y, k, dt, f_lo, f_hi, value, f_tol, t_tol):
    """``(tau, y(tau))`` with ``value(y(tau)) = 0`` for ``tau`` in ``[0, dt]``, where ``value`` goes from ``f_lo < 0``
    to ``f_hi >= 0`` over the accepted step: regula falsi, Illinois variant, on the step size from ``y``."""
    lo, hi, side = 0.0, dt, 0
    tau, y_tau = dt, None
    for _ in range(60):
        tau = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        y_tau, _, _ = _rk_step(rhs, y, k, tau)
        f_tau = value(y_tau)
        if abs(f_tau) <= f_tol or hi - lo <= t_tol:
            break
        if f_tau < 0:
            lo, f_lo = tau, f_tau
            if side == -1:
                f_hi /= 2
            side = -1
        else:
            hi, f_hi = tau, f_tau
            if side == 1:
                f_lo /= 2
            side = 1
    return tau, y_tau


def _one_orbit(F: OrbitFunctions, x0, rtol, max_steps, radius):
    n, m = F.n, F.m
    values, levels = _list_functions(F)
    x0 = [float(v) for v in x0]
    y = x0 + [0.0] * m
    k = values(y)
    speed = _norm(k[:n])
    if not math.isfinite(speed) or speed < 1e-12:
        return None, "X_{H,G} vanishes (an equilibrium) or is not finite at x0"
    v = [c / speed for c in k[:n]]
    H0 = levels(y)
    atol = rtol * max(1.0, max(abs(c) for c in x0))
    t, dt = 0.0, 1e-2 / speed
    s_prev = 0.0
    diam = 0.0
    scale = [0.0] * m
    dH = 0.0
    signs = [_sign(c) for c in x0]
    crossings = [0] * n
    accepted = 0
    for _ in range(max_steps):
        y_new, err, k_new = _rk_step(values, y, k, dt)
        e = _rms(err, [atol + rtol * max(abs(a), abs(b)) for a, b in zip(y, y_new)])
        if not math.isfinite(e):
            return None, "the orbit is not finite (escapes)"
        if e > 1.0:
            dt *= max(0.2, 0.9 * e ** -0.2)
            continue
        accepted += 1
        x_new = y_new[:n]
        if max(abs(c) for c in x_new) > radius:
            return None, f"the orbit leaves the ball of radius {radius:g} (not periodic)"
        dx = [a - b for a, b in zip(x_new, x0)]
        s_new = _dot(v, dx)
        d_new = _norm(dx)
        diam = max(diam, d_new)
        scale = [max(a, abs(b)) for a, b in zip(scale, k_new[n:])]
        dH = max(dH, max(abs(a - b) for a, b in zip(levels(y_new), H0)))
        for i, c in enumerate(x_new):
            sg = _sign(c)
            if sg != 0:
                if sg != signs[i]:
                    crossings[i] += 1
                signs[i] = sg
        if accepted > 3 and s_prev < 0.0 <= s_new and d_new < 0.5 * diam:
            tau, y_tau = _crossing(values, y, k, dt, s_prev, s_new,
                                   lambda z: _dot(v, [a - b for a, b in zip(z[:n], x0)]),
                                   1e-15 * max(1.0, diam), 1e-16 * max(1.0, t))
            dz = [a - b for a, b in zip(y_tau[:n], x0)]
            if _norm(dz) < 1e-4 * diam:
                T = t + tau
                return dict(period=T, averages=[g / T for g in y_tau[n:]], scales=scale, H0=H0, dH=dH,
                            crossings=crossings, steps=accepted), ""
        t += dt
        y, k, s_prev = y_new, k_new, s_new
        dt *= min(5.0, max(0.2, 0.9 * max(e, 1e-10) ** -0.2))
    return None, f"no return to the section within {max_steps} steps (period too long, or not periodic)"


def _sign(c: float) -> float:
    """``numpy.sign`` of a finite float: -1.0, 0.0 or 1.0."""
    return 1.0 if c > 0 else -1.0 if c < 0 else 0.0


def orbit_average(F: OrbitFunctions, x0, rtol: float = 1e-10, max_steps: int = MAX_STEPS,
                  radius: float = 1e6) -> OrbitAverage:
    """Averages ``<g_a>`` over the periodic orbit of ``X_{H,G}`` through ``x0`` (Eq. AV of the module doc).

    The orbit is integrated twice, at ``rtol`` and ``rtol / 100``; the finer
    result is returned, the difference is the error estimate.

    Parameters
    ----------
    F : OrbitFunctions -- from :func:`orbit_functions`
    x0 : sequence of float
    rtol : float -- relative tolerance of the coarser run (``1e-13 <= rtol <= 1e-4``)
    max_steps : int -- the step budget of each run (refused beyond ``10^6``)
    radius : float -- an orbit leaving this ball is reported as not periodic

    Returns
    -------
    OrbitAverage

    Examples
    --------
    >>> import sympy
    >>> from nambu_bch import System
    >>> S = System("x1 x2", ["x1**2/2 + x2**2/2"])          # circles, period 2 pi
    >>> x1, x2 = S.coordinates
    >>> A = orbit_average(orbit_functions(S, [x1**2, x1 * x2], {}), [1.0, 0.0])
    >>> round(A.period, 9), round(A.averages[0], 9), abs(A.averages[1]) < 1e-10
    (6.283185307, 0.5, True)
    """
    if not (1e-13 <= rtol <= 1e-4):
        raise NambuBCHError(f"rtol must lie in [1e-13, 1e-4], got {rtol!r}")
    if not is_int(max_steps, 10, 1_000_000):
        raise NambuBCHError(f"max_steps must be an integer in [10, 10^6], got {max_steps!r}")
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != (F.n,) or not np.all(np.isfinite(x0)):
        raise NambuBCHError(f"x0 must be {F.n} finite numbers, got {x0.tolist()!r}")
    coarse, why = _one_orbit(F, x0, rtol, max_steps, radius)
    if coarse is None:
        return OrbitAverage(tuple(x0), False, reason=why)
    fine, why = _one_orbit(F, x0, rtol / 100, max_steps, radius)
    if fine is None:
        return OrbitAverage(tuple(x0), False, reason="finer run: " + why)
    errors = np.abs(np.array(fine["averages"]) - np.array(coarse["averages"])) + 1e-15 * np.array(fine["scales"])
    return OrbitAverage(
        tuple(float(v) for v in x0), True, fine["period"], tuple(float(a) for a in fine["averages"]),
        tuple(float(e) for e in errors), tuple(float(s) for s in fine["scales"]),
        tuple(float(h) for h in fine["H0"]), fine["dH"],
        {i: int(c) for i, c in enumerate(fine["crossings"])}, fine["steps"],
    )


def sample_points(n: int, count: int, seed: int = 17, low: float = 0.2, high: float = 1.0) -> np.ndarray:
    """``count`` reproducible starting points in ``[low, high]^n`` (positive: the Lotka--Volterra octant too)."""
    rng = np.random.default_rng(seed)
    return low + (high - low) * rng.random((count, n))


def section_integral(F: OrbitFunctions, x, index: int, rtol: float = 1e-11, max_steps: int = MAX_STEPS) -> np.ndarray:
    """``int_0^{t*} g(phi_t(x)) dt``, ``t*`` the first time the orbit of ``X_{H,G}`` crosses ``x_index = 0`` upwards.

    With vanishing orbit averages this is the smooth solution ``a`` of the homological
    equation ``X_{H,G}(a) = -g`` normalised by ``a = 0`` on the section (module doc,
    Eq. HE): ``a(phi_s x) = int_s^{t*} g``, so ``d/ds a(phi_s x) = -g``, and crossing
    the section changes ``t*`` by one period, hence ``a`` by ``T <g> = 0``.

    Parameters
    ----------
    F : OrbitFunctions
    x : sequence of float -- the point
    index : int -- the coordinate whose zero set is the section (``Fix(rho)`` of a reversing sign flip)
    rtol : float
    max_steps : int

    Returns
    -------
    numpy.ndarray -- one value per integrand

    Raises
    ------
    NambuBCHError -- the orbit does not reach the section within ``max_steps``
    """
    n, m = F.n, F.m
    if not (0 <= index < n):
        raise NambuBCHError(f"index must be a coordinate index 0..{n - 1}, got {index!r}")
    values, _ = _list_functions(F)
    y = [float(v) for v in x] + [0.0] * m
    k = values(y)
    speed = _norm(k[:n])
    if not math.isfinite(speed) or speed < 1e-12:
        raise NambuBCHError(f"X_{{H,G}} vanishes at {list(x)}: no orbit to integrate along")
    atol = rtol * max(1.0, max(abs(c) for c in y[:n]))
    dt = 1e-2 / speed
    for _ in range(max_steps):
        y_new, err, k_new = _rk_step(values, y, k, dt)
        e = _rms(err, [atol + rtol * max(abs(a), abs(b)) for a, b in zip(y, y_new)])
        if not math.isfinite(e):
            break
        if e > 1.0:
            dt *= max(0.2, 0.9 * e ** -0.2)
            continue
        if y[index] < 0.0 <= y_new[index]:
            _, y_tau = _crossing(values, y, k, dt, y[index], y_new[index], lambda z: z[index], 1e-15, 1e-16)
            return np.array(y_tau[n:])
        y, k = y_new, k_new
        dt *= min(5.0, max(0.2, 0.9 * max(e, 1e-10) ** -0.2))
    raise NambuBCHError(f"the orbit through {list(x)} does not reach x{index + 1} = 0 within {max_steps} steps")
