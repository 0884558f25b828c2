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

from dataclasses import dataclass

import numpy as np
import sympy

from ..checks import is_int
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

    ``rhs(x)`` returns ``(X(x), g(x))`` concatenated; ``hamiltonians(x)`` the values ``H_a(x)``.
    """

    n: int
    m: int
    rhs: object
    hamiltonians: object
    integrand_names: tuple


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
    subs = {p: sympy.nsimplify(params[p]) for p in system.parameters}
    field_ = [sympy.expand(sympy.sympify(c).subs(subs)) for c in system.equations_of_motion()]
    ints = [sympy.expand(sympy.sympify(g).subs(subs)) for g in integrands]
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
    )


def _rk_step(F, y, k1, dt):
    ks = [k1]
    for i in range(1, 7):
        yi = y + dt * sum(a * k for a, k in zip(_A[i], ks) if a)
        ks.append(F(yi))
    y_new = y + dt * sum(b * k for b, k in zip(_B5, ks) if b)
    err = dt * sum(e * k for e, k in zip(_E, ks) if e)
    return y_new, err, ks[6]


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
    y = np.concatenate([np.asarray(x0, float), np.zeros(m)])
    k = F.rhs(y)
    v = k[:n].copy()
    speed = float(np.linalg.norm(v))
    if not np.isfinite(speed) or speed < 1e-12:
        return None, "X_{H,G} vanishes (an equilibrium) or is not finite at x0"
    v /= speed
    H0 = F.hamiltonians(y)
    atol = rtol * max(1.0, float(np.abs(y[:n]).max()))
    t, dt = 0.0, 1e-2 / speed
    s_prev = 0.0
    diam = 0.0
    scale = np.zeros(m)
    dH = 0.0
    signs = np.sign(y[:n])
    crossings = np.zeros(n, dtype=int)
    accepted = 0
    for _ in range(max_steps):
        y_new, err, k_new = _rk_step(F.rhs, y, k, dt)
        sc = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
        e = float(np.sqrt(np.mean((err / sc) ** 2)))
        if not np.isfinite(e):
            return None, "the orbit is not finite (escapes)"
        if e > 1.0:
            dt *= max(0.2, 0.9 * e ** -0.2)
            continue
        accepted += 1
        x_new = y_new[:n]
        if float(np.abs(x_new).max()) > radius:
            return None, f"the orbit leaves the ball of radius {radius:g} (not periodic)"
        s_new = float(v @ (x_new - x0))
        d_new = float(np.linalg.norm(x_new - x0))
        diam = max(diam, d_new)
        scale = np.maximum(scale, np.abs(k_new[n:]))
        dH = max(dH, float(np.abs(F.hamiltonians(y_new) - H0).max()))
        sg = np.sign(x_new)
        crossings += (sg != signs) & (sg != 0)
        signs = np.where(sg != 0, sg, signs)
        if accepted > 3 and s_prev < 0.0 <= s_new and d_new < 0.5 * diam:
            tau, y_tau = _crossing(F.rhs, y, k, dt, s_prev, s_new, lambda z: float(v @ (z[:n] - x0)),
                                   1e-15 * max(1.0, diam), 1e-16 * max(1.0, t))
            if float(np.linalg.norm(y_tau[:n] - x0)) < 1e-4 * diam:
                T = t + tau
                return dict(period=T, averages=y_tau[n:] / T, scales=scale, H0=H0, dH=dH,
                            crossings=crossings, steps=accepted), ""
        t += dt
        y, k, s_prev = y_new, k_new, s_new
        dt *= min(5.0, max(0.2, 0.9 * max(e, 1e-10) ** -0.2))
    return None, f"no return to the section within {max_steps} steps (period too long, or not periodic)"


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
    errors = np.abs(fine["averages"] - coarse["averages"]) + 1e-15 * fine["scales"]
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
    y = np.concatenate([np.asarray(x, float), np.zeros(m)])
    k = F.rhs(y)
    speed = float(np.linalg.norm(k[:n]))
    if not np.isfinite(speed) or speed < 1e-12:
        raise NambuBCHError(f"X_{{H,G}} vanishes at {list(x)}: no orbit to integrate along")
    atol = rtol * max(1.0, float(np.abs(y[:n]).max()))
    dt = 1e-2 / speed
    for _ in range(max_steps):
        y_new, err, k_new = _rk_step(F.rhs, y, k, dt)
        e = float(np.sqrt(np.mean((err / (atol + rtol * np.maximum(np.abs(y), np.abs(y_new)))) ** 2)))
        if not np.isfinite(e):
            break
        if e > 1.0:
            dt *= max(0.2, 0.9 * e ** -0.2)
            continue
        if y[index] < 0.0 <= y_new[index]:
            _, y_tau = _crossing(F.rhs, y, k, dt, float(y[index]), float(y_new[index]), lambda z: float(z[index]),
                                 1e-15, 1e-16)
            return y_tau[n:].copy()
        y, k = y_new, k_new
        dt *= min(5.0, max(0.2, 0.9 * max(e, 1e-10) ** -0.2))
    raise NambuBCHError(f"the orbit through {list(x)} does not reach x{index + 1} = 0 within {max_steps} steps")
