"""Formal BCH series: literature values (Eqs. BCH1, BCH2), exact matrix logarithms, properties."""

from fractions import Fraction
from math import factorial, lcm

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch.bch import (
    BracketEvaluator,
    formal_bch,
    lie_to_associative,
    tree_degree,
    tree_to_associative,
)
from nambu_bch.errors import InvalidCompositionError, InvalidOrderError, NambuBCHError
from nambu_bch.integrators import PAPER_WORDS, Composition, composition
from strategies import compositions

R = sympy.Rational

# Eq. (BCH2): X_eff = X_{H,G} - h^2/24 ( ... ), the paper's nine double commutators
BCH2 = [
    (1, (1, (1, 2))), (1, (1, (1, 3))), (1, (1, (2, 3))),
    (-2, (2, (2, 1))), (1, (2, (2, 3))), (1, (2, (1, 3))),
    (-2, (3, (3, 1))), (-2, (3, (3, 2))), (3, (3, (1, 2))),
]


def _paper_bch2():
    return [(R(-1, 24) * c, t) for c, t in BCH2]


# -- independent reference: truncated free associative algebra with dicts of Fractions ------------------

def _mul(a, b, n):
    out = {}
    for u, cu in a.items():
        for v, cv in b.items():
            if len(u) + len(v) <= n:
                out[u + v] = out.get(u + v, 0) + cu * cv
    return {w: c for w, c in out.items() if c}


def _assoc_log(factors, n, K=None):
    """log(prod exp(c X_k)) through degree n, as {word: coefficient}, straight from the definitions.

    Coefficients are Fractions, or elements of the sympy domain ``K`` (e.g. QQ<2^(1/3)>) when given."""
    if K is None:
        one, convert, ratio = Fraction(1), (lambda c: Fraction(int(c.p), int(c.q))), Fraction
    else:
        one, convert, ratio = K.one, K.from_sympy, (lambda a, b: K.from_sympy(R(a, b)))
    P = {(): one}
    for k, c in factors:
        c = convert(c)
        P = _mul(P, {(k,) * j: c**j * ratio(1, factorial(j)) for j in range(n + 1)}, n)
    Q = {w: c for w, c in P.items() if w}
    L, power = {}, {(): one}
    for j in range(1, n + 1):
        power = _mul(power, Q, n)
        for w, c in power.items():
            L[w] = L.get(w, 0) + ratio((-1) ** (j + 1), j) * c
    return {w: c for w, c in L.items() if c}


def _series_assoc(B, degrees=None):
    terms = [t for d in (degrees or range(1, B.max_degree + 1)) for t in B.terms(d)]
    return {w: Fraction(int(c.p), int(c.q)) for w, c in lie_to_associative(terms).items()}


# -- literature values ------------------------------------------------------------------------------------

def test_BCH1_position_verlet():
    """Eq. (BCH1): X_T + X_V - h^2/24([X_T,[X_T,X_V]] - 2[X_V,[X_V,X_T]])."""
    B = formal_bch("TVT", 3)
    paper = [(1, 1), (1, 2), (R(-1, 24), (1, (1, 2))), (R(2, 24), (2, (2, 1)))]
    ours = B.terms(1) + B.terms(3)
    assert lie_to_associative(ours) == lie_to_associative(paper)
    assert B.terms(3) == [(R(-1, 24), (1, (1, 2))), (R(1, 12), ((1, 2), 2))]
    assert B.degrees == (1, 3)


def test_BCH2_equals_lyndon_series_in_free_associative_algebra():
    """Eq. (BCH2): the paper's nine-term (non-basis) form equals our 8 Lyndon terms as associative elements."""
    B = formal_bch("12321", 3)
    assert len(B.terms(3)) == 8
    assert lie_to_associative(_paper_bch2()) == lie_to_associative(B.terms(3))
    assert lie_to_associative(_paper_bch2())  # non-trivial
    # and the degree-1 part is X_{H,G} = X_1 + X_2 + X_3
    assert B.terms(1) == [(1, 1), (1, 2), (1, 3)]


def test_BCH2_nine_terms_are_not_a_basis():
    """Eq. (BCH2): the nine double commutators are linearly dependent (Jacobi), dim L_3 = 8 for 3 generators."""
    vectors = [tree_to_associative(t) for _, t in BCH2]
    words = sorted({w for v in vectors for w in v})
    M = sympy.Matrix([[v.get(w, 0) for w in words] for v in vectors])
    assert M.rank() == 8
    assert lie_to_associative([(1, (1, (2, 3))), (1, (2, (3, 1))), (1, (3, (1, 2)))]) == {}


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_BCH2_for_all_six_paper_words(word):
    """Eq. (BCH2) with the letters permuted: each of the six words (Sect. 5.1) gives the relabelled series."""
    a, b, c = (int(ch) for ch in word[:3])
    relabel = {1: a, 2: b, 3: c}

    def sub(t):
        return (sub(t[0]), sub(t[1])) if isinstance(t, tuple) else relabel[t]

    paper = [(k, sub(t)) for k, t in _paper_bch2()]
    assert lie_to_associative(formal_bch(word, 3).terms(3)) == lie_to_associative(paper)


def test_BCH2_latex_term_by_term():
    """Eq. (BCH2) printed as LaTeX, term by term."""
    from nambu_bch.printing import flatten

    text = flatten(formal_bch("12321", 3).to_latex())   # an aligned, line-broken block, compared as one line
    assert text.startswith(r"X_{\rm eff} = X_{1} + X_{2} + X_{3} - \frac{h^{2}}{24} [X_{1},[X_{1},X_{2}]]")
    assert text.count("h^{2}") == 8 and text.endswith("+ O(h^{4})")     # symmetric: no h^3 term
    names = {1: "X_T", 2: "X_V"}
    assert flatten(formal_bch("121", 3).to_latex(names)) == (
        r"X_{\rm eff} = X_T + X_V - \frac{h^{2}}{24} [X_T,[X_T,X_V]] + \frac{h^{2}}{12} [[X_T,X_V],X_V] + O(h^{4})"
    )
    assert flatten(formal_bch("12", 2).to_latex(step=None)) == r"\log \Phi = X_{1} + X_{2} + \frac{1}{2} [X_{1},X_{2}]"


def test_classical_bch_two_generators_degree_4():
    """log(e^X e^Y) = X + Y + [X,Y]/2 + ([X,[X,Y]] + [Y,[Y,X]])/12 - [Y,[X,[X,Y]]]/24 (HLW, Sect. III.4.2)."""
    B = formal_bch("12", 4)
    ref = [(1, 1), (1, 2), (R(1, 2), (1, 2)), (R(1, 12), (1, (1, 2))), (R(1, 12), (2, (2, 1))),
           (R(-1, 24), (2, (1, (1, 2))))]
    assert lie_to_associative(B.all_terms()) == lie_to_associative(ref)


def test_symmetric_BCH_degree_5_coefficient():
    """Symmetric BCH of e^{X/2} e^Y e^{X/2}, degree 5 (HLW, Sect. III.4.2, Eq. (4.11)):
    7/5760 [X,[X,[X,[X,Y]]]] - 7/360 [Y,[X,[X,[X,Y]]]] ... checked on the first coefficient."""
    B = formal_bch("121", 5)
    assert B.degrees == (1, 3, 5)
    assert dict((t, c) for c, t in B.terms(5))[(1, (1, (1, (1, 2))))] == R(7, 5760)


@pytest.mark.parametrize("spec,degree", [("12321", 7), ("121", 9), ("12", 9), ("12", 6), ("1:1/3,2:1,3:1,1:2/3", 6), ("121", 8), ("2:1/3,1:1/2,2:2/3,1:1/2", 6)])
def test_against_free_associative_log(spec, degree):
    """Every coefficient through the given degree against log computed naively in the free associative algebra."""
    B = formal_bch(spec, degree)
    assert _series_assoc(B) == _assoc_log(B.composition.factors(), degree)


def test_lie_trotter_operator_order():
    """Word "12" = e^{hX_1} e^{hX_2}: X_eff = X_1 + X_2 + h/2 [X_1, X_2] + ... (operator order convention)."""
    B = formal_bch("12", 3)
    assert B.terms(2) == [(R(1, 2), (1, 2))]
    assert formal_bch("21", 2).terms(2) == [(R(-1, 2), (1, 2))]
    assert B.degrees == (1, 2, 3)


def test_triple_jump_is_fourth_order_and_algebraic():
    """Forest-Ruth / Yoshida triple jump (Yoshida 1990, Eq. 5.19): degree 3 vanishes, degree 5 has coefficients
    in QQ(2^(1/3)); all of them against the naive log computed in that field."""
    B = formal_bch("forest-ruth", 5)
    assert B.degrees == (1, 5)
    assert any(c.has(sympy.root(2, 3)) for c, _ in B.terms(5))
    K = sympy.QQ.algebraic_field(sympy.root(2, 3))
    naive = _assoc_log(B.composition.factors(), 5, K)
    ours = lie_to_associative([(K.from_sympy(c), t) for c, t in B.all_terms()])
    assert ours == naive


# -- exact nilpotent matrices: log(prod exp(c A)) with 10 x 10 strictly upper triangular integers ---------

def _frac_matrix(M):
    return np.array([[Fraction(int(v)) for v in row] for row in M], dtype=object)


def _exp_nilpotent(A, c):
    n = A.shape[0]
    out = _frac_matrix(np.eye(n, dtype=np.int64))
    term = out.copy()
    for k in range(1, n):
        term = term.dot(A) * (c / k)
        out = out + term
    return out


def _log_unipotent(P):
    n = P.shape[0]
    Q = P - _frac_matrix(np.eye(n, dtype=np.int64))
    out, power = Q * 0, _frac_matrix(np.eye(n, dtype=np.int64))
    for k in range(1, n):
        power = power.dot(Q)
        out = out + power * Fraction((-1) ** (k + 1), k)
    return out


def _matrix_evaluator(mats):
    return BracketEvaluator(
        {k: np.array(A, dtype=object) for k, A in mats.items()},
        bracket=lambda X, Y: X.dot(Y) - Y.dot(X),
        is_zero=lambda X: not X.any(),
    )


def _series_at_matrices(B, mats):
    """sum c * P_w(A_1, ..., A_g) with integer matrix brackets, memoised."""
    E = _matrix_evaluator(mats)
    terms = B.all_terms()
    D = lcm(*(int(c.q) for c, _ in terms))
    total = np.zeros_like(next(iter(mats.values())), dtype=object)
    for c, tree in terms:
        value = E.value(tree)
        if value is not None:
            total = total + value * (int(c.p) * (D // int(c.q)))
    return total, D


def _nilpotent(rng, size, bound=3):
    """Strictly upper triangular with non-zero integer entries in -bound..bound above the diagonal."""
    entries = rng.integers(1, bound + 1, size=(size, size)) * rng.choice([-1, 1], size=(size, size))
    return np.triu(entries, k=1).astype(object)


def _check_matrices(spec, degree, seed, size=10):
    B = formal_bch(spec, degree)
    rng = np.random.default_rng(seed)
    mats = {k: _nilpotent(rng, size) for k in B.generators}
    P = _frac_matrix(np.eye(size, dtype=np.int64))
    for k, c in B.composition.factors():
        P = P.dot(_exp_nilpotent(mats[k], Fraction(int(c.p), int(c.q))))
    exact = _log_unipotent(P)
    total, D = _series_at_matrices(B, mats)
    return total, exact * D, B, mats


@pytest.mark.parametrize("spec,seed", [("12321", 1), ("12321", 2), ("123", 3), ("1:1/3,2:1/2,1:2/3,3:1,2:1/2", 4)])
def test_degree_9_exact_against_nilpotent_matrix_log(spec, seed):
    """Series truncated at degree 9 == log(prod exp(c_i A_i)) exactly for 10x10 strictly upper triangular A_i
    (words of length >= 10 vanish, so the truncation is exact)."""
    total, exact, B, _ = _check_matrices(spec, 9, seed)
    assert B.max_degree == 9
    assert (total == exact).all()
    assert exact[0, 9] != 0  # the degree-9 part actually reaches the compared entries


def test_matrix_check_detects_a_wrong_high_degree_coefficient():
    """The exact matrix test catches an error in any single coefficient of degree 7 or 9 (the class of bug
    of a published library that gets degree >= 6 wrong): every Lyndon bracket of those degrees is non-zero
    on at least one of three random matrix sets, so a wrong coefficient changes some compared matrix."""
    nonzero = set()
    for seed in (5, 6, 7):
        total, exact, B, mats = _check_matrices("12321", 9, seed)
        assert (total == exact).all()
        E = _matrix_evaluator(mats)
        D = lcm(*(int(c.q) for c, _ in B.all_terms()))
        for d in (7, 9):
            for c, tree in B.terms(d):
                value = E.value(tree)
                if value is not None:
                    nonzero.add(tree)
                    if len(nonzero) % 500 == 1:   # a sample of perturbations: off by 1/1000
                        assert not ((total + value * Fraction(D, 1000)) == exact).all()
    assert all(tree in nonzero for d in (7, 9) for _, tree in B.terms(d))
    assert len(nonzero) == len(B.terms(7)) + len(B.terms(9)) > 2000


# -- property tests -----------------------------------------------------------------------------------------

@settings(max_examples=25, deadline=None)
@given(compositions())
def test_property_equals_naive_associative_log(comp):
    """Random compositions: the Lyndon series equals the naive free-associative log through degree 5."""
    B = formal_bch(comp, 5)
    assert _series_assoc(B) == _assoc_log(comp.factors(), 5)


@settings(max_examples=15, deadline=None)
@given(compositions(), st.integers(0, 10**6))
def test_property_matrices(comp, seed):
    """Random compositions and random nilpotent 7x7 integer matrices: exact through degree 6."""
    total, exact, _, _ = _check_matrices(comp, 6, seed, size=7)
    assert (total == exact).all()


@settings(max_examples=20, deadline=None)
@given(compositions())
def test_property_symmetric_compositions_have_odd_degrees_only(comp):
    """Phi = C(h/2) C*(h/2) is symmetric: its series has odd degrees only (HLW, Thm. III.5.2)."""
    half = [c / 2 for c in comp.coefficients]
    sym = Composition(comp.pieces + comp.pieces[::-1], tuple(half + half[::-1]), "sym")
    assert sym.symmetric
    B = formal_bch(sym, 6)
    assert all(d % 2 == 1 for d in B.degrees)
    assert not B.terms(2) and not B.terms(4) and not B.terms(6)


@settings(max_examples=20, deadline=None)
@given(compositions())
def test_property_adjoint(comp):
    """The adjoint (reversed product) has L_d(adjoint) = (-1)^(d+1) L_d (HLW, Sect. II.3 and III.5)."""
    B, A = formal_bch(comp, 5), formal_bch(comp.adjoint(), 5)
    for d in range(1, 6):
        sign = (-1) ** (d + 1)
        assert lie_to_associative(A.terms(d)) == lie_to_associative([(sign * c, t) for c, t in B.terms(d)])


@settings(max_examples=20, deadline=None)
@given(compositions())
def test_property_terms_are_homogeneous_trees(comp):
    B = formal_bch(comp, 5)
    for d in range(1, 6):
        for c, tree in B.terms(d):
            assert tree_degree(tree) == d and c != 0 and isinstance(c, sympy.Basic)


# -- bad input ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("degree", [0, -1, 2.5, "3", None, True])
def test_bad_degree(degree):
    with pytest.raises(InvalidOrderError, match="degree"):
        formal_bch("12", degree)


def test_absurd_degree_refused_up_front_with_witt_count():
    with pytest.raises(InvalidOrderError, match="Lyndon basis elements .Witt's formula."):
        formal_bch("12321", 30)
    with pytest.raises(InvalidOrderError, match="degree"):
        formal_bch("12", 10**9)
    with pytest.raises(InvalidOrderError, match="degree"):
        formal_bch("1", 10**9)  # one generator: cheap per degree, but not a billion degrees


@pytest.mark.parametrize("spec", ["", "abc", [], "1:0.5", [(1, 0.5), (1, 0.5)], "1:1/2,2:1"])
def test_bad_compositions(spec):
    with pytest.raises(InvalidCompositionError):
        formal_bch(spec, 3)


def test_bad_coefficient_expression():
    with pytest.raises(NambuBCHError, match="'x'"):
        formal_bch("1:x", 3)


def test_terms_out_of_range():
    B = formal_bch("12", 3)
    with pytest.raises(InvalidOrderError):
        B.terms(4)
    with pytest.raises(NambuBCHError):
        B.terms(0)


def test_single_factor_and_composition_object():
    assert formal_bch("1", 5).all_terms() == [(1, 1)]
    comp = composition("12321")
    assert formal_bch(comp, 3).terms(3) == formal_bch("12321", 3).terms(3)
