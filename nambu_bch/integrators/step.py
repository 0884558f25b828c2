"""A numeric step ``x -> Phi_h(x)`` generated once from the exact sub-flows.

The sub-flows are lambdified one by one (never the composed expression, which
grows exponentially for exponential flows) and applied in word order.  This
is the plain numpy path; :mod:`nambu_bch.numeric` compiles the same sub-flows
with numba for long runs.
"""

from __future__ import annotations

import numpy as np
import sympy

from ..errors import InvalidSystemError
from .composition import composition_for
from .flows import TIME, exact_flow


def parameter_values(system, params=None) -> dict:
    """``{Symbol: float}`` for every parameter; missing ones default to 1 (``m = omega = 1``)."""
    from ..checks import finite_float, show
    from ..systems.spec import as_system

    system = as_system(system)
    if params is not None and not isinstance(params, dict):
        raise InvalidSystemError(f"params must be a dict such as {{'omega': 1.0}}, got {show(params)}")
    params = dict(params or {})
    names = {p.name: p for p in system.parameters}
    unknown = [k for k in params if str(k) not in names]
    if unknown:
        raise InvalidSystemError(
            f"unknown parameter(s) {unknown} for {system.name}; its parameters are {sorted(names) or 'none'}"
        )
    values = {names[str(k)]: v for k, v in params.items()}
    return {p: finite_float(values.get(p, 1.0), f"parameter {p.name}") for p in system.parameters}


def subflow_functions(splitting, comp, params=None):
    """``[(f, c), ...]`` with ``f(x1, ..., xN, t) -> new state`` (numpy), ``c`` the float coefficient."""
    comp = composition_for(comp, splitting)
    system = splitting.system
    values = parameter_values(system, params)
    out = []
    for k, c in comp.factors():
        exprs = [sympy.sympify(e, strict=True).subs(values) for e in exact_flow(splitting[k], system.coordinates).expressions]
        f = sympy.lambdify((*system.coordinates, TIME), exprs, modules="numpy")
        out.append((f, float(c)))
    return out


def step_function(splitting, comp, params=None):
    """``step(x, h) -> Phi_h(x)`` for a float array ``x`` of shape ``(N,)`` or ``(N, batch)``.

    Examples
    --------
    >>> from nambu_bch import model
    >>> step = step_function(model("ho").splitting, "121")
    >>> [round(float(v), 6) for v in step([1.0, 0.0], 0.1)]
    [0.995, -0.1]
    """
    flows = subflow_functions(splitting, comp, params)

    def step(x, h):
        state = [np.asarray(v, dtype=float) for v in x]
        for f, c in flows:
            state = [np.asarray(v, dtype=float) + 0.0 * state[0] for v in f(*state, c * h)]
        return np.array(state)

    return step
