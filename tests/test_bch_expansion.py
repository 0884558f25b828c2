"""Term-by-term expansion into Liouville terms: Eqs. (BCH3), (BCH4) and pruning."""

import re

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import System, model
from nambu_bch.bch import (
    effective_field_bch,
    expand_terms,
    formal_bch,
    lie_to_associative,
)
from nambu_bch.bch.expansion import piece_evaluator, term_evaluator
from nambu_bch.errors import UnknownPieceError

from reference_fields import effective_field_reference

R = sympy.Rational
x1, x2, x3 = sympy.symbols("x1 x2 x3")
m, omega = sympy.symbols("m omega")

# Eq. (BCH2), coefficients of -h^2/24
BCH2 = [
    (1, (1, (1, 2))), (1, (1, (1, 3))), (1, (1, (2, 3))),
    (-2, (2, (2, 1))), (1, (2, (2, 3))), (1, (2, (1, 3))),
    (-2, (3, (3, 1))), (-2, (3, (3, 2))), (3, (3, (1, 2))),
]

# Eq. (BCH3) transcribed from the paper's LaTeX source (X_{ij} = X_{H_i,G_j}), inside -h^2/24 ( ... )
BCH3_TEXT = """
    [X_{23},[X_{23},X_{31}]]+[X_{23},[X_{23},X_{13}]]
    +[X_{23},[X_{32},X_{31}]]+[X_{23},[X_{32},X_{13}]]
    +[X_{32},[X_{23},X_{31}]]+[X_{32},[X_{23},X_{13}]]
    +[X_{32},[X_{32},X_{31}]]+[X_{32},[X_{32},X_{13}]]
    +[X_{23},[X_{23},X_{12}]]+[X_{23},[X_{23},X_{21}]]
    +[X_{23},[X_{32},X_{12}]]+[X_{23},[X_{32},X_{21}]]
    +[X_{32},[X_{23},X_{12}]]+[X_{32},[X_{23},X_{21}]]
    +[X_{32},[X_{32},X_{12}]]+[X_{32},[X_{32},X_{21}]]
    +[X_{23},[X_{31},X_{12}]]+[X_{23},[X_{31},X_{21}]]
    +[X_{23},[X_{13},X_{12}]]+[X_{23},[X_{13},X_{21}]]
    +[X_{32},[X_{31},X_{12}]]+[X_{32},[X_{31},X_{21}]]
    +[X_{32},[X_{13},X_{12}]]+[X_{32},[X_{13},X_{21}]]
    -2[X_{31},[X_{31},X_{23}]]-2[X_{31},[X_{31},X_{32}]]
    -2[X_{31},[X_{13},X_{23}]]-2[X_{31},[X_{13},X_{32}]]
    -2[X_{13},[X_{31},X_{23}]]-2[X_{13},[X_{31},X_{32}]]
    -2[X_{13},[X_{13},X_{23}]]-2[X_{13},[X_{13},X_{32}]]
    +[X_{31},[X_{31},X_{12}]]+[X_{31},[X_{31},X_{21}]]
    +[X_{31},[X_{13},X_{12}]]+[X_{31},[X_{13},X_{21}]]
    +[X_{13},[X_{31},X_{12}]]+[X_{13},[X_{31},X_{21}]]
    +[X_{13},[X_{13},X_{12}]]+[X_{13},[X_{13},X_{21}]]
    +[X_{31},[X_{23},X_{12}]]+[X_{31},[X_{23},X_{21}]]
    +[X_{31},[X_{32},X_{12}]]+[X_{31},[X_{32},X_{21}]]
    +[X_{13},[X_{23},X_{12}]]+[X_{13},[X_{23},X_{21}]]
    +[X_{13},[X_{32},X_{12}]]+[X_{13},[X_{32},X_{21}]]
    -2[X_{12},[X_{12},X_{23}]]-2[X_{12},[X_{12},X_{32}]]
    -2[X_{12},[X_{21},X_{23}]]-2[X_{12},[X_{21},X_{32}]]
    -2[X_{21},[X_{12},X_{23}]]-2[X_{21},[X_{12},X_{32}]]
    -2[X_{21},[X_{21},X_{23}]]-2[X_{21},[X_{21},X_{32}]]
    -2[X_{12},[X_{12},X_{31}]]-2[X_{12},[X_{12},X_{13}]]
    -2[X_{12},[X_{21},X_{31}]]-2[X_{12},[X_{21},X_{13}]]
    -2[X_{21},[X_{12},X_{31}]]-2[X_{21},[X_{12},X_{13}]]
    -2[X_{21},[X_{21},X_{31}]]-2[X_{21},[X_{21},X_{13}]]
    +3[X_{12},[X_{23},X_{31}]]+3[X_{12},[X_{23},X_{13}]]
    +3[X_{12},[X_{32},X_{31}]]+3[X_{12},[X_{32},X_{13}]]
    +3[X_{21},[X_{23},X_{31}]]+3[X_{21},[X_{23},X_{13}]]
    +3[X_{21},[X_{32},X_{31}]]+3[X_{21},[X_{32},X_{13}]]
"""


def _parse_bch3():
    pattern = re.compile(r"([+-]?\d*)\[X_\{(\d)(\d)\},\[X_\{(\d)(\d)\},X_\{(\d)(\d)\}\]\]")
    out = []
    for sign, a1, b1, a2, b2, a3, b3 in pattern.findall(BCH3_TEXT.replace(" ", "")):
        c = int(sign + "1") if sign in ("+", "-", "") else int(sign)
        out.append((c, ((int(a1), int(b1)), ((int(a2), int(b2)), (int(a3), int(b3))))))
    return out


def _generic_system():
    """H = H1(x1) + H2(x2) + H3(x3), G = G1(x1) + G2(x2) + G3(x3) with undefined functions."""
    H = [sympy.Function(f"H{i}")(x) for i, x in enumerate((x1, x2, x3), 1)]
    G = [sympy.Function(f"G{i}")(x) for i, x in enumerate((x1, x2, x3), 1)]
    return System([x1, x2, x3], [sum(H), sum(G)], [], name="generic"), H, G


def _ho3_terms():
    A, B = x2**2 / (2 * m), m * omega**2 * x3 / 2
    C, D = x3, -x1**2
    return (A, C), (B, D), (A, D), (A, B, C, D)


def test_BCH3_72_terms_for_generic_separable_system():
    """Eq. (BCH3): expanding the nine double commutators of Eq. (BCH2) in X_{ij} = X_{H_i,G_j} gives the
    paper's 72 terms, coefficient by coefficient (generic H_i(x_i), G_j(x_j), full split)."""
    system, H, G = _generic_system()
    S = system.splitting
    index = {(h, g): (i, j) for i, h in enumerate(H, 1) for j, g in enumerate(G, 1)}

    def rename(tree):
        if isinstance(tree, tuple) and len(tree) == 2 and all(isinstance(e, sympy.Basic) for e in tree):
            return index[tree]
        return (rename(tree[0]), rename(tree[1]))

    expanded = expand_terms(BCH2, S, prune=False)
    ours = sorted((c, rename(t)) for c, t in expanded)
    paper = sorted(_parse_bch3())
    assert len(paper) == 72 and len(ours) == 72
    assert ours == paper
    # pruning keeps all of them: none vanishes for generic functions
    assert len(expand_terms(BCH2, S, prune=True)) == 72


def test_BCH3_equals_lyndon_expansion_as_associative_elements():
    """Eq. (BCH3) vs our Lyndon series expanded term by term (64 = 8 x 2^3 terms): equal in the free
    associative algebra on the six letters X_{ij}."""
    S = _generic_system()[0].splitting
    ours = expand_terms(formal_bch("12321", 3).terms(3), S, prune=False)
    assert len(ours) == 64
    paper = [(R(-1, 24) * c, t) for c, t in expand_terms(BCH2, S, prune=False)]
    assert lie_to_associative(ours) == lie_to_associative(paper)


def test_BCH4_five_of_nine_commutators_vanish_for_ho3():
    """Eq. (BCH4): [X1,[X1,X3]] = [X2,[X2,X3]] = [X3,[X3,X1]] = [X3,[X3,X2]] = [X3,[X1,X2]] = 0 for ho3."""
    E = piece_evaluator(model("ho3").splitting)
    vanishing = {(1, (1, 3)), (2, (2, 3)), (3, (3, 1)), (3, (3, 2)), (3, (1, 2))}
    assert {t for _, t in BCH2 if E.is_zero(t)} == vanishing


def test_BCH4_pruned_expansion():
    """Eq. (BCH4): the pruned expansion of Eq. (BCH2) for ho3 is exactly the paper's four terms."""
    AC, BD, AD, _ = _ho3_terms()
    paper = [(1, (AC, (AC, BD))), (1, (AC, (BD, AD))), (-2, (BD, (BD, AC))), (1, (BD, (AC, AD)))]
    assert expand_terms(BCH2, model("ho3").splitting) == paper
    # our Lyndon series prunes to four terms as well, with the same value
    ours = expand_terms(formal_bch("12321", 3).terms(3), model("ho3").splitting)
    assert len(ours) == 4


def test_CL5_to_CL8_values():
    """Eqs. (CL5)-(CL8): the four surviving double commutators as single Liouville fields."""
    S = model("ho3").splitting
    alg = S.system.algebra
    from nambu_bch.algebra import liouville_field as X

    AC, BD, AD, (A, B, C, D) = _ho3_terms()
    E = term_evaluator(S)
    assert E.field((AC, (AC, BD))) == X(alg, B, -2 * x2**2 / m**2) == X(alg, omega**2 * x2**2 / m, C)
    assert E.field((AC, (BD, AD))) == X(alg, A, 2 * omega**2 * x1**2) == X(alg, -omega**2 * x2**2 / m, D)
    assert E.field((BD, (BD, AC))) == X(alg, B, -2 * omega**2 * x1**2) == X(alg, m * omega**4 * x1**2, C)
    assert E.field((BD, (AC, AD))) == X(alg, A, 2 * omega**2 * x1**2)


def test_BCH5_effective_field_of_12321():
    """Eq. (BCH5): X_eff = X_{H,G} + h^2 X_{H, x2^2/(4m^2)} + h^2 X_{w^2 x2^2/(12m) + m w^4 x1^2/12, G} + O(h^4)."""
    from nambu_bch.algebra import liouville_field as X

    system = model("ho3")
    alg = system.algebra
    Xeff = effective_field_bch(system.splitting, "12321", 3)
    expected = X(alg, system.H, x2**2 / (4 * m**2)) + X(alg, omega**2 * x2**2 / (12 * m) + m * omega**4 * x1**2 / 12, system.G)
    assert Xeff[2] == expected
    assert Xeff[0] == system.vector_field and Xeff[1].is_zero() and Xeff[3].is_zero()


def test_generic_effective_field_specialises_to_ho3():
    """The h^2 field of the generic separable system (undefined H_i, G_j), specialised to H1 = 0, H2 = A,
    H3 = B, G1 = D, G2 = 0, G3 = C (Sect. 5.1), equals ho3's h^2 field from backward error analysis."""
    system, H, G = _generic_system()
    generic = effective_field_bch(system.splitting, "12321", 2)[2].to_sympy()
    _, _, _, (A, B, C, D) = _ho3_terms()
    values = dict(zip([f.func for f in H + G], [0, A, B, D, 0, C]))
    specialised = []
    for comp in generic:
        expr = comp
        for f, v in values.items():
            x = {"H1": x1, "G1": x1, "H2": x2, "G2": x2, "H3": x3, "G3": x3}[f.__name__]
            expr = expr.replace(f, sympy.Lambda(x, v))
        specialised.append(sympy.expand(expr.doit()))
    reference = effective_field_reference(model("ho3").splitting, "12321", 2)[2].to_sympy()
    assert [sympy.expand(a - b) for a, b in zip(specialised, reference)] == [0, 0, 0]


@pytest.mark.parametrize("name", ["ho3", "rigid-body", "lotka-volterra"])
def test_expansion_preserves_the_concrete_value(name):
    """Sum of the pruned, expanded terms == sum of the piece-level series (degrees 3 and 5 of 12321)."""
    S = model(name).splitting
    pieces, terms = piece_evaluator(S), term_evaluator(S)
    series = formal_bch("12321" if len(S) == 3 else "121", 5)
    for d in (3, 5):
        expanded = expand_terms(series.terms(d), S, evaluators=(pieces, terms))
        lhs = _sum(S, [(c, terms.field(t)) for c, t in expanded])
        rhs = _sum(S, [(c, pieces.field(t)) for c, t in series.terms(d)])
        assert not rhs.is_zero()
        assert lhs == rhs
        assert len(expanded) <= len(expand_terms(series.terms(d), S, prune=False))


def _sum(S, pairs):
    from nambu_bch.algebra import VectorField

    total = VectorField.zero(S.system.algebra)
    for c, X in pairs:
        if X is not None:
            total = total + X.scale(c)
    return total


@settings(max_examples=15, deadline=None)
@given(st.lists(st.tuples(st.integers(-3, 3), st.integers(1, 3), st.integers(1, 3), st.integers(1, 3)), min_size=1, max_size=6))
def test_property_pruning_never_changes_the_value(items):
    """Random double commutators on the rigid body: pruned expansion and unpruned expansion have equal sums."""
    S = model("rigid-body").splitting
    trees = [(R(c), (a, (b, d))) for c, a, b, d in items]
    terms = term_evaluator(S)
    pruned = _sum(S, [(c, terms.field(t)) for c, t in expand_terms(trees, S)])
    full = _sum(S, [(c, terms.field(t)) for c, t in expand_terms(trees, S, prune=False)])
    assert pruned == full


@pytest.mark.parametrize("prune", [True, False])
def test_unknown_generator(prune):
    with pytest.raises(UnknownPieceError, match="7"):
        expand_terms([(1, (1, 7))], model("ho3").splitting, prune=prune)


def test_BCH3_printed_term_by_term_equals_the_papers_latex():
    """Eq. (BCH3): expanding Eq. (BCH2) and printing it with X_{ij} names reproduces the paper's LaTeX term by
    term (whitespace aside; within a block of eight the order of X_{31}, X_{13} follows Piece.terms)."""
    from nambu_bch.bch import terms_to_latex

    system, H, G = _generic_system()
    index = {(h, g): f"X_{{{i}{j}}}" for i, h in enumerate(H, 1) for j, g in enumerate(G, 1)}
    printed = terms_to_latex(expand_terms(BCH2, system.splitting, prune=False), index).replace(" ", "")
    token = re.compile(r"[+-]?\d*\[X_\{\d\d\},\[X_\{\d\d\},X_\{\d\d\}\]\]")

    def blocks(text):
        terms = [t if t[0] in "+-" else "+" + t for t in token.findall(text)]
        assert "".join(terms).lstrip("+") == text.lstrip("+")  # nothing but these terms
        return [sorted(terms[i:i + 8]) for i in range(0, len(terms), 8)]

    ours, paper = blocks(printed), blocks("".join(BCH3_TEXT.split()))
    assert len(paper) == 9 and ours == paper


def test_BCH2_printed_term_by_term():
    """Eq. (BCH2) in the paper's nine-term form, printed as LaTeX."""
    from nambu_bch.bch import terms_to_latex

    assert terms_to_latex(BCH2).replace(" ", "") == (
        "[X_{1},[X_{1},X_{2}]]+[X_{1},[X_{1},X_{3}]]+[X_{1},[X_{2},X_{3}]]"
        "-2[X_{2},[X_{2},X_{1}]]+[X_{2},[X_{2},X_{3}]]+[X_{2},[X_{1},X_{3}]]"
        "-2[X_{3},[X_{3},X_{1}]]-2[X_{3},[X_{3},X_{2}]]+3[X_{3},[X_{1},X_{2}]]"
    )
