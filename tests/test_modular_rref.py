"""The multi-modular reduced echelon form over QQ (nambu_bch/algebra/modular_rref.py) against the references.

The reduced row echelon form is unique, so the modular result must equal, entry for entry and pivot for pivot,

* sympy's sparse Gauss-Jordan ``DomainMatrix.rref`` over ``QQ`` (``sympy/polys/matrices``; the package's
  plain path), and
* python-flint's ``fmpq_mat.rref`` (FLINT ``fmpq_mat_rref``; fraction-free inside), when installed,

on random sparse matrices (hypothesis): zero rows, rank-deficient (dependent rows), large entries (needing many
primes; beyond int64), augmented systems with an inconsistent right-hand side.  Unlucky primes (Cabay 1971; von zur
Gathen & Gerhard, *Modern Computer Algebra*, Sect. 5.5: ``p`` divides a minor the elimination needs) are built on
purpose from the first prime used, ``2^31 - 1``.  The exact verification and the Hadamard-bound refusal are tested
directly.  The N = 4 single-split system (1234321) is compared end to end with python-flint and with
the modular route at h^4.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy.polys.domains import QQ
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.sdm import SDM

from nambu_bch import System
from nambu_bch.algebra import elimination as E
from nambu_bch.algebra import modular_rref as MR
from nambu_bch.errors import NambuBCHError, ResourceLimitError
from nambu_bch.shadow import shadow_hamiltonians

P0 = MR.prime(0)


def reference(rows: dict, nrows: int, ncols: int):
    """sympy's DomainMatrix.rref over QQ (the package's plain path): ``(R, pivots)`` as dicts of QQ values."""
    M = DomainMatrix.from_rep(SDM({i: dict(r) for i, r in rows.items() if r}, (nrows, ncols), QQ))
    R, pivots = M.rref()
    return {i: dict(r) for i, r in R.rep.to_sdm().items()}, tuple(pivots)


def flint_reference(rows: dict, nrows: int, ncols: int):
    flint = pytest.importorskip("flint")
    M = flint.fmpq_mat(nrows, ncols)
    for i, r in rows.items():
        for j, v in r.items():
            M[i, j] = flint.fmpq(int(QQ.numer(v)), int(QQ.denom(v)))
    R, rank = M.rref()
    e = R.entries()
    out = {i: {j: QQ(int(v.p), int(v.q)) for j, v in enumerate(e[i * ncols:(i + 1) * ncols]) if v} for i in range(rank)}
    return out, tuple(min(r) for r in out.values())


@st.composite
def matrices(draw, max_size=9, big=False):
    """A random sparse rational matrix: some zero rows, some rows combinations of others (rank deficiency), entries
    small or (``big``) up to 200-bit numerators and 100-bit denominators."""
    nrows = draw(st.integers(1, max_size))
    ncols = draw(st.integers(1, max_size))
    num = st.integers(-(2**200), 2**200) if big else st.integers(-9, 9)
    den = st.integers(1, 2**100) if big else st.integers(1, 6)
    rows = {}
    for i in range(nrows):
        if draw(st.integers(0, 4)) == 0:
            continue  # a zero row
        entries = draw(st.dictionaries(st.integers(0, ncols - 1), st.tuples(num, den), max_size=ncols))
        rows[i] = {j: QQ(a, b) for j, (a, b) in entries.items() if a}
    live = [i for i in rows if rows[i]]
    if len(live) >= 2 and draw(st.booleans()) and nrows < max_size:  # a dependent row
        c = QQ(draw(st.integers(-5, 5)), draw(st.integers(1, 5)))
        i, k = live[0], live[1]
        dep = dict(rows[i])
        for j, v in rows[k].items():
            dep[j] = dep.get(j, QQ(0)) + c * v
        rows[nrows] = {j: v for j, v in dep.items() if v}
        nrows += 1
    return {i: r for i, r in rows.items() if r}, nrows, ncols


def _check(rows, nrows, ncols):
    R, piv = MR.rref_qq(rows, nrows, ncols)
    assert (R, piv) == reference(rows, nrows, ncols)
    return R, piv


@settings(max_examples=150, deadline=None, derandomize=True)
@given(matrices())
def test_random_sparse_matrices_match_domainmatrix_rref(m):
    _check(*m)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(matrices(max_size=6, big=True))
def test_large_entries_match_domainmatrix_rref(m):
    """Entries beyond int64 (the Python-int residue path) and echelon entries needing several primes."""
    _check(*m)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(matrices(max_size=8))
def test_random_matrices_match_flint(m):
    rows, nrows, ncols = m
    assert MR.rref_qq(rows, nrows, ncols) == flint_reference(rows, nrows, ncols)


def test_inconsistent_augmented_systems_through_solve_affine(monkeypatch):
    """solve_affine on L | b through the modular route (python-flint off, every QQ block modular) equals the plain
    DomainMatrix path: consistency, pivots, particular solutions, kernel, certificate.  One right-hand side has
    an entry in a row where L is zero: inconsistent, with a certificate."""
    monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
    monkeypatch.setattr(E, "MODULAR_MIN", 1)

    @settings(max_examples=60, deadline=None, derandomize=True)
    @given(matrices(max_size=7), st.integers(0, 3))
    def check(m, k):
        rows, nrows, ncols = m
        columns = [{i: r[j] for i, r in rows.items() if j in r} for j in range(ncols)]
        rhs = [{i: QQ(k + 1) for i in range(nrows) if i % 2 == 0}, {nrows: QQ(1)} if k else {}]
        nr = nrows + 1
        L = E.SparseMatrix.from_columns(columns, nr, QQ)
        new = E.solve_affine(L, rhs)
        old = E.FAST_PATHS
        E.FAST_PATHS = False
        try:
            ref = E.solve_affine(L, rhs)
        finally:
            E.FAST_PATHS = old
        assert new == ref
        if k:
            assert not new.consistent  # row nrows of L is zero, b has a 1 there

    check()


def test_unlucky_prime_rank_drop_is_detected():
    """[[1, 1], [1, 1 + p]] has rank 2 over QQ but rank 1 modulo p = 2^31 - 1, the first prime used: that prime's
    pattern is discarded for the better one of the next prime (Cabay; MCA Sect. 5.5)."""
    A = np.array([[1, 1], [1, (1 + P0) % P0]], dtype=np.int64)
    assert MR.rref_mod_p(A, P0)[1] == [0]  # unlucky indeed
    rows = {0: {0: QQ(1), 1: QQ(1)}, 1: {0: QQ(1), 1: QQ(1 + P0)}}
    R, piv = _check(rows, 2, 2)
    assert piv == (0, 1) and R == {0: {0: QQ(1)}, 1: {1: QQ(1)}}


def test_unlucky_prime_pivot_shift_is_detected():
    """[[p, 1, 1], [0, 0, 1]]: pivots (0, 2) over QQ, (1, 2) modulo p (the pivot moves right); the answer keeps
    the entry 1/p of row 0 exactly."""
    rows = {0: {0: QQ(P0), 1: QQ(1), 2: QQ(1)}, 1: {2: QQ(1)}}
    A = np.array([[0, 1, 1], [0, 0, 1]], dtype=np.int64)
    assert MR.rref_mod_p(A, P0)[1] == [1, 2]
    R, piv = _check(rows, 2, 3)
    assert piv == (0, 2) and R[0] == {0: QQ(1), 1: QQ(1, P0)}


def test_unlucky_first_primes_then_restart_keeps_the_answer():
    """A matrix unlucky for the first two primes (a minor equal to their product) still gives the DomainMatrix
    answer: the accumulation restarts on the first prime with the better pattern."""
    p1 = MR.prime(1)
    rows = {0: {0: QQ(1), 1: QQ(1)}, 1: {0: QQ(1), 1: QQ(1 + P0 * p1)}, 2: {1: QQ(3), 2: QQ(5, 7)}}
    _check(rows, 3, 3)


def test_verification_rejects_a_wrong_candidate():
    """The exact check (row space of A inside that of R) refuses a candidate with one wrong entry."""
    rows = {0: {0: QQ(3), 1: QQ(1)}, 1: {0: QQ(6), 1: QQ(2), 2: QQ(7)}}
    ri, ci, vals = MR.integer_rows(rows)
    good = [(3, [(1, 3)]), (1, [None])]  # R = [[1, 1/3, 0], [0, 0, 1]]: (row denominator, [(num, den)])
    assert MR._verify(ri, ci, vals, [0, 2], [1], good)
    bad = [(2, [(1, 2)]), (1, [None])]
    assert not MR._verify(ri, ci, vals, [0, 2], [1], bad)


def test_wang_reconstruction():
    """Rational reconstruction (MCA Sect. 5.10): -3/7 from its residue modulo 2^31 - 1, and a failure when the
    modulus is too small for the fraction."""
    u = (-3 * pow(7, -1, P0)) % P0
    assert MR._reconstruct(u, P0, 32767) == (-3, 7)
    assert MR._reconstruct((12345 * pow(6789, -1, 10007)) % 10007, 10007, 70) is None


def test_refused_beyond_the_hadamard_prime_bound(monkeypatch):
    """With the bound forced to zero bits (four primes allowed), 300-bit echelon entries cannot be reconstructed:
    refused in one line, a ResourceLimitError (a NambuBCHError), never a wrong answer."""
    monkeypatch.setattr(MR, "hadamard_bits", lambda *a: 0)
    big = QQ(2**300 + 1, 3**150)
    with pytest.raises(ResourceLimitError, match="needed more than 4 primes") as info:
        MR.rref_qq({0: {0: QQ(1), 1: big}, 1: {0: QQ(2), 1: QQ(1), 2: QQ(1)}}, 2, 3)
    assert isinstance(info.value, NambuBCHError) and "\n" not in str(info.value)


def test_hadamard_bits_bounds_every_minor():
    """The bound's bits exceed those of the determinant (Hadamard's inequality), here for a 3 x 3 integer matrix."""
    M = sympy.Matrix([[3, -1, 4], [1, 5, -9], [2, 6, 5]])
    rows = {i: {j: QQ(int(M[i, j])) for j in range(3)} for i in range(3)}
    ri, ci, vals = MR.integer_rows(rows)
    assert abs(M.det()) < 2 ** MR.hadamard_bits(ri, vals, 3)


N4 = ["x1**2/2 + x2**2/2 + x3**2/2 + x4**2/2", "x1**2/2 + x2**2 + 3*x3**2/2 + 2*x4**2", "x1 + x2 + x3 + x4"]


def test_n4_single_split_h4_same_with_modular_and_flint(monkeypatch):
    """Row d of benchmarks/bench_shadow.py --issue14:: N = 4 single split, 1234321, h^4 (630 unknowns, 1204 equations at
    h^4): the members alpha = 0, 1 are identical with the modular route and with python-flint's fmpq_mat.rref (or,
    without python-flint, sympy's DomainMatrix.rref): two eliminations, one answer."""
    S = System("x1 x2 x3 x4", N4, name="n4-single", split="single")
    members = {}
    for route in ("modular", "flint" if E.flint_available() else "sympy"):
        with monkeypatch.context() as mp:
            if route != "flint":
                mp.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
                mp.setattr(E, "MODULAR_MIN", 1 if route == "modular" else 10**9)
            F = shadow_hamiltonians(S, "1234321", 4)
            assert F.exists and [o.status for o in F.details.orders] == ["vanishes", "solved", "vanishes", "solved"]
            members[route] = [tuple(map(sympy.srepr, F.member(alpha=a))) for a in (0, 1)]
    first, second = members.values()
    assert first == second
