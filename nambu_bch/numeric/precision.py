"""Arithmetic beyond plain float64: compensated summation and arbitrary precision (mpmath).

Compensated (Kahan) summation.  A long run adds ~10^7 small increments
``d = O(h)`` to each coordinate; each addition rounds with an error up to
``eps |x| / 2``, and these errors accumulate (random walk ~ ``eps sqrt(n)``, or
linearly when they are biased).  With ``kahan=True`` the generated kernels
carry one compensation ``c_i`` per coordinate and add ``d - c_i`` instead
(:mod:`nambu_bch.numeric.codegen`), so the state is accurate to ``O(eps)``
independent of ``n`` up to the error of the increments themselves
(Higham, *Accuracy and Stability of Numerical Algorithms*, Sect. 4.3;
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. VIII.5).
It costs ~4 extra flops per update and is not available with ``dps``.

Arbitrary precision.  With ``dps=...`` the same generated loop runs on
``mpmath.mpf`` numbers (:func:`run_mpmath`); floats given for ``h``, the
parameters and ``x0`` are converted *exactly* (their binary values), strings
such as ``"0.1"`` are read at ``dps`` digits.  This is the reference for
round-off studies: the float64 run and the mpmath run then iterate the *same*
map, and their difference is pure round-off.  It is ~10^3-10^4 times slower
than float64 per step.

References
----------
Horikoshi, Sect. 5.5 (long runs of Phi^{32123}).
"""

from __future__ import annotations

import weakref

import numpy as np

from ..checks import is_int
from ..errors import InvalidRunError
from .codegen import mpmath_source
from .samples import n_samples

#: Largest accepted ``dps``.
MAX_DPS = 10_000


def check_dps(dps) -> int:
    """``dps`` as an int in ``[15, MAX_DPS]``."""
    if not is_int(dps, 15, MAX_DPS, numpy=True):
        raise InvalidRunError(f"dps must be an integer number of decimal digits between 15 and {MAX_DPS}, got {dps!r}")
    return int(dps)


def to_mpf(value):
    """A number as ``mpmath.mpf`` (floats exactly, strings at the working precision).

    Examples
    --------
    >>> import mpmath
    >>> with mpmath.workdps(30):
    ...     print(to_mpf(0.1), to_mpf("0.1"))
    0.100000000000000005551115123126 0.1
    """
    import mpmath

    if hasattr(value, "_mpf_"):
        return mpmath.mpf(value)
    if isinstance(value, str):
        return mpmath.mpf(value)
    if isinstance(value, (int, np.integer)):
        return mpmath.mpf(int(value))
    return mpmath.mpf(float(value))


def _namespace():
    import mpmath

    ns = {f"_mp_{name}": getattr(mpmath, name) for name in
          ("exp", "expm1", "log", "sin", "cos", "tan", "sinh", "cosh", "tanh", "sqrt", "atan", "asin", "acos")}
    ns["_mp_isfinite"] = mpmath.isfinite
    ns["_mp_pi"], ns["_mp_e"] = mpmath.pi, mpmath.e   # at the working precision, not float64's
    return ns


#: kernel -> {"run": the mpmath step loop, "constants": the mpmath constant function}, built once per kernel
#: and dropped with it (the kernel object itself is never written to).
_MPMATH: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _compiled(kernel) -> dict:
    entry = _MPMATH.get(kernel)
    if entry is None:
        ns = _namespace()
        exec(compile(mpmath_source(kernel.program), f"<nambu_bch mpmath {kernel.program.word}>", "exec"), ns)
        entry = _MPMATH[kernel] = {"run": ns["run"], "constants": kernel.program.constant_function("mpmath")}
    return entry


def clear_cache() -> None:
    """Forget the compiled mpmath loops (they are rebuilt on the next run)."""
    _MPMATH.clear()


def mp_constants(kernel, h, params=None):
    """The constants ``K`` as mpf at the current mpmath precision (missing parameters default to 1)."""
    raw = {str(k): v for k, v in (params or {}).items()}
    args = [to_mpf(raw.get(p.name, 1)) for p in kernel.program.parameters]
    f = _compiled(kernel)["constants"]
    return [to_mpf(k) for k in f(to_mpf(h), *args)]


def run_mpmath(kernel, x0, h, steps, every, params=None, dps=50, progress=None):
    """Iterate in mpmath at ``dps`` digits; samples as an object array of ``mpf`` (shape as :func:`iterate`).

    Parameters
    ----------
    kernel : :class:`~nambu_bch.numeric.kernels.Kernel`
    x0 : array of shape (N,) or (N, batch) (floats, strings or mpf)
    h : float, str or mpf
    steps, every : int
    params : dict, optional
    dps : int
    progress : callable(done_steps) or None
    """
    import mpmath

    run = _compiled(kernel)["run"]
    arr = np.asarray(x0, dtype=object)
    single = arr.ndim == 1
    cols = arr.reshape(arr.shape[0], -1)
    N, B = cols.shape
    out = np.empty((n_samples(steps, every), N, B), dtype=object)
    with mpmath.workdps(dps):
        K = mp_constants(kernel, h, params)
        for b in range(B):
            x = [to_mpf(v) for v in cols[:, b]]
            view = np.empty((out.shape[0], N), dtype=object)
            view[0] = x
            done_before = b * steps
            cb = (lambda n, d=done_before: progress(d + n)) if progress is not None else None
            n = run(x, K, steps, every, view, cb)
            if n < steps:
                view[view == None] = mpmath.nan  # noqa: E711
            out[:, :, b] = view
    return out[:, :, 0] if single else out
