"""Do shadow Hamiltonians exist (in smooth functions), and are they polynomial?  Three honest outcomes.

The criterion.  Let ``h^j`` be the first order at which the direct route finds
no polynomial corrections (or refuses the solve as too large), ``H', G'`` the
Hamiltonians with their corrections below ``h^j`` (``alpha = 0``), and ``R_j``
the right-hand side of Eq. (*) of :mod:`~nambu_bch.shadow.direct_route`
(``Z_j`` minus the cross terms), so ``X_eff = X_{H',G'} + h^j R_j + O(h^{j+1})``.

1. *Necessity.*  Every quantity conserved by ``X_eff`` to ``O(h^j)`` is
   ``Phi(H', G'; h)`` on a region foliated by periodic orbits of ``X_{H,G}``
   (induction on the powers of ``h``: the ``h^0`` part is a first integral of
   ``X_{H,G}``, hence a function of ``H, G``).  At ``h^j`` conservation of
   ``Phi + h^j a`` reads ``X_{H,G}(a) = -(Phi_H g_H + Phi_G g_G)`` with
   ``g_H = R_j . grad H``, ``g_G = R_j . grad G``; averaging over a periodic
   orbit gives ``Phi_H <g_H> + Phi_G <g_G> = 0``.  A shadow pair has two such
   ``Phi`` with Jacobian ``d(Phi_1, Phi_2)/d(H, G) = 1`` (so that
   ``X_{Phi_1,Phi_2} = X_{H,G}``), hence ``(<g_H>, <g_G>) = 0`` on every
   periodic orbit.  **A non-zero average on one periodic orbit certifies that no
   smooth shadow pair exists through h^j** (for N > 3 the same with ``N - 1``
   averages), and on that orbit ``H'`` drifts secularly at the rate
   ``dH'/dt = h^j <g_H>`` (first-order averaging: Hairer, Lubich, Wanner,
   *Geometric Numerical Integration*, 2nd ed., Sect. XI.2; Arnold, *Mathematical
   Methods of Classical Mechanics*, Sect. 52).

2. *Sufficiency.*  If all averages vanish, ``X_{H,G}(a) = -g_H`` and
   ``X_{H,G}(b) = -g_G`` have smooth solutions (integrate along the orbits from
   a transversal section), so ``H' + h^j a, G' + h^j b`` are conserved to
   ``O(h^{j+1})``.  ``X_eff`` is divergence-free (each sub-flow is a Nambu flow,
   hence volume-preserving, and so is their BCH series), and a divergence-free
   field with two independent first integrals is ``f X_{H_S,G_S}`` with
   ``X_{H_S,G_S}(f) = div = 0``, i.e. ``f = f(H_S, G_S)``; replacing ``H_S`` by
   ``int f dH_S`` makes it ``X_{H_S,G_S}`` exactly.  So a smooth shadow pair
   exists at ``h^j`` -- generally not polynomial.

3. *Reversibility.*  If a sign flip ``rho`` of an odd number of coordinates
   fixes ``H`` and ``G`` (so ``X_{H,G}`` is ``rho``-reversible,
   ``X(rho x) = -rho X(x)``) and the integrands are odd, ``g(rho x) = -g(x)``
   -- as happens for symmetric methods built from ``rho``-reversible pieces
   (HLW Sects. V.1 and XI.1: the modified equation of a reversible method is
   reversible) -- then ``<g> = 0`` exactly on every orbit that meets
   ``Fix(rho)`` (such an orbit is mapped onto itself with time reversed).

How the averages are obtained (in this order):

* **exact**: solve ``g = X_{H,G}(p) + c(H, G)`` for a polynomial ``p`` and a
  polynomial ``c`` in the Hamiltonians (exact linear algebra); then ``<g> = c(H, G)``
  on *every* periodic orbit (``<X(p)> = 0``) -- certified, with the drift as a formula;
* **symmetry**: the reversibility argument above, checked exactly on the
  polynomials; the sampled orbits are checked to meet ``Fix(rho)``;
* **numerical**: :func:`~nambu_bch.shadow.averaging.orbit_average` on sampled
  orbits, two tolerances, error estimate; a non-zero average is reported only
  when it exceeds 100 times the estimate (stated as *numerical*, not interval-rigorous).
  Numerically vanishing averages are evidence only: the outcome stays undecided.

Every certified non-existence comes with the measured drift of ``H'`` under the
iterated integrator at two step sizes (:func:`measure_drift`), which must match
``h^j <g_H>`` -- the second, independent check.

References
----------
Hairer, Lubich, Wanner, Geometric Numerical Integration (2006), Sects. V.1, IX.2, XI.1, XI.2;
Horikoshi, Eqs. (L2), (Xeff3).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, reduce
from itertools import combinations, product
from operator import mul

import numpy as np
import sympy

from ..algebra.ansatz import Ansatz, Rows
from ..algebra.elimination import SparseMatrix, solve_affine
from ..checks import check_flag, check_type, finite_float, is_int, show
from ..errors import NambuBCHError
from ..parsing import as_expression
from .averaging import orbit_average, orbit_functions, sample_points, section_integral
from ..symbols import ALPHA, STEP
from ..values import ValueEquality

MAX_EXACT_UNKNOWNS = 400  # the exact decomposition g = X(p) + c(H, G) is refused above this size
DEFAULT_ORBITS = 6
PERIODS = 6.0  # length of the drift measurement, in orbit periods
SLACK = 2  # extra degree of p in the exact decomposition (the fields are not homogeneous)


@dataclass(eq=False)
class Existence(ValueEquality):
    """The decision at the first order the polynomial ansatz did not solve.

    Attributes
    ----------
    outcome : ``"smooth"`` (a pair exists, not polynomial up to the degree tried),
        ``"none"`` (certified non-existence) or ``"undecided"``
    exists : True / False / None
    order : int -- the power ``h^j`` decided
    method : ``"exact"``, ``"symmetry"``, ``"numerical"`` or None
    averages : list of sympy expressions in the Hamiltonian symbols (exact method) or None
    involution : tuple of coordinate indices flipped by ``rho`` (symmetry method) or None
    orbits : list of :class:`~nambu_bch.shadow.averaging.OrbitAverage`
    certificate_orbit : OrbitAverage or None -- the orbit with the non-zero average
    drift : dict ``name -> sympy expression`` -- predicted ``dH'/dt`` (with ``h``) on that orbit / as a formula
    measured : list of dict -- measured drift rates of the iterated integrator (two step sizes)
    reason : str
    params : dict -- the parameter values used for the numerics
    """

    outcome: str
    exists: object
    order: int
    method: str | None = None
    averages: list | None = None
    involution: tuple | None = None
    orbits: list = field(default_factory=list)
    certificate_orbit: object = None
    drift: dict | None = None
    measured: list = field(default_factory=list)
    reason: str = ""
    params: dict = field(default_factory=dict)
    names: tuple = ()
    functions: object = field(default=None, repr=False)
    sections: tuple = ()

    def _value(self) -> tuple:
        """The decision as data (``==``, ``hash``); ``functions``, the numerical integrands, are rebuilt from it."""
        return (self.outcome, self.exists, self.order, self.method, self.averages, self.involution, self.orbits,
                self.certificate_orbit, self.drift, self.measured, self.reason, self.params, self.names, self.sections)

    def correction(self, x, index=None) -> np.ndarray:
        """The smooth corrections ``(a_H, a_G)`` at ``x``: ``H + h^j a_H`` and ``G + h^j a_G`` are conserved to ``O(h^{j+1})``.

        Available for the symmetry outcome: ``a = int_0^{t*} R_j.grad H dt`` along the orbit
        of ``X_{H,G}`` up to its upward crossing of ``Fix(rho)`` (the solution of Eq. HE of
        :mod:`~nambu_bch.shadow.averaging` that vanishes there; :func:`~nambu_bch.shadow.averaging.section_integral`).
        These are the non-polynomial parts of the shadow pair at ``h^j`` (up to ``psi(H, G)``).
        """
        if self.method != "symmetry" or not self.sections or self.functions is None:
            raise NambuBCHError(f"smooth corrections are available for the symmetry outcome with one flipped coordinate; "
                                f"this decision is {self.outcome!r} by {self.method!r}")
        index = self.sections[0] if index is None else index
        if index not in self.sections:
            raise NambuBCHError(f"index must be one of the reversing sections {list(self.sections)} (x_i = 0), got {index!r}")
        return section_integral(self.functions, x, index)

    def section_for(self, x) -> int:
        """A reversing section ``x_i = 0`` that the orbit through ``x`` meets (use one per trajectory: ``a`` is
        defined up to a function of ``H, G``, which depends on the section)."""
        o = orbit_average(self.functions, x)
        for i in self.sections:
            if o.closed and o.fix_crossings.get(i, 0) > 0:
                return i
        raise NambuBCHError(f"the orbit through {list(x)} meets none of the reversing sections "
                            f"{[f'x{i + 1} = 0' for i in self.sections]}")

    def evidence(self) -> dict:
        """The evidence as JSON-ready data."""
        out = {"outcome": self.outcome, "order": self.order, "method": self.method, "reason": self.reason,
               "params": {str(k): str(v) for k, v in self.params.items()}}
        if self.averages is not None:
            out["averages"] = {n: str(a) for n, a in zip(self.names, self.averages)}
        if self.sections:
            out["involutions"] = [f"x{i + 1} -> -x{i + 1}" for i in self.sections]
        closed = [o for o in self.orbits if o.closed]
        out["orbits_closed"] = len(closed)
        out["orbits_tried"] = len(self.orbits)
        out["orbits"] = [o.to_dict() for o in self.orbits]
        if self.certificate_orbit is not None:
            out["certificate_orbit"] = self.certificate_orbit.to_dict()
        if self.measured:
            out["measured_drift"] = self.measured
        return out

    def drift_dict(self) -> dict | None:
        return None if self.drift is None else {k: str(v) for k, v in self.drift.items()}


# -- the integrands ---------------------------------------------------------------------

def integrands(result):
    """``g_a = R_j . grad H_a`` at the first unsolved order of a :class:`DirectResult` (``alpha = 0``), and ``j``."""
    bad = next(o for o in result.orders if o.status not in ("solved", "vanishes"))
    system = result.system
    R = [sympy.expand(c.subs(ALPHA, 0)) for c in bad.rhs.to_sympy()]
    ops = system.algebra.expression_backend  # R . grad H = R(H), the field applied to H (expanded sympy)
    gs = [ops.apply(ops.field(R), ops.function(H)) for H in system.hamiltonians]
    return gs, bad.order


def conserved_below(result, j):
    """``H'_a``: the Hamiltonians with the corrections below ``h^j`` (``alpha = 0``), sympy in ``h``."""
    return tuple(sympy.expand(S.subs(ALPHA, 0)) for S in result.shadow(upto=j - 1))


def _names(system):
    k = len(system.hamiltonians)
    return ("H",) if k == 1 else ("H", "G") if k == 2 else tuple(f"H{a + 1}" for a in range(k))


# -- exact: g = X(p) + c(H, G) ---------------------------------------------------------------

def exact_average(system, g, max_unknowns: int = MAX_EXACT_UNKNOWNS):
    """``c(H_1, .., H_{N-1})`` with ``g = X_{H..}(p) + c`` for a polynomial ``p``, or None if the ansatz fails.

    Then ``<g>_gamma = c(H(gamma), ..)`` on every periodic orbit ``gamma`` (``<X(p)> = 0``).
    Returns a sympy expression in the symbols ``H, G`` (``H1, H2, ..`` for N > 3), or None.

    Examples
    --------
    >>> from nambu_bch import System
    >>> S = System("x1 x2", ["x1**2/2 + x2**2/2"])
    >>> x1, x2 = S.coordinates
    >>> exact_average(S, x1**2)            # <x1^2> = H on the circle of radius sqrt(2H)
    H
    """
    alg = system.algebra
    coords = system.coordinates
    n = len(coords)
    g = sympy.expand(g)
    if g == 0:
        return sympy.Integer(0)
    deg_g = sympy.Poly(g, *coords).total_degree()
    hams = [sympy.expand(H) for H in system.hamiltonians]
    hdeg = [sympy.Poly(H, *coords).total_degree() for H in hams]
    reach = sum(d - 1 for d in hdeg)
    Dp = max(1, deg_g + 1 - reach) + SLACK
    names = [sympy.Symbol(s) for s in _names(system)]
    cmonos = [e for e in product(range(deg_g + 1), repeat=len(hams))
              if sum(d * k for d, k in zip(hdeg, e)) <= deg_g]
    if Ansatz.size(n, Dp, lowest=1) + len(cmonos) > max_unknowns:  # refused before the monomials are built
        return None
    pmonos = sorted(Ansatz(n, Dp, lowest=1).monomials)  # p: degree 1..Dp, ascending lexicographic
    X = system.vector_field
    rows = Rows()

    def vec(expr):
        return rows.vector(expr if hasattr(expr, "ring") else alg.convert(sympy.expand(expr)))

    cols = [vec(X.apply(alg.convert(sympy.Mul(*(x**k for x, k in zip(coords, e)))))) for e in pmonos]
    # the products of powers of the Hamiltonians in the ring (sympy's expansion of each product cost most of this
    # function for the quartic pairs); the solution does not depend on the order in which rows first appear
    ring_hams = [alg.convert(H) for H in hams]
    if all(hasattr(H, "ring") for H in ring_hams):
        ccols = [vec(reduce(mul, (H**k for H, k in zip(ring_hams, e)), alg.convert(1)))
                 for e in cmonos]
    else:
        ccols = [vec(sympy.Mul(*(H**k for H, k in zip(hams, e)))) for e in cmonos]
    b = vec(g)
    solution = solve_affine(SparseMatrix.from_columns(cols + ccols, len(rows), alg.domain), [b], certificate=False)
    if not solution.consistent:
        return None
    particular = solution.particular[0]
    c = sympy.Integer(0)
    for col, v in particular.items():
        if col >= len(cols):
            e = cmonos[col - len(cols)]
            c += alg.domain.to_sympy(v) * sympy.Mul(*(s**k for s, k in zip(names, e)))
    return sympy.factor(c)


# -- symmetry ---------------------------------------------------------------------------------

def reversing_involutions(system, gs) -> list:
    """Sign flips ``rho`` (odd number of coordinates) with ``H_a o rho = H_a`` and ``g o rho = -g`` for all integrands."""
    coords = system.coordinates
    n = len(coords)
    out = []
    for size in range(1, n + 1, 2):
        for flip in combinations(range(n), size):
            # symbols replaced by symbols: xreplace (one rebuild of the tree) is subs(simultaneous=True) without
            # its pattern matching, ~6x faster on the integrands of a quartic pair (80 terms)
            sub = {coords[i]: -coords[i] for i in flip}
            if all(sympy.expand(H.xreplace(sub) - H) == 0 for H in system.hamiltonians) and \
                    all(sympy.expand(g.xreplace(sub) + g) == 0 for g in gs):
                out.append(flip)
    return out


# -- the measured drift -----------------------------------------------------------------------

def measure_drift(system, word, conserved, x0, params: dict, h: float, periods: float, period: float):
    """Secular rate ``dH'/dt`` of the iterated integrator from ``x0``: window means one period wide, first vs last.

    The ``O(h^j)`` oscillation of ``H'`` is periodic with (nearly) the orbit's period,
    so its mean over one period is (nearly) constant; the difference of the means over
    the first and the last period, divided by the time between them, is the drift.
    ``conserved`` are the ``H'_a`` (sympy in the coordinates, the parameters and ``h``).
    """
    from ..numeric.iterate import iterate

    steps = int(np.ceil(periods * period / h))
    if steps > 2_000_000:
        raise NambuBCHError(f"the drift measurement needs {steps} steps (> 2e6); use a larger h or fewer periods")
    pvals = {str(p): float(v) for p, v in params.items()}
    xs = iterate(system, word, h, steps, np.asarray(x0, float), params=pvals, progress=False)
    subs = {p: sympy.nsimplify(v) for p, v in params.items()}
    t = np.arange(xs.shape[0]) * h
    w = int(round(period / h))
    rates = []
    for C in conserved:
        f = sympy.lambdify([system.coordinates], C.subs(subs).subs(STEP, sympy.nsimplify(h)), modules="numpy")
        vals = np.asarray(f(xs.T), dtype=float) * np.ones(xs.shape[0])
        first, last = vals[:w].mean(), vals[-w:].mean()
        rates.append(float((last - first) / (t[-w:].mean() - t[:w].mean())))
    return rates


# -- the decision -----------------------------------------------------------------------------

def _default_params(system) -> dict:
    # generic, distinct values (1 is often special)
    return {p: sympy.Rational(k + 3, k + 2) for k, p in enumerate(system.parameters)}


def _check_params(system, params):
    if params is None:
        return _default_params(system)
    if not isinstance(params, dict):
        raise NambuBCHError(f"params must be a dict name -> number, got {show(params)}")
    by_name = {str(p): p for p in system.parameters}
    out = _default_params(system)
    for k, v in params.items():
        if str(k) not in by_name:
            raise NambuBCHError(f"unknown parameter {show(k)}; the system has {sorted(by_name)}")
        try:
            val = sympy.nsimplify(as_expression(v, (), f"parameter {k}"))  # nsimplify would sympify text
        except (sympy.SympifyError, TypeError) as exc:
            raise NambuBCHError(f"parameter {k} must be a number, got {show(v)}") from exc
        if not val.is_real or not val.is_number:
            raise NambuBCHError(f"parameter {k} must be a real number, got {show(v)}")
        out[by_name[str(k)]] = val
    return out


def decide(result, params=None, points=None, orbits: int = DEFAULT_ORBITS, measure: bool = True,
           rtol: float = 1e-10) -> Existence:
    """Decide existence at the first order a :class:`DirectResult` did not solve polynomially.

    The strategies of :data:`STRATEGIES` are asked in order; the first that decides answers.  A
    certified non-existence is then checked by measuring the drift of the iterated integrator.

    Parameters
    ----------
    result : DirectResult -- with an ``"obstructed"`` or ``"refused"`` order
    params : dict, optional -- parameter values for the numerics (default: generic rationals ``3/2, 4/3, ..``)
    points : array (count, N), optional -- starting points of the orbits (default: ``orbits`` seeded points in ``[0.2, 1]^N``)
    orbits : int -- number of sampled orbits (1..64)
    measure : bool -- iterate the integrator to measure the drift of a certified non-existence
    rtol : float -- tolerance of the orbit integration

    Returns
    -------
    Existence

    Examples
    --------
    >>> from nambu_bch import model
    >>> from nambu_bch.shadow.direct_route import direct_route
    >>> d = decide(direct_route(model("ho3"), "123", 1), measure=False)    # Lie-Trotter on ho3: h^1
    >>> d.outcome, d.method, d.averages
    ('none', 'exact', [omega**2*(G*m*omega**2 - 2*H)/4, (G*m*omega**2 - 2*H)/(2*m)])
    """
    from .direct_route import DirectResult

    system = check_type(result, DirectResult, "result").system
    if not is_int(orbits, 1, 64):
        raise NambuBCHError(f"orbits must be an integer in 1..64, got {show(orbits)}")
    measure = check_flag(measure, "measure")
    rtol = finite_float(rtol, "rtol")
    if not 0 < rtol < 1:
        raise NambuBCHError(f"rtol must be a tolerance between 0 and 1, got {show(rtol)}")
    ctx = _Context(result, _check_params(system, params), points, orbits, rtol)
    dec = next(d for d in (strategy(ctx) for strategy in STRATEGIES) if d is not None)
    if measure and dec.exists is False:
        _measure(ctx, dec)
    return dec


class _Context:
    """What every strategy may read: the integrands at ``h^j`` and, computed on first use, the sampled orbits.

    ``draft`` is the decision under construction; a strategy that passes may still record what it found
    there (the reversing involutions), and the one that decides returns it.
    """

    def __init__(self, result, params, points, orbits, rtol):
        self.result, self.params, self._points, self._count, self._rtol = result, params, points, orbits, rtol
        self.system = result.system
        self.gs, self.j = integrands(result)
        self.names = _names(self.system)

    @cached_property
    def draft(self) -> Existence:
        n = len(self.system.coordinates)
        if self._points is None:
            pts = sample_points(n, self._count)
        else:
            try:
                pts = np.asarray(self._points, dtype=float)
            except (TypeError, ValueError, OverflowError):  # text, ragged or complex entries: named below
                pts = np.zeros(0)
            if pts.ndim != 2 or pts.shape[1] != n or not 1 <= len(pts) <= 64 or not np.all(np.isfinite(pts)):
                raise NambuBCHError(f"points must be 1 to 64 finite points of {n} coordinates, got {show(self._points)}")
        F = orbit_functions(self.system, self.gs, self.params, self.names)
        found = [orbit_average(F, x, rtol=self._rtol) for x in pts]
        return Existence("undecided", None, self.j, orbits=found, params=self.params, names=self.names, functions=F)

    @property
    def closed(self) -> list:
        return [o for o in self.draft.orbits if o.closed]


def _needs_curves(ctx):
    """Undecided at once when the orbits are not curves (fewer than N - 1 Hamiltonians)."""
    system, j = ctx.system, ctx.j
    n = len(system.coordinates)
    if len(system.hamiltonians) == n - 1:
        return None
    # the criterion needs orbits that are curves (N - 1 first integrals); canonical d >= 2 and triplet
    # systems have invariant tori of higher dimension, whose averages are not orbit averages
    return Existence("undecided", None, j, params=ctx.params, names=ctx.names,
                     reason=(f"the orbit-average criterion needs N - 1 = {n - 1} Hamiltonians (orbits that are "
                             f"curves); {system.name} has {len(system.hamiltonians)} on N = {n}, so no decision "
                             "is made beyond the polynomial ansatz"))


def _vanishing(ctx):
    """A pair when the integrands vanish identically."""
    if not all(g == 0 for g in ctx.gs):
        return None
    dec = ctx.draft
    dec.outcome, dec.exists, dec.method = "smooth", True, "exact"
    dec.averages = [sympy.Integer(0)] * len(ctx.gs)
    dec.reason = f"at h^{ctx.j} the integrands R.grad H vanish identically"
    return dec


def _exact(ctx):
    """``g = X(p) + c(H, G)`` solved for every integrand: the averages ``c`` as formulas (passes if one fails)."""
    dec = ctx.draft  # the orbits first: bad points are refused before the exact solve
    exact = [exact_average(ctx.system, g) for g in ctx.gs]
    if any(c is None for c in exact):
        return None
    j, names = ctx.j, ctx.names
    dec.averages = exact
    dec.method = "exact"
    if all(c == 0 for c in exact):
        dec.outcome, dec.exists = "smooth", True
        dec.reason = (f"at h^{j} every R.grad H_a is X_{{H,G}}(p_a) for a polynomial p_a: the averages vanish "
                      "identically (conserved polynomials exist; the pair needs a function of them)")
        return dec
    # certified: <g> = c(H, G) on every periodic orbit; find one where c != 0
    syms = [sympy.Symbol(s) for s in names]
    for o in ctx.closed:
        vals = [float(c.subs(ctx.params).subs(dict(zip(syms, o.hamiltonians)))) for c in exact]
        if any(abs(v) > 1e-12 for v in vals):
            dec.certificate_orbit = o
            break
    if dec.certificate_orbit is None:
        dec.reason = f"exact averages {exact} but no sampled periodic orbit where they are non-zero"
        return dec
    dec.outcome, dec.exists = "none", False
    dec.drift = {nm: STEP**j * c for nm, c in zip(names, exact)}
    dec.reason = (f"at h^{j} the orbit averages are exactly " +
                  ", ".join(f"<R.grad {nm}> = {c}" for nm, c in zip(names, exact)) +
                  " on every periodic orbit (g = X(p) + c(H, G)), non-zero on the certificate orbit")
    return dec


def _symmetry(ctx):
    """A pair by reversibility, on the sampled orbits that meet a reversing plane ``x_i = 0``.

    The single-coordinate involutions found are recorded on the draft even when no sampled orbit meets
    their planes (the evidence lists them; :meth:`Existence.correction` needs them).
    """
    dec, closed = ctx.draft, ctx.closed
    singles = tuple(f[0] for f in reversing_involutions(ctx.system, ctx.gs) if len(f) == 1)
    if not singles:
        return None
    good = [o for o in closed if any(o.fix_crossings.get(i, 0) > 0 for i in singles)]
    dec.involution = (singles[0],)
    dec.sections = singles
    if not good:
        return None
    dec.outcome, dec.exists, dec.method = "smooth", True, "symmetry"
    small = all(all(o.negligible()) for o in good)
    dec.reason = (f"at h^{ctx.j} the integrands are odd under the reversing involutions "
                  f"{', '.join(f'x{i + 1} -> -x{i + 1}' for i in singles)}, which fix the Hamiltonians: the "
                  f"averages vanish exactly on every orbit meeting one of their fixed planes ({len(good)} of "
                  f"{len(closed)} sampled closed orbits do); numerically |<g>| <= "
                  f"{max(max(abs(a) for a in o.averages) for o in good):.1e} "
                  f"({'consistent' if small else 'INCONSISTENT'} with zero)")
    if not small:
        dec.outcome, dec.exists, dec.method = "undecided", None, None
    return dec


def _numerical_certificate(ctx):
    """No pair: an orbit whose quadrature average exceeds 100 times its error estimate."""
    sig = [o for o in ctx.closed if any(o.significant())]
    if not sig:
        return None
    dec = ctx.draft
    dec.method = "numerical"
    o = max(sig, key=lambda o: max(abs(a) / (e + 1e-300) for a, e in zip(o.averages, o.errors)))
    dec.certificate_orbit = o
    dec.outcome, dec.exists = "none", False
    dec.drift = {nm: STEP**ctx.j * sympy.Float(a, 12) for nm, a in zip(ctx.names, o.averages)}
    dec.reason = (f"at h^{ctx.j} the average " + ", ".join(f"<R.grad {nm}> = {a:.6g} (+- {e:.1e})"
                                                         for nm, a, e in zip(ctx.names, o.averages, o.errors)) +
                  f" on the periodic orbit through {[round(v, 6) for v in o.x0]} (numerical, error estimate from two tolerances)")
    return dec


def _numerical_evidence(ctx):
    """Undecided, with the evidence: the averages vanish numerically on every sampled closed orbit."""
    closed = ctx.closed
    if not (closed and all(all(o.negligible()) for o in closed)):
        return None
    dec = ctx.draft
    dec.method = "numerical"
    worst = max(max(abs(a) / s for a, s in zip(o.averages, o.scales) if s) for o in closed)
    dec.reason = (f"at h^{ctx.j} the averages vanish numerically on {len(closed)} orbits (|<g>|/max|g| <= {worst:.1e}): "
                  "evidence of a smooth shadow pair, not a proof; undecided")
    return dec


def _no_decision(ctx):
    """Undecided: the sampled averages are neither clearly zero nor clearly non-zero (always answers)."""
    dec = ctx.draft
    dec.method = "numerical"
    dec.reason = (f"at h^{ctx.j} no decision: {len(ctx.closed)} of {len(dec.orbits)} sampled orbits closed, "
                  "averages neither clearly zero nor clearly non-zero")
    return dec


#: The decision procedure: each strategy takes the :class:`_Context` and returns an :class:`Existence` or None
#: (passes); the first answer is the decision.  The order is the one the module docstring documents: exact
#: averages before the symmetry argument before quadrature, and the last strategy always answers.
STRATEGIES = (_needs_curves, _vanishing, _exact, _symmetry, _numerical_certificate, _numerical_evidence, _no_decision)


def _measure(ctx, dec) -> None:
    """Append to ``dec.measured`` the drift of ``H'`` measured on the certificate orbit at two step sizes."""
    o, j, names, params = dec.certificate_orbit, ctx.j, ctx.names, ctx.params
    conserved = conserved_below(ctx.result, j)
    # small enough that H' moves by <= 0.5% of its size over the run (the rate is then that of one orbit)
    size = max(1e-3, max(abs(v) for v in o.hamiltonians))
    rate = max(abs(a) for a in o.averages) + 1e-300
    h1 = float(min(0.05, o.period / 100, (0.005 * size / (rate * PERIODS * o.period)) ** (1.0 / j)))
    syms = [sympy.Symbol(s) for s in names]
    for h in (h1, h1 / 2):
        try:
            rates = measure_drift(ctx.system, ctx.result.composition, conserved, o.x0, params, h, PERIODS, o.period)
        except NambuBCHError as exc:  # e.g. a step outside the stability interval: say so, keep the certificate
            dec.measured.append({"h": h, "error": str(exc)})
            continue
        if dec.method == "exact":
            predicted = [float(h**j * c.subs(params).subs(dict(zip(syms, o.hamiltonians)))) for c in dec.averages]
        else:
            predicted = [float(h**j * a) for a in o.averages]
        dec.measured.append({"h": h, "measured": dict(zip(names, rates)), "predicted": dict(zip(names, predicted))})
