"""Splitting methods with complex coefficients, run in complex arithmetic (complex128).

A composition ``Phi_h = exp(c_1 h X_{k_1}) ... exp(c_s h X_{k_s})`` with some ``c_j`` not real
(``1:1/4+I/4,2:1/2+I/2,...``, the complex triple jump) is a map of ``C^N``: each factor is the exact
sub-flow of its piece continued analytically to the complex time ``c_j h``.  That continuation is
unique only where the sub-flow is an entire function of the state and the time -- polynomials, ``exp``,
``sin``, ``cos`` (shears, the exponentials of Lotka--Volterra, the rotations of the rigid body) -- so a
sub-flow with a branch cut or a pole (``sqrt``, ``log``, a quotient) is refused in one line.

Two runs are offered (Blanes, Casas & Murua 2010, Sect. 4; Castella et al. 2009):

* ``project=False``: the complex map itself, ``x_{n+1} = Phi_h(x_n)`` in ``C^N`` from a real ``x_0``.
  By backward error analysis it is the time-``h`` flow of the complex modified field ``X_eff``
  (:func:`nambu_bch.bch.effective_field`, now over ``QQ(i)``), so the complex shadow pair
  ``H_S, G_S`` of :func:`nambu_bch.shadow_hamiltonians` is what it conserves;
* ``project=True``: the real projection ``x_{n+1} = Re Phi_h(x_n)``, the real method a user of a
  complex-coefficient scheme for a real problem runs; its order is that of ``Phi_h``, but it is no
  longer a composition of real flows, so no real shadow pair is conserved: what holds is measured by
  :func:`~nambu_bch.numeric.diagnostics.complex_check` and reported in docs/integrators.md.

Two implementations of the step (``backend=``):

* the reference (``"numpy"``): the sub-flows lambdified one by one with the parameters substituted (as the exact
  rationals their float values are, so the parameter factors are rounded once), run on ``cmath`` for one
  trajectory and on numpy arrays for a batch;
* the compiled loop (``"numba"``, :mod:`~nambu_bch.numeric.complex_codegen`): the same exact sub-flows generated
  as straight-line complex128 source, compiled by numba and cached on disk like the float64 kernels; one
  trajectory gets the reference's bits (where the parameter factors round alike in float64, as the defaults do);
* ``"auto"``: the compiled loop, except short runs whose loop is not compiled yet, which step each state on
  ``cmath`` (:data:`INTERPRET_FACTOR_STEPS`).

References
----------
S. Blanes, F. Casas, A. Murua, *Splitting methods with complex coefficients*, SeMA J. 50 (2010) 47--61
(arXiv:1001.1549), Sects. 2 and 4 (complex compositions, the real part taken at every step);
F. Castella, P. Chartier, S. Descombes, G. Vilmart, BIT 49 (2009) 487 (complex compositions with
positive real parts); E. Hansen, A. Ostermann, BIT 49 (2009) 527 (the complex triple jump);
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.1 (modified equations).
"""

from __future__ import annotations

import cmath

import numpy as np
import sympy

from ..checks import check_flag
from ..errors import NumericalRangeError, ResourceLimitError
from ..integrators.composition import composition_for
from ..integrators.flows import TIME, exact_flow
from ..integrators.step import parameter_values
from .guards import MAX_SAMPLE_BYTES, check_backend, check_count, check_inputs, check_work, initial_state, run_label
from .complex_flows import ENTIRE, check_entire, coefficient_value
from .kernels import resolve_backend
from .samples import sample_steps

#: The entire functions by name for one trajectory's scalar step.
_CMATH = {f.__name__: getattr(cmath, f.__name__) for f in ENTIRE}


def complex_subflows(system, word, params=None) -> list:
    """``[(f_scalar, f_array, c), ...]`` per factor of ``word``: the sub-flow ``f(x_1, .., x_N, t)`` lambdified for
    ``cmath`` and for numpy, ``c`` the complex coefficient; refused in one line when a sub-flow is not entire."""
    comp = composition_for(word, system.splitting)
    # each value as the exact rational it is: sympy folds the parameter factors exactly and lambdify prints the
    # result as a quotient of integers, which Python rounds once (a Float would be printed to 15 digits)
    values = {p: sympy.Rational(v) for p, v in parameter_values(system, params).items()}
    flows = {}
    for k in sorted(set(comp.pieces)):
        exprs = [sympy.sympify(e, strict=True).xreplace(values) for e in exact_flow(system.splitting[k], system.coordinates).expressions]
        check_entire(system, comp, k, exprs)
        args = (*system.coordinates, TIME)
        # cmath's functions by name (sympy's "cmath" printer recurses on Float constants)
        flows[k] = (sympy.lambdify(args, exprs, modules=[_CMATH]), sympy.lambdify(args, exprs, modules="numpy"))
    return [(*flows[k], coefficient_value(comp, c)) for k, c in comp.factors()]


#: ``backend="auto"`` interprets a run while its compiled loop is not in this process and the run is small: at most
#: this many factor-steps (steps x sub-flows of the step x states).  The interpreter takes ~8 us a factor-step
#: (cmath, ho3), so this costs at most ~0.2 s, less than compiling the loop (1-4 s, of which importing numba
#: 0.3-0.5 s).  The interpreter then steps one state at a time (each column of a batch alone): the compiled bits.
INTERPRET_FACTOR_STEPS = 25_000


def iterate_complex(system, word, h, steps, x0=None, params=None, every=1, *, project=False,
                    backend="auto") -> np.ndarray:
    """Iterate ``Phi_h`` of a composition with complex coefficients in complex128; the samples every ``every`` steps.

    Parameters
    ----------
    system : System or model name; word : a composition (complex coefficients, e.g. ``"1:1/4+I/4,2:1/2+I/2,..."``)
    h : float -- the (real) step; steps : int >= 0; every : int >= 1
    x0 : real array of shape (N,) or (N, batch); None: the model's default initial state
    params : dict, optional -- parameter values (missing ones are 1)
    project : bool -- take the real part after every step (``x_{n+1} = Re Phi_h(x_n)``, a real method of the
        same order); False: the complex map itself
    backend : ``"auto"`` | ``"numba"`` | ``"numpy"`` -- ``"numba"``: the step compiled
        (:class:`~nambu_bch.numeric.complex_codegen.ComplexKernel`, cached on disk); ``"numpy"``: the sub-flows
        lambdified, ``cmath`` for one state, numpy arrays for a batch (the reference); ``"auto"``: compiled, except
        runs of at most :data:`INTERPRET_FACTOR_STEPS` whose loop is not compiled in this process yet, which
        step each state on ``cmath``.  One state gets the same bits on every backend (where the parameter factors
        are exact, e.g. the defaults; else within a few ulps a step); numpy's complex product on arrays is
        fused, so a batch on ``"numpy"`` differs from the others by rounding.

    Returns
    -------
    numpy.ndarray -- complex128 of shape ``(n_samples, N)`` or ``(n_samples, N, batch)`` (float64 with
    ``project=True``), samples at :func:`~nambu_bch.numeric.samples.sample_steps`, ``samples[0] == x0``.

    Raises
    ------
    InvalidRunError -- bad arguments, or a sub-flow that is not entire (``sqrt``, ``log``, a quotient)
    NumericalRangeError -- a non-finite state (the complex orbit left the range of complex128)

    Examples
    --------
    >>> x = iterate_complex("ho", "1:1/4+I/4,2:1/2+I/2,1:1/2,2:1/2-I/2,1:1/4-I/4", 0.1, 10, [1.0, 0.0])
    >>> x.dtype, x.shape, bool(abs(x[-1].imag).max() > 0)
    (dtype('complex128'), (11, 2), True)
    """
    from ..systems.spec import as_system

    system = as_system(system)
    project = check_flag(project, "project")
    chosen = resolve_backend(check_backend(backend))
    x0, origin = initial_state(system, x0)
    check_work(check_count(steps, "steps", 0), x0)
    h, steps, every, X, _ = check_inputs(system, h, steps, every, x0, params)
    h = float(h)
    comp = composition_for(word, system.splitting)
    what = run_label(system, comp.name, h, X, origin)
    grid = sample_steps(steps, every)
    if len(grid) * X.size * 16 > MAX_SAMPLE_BYTES:
        raise ResourceLimitError(f"{len(grid)} complex samples of {X.size} values need more than "
                                 f"{MAX_SAMPLE_BYTES / 2**30:.0f} GiB; sample less often (larger every)")
    if backend == "auto" and chosen == "numba" and not _worth_compiling(system, comp, steps, X):
        chosen = "interpreter"
    if chosen == "numba":
        out, done = _compiled(system, comp, h, params, X, steps, every, len(grid), project)
    else:
        out, done = _interpreted(complex_subflows(system, comp, params), h, X, steps, grid, project,
                                 vector=chosen == "numpy")
    if done < steps:
        j = int(np.searchsorted(grid, done))
        raise NumericalRangeError(
            f"{what}: the complex state became inf/nan between steps {int(grid[j - 1])} and {done}; the complex "
            "orbit escapes (complex-coefficient methods have their own stability region); take a smaller h")
    return out


def _worth_compiling(system, comp, steps, X) -> bool:
    """Whether ``backend="auto"`` runs the compiled loop: already compiled in this process, or more than
    :data:`INTERPRET_FACTOR_STEPS` factor-steps of work."""
    from .complex_codegen import compiled_in_process

    batch = X.ndim == 2
    if compiled_in_process(system, comp, batch):
        return True
    return steps * len(comp.pieces) * (X.shape[1] if batch else 1) > INTERPRET_FACTOR_STEPS


def _compiled(system, comp, h, params, X, steps, every, count, project) -> tuple:
    """``(samples, steps done)`` of the compiled loop (:mod:`~nambu_bch.numeric.complex_codegen`)."""
    from .complex_codegen import complex_kernel

    kern = complex_kernel(system, comp)
    T, K = kern.constants(h, params)
    out = np.empty((count, *X.shape), dtype=np.complex128)
    out[0] = X
    start = X.astype(np.complex128)
    run = kern.run if X.ndim == 1 else kern.run_batch
    done = run(start, T, K, steps, every, out, project=project)
    return (np.ascontiguousarray(out.real) if project else out), done


def _interpreted(flows, h, X, steps, grid, project, vector) -> tuple:
    """``(samples, steps done)`` of the lambdified sub-flows: one state (or each column of a batch) on ``cmath``, or
    with ``vector`` a batch on numpy arrays; a run stops at its first sample that is not finite."""
    out = np.empty((len(grid), *X.shape), dtype=np.float64 if project else np.complex128)
    out[0] = X
    times = [(f, g, c * h) for f, g, c in flows]
    if X.ndim == 1 or vector:
        return out, _interpret(times, X, steps, grid, project, out)
    return out, min(_interpret(times, X[:, b], steps, grid, project, out[:, :, b]) for b in range(X.shape[1]))


def _interpret(times, X, steps, grid, project, out) -> int:
    """Step ``X`` (one state, or a batch as numpy arrays) writing the samples into ``out``; the step of the first sample
    that is not finite, else ``steps``."""
    single = X.ndim == 1
    state = [complex(v) for v in X] if single else [np.asarray(v, dtype=np.complex128) for v in X]
    j = 1
    with np.errstate(all="ignore"):
        for n in range(1, steps + 1):
            try:
                for f, g, t in times:
                    state = f(*state, t) if single else [np.asarray(v, dtype=np.complex128) + 0 * state[0] for v in g(*state, t)]
            except (OverflowError, ValueError, ZeroDivisionError):
                state = [complex("nan")] * len(state) if single else [np.full_like(state[0], np.nan)] * len(state)
            if project:
                state = [complex(v.real) for v in state] if single else [v.real.astype(np.complex128) for v in state]
            if j < len(grid) and n == grid[j]:
                out[j] = np.array(state).real if project else np.array(state)
                if not np.isfinite(out[j]).all():
                    return n
                j += 1
    return steps
