"""Runge--Kutta steps in float64: Newton's method on the stage equations, to round-off.

The stages ``K_i = f(y + h sum_j a_ij K_j)`` are solved by Newton's method on the
``s N`` unknowns (the Jacobian of ``f`` lambdified once, no sympy per step), started
from ``K_i = f(y)`` and stopped when a correction no longer shrinks the residual
(round-off reached) or after :data:`MAX_NEWTON` iterations; the step is
``y + h sum_i b_i K_i``.  This is the plain, uncompiled reference the exact modified
equations (:mod:`nambu_bch.bseries`) are checked against.

:func:`iterate_runge_kutta` is the driver :func:`nambu_bch.numeric.iterate` hands a Runge--Kutta method to:
the same Newton iteration, generated once per system as a Python module
(:func:`~nambu_bch.numeric.codegen.runge_kutta_source`: the field and its Jacobian printed from the
validated exact field, then fixed loops with their own Gaussian elimination), compiled with numba
(machine code in the package's private, verified cache, :func:`nambu_bch.compiled.enable_private_cache`)
or run by the interpreter (``backend="numpy"``: the same source, the same operations in the same order).
Kahan's method on a quadratic field is linearly implicit, ``x' = x + h (I - h/2 f'(x))^{-1} f(x)``
(Celledoni, McLachlan, Owren, Quispel, J. Phys. A 46 (2013) 025201; equation number not checked, the equality
with the tableau is tested): one linear solve per step,
no Newton iteration.  The work of a run is reported as Newton iterations (``stats=``).
"""

from __future__ import annotations

import numpy as np
import sympy

from ..errors import InvalidRunError, NumericalRangeError, ResourceLimitError
from ..integrators.runge_kutta import TABLEAUX, butcher_tableau
from .guards import check_inputs

#: Newton iterations allowed per step before the step is refused.
MAX_NEWTON = 50


def rk_step_function(system, method, params=None):
    """``step(y, h) -> y1`` (float64 arrays of shape ``(N,)``) for the Runge--Kutta ``method`` on ``system``
    (a tableau, or a partitioned pair on a canonical system: coordinate ``k`` staged by its own tableau)."""
    from ..integrators.step import parameter_values
    from ..systems.spec import as_system

    system = as_system(system)
    tableau = _method(method)
    per_coordinate = _per_coordinate(system, tableau)
    values = parameter_values(system, params)
    f_exprs = [sympy.sympify(e, strict=True).subs(values) for e in system.vector_field.to_sympy()]
    coords = system.coordinates
    jac = sympy.Matrix(f_exprs).jacobian(coords)
    f_num = sympy.lambdify(coords, f_exprs, modules="numpy")
    j_num = sympy.lambdify(coords, jac, modules="numpy")
    A = np.array([[[float(a) for a in row] for row in t.A] for t in per_coordinate])  # (N, s, s)
    b = np.array([[float(x) for x in t.b] for t in per_coordinate])  # (N, s)
    n, s = b.shape

    def f(y):
        return np.asarray(f_num(*y), dtype=np.float64)

    def step(y, h):
        K = np.tile(f(y), (s, 1))
        best = np.inf
        for _ in range(MAX_NEWTON):
            Y = y + h * np.einsum("kij,jk->ik", A, K)
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
                for j in range(s):  # d f(Y_i) / d K_j: column c of J_i scaled by coordinate c's a_ij
                    J[i * n:(i + 1) * n, j * n:(j + 1) * n] -= h * Ji * A[:, i, j]
            try:
                K = K - np.linalg.solve(J, residual).reshape(s, n)
            except np.linalg.LinAlgError:
                raise NumericalRangeError(f"the stage equations of {tableau.name} are singular at h = {h}, "
                                          f"y = {y.tolist()}; lower h") from None
        else:
            raise NumericalRangeError(f"Newton's method for {tableau.name} did not settle in {MAX_NEWTON} iterations "
                                      f"at h = {h}, y = {y.tolist()}; lower h")
        return y + h * np.einsum("ki,ik->k", b, K)

    return step


def rk_iterate(system, method, h, steps, x0, params=None, every=1) -> np.ndarray:
    """``steps`` steps of the Runge--Kutta ``method``; the states at steps ``0, every, 2 every, ..`` (shape ``(samples, N)``)."""
    from ..integrators.step import parameter_values
    from ..systems.spec import as_system

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


#: Trajectory-steps up to which ``backend="auto"`` interprets rather than compiles (a cold numba compile of the
#: module costs seconds; the interpreter does a few thousand implicit steps per second).
INTERPRET_STEPS = 2000
#: Most trajectory-steps of one Runge--Kutta run (an implicit step costs 10-100 splitting steps; the interpreter
#: about 1e4 times more): refused up front above this, compiled or not.
MAX_RK_STEPS = 10**8
#: Residual accepted when Newton's iteration stagnates: ``tol * (1 + max|K|)`` (round-off is far below).
NEWTON_TOL = 1e-10
_MODULES: dict = {}


def is_linearly_implicit(tableau) -> bool:
    """Kahan's tableau (``TABLEAUX["kahan"]``, by its exact coefficients): stepped by one linear solve."""
    kahan = TABLEAUX["kahan"]
    return tableau.quadratic_only and tableau.A == kahan.A and tableau.b == kahan.b


#: The functions of the generated Runge--Kutta module, callees first.
_RK_FUNCTIONS = ("rk_field", "rk_jacobian", "rk_run_explicit", "rk_run_kahan", "rk_run_newton")
#: The entry point of each kind of step, its loops inline (numba compiles a function on its first call, with the
#: callees it reaches: an explicit run compiles the field and its own loop, never Newton's iteration or the solve).
_RK_ENTRIES = {"explicit": "rk_run_explicit", "kahan": "rk_run_kahan", "newton": "rk_run_newton"}


def _method(method):
    """The tableau or partitioned pair ``method`` names (:func:`~nambu_bch.integrators.runge_kutta.runge_kutta_method`)."""
    from ..integrators.runge_kutta import runge_kutta_method

    return runge_kutta_method(method) or butcher_tableau(method)  # the latter names what is accepted


def _per_coordinate(system, tableau) -> list:
    """The tableau of each coordinate: one for all, or a partitioned pair's ``q`` and ``p`` tableaux on a canonical
    system (refused on any other)."""
    from ..integrators.runge_kutta import PartitionedTableau

    if isinstance(tableau, PartitionedTableau):
        from ..bseries.modified import _canonical_half

        _canonical_half(system, tableau)
        return tableau.per_coordinate(system.N)
    return [tableau] * system.N


def _module(system, backend):
    """The generated Runge--Kutta module of ``system``: interpreted, or with its functions compiled by numba."""
    from ..systems.spec import as_system
    from .codegen import runge_kutta_source, source_hash
    from .kernels import _load_module, _write_file, cache_dir

    system = as_system(system)
    key = (system, backend)
    module = _MODULES.get(key)
    if module is not None:
        return module
    source = runge_kutta_source(system)
    directory = cache_dir()
    name = f"nambu_bch_rk_{source_hash(source)}"
    path = directory / f"{name}.py"
    try:  # numba keeps machine code next to a source file; the module itself runs from memory, never read back
        _write_file(path, source.encode("utf-8"))
    except OSError:
        pass
    module = _load_module(name, path, source, _RK_FUNCTIONS)
    if backend == "numba":
        import sys

        import numba

        from ..compiled import enable_private_cache

        sys.modules[name] = module  # numba's cache locates the functions through their module (not the numpy twin)

        # callees first: the compiled callers find them as globals of the module; each is compiled on its first call
        for fn in _RK_FUNCTIONS:
            jitted = numba.njit(nogil=True, error_model="numpy")(module.__dict__[fn])
            if path.is_file():
                enable_private_cache(jitted, directory / "__pycache__")
            module.__dict__[fn] = jitted
    _MODULES[key] = module
    return module


def _compiled(system, entry) -> bool:
    """Whether this process has compiled (or loaded from numba's cache) the entry point ``entry`` for ``system``."""
    module = _MODULES.get((system, "numba"))
    return module is not None and bool(getattr(module, entry).signatures)


def iterate_runge_kutta(system, method, h, steps, x0=None, params=None, every=1, *, kahan=False, backend="auto",
                        out=None, max_newton=MAX_NEWTON, compensation=None, stats=None):
    """``steps`` steps of the Runge--Kutta ``method`` (implicit ones by Newton's method), sampled like
    :func:`nambu_bch.numeric.iterate` (shape ``(n_samples, N)`` or ``(n_samples, N, batch)``).

    Parameters
    ----------
    system, h, steps, x0, params, every, out : as for :func:`~nambu_bch.numeric.iterate`
    method : a name of :data:`~nambu_bch.integrators.runge_kutta.TABLEAUX` or a ButcherTableau; or a partitioned
        pair (:data:`~nambu_bch.integrators.runge_kutta.PARTITIONED`) on a canonical system: the stages of the ``q``
        coordinates use its first tableau, those of ``p`` its second, in the same Newton iteration (HLW Sect. II.2)
    kahan : bool -- compensated summation of the increments
    backend : ``"auto"`` | ``"numba"`` | ``"numpy"`` -- compiled, or the same generated source interpreted (the same
        bits); ``"auto"``: compiled, except runs of at most :data:`INTERPRET_STEPS` trajectory-steps before the
        entry point of the method's kind of step (explicit, Kahan's, Newton's) is compiled in this process
    max_newton : int -- Newton iterations allowed per step
    compensation : float64 array of shape (N,), optional -- the compensated summation's carry, updated in place
        (a run continued block by block: :func:`nambu_bch.numeric.iterate_chunks`); one trajectory only
    stats : dict, optional -- receives the run's work: ``method``, ``steps`` (trajectory-steps),
        ``newton_iterations`` and ``linear_solves`` (Kahan's method; None otherwise), the cost measure of
        :func:`nambu_bch.design.compare`

    Raises
    ------
    NumericalRangeError -- Newton's method did not converge, or its matrix was singular, at step ``k`` (the
        message names ``h`` and ``k``; lower ``h``), or the state left the float64 range.
    ResourceLimitError -- more than :data:`MAX_RK_STEPS` trajectory-steps, before any work

    References
    ----------
    Hairer, Norsett, Wanner, *Solving ODEs I*, Sect. II.7; Hairer, Wanner, *Solving ODEs II*, Sect. IV.8
    (Newton's method for the stage equations).
    """
    from ..checks import check_flag
    from ..systems.spec import as_system
    from .guards import check_backend, check_count, initial_state, run_label, sample_array
    from .kernels import resolve_backend
    from .samples import n_samples

    if stats is not None and not isinstance(stats, dict):
        raise InvalidRunError(f"stats must be a dict to receive the run's work, got {type(stats).__name__}")
    system = as_system(system)
    tableau = _method(method)
    per_coordinate = _per_coordinate(system, tableau)
    x0, origin = initial_state(system, x0)
    kahan = check_flag(kahan, "kahan")
    auto = check_backend(backend) == "auto"
    backend = resolve_backend(backend)
    max_newton = check_count(max_newton, "max_newton", 1)
    h, steps, every, X, values = check_inputs(system, h, steps, every, x0, params)
    h = float(h)
    work = steps * (1 if X.ndim == 1 else X.shape[1])
    if work > MAX_RK_STEPS:
        raise ResourceLimitError(f"{work} trajectory-steps of {tableau.name} are more than the {MAX_RK_STEPS:.0e} one "
                                 "Runge-Kutta run accepts; split the run or take a larger h")
    linear = is_linearly_implicit(tableau)
    if linear:
        from ..bseries.modified import _polynomial_field

        _polynomial_field(system, tableau)  # Kahan's formula is the method only on quadratic fields: refuse others
    entry = _RK_ENTRIES["kahan" if linear else "explicit" if tableau.is_explicit else "newton"]
    if backend == "numba" and auto and work <= INTERPRET_STEPS and not _compiled(system, entry):
        backend = "numpy"  # compiling costs seconds; a short run is done sooner by the interpreter (the same bits)
    run = getattr(_module(system, backend), entry)
    P = np.array([float(values[p]) for p in system.parameters], dtype=np.float64)
    A = np.array([[[float(a) for a in row] for row in t.A] for t in per_coordinate], dtype=np.float64)
    b = np.array([[float(x) for x in t.b] for t in per_coordinate], dtype=np.float64)
    single = X.ndim == 1
    batch = 1 if single else X.shape[1]
    count = n_samples(steps, every)
    shape = (count, system.N) if single else (count, system.N, batch)
    out = sample_array(out, shape, x0, X)
    columns = [X] if single else [np.ascontiguousarray(X[:, k]) for k in range(batch)]
    what = run_label(system, tableau.name, h, X, origin)
    total = 0
    for k, x in enumerate(columns):
        samples = np.empty((count, system.N))
        samples[0] = x
        c = compensation if compensation is not None and single else np.zeros(system.N)
        info = np.zeros(3, dtype=np.int64)
        with np.errstate(all="ignore"):
            try:
                done = run(x, c, kahan, h, P, A, b, steps, every, samples, max_newton, NEWTON_TOL, info)
            except (OverflowError, ValueError, ZeroDivisionError):  # the interpreter's math.sin(inf), math.exp(1e3),
                # 1/0 raise where the compiled loop gets nan or inf and stops at the step (reported below)
                raise NumericalRangeError(f"{tableau.name} on {what}: the state left the float64 range (h = {h:g}); "
                                          "lower h") from None
        total += int(info[0])
        if done < steps:
            why = {1: "the Newton matrix is singular", 2: f"Newton's method did not converge in {max_newton} iterations",
                   3: "the state left the float64 range"}[int(info[1])]
            raise NumericalRangeError(f"{tableau.name} on {what}: {why} at step {int(info[2])} (h = {h:g}); lower h")
        if single:
            out[...] = samples
        else:
            out[:, :, k] = samples
    if stats is not None:
        stats.update({"method": tableau.name, "steps": steps * batch, "newton_iterations": total,
                      "linear_solves": total if linear else None})
    return out
