"""Guards of a numeric run: accepted inputs, the stability interval, the float64 range.

Checks made before any step is taken, each raising one
:class:`~nambu_bch.errors.NambuBCHError` subclass with a one-line message:

* :func:`check_inputs` -- ``h``, ``steps``, ``every``, ``x0`` and the parameters
  are finite real numbers of the accepted shapes (``NumericalRangeError`` for
  NaN/inf, ``InvalidRunError`` for the rest);
* :func:`check_stability` -- the *linear part* of the step: the largest set of
  coordinates ``S`` whose increments are affine in ``x_S`` alone (``(x1, x2)``
  of ``ho`` and ``ho3``, all three of ``ho3-composite``).  Its matrix ``M(h)`` is
  formed numerically; the step is unstable (``UnstableStepError``) if an
  eigenvalue has ``|lambda| > 1`` or an eigenvalue on the unit circle is
  defective (a Jordan block: linear growth, the boundary ``omega h = 2`` where
  ``tr M = -2``).  For the oscillators this is exactly ``|omega h| < 2``
  (position/velocity Verlet: ``tr M = 2 - omega^2 h^2``, Hairer-Lubich-Wanner
  Sect. I.5);
* :func:`check_range` -- one step in extended precision (``numpy.longdouble``,
  exponent range 10^4932 on x86; mpmath elsewhere) against float64: if they
  differ by more than ``1e-6`` relative to the state's scale, float64 over- or
  underflows for this initial state (``NumericalRangeError``).

:func:`check_result` turns non-finite samples after a run into a
``NumericalRangeError`` naming the step.

References
----------
Horikoshi, Sect. 5.5; Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. I.5.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..checks import finite_float, show
from ..errors import InvalidRunError, NumericalRangeError, ResourceLimitError, UnstableStepError
from ..integrators.step import parameter_values

#: Smallest positive normal float64.
TINY = np.finfo(np.float64).tiny
#: Relative disagreement with the extended-precision step that counts as over/underflow.
RANGE_RTOL = 1e-6
#: The kernel backends a run accepts (:func:`~nambu_bch.numeric.kernels.resolve_backend` resolves ``"auto"``).
BACKENDS = ("auto", "numba", "numpy")
#: Largest sample array accepted (bytes); beyond it, sample less often (larger ``every``).
MAX_SAMPLE_BYTES = 16 * 2**30


def finite_array(values, what) -> np.ndarray:
    """``values`` (a number or an array of numbers) as a float64 array of finite values, else one line naming ``what``."""
    try:
        out = np.asarray(values, dtype=np.float64)
    except OverflowError:
        raise NumericalRangeError(f"{what} holds a number beyond the float64 range (|x| <= "
                                  f"{np.finfo(np.float64).max:.3g}); give finite real numbers") from None
    except (TypeError, ValueError):
        raise InvalidRunError(f"{what} must be a real number or an array of real numbers, got {show(values)}") from None
    if not np.all(np.isfinite(out)):
        raise NumericalRangeError(f"{what} holds a non-finite value (nan or inf); give finite real numbers")
    return out


def _real(value, what):
    """``value`` itself if it is a finite real number (strings and mpf kept for mpmath runs), else one line."""
    if hasattr(value, "_mpf_"):  # mpmath.mpf: an mpmath run reads it at full precision
        return value
    if not isinstance(value, (numbers.Real, np.floating, np.integer, str)):
        raise InvalidRunError(f"{what} must be a real number, got {show(value)}")
    finite_float(value, what)
    return value


def check_count(value, what, minimum):
    """``value`` as an int ``>= minimum`` (integral floats such as ``1e5`` accepted)."""
    if isinstance(value, bool):
        raise InvalidRunError(f"{what} must be an integer >= {minimum}, got {value!r}")
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value) or value != int(value):
            raise InvalidRunError(f"{what} must be an integer >= {minimum}, got {value!r}")
        value = int(value)
    if not isinstance(value, (int, np.integer)) or value < minimum:
        raise InvalidRunError(f"{what} must be an integer >= {minimum}, got {show(value)}")
    return int(value)


def check_backend(backend) -> str:
    """``backend`` if it is a string (:func:`~nambu_bch.numeric.kernels.resolve_backend` checks the name)."""
    if not isinstance(backend, str):
        raise InvalidRunError(f"backend must be one of {', '.join(BACKENDS)}, got {show(backend)}")
    return backend


#: Most trajectory-steps (steps x states of a batch) of one float64 run.  A compiled step costs about 18 ns
#: (ho3) to 37 ns (fpu-beta) on one core, so 10^10 is 3-6 minutes -- the longest run that can be meant --
#: while 10^400 would never end (and 2^63 overflows the kernels' int64 step counters).
MAX_RUN_STEPS = 10**10
#: Most trajectory-steps of one mpmath run (``dps=...``): a step at 30 digits costs about 90 us (ho3) to
#: 560 us (fpu-beta, toda), so 10^6 is 1.5-10 minutes.
MAX_MPMATH_STEPS = 10**6


def check_work(steps: int, x0, mpmath: bool = False) -> None:
    """Refuse a run of more than :data:`MAX_RUN_STEPS` (mpmath: :data:`MAX_MPMATH_STEPS`) trajectory-steps.

    Decided from the request alone (``steps`` times the batch size of ``x0``), before a kernel is
    generated or a step taken (:class:`~nambu_bch.errors.ResourceLimitError`).
    """
    try:
        shape = np.shape(x0)
    except (TypeError, ValueError):  # a ragged x0: check_inputs names it
        return
    batch = shape[1] if len(shape) == 2 else 1
    limit = MAX_MPMATH_STEPS if mpmath else MAX_RUN_STEPS
    if steps * batch > limit:
        states = f" x {batch} states" if batch > 1 else ""
        raise ResourceLimitError(
            f"steps = {show(steps)}{states} is more than the {limit:.0e} trajectory-steps one "
            f"{'mpmath' if mpmath else 'float64'} run accepts; split the run or take a larger h")


def check_inputs(system, h, steps, every, x0, params=None, exact=False, scan=None, copy=True, deferred=False):
    """Validate a run's arguments; returns ``(h, steps, every, x0 array, params dict)``.

    ``x0`` must have shape ``(N,)`` or ``(N, batch)``; with ``exact=True`` (the mpmath
    path) strings and mpf values are kept as they are (object array).  ``scan``: a one-pass
    scan of a batch returning ``(non-finite count, subnormal count, columns)``
    (:meth:`~nambu_bch.numeric.kernels.Kernel.scan` or :func:`scan_states`) used instead of
    whole-array numpy passes for the finiteness and underflow checks.  ``copy``: return a fresh
    array (a float64 run advances it in place); with ``copy=False`` a C-contiguous, aligned,
    writeable float64 ``x0`` is returned as it is (the caller only reads it).  ``deferred``: the values of a
    float64 batch are left to the caller, whose compiled loop scans the states as it loads them and calls
    :func:`check_states` if one is non-finite or subnormal -- a batch read once instead of twice.
    """
    h = _real(h, "step h")
    steps = check_count(steps, "steps", 0)
    check_work(steps, x0, exact)
    # every > steps samples 0 and steps, as every = steps does: the same grid, and int64 counters stay small
    every = min(check_count(every, "every", 1), max(steps, 1))
    if params is not None and not isinstance(params, dict):
        raise InvalidRunError(f"params must be a dict such as {{'omega': 1.0}}, got {params!r}")
    for k, v in (params or {}).items():
        _real(v, f"parameter {k}")
    values = parameter_values(system, params)  # unknown names -> InvalidSystemError
    try:  # a fresh C-ordered copy (the float64 run advances it in place) unless the caller only reads it
        convert = np.array if copy or exact else np.asarray
        arr = convert(x0, dtype=object if exact else np.float64, order="C")
        if not (arr.flags.c_contiguous and arr.flags.aligned and arr.flags.writeable):
            arr = np.array(arr, order="C")  # one layout for the compiled kernels (no recompilation)
    except OverflowError:
        raise NumericalRangeError(f"x0 = {show(x0)} holds a number beyond the float64 range (|x| <= "
                                  f"{np.finfo(np.float64).max:.3g}); give finite real numbers") from None
    except (TypeError, ValueError):
        raise InvalidRunError(f"x0 must be an array of {system.N} real numbers (or shape ({system.N}, batch)), "
                              f"got {show(x0)}") from None
    if arr.ndim not in (1, 2) or arr.shape[0] != system.N or (arr.ndim == 2 and arr.shape[1] == 0):
        raise InvalidRunError(
            f"x0 has shape {arr.shape}, but {system.name} has {system.N} coordinates "
            f"{tuple(str(c) for c in system.coordinates)}: give shape ({system.N},) or ({system.N}, batch)"
        )
    if arr.ndim == 2 and not exact:
        if deferred:
            return h, steps, every, arr, values
        if scan is not None:
            nonfinite, subnormal, _ = scan(arr)
            if not (nonfinite or subnormal):
                return h, steps, every, arr, values
    check_states(x0, arr, exact)
    return h, steps, every, arr, values


def check_states(x0, arr, exact=False) -> None:
    """Refuse, in one line, initial states ``arr`` (``x0`` as given, converted) holding a non-finite value or
    (float64 runs) a subnormal one; ``exact``: an object array of an mpmath run (strings, mpf)."""
    if exact:
        try:
            floats = np.array([float(v) for v in arr.ravel()]).reshape(arr.shape)
        except OverflowError:
            raise NumericalRangeError(f"x0 = {show(x0)} holds a number beyond the float64 range; give finite "
                                      "real numbers") from None
        except (TypeError, ValueError):
            raise InvalidRunError(f"x0 must hold {arr.shape[0]} real numbers (floats, strings or mpf with dps), "
                                  f"got {show(x0)}") from None
    else:
        floats = arr
    flat = floats.reshape(-1)
    if not np.isfinite(np.max(flat) - np.min(flat)):  # nan propagates, +-inf gives inf or nan
        bad = floats[~np.isfinite(floats)].ravel()[0]
        raise NumericalRangeError(f"x0 contains the non-finite value {bad}; initial states must be finite")
    if not exact:
        magnitude = np.abs(flat)
        sub = (magnitude < TINY) & (magnitude > 0)
        if np.any(sub):
            raise NumericalRangeError(
                f"x0 contains {flat[sub][0]:.3g}, below the smallest normal float64 ({TINY:.3g}): it underflows; "
                "rescale the initial state or use dps=... (mpmath)"
            )


def sample_array(out, shape, *inputs) -> np.ndarray:
    """Where a run writes its samples of ``shape``: the caller's ``out`` (its layout checked by :func:`check_out`),
    else a new float64 array, not zeroed (the loops write every sample), refused in one line above
    :data:`MAX_SAMPLE_BYTES`."""
    if out is not None:
        return check_out(out, shape, *inputs)
    nbytes = math.prod(shape) * 8
    if nbytes > MAX_SAMPLE_BYTES:
        count, N, batch = (*shape, 1)[:3]
        raise InvalidRunError(f"{count} samples of {N} x {batch} states need {nbytes / 2**30:.1f} GiB "
                              f"(limit {MAX_SAMPLE_BYTES / 2**30:.0f} GiB); sample less often (larger every)")
    return np.empty(shape, dtype=np.float64)


def check_out(out, shape, *inputs) -> np.ndarray:
    """``out`` if it can receive a run's samples in place, else one :class:`InvalidRunError` line.

    Accepted: a numpy array of dtype float64 and exactly ``shape``, C-contiguous, aligned and
    writeable, sharing no memory with any of ``inputs`` (the start states the run reads while
    it writes the samples).  The run writes every element, so ``out`` may come from ``np.empty``.
    """
    want = f"a writeable C-contiguous float64 array of shape {shape}"
    if not isinstance(out, np.ndarray):
        raise InvalidRunError(f"out must be {want} (the samples of this run), got {show(out)}")
    flags = out.flags
    if out.dtype != np.float64 or out.shape != tuple(shape) or not (flags.c_contiguous and flags.aligned):
        layout = "C-contiguous" if flags.c_contiguous else "not C-contiguous"
        raise InvalidRunError(f"out must be {want} (the samples of this run), got a {layout} {out.dtype} "
                              f"array of shape {out.shape}")
    if not flags.writeable:
        raise InvalidRunError(f"out must be {want}, got a read-only array")
    if any(isinstance(a, np.ndarray) and np.may_share_memory(out, a) for a in inputs):
        raise InvalidRunError("out shares memory with x0; the run reads x0 while it writes the samples: "
                              "give a separate array")
    return out


def initial_state(system, x0):
    """``(x0, origin)``: ``x0`` as given (origin ``""``), or for ``x0=None`` the system's documented default
    (:func:`nambu_bch.systems.catalog.default_x0`) with ``origin`` saying so, e.g. ``" (the default x0 of ho3)"``."""
    if x0 is not None:
        return x0, ""
    from ..systems.catalog import default_x0

    x0, where = default_x0(system)
    return np.array(x0, dtype=np.float64), f" ({where})"


def run_label(system, word, h, X, origin="") -> str:
    """``"<system> under <word> with h = <h> from x0 = [...]"``: the run named in its error messages."""
    start = f" from x0 = {np.asarray(X, dtype=np.float64).tolist()}" if np.ndim(X) == 1 else ""
    return f"{system.name} under {word} with h = {h!r}{start}{origin}"


# -- stability --------------------------------------------------------------------------------------------


def linear_part(program):
    """``(S, maps)``: the coordinates ``S`` whose increments are affine in ``x_S`` alone, and per update
    the list ``(i, {j: constant or 1/-1 coefficient}, additive constant)`` restricted to ``S``."""
    import sympy

    state = program.state
    S = set(range(program.N))
    changed = True
    while changed:
        changed = False
        for u in program.updates:
            for i, d in u.expanded():
                if i not in S:
                    continue
                used = {state.index(s) for s in d.free_symbols & set(state)}
                ok = used <= S and d.is_polynomial(*state) and sympy.Poly(d, *state).total_degree() <= 1
                if not ok:
                    S.discard(i)
                    changed = True
    return tuple(sorted(S))


def step_matrix(kernel, K, S):
    """The matrix of the (affine) step restricted to the coordinates ``S`` (the constant part dropped).

    Measured on the kernel itself (no sympy): column ``j`` is ``Phi(e_j) - Phi(0)`` on ``S``, with
    the other coordinates at 0.  The increments of ``S`` are affine in ``x_S`` alone
    (:func:`linear_part`), so this is the exact product of the sub-flows' matrices up to rounding.
    """
    S = list(S)
    N = kernel.N
    X = np.zeros((N, len(S) + 1))
    for col, i in enumerate(S):
        X[i, col + 1] = 1.0
    with np.errstate(all="ignore"):
        kernel.run_batch(X, K, 1, 1, np.zeros((2, N, len(S) + 1)), backend="numpy")
    return X[S, 1:] - X[S, :1]


#: Most constants vectors a kernel remembers as stable (:func:`check_stability`; a few kB each at most).
MAX_REMEMBERED = 1024


def check_stability(kernel, h, K, params=None):
    """Raise :class:`UnstableStepError` if the linear part of the step is not power-bounded.

    The verdict depends on the constants ``K`` alone, so a stable ``K`` is remembered by the kernel
    (``kernel.stable_constants``): repeated runs with one step and one set of parameters check it once.

    Examples
    --------
    >>> from nambu_bch import model
    >>> from nambu_bch.numeric.kernels import kernel
    >>> k = kernel(model("ho3"), "32123")
    >>> check_stability(k, 1.9, k.constants(1.9))
    >>> check_stability(k, 2.0, k.constants(2.0))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    nambu_bch.errors.UnstableStepError: h = 2.0 is outside the stability interval of 32123 on ho3 (omega*h = 2, must be < 2): ...
    """
    S = kernel.linear
    passed = getattr(kernel, "stable_constants", None)  # the verdict depends on K alone: each K checked once
    key = np.asarray(K, dtype=np.float64).tobytes()
    if not S or (passed is not None and key in passed):
        return
    M = step_matrix(kernel, K, S)
    if not np.all(np.isfinite(M)):
        raise NumericalRangeError(f"h = {h!r}: the step's coefficients overflow float64")
    lam = np.linalg.eigvals(M)
    radius = float(np.max(np.abs(lam)))
    reason = None
    if radius > 1 + 1e-9:
        reason = f"the linear part on {_names(kernel, S)} has spectral radius {radius:.6g} > 1 (exponential growth)"
    else:
        scale = max(1.0, float(np.linalg.norm(M)))
        for lam0 in lam:
            if abs(abs(lam0) - 1) > 1e-6:
                continue
            cluster = np.abs(lam - lam0) < 1e-6
            if cluster.sum() < 2:
                continue
            centre = lam[cluster].mean()
            sv = np.linalg.svd(M - centre * np.eye(len(S)), compute_uv=False)
            geometric = int(np.sum(sv < 1e-6 * scale))
            if geometric < cluster.sum():
                reason = (f"the linear part on {_names(kernel, S)} has a defective eigenvalue {complex(centre).real:.6g} "
                          "on the unit circle (the stability boundary: linear growth)")
                break
    if reason:
        values = parameter_values(kernel.system, params)
        omega = {p.name: v for p, v in values.items()}.get("omega")
        hint = f" (omega*h = {omega * float(h):.6g}, must be < 2)" if omega is not None else ""
        raise UnstableStepError(f"h = {h!r} is outside the stability interval of {kernel.word} on "
                                f"{kernel.system.name}{hint}: {reason}; take a smaller step")
    if passed is not None and len(passed) < MAX_REMEMBERED:
        passed.add(key)


def _names(kernel, S):
    return "(" + ", ".join(str(kernel.system.coordinates[i]) for i in S) + ")"


# -- float64 range -----------------------------------------------------------------------------------------


#: States of a batch checked in extended precision (the most extreme ones, see :func:`extreme_states`).
MAX_CHECKED = 64


def extreme_states(X, k=MAX_CHECKED):
    """Column indices of the most extreme states of ``X`` (N, B) (all of them if ``B <= k``): largest
    and smallest max-norm, largest and smallest product of magnitudes, smallest non-zero component
    (and the first and last state)."""
    B = X.shape[1]
    if B <= k:
        return np.arange(B)
    return scan_states(X)[2]


#: States per block of :func:`scan_states` (the block's temporaries stay in cache).
SCAN_BLOCK = 16384


def scan_states(X, block=SCAN_BLOCK):
    """One blocked pass over a batch ``X`` (N, B): ``(non-finite count, subnormal count, columns)``.

    The numpy twin of the compiled :meth:`~nambu_bch.numeric.kernels.Kernel.scan`: ``columns``
    are the states with the largest and smallest max-norm, largest and smallest product of
    magnitudes (rows multiplied in order) and smallest non-zero component -- the first one of each
    (like ``numpy.argmax``) -- plus the first and last state.  Each block of ``block`` states is
    reduced while its temporaries are in cache, instead of whole-array passes.
    """
    X = np.asarray(X, dtype=np.float64)
    N, B = X.shape
    nonfinite = subnormal = 0
    # (best value, column) of: max of big, min of big, max of prod, min of prod, min of small
    best = [[-1.0, 0], [np.inf, 0], [-1.0, 0], [np.inf, 0], [np.inf, 0]]
    with np.errstate(all="ignore"):
        for b0 in range(0, B, block):
            A = np.abs(X[:, b0:b0 + block])
            big = A.max(axis=0)                              # NaN propagates: a bad block shows in big.max()
            if not big.max() <= np.finfo(np.float64).max:
                nonfinite += int(np.count_nonzero(~(A <= np.finfo(np.float64).max)))
            prod = A[0].copy()
            for row in A[1:]:
                prod *= row
            np.copyto(A, np.inf, where=~(A > 0))
            small = A.min(axis=0)
            if small.min() < TINY:                           # the smallest non-zero magnitude is subnormal
                subnormal += int(np.count_nonzero(A < TINY))
            for slot, (values, take_max) in enumerate(((big, True), (big, False), (prod, True), (prod, False),
                                                       (small, False))):
                i = int(values.argmax() if take_max else values.argmin())
                v = values[i]
                if (v > best[slot][0]) if take_max else (v < best[slot][0]):
                    best[slot] = [v, b0 + i]
    columns = np.unique(np.array([c for _, c in best] + [0, B - 1], dtype=np.int64))
    return nonfinite, subnormal, columns


def check_range(kernel, x0, K, max_mpmath=64, columns=None):
    """Raise :class:`NumericalRangeError` if one float64 step over- or underflows from ``x0`` (shape (N,) or (N, B)).

    For a batch of more than 64 states only the :func:`extreme_states` are checked; an overflow of
    any other state is still caught after the run (:func:`check_result`).
    """
    X = np.asarray(x0, dtype=np.float64)
    X = X.reshape(X.shape[0], -1)
    X = X[:, extreme_states(X) if columns is None or X.shape[1] <= MAX_CHECKED else columns]
    N, B = X.shape
    out = np.zeros((2, N, B))
    f64 = X.copy()
    with np.errstate(all="ignore"):
        kernel.run_batch(f64, K, 1, 1, out, backend="numpy")
        if np.finfo(np.longdouble).maxexp > 1024:
            ref = X.astype(np.longdouble)
            kernel.run_batch(ref, K, 1, 1, np.zeros((2, N, B), dtype=np.longdouble), backend="numpy")
        else:  # no extended exponent range: mpmath on (a sample of) the states
            import mpmath

            cols = np.unique(np.linspace(0, B - 1, min(B, max_mpmath)).astype(int))
            X, f64 = X[:, cols], f64[:, cols]
            ref = np.empty(X.shape, dtype=object)
            src = kernel.module
            for c in range(X.shape[1]):
                xs = [mpmath.mpf(float(v)) for v in X[:, c]]
                src.run(xs, [mpmath.mpf(float(k)) for k in K], 1, 1, np.zeros((2, N), dtype=object))
                ref[:, c] = xs
        scale = np.maximum(np.abs(X).astype(ref.dtype), np.abs(ref))
        diff = np.abs(f64.astype(ref.dtype) - ref)
        bad = ~(diff <= RANGE_RTOL * scale)
    if np.any(bad):
        i, b = [int(v[0]) for v in np.nonzero(bad)]
        value = ref[i, b]
        big = abs(float(value)) > 1 or not np.isfinite(f64[i, b])
        kind = "overflows" if big else "underflows"
        limit = f"the largest float64 is {np.finfo(np.float64).max:.3g}" if big else f"the smallest normal float64 is {TINY:.3g}"
        where = f"from x0 = {X[:, b].tolist()}" if B > 1 else f"from x0 = {X[:, 0].tolist()}"
        raise NumericalRangeError(
            f"one step of {kernel.word} on {kernel.system.name} {where} {kind} float64 in "
            f"{kernel.system.coordinates[i]} (about {_fmt(value)}; {limit}); rescale the initial state or use dps=... (mpmath)"
        )


def _fmt(value):
    try:
        import mpmath

        return mpmath.nstr(mpmath.mpf(str(value)) if not hasattr(value, "_mpf_") else value, 3)
    except Exception:  # pragma: no cover - formatting only
        return str(value)


def check_result(samples, steps_of_samples, what="the state", start=None):
    """Raise :class:`NumericalRangeError` at the first non-finite sample (overflow during the run).

    ``start``: the step of the sample before ``samples[0]`` (when the samples given are a tail).
    """
    if np.isfinite(samples).all():
        return
    finite = np.isfinite(samples)
    axes = tuple(range(1, samples.ndim))
    first = int(np.argmin(finite.all(axis=axes)))
    lo = int(steps_of_samples[first - 1]) if first > 0 else (start or 0)
    hi = int(steps_of_samples[first])
    raise NumericalRangeError(
        f"{what} overflowed float64 (became inf/nan) between steps {lo} and {hi}: the orbit from this x0 escapes to "
        "infinity, or the initial state is too large for float64, or the step is unstable for it; start from a "
        "bounded orbit, rescale, take a smaller h, or use dps=... (mpmath)"
    )
