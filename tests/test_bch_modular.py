"""The sparse multi-modular BCH engine (nambu_bch.bch.modular) against the dense engine and the literature."""

from math import factorial, lcm

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from sympy.polys.constructor import construct_domain

from nambu_bch.bch import formal_bch, lyndon_words, standard_bracketing, witt_dimension
from nambu_bch.bch import formal as formal_module
from nambu_bch.bch import modular
from nambu_bch.bch.lyndon import standard_factorization
from nambu_bch.errors import InvalidOrderError
from nambu_bch.integrators import composition
from strategies import compositions

R = sympy.Rational


@pytest.fixture(autouse=True)
def sparse_at_every_degree(monkeypatch):
    """formal_bch uses the sparse engine from SPARSE_FROM_DEGREE on (or above DENSE_COLD_WORDS words, or once it
    has run); here it is exercised at every degree."""
    monkeypatch.setattr(formal_module, "SPARSE_FROM_DEGREE", 1)


def _dense(spec, degree):
    comp = composition(spec)
    return formal_module._formal_dense(comp, tuple(sorted(set(comp.pieces))), degree)


def _same(A, B):
    return all(A.scaled_terms(d) == B.scaled_terms(d) for d in range(1, A.max_degree + 1))


# -- tables ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("g,n", [(2, 9), (3, 6), (4, 4)])
def test_lyndon_table_is_duval_order_with_standard_factorisations(g, n):
    """Reutenauer Sect. 5.1: words (lexicographic within a length) and ``w = u v``, ``v`` the longest Lyndon suffix."""
    words, lengths, left, right = modular.lyndon_table(g, n)
    for d in range(1, n + 1):
        ours = [tuple(int(a) for a in words[i, :d]) for i in range(len(lengths)) if lengths[i] == d]
        assert ours == lyndon_words(g, d)
        assert len(ours) == witt_dimension(g, d)
    for i in range(len(lengths)):
        if lengths[i] > 1:
            w = tuple(int(a) for a in words[i, : lengths[i]])
            u, v = standard_factorization(w)
            assert tuple(int(a) for a in words[left[i], : lengths[left[i]]]) == u
            assert tuple(int(a) for a in words[right[i], : lengths[right[i]]]) == v


def test_garner_recovers_signed_integers():
    """Mixed-radix CRT (Knuth 4.3.2) in the symmetric range, beyond int64."""
    primes = list(modular.PRIMES[:4])
    values = [0, 1, -1, 10**30, -(10**30) + 7, 2**100 - 3]
    residues = np.array([[v % p for p in primes] for v in values], dtype=np.int64)
    assert modular._garner(residues, primes) == values


def _garner_by_python_ints(residues, moduli):
    """The CRT one value at a time in Python ints (``sum r_i M_i (M_i^-1 mod p_i) mod M``), symmetric range."""
    M = 1
    for p in moduli:
        M *= p
    out = []
    for row in residues.tolist():
        v = sum(r * (M // p) * pow(M // p, -1, p) for r, p in zip(row, moduli)) % M
        out.append(v - M if v > M // 2 else v)
    return out


@pytest.mark.parametrize("k", [1, 2, 7, 17])
def test_garner_equals_the_textbook_crt(k):
    """The limb-wise Horner reconstruction against the plain CRT, random residues and the range's ends."""
    primes = list(modular.PRIMES[:k])
    M = 1
    for p in primes:
        M *= p
    rng = np.random.default_rng(k)
    residues = np.stack([rng.integers(0, p, size=300) for p in primes], axis=1)
    ends = [0, 1, -1, M // 2, -(M // 2) + (M + 1) % 2, M // 2 - 1]  # the largest and smallest representable
    residues = np.concatenate([residues, np.array([[v % p for p in primes] for v in ends], dtype=np.int64)])
    expected = _garner_by_python_ints(residues, primes)
    assert expected[-len(ends):] == ends
    assert modular._garner(residues, primes) == expected
    assert modular._garner(residues[:0], primes) == []


@pytest.mark.parametrize("values,q,n", [([1, 1], 1, 12), ([1, 2, -3], 2, 9), ([0, 7, -5, 1], 6, 5)])
def test_factor_tables_equal_modular_powers(values, q, n):
    """Running products for c^r / r! and (-1)^(k+1) / k equal the entries by modular powers, prime by prime."""
    moduli = list(modular.PRIMES[:3])
    cpow, logk = modular._factor_tables(moduli, values, q, n)
    for i, p in enumerate(moduli):
        for t, v in enumerate(values):
            c = v % p * pow(q, p - 2, p) % p
            assert cpow[i, t].tolist() == [pow(c, r, p) * pow(factorial(r), p - 2, p) % p for r in range(n + 1)]
        assert logk[i, 1:].tolist() == [(1 if k % 2 else p - 1) * pow(k, p - 2, p) % p for k in range(1, n + 1)]


def test_numerator_bound_in_integers_equals_the_rational_formula():
    """The bound in integer arithmetic is floor(D (d-1)! C^d surj(d) / d!) + 1, as with Fractions."""
    from fractions import Fraction

    for total in (Fraction(2), Fraction(5, 2), Fraction(7, 6)):
        for d in range(1, 23):
            den = factorial(d) * lcm(*range(1, 23)) * total.denominator**d
            value = den * factorial(d - 1) * total**d * modular._surjection_sum(d) / factorial(d)
            assert modular.numerator_bound(d, total, den) == int(value) + 1


# -- the engines agree exactly -----------------------------------------------------------------------------

@pytest.mark.parametrize(
    "spec,degree",
    [("12", 12), ("121", 11), ("12321", 9), ("123", 8), ("21", 8), ("3:1/2,1:1,3:1/2", 8), ("1234321", 6),
     ("1:1/3,2:1/2,1:2/3,3:1,2:1/2", 7), ("1:999/7,2:1,1:-992/7", 8)],
)
def test_sparse_engine_equals_dense_engine(spec, degree):
    """Same numerators, same denominators, same Lyndon trees in the same order (the dense engine:
    associative log over all g^d words + residual solve with the full P_w expansions)."""
    A, B = formal_bch(spec, degree), _dense(spec, degree)
    assert _same(A, B)
    assert len(A) == len(B) > 0


def test_a_program_outgrowing_its_workspace_resumes_at_its_class(monkeypatch):
    """The solve's program table is allocated in Python (``modular._engine``; compiled code allocates nothing): with
    room for one inner node, each class whose program needs more comes back before it is touched and is solved again,
    from its start, in a larger table; the numerators are those of a table large enough from the start."""
    dens = [factorial(d) * lcm(*range(1, 8)) for d in range(8)]
    args = ([0, 1, 2], [1, 1, 1], 1, 3, 7, dens)
    expected = modular.lyndon_numerators(*args)
    starts, solve = [], modular._solve
    monkeypatch.setattr(modular, "_PROGRAM_CAPACITY", 1)
    monkeypatch.setattr(modular, "_solve", lambda *a: starts.append(int(a[15])) or solve(*a))
    assert modular.lyndon_numerators(*args) == expected
    assert len(starts) > 2 and starts[0] == 0 and starts == sorted(starts)


def test_algebraic_coefficients_use_the_dense_engine():
    """Triple jump (2^(1/3)): not rational, so the series comes from the dense engine with field elements."""
    B = formal_bch("yoshida:121", 5)
    assert B.domain != sympy.QQ and B.degrees == (1, 5)


@settings(max_examples=30, deadline=None)
@given(compositions(max_factors=6, numerators=9, denominators=7))
def test_property_sparse_equals_dense(comp):
    """Random consistent rational compositions (zeros, negatives, repeated letters): identical series."""
    n = 7 if len(set(comp.pieces)) < 3 else 6
    A = formal_bch(comp, n)
    B = formal_module._formal_dense(comp, tuple(sorted(set(comp.pieces))), n)
    assert _same(A, B)


@pytest.mark.parametrize("spec,degree", [("12", 10), ("12321", 9), ("1:1/3,2:1/2,1:2/3,3:1,2:1/2", 7)])
def test_numerator_bound_holds(spec, degree):
    """The a-priori bound (dual PBW basis, Reutenauer Thm. 5.3) dominates every actual numerator."""
    comp = composition(spec)
    B = formal_bch(comp, degree)
    scalars = formal_module._Scalars(tuple(comp.coefficients))
    total = sympy.Rational(sum(abs(v) for v in scalars.values), scalars.q)
    from fractions import Fraction

    total = Fraction(int(total.p), int(total.q))
    for d in B.degrees:
        den, items = B.scaled_terms(d)
        bound = modular.numerator_bound(d, total, den)
        assert max(abs(int(n)) for n, _ in items) <= bound


def test_huge_coefficients_many_primes_or_python_ints():
    """Coefficients 10^30: 17 primes, still identical to the dense engine; 10^80: the bound needs more than
    MAX_PRIMES primes, the dense Python-int engine runs.  Degree 2 is (a - b)/2 [X, Y] (HLW Sect. III.4)."""
    for e in (30, 80):
        a, b = sympy.Integer(10) ** e, 1 - sympy.Integer(10) ** e
        dens = [factorial(d) * lcm(*range(1, 6)) for d in range(6)]
        stats = {}
        out = modular.lyndon_numerators([0, 1, 0], [int(a), 1, int(b)], 1, 2, 5, dens, stats)
        assert (out is None) == (e == 80)
        assert (stats["primes"] >= 17) if e == 30 else stats == {}
        spec = f"1:{a},2:1,1:{b}"
        B = formal_bch(spec, 5)
        assert B.terms(2) == [((a - b) / 2, (1, 2))]
        assert _same(B, _dense(spec, 5))


# -- literature values at high degree -------------------------------------------------------------------

def test_hofstaetter_counts_at_degree_18():
    """log(e^A e^B) through degree 18 in the Lyndon basis: 31042 basis elements, 21573 non-zero coefficients
    (Hofstätter, bch user manual, arXiv:2102.06570, Sect. 5, table 'Lyndon basis')."""
    B = formal_bch("12", 18)
    assert sum(witt_dimension(2, d) for d in range(1, 19)) == 31042
    assert len(B) == 21573


@pytest.mark.parametrize("m", [13, 14, 16])
def test_bernoulli_coefficients_of_ad_powers(m):
    """log(e^X e^Y) = X + ad_X/(1 - e^(-ad_X)) Y + O(Y^2) and = Y + ad_Y/(e^(ad_Y) - 1) X + O(X^2)
    (Hairer-Lubich-Wanner, Sect. III.4.2): the Lyndon words 0^m 1 ([A,[A,...,[A,B]]] = ad_A^m B) and
    0 1^m ([[[A,B],B],...,B] = (-1)^m ad_B^m A) carry B_m/m! with B_1 = +1/2 and (-1)^m B_m/m!
    with B_1 = -1/2."""
    B = formal_bch("12", m + 1)
    terms = dict((t, c) for c, t in B.terms(m + 1))
    left = standard_bracketing((0,) * m + (1,), (1, 2))
    right = standard_bracketing((0,) + (1,) * m, (1, 2))
    bern = sympy.bernoulli(m)  # B_m, the same in both conventions for m >= 2
    assert terms.get(left, 0) == bern / sympy.factorial(m)
    assert terms.get(right, 0) == (-1) ** m * bern / sympy.factorial(m)
    assert (bern != 0) == (m % 2 == 0)


# -- size guard ----------------------------------------------------------------------------------------

def test_degrees_accepted_and_refused_by_the_sparse_estimate():
    """No cap below degree 20 (2 generators) and 14 (3 generators); refusals name the estimate."""
    assert formal_module.check_degree(20, 2) == 20 and formal_module.check_degree(14, 3) == 14
    with pytest.raises(InvalidOrderError, match="Witt's formula.*same-content Lyndon pairs"):
        formal_module.check_degree(23, 2)
    with pytest.raises(InvalidOrderError, match="largest accepted degree for 3 generators is 14"):
        formal_module.check_degree(15, 3)
    with pytest.raises(InvalidOrderError, match="dense engine"):
        formal_module.check_degree(16, 2, dense=True)
    with pytest.raises(InvalidOrderError, match="degree 15 in 3 generators"):
        formal_bch("12321", 15)


def test_pair_estimate_matches_the_tables():
    """``estimate_size(...)["pairs"]`` counts the same-content Lyndon pairs of the top degree (the classes the
    solve walks): checked by grouping the words."""
    for g, n in [(2, 10), (3, 6)]:
        words, lengths, _, _ = modular.lyndon_table(g, n)
        groups: dict = {}
        for i in range(len(lengths)):
            if lengths[i] != n:
                continue
            w = tuple(int(a) for a in words[i, : lengths[i]])
            key = (len(w),) + tuple(w.count(a) for a in range(g))
            groups[key] = groups.get(key, 0) + 1
        assert formal_module.estimate_size(g, n)["pairs"] == sum(m * (m - 1) // 2 for m in groups.values())


def test_without_numba_the_dense_engine_gives_the_same_series(monkeypatch):
    """NAMBU_BCH_DISABLE_NUMBA=1 (or numba missing): formal_bch falls back to the pure-Python dense engine,
    coefficient for coefficient the same series (Eq. BCH2 for 12321, and a non-symmetric word)."""
    from nambu_bch.bch.formal import formal_bch

    for word, degree in (("12321", 7), ("123", 6)):
        fast = formal_bch(word, degree)
        monkeypatch.setenv("NAMBU_BCH_DISABLE_NUMBA", "1")
        dense = formal_bch(word, degree)
        monkeypatch.delenv("NAMBU_BCH_DISABLE_NUMBA")
        assert all(fast.terms(d) == dense.terms(d) for d in range(1, degree + 1))


# -- chains and Eriksen's relation -----------------------------------------------------------------------

@pytest.mark.parametrize("g,n", [(2, 9), (3, 6)])
def test_chain_entries_are_the_core_entries(g, n):
    """Eq. (2) of modular._solve: ``<P_v, w> = [w starts with a^K_v] <P_core, w[K_v:]>`` for equal-content Lyndon
    words ``v < w``, against the full expansion of ``P_v`` (Reutenauer Thm. 5.1), and ``P_v = ad_a^K P_core``."""
    from nambu_bch.bch.lyndon import lyndon_expansion, word_index

    table = modular.lyndon_table(g, n)
    words, lengths, left, right = table
    K, core, lead, span = table.chains
    word = [tuple(int(a) for a in words[i, : lengths[i]]) for i in range(len(lengths))]
    checked = 0
    for v in range(len(lengths)):
        if lengths[v] < 2:
            continue
        a, kv, u = word[v][0], int(K[v]), word[core[v]]
        assert word[v] == (a,) * kv + u and int(lead[v]) >= kv
        assert standard_bracketing(word[v]) == _ad_power(a, kv, standard_bracketing(u))
        idx, coef = lyndon_expansion(word[v], g)
        full = dict(zip(idx.tolist(), coef.tolist()))
        ui, uc = lyndon_expansion(u, g)
        core_entries = dict(zip(ui.tolist(), uc.tolist()))
        for w in range(len(lengths)):
            if lengths[w] == lengths[v] and sorted(word[w]) == sorted(word[v]) and word[w] > word[v]:
                starts = word[w][:kv] == (a,) * kv
                expected = core_entries.get(word_index(word[w][kv:], g), 0) if starts else 0
                assert full.get(word_index(word[w], g), 0) == expected
                checked += 1
    assert checked > 100


def _ad_power(a, k, tree):
    for _ in range(k):
        tree = (a, tree)
    return tree


@pytest.mark.parametrize("spec", ["12", "21"])
@pytest.mark.parametrize("degree", [2, 6, 10])
def test_even_top_degree_by_eriksen_equals_the_dense_engine(spec, degree):
    """Eriksen (J. Math. Phys. 9 (1968) 790, Sect. III.A): Z_even = tanh(ad_A/2) Z_odd for log(e^{aA} e^{bB}) (sign
    flipped for e^{bB} e^{aA}); the sparse engine takes the even top degree from it, the dense engine expands."""
    assert modular._eriksen_sign([0, 1] if spec[0] == "1" else [1, 0], 2, degree)
    assert _same(formal_bch(spec, degree), _dense(spec, degree))


def test_tanh_half_coefficients():
    """tanh(x/2) = x/2 - x^3/24 + x^5/240 - 17 x^7/40320 + ... (the beta_k of Eq. (3) in modular._even_top)."""
    x = sympy.Symbol("x")
    series = sympy.series(sympy.tanh(x / 2), x, 0, 12).removeO()
    got = modular._tanh_half_coefficients(11)
    assert {k: R(v.numerator, v.denominator) for k, v in got.items()} == {k: series.coeff(x, k) for k in range(1, 12, 2)}


def test_number_theory_helpers_match_sympy():
    """The size guard's and the bound's small helpers (no sympy on the hot path) against sympy: Möbius function and
    divisors (Witt's formula, Reutenauer Cor. 4.14), sum_k (k-1)! S(d, k) (Stirling numbers, modular.numerator_bound)."""
    from nambu_bch.bch.lyndon import divisors, mobius

    assert [mobius(n) for n in range(1, 300)] == [int(sympy.mobius(n)) for n in range(1, 300)]
    assert all(divisors(n) == sympy.divisors(n) for n in range(1, 120))
    stirling = sympy.functions.combinatorial.numbers.stirling
    assert [modular._surjection_sum(d) for d in range(1, 25)] == [
        sum(factorial(k - 1) * int(stirling(d, k)) for k in range(1, d + 1)) for d in range(1, 25)
    ]


def test_engine_choice_dense_before_numba_starts_sparse_after(monkeypatch):
    """formal.DENSE_COLD_WORDS: in a process where the sparse engine has not run, a small series (g^n <= 3^9) takes
    the dense engine (no numba import); once the sparse engine has run, it takes the sparse one; same series."""
    monkeypatch.setattr(formal_module, "SPARSE_FROM_DEGREE", 32)
    monkeypatch.setattr(modular, "runs", 0)
    dense = formal_bch("12321", 8)  # 3^8 words
    assert modular.runs == 0
    formal_bch("123", 10)  # 3^10 words > DENSE_COLD_WORDS: sparse
    assert modular.runs == 1
    sparse = formal_bch("12321", 8)
    assert modular.runs == 2
    assert _same(dense, sparse)


def test_rational_scalars_skip_the_domain_search_with_the_same_result():
    """Rational coefficients take the short path; q and the integer values equal construct_domain's route."""
    coefficients = (R(1, 2), sympy.Integer(-3), R(2, 3), R(0))
    scalars = formal_module._Scalars(coefficients)
    K, _ = construct_domain(list(coefficients), extension=True)
    assert K.is_QQ and scalars.K is None
    assert (scalars.q, scalars.values) == (6, [3, -18, 4, 0])
    assert formal_module._Scalars((sympy.Integer(2) ** R(1, 3), R(1))).K is not None  # algebraic: the field


def test_stats_report_the_phases():
    """``stats`` names the primes, the solved degree and the CPU seconds of each phase (the benchmark's breakdown)."""
    stats = {}
    dens = [factorial(d) * lcm(*range(1, 9)) for d in range(9)]
    assert modular.lyndon_numerators([0, 1], [1, 1], 1, 2, 8, dens, stats) is not None
    assert stats["solved_degree"] == 7 and stats["primes"] >= 1
    assert list(stats["seconds"]) == ["lyndon_tables", "factor_tables", "word_coefficients", "solve", "crt"]
    assert all(t >= 0 for t in stats["seconds"].values())


def test_the_solve_compiles_each_helper_for_one_signature():
    """numba types an argument that is a literal on a loop's first pass as ``Literal[int](0)`` and compiles the
    callee again for ``int64``: the class loop's start must not be a literal (five helpers compiled twice cost
    ~3 s of a cold start).  Checked where the engine was compiled in this process (a cold cache)."""
    formal_bch("123", 5)
    for helper in (modular._class_program, modular._run_program, modular._add_earlier, modular._finish_group,
                   modular._reduce):
        assert len(helper.signatures) <= 1, (helper, helper.signatures)


def test_the_engine_compiles_only_what_a_series_needs():
    """Each compiled function, each numpy call numba specialises and each CPython wrapper is a separate compile on a
    cold start: Eq. (3) (two letters, even degree) is an entry point of its own (a three-letter series never compiles
    it), the chains come with the Lyndon table (one kernel) and are walked where they are used (no compiled function
    tabulates them), the helpers called only from compiled code have no CPython wrapper, and the kernels call no
    ``min``/``max``/``astype`` (one more compile each).  Read from the source and the options, so nothing is
    compiled here."""
    solve = set(modular._solve.py_func.__code__.co_names)
    assert "_even_top" not in solve
    assert not hasattr(modular, "_chains") and not hasattr(modular, "_class_chains")
    kernels = [modular._lyndon_table_kernel, modular._add_earlier, modular._finish_group, modular._solve,
               modular._word_coefficients, modular._even_top, modular._class_program, modular._run_program]
    for kernel in kernels:
        names = set(kernel.py_func.__code__.co_names)
        assert not {"min", "max", "astype"} & names, (kernel, names)
    for helper in (modular._add_earlier, modular._finish_group, modular._class_program, modular._run_program):
        options = getattr(helper, "targetoptions", None) or helper.options  # a numba dispatcher once made
        assert options.get("no_cpython_wrapper"), helper


def test_the_word_coefficients_and_the_reduction_are_compiled_once_each():
    """A loop over the primes in a statement costs numba and LLVM about as much to compile as the statement: the word
    coefficients walk the Lyndon words once per prime with scalar recurrences (one loop over the primes, around the
    walk), and the modular reduction is compiled once and called (LLVM inlines it), not copied and typed again by
    numba at each call site (``inline="always"``).  Read from the source and the
    options, so nothing is compiled here."""
    import inspect

    assert inspect.getsource(modular._word_coefficients.py_func).count("in range(k)") == 1
    options = getattr(modular._reduce, "targetoptions", None) or modular._reduce.options
    assert options.get("inline", "never") == "never" and options.get("no_cpython_wrapper")


# -- numba is imported on first use ------------------------------------------------------------------------

def test_importing_the_compiled_modules_does_not_import_numba(tmp_path):
    """Decorating with ``compiled.njit`` imports nothing: a fresh process imports the two modules of compiled
    functions without numba; the first use of one brings it in and makes every dispatcher of that module."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    code = ("import sys\nimport nambu_bch.bch.modular as m, nambu_bch.numeric.scan\n"
            "print('numba' in sys.modules)\n"
            "print(m._solve.signatures, 'numba' in sys.modules, type(m._even_top).__name__)\n")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1]), "NAMBU_BCH_CACHE": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:2] == ["False", "[] True CPUDispatcher"]


def _twice(x):
    return 2 * x


def test_a_compiled_function_held_before_first_use_forwards_to_its_dispatcher(tmp_path, monkeypatch):
    """A wrapper held outside its module's namespace (as when imported by name) calls and inspects its own
    dispatcher, made once, and :func:`compiled.dispatcher` unwraps it."""
    from nambu_bch.compiled import LazyDispatcher, dispatcher

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path))
    held = LazyDispatcher(_twice, {})
    assert "not made yet" in repr(held) and held.__name__ == "_twice"
    assert held(21) == 42
    made = dispatcher(held)
    assert made is held.dispatcher and dispatcher(made) is made and "made" in repr(held)
    assert held.signatures == made.signatures and len(made.signatures) == 1
    import numba  # compiled code holding the wrapper as a global types it as its dispatcher

    namespace = {"_held": held}
    exec("def caller(x):\n    return _held(x) + 1\n", namespace)  # noqa: S102 - a fixed test source
    assert numba.njit(namespace["caller"])(4) == 9
