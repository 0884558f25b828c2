"""Exact reduced row echelon form over ``QQ`` by multi-modular elimination (numpy only, no python-flint).

The reduced row echelon form ``R`` of a rational matrix ``A`` is unique, and every entry of
``R`` is a quotient of two ``r x r`` minors of ``A`` (Cramer's rule on the pivot rows and
columns, ``r`` the rank).  It is computed here without rational arithmetic (Cabay 1971;
von zur Gathen & Gerhard, *Modern Computer Algebra*, 3rd ed., Sects. 5.4-5.5 and 5.10):

1. every row is scaled by the lcm of its denominators (row scaling keeps ``R``): an
   integer matrix ``A``;
2. for primes ``p < 2^31`` (a product of two residues fits ``int64``) the reduced echelon
   form ``R_p`` of ``A mod p`` is computed by vectorised Gauss-Jordan elimination in numpy;
3. the residues of ``R``'s entries are combined by the Chinese remainder theorem and the
   rational entries recovered by rational reconstruction (Wang's half-extended Euclid, with
   Monagan's remark that a running row denominator makes most entries plain integers:
   M. Monagan, *Maximal quotient rational reconstruction*, ISSAC 2004; MCA Sect. 5.10);
4. the candidate is VERIFIED exactly before it is returned: every row of ``A`` equals
   ``sum_k A[i, P_k] R_k`` (the row space of ``A`` lies in that of ``R``) and ``r`` is the rank of
   ``A mod p`` (at most the rank over ``QQ``), so the two row spaces agree and ``R`` is *the*
   reduced echelon form of ``A`` -- whatever the primes were.

Unlucky primes (``p`` divides a minor the elimination needs: the rank drops or a pivot moves
right) are detected by comparing pivot patterns: the pattern over ``QQ`` is the one of
largest rank and, among those, lexicographically first, since a minor non-zero mod ``p``
is non-zero over ``QQ``; a prime with a worse pattern is dropped, a better one restarts the
accumulation.  Termination: every minor is at most the Hadamard bound ``H`` (product of the
``r`` largest row norms), so once the product ``M`` of the lucky primes exceeds ``2 H^2``
reconstruction is exact (numerator and denominator below ``sqrt(M / 2)``, MCA Sect. 5.10) and at
most ``log_p H`` primes divide the pivot minor (unlucky); :func:`rref_qq` stops after
``(3 log2 H + 1) / 30 + 4`` primes with a one-line :class:`~nambu_bch.errors.ResourceLimitError`
(never reached for a correct implementation: the bound is the proof that the loop ends).  In
practice three primes suffice for the N = 4 shadow systems (echelon entries with 40-bit
numerators and 34-bit denominators).

References
----------
S. Cabay, *Exact solution of linear equations*, SYMSAM 1971; J. D. Dixon, Numer. Math. 40 (1982) 137
(p-adic lifting, the alternative); M. Monagan, ISSAC 2004; von zur Gathen & Gerhard, *Modern Computer
Algebra*, ch. 5 (Sects. 5.4 CRT, 5.5 modular determinant, 5.10 rational reconstruction).
"""

from __future__ import annotations

import math

import numpy as np
from sympy import prevprime
from sympy.polys.domains import QQ

from ..errors import ResourceLimitError

#: The largest prime used; the next ones are the primes below it (``p < 2^31``: products of residues < 2^62).
FIRST_PRIME = 2147483647
_PRIMES: list = [FIRST_PRIME]


def prime(k: int) -> int:
    """The ``k``-th prime below ``2^31`` (``prime(0) = 2^31 - 1``), computed once."""
    while len(_PRIMES) <= k:
        _PRIMES.append(int(prevprime(_PRIMES[-1])))
    return _PRIMES[k]


def integer_rows(rows: dict):
    """The rows scaled by the lcm of their denominators: ``(rows, cols, values)`` triplets as lists of ints.

    Row scaling does not change the reduced echelon form.
    """
    ri, ci, vals = [], [], []
    for k, (i, row) in enumerate(sorted(rows.items())):
        den = 1
        for v in row.values():
            den = math.lcm(den, int(QQ.denom(v)))
        for j, v in row.items():
            ri.append(k)
            ci.append(j)
            vals.append(int(QQ.numer(v)) * (den // int(QQ.denom(v))))
    return ri, ci, vals


def rref_mod_p(A: np.ndarray, p: int):
    """Reduced echelon form of ``A mod p`` (``int64``, entries in ``[0, p)``, ``p < 2^31``), in place.

    Gauss-Jordan elimination, one pivot column at a time; the row operations of a pivot touch
    only the rows with a non-zero entry in its column and the columns from it on (the columns
    to its left are already zero in the pivot row).  Returns ``(R, pivots)``: the ``rank`` non-zero
    rows (pivot entries one) and the pivot columns.

    >>> R, piv = rref_mod_p(np.array([[2, 4, 1], [1, 2, 3]], dtype=np.int64), 7)
    >>> R.tolist(), piv
    ([[1, 2, 0], [0, 0, 1]], [0, 2])
    """
    m, n = A.shape
    pivots: list = []
    r = 0
    for c in range(n):
        if r == m:
            break
        nz = np.flatnonzero(A[r:, c])
        if not nz.size:
            continue
        k = r + int(nz[0])
        if k != r:
            A[[r, k]] = A[[k, r]]
        inv = pow(int(A[r, c]), -1, p)
        if inv != 1:
            A[r, c:] = A[r, c:] * inv % p
        col = A[:, c].copy()
        col[r] = 0
        others = np.flatnonzero(col)
        if others.size:
            A[others, c:] = (A[others, c:] - col[others, None] * A[r, c:]) % p
        pivots.append(c)
        r += 1
    return A[:r], pivots


def _residues(vals: list, p: int, small: np.ndarray | None) -> np.ndarray:
    if small is not None:
        return small % p
    return np.array([v % p for v in vals], dtype=np.int64)


def _better(a: list, b: list) -> bool:
    """Pivot pattern ``a`` is nearer the one over ``QQ`` than ``b``: larger rank, then lexicographically first."""
    return (len(a), [-c for c in a]) > (len(b), [-c for c in b])


def _reconstruct(u: int, M: int, bound: int):
    """Wang's rational reconstruction: ``(n, d)`` with ``n/d = u mod M``, ``|n| <= bound``, ``0 < d <= bound``; or None."""
    r0, r1, t0, t1 = M, u, 0, 1
    while r1 > bound:
        q = r0 // r1
        r0, r1, t0, t1 = r1, r0 - q * r1, t1, t0 - q * t1
    if t1 == 0 or abs(t1) > bound or math.gcd(r1, abs(t1)) != 1:
        return None
    return (r1, t1) if t1 > 0 else (-r1, -t1)


def _rationals(X: np.ndarray, M: int):
    """The rational matrix with residues ``X`` (object array of ints in ``[0, M)``), row by row: ``[(D, entries)]``,
    an entry ``(n, d)`` meaning ``n / d`` with ``d | D``, or None for zero; None when some entry fails.

    A running row denominator ``D`` (the lcm of the denominators so far): an entry ``u`` with ``v = u D mod M``
    (symmetric) at most ``B = sqrt(M / 2)`` is ``v / D``; otherwise Wang's reconstruction of ``u`` itself.  Both are
    right once ``M > 2 H^2`` (``H`` bounds every minor, so numerators and ``D``, a divisor of the pivot minor, are
    below ``B``: ``|v b - a D| <= 2 B H < M`` for the true ``a / b``); before that a wrong candidate is possible and
    :func:`_verify` rejects it."""
    bound = math.isqrt(M // 2)
    half = M // 2
    out = []
    for row in X:
        D = 1
        vals = []
        for u in row:
            if not u:
                vals.append(None)
                continue
            v = u * D % M
            if v > half:
                v -= M
            if abs(v) <= bound:
                vals.append((v, D))
                continue
            nd = _reconstruct(u, M, bound)
            if nd is None:
                return None
            D = math.lcm(D, nd[1])
            if D > bound:
                return None
            vals.append(nd)
        out.append((D, vals))
    return out


def _verify(ri, ci, vals, pivots, free, cand) -> bool:
    """Exactly: every integer row ``a`` of ``A`` equals ``sum_k a[P_k] R_k`` on the free columns (on the pivot
    columns it holds by construction).  ``cand`` holds per echelon row its denominator ``D`` and the
    numerators ``(n, d)`` of ``n / d`` (``d`` divides ``D``)."""
    r = len(pivots)
    pos_p = {c: k for k, c in enumerate(pivots)}
    pos_f = {c: k for k, c in enumerate(free)}
    Dall = 1
    for D, _ in cand:
        Dall = math.lcm(Dall, D)
    G = np.zeros((r, len(free)), dtype=object)
    for k, (_, row) in enumerate(cand):
        for j, e in enumerate(row):
            if e is not None:
                G[k, j] = e[0] * (Dall // e[1])
    rows: dict = {}
    for i, j, v in zip(ri, ci, vals):
        rows.setdefault(i, []).append((j, v))
    for entries in rows.values():
        acc = np.zeros(len(free), dtype=object)
        for j, v in entries:
            k = pos_p.get(j)
            if k is not None:
                acc -= v * G[k]
            else:
                acc[pos_f[j]] += v * Dall
        if any(acc):
            return False
    return True


def hadamard_bits(ri, vals, rank: int) -> int:
    """``log2`` (rounded up) of the Hadamard bound: the product of the ``rank`` largest row 2-norms of the integer matrix."""
    sq: dict = {}
    for i, v in zip(ri, vals):
        sq[i] = sq.get(i, 0) + v * v
    norms = sorted(sq.values(), reverse=True)[:rank]
    return sum((s.bit_length() + 1) // 2 + 1 for s in norms)


def rref_qq(rows: dict, nrows: int, ncols: int):
    """The reduced row echelon form over ``QQ`` of ``{row: {column: value}}`` (values in sympy's ``QQ``): ``(R, pivots)``.

    Multi-modular (module docstring): elimination modulo primes ``p < 2^31`` in numpy, Chinese
    remaindering, rational reconstruction, and an exact check of the candidate; primes are
    added until the candidate verifies.  ``R`` is ``{k: {column: value}}`` for the ``rank``
    non-zero rows (pivot entries one), identical to ``DomainMatrix.rref`` over ``QQ``.

    Raises
    ------
    ResourceLimitError -- more primes than the Hadamard bound allows were needed (cannot happen for a
    correct elimination; the bound makes the loop finite).

    >>> R, piv = rref_qq({0: {0: QQ(2), 1: QQ(1, 3)}, 1: {0: QQ(4), 1: QQ(1)}, 2: {1: QQ(5)}}, 3, 2)
    >>> {k: {j: str(v) for j, v in r.items()} for k, r in R.items()}, piv
    ({0: {0: '1'}, 1: {1: '1'}}, (0, 1))
    >>> R, piv = rref_qq({0: {0: QQ(3), 1: QQ(1), 2: QQ(2)}, 1: {0: QQ(6), 1: QQ(2), 2: QQ(7)}}, 2, 3)
    >>> {k: {j: str(v) for j, v in r.items()} for k, r in R.items()}, piv
    ({0: {0: '1', 1: '1/3'}, 1: {2: '1'}}, (0, 2))
    """
    ri, ci, vals = integer_rows(rows)
    m = len(rows)
    if not vals:
        return {}, ()
    small = np.array(vals, dtype=np.int64) if max(abs(v) for v in vals) < 2**62 else None
    ri_a, ci_a = np.array(ri, dtype=np.intp), np.array(ci, dtype=np.intp)
    best: list | None = None
    X = M = None
    # Hadamard: every minor is below 2^bits; at most bits/30 primes (> 2^30) divide the pivot minor (unlucky),
    # and (2 bits + 1)/30 lucky ones give M > 2 H^2 (reconstruction exact): the loop ends within this many primes
    bits = hadamard_bits(ri, vals, min(m, ncols))
    limit = (3 * bits + 1) // 30 + 4
    for k in range(limit):
        p = prime(k)
        A = np.zeros((m, ncols), dtype=np.int64)
        A[ri_a, ci_a] = _residues(vals, p, small)
        Rp, piv = rref_mod_p(A, p)
        if best is None or _better(piv, best):
            best, X, M = piv, None, 1
            pivot_set = set(best)
            free = [c for c in range(ncols) if c not in pivot_set]
        elif piv != best:
            continue  # unlucky prime
        res = Rp[:, free] if free else np.zeros((len(best), 0), dtype=np.int64)
        if X is None:
            X = res.astype(object)
        else:
            Xp = np.array(X % p, dtype=np.int64)
            t = (res - Xp) % p * pow(M % p, -1, p) % p
            X = X + M * t.astype(object)
        M *= p
        cand = _rationals(X, M)
        if cand is None or not _verify(ri, ci, vals, best, free, cand):
            continue
        R = {}
        for r, (c, (_, row)) in enumerate(zip(best, cand)):
            out = {c: QQ.one}
            for j, e in zip(free, row):
                if e is not None:
                    out[j] = QQ(e[0], e[1])
            R[r] = out
        return R, tuple(best)
    raise ResourceLimitError(
        f"the modular elimination of a {nrows} x {ncols} matrix over QQ needed more than {limit} primes "
        "(the Hadamard bound): refused")
