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
calls it, on the column ranges of a threaded run each in its own thread (:func:`scan_range`, :func:`combine`:
the same result as one pass, so a threaded run's guards see what a one-thread run's see).  The numpy twin
is :func:`~nambu_bch.numeric.guards.scan_states`.
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
def _fold(row, nb, src, dst):
    """``dst`` = the max-norm, product and smallest non-zero magnitude of ``src`` (rows 0-2) extended by ``row``;
    returns the counts of non-finite and of subnormal entries of ``row``."""
    bi = src[0]
    pi = src[1]
    si = src[2]
    bo = dst[0]
    po = dst[1]
    so = dst[2]
    nf = 0
    sb = 0
    for b in range(nb):
        a = abs(row[b])
        g = bi[b]
        bo[b] = a if a > g else g
        po[b] = pi[b] * a
        m = si[b]
        so[b] = a if (a < m) & (a > 0.0) else m
        nf += 0 if a <= _MAX else 1
        sb += 1 if (a < _TINY) & (a > 0.0) else 0
    return nf, sb


@njit(nogil=True, error_model="numpy")
def scan_range(X, lo, hi, res):
    """``res[:] = (non-finite count, subnormal count, 5 extreme columns, their 5 values)`` of the states
    ``lo <= b < hi`` of ``X`` (N, B); returns the two counts' sum.

    The values are the int64 bit patterns of the extremes (largest and smallest max-norm, largest and
    smallest product, smallest non-zero component), so the results of disjoint ranges combine into the
    whole batch's exactly (:func:`combine`): each thread of a threaded run scans its own range.  The counts
    are taken while each row is read for the extremes.
    """
    start_result(res)
    return scan_into(X, lo, hi, np.empty((2, 3, 1024)), res)


_TOP = 9223372036854775807
#: The result of scanning no state (counts 0, every extreme still to be found): what :func:`scan_into` extends.
START = (0, 0, 0, 0, 0, 0, 0, -1, _TOP, -1, _TOP, _TOP)


@njit(nogil=True, error_model="numpy")
def start_result(res):
    """``res[:] =`` :data:`START`."""
    for i in range(12):
        res[i] = START[i]


@njit(nogil=True, error_model="numpy")
def scan_into(X, lo, hi, acc, res):
    """Extend ``res`` (the result of :func:`scan_range` over the states before ``lo``, or :func:`start_result`)
    by the states ``lo <= b < hi``; returns the two counts' sum so far.  ``acc``: scratch of shape (2, 3, W),
    the states are reduced in blocks of ``W``.

    A batch kernel calls it on each chunk just before loading that chunk, so the guards' scan of ``x0`` reads
    the batch from memory once with the run instead of in a pass of its own; ranges taken in order give the
    result of one pass, because the comparisons are strict and the first state reaching an extreme is kept.
    """
    N = X.shape[0]
    W = acc.shape[2]
    # two sets of per-state accumulators, each row read from one set and written to the other: written in
    # place, ``big[b] = a if a > big[b] else big[b]`` became a masked store (vmaskmovpd), microcoded and
    # slow on AMD cores -- the pass ran at 1.5 ns per element in cache, 3x a plain read
    nonfinite = res[0]
    subnormal = res[1]
    ibmax = res[2]; ibmin = res[3]; ipmax = res[4]; ipmin = res[5]; ismin = res[6]
    bmax = res[7]; bmin = res[8]; pmax = res[9]; pmin = res[10]; smin = res[11]
    for b0 in range(lo, hi, W):
        nb = min(W, hi - b0)
        row = X[0, b0:b0 + nb]
        big = acc[0, 0]
        prod = acc[0, 1]
        small = acc[0, 2]
        nf = 0
        sb = 0
        for b in range(nb):
            a = abs(row[b])
            big[b] = a
            prod[b] = a
            small[b] = a if a > 0.0 else _INF
            nf += 0 if a <= _MAX else 1
            sb += 1 if (a < _TINY) & (a > 0.0) else 0
        for i in range(1, N):
            f, s = _fold(X[i, b0:b0 + nb], nb, acc[(i - 1) % 2], acc[i % 2])
            nf += f
            sb += s
        big = acc[(N - 1) % 2, 0]
        Ib = big.view(np.int64)
        Ip = acc[(N - 1) % 2, 1].view(np.int64)
        Is = acc[(N - 1) % 2, 2].view(np.int64)
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
    res[7] = bmax
    res[8] = bmin
    res[9] = pmax
    res[10] = pmin
    res[11] = smin
    return nonfinite + subnormal


#: Which extreme each column slot of :func:`scan_range` holds: True for a largest, False for a smallest.
_LARGEST = (True, False, True, False, False)
#: Entries of :func:`scan_range`'s result.
RESULT_SIZE = 12


def combine(parts) -> np.ndarray:
    """The result of :func:`scan_range` over a whole batch from its results over consecutive ranges (in order).

    Counts add up; for each extreme the first range holding the most extreme value wins (strict
    comparison), as the first state reaching it wins within a range -- so the columns are those one
    pass over the whole batch finds.
    """
    res = np.array(parts[0], dtype=np.int64)
    for part in parts[1:]:
        res[0] += part[0]
        res[1] += part[1]
        for slot, largest in enumerate(_LARGEST):
            v, best = part[7 + slot], res[7 + slot]
            if (v > best) if largest else (v < best):
                res[2 + slot], res[7 + slot] = part[2 + slot], v
    return res


def scan(X, res):
    """``res[:7] = (non-finite count, subnormal count, 5 extreme columns)`` of the whole batch ``X`` (N, B)
    (:func:`scan_range` over all states); returns the two counts' sum."""
    full = np.zeros(RESULT_SIZE, dtype=np.int64)
    total = scan_range(X, 0, X.shape[1], full)
    for i in range(7):
        res[i] = full[i]
    return int(total)
