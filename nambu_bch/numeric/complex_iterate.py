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
  :func:`check_complex` and reported in docs/integrators.md.

The step is generated once (the sub-flows lambdified one by one with the parameters substituted, as
:func:`nambu_bch.integrators.step.step_function` does) and runs on ``cmath`` for one trajectory and on
numpy arrays for a batch; the numba kernels (:mod:`~nambu_bch.numeric.kernels`) are float64 only and
are not used.

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
from ..errors import InvalidRunError, NumericalRangeError
from ..integrators.composition import composition_for
from ..integrators.flows import TIME, exact_flow
from ..integrators.step import parameter_values
from .guards import check_count, check_inputs, check_work, initial_state, run_label
from .samples import n_samples, sample_steps

#: The functions an entire sub-flow may contain (analytic on all of ``C^N x C``: no branch cut, no pole).
ENTIRE = (sympy.exp, sympy.sin, sympy.cos, sympy.sinh, sympy.cosh)


#: The entire functions by name for one trajectory's scalar step.
_CMATH = {f.__name__: getattr(cmath, f.__name__) for f in ENTIRE}


def _entire_obstacle(expr):
    """``None`` if ``expr`` is an entire function of its symbols, else the sub-expression that is not."""
    for node in sympy.preorder_traversal(expr):
        if isinstance(node, sympy.Pow) and not (node.exp.is_Integer and node.exp >= 0) and node.base.free_symbols:
            return node
        if isinstance(node, sympy.Function) and not isinstance(node, ENTIRE):
            return node
    return None


def complex_subflows(system, word, params=None) -> list:
    """``[(f_scalar, f_array, c), ...]`` per factor of ``word``: the sub-flow ``f(x_1, .., x_N, t)`` lambdified for
    ``cmath`` and for numpy, ``c`` the complex coefficient; refused in one line when a sub-flow is not entire."""
    comp = composition_for(word, system.splitting)
    values = parameter_values(system, params)
    flows = {}
    for k in sorted(set(comp.pieces)):
        exprs = [sympy.sympify(e, strict=True).xreplace(values) for e in exact_flow(system.splitting[k], system.coordinates).expressions]
        bad = next((b for b in map(_entire_obstacle, exprs) if b is not None), None)
        if bad is not None:
            raise InvalidRunError(
                f"composition {comp.name!r} has complex coefficients, and the flow of piece {k} of {system.name} contains "
                f"{bad}, which has a branch cut or a pole in the complex plane: a complex time step is defined only for "
                "sub-flows built from polynomials, exp, sin and cos")
        args = (*system.coordinates, TIME)
        # cmath's functions by name (sympy's "cmath" printer recurses on Float constants)
        flows[k] = (sympy.lambdify(args, exprs, modules=[_CMATH]), sympy.lambdify(args, exprs, modules="numpy"))
    return [(*flows[k], complex(sympy.N(c, 17))) for k, c in comp.factors()]


def iterate_complex(system, word, h, steps, x0=None, params=None, every=1, *, project=False) -> np.ndarray:
    """Iterate ``Phi_h`` of a composition with complex coefficients in complex128; the samples every ``every`` steps.

    Parameters
    ----------
    system : System or model name; word : a composition (complex coefficients, e.g. ``"1:1/4+I/4,2:1/2+I/2,..."``)
    h : float -- the (real) step; steps : int >= 0; every : int >= 1
    x0 : real array of shape (N,) or (N, batch); None: the model's default initial state
    params : dict, optional -- parameter values (missing ones are 1)
    project : bool -- take the real part after every step (``x_{n+1} = Re Phi_h(x_n)``, a real method of the
        same order); False: the complex map itself

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
    x0, origin = initial_state(system, x0)
    check_work(check_count(steps, "steps", 0), x0)
    h, steps, every, X, _ = check_inputs(system, h, steps, every, x0, params)
    flows = complex_subflows(system, word, params)
    comp = composition_for(word, system.splitting)
    what = run_label(system, comp.name, h, X, origin)
    count = n_samples(steps, every)
    dtype = np.float64 if project else np.complex128
    out = np.empty((count, *X.shape), dtype=dtype)
    out[0] = X
    grid = sample_steps(steps, every)
    times = [(f, g, c * h) for f, g, c in flows]
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
            if j < count and n == grid[j]:
                out[j] = np.array(state).real if project else np.array(state)
                if not np.isfinite(out[j]).all():
                    raise NumericalRangeError(
                        f"{what}: the complex state became inf/nan between steps {int(grid[j - 1])} and {n}; the "
                        "complex orbit escapes (complex-coefficient methods have their own stability region); take "
                        "a smaller h")
                j += 1
    return out
