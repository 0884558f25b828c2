"""Design: solve a template's order conditions and keep the solution with the smallest error constant.

Algorithm
---------
1. The order conditions ``F(x) = 0`` of the template (:func:`order_conditions`, exact
   polynomials) and the objective ``f(x) = LEM(x)^2``, the sum of squares of the degree
   ``p + 1`` log defects (``p`` the requested order, raised past degrees whose defects
   vanish identically, e.g. the even ones of symmetric templates).
2. A maximal independent subset of ``F`` (numerical rank of the Jacobian at a solution).
3. The critical points of ``f`` on ``{F = 0}``: Newton's method on the Lagrange system
   ``grad f + J^T lambda = 0, F = 0`` in mpmath (``dps`` digits, default 30) from many
   seeded starting points (each first projected onto ``{F = 0}`` by Gauss-Newton);
   converged real points are de-duplicated and the smallest ``f`` wins.  With as many
   independent conditions as unknowns this is the plain solve, polished by Newton.
4. An exact form: the ``n - r`` unknowns left free by the conditions are fixed to nearby
   rationals (each choice of free unknowns is tried), the remaining conditions are solved
   with ``sympy.solve``; a solution counts only if it is real and written in real radicals,
   and it is then *verified exactly* (every log defect of length ``<= p`` is zero in the
   algebraic field of the coefficients).  The exact composition nearest in error constant
   to the numerical optimum is returned.
5. If no such exact form exists, the coefficients are the ``dps``-digit optimum as
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

from dataclasses import dataclass
from fractions import Fraction
from itertools import combinations

import mpmath
import numpy as np
import sympy

from ..errors import InvalidOrderError, NambuBCHError
from ..integrators.composition import Composition
from .conditions import _Exact, error_analysis, order_conditions, symbolic_defects, template

#: Largest number of unknowns accepted by :func:`optimize_composition`.
MAX_UNKNOWNS = 8


class NoSolutionError(NambuBCHError):
    """A template whose order conditions have no real solution (found by the search)."""


@dataclass(frozen=True)
class DesignedComposition(Composition):
    """A :class:`Composition` found by :func:`optimize_composition`, usable wherever a word is.

    Extra attributes
    ----------------
    template : str            -- the template's name
    values : tuple            -- ``(unknown, exact value)`` pairs
    optimum : tuple           -- ``(unknown, dps-digit value)`` of the true constrained optimum
    lem : float               -- the error constant of *this* composition (exact, as float)
    lem_optimum : float       -- the error constant at the numerical optimum
    exact : bool              -- True: order conditions hold exactly; False: see ``error_bound``
    error_bound : float       -- largest absolute Lyndon defect of length <= order (0 when exact)
    """

    template: str = ""
    values: tuple = ()
    optimum: tuple = ()
    lem: float = float("nan")
    lem_optimum: float = float("nan")
    exact: bool = True
    error_bound: float = 0.0

    def summary(self) -> dict:
        return {
            "name": self.name, "template": self.template, "order": self.order, "exact": self.exact,
            "error_bound": self.error_bound, "error_constant": self.lem, "error_constant_optimum": self.lem_optimum,
            "values": {str(k): str(v) for k, v in self.values},
            "optimum": {str(k): str(v) for k, v in self.optimum},
        }


def _lambdify(exprs, args):
    return sympy.lambdify(args, exprs, modules="mpmath")


def _independent(jac, tol):
    """Indices of a maximal set of linearly independent rows of ``jac`` (mpmath matrix), greedily."""
    rows = []
    basis = []
    for i in range(jac.rows):
        v = [jac[i, j] for j in range(jac.cols)]
        for b in basis:
            d = mpmath.fsum(x * y for x, y in zip(v, b))
            v = [x - d * y for x, y in zip(v, b)]
        norm = mpmath.sqrt(mpmath.fsum(x * x for x in v))
        if norm > tol:
            basis.append([x / norm for x in v])
            rows.append(i)
    return rows


def _solve_linear(A, b):
    return mpmath.lu_solve(A, b)


def _project(F, J, x, steps=60, tol=None):
    """Gauss-Newton (minimum-norm steps) onto ``F = 0``; ``None`` if it does not converge."""
    for _ in range(steps):
        Fx = mpmath.matrix(F(*x))
        if mpmath.norm(Fx) < tol:
            return x
        Jx = mpmath.matrix(J(*x))
        try:
            y = _solve_linear(Jx * Jx.T, Fx)
        except ZeroDivisionError:
            return None
        dx = Jx.T * y
        x = [xi - dxi for xi, dxi in zip(x, dx)]
        if any(abs(v) > 1e6 for v in x):
            return None
    return x if mpmath.norm(mpmath.matrix(F(*x))) < tol else None


def optimize_composition(spec, parts: int | None = None, order: int = 4, stages: int | None = None, *,
                         dps: int = 30, starts: int = 40, seed: int = 0, max_denominator: int = 1000,
                         name: str | None = None) -> DesignedComposition:
    """The composition of a template with order ``>= order`` and the smallest error constant found.

    Parameters
    ----------
    spec : ``"strang"``, a palindromic base word, ``"word:WORD"`` or a :class:`Template`
    parts : int -- number of pieces (``"strang"``)
    order : int -- required order ``p``
    stages : int -- number of base steps of a ``"strang"`` / base-word template
    dps : int -- digits of the numerical search (mpmath), default 30
    starts : int -- seeded random starting points of the search
    seed : int
    max_denominator : int -- the free unknowns of the exact form are rationals with at most this denominator
    name : str, optional -- name of the returned composition

    Returns
    -------
    DesignedComposition -- a :class:`Composition` (coefficients exact: rationals and real radicals,
    or, with ``exact=False``, ``dps``-digit rationals with ``error_bound``).

    Raises
    ------
    NoSolutionError -- no real solution was found; InvalidOrderError -- order too high.

    Examples
    --------
    >>> C = optimize_composition("strang", parts=2, order=4, stages=3)     # the triple jump: unique
    >>> C.exact, C.order, round(C.lem, 4)
    (True, 4, 3.7163)
    """
    T = template(spec, parts, stages)
    if isinstance(order, bool) or not isinstance(order, int) or order < 1:
        raise InvalidOrderError(f"order must be a positive integer, got {order!r}")
    n = len(T.unknowns)
    if n > MAX_UNKNOWNS:
        raise InvalidOrderError(f"template {T.name!r} has {n} unknowns; the search accepts at most {MAX_UNKNOWNS}")
    conds = order_conditions(T, order)
    eqs = conds.polynomials
    degree = order + 1
    defects = symbolic_defects(T, degree)
    while all(sympy.expand(e) == 0 for e in defects.values()):
        degree += 1
        defects = symbolic_defects(T, degree)
    objective = sympy.expand(sum(e**2 for e in defects.values()))
    x = list(T.unknowns)
    with mpmath.workdps(dps + 10):
        tol = mpmath.mpf(10) ** (-(dps + 5))
        F_all = _lambdify(eqs, x)
        J_all = _lambdify([[sympy.diff(e, v) for v in x] for e in eqs], x)
        rng = np.random.RandomState(seed)
        found = []
        selected = None
        for _ in range(starts):
            x0 = [mpmath.mpf(float(v)) for v in rng.uniform(-1, 1, n)]
            p = _project(F_all if selected is None else F_sel, J_all if selected is None else J_sel, x0, tol=tol)
            if p is None:
                continue
            if selected is None:
                rows = _independent(mpmath.matrix(J_all(*p)), mpmath.mpf(10) ** (-dps // 2))
                selected = [eqs[i] for i in rows]
                lams = [sympy.Symbol(f"_lambda{i}") for i in range(len(selected))]
                F_sel = _lambdify(selected, x)
                J_sel = _lambdify([[sympy.diff(e, v) for v in x] for e in selected], x)
                L = objective + sum(l * e for l, e in zip(lams, selected))
                z = x + lams
                G = _lambdify([sympy.diff(L, v) for v in z], z)
                DG = _lambdify([[sympy.diff(L, a, b) for b in z] for a in z], z)
                grad = _lambdify([sympy.diff(objective, v) for v in x], x)
            Jp = mpmath.matrix(J_sel(*p))
            try:
                lam = -_solve_linear(Jp * Jp.T, Jp * mpmath.matrix(grad(*p)))
            except ZeroDivisionError:
                continue
            zk = list(p) + list(lam)
            ok = False
            for _ in range(80):
                Gz = mpmath.matrix(G(*zk))
                if mpmath.norm(Gz) < tol * 10**3:
                    ok = True
                    break
                try:
                    dz = _solve_linear(mpmath.matrix(DG(*zk)), Gz)
                except ZeroDivisionError:
                    break
                zk = [a - b for a, b in zip(zk, dz)]
                if any(abs(v) > 1e6 for v in zk):
                    break
            if not ok:
                continue
            xs = zk[:n]
            if mpmath.norm(mpmath.matrix(F_all(*xs))) > tol * 10**3:
                continue
            if not any(max(abs(a - b) for a, b in zip(xs, y)) < mpmath.mpf(10) ** (-dps // 2) for y, _ in found):
                found.append((xs, objective.subs(dict(zip(x, [sympy.Float(str(v), dps + 5) for v in xs])))))
        if not found:
            raise NoSolutionError(
                f"no real solution of the order-{order} conditions of template {T.name!r} was found from {starts} "
                "starting points; add stages or lower the order"
            )
        best, fbest = min(found, key=lambda item: item[1])
        optimum = tuple((v, mpmath.nstr(b, dps)) for v, b in zip(x, best))
        lem_opt = float(sympy.sqrt(fbest))
        final_order = degree - 1
        label = name or f"designed:{T.name}:p{final_order}"
        citation = f"optimize_composition({T.name!r}, order={order}): smallest error constant found ({len(found)} critical points)"
        exact = _exact_form(T, eqs, selected, x, best, final_order, lem_opt, max_denominator, label, citation)
        if exact is not None:
            comp, values, lem = exact
            return DesignedComposition(comp.pieces, comp.coefficients, label, final_order, citation,
                                       T.name, values, optimum, lem, lem_opt, True, 0.0)
        return _rational_form(T, conds, x, best, final_order, dps, label, citation, optimum, lem_opt)


def _is_real_radical(v) -> bool:
    v = sympy.nsimplify(v) if v.is_Float else v
    if v.has(sympy.I) or v.has(sympy.RootOf) or v.has(sympy.Float):
        return False
    if not v.is_real:
        return False
    return all(a.exp.is_Rational for a in v.atoms(sympy.Pow))


def _exact_form(T, eqs, selected, x, best, order, lem_opt, max_denominator, label, citation):
    """The simplest verified exact composition near ``best`` (module docstring, step 4), or ``None``."""
    n, r = len(x), len(selected)
    candidates = []
    for free in combinations(range(n), n - r):
        subs = {x[i]: sympy.Rational(Fraction(str(mpmath.nstr(best[i], 40))).limit_denominator(max_denominator)) for i in free}
        rest = [x[i] for i in range(n) if i not in free]
        system = [sympy.expand(e.subs(subs)) for e in selected]
        try:
            sols = sympy.solve(system, rest, dict=True) if rest else [{}]
        except (NotImplementedError, ValueError):
            continue
        for sol in sols:
            values = dict(subs)
            values.update({k: sympy.radsimp(v) for k, v in sol.items()})
            if len(values) != n or not all(_is_real_radical(values[v]) for v in x):
                continue
            if any(abs(sympy.N(values[x[i]], 30) - sympy.Float(str(best[i]), 30)) > 1e-4 for i in range(n)):
                continue
            candidates.append((sum(sympy.count_ops(v) for v in values.values()), len(candidates), values))
    for _, _, values in sorted(candidates, key=lambda c: c[:2]):
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
    linear = [e for w, e in conds.equations if len(w) == 1]
    if linear:
        basis = sympy.Matrix([[sympy.diff(e, v) for v in x] for e in linear])
        pivots = basis.rref()[1]
        solve_for = [x[i] for i in pivots]
        fixed = {v: values[v] for v in x if v not in solve_for}
        sol = sympy.solve([e.subs(fixed) for e in linear], solve_for, dict=True)
        if sol:
            values.update(sol[0])
    comp = T.instantiate(values, label, order, citation)
    field = _Exact(comp)
    bound = max((abs(float(field.K.to_sympy(v))) for q in range(1, order + 1)
                 for v in field.defects(T.parts, q).values()), default=0.0)
    lem = error_analysis(comp, T.parts)
    return DesignedComposition(comp.pieces, comp.coefficients, label, order, citation + f"; {dps}-digit rationals",
                               T.name, tuple((v, values[v]) for v in x), optimum, lem.value if lem.order == order else lem_opt,
                               False, bound)
