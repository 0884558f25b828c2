"""Iterating a splitting integrator: ``x_n = (Phi_h)^n x_0``, sampled every ``every`` steps.

:func:`iterate` is the one driver of the numeric backend.  It validates the
input (:mod:`~nambu_bch.numeric.guards`), fetches the compiled kernel of the
``(system, word)`` (:mod:`~nambu_bch.numeric.kernels`, generated once from the
exact sub-flows and cached on disk), and runs it for one trajectory or a batch
of initial states, in float64, float64 with compensated summation, or mpmath
(:mod:`~nambu_bch.numeric.precision`).

Shape convention (stable): the state index comes first, as in
:func:`nambu_bch.integrators.step_function` -- ``x0`` of shape ``(N,)`` gives
samples of shape ``(n_samples, N)``, ``x0`` of shape ``(N, batch)`` gives
``(n_samples, N, batch)``.  Sample ``j`` is the state after
``sample_steps(steps, every)[j]`` steps: ``0, every, 2 every, ...`` and, if
``every`` does not divide ``steps``, the final step ``steps`` as the last sample.
So ``samples[0]`` is ``x0`` and ``samples[-1]`` the final state, always.

References
----------
Horikoshi, Sect. 5.5: ``x^{32123}(t) = (Phi^{32123}_h)^n x(0)``, ``t = n h``.
"""

from __future__ import annotations

import contextlib
import contextvars
import os

import numpy as np

from ..errors import InvalidRunError, NumericalRangeError
from ..progress import Progress, progress_wanted
from ..systems.spec import as_system  # the one reading of a system argument (numeric modules import it from here)
from ..checks import check_flag
from .guards import (check_backend, check_count, check_inputs, check_range, check_result, check_stability,
                     check_states, check_work, initial_state, run_label, sample_array, scan_states)
from .kernels import kernel, resolve_backend
from .precision import check_dps, run_mpmath
from .runge_kutta import iterate_runge_kutta
from ..integrators.runge_kutta import runge_kutta_method
from .samples import MAX_SAMPLE_BYTES, n_samples, sample_steps

#: Trajectory-steps per kernel call when progress is reported (a few tenths of a second compiled).
_SEGMENT_WORK = 20_000_000
#: ``workers=None`` splits a compiled batch across threads only with at least this many trajectory-steps
#: per thread: starting and joining a thread costs ~0.1 ms, this much work a few ms.
PARALLEL_WORK = 1_000_000
#: The most threads ``workers=None`` may use in this context: :func:`single_threaded` sets it to 1 inside
#: the tasks of a parallel sweep, whose processes already share the cores.
_MAX_THREADS = contextvars.ContextVar("nambu_bch_batch_threads", default=None)


@contextlib.contextmanager
def single_threaded():
    """Inside the block, batches of ``iterate(workers=None)`` run on one thread (for tasks of a sweep)."""
    token = _MAX_THREADS.set(1)
    try:
        yield
    finally:
        _MAX_THREADS.reset(token)


def available_threads() -> int:
    """The cores this process may run on (its CPU affinity), at most ``$NUMBA_NUM_THREADS`` when that is set
    (joblib sets it in its workers) and 1 inside :func:`single_threaded`."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    limit = os.environ.get("NUMBA_NUM_THREADS", "").strip()
    if limit.isdigit() and int(limit) >= 1:
        cores = min(cores, int(limit))
    return max(1, min(cores, _MAX_THREADS.get() or cores))


def batch_workers(workers, batch: int, steps: int) -> int:
    """Threads for a compiled batch run: ``workers`` when given, else :func:`available_threads` limited so
    that each thread has :data:`PARALLEL_WORK` trajectory-steps."""
    if workers is not None:
        return workers
    return max(1, min(available_threads(), batch * steps // PARALLEL_WORK))


def iterate(system, word, h, steps, x0=None, params=None, every=1, *, kahan=False, dps=None,
            backend="auto", progress=None, chunk=None, check_stable=True, out=None, fma=False, workers=None):
    """Iterate ``Phi_h`` of ``word`` on ``system`` ``steps`` times from ``x0``; the samples every ``every`` steps.

    The step is generated once from the exact sub-flows (Eqs. hX1e-hX3e for ``ho3``)
    and applied in word order (left to right, :mod:`nambu_bch.integrators.composition`),
    compiled with numba; the numpy fallback runs the same generated operations.

    Parameters
    ----------
    system : System or str -- e.g. ``"ho3"``
    word : str or Composition -- e.g. ``"32123"``, ``"TVT"``, ``"forest-ruth"``
    h : float -- the step (negative steps run backwards; str or mpf accepted with ``dps``)
    steps : int >= 0
    x0 : array of shape (N,) -- one trajectory -- or (N, batch) -- a batch of initial states; None: the
        model's documented default (:data:`nambu_bch.systems.catalog.DEFAULT_X0`, else ``(1, ..., 1)``)
    params : dict, optional -- e.g. ``{"m": 1, "omega": 1}``; missing parameters are 1
    every : int >= 1 -- keep every ``every``-th state (long runs need not fill memory)
    kahan : bool -- compensated summation of the increments (float64 only)
    dps : int, optional -- decimal digits of an mpmath run (a reference; ~10^3x slower)
    backend : ``"auto"`` | ``"numba"`` | ``"numpy"`` -- ``"auto"``: compiled, except runs too small to pay for
        compiling their loop (:data:`INTERPRET_STEPS`), which take the interpreter (the same bits); one
        trajectory (no ``kahan``, no ``fma``) runs through the kernel's C library when one is cached and
        verifies (:mod:`~nambu_bch.numeric.clib`: the same bits, numba not imported)
    progress : bool or None -- a progress line on stderr; None: only on a terminal and for long runs
    chunk : int, optional -- states per cache block of a batch (tuning only)
    check_stable : bool -- refuse steps outside the stability interval (:func:`~nambu_bch.numeric.guards.check_stability`)
    out : numpy.ndarray, optional -- receives the samples in place and is returned: float64 of the shape
        returned, C-contiguous, writeable, sharing no memory with ``x0`` (:func:`~nambu_bch.numeric.guards.check_out`).
        Every element is written (``np.empty`` suffices), so repeated runs allocate nothing.  float64 runs only.
    fma : bool -- let the compiled loops fuse ``a*b + c`` into one rounding (faster, chiefly for one
        trajectory; docs/numerics.md).  One trajectory: every increment that is a product is added by an
        explicit fused multiply-add (correctly rounded on every machine), other operations may be contracted
        where the CPU has FMA; batches: contraction where the CPU has it.  The samples are then close to the
        default ones, not equal; the interpreter and numpy never fuse.  Default False: the same bits on
        every backend.  float64 runs only.
    workers : int >= 1 or None -- threads advancing a batch with the compiled loop, each on its own range of
        states (the loop releases the GIL).  The samples are the same bits for every value.  None: the
        cores available (:func:`available_threads`), fewer for small batches (:data:`PARALLEL_WORK`
        trajectory-steps per thread), one inside the tasks of :func:`nambu_bch.parallel.sweep`.  Ignored by
        one trajectory, the numpy loop, mpmath runs and Runge--Kutta methods.

    Returns
    -------
    numpy.ndarray
        ``(n_samples, N)`` for one trajectory, ``(n_samples, N, batch)`` for a batch, with
        ``n_samples = ceil(steps / every) + 1`` at the steps :func:`sample_steps` lists
        (``samples[0] == x0``); float64 (``out`` when given), or ``object`` (``mpmath.mpf``) with ``dps``.

    Raises
    ------
    InvalidRunError, InvalidSystemError, InvalidCompositionError -- bad arguments
    NumericalRangeError -- non-finite input, or float64 overflow/underflow (before or during the run)
    ResourceLimitError -- more than ``MAX_RUN_STEPS`` (mpmath: ``MAX_MPMATH_STEPS``) trajectory-steps
        (:func:`~nambu_bch.numeric.guards.check_work`), refused before any work
    UnstableStepError -- ``h`` outside the stability interval (``|omega h| >= 2`` for the oscillators)

    Examples
    --------
    >>> x = iterate("ho3", "32123", 0.1, 1000, [1.0, 1.0, 1.0], every=500)
    >>> x.shape
    (3, 3)
    >>> H = x[:, 1]**2 / 2 + x[:, 2] / 2          # H of Eq. (H), m = omega = 1: not conserved ...
    >>> Hc = H + 0.1**2 * x[:, 0]**2 / 8          # ... but H_c of Table (table) is, to round-off
    >>> bool(abs(Hc - Hc[0]).max() < 1e-13), bool(abs(H - H[0]).max() > 1e-4)
    (True, True)
    >>> iterate("ho", "TVT", 0.1, 4, [[1.0, 0.0], [0.0, 1.0]]).shape     # a batch of two states
    (5, 2, 2)
    """
    system = as_system(system)
    if workers is not None:
        workers = check_count(workers, "workers", 1)
    tableau = runge_kutta_method(word)
    if tableau is not None:  # an implicit or explicit Runge--Kutta method: Newton's method, compiled alike
        _runge_kutta_options(tableau, dps, fma)
        check_flag(check_stable, "check_stable")  # no stability interval to check: Newton's failure is the guard
        check_flag(progress, "progress", none=True)
        return iterate_runge_kutta(system, tableau, h, steps, x0, params, every, kahan=kahan, backend=backend, out=out)
    from .force_gradient import is_gradient_method

    if is_gradient_method(word):  # a force-gradient composition or a processed kernel: its own numpy loop
        return _gradient_run(system, word, h, steps, x0, params, every, kahan, dps, out, fma)
    if _complex(system, word):  # a complex map: complex128 on its own path (numeric/complex_iterate.py)
        return _iterate_complex(system, word, h, steps, x0, params, every, kahan, dps, out, fma, backend)
    x0, origin = initial_state(system, x0)
    check_work(check_count(steps, "steps", 0), x0, mpmath=dps is not None)  # from the request, before any work
    kahan, check_stable = check_flag(kahan, "kahan"), check_flag(check_stable, "check_stable")
    progress, backend = check_flag(progress, "progress", none=True), check_backend(backend)
    fma = check_flag(fma, "fma")
    kern = kernel(system, word)
    if dps is not None:
        dps = check_dps(dps)
        if kahan:
            raise InvalidRunError("kahan=True applies to float64 runs; an mpmath run (dps=...) needs no compensation")
        if out is not None:
            raise InvalidRunError("out= receives float64 samples; an mpmath run (dps=...) returns a new object array")
        if fma:
            raise InvalidRunError("fma=True applies to compiled float64 runs; an mpmath run (dps=...) has no fused "
                                  "multiply-add")
        h, steps, every, X, _ = check_inputs(system, h, steps, every, x0, params, exact=True)
        if check_stable:
            check_stability(kern, h, kern.constants(float(h), params), params)
        batch = 1 if X.ndim == 1 else X.shape[1]
        reporter = Progress(steps * batch, f"iterate {system.name} {kern.word} (mpmath, dps={dps})",
                            enabled=_enabled(progress, steps * batch * 1000))
        with reporter:
            return run_mpmath(kern, X, h, steps, every, params, dps, reporter.update if reporter.enabled else None)

    run = _prepare(system, kern, h, steps, every, x0, params, backend, chunk, check_stable, kahan, fma, workers)
    h, steps, every, X, be, K = run.h, run.steps, run.every, run.X, run.backend, run.K
    chunk = run.chunk

    single = X.ndim == 1
    batch = 1 if single else X.shape[1]
    count = n_samples(steps, every)
    shape = (count, system.N) if single else (count, system.N, batch)
    out = sample_array(out, shape, x0, X)
    what = run_label(system, kern.word, h, X, origin)
    reporter = Progress(steps * batch, f"iterate {system.name} {kern.word}",
                        enabled=_enabled(progress, steps * batch * (30 if be == "numpy" and single else 1)))
    segment = steps if not reporter.enabled else max(every, (_SEGMENT_WORK // batch) // every * every)
    if not single:
        with reporter:
            _run_batch(kern, X, K, steps, every, out, kahan, be, chunk, segment, reporter, what, fma, run.workers,
                       x0 if run.deferred else None)
        return out
    state = X  # check_inputs made a fresh float64 copy: advanced in place
    out[0] = state
    comp = np.zeros_like(state) if kahan else None
    done, j = 0, 0
    with reporter, np.errstate(over="ignore", invalid="ignore"):
        while done < steps:
            seg = min(segment, steps - done)
            nseg = n_samples(seg, every)
            n, be = _run_single(kern, state, K, seg, every, out[j:j + nseg], kahan, comp, be, run.fallback, what, fma)
            if n < seg:  # stopped at a non-finite sample: the rest is undefined
                out[j + n_samples(n, every):] = np.nan
                break
            done += seg
            j += nseg - 1
            reporter.update(done)
    if count > 1:  # sample 0 is x0, checked before the run
        check_result(out[1:], sample_steps(steps, every)[1:], what, start=0)
    return out


def _gradient_run(system, word, h, steps, x0, params, every, kahan, dps, out, fma):
    """A force-gradient composition (:func:`~nambu_bch.numeric.force_gradient.iterate_gradient`) or a catalogue kernel
    run processed (:func:`~nambu_bch.numeric.force_gradient.iterate_processed`); float64 without the kernel options."""
    from .force_gradient import is_processed_kernel, iterate_gradient, iterate_processed

    for flag, name in ((kahan, "kahan"), (dps is not None, "dps"), (out is not None, "out"), (fma, "fma")):
        if flag:
            raise InvalidRunError(f"{name}= applies to the compiled splitting kernels; force-gradient methods run in a "
                                  f"float64 numpy loop without it")
    run = iterate_processed if is_processed_kernel(word) else iterate_gradient
    return run(system, word, h, steps, x0, params, every)


def _run_single(kern, state, K, steps, every, out, kahan, comp, be, fallback, what, fma=False):
    """One segment of a single trajectory: ``(steps done, backend for the next segment)``.

    The interpreter raises where compiled float64 arithmetic gives inf or nan (``math.exp``
    overflowing, ``log`` of a negative number, division by zero); it leaves ``state`` and ``comp``
    untouched then.  If it was chosen only for speed (``fallback``) the compiled loop runs the
    segment instead, so ``backend="auto"`` reports the same result as with ``"numba"``;
    otherwise (``backend="numpy"``, or numba absent) the run is refused in one line.
    """
    try:
        return kern.run(state, K, steps, every, out, kahan=kahan, comp=comp, backend=be, fma=fma), be
    except (ArithmeticError, ValueError) as exc:
        if be != "numpy":
            raise
        if fallback:
            return kern.run(state, K, steps, every, out, kahan=kahan, comp=comp, backend="numba", fma=fma), "numba"
        raise NumericalRangeError(f"{what}: float64 arithmetic failed on the interpreter ({exc}); the state "
                                  "left the range of the step's functions; take a smaller h, or use dps=... (mpmath)"
                                  ) from None


def _run_batch(kern, X, K, steps, every, out, kahan, be, chunk, segment, reporter, what, fma=False, workers=1,
               x0=None):
    """Fill ``out`` with the samples of a batch: ``X`` (the caller's start states) is only read.

    The kernel copies ``X`` into ``out[0]`` while it loads each chunk, starts every later segment
    from the last sample written, and counts non-finite values as it writes the samples; only a
    positive count costs a pass over the samples (:func:`check_result` names the step).

    ``x0`` (the argument as given) when the input guards were left to the first segment's loop
    (:func:`_prepare`, ``deferred``): it scans ``X`` as it loads each chunk, stops at a non-finite or
    subnormal state (refused by :func:`check_states`, the message of a run checked up front), and the extreme
    states it found are then checked by :func:`check_range` before anything else is reported -- the batch
    is read from memory once.
    """
    if steps == 0:
        if x0 is not None:  # no loop to scan it
            check_states(x0, X)
            check_range(kern, X, K, columns=kern.scan(X, workers)[2])
        out[0] = X
        return
    comp = np.zeros_like(X) if kahan else None
    source, done, j = X, 0, 0
    with np.errstate(over="ignore", invalid="ignore"):
        while done < steps:
            seg = min(segment, steps - done)
            nseg = n_samples(seg, every)
            scanned = {} if x0 is not None and j == 0 else None
            bad = kern.run_batch(source, K, seg, every, out[j:j + nseg], kahan=kahan, comp=comp, backend=be,
                                 chunk=chunk, start=j == 0, back=False, fma=fma, workers=workers, scanned=scanned)
            if scanned is not None:
                if bad < 0 or sum(scanned["result"][:2]):
                    check_states(x0, X)
                    raise NumericalRangeError(f"{what}: x0 holds a non-finite or subnormal value")  # pragma: no cover
                check_range(kern, X, K, columns=scanned["result"][2])
            if bad:
                grid = sample_steps(steps, every)
                samples = out[1:j + nseg]
                broken = ~np.isfinite(samples).all(axis=1)  # (sample, state)
                first = int(np.argmax(broken.any(axis=1)))
                state = int(np.argmax(broken[first]))  # the first state to overflow: named as its own run is
                check_result(samples, grid[1:j + nseg], f"{what} from x0 = {X[:, state].tolist()}", start=0)
            done += seg
            j += nseg - 1
            source = out[j]
            reporter.update(done * X.shape[1])


#: ``backend="auto"`` runs a loop on the interpreter while its compiled version is not ready
#: (:meth:`~nambu_bch.numeric.kernels.Kernel.ready`: neither compiled in this process nor in numba's
#: cache on disk, or numba not even imported) and compiling would cost more than the run: up to this
#: many trajectory-steps of one state per loop and process, in total.  Compiling a single-state loop
#: costs 0.1-0.7 s (importing numba another 0.3 s); the interpreter takes 0.3-2 us a step (ho3 0.4,
#: Lotka-Volterra 2.1), so this budget costs at most ~0.1 s -- and the loop is compiled once a
#: process needs more.  The interpreter runs the same statements on Python floats and the C
#: library's functions: the samples are the compiled loop's, bit for bit.
INTERPRET_STEPS = 50_000
#: Batches of at most this many steps (and states) likewise run on numpy arrays while the compiled batch
#: loop is not ready (0.3-4 s to compile) -- only kernels whose numpy loop gives the compiled bits
#: (:attr:`~nambu_bch.numeric.kernels.Kernel.numpy_matches_compiled`: polynomial and trigonometric flows).
SMALL_BATCH_STEPS, SMALL_BATCH_STATES = 100, 16384


class _Run:
    """The validated inputs of one float64 run."""

    __slots__ = ("h", "steps", "every", "X", "backend", "K", "chunk", "fallback", "workers", "deferred")

    def __init__(self, **kw):
        for k, v in kw.items():
            setattr(self, k, v)


def _prepare(system, kern, h, steps, every, x0, params, backend, chunk, check_stable, kahan=False, fma=False,
             workers=None) -> _Run:
    """Validate a float64 run, choose the backend, compute the constants, check stability and range.

    ``workers`` as in :func:`iterate`: a batch's threads (:func:`batch_workers`) scan their own ranges of
    states for the guards, the ranges they then advance, so no serial pass precedes the threaded run.
    A large batch on the compiled loop (``deferred`` in the result) leaves the values of ``x0`` and the
    range check to that loop, which scans each chunk as it loads it (:func:`_run_batch`).
    """
    be = resolve_backend(backend)
    steps = check_count(steps, "steps", 0)
    shape = np.shape(x0)
    fallback = False  # the interpreter chosen for speed: on an arithmetic exception the compiled loop takes over
    if backend == "auto" and be == "numba" and len(shape) == 1 and not (kahan or fma) and kern.library() is not None:
        be = "c"  # the kernel's cached C library (numeric.clib): numba's bits without importing numba
    elif backend == "auto" and be == "numba":
        be, fallback = _interpret_small(kern, steps, shape, kahan, fma)
    # a large batch: non-finite, subnormal and extreme states are found by the compiled loop as it loads the
    # states (deferred), by one blocked numpy pass otherwise; the batch itself is only read, so it is not copied
    batch = len(shape) == 2
    threads = batch_workers(workers, shape[1], steps) if batch else 1
    scanned = {}
    deferred = batch and shape[1] > SCAN_BATCH and be == "numba"
    if batch and shape[1] > SCAN_BATCH and not deferred:
        def scan(arr):
            scanned["result"] = scan_states(arr)
            return scanned["result"]
    else:
        scan = None
    h, steps, every, X, _ = check_inputs(system, h, steps, every, x0, params, scan=scan, copy=not batch,
                                         deferred=deferred)
    if chunk is not None:
        chunk = check_count(chunk, "chunk", 1)
    K = kern.constants(float(h), params)
    if check_stable:
        check_stability(kern, h, K, params)
    if not deferred:
        check_range(kern, X, K, columns=scanned["result"][2] if scanned else None)
    return _Run(h=h, steps=steps, every=every, X=X, backend=be, K=K, chunk=chunk, fallback=fallback, workers=threads,
                deferred=deferred)


def _interpret_small(kern, steps, shape, kahan, fma=False):
    """``("numpy", True)`` if the run should take the interpreter (or numpy, for a batch), else ``("numba", False)``.

    A single state: the loop is not :meth:`~nambu_bch.numeric.kernels.Kernel.ready` and the steps
    interpreted so far in this process plus these stay within :data:`INTERPRET_STEPS`.  A batch:
    the same readiness, at most :data:`SMALL_BATCH_STEPS` steps of :data:`SMALL_BATCH_STATES`
    states, and a numpy loop with the compiled loop's bits.
    """
    batch = len(shape) == 2
    name = kern.loop_name(kahan, batch, fma)
    if kern.ready(name):
        return "numba", False
    if batch:
        small = steps <= SMALL_BATCH_STEPS and shape[1] <= SMALL_BATCH_STATES and kern.numpy_matches_compiled
    else:
        small = len(shape) == 1 and kern.interpreted.get(name, 0) + steps <= INTERPRET_STEPS
    if not small:
        return "numba", False
    kern.interpreted[name] = kern.interpreted.get(name, 0) + steps
    return "numpy", True


#: Batches with more states than this are scanned in one pass (compiled, or numpy blocks) instead of
#: whole-array numpy passes.
SCAN_BATCH = 4096

#: Samples per block of :func:`iterate_chunks` (a few MB per block for N = 3).
CHUNK_SAMPLES = 1 << 16


def iterate_chunks(system, word, h, steps, x0=None, params=None, every=1, *, kahan=False, backend="auto",
                   chunk_samples=CHUNK_SAMPLES, check_stable=True):
    """Iterate like :func:`iterate` (one trajectory) but yield the samples block by block.

    Yields ``(numbers, samples)``: the step numbers of the block's samples (int64) and the samples
    (shape ``(len(numbers), N)``, float64).  The first block starts with sample 0 (``x0``); the
    blocks together are exactly :func:`sample_steps` and the samples :func:`iterate` returns
    (the state and Kahan compensation carry over from block to block), but at most
    ``chunk_samples`` of them are held at a time -- so diagnostics of ``10^8`` steps sampled at
    every step run in bounded memory.

    Raises
    ------
    NumericalRangeError -- at the first block with a non-finite sample (the blocks before it were yielded).
    """
    system = as_system(system)
    tableau = runge_kutta_method(word)
    if tableau is not None:
        yield from _runge_kutta_chunks(system, tableau, h, steps, x0, params, every, kahan, backend, chunk_samples)
        return
    x0, origin = initial_state(system, x0)
    check_work(check_count(steps, "steps", 0), x0)  # from the request, before any work
    kahan, check_stable = check_flag(kahan, "kahan"), check_flag(check_stable, "check_stable")
    backend = check_backend(backend)
    chunk_samples = _block_samples(chunk_samples, system.N)
    kern = kernel(system, word)
    run = _prepare(system, kern, h, steps, every, x0, params, backend, None, check_stable, kahan)
    if run.X.ndim != 1:
        raise InvalidRunError(f"iterate_chunks takes one initial state of shape ({system.N},), got shape {run.X.shape}")
    steps, every, be = run.steps, run.every, run.backend
    state = np.array(run.X, dtype=np.float64)
    comp = np.zeros_like(state) if kahan else None
    what = run_label(system, kern.word, run.h, run.X, origin)
    yield np.zeros(1, dtype=np.int64), state.copy()[None, :]
    block = (chunk_samples - 1) * every  # steps per block
    done = 0
    with np.errstate(over="ignore", invalid="ignore"):
        while done < steps:
            seg = min(block, steps - done)
            nseg = n_samples(seg, every)
            out = np.empty((nseg, system.N))
            out[0] = state
            n, be = _run_single(kern, state, run.K, seg, every, out, kahan, comp, be, run.fallback, what)
            numbers = done + sample_steps(seg, every)
            if n < seg:
                out[n_samples(n, every):] = np.nan
            check_result(out, numbers, what)
            done += seg
            yield numbers[1:], out[1:]


def _complex(system, word) -> bool:
    """``word`` is a composition with complex coefficients (checked against the system's splitting)."""
    from ..integrators.composition import composition_for

    return composition_for(word, system.splitting).is_complex


def _iterate_complex(system, word, h, steps, x0, params, every, kahan, dps, out, fma, backend):
    """:func:`~nambu_bch.numeric.complex_iterate.iterate_complex`, the float64-only options refused in one line."""
    from .complex_iterate import iterate_complex

    for flag, given in (("kahan=True", check_flag(kahan, "kahan")), ("dps=...", dps is not None),
                        ("out=...", out is not None), ("fma=True", check_flag(fma, "fma"))):
        if given:
            raise InvalidRunError(f"{flag} applies to float64 runs; {str(word)[:60]!r} has complex coefficients and "
                                  "runs in complex128 (numeric.complex_iterate)")
    return iterate_complex(system, word, h, steps, x0, params, every, backend=backend)


def _runge_kutta_options(tableau, dps, fma) -> None:
    """Refuse, in one line, the options of :func:`iterate` that only the splitting kernels have."""
    if dps is not None:
        raise InvalidRunError(f"dps= (an mpmath run) is available for compositions; the Runge-Kutta method "
                              f"{tableau.name} runs in float64 only")
    if check_flag(fma, "fma"):
        raise InvalidRunError(f"fma=True applies to the compiled splitting kernels, not to the Runge-Kutta method {tableau.name}")


def _block_samples(chunk_samples, N: int) -> int:
    """``chunk_samples`` checked: at least 2, and one block (held at a time) within the samples' memory bound."""
    chunk_samples = _count(chunk_samples, "chunk_samples", 2)
    if chunk_samples * N * 8 > MAX_SAMPLE_BYTES:
        raise InvalidRunError(f"chunk_samples = {chunk_samples} blocks of {N} coordinates need more than "
                              f"{MAX_SAMPLE_BYTES / 2**30:.0f} GiB; take fewer samples per block")
    return chunk_samples


def _runge_kutta_chunks(system, tableau, h, steps, x0, params, every, kahan, backend, chunk_samples):
    """:func:`iterate_chunks` for a Runge--Kutta method: blocks of :func:`iterate_runge_kutta` runs, the state and
    the compensation carried from block to block (the same samples as one run)."""
    x0, _ = initial_state(system, x0)
    steps = check_count(steps, "steps", 0)
    chunk_samples = _block_samples(chunk_samples, system.N)
    first = iterate_runge_kutta(system, tableau, h, 0, x0, params, 1, backend=backend)  # validates the run
    if first.ndim != 2:
        raise InvalidRunError(f"iterate_chunks takes one initial state of shape ({system.N},), got shape {first.shape[1:]}")
    every = min(check_count(every, "every", 1), max(steps, 1))
    state, comp = first[0].copy(), np.zeros(system.N)
    yield np.zeros(1, dtype=np.int64), first.copy()
    block = (chunk_samples - 1) * every
    done = 0
    while done < steps:
        seg = min(block, steps - done)
        out = iterate_runge_kutta(system, tableau, h, seg, state, params, every, kahan=kahan, backend=backend,
                                  compensation=comp)
        state = out[-1].copy()
        yield done + sample_steps(seg, every)[1:], out[1:]
        done += seg


def _count(value, what, minimum):
    from .guards import check_count

    return check_count(value, what, minimum)


def _enabled(progress, work):
    """Explicit choice, else automatic: a terminal and enough work (trajectory-steps, ~1 ns each compiled)."""
    if progress is not None:
        return bool(progress)
    return work >= 5e8 and progress_wanted()
