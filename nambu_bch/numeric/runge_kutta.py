"""Runge--Kutta steps in float64: Newton's method on the stage equations, to round-off.

The stages ``K_i = f(y + h sum_j a_ij K_j)`` are solved by Newton's method on the
``s N`` unknowns (the Jacobian of ``f`` lambdified once, no sympy per step), started
from ``K_i = f(y)`` and stopped when a correction no longer shrinks the residual
(round-off reached) or after :data:`MAX_NEWTON` iterations; the step is
``y + h sum_i b_i K_i``.  This is the plain, uncompiled reference the exact modified
equations (:mod:`nambu_bch.bseries`) are checked against.
"""

from __future__ import annotations

import numpy as np
import sympy

from ..errors import InvalidRunError, NumericalRangeError
from ..integrators.runge_kutta import butcher_tableau
from .guards import check_inputs

#: Newton iterations allowed per step before the step is refused.
MAX_NEWTON = 50


def rk_step_function(system, method, params=None):
    """``step(y, h) -> y1`` (float64 arrays of shape ``(N,)``) for the Runge--Kutta ``method`` on ``system``."""
    from ..integrators.step import parameter_values
    from ..systems.system import as_system

    system = as_system(system)
    tableau = butcher_tableau(method)
    values = parameter_values(system, params)
    f_exprs = [sympy.sympify(e, strict=True).subs(values) for e in system.vector_field.to_sympy()]
    coords = system.coordinates
    jac = sympy.Matrix(f_exprs).jacobian(coords)
    f_num = sympy.lambdify(coords, f_exprs, modules="numpy")
    j_num = sympy.lambdify(coords, jac, modules="numpy")
    A = np.array([[float(a) for a in row] for row in tableau.A])
    b = np.array([float(x) for x in tableau.b])
    s, n = len(b), system.N

    def f(y):
        return np.asarray(f_num(*y), dtype=np.float64)

    def step(y, h):
        K = np.tile(f(y), (s, 1))
        best = np.inf
        for _ in range(MAX_NEWTON):
            Y = y + h * (A @ K)
            F = np.array([f(Yi) for Yi in Y])
            residual = (K - F).ravel()
            size = np.max(np.abs(residual))
            if not size < best:  # no longer shrinking: round-off reached
                break
            best = size
            if size == 0:
                break
            J = np.eye(s * n)
            for i in range(s):
                Ji = np.asarray(j_num(*Y[i]), dtype=np.float64)
                for j in range(s):
                    J[i * n:(i + 1) * n, j * n:(j + 1) * n] -= h * A[i, j] * Ji
            try:
                K = K - np.linalg.solve(J, residual).reshape(s, n)
            except np.linalg.LinAlgError:
                raise NumericalRangeError(f"the stage equations of {tableau.name} are singular at h = {h}, "
                                          f"y = {y.tolist()}; lower h") from None
        else:
            raise NumericalRangeError(f"Newton's method for {tableau.name} did not settle in {MAX_NEWTON} iterations "
                                      f"at h = {h}, y = {y.tolist()}; lower h")
        return y + h * (b @ K)

    return step


def rk_iterate(system, method, h, steps, x0, params=None, every=1) -> np.ndarray:
    """``steps`` steps of the Runge--Kutta ``method``; the states at steps ``0, every, 2 every, ..`` (shape ``(samples, N)``)."""
    from ..integrators.step import parameter_values
    from ..systems.system import as_system

    system = as_system(system)
    parameter_values(system, params)  # first: its message shows a wrong params value on one line
    h, steps, every, y, values = check_inputs(system, h, steps, every, x0, params)
    if y.ndim != 1:
        raise InvalidRunError(f"x0 must have shape ({system.N},) for a Runge-Kutta run, got {y.shape}")
    step = rk_step_function(system, method, {p.name: v for p, v in values.items()})
    out = [y.copy()]
    for k in range(1, steps + 1):
        with np.errstate(all="ignore"):
            y = step(y, h)
        if not np.all(np.isfinite(y)):
            raise NumericalRangeError(f"{method} left the float64 range at step {k} (h = {h}); lower h")
        if k % every == 0:
            out.append(y.copy())
    return np.array(out)
