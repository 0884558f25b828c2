"""Tests of nambu_bch.shadow: Liouville-term algebra, fundamental identity, FI route, direct route, existence.

Literature values name the equation label of Horikoshi, *Shadow Hamiltonians of structure-preserving
integrators for Nambu mechanics*, that they check.  Existence results are stated in the docstrings.
"""

from __future__ import annotations

import json

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import PAPER_WORDS, System, liouville_field, model
from nambu_bch.bch import effective_field
from nambu_bch.errors import (
    InvalidOrderError,
    NambuBCHError,
    NotSeparableError,
    UnknownPieceError,
)
from nambu_bch.shadow import (
    FI_LABELS,
    JetAlgebra,
    LiouvilleSum,
    LiouvilleTerm,
    commutator_terms,
    direct_route,
    fi_route,
    representations,
    shadow_hamiltonians,
)

import shared_results as shared

x1, x2, x3, x4 = sympy.symbols("x1 x2 x3 x4")
m, omega, h, alpha = sympy.symbols("m omega h alpha")
I1, I2, I3 = sympy.symbols("I1 I2 I3")

# Eqs. (AB), (CD)
A = x2**2 / (2 * m)
B = m * omega**2 * x3 / 2
C = x3
D = -x1**2
AC, BD, AD = (A, C), (B, D), (A, D)

# Eqs. (SH12321a)-(SG12321c): the h^2 corrections
SH_A = omega**2 * x2**2 / (12 * m) + m * omega**4 * x1**2 / 12
SG_A = x2**2 / (4 * m**2)
SH_B = sympy.Integer(0)
SG_B = x2**2 / (12 * m**2) - omega**2 * x1**2 / 6
SH_C = alpha * omega**2 * x2**2 / (12 * m) + alpha * m * omega**4 * x1**2 / 12
SG_C = x2**2 / (12 * m**2) + alpha * x2**2 / (6 * m**2) - (1 - alpha) * omega**2 * x1**2 / 6


def zero(expr) -> bool:
    return sympy.expand(expr) == 0


def same_field(alg, X, Y) -> bool:
    return all(zero(a - b) for a, b in zip(X.to_sympy(), Y.to_sympy()))


# ---------------------------------------------------------------------------------------------
# 1. Liouville-term algebra
# ---------------------------------------------------------------------------------------------


def test_vanishing_rule_of_eq_BCH5():
    """Eq. (BCH5) uses X_{A, -2x2^2/m^2} = 0 and X_{m omega^4 x1^2, D} = 0: gradients are parallel."""
    coords = (x1, x2, x3)
    assert LiouvilleTerm((A, -2 * x2**2 / m**2)).vanishes(coords)
    assert LiouvilleTerm((m * omega**4 * x1**2, D)).vanishes(coords)
    assert not LiouvilleTerm((B, x2**2)).vanishes(coords)
    alg = model("ho3").algebra
    assert LiouvilleSum.from_slots(alg, (A, -2 * x2**2 / m**2)).is_zero()
    assert LiouvilleSum.from_slots(alg, (m * omega**4 * x1**2, D)).is_zero()


def test_antisymmetry_and_canonical_order():
    t = LiouvilleTerm((x3, x1**2), 5).canonical()
    assert t.slots == (x1**2, x3) and t.coefficient == -5
    alg = model("ho3").algebra
    assert LiouvilleSum.from_slots(alg, (x3, x1**2)) == -LiouvilleSum.from_slots(alg, (x1**2, x3))


def test_atoms_keep_the_papers_bookkeeping():
    """With the pieces as atoms, X_{B, x2^2} and X_{-m omega^2 x2^2/2, C} differ formally but agree as fields."""
    alg = model("ho3").algebra
    atoms = (A, B, C, D)
    P = LiouvilleSum.from_slots(alg, (B, x2**2), atoms=atoms)
    Q = LiouvilleSum.from_slots(alg, (-m * omega**2 * x2**2 / 2, C), atoms=atoms)
    assert P != Q
    assert same_field(alg, P.field(), Q.field())


_coef = st.integers(-3, 3)
_mono = st.tuples(st.integers(0, 2), st.integers(0, 2), st.integers(0, 2))
_poly = st.lists(st.tuples(_coef, _mono), min_size=1, max_size=3)


def _expr(terms):
    return sum((c * x1**a * x2**b * x3**e for c, (a, b, e) in terms), sympy.Integer(0))


@settings(deadline=None, max_examples=25)
@given(_poly, _poly, _poly, _coef)
def test_formal_sums_evaluate_to_the_field(P, Q, R, c):
    """Bilinearity and antisymmetry of the formal sums agree with the concrete Liouville fields."""
    alg = model("ho3").algebra
    P, Q, R = _expr(P), _expr(Q), _expr(R)
    S = LiouvilleSum.from_slots(alg, (P + c * R, Q))
    assert S == LiouvilleSum.from_slots(alg, (P, Q)) + LiouvilleSum.from_slots(alg, (R, Q)).scale(c)
    assert S == -LiouvilleSum.from_slots(alg, (Q, P + c * R))
    assert same_field(alg, S.field(), liouville_field(alg, P + c * R, Q))


# ---------------------------------------------------------------------------------------------
# 2. Fundamental identity
# ---------------------------------------------------------------------------------------------


def test_eight_representations_for_generic_functions():
    """Eqs. (1AX)-(2BY) and (CL2a), (CL2b) hold for generic smooth A..F (sympy Functions): applied to f."""
    J = JetAlgebra((x1, x2, x3), "ABCDEFf", 3)
    fA, fB, fC, fD, fE, fF, f = J.functions()
    f = J.convert(f)
    XAB, XCD, XEF = (liouville_field(J, P, Q) for P, Q in [(fA, fB), (fC, fD), (fE, fF)])
    inner = XCD.bracket(XEF)
    applied = {}  # X_{slots} f, evaluated once per slots (the eight representations share 16 of their 36 terms)

    def field_on_f(slots):
        if slots not in applied:
            applied[slots] = liouville_field(J, *(J.convert(s) for s in slots)).apply(f)
        return applied[slots]

    for way in "ab":  # Eqs. (CL2a), (CL2b)
        total = J.ring.zero
        for t in commutator_terms(J, (fC, fD), (fE, fF), way):
            total += field_on_f(tuple(t.slots)) * J.convert(t.coefficient)
        assert total == inner.apply(f)
    lhs = XAB.bracket(inner).apply(f)
    reps = representations(J, (fA, fB), (fC, fD), (fE, fF))
    assert tuple(reps) == FI_LABELS
    for label, terms in reps.items():
        total = J.ring.zero
        for t in terms:
            total += field_on_f(tuple(t.slots)) * J.convert(t.coefficient)
        assert total == lhs, label


def test_jet_algebra_matches_sympy_on_a_small_case():
    J = JetAlgebra((x1, x2, x3), "AB", 2)
    fA, fB = J.functions()
    X = liouville_field(J, fA, fB)
    direct = sympy.diff(fA, x2) * sympy.diff(fB, x3) - sympy.diff(fA, x3) * sympy.diff(fB, x2)
    assert sympy.expand(J.to_sympy(X.components[0]) - direct) == 0


# ---------------------------------------------------------------------------------------------
# 3. FI route
# ---------------------------------------------------------------------------------------------

#: Eq. (BCH4): the h^2 part of X_eff for Phi^{12321}, as the paper writes it.
BCH4 = [
    (sympy.Rational(-1, 24), (AC, (AC, BD))),
    (sympy.Rational(-1, 24), (AC, (BD, AD))),
    (sympy.Rational(2, 24), (BD, (BD, AC))),
    (sympy.Rational(-1, 24), (BD, (AC, AD))),
]

#: Eqs. (CL5)-(CL8): the two representations of each double commutator.
CL = [
    ((B, -2 * x2**2 / m**2), (omega**2 * x2**2 / m, C)),
    ((A, 2 * omega**2 * x1**2), (-omega**2 * x2**2 / m, D)),
    ((B, -2 * omega**2 * x1**2), (m * omega**4 * x1**2, C)),
    ((A, 2 * omega**2 * x1**2), (-omega**2 * x2**2 / m, D)),
]


@pytest.fixture(scope="module")
def fi_paper():
    return fi_route(model("ho3"), "12321", terms=BCH4)


def test_fi_route_reproduces_eqs_CL5_to_CL8(fi_paper):
    """Eqs. (CL5)-(CL8): each double commutator of Eq. (BCH4) has exactly the paper's two representations."""
    alg = model("ho3").algebra
    for comm, pair in zip(fi_paper.commutators, CL):
        want = [LiouvilleSum.from_slots(alg, slots, atoms=(A, B, C, D)) for slots in pair]
        got = [rep.formal for rep in comm.representations]
        assert len(got) == 2 and got[0] != got[1]
        assert all(g in want for g in got) and all(w in got for w in want)


def test_fi_labels_of_eq_CL5(fi_paper):
    """Sect. 5.2: for [X_{A,C},[X_{A,C},X_{B,D}]], 1AX and 1BX give X_{B,-2x2^2/m^2}, the other six X_{omega^2 x2^2/m, C}."""
    alg = model("ho3").algebra
    first = LiouvilleSum.from_slots(alg, CL[0][0], atoms=(A, C, B, D))
    reps = fi_paper.commutators[0].representations
    by_formal = {rep.labels: rep.formal for rep in reps}
    assert by_formal[("1AX", "1BX")] == first
    assert ("1AY", "1BY", "2AX", "2AY", "2BX", "2BY") in by_formal


def _paper_weights(R, choice):
    """Weights (per commutator, aligned with its representations) of the paper's choice a or b."""
    alg = model("ho3").algebra
    wanted = {
        "a": [{0: 3, 1: -2}, {1: 1}, {1: 1}, {1: 1}],  # Eqs. (CL5a)-(CL8a)
        "b": [{0: 1}, {0: 1}, {0: 1}, {0: 1}],  # Eqs. (CL5b)-(CL8b)
    }[choice]
    out = []
    for comm, pair, w in zip(R.commutators, CL, wanted):
        targets = [LiouvilleSum.from_slots(alg, pair[k], atoms=(A, C, B, D)) for k in (0, 1)]
        row = []
        for rep in comm.representations:
            k = targets.index(rep.formal)
            row.append(w.get(k, 0))
        out.append(row)
    return out


def test_choices_a_and_b_give_eqs_SH12321a_and_SH12321b(fi_paper):
    """Eqs. (CL5a)-(CL8a) give (SH12321a)/(SG12321a); Eqs. (CL5b)-(CL8b) give (SH12321b)/(SG12321b); Eq. (Xeff3) mixes them."""
    wa, wb = _paper_weights(fi_paper, "a"), _paper_weights(fi_paper, "b")
    assert fi_paper.check_member(wa, (SH_A, SG_A))
    assert fi_paper.check_member(wb, (SH_B, SG_B))
    assert not fi_paper.check_member(wb, (SH_A, SG_A))
    for a in (sympy.Rational(1, 3), sympy.Integer(2)):  # Eq. (Xeff3): alpha (a) + (1 - alpha) (b)
        w = [[a * p + (1 - a) * q for p, q in zip(ra, rb)] for ra, rb in zip(wa, wb)]
        assert fi_paper.check_member(w, (SH_C.subs(alpha, a), SG_C.subs(alpha, a)))


def test_fi_alpha_family_is_eq_SH12321c():
    """Default FI route (formal BCH in the Lyndon basis): its alpha-family is Eqs. (SH12321c), (SG12321c)."""
    R = fi_route(model("ho3"), "12321")
    assert zero(R.corrections[0] - SH_C) and zero(R.corrections[1] - SG_C)
    assert zero(R.members[0].corrections[0] - SH_B) and zero(R.members[1].corrections[1] - SG_A)
    # the alpha = 1 member uses the weights 3, -2 of Eq. (CL5a) on [X_{A,C},[X_{A,C},X_{B,D}]]
    assert R.members[1].weights[0] == [3, -2]
    assert "1AX/1BX" in R.to_text()


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_fi_family_lies_in_direct_solution_space(word):
    """All six words of ho3: the FI alpha-family equals the direct one, and every FI direction is a direct solution."""
    S = model("ho3")
    fi = fi_route(S, word)
    direct = direct_route(S, word, 2)
    o2 = direct.orders[1]
    assert all(zero(a - b) for a, b in zip(fi.corrections, o2.corrections))
    alg = S.algebra.with_constants(alpha)
    Z2 = shared.backward_field("ho3", word, 2)[2].to_sympy()
    dH, dG = fi.corrections
    field = liouville_field(alg, dH, S.G) + liouville_field(alg, S.H, dG)
    assert all(zero(a - b) for a, b in zip(field.to_sympy(), Z2))
    for dH, dG in fi.kernel_corrections():  # homogeneous solutions: their corrections are in the direct kernel
        assert (liouville_field(alg, dH, S.G) + liouville_field(alg, S.H, dG)).is_zero()
    assert fi.exists and fi.free_parameter_count >= 1


# ---------------------------------------------------------------------------------------------
# 4. Direct route: literature values
# ---------------------------------------------------------------------------------------------


def test_direct_route_eq_SHPV1():
    """Eq. (SHPV1): position Verlet on the oscillator, H_S = H - w^2 h^2 x2^2/(24 m) + m w^4 h^2 x1^2/12, unique."""
    F = shadow_hamiltonians(model("ho"), "TVT")
    assert zero(F.H_S - model("ho").H + omega**2 * h**2 * x2**2 / (24 * m) - m * omega**4 * h**2 * x1**2 / 12)
    assert F.G_S is None and F.free_parameters == []
    assert F.details.orders[1].kernel_dim == 1  # only the constants: X_{dH} = 0 iff dH is constant


def test_direct_route_eqs_SH12321c_and_members():
    """Default route: Eqs. (SH12321c), (SG12321c); alpha = 1 gives (SH12321a)/(SG12321a), alpha = 0 (SH12321b)/(SG12321b)."""
    S = model("ho3")
    F = shared.family("ho3", "12321")
    assert F.route == "direct" and F.free_parameters == ["alpha"]
    assert zero(F.H_S - S.H - h**2 * SH_C) and zero(F.G_S - S.G - h**2 * SG_C)
    Ha, Ga = F.member(alpha=1)
    Hb, Gb = F.member(alpha=0)
    assert zero(Ha - S.H - h**2 * SH_A) and zero(Ga - S.G - h**2 * SG_A)
    assert zero(Hb - S.H - h**2 * SH_B) and zero(Gb - S.G - h**2 * SG_B)
    assert any("vanishes" in n for n in F.notes)  # h^1: odd order of a symmetric word


def test_gauge_of_ho3_is_psi_of_H_and_G():
    """ho3, h^2, degree 2: the kernel is 5-dimensional and all of it is (psi_G, -psi_H) for psi in span(H, G, H^2, HG, G^2)."""
    o = direct_route(model("ho3"), "12321", 2).orders[1]
    assert o.kernel_dim == 5 and o.psi_dim == 5 and o.extra_gauge_dim == 0
    S = model("ho3")
    alg = S.algebra
    for dH, dG in o.gauge:
        assert (liouville_field(alg, dH, S.G) + liouville_field(alg, S.H, dG)).is_zero()


# ---------------------------------------------------------------------------------------------
# 5. Cross-validation: X_{H_S, G_S} = X_eff + O(h^{k+1}), independently evaluated
# ---------------------------------------------------------------------------------------------


def _check_shadow(S, word, order, shadows, eff=None):
    """X_{H_S,G_S} (built with liouville_field, exact ring arithmetic) against effective_field, h^0..h^order
    (``eff``: that field when already computed, :mod:`shared_results`)."""
    if eff is None:
        eff = effective_field(S.splitting, word, order)  # backward error analysis, independent of the BCH route
    alg = eff[0].algebra.with_constants(alpha)
    X = liouville_field(alg, *(alg.convert(sympy.expand(H)) for H in shadows))
    ih = alg.n + alg.constants.index(h)
    for j in range(order + 1):
        for comp, Z in zip(X.components, eff[j].components):
            part = {mono[:ih] + (0,) + mono[ih + 1:]: c for mono, c in comp.items() if mono[ih] == j}
            want = {mono + (0,): c for mono, c in Z.items()}
            assert alg.ring.from_dict(part) == alg.ring.from_dict(want), (word, j)


@pytest.mark.parametrize(
    "name, word, order",
    [("ho3", w, 2) for w in PAPER_WORDS]
    + [("ho3", "12321", 6), ("ho", "121", 4), ("ho", "12", 3), ("rigid-body", "12321", 4),
       ("lotka-volterra", "12321", 4), ("lotka-volterra", "123", 2), ("ho3-composite", "121", 4), ("ho3-composite", "12", 2)],
)
def test_shadow_pair_reproduces_effective_field(name, word, order):
    """Every reported family (alpha symbolic) satisfies X_{H_S,G_S} = X_eff coefficient by coefficient."""
    S = model(name)
    F = shared.family(name, word, order)
    assert F.exists
    _check_shadow(S, word, order, F.shadows, shared.backward_field(name, word, order))


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_fi_route_family_reproduces_effective_field(word):
    S = model("ho3")
    F = shared.family("ho3", word, 2, route="fi")
    _check_shadow(S, word, 2, F.shadows, shared.backward_field("ho3", word, 2))


# ---------------------------------------------------------------------------------------------
# 6. Existence, order by order
# ---------------------------------------------------------------------------------------------


def _verify_certificate(S, word, F):
    """The certificate kills every ansatz field X_{dH,G} + X_{H,dG} (monomials of the degree tried) but not Z_k - cross."""
    cert = F.certificate
    k, D = F.failed_order, F.degree[F.failed_order]
    alg = S.algebra
    index = {x: i for i, x in enumerate(S.coordinates)}

    def functional(comps):
        total = sympy.Integer(0)
        for (x, mono), c in cert.items():
            poly = sympy.Poly(sympy.expand(comps[index[x]]), *S.coordinates)
            total += c * poly.coeff_monomial(mono)
        return sympy.cancel(total)  # a rational function of the parameters: zero iff its cancelled form is

    monos = [x1**a * x2**b * x3**c for a in range(D + 1) for b in range(D + 1) for c in range(D + 1) if a + b + c <= D]
    for mono in monos:
        for slots in ((mono, S.G), (S.H, mono)):
            assert functional(liouville_field(alg, *slots).to_sympy()) == 0
    assert k == 1  # no cross terms at h^1: the right-hand side is Z_1
    assert functional(effective_field(S.splitting, word, 1)[1].to_sympy()) != 0


def test_rigid_body_full_split_has_polynomial_shadows_through_h4():
    """Free rigid body, full split, Phi^{12321}: the computation FINDS polynomial shadow Hamiltonians at h^2 (ansatz
    degree 4) and h^4 (degree 6), with an alpha-family; the gauge is exactly the psi(H, G) directions (9 and 14
    dimensions).  So the (quartic, sextic) BCH corrections of the symmetric scheme are of the form X_{H_S,G_S} to h^4."""
    F = shared.family("rigid-body", "12321", 4)
    assert F.exists and F.free_parameters == ["alpha"]
    assert F.degree == {2: 4, 4: 6}
    orders = {o.order: o for o in F.details.orders}
    assert (orders[2].kernel_dim, orders[2].psi_dim) == (9, 9)
    assert (orders[4].kernel_dim, orders[4].psi_dim) == (14, 14)
    assert orders[1].status == orders[3].status == "vanishes"


def test_rigid_body_non_symmetric_word_is_obstructed_at_h1():
    """Free rigid body, full split, Phi^{123} (Lie-Trotter): NO polynomial shadow pair already at h^1 (degree 3 tried,
    also degree 5); certificate l = [x1 x2^2]Y^1 ... with l(Z_1) = (I1-I2)(I1-I3)/(2 I1^2 I2 I3) != 0."""
    S = model("rigid-body")
    F = shared.family("rigid-body", "123", 2)   # also test_existence's and test_pickle's (tests/conftest.py LONG)
    assert not F.exists and F.failed_order == 1 and F.degree[1] == 3
    assert sympy.cancel(F.details.orders[0].obstruction_value - (I1 - I2) * (I1 - I3) / (2 * I1**2 * I2 * I3)) == 0
    _verify_certificate(S, "123", F)
    d = F.to_dict()
    assert d["exists"] is False and d["H_S"] is None and "h^1" in d["obstruction"]


def test_rigid_body_non_symmetric_word_is_obstructed_at_h1_degree_5():
    """The rigid body's Phi^{123} obstruction at h^1 persists with ansatz degree 5."""
    assert not shadow_hamiltonians(model("rigid-body"), "123", 1, degree=5).exists


@pytest.mark.parametrize("word", ["123", "lie-trotter", "132"])
def test_ho3_non_symmetric_words_are_obstructed_at_h1(word):
    """ho3, Phi^{123} / Lie-Trotter / Phi^{132}: odd orders appear, and already the h^1 term admits NO polynomial shadow
    pair (degree 2 tried; the same certificate works at degrees 4 and 6)."""
    S = model("ho3")
    F = shared.family("ho3", word, 2)
    assert not F.exists and F.failed_order == 1
    _verify_certificate(S, word, F)


def test_ho3_123_obstruction_persists_at_higher_degree():
    """ho3, Phi^{123}: with ansatz degree 6 the h^1 equation is still unsolvable."""
    F = shadow_hamiltonians(model("ho3"), "123", 1, degree=6)
    assert not F.exists and F.degree == {1: 6}


def test_single_split_models_have_shadows():
    """Single-Hamiltonian split (noncanonical Poisson, the paper's footnote): Lotka-Volterra Phi^{12321} to h^4 and
    Phi^{123} (h and h^2 terms!) to h^2, ho3-composite Phi^{121} to h^4 and Phi^{12} to h^2 all EXIST; the
    Lotka-Volterra Lie-Trotter family has no free parameter (G = x1 x2 x3 is exactly conserved and G_S = G)."""
    F = shared.family("lotka-volterra", "123", 2)
    assert F.exists and F.free_parameters == [] and zero(F.G_S - x1 * x2 * x3)
    assert F.corrections[1] != (0, 0)
    assert shared.family("lotka-volterra", "12321", 4).exists
    assert shared.family("ho3-composite", "121", 4).exists
    assert shared.family("ho3-composite", "12", 2).exists


def test_odd_orders_of_symmetric_words_vanish():
    F = shadow_hamiltonians(model("ho3"), "12321", 3)
    assert F.exists
    assert [o.status for o in F.details.orders] == ["vanishes", "solved", "vanishes"]
    assert sum("odd order" in n for n in F.notes) == 2
    G = shadow_hamiltonians(model("ho3"), "12321", 3, route="fi")
    assert zero(G.H_S - F.H_S) and zero(G.G_S - F.G_S)


# ---------------------------------------------------------------------------------------------
# 7. Output and bad input
# ---------------------------------------------------------------------------------------------


def test_to_dict_is_json_and_sympifies_back():
    S = model("ho3")
    F = shared.family("ho3", "12321")
    d = json.loads(json.dumps(F.to_dict()))
    assert set(d) >= {"model", "integrator", "order", "coordinates", "H", "G", "exists", "H_S", "G_S", "free_parameters"}
    names = S.symbols()
    assert zero(sympy.sympify(d["H_S"], locals=names) - F.H_S)
    assert zero(sympy.sympify(d["G_S"], locals=names) - F.G_S)
    assert d["free_parameters"] == ["alpha"] and d["integrator"] == "12321" and d["order"] == 2
    assert shadow_hamiltonians(model("ho"), "121").to_dict()["G_S"] is None


def test_latex_output():
    F = shared.family("ho3", "12321")
    tex = F.to_latex()
    # symmetric word: X_eff has no h^3 term, so the remainder after h^2 is O(h^4) (as in Eqs. SH12321a-c)
    assert tex.startswith("\\begin{aligned}\nH_{S} &= H + h^{2}") and "G_{S} &= G + h^{2}" in tex and r"\alpha" in tex
    assert "O(h^{4})" in tex
    text = F.to_text()
    assert "H_S = H + h**2*(alpha*m*omega**4*x1**2/12 + alpha*omega**2*x2**2/(12*m)) + O(h^4)" in text
    assert F._repr_latex_().startswith("$$")


def test_bad_input():
    ho3 = model("ho3")
    with pytest.raises(NambuBCHError, match="route"):
        shadow_hamiltonians(ho3, "12321", route="bch")
    with pytest.raises(InvalidOrderError, match="degree"):
        shadow_hamiltonians(ho3, "12321", degree=0)
    with pytest.raises(InvalidOrderError, match="cannot match"):
        shadow_hamiltonians(ho3, "12321", degree=1)
    with pytest.raises(UnknownPieceError):
        shadow_hamiltonians(ho3, "124")
    with pytest.raises(InvalidOrderError, match="direct"):  # the FI route stops at h^6 (MAX_FI_ORDER)
        shadow_hamiltonians(ho3, "12321", 7, route="fi")
    with pytest.raises(InvalidOrderError):
        shadow_hamiltonians(ho3, "12321", -1)
    with pytest.raises(NotSeparableError):
        shadow_hamiltonians(System("x1 x2 x3", ["x1*x2 + x3", "x3"]), "12321")
    with pytest.raises(NambuBCHError, match="system"):
        shadow_hamiltonians(42, "121")


# ---------------------------------------------------------------------------------------------
# 8. N = 4 (three Hamiltonians, multilinear expansion)
# ---------------------------------------------------------------------------------------------

N4_HAMILTONIANS = ["x1**2/2 + x2**2/2 + x3**2/2 + x4**2/2", "x1**2/2 + x2**2 + 3*x3**2/2 + 2*x4**2", "x1 + x2 + x3 + x4"]


def test_n4_full_split_is_obstructed():
    """N = 4, H1 = |x|^2/2, H2 = sum k x_k^2/2, H3 = sum x_k, every Hamiltonian split (piece i moves x_i):
    the symmetric Phi^{1234321} has NO polynomial shadow triple at h^2 (degree 4 tried; degree 6 too, slower)."""
    S = System("x1 x2 x3 x4", N4_HAMILTONIANS, name="n4")
    F = shadow_hamiltonians(S, "1234321", 2)
    assert not F.exists and F.failed_order == 2 and F.degree[2] == 4
    assert F.details.orders[-1].obstruction_value == -6
    assert "sum_a X_{H_1..dH_a..H_3}" in F.obstruction


def test_n4_full_split_non_symmetric_word_is_obstructed_at_h1():
    """The same N = 4 full split: Phi^{1234} fails already at h^1 (degree 3)."""
    S = System("x1 x2 x3 x4", N4_HAMILTONIANS, name="n4")
    G = shadow_hamiltonians(S, "1234", 1)
    assert not G.exists and G.failed_order == 1 and G.degree[1] == 3


@pytest.mark.parametrize("word, order", [("1234321", 2), ("1234", 2)])
def test_n4_single_split_has_shadows(word, order):
    """N = 4, only H1 split (pieces X_{x_k^2/2, H2, H3}): shadow triples EXIST, Phi^{1234} with h and h^2 terms (the
    h^2 equation carries the cross terms X_{dH1_1, dH2_1, H3} etc.); checked against X_eff independently."""
    S = System("x1 x2 x3 x4", N4_HAMILTONIANS, name="n4-single", split="single")
    F = shadow_hamiltonians(S, word, order)
    assert F.exists and len(F.shadows) == 3
    _check_shadow(S, word, order, F.shadows)
    assert "shadows" in F.to_dict()


def test_fi_route_for_N2_is_eq_CL1_and_SHPV1():
    """N = 2: both uses of the identity coincide (Jacobi, Eq. CL1): one representation; the result is Eq. (SHPV1)."""
    F = shadow_hamiltonians(model("ho"), "121", route="fi")
    assert all(len(c.representations) == 1 for c in F.details.commutators)
    assert zero(F.H_S - model("ho").H + omega**2 * h**2 * x2**2 / (24 * m) - m * omega**4 * h**2 * x1**2 / 12)


@pytest.mark.parametrize("name, word", [("ho3", "123"), ("lotka-volterra", "123"), ("ho", "12")])
def test_fi_route_agrees_with_direct_at_h1(name, word):
    """Non-symmetric words, h^1 (single commutators, Eqs. CL2a/CL2b): the FI route finds a family iff the direct route does."""
    F = shadow_hamiltonians(model(name), word, 1, route="fi")
    D = shadow_hamiltonians(model(name), word, 1)
    assert F.exists == D.exists
    if F.exists:
        assert all(zero(a - b) for a, b in zip(F.shadows, D.shadows))


def test_family_is_frozen_and_built_by_named_constructors():
    """A ShadowFamily is immutable and is what its named constructor makes of the route's own
    result: ``from_direct(direct_route(...))`` and ``from_fi(fi_route(...))`` equal ``shadow_hamiltonians``
    (ho3, Phi^{12321}, Eqs. SH12321c, SG12321c); an undecided obstruction keeps its order (ho3, Phi^{123}, h^1)."""
    import dataclasses

    from nambu_bch.integrators.composition import composition_for
    from nambu_bch.shadow import ShadowFamily

    S = model("ho3")
    comp = composition_for("12321", S.splitting)
    F = shadow_hamiltonians(S, "12321")
    with pytest.raises(dataclasses.FrozenInstanceError):
        F.exists = False
    D = ShadowFamily.from_direct(S, comp, 2, direct_route(S, comp, 2))
    assert D.to_dict() == F.to_dict() and D.shadows == F.shadows and D.free_parameters == ["alpha"]
    G = shadow_hamiltonians(S, "12321", route="fi")
    assert ShadowFamily.from_fi(S, comp, 2, fi_route(S, comp, 2)).to_dict() == G.to_dict()
    assert all(sympy.expand(a - b) == 0 for a, b in zip(F.shadows, G.shadows))
    U = shadow_hamiltonians(S, "123", 1, existence=False)
    assert U.exists is None and U.evidence["outcome"] == "undecided" and U.evidence["order"] == U.failed_order == 1


def test_symmetric_word_below_its_first_correction_is_a_polynomial_pair():
    """FI route, 12321 on ho3 at order 1: the shadows are H, G themselves (Eq. BCH2 has no h^1 term), a polynomial
    pair, reported as such (it was polynomial=None)."""
    fam = shadow_hamiltonians(model("ho3"), "12321", order=1, route="fi")
    assert fam.exists is True and fam.polynomial is True and fam.H_S == sympy.expand(model("ho3").H)


def test_exact_average_multiplies_the_hamiltonians_in_the_ring(monkeypatch):
    """``exact_average``'s columns ``H^k G^l`` are products in the polynomial ring, not sympy expansions of
    ``Mul(H**k, ..)`` (most of its time for quartic pairs); the answer is unchanged: ``<x1^4> = 3 H^2 / 2`` on the
    circles of ``H = (x1^2 + x2^2) / 2``."""
    from nambu_bch.shadow import existence

    S = System("x1 x2", ["x1**2/2 + x2**2/2"])
    x1, _ = S.coordinates
    H = sympy.expand(S.hamiltonians[0])
    expanded, expand = [], sympy.expand

    def spy(e, *a, **k):
        expanded.append(e)
        return expand(e, *a, **k)

    monkeypatch.setattr(existence.sympy, "expand", spy)
    assert existence.exact_average(S, x1**4) == 3 * sympy.Symbol("H") ** 2 / 2
    assert not [e for e in expanded if any(p.base == H for p in sympy.sympify(e).atoms(sympy.Pow))]
