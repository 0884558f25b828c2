"""One compiled pass over a batch of states for the input guards: system-independent, so compiled once.

One pass over a batch ``X`` (N, B): what the input guards need.  Blocks of
``W`` states: the per-state max-norm, product and smallest non-zero magnitude (rows combined in
order, as :func:`~nambu_bch.numeric.guards.extreme_states`), then the block's extremes.  Those
are found on the IEEE bit patterns as int64 -- ordered like the values for the non-negative
doubles compared here -- so the reductions vectorise without fast-math; the first state reaching
a new extreme is kept, like ``numpy.argmax``.  (A non-finite input makes the columns meaningless;
the caller then refuses the batch on the counts.)

It was part of every generated kernel module (compiled once per kernel, 1-1.4 s each cold); it
depends on nothing but the batch, so it lives here, compiled once and cached by numba in the
package's private cache (:func:`nambu_bch.compiled.njit`); :func:`~nambu_bch.numeric.kernels.Kernel.scan`
calls it.  The numpy twin is :func:`~nambu_bch.numeric.guards.scan_states`.
"""

import math

import numpy as np

from ..compiled import njit

_INF, _MAX, _TINY = math.inf, 1.7976931348623157e308, 2.2250738585072014e-308


@njit(nogil=True, error_model="numpy")
def _first(a, n, v):
    """The first ``i < n`` with ``a[i] == v`` (0 if none, like ``numpy.argmax`` of ``a[:n] == v``): a loop, since
    the array expression and ``argmax`` cost numba ~1.5 s to compile (five of them), the loop ~0.1 s."""
    for i in range(n):
        if a[i] == v:
            return i
    return 0


@njit(nogil=True, error_model="numpy")
def scan(X, res):
    """``res[:] = (non-finite count, subnormal count, 5 extreme columns)`` of ``X`` (N, B); returns the two counts' sum."""
    N = X.shape[0]
    B = X.shape[1]
    W = 1024
    big = np.empty(W)
    prod = np.empty(W)
    small = np.empty(W)
    Ib = big.view(np.int64)
    Ip = prod.view(np.int64)
    Is = small.view(np.int64)
    nonfinite = 0
    subnormal = 0
    top = np.int64(9223372036854775807)
    bmax = np.int64(-1); bmin = top; pmax = np.int64(-1); pmin = top; smin = top
    ibmax = 0; ibmin = 0; ipmax = 0; ipmin = 0; ismin = 0
    for b0 in range(0, B, W):
        nb = min(W, B - b0)
        row = X[0, b0:b0 + nb]
        for b in range(nb):
            a = abs(row[b])
            big[b] = a
            prod[b] = a
            small[b] = a if a > 0.0 else _INF
        for i in range(1, N):
            row = X[i, b0:b0 + nb]
            for b in range(nb):
                a = abs(row[b])
                g = big[b]
                big[b] = a if a > g else g
                prod[b] *= a
                m = small[b]
                small[b] = a if (a < m) & (a > 0.0) else m
        for i in range(N):
            row = X[i, b0:b0 + nb]
            nf = 0
            sb = 0
            for b in range(nb):
                a = abs(row[b])
                nf += 0 if a <= _MAX else 1
                sb += 1 if (a < _TINY) & (a > 0.0) else 0
            nonfinite += nf
            subnormal += sb
        m1 = Ib[0]; m2 = Ib[0]; m3 = Ip[0]; m4 = Ip[0]; m5 = Is[0]
        for b in range(nb):
            v = Ib[b]
            m1 = max(m1, v)
            m2 = min(m2, v)
            v = Ip[b]
            m3 = max(m3, v)
            m4 = min(m4, v)
            m5 = min(m5, Is[b])
        if m1 > bmax:
            bmax = m1; ibmax = b0 + _first(Ib, nb, m1)
        if m2 < bmin:
            bmin = m2; ibmin = b0 + _first(Ib, nb, m2)
        if m3 > pmax:
            pmax = m3; ipmax = b0 + _first(Ip, nb, m3)
        if m4 < pmin:
            pmin = m4; ipmin = b0 + _first(Ip, nb, m4)
        if m5 < smin:
            smin = m5; ismin = b0 + _first(Is, nb, m5)
    res[0] = nonfinite
    res[1] = subnormal
    res[2] = ibmax
    res[3] = ibmin
    res[4] = ipmax
    res[5] = ipmin
    res[6] = ismin
    return nonfinite + subnormal
