"""Design: solve a template's order conditions and keep the solution with the smallest error constant.

Algorithm
---------
1. The order conditions ``F(x) = 0`` of the template (:func:`order_conditions`, exact
   polynomials) and the objective ``f(x) = LEM(x)^2``, the sum of squares of the degree
   ``p + 1`` log defects (``p`` the requested order, raised past degrees whose defects
   vanish identically, e.g. the even ones of symmetric templates).
2. A maximal independent subset of ``F`` (numerical rank of the Jacobian at a solution).
3. The critical points of ``f`` on ``{F = 0}``: from ``starts`` seeded random points, each
   projected onto ``{F = 0}`` by Gauss-Newton, Newton's method on the Lagrange system
   ``grad f + J^T lambda = 0, F = 0`` in float64; distinct converged real points are
   ranked by ``f`` and the three best are polished by Newton in mpmath (``dps`` digits,
   default 30); the smallest ``f`` wins.  With as many independent conditions as unknowns
   this is the plain solve, polished by Newton.
4. The exact minimiser, when the conditions leave ``n - r > 0`` unknowns free: the critical-point equations
   (conditions and Lagrange minors) are polynomial over QQ and, when small enough, solved exactly through a lex
   Groebner basis in shape position; the root near the numerical optimum is certified by its isolating interval
   and by reducing every equation to zero in ``QQ[t]/(g)`` (:func:`_exact_critical_point`).  In real radicals it is
   the returned composition (``optimal=True``; ``word:12121`` gives McLachlan's 0.19318332750378...); otherwise
   it is ``optimum`` as ``CRootOf`` values and the composition comes from step 5.
5. An exact form: the ``n - r`` unknowns left free by the conditions are fixed to nearby
   rationals (each choice of free unknowns is tried), the remaining conditions are solved
   exactly through a lex Groebner basis in shape position (a univariate polynomial of degree
   <= 4, solved in radicals, the lowest degree preferred); a solution counts only if it is
   real and written in real radicals,
   and it is then *verified exactly* (every log defect of length ``<= p`` is zero in the
   algebraic field of the coefficients).  The exact composition nearest in error constant
   to the numerical optimum is returned, with ``optimal=False`` when unknowns were fixed (it is an exact solution
   of the order conditions next to the minimiser, not the minimiser).
6. If no such exact form exists, the coefficients are the ``dps``-digit optimum as
   rationals (the degree-1 conditions re-solved exactly, so the scheme is consistent), the
   result is marked ``exact=False`` and carries ``error_bound``: the largest absolute
   Lyndon defect of length ``<= p``, computed exactly.  Symbolic routes then analyse these
   rationals as they are: their ``X_eff`` has terms of size ``error_bound`` below ``h^p``.

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. V.3 (composition
methods, optimal coefficients); McLachlan, SIAM J. Sci. Comput. 16 (1995) 151;
Auzinger, Hofstaetter, Ketcheson, Koch, BIT 57 (2017) 55 (LEM, Newton polishing).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from fractions import Fraction
from itertools import combinations, product

import mpmath
import numpy as np
import sympy
from sympy.polys.domains import QQ
from sympy.polys.orderings import grevlex

from ..algebra.elimination import SparseMatrix, solve_affine
from ..checks import check_flag, check_int, is_int, show
from ..errors import InvalidOrderError, NambuBCHError
from ..integrators.composition import Composition
from ..systems.system import check_name
from .conditions import _Exact, defect_polynomials, error_analysis, order_conditions, template

#: Largest number of unknowns accepted by :func:`optimize_composition`.
MAX_UNKNOWNS = 8
#: Most starting points of the float search (each is a Newton projection; the default is 40).
MAX_STARTS = 10_000
#: Solutions with a coefficient larger than this in absolute value are not searched (useless in practice).
MAX_COEFFICIENT = 50.0


class NoSolutionError(NambuBCHError):
    """A template whose order conditions have no real solution (found by the search)."""


@dataclass(frozen=True)
class DesignedComposition(Composition):
    """A :class:`Composition` found by :func:`optimize_composition`, usable wherever a word is.

    Extra attributes
    ----------------
    template : str            -- the template's name
    values : tuple            -- ``(unknown, exact value)`` pairs: the coefficients of *this* composition
    optimum : tuple           -- ``(unknown, value)`` of the constrained minimiser: exact algebraic numbers (real
    radicals, or ``CRootOf`` of the minimal polynomial, whose isolating interval certifies which root) when the
    critical-point equations were solved exactly, else ``dps``-digit decimal strings
    lem : float               -- the error constant of *this* composition (exact, as float)
    lem_optimum : float       -- the error constant at the numerical optimum
    exact : bool              -- True: order conditions hold exactly; False: see ``error_bound``
    error_bound : float       -- largest absolute Lyndon defect of length <= order (0 when exact)
    optimal : bool            -- True: ``values`` are the minimiser itself (exactly); False: an exact solution
    of the order conditions near it, or its decimals (see ``optimum``)
    """

    template: str = ""
    values: tuple = ()
    optimum: tuple = ()
    lem: float = float("nan")
    lem_optimum: float = float("nan")
    exact: bool = True
    error_bound: float = 0.0
    optimal: bool = False

    def summary(self) -> dict:
        return {
            "name": self.name, "template": self.template, "order": self.order, "exact": self.exact,
            "optimal": self.optimal,
            "error_bound": self.error_bound, "error_constant": self.lem, "error_constant_optimum": self.lem_optimum,
            "values": {str(k): str(v) for k, v in self.values},
            "optimum": {str(k): str(v) for k, v in self.optimum},
        }


class _PolyEval:
    """A polynomial with rational coefficients evaluated from its terms, in float64 or in mpmath."""

    def __init__(self, poly: sympy.Poly):
        terms = poly.terms() or [((0,) * len(poly.gens), sympy.Integer(0))]
        self.monoms = np.array([m for m, _ in terms], dtype=np.int64)
        self.cf = np.array([float(c) for _, c in terms])
        self.fractions = [(int(sympy.Rational(c).p), int(sympy.Rational(c).q)) for _, c in terms]
        self.top = int(self.monoms.max()) if self.monoms.size else 0
        self.monoms_list = [tuple(int(e) for e in m) for m in self.monoms]

    def float(self, x):
        return float(np.sum(self.cf * np.prod(np.power(np.asarray(x, float), self.monoms), axis=1)))

    def mp(self, x, powers=None):
        """The value at ``x`` in mpmath (the working precision); ``powers[i][e] = x_i^e`` may be passed in, built
        by :func:`_mp_powers` (one table for every polynomial of a point: the same products, computed once)."""
        if powers is None:
            powers = _mp_powers(x, self.top)
        total = mpmath.mpf(0)
        for term, mon in zip(self._mp_constants(), self.monoms_list):
            if term is not None:
                for i, e in enumerate(mon):
                    if e:
                        term *= powers[i][e]
                total += term
        return total

    def _mp_constants(self):
        """``mpf(p) / q`` per term (None for ``p = 0``) at the working precision, computed once per precision."""
        prec = mpmath.mp.prec
        cached = self.__dict__.get("_mp_cache")
        if cached is None or cached[0] != prec:
            cached = (prec, [mpmath.mpf(p) / q if p else None for p, q in self.fractions])
            self._mp_cache = cached
        return cached[1]


def _mp_powers(x, top: int) -> list:
    """``powers[i][e] = x_i^e`` for ``e <= top`` in mpmath, by repeated multiplication from 1."""
    powers = [[mpmath.mpf(1)] for _ in x]
    for i, v in enumerate(x):
        for _ in range(top):
            powers[i].append(powers[i][-1] * v)
    return powers


class _Problem:
    """``f`` (objective) and ``F`` (conditions) with gradients and Hessians, evaluated from polynomial terms."""

    def __init__(self, objective: sympy.Poly, conditions, x):
        self.x, self.n, self.m = list(x), len(x), len(conditions)
        Fp = [sympy.Poly(e, *x) for e in conditions]
        grad = [objective.diff(v) for v in x]
        jac = [[P.diff(v) for v in x] for P in Fp]
        E = _PolyEval
        self.f = E(objective)
        self.F = [E(P) for P in Fp]
        self.g = [E(g) for g in grad]
        self.H = [[E(g.diff(v)) for v in x] for g in grad]
        self.J = [[E(d) for d in row] for row in jac]
        self.C = [[[E(d.diff(v)) for v in x] for d in row] for row in jac]
        self.top = max(P.top for P in [self.f, *self.F, *_leaves([self.g, self.H, self.J, self.C])])
        self._stacks = {}

    def values(self, name, x, lib):
        if lib == "mp":  # one table of powers for every polynomial of the point
            powers = _mp_powers(x, self.top)

            def ev(obj):
                return [ev(o) for o in obj] if isinstance(obj, list) else obj.mp(x, powers)

            return ev(getattr(self, name))
        stack = self._stacks.get(name)
        if stack is None:
            stack = self._stacks[name] = _FloatStack(getattr(self, name))
        return stack(x)

    def kkt(self, z, lib):
        """``(G, DG)`` of the Lagrange system at ``z = (x, lambda)``; ``lib`` is ``"float"`` or ``"mp"``."""
        n, m = self.n, self.m
        x, lam = list(z[:n]), list(z[n:])
        F, g, H, J, C = (self.values(k, x, lib) for k in ("F", "g", "H", "J", "C"))
        G = [g[i] + sum(lam[k] * J[k][i] for k in range(m)) for i in range(n)] + list(F)
        DG = [[H[i][j] + sum(lam[k] * C[k][i][j] for k in range(m)) for j in range(n)] + [J[k][i] for k in range(m)]
              for i in range(n)]
        DG += [[J[k][j] for j in range(n)] + [0] * m for k in range(m)]
        return G, DG


def _leaves(nested) -> list:
    """The polynomials of nested lists."""
    return [leaf for o in nested for leaf in (_leaves(o) if isinstance(o, list) else [o])]


class _FloatStack:
    """The nested list of :class:`_PolyEval` of one name (``F``, ``J``, ``C`` ...) evaluated in float64 together.

    The float Newton iterations and projections evaluate ~``m n^2`` small polynomials per step; one at a time, each
    paid numpy's per-call overhead five times over (``benchmarks/bench_optimize.py``: ~15 % of a whole optimisation;
    the symbolic defects and the mpmath polish are the rest).  Here the terms of all of them are one array (the same
    elementwise products as :meth:`_PolyEval.float`), and each polynomial's value is ``np.sum`` of its contiguous
    slice, so the values are bit for bit those of :meth:`_PolyEval.float`.
    """

    def __init__(self, nested):
        polys = _leaves(nested) if isinstance(nested, list) else [nested]
        self.shape = _shape(nested) if isinstance(nested, list) else None
        self.monoms = np.concatenate([P.monoms for P in polys]) if polys else None
        self.cf = np.concatenate([P.cf for P in polys]) if polys else None
        ends = np.cumsum([len(P.cf) for P in polys]).tolist()
        self.bounds = list(zip([0, *ends[:-1]], ends))

    def __call__(self, x):
        if not self.bounds:  # no conditions: F, J and C are empty lists
            return np.empty(self.shape).tolist()
        terms = self.cf * np.prod(np.power(np.asarray(x, float), self.monoms), axis=1)
        flat = [float(np.sum(terms[a:b])) for a, b in self.bounds]
        if self.shape is None:
            return flat[0]
        return np.array(flat, dtype=object).reshape(self.shape).tolist()


def _shape(nested) -> tuple:
    """The rectangular shape of nested lists (``[m][n][n]`` ...)."""
    return (len(nested), *(_shape(nested[0]) if nested and isinstance(nested[0], list) else ()))


def _newton_float(prob, z, steps=80):
    """Newton on the Lagrange system in float64, stopped when the step is at round-off level."""
    for _ in range(steps):
        G, DG = prob.kkt(z, "float")
        G = np.asarray(G, float)
        if not np.all(np.isfinite(G)):
            return None
        try:
            dz = np.linalg.solve(np.asarray(DG, float), G)
        except np.linalg.LinAlgError:
            return None
        z = z - dz
        if not np.all(np.isfinite(z)) or np.abs(z[:prob.n]).max() > MAX_COEFFICIENT:
            return None
        if np.linalg.norm(dz) < 1e-12 * (1 + np.linalg.norm(z)):
            return z
    return None


def _newton_mp(prob, z, tol, steps=30):
    """Newton on the Lagrange system in mpmath from a float64 root; ``None`` if the residual stays above ``tol * 1e6``.

    Newton converges quadratically from a float64 root (three steps from ``1e-16`` to ``1e-40``); once the residual
    stops decreasing it sits at the round-off level of the working precision and further steps only move ``z`` by
    round-off, so the loop stops there.
    """
    z = [mpmath.mpf(float(v)) for v in z]
    last = None
    for _ in range(steps):
        G, DG = prob.kkt(z, "mp")
        G = mpmath.matrix(G)
        norm = mpmath.norm(G)
        if norm < tol:
            return z
        if last is not None and norm >= last:
            break
        last = norm
        try:
            dz = mpmath.lu_solve(mpmath.matrix(DG), G)
        except ZeroDivisionError:
            return None
        z = [a - b for a, b in zip(z, dz)]
    else:
        G, _ = prob.kkt(z, "mp")
        norm = mpmath.norm(mpmath.matrix(G))
    return z if norm < tol * 10**6 else None


def _project(prob_F, prob_J, x, steps=80):
    """Gauss-Newton (minimum-norm steps, float) onto ``F = 0``; ``None`` if it does not converge."""
    for _ in range(steps):
        F = np.asarray(prob_F(*x), float)
        if not np.all(np.isfinite(F)):
            return None
        J = np.asarray(prob_J(*x), float)
        dx = np.linalg.lstsq(J, F, rcond=None)[0]
        x = x - dx
        if not np.all(np.isfinite(x)) or np.abs(x).max() > MAX_COEFFICIENT:
            return None
        if np.linalg.norm(dx) < 1e-12 * (1 + np.linalg.norm(x)):
            break
    F = np.asarray(prob_F(*x), float)
    return x if np.all(np.isfinite(F)) and np.linalg.norm(F) < 1e-9 else None


def _independent(J, tol=1e-8):
    """Indices of a maximal set of linearly independent rows of ``J`` (float), greedily."""
    rows, basis = [], []
    for i, row in enumerate(np.asarray(J, float)):
        v = row.copy()
        for b in basis:
            v = v - (v @ b) * b
        norm = np.linalg.norm(v)
        if norm > tol * max(1.0, np.linalg.norm(row)):
            basis.append(v / norm)
            rows.append(i)
    return rows


def optimize_composition(spec, parts: int | None = None, order: int = 4, stages: int | None = None, *,
                         dps: int = 30, starts: int = 40, seed: int = 0, max_denominator: int = 1000,
                         name: str | None = None, exact: bool = True) -> DesignedComposition:
    """The composition of a template with order ``>= order`` and the smallest error constant found.

    Parameters
    ----------
    spec : ``"strang"``, a palindromic base word, ``"word:WORD"`` or a :class:`Template`
    parts : int -- number of pieces (``"strang"``)
    order : int -- required order ``p``
    stages : int -- number of base steps of a ``"strang"`` / base-word template
    dps : int -- digits of the final Newton polish (mpmath), default 30
    starts : int -- seeded random starting points of the (float) search
    seed : int
    max_denominator : int -- the free unknowns of the exact form are rationals with at most this denominator
    name : str, optional -- name of the returned composition
    exact : bool -- look for an exact (real-radical) form first (default); ``False`` returns the
        ``dps``-digit rationals with their ``error_bound`` directly

    Returns
    -------
    DesignedComposition -- a :class:`Composition` (coefficients exact: rationals and real radicals,
    or, with ``exact=False``, ``dps``-digit rationals with ``error_bound``).

    Raises
    ------
    NoSolutionError -- no real solution was found; InvalidOrderError -- order too high or too many unknowns.

    Examples
    --------
    >>> C = optimize_composition("strang", parts=2, order=4, stages=3)     # the triple jump: unique
    >>> C.exact, C.order, round(C.lem, 4)
    (True, 4, 3.7163)
    """
    T = template(spec, parts, stages)
    if not is_int(order, 1):
        raise InvalidOrderError(f"order must be a positive integer, got {show(order)}")
    starts = check_int(starts, "starts", 1, MAX_STARTS)
    seed = check_int(seed, "seed", 0, 2**32 - 1)  # numpy's RandomState seeds
    max_denominator = check_int(max_denominator, "max_denominator", 1)
    exact = check_flag(exact, "exact")
    if name is not None:
        check_name(name, "name", strict=False)
    n = len(T.unknowns)
    if n > MAX_UNKNOWNS:
        raise InvalidOrderError(f"template {T.name!r} has {n} unknowns; the search accepts at most {MAX_UNKNOWNS}")
    if not is_int(dps, 15, 200):
        raise InvalidOrderError(f"dps must be an integer in 15..200, got {show(dps)}")
    conds = order_conditions(T, order)
    eqs = conds.polynomials
    degree = order + 1
    defects = defect_polynomials(T, degree)
    while not any(defects.values()):
        degree += 1
        defects = defect_polynomials(T, degree)
    x = list(T.unknowns)
    square = sum((p**2 for p in defects.values()), next(iter(defects.values())).ring.zero)   # sparse, exact
    objective = sympy.Poly.from_dict(dict(square), *x, domain=QQ)
    every = _Problem(objective, eqs, x)
    rng = np.random.RandomState(seed)
    selected, prob, found = None, None, []
    for _ in range(starts):
        p = _project(lambda *v: every.values("F", v, "float"), lambda *v: every.values("J", v, "float"),
                     rng.uniform(-1, 1, n))
        if p is None:
            continue
        if selected is None:
            selected = [eqs[i] for i in _independent(every.values("J", list(p), "float"))]
            prob = _Problem(objective, selected, x)
        J = np.asarray(prob.values("J", list(p), "float"), float)
        g = np.asarray(prob.values("g", list(p), "float"), float)
        lam = -np.linalg.lstsq(J.T, g, rcond=None)[0]
        z = _newton_float(prob, np.concatenate([p, lam]))
        if z is None or np.linalg.norm(np.asarray(every.values("F", list(z[:n]), "float"), float)) > 1e-8:
            continue
        if not any(np.abs(z[:n] - y[:n]).max() < 1e-7 for y in found):
            found.append(z)
    if not found:
        raise NoSolutionError(
            f"no real solution of the order-{order} conditions of template {T.name!r} was found from {starts} "
            "starting points; add stages or lower the order"
        )
    found.sort(key=lambda z: every.f.float(z[:n]))
    # 20 guard digits: the Lagrange residual loses ~12 digits to cancellation (Yoshida's order-6 template: its
    # floor is ~1e-28 at 40 digits, ~1e-38 at 50, with z right to ~38 digits in both), so at dps + 10 it never
    # reaches tol
    with mpmath.workdps(dps + 20):
        tol = mpmath.mpf(10) ** (-(dps + 5))
        best = None
        for z in found[:3]:
            zp = _newton_mp(prob, z, tol)
            if zp is not None:
                value = prob.f.mp(zp[:n])
                if best is None or value < best[1]:
                    best = (zp[:n], value)
        if best is None:
            raise NoSolutionError(f"the Newton polish of the order-{order} solutions of template {T.name!r} did not converge")
        best, fbest = best
        optimum = tuple((v, mpmath.nstr(b, dps)) for v, b in zip(x, best))
        lem_opt = float(mpmath.sqrt(fbest))
    final_order = degree - 1
    label = name or f"designed:{T.name}:p{final_order}"
    citation = (f"optimize_composition({T.name!r}, order={order}): smallest error constant among "
                f"{len(found)} critical points found")
    critical = _exact_critical_point(objective, selected, x, best, dps) if exact and len(selected) < n else None
    if critical is not None:
        optimum, radical = critical
        if radical:  # the minimiser itself in real radicals: it is the composition
            found_exact = _verified(T, [dict(optimum)], final_order, label, citation)
            if found_exact is not None:
                comp, values, lem = found_exact
                return DesignedComposition(comp.pieces, comp.coefficients, label, final_order, citation, T.name,
                                           values, optimum, lem, lem_opt, True, 0.0, True)
    found_exact = _exact_form(T, selected, x, best, final_order, max_denominator, label, citation) if exact else None
    if found_exact is not None:
        comp, values, lem = found_exact
        return DesignedComposition(comp.pieces, comp.coefficients, label, final_order, citation,
                                   T.name, values, optimum, lem, lem_opt, True, 0.0, len(selected) == n)
    return _rational_form(T, conds, x, best, final_order, dps, label, citation, optimum, lem_opt)


#: Largest Bezout number (product of the degrees) of the critical-point equations that are solved exactly.
MAX_CRITICAL_BEZOUT = 100
#: Largest degree of the minimal polynomial of an exact minimiser (beyond it the decimals stand).
MAX_CRITICAL_DEGREE = 40


def _exact_critical_point(objective, selected, x, best, dps):
    """The constrained minimiser near ``best`` as exact algebraic numbers: ``(optimum, radical)`` or ``None``.

    A critical point of ``f`` on ``{F = 0}`` (``F`` the ``r`` independent conditions, ``r < n``) solves ``F = 0``
    and the vanishing of every ``(r+1)``-minor of the Jacobian of ``(f, F)`` (``grad f`` in the row space of
    ``grad F``): polynomial equations over QQ.  Their lex Groebner basis in shape position,
    ``x_i - r_i(x_n)`` and ``q(x_n)``, gives the minimiser from the irreducible factor ``g`` of ``q`` with a real root
    at ``best``; which root is certified by its isolating interval (``CRootOf``).  Exactness is then checked in
    ``QQ[t]/(g)``: every condition and every minor reduces to zero at ``x_i = r_i(t)``.  ``radical`` is True when
    sympy writes that root in real radicals (``deg g <= 4``; the values are then radical expressions), else the
    values are polynomials in the ``CRootOf``.  ``None`` when the equations are too large
    (:data:`MAX_CRITICAL_BEZOUT`, :data:`MAX_CRITICAL_DEGREE`) or not in shape position.
    """
    n, r = len(x), len(selected)
    F = [sympy.Poly(e, *x) for e in selected]
    minor_degree = (objective.total_degree() - 1) + sum(P.total_degree() - 1 for P in F)
    if np.prod([P.total_degree() for P in F]) * minor_degree ** (n - r) > MAX_CRITICAL_BEZOUT:
        return None
    # the Jacobian and its minors in QQ[x] (sparse polynomial arithmetic): through sympy expressions, the
    # derivatives of the objective (a sum of squares of the defects) and the expanded determinants were
    # most of the cost of the exact step
    M = [[P.diff(v) for v in x] for P in [objective, *F]]
    minors = [_poly_det([[row[j] for j in cols] for row in M]) for cols in combinations(range(n), r + 1)]
    system = [P.as_expr() for P in F] + [m.as_expr() for m in minors if not m.is_zero]
    G = sympy.groebner(system, *x, order="grevlex")
    if G.exprs == [1] or not G.is_zero_dimensional or _quotient_dimension(G, MAX_CRITICAL_DEGREE) > MAX_CRITICAL_DEGREE:
        return None
    polys = list(G.fglm("lex").polys)
    last = x[-1]
    if len(polys) != n or polys[-1].free_symbols - {last}:
        return None
    t = sympy.Dummy("t")
    shape = {}
    for var, P in zip(x[:-1], polys[:-1]):
        P = sympy.Poly(P.as_expr(), var)
        if P.degree() != 1 or P.LC().free_symbols or P.as_expr().free_symbols - {var, last}:
            return None
        shape[var] = sympy.Poly(sympy.expand(-P.nth(0) / P.LC()).subs(last, t), t, domain=QQ)
    shape[last] = sympy.Poly(t, t, domain=QQ)
    target = [mpmath.mpf(b) for b in best]
    with mpmath.workdps(dps + 10):
        for g, _ in sympy.Poly(polys[-1].as_expr(), last).factor_list()[1]:
            g = sympy.Poly(g.as_expr().subs(last, t), t, domain=QQ)
            rem = {v: P.rem(g) for v, P in shape.items()}
            for root in g.real_roots():
                value = mpmath.mpf(str(root.evalf(dps + 10)))
                point = [mpmath.polyval([mpmath.mpf(c.p) / c.q for c in rem[v].all_coeffs()], value) for v in x]
                if max(abs(a - b) for a, b in zip(point, target)) > mpmath.mpf(10) ** (-(dps // 2)):
                    continue
                if not all(_vanishes_at(e, x, rem, g) for e in system):
                    return None
                return _algebraic_values(g, root, rem, x, t)
    return None


def _poly_det(rows):
    """The determinant of a small square matrix of :class:`sympy.Poly` (same generators), by Laplace expansion
    along the first row; exact, and no expression is built."""
    if len(rows) == 1:
        return rows[0][0]
    total = None
    for j, a in enumerate(rows[0]):
        if a.is_zero:
            continue
        term = a * _poly_det([row[:j] + row[j + 1:] for row in rows[1:]])
        term = -term if j % 2 else term
        total = term if total is None else total + term
    return total if total is not None else rows[0][0]


def _vanishes_at(e, x, rem, g) -> bool:
    """Exact certificate: ``e(r_1(t), ..., r_n(t)) = 0`` in ``QQ[t]/(g)``, every product reduced modulo ``g``."""
    powers = {v: [rem[v].one] for v in x}
    total = g.zero
    for monom, c in sympy.Poly(e, *x).terms():
        term = g.one * c
        for v, k in zip(x, monom):
            while len(powers[v]) <= k:
                powers[v].append((powers[v][-1] * rem[v]).rem(g))
            term = (term * powers[v][k]).rem(g)
        total += term
    return total.rem(g).is_zero


def _algebraic_values(g, root, rem, x, t):
    """``((unknown, value), ...)`` with ``t = root``: real radicals when sympy finds them, else in ``CRootOf``."""
    if g.degree() <= 4:
        for candidate in sympy.roots(g, t):
            if _is_real_radical(candidate) and abs(sympy.N(candidate - root, 50)) < sympy.Float(10) ** -40:
                return tuple((v, sympy.radsimp(sympy.expand(rem[v].as_expr().subs(t, candidate)))) for v in x), True
    # sum c_k root^k built term by term: the same expression as expanding ``rem[v](root)`` (an expanded
    # polynomial with one atom substituted), without expand's walk over the CRootOf powers
    return tuple((v, sympy.Add(*(c * root**k for (k,), c in rem[v].terms()))) for v in x), False


def _is_real_radical(v) -> bool:
    v = sympy.nsimplify(v) if v.is_Float else v
    if v.has(sympy.I) or v.has(sympy.RootOf) or v.has(sympy.Float):
        return False
    if not v.is_real:
        return False
    return all(a.exp.is_Rational for a in v.atoms(sympy.Pow))


def _quotient_dimension(G, limit):
    """``dim_k k[x]/I`` for a zero-dimensional grevlex Groebner basis ``G`` of ``I``, counted up to ``limit + 1``.

    The standard monomials (those divisible by no leading monomial) are a basis of the quotient (Cox, Little,
    O'Shea, *Ideals, Varieties, and Algorithms*, Sect. 5.3, Prop. 4); they lie in the box below the pure powers
    ``x_i^{a_i}`` that lead some element (Sect. 5.3, Thm. 6).
    """
    # the ordering object, not its name: a univariate basis is stored in python-flint's DMP, whose ``monoms``
    # reads ``order.alias`` and fails on the string
    leads = [P.monoms(order=grevlex)[0] for P in G.polys]
    n = len(G.gens)
    box = [min(m[i] for m in leads if all(e == 0 for j, e in enumerate(m) if j != i) and m[i] > 0) for i in range(n)]
    count = 0
    for mon in product(*(range(a) for a in box)):
        if not any(all(a >= b for a, b in zip(mon, m)) for m in leads):
            count += 1
            if count > limit:
                break
    return count


def _shape_solutions(system, rest, max_degree=4):
    """Real solutions of a zero-dimensional polynomial ``system`` in shape position, exactly, with their degree.

    A lex Groebner basis ``[x_1 - r_1(x_k), ..., x_{k-1} - r_{k-1}(x_k), q(x_k)]`` gives every solution
    from the real roots of the univariate ``q`` (``deg q <= max_degree``, roots in radicals).
    Returns ``(deg q, [{unknown: value}, ...])`` or ``None`` if the basis is not of that shape.
    """
    if not rest:
        return 0, [{}]
    # In shape position k[x]/I = k[x_k]/(q), so deg q is the dimension of the quotient ring: count it first from
    # a grevlex basis (much cheaper than lex; Yoshida's order-6 template: 0.4 s against 1.8 s, dimension 39) and
    # convert to lex by FGLM only when it can be <= max_degree (the reduced lex basis is unique).
    G = sympy.groebner(system, *rest, order="grevlex")
    if G.exprs == [1] or not G.is_zero_dimensional or _quotient_dimension(G, max_degree) > max_degree:
        return None
    G = G.fglm("lex")
    polys = list(G.polys)
    last = rest[-1]
    if len(polys) != len(rest) or polys[-1].free_symbols - {last}:
        return None
    q = sympy.Poly(polys[-1].as_expr(), last)
    if not 1 <= q.degree() <= max_degree:
        return None
    linear = {}
    for var, P in zip(rest[:-1], polys[:-1]):
        P = sympy.Poly(P.as_expr(), var)
        if P.degree() != 1 or P.LC().free_symbols or P.as_expr().free_symbols - {var, last}:
            return None
        linear[var] = sympy.expand(-P.nth(0) / P.LC())
    roots = sympy.roots(q, filter="R")
    if sum(roots.values()) == 0:
        return q.degree(), []
    sols = []
    for r in roots:
        sol = {last: sympy.radsimp(r)}
        sol.update({var: sympy.radsimp(sympy.expand(expr.subs(last, r))) for var, expr in linear.items()})
        sols.append(sol)
    return q.degree(), sols


def _exact_form(T, selected, x, best, order, max_denominator, label, citation):
    """The simplest verified exact composition near ``best`` (module docstring, step 5), or ``None``."""
    n, r = len(x), len(selected)
    candidates = []
    for free in combinations(range(n), n - r):
        subs = {x[i]: sympy.Rational(Fraction(str(mpmath.nstr(best[i], 40))).limit_denominator(max_denominator)) for i in free}
        rest = [x[i] for i in range(n) if i not in free]
        system = [sympy.expand(e.subs(subs)) for e in selected]
        found = _shape_solutions(system, rest)
        if found is None:
            continue
        degree, sols = found
        for sol in sols:
            values = dict(subs)
            values.update(sol)
            if len(values) != n or not all(_is_real_radical(values[v]) for v in x):
                continue
            if any(abs(sympy.N(values[x[i]], 30) - sympy.Float(str(best[i]), 30)) > 1e-4 for i in range(n)):
                continue
            candidates.append((degree, sum(sympy.count_ops(v) for v in values.values()), len(candidates), values))
    return _verified(T, [values for *_, values in sorted(candidates, key=lambda c: c[:3])], order, label, citation)


def _verified(T, candidates, order, label, citation):
    """The first of the exact ``candidates`` (``{unknown: value}``) whose Lyndon defects of length ``<= order`` all
    vanish exactly and whose order is exactly ``order``: ``(composition, values, LEM)``, or ``None``."""
    x = T.unknowns
    for values in candidates:
        try:
            comp = T.instantiate(values, label, order, citation)
        except NambuBCHError:
            continue
        field = _Exact(comp)
        if all(v == field.K.zero for q in range(1, order + 1) for v in field.defects(T.parts, q).values()):
            analysis = error_analysis(comp, T.parts)
            if analysis.order == order:
                return comp, tuple((v, values[v]) for v in x), analysis.value
    return None


def _rational_form(T, conds, x, best, order, dps, label, citation, optimum, lem_opt):
    values = {v: sympy.Rational(Fraction(mpmath.nstr(b, dps))) for v, b in zip(x, best)}
    linear = [sympy.Poly(e, *x) for w, e in conds.equations if len(w) == 1]
    if linear:
        # the degree-1 conditions solved exactly for their pivot unknowns, the other unknowns kept at the optimum:
        # x = particular + sum over the free unknowns f of x_f * (kernel vector of f)
        columns = [{r: QQ.from_sympy(P.coeff_monomial(v)) for r, P in enumerate(linear)} for v in x]
        rhs = {r: QQ.from_sympy(-P.coeff_monomial(1)) for r, P in enumerate(linear)}
        S = solve_affine(SparseMatrix.from_columns(columns, len(linear), QQ), [rhs], certificate=False)
        if S.consistent:
            free = [j for j in range(len(x)) if j not in S.pivots]
            sol = dict(S.particular[0])
            for f, vec in zip(free, S.kernel):
                for c, v in vec.items():
                    sol[c] = sol.get(c, QQ.zero) + QQ.from_sympy(values[x[f]]) * v
            values.update({x[p]: QQ.to_sympy(sol.get(p, QQ.zero)) for p in S.pivots})
    comp = T.instantiate(values, label, order, citation)
    field = _Exact(comp)
    bound = max((abs(float(field.K.to_sympy(v))) for q in range(1, order + 1)
                 for v in field.defects(T.parts, q).values()), default=0.0)
    designed = DesignedComposition(
        comp.pieces, comp.coefficients, label, order, citation + f"; {dps}-digit rationals, order conditions to {bound:.1e}",
        template=T.name, values=tuple((v, values[v]) for v in x), optimum=optimum, lem_optimum=lem_opt,
        exact=False, error_bound=bound,
    )
    analysis = error_analysis(designed, T.parts)  # defects below error_bound count as zero
    if analysis.order != order:
        raise NoSolutionError(
            f"the {dps}-digit rationals of the order-{order} solution of template {T.name!r} do not reach order {order} "
            f"within their error bound {bound:.1e}; raise dps"
        )
    return dataclasses.replace(designed, lem=analysis.value)
