"""Tests of nambu_bch.integrators: compositions as data, exact sub-flows, composed maps, numeric steps.

Literature values name the equation label of Horikoshi, *Shadow Hamiltonians of structure-preserving
integrators for Nambu mechanics*, that they check.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import sympy

from nambu_bch import System, model
from nambu_bch.algebra import is_symplectic, satisfies_nambu_condition
from nambu_bch.errors import (
    ExpressionParseError,
    InconsistentCoefficientsError,
    InvalidCompositionError,
    NambuBCHError,
    NoExactFlowError,
    UnknownPieceError,
)
from nambu_bch.integrators import (
    PAPER_WORDS,
    Composition,
    composed_map,
    composition,
    exact_flow,
    parameter_values,
    step_function,
)
from nambu_bch.integrators.flows import TIME

x1, x2, x3 = sympy.symbols("x1 x2 x3")
m, omega, h, t = sympy.symbols("m omega h t")
half = sympy.Rational(1, 2)
TVT_WORDS = ("12321", "13231", "31213")  # Eq. (equiv1)
VTV_WORDS = ("23132", "21312", "32123")  # Eq. (equiv2)
PARAMS = {"m": 2.0, "omega": 1.5}
# Lotka-Volterra is invariant under the cyclic shift x1 -> x2 -> x3 -> x1, which maps piece k to k+1: the
# six paper words fall into two conjugacy classes, {12321, 23132, 31213} and {13231, 21312, 32123}.
LV_CLASSES = ("12321", "13231")
RIGID_BODY_VALUES = {"I1": 1, "I2": 2, "I3": sympy.Rational(7, 2)}


def same(a, b) -> bool:
    return len(a) == len(b) and all(sympy.simplify(sympy.expand(u - v)) == 0 for u, v in zip(a, b))


def chain(splitting, comp):
    """Apply the exact sub-flows to a state by sympy substitution, in word order (X_{k_1} first)."""
    coords = splitting.system.coordinates
    state = list(coords)
    for k, c in composition(comp, len(splitting)).factors():
        step = exact_flow(splitting[k], coords).at(c * h)
        state = [sympy.expand(e.subs(dict(zip(coords, state)), simultaneous=True)) for e in step]
    return tuple(state)


# --------------------------------------------------------------------------------------------------
# compositions as data
# --------------------------------------------------------------------------------------------------
class TestCompositionData:
    def test_paper_words_12321(self):
        """Sect. 5.1: the 3! = 6 symmetric words; Eq. (12321): half steps except the middle letter."""
        assert sorted(PAPER_WORDS) == sorted(["12321", "13231", "31213", "23132", "21312", "32123"])
        for word in PAPER_WORDS:
            c = composition(word)
            assert c.pieces == tuple(int(ch) for ch in word)
            assert c.coefficients == (half, half, 1, half, half)
            assert all(isinstance(a, sympy.Rational) for a in c.coefficients)
            assert c.symmetric and c.order == 2 and c.name == word
            assert c.adjoint().pieces == c.pieces and c.adjoint().coefficients == c.coefficients
            assert c.factors() == list(zip(c.pieces, c.coefficients))
            assert c.extension == ()
            assert "(ST2)" in c.citation

    @pytest.mark.parametrize("spec", ["TVT", "PV", "tvt", "position-verlet", "121"])
    def test_position_verlet_PV1(self, spec):
        """Eq. (PV1): Phi^TVT = e^{h/2 X_T} e^{h X_V} e^{h/2 X_T}, symmetric, second order."""
        c = composition(spec)
        assert c.pieces == (1, 2, 1) and c.coefficients == (half, 1, half)
        assert c.symmetric and c.order == 2

    @pytest.mark.parametrize("spec", ["VTV", "VV", "velocity-verlet", "212"])
    def test_velocity_verlet(self, spec):
        c = composition(spec)
        assert c.pieces == (2, 1, 2) and c.coefficients == (half, 1, half)
        assert c.symmetric and c.order == 2

    @pytest.mark.parametrize("word", ["12", "21", "123", "312", "1234", "3214"])
    def test_plain_words_first_order(self, word):
        c = composition(word)
        assert c.pieces == tuple(int(ch) for ch in word)
        assert c.coefficients == (1,) * len(word)
        assert not c.symmetric and c.order == 1

    @pytest.mark.parametrize("word, detail", [("1221", "piece 1: 2, piece 2: 2"), ("1223", "piece 2: 2"), ("1212", "piece 1: 2")])
    def test_repeated_letters_in_plain_words_are_inconsistent(self, word, detail):
        """'1221' is not of the paper's odd symmetric form: plain full steps, piece sums 2 -> rejected."""
        with pytest.raises(InconsistentCoefficientsError, match=detail):
            composition(word)

    def test_lie_trotter_and_strang(self):
        lt = composition("lie-trotter", 3)
        assert lt.pieces == (1, 2, 3) and lt.coefficients == (1, 1, 1) and not lt.symmetric and lt.order == 1
        st = composition("strang", 3)
        assert st.pieces == (1, 2, 3, 2, 1) and st.order == 2
        assert composition("strang", 2).pieces == (1, 2, 1)
        with pytest.raises(InvalidCompositionError, match="number of pieces"):
            composition("lie-trotter")

    @pytest.mark.parametrize(
        "spec",
        [
            "1:1/2,2:1,1:1/2",
            " 1: 1/2 , 2:1, 1:0.5",
            [(1, half), (2, 1), (1, half)],
            [(1, Fraction(1, 2)), (2, 1), (1, "1/2")],
            ((1, "Rational(1, 2)"), (2, sympy.Integer(1)), (1, half)),
        ],
    )
    def test_explicit_coefficients(self, spec):
        c = composition(spec)
        assert c.pieces == (1, 2, 1)
        assert c.coefficients == (half, 1, half)
        assert c.symmetric and c.order == 2

    def test_explicit_non_symmetric(self):
        c = composition("1:1/3,2:1,1:2/3")
        assert c.coefficients == (sympy.Rational(1, 3), 1, sympy.Rational(2, 3))
        assert not c.symmetric and c.order == 1
        assert c.adjoint().coefficients == (sympy.Rational(2, 3), 1, sympy.Rational(1, 3))

    def test_composition_passthrough(self):
        c = composition("12321")
        assert composition(c) is c
        assert Composition((1, 2, 1), (half, 1, half)).symmetric

    def test_forest_ruth_exact(self):
        """Forest & Ruth (1990) / Yoshida (1990) triple jump of Eq. (PV1): exact coefficients in QQ(2^(1/3))."""
        c = composition("forest-ruth")
        assert c.pieces == (1, 2, 1, 2, 1, 2, 1)
        assert c.order == 4 and c.symmetric
        assert c.extension == (sympy.cbrt(2),)
        assert not any(a.has(sympy.Float) for a in c.coefficients)
        r = sympy.cbrt(2)
        theta = sympy.Rational(2, 3) + r / 3 + r**2 / 6  # = 1/(2 - 2^(1/3)) in the basis 1, r, r^2
        assert sympy.expand(theta * (2 - r)) == 1
        expected = (theta / 2, theta, (1 - theta) / 2, 1 - 2 * theta, (1 - theta) / 2, theta, theta / 2)
        for a, b in zip(c.coefficients, expected):
            assert sympy.expand(a - b) == 0  # exact: both are Q-combinations of 1, r, r^2
        for k in (1, 2):
            assert sympy.expand(sum(a for p, a in c.factors() if p == k)) == 1  # consistency, exactly
        assert float(c.coefficients[3]) == pytest.approx(-1.7024143839193153)  # 1 - 2 theta

    def test_yoshida_of_paper_word(self):
        c = composition("yoshida:12321")
        assert c.order == 4 and c.symmetric
        for k in (1, 2, 3):
            assert sympy.expand(sum(a for p, a in c.factors() if p == k)) == 1
        with pytest.raises(InvalidCompositionError, match="symmetric base scheme"):
            composition("yoshida:123")

    def test_latex(self):
        tex = composition("12321").to_latex()
        assert tex.startswith(r"\Phi_h = ") and r"e^{h X_{3}}" in tex and r"\frac{1}{2}" in tex


class TestCompositionErrors:
    @pytest.mark.parametrize("spec", ["", "   ", None, [], ()])
    def test_empty(self, spec):
        with pytest.raises(InvalidCompositionError):
            composition(spec)

    @pytest.mark.parametrize("spec", ["0", "120", "1201", "00"])
    def test_zero_digit(self, spec):
        with pytest.raises(InvalidCompositionError, match=f"unknown composition '{spec}'.*digits 1-9"):
            composition(spec)

    @pytest.mark.parametrize("spec", ["abc", "12a", "TVX", "1-2"])
    def test_unknown_word(self, spec):
        with pytest.raises(InvalidCompositionError, match="unknown composition"):
            composition(spec)

    @pytest.mark.parametrize(
        "spec, detail",
        [
            ("1:1/2,2:1", "piece 1: 1/2"),
            ("1:1/2,2:1,1:1/3", "piece 1: 5/6"),
            ([(1, sympy.Rational(1, 3)), (2, 1)], "piece 1: 1/3"),
            ([(1, 1), (2, 2)], "piece 2: 2"),
        ],
    )
    def test_inconsistent_coefficients(self, spec, detail):
        with pytest.raises(InconsistentCoefficientsError, match=f"must sum to 1 for every piece; got {detail}"):
            composition(spec)

    @pytest.mark.parametrize(
        "coeff", [0.5, np.float64(0.5), sympy.Float(0.5)]
    )
    def test_float_coefficients(self, coeff):
        with pytest.raises(InvalidCompositionError, match="float|exact"):
            composition([(1, coeff), (2, 1), (1, coeff)])

    def test_float_message(self):
        with pytest.raises(InvalidCompositionError, match=r"coefficient 0.5 .* is a float; give exact numbers"):
            composition([(1, 0.5), (2, 1), (1, 0.5)])

    @pytest.mark.parametrize("spec", ["1:x,2:1", "1:__import__('os'),2:1"])
    def test_non_numeric_coefficients(self, spec):
        # refused by the parser, or already by the character whitelist of composition text (quotes)
        with pytest.raises((ExpressionParseError, InvalidCompositionError)):
            composition(spec)

    @pytest.mark.parametrize("spec", ["1:I,2:1", [(1, sympy.I), (2, 1)], [(1, sympy.Symbol("a")), (2, 1)]])
    def test_non_real_coefficients(self, spec):
        with pytest.raises(NambuBCHError):
            composition(spec)

    @pytest.mark.parametrize("spec", ["x:1", "1/2", "1:1/2,:1"])
    def test_malformed_explicit(self, spec):
        with pytest.raises(InvalidCompositionError):
            composition(spec)

    def test_bad_piece_numbers(self):
        with pytest.raises(UnknownPieceError):
            Composition((0, 1), (1, 1))
        with pytest.raises(InvalidCompositionError, match="2 pieces but 1 coefficients"):
            Composition((1, 2), (1,))

    def test_unknown_piece_check(self, ho, ho3):
        """A word naming a piece the splitting does not have: UnknownPieceError naming the piece."""
        with pytest.raises(UnknownPieceError, match=r"uses piece\(s\) \[3\].*ho has pieces 1..2"):
            composition("12321").check(ho.splitting)
        with pytest.raises(UnknownPieceError, match=r"\[4\]"):
            composed_map(ho3.splitting, "12421")
        with pytest.raises(UnknownPieceError, match=r"\[3\]"):
            step_function(ho.splitting, "123")
        with pytest.raises(UnknownPieceError):
            composed_map(model("ho3-composite").splitting, "12321")
        assert composition("12321").check(ho3.splitting).name == "12321"


# --------------------------------------------------------------------------------------------------
# exact sub-flows
# --------------------------------------------------------------------------------------------------
class TestExactFlows:
    def test_ho3_subflows_hX1e_hX3e(self, ho3):
        """Eqs. (hX1e)-(hX3e)."""
        sp, c = ho3.splitting, ho3.coordinates
        assert same(exact_flow(sp[1], c).at(h), (x1 + h * x2 / m, x2, x3))
        assert same(exact_flow(sp[2], c).at(h), (x1, x2 - m * omega**2 * h * x1, x3))
        assert same(exact_flow(sp[3], c).at(h), (x1, x2, x3 + 2 * h * x1 * x2 / m))
        for piece in sp.pieces:
            f = exact_flow(piece, c)
            assert f.kind == "shear" and f.polynomial

    def test_ho_subflows_XT_VT(self, ho):
        """Eqs. (XT), (VT): e^{hX_T} moves x1 by h dT/dx2, e^{hX_V} moves x2 by -h dV/dx1."""
        sp, c = ho.splitting, ho.coordinates
        assert same(exact_flow(sp[1], c).at(h), (x1 + h * x2 / m, x2))
        assert same(exact_flow(sp[2], c).at(h), (x1, x2 - h * m * omega**2 * x1))

    def test_generic_subflows_hX1g_hX3g(self):
        """Eqs. (hX1g)-(hX3g) for a generic separable pair with all six parts non-zero."""
        H1, H2, H3 = x1**2, 3 * x2, x3**3
        G1, G2, G3 = x1, -x2**2, 2 * x3**2
        S_ = System("x1 x2 x3", [H1 + H2 + H3, G1 + G2 + G3])
        d = sympy.diff
        c = S_.coordinates
        sp = S_.splitting
        assert same(exact_flow(sp[1], c).at(h), (x1 + h * (d(H2, x2) * d(G3, x3) - d(H3, x3) * d(G2, x2)), x2, x3))
        assert same(exact_flow(sp[2], c).at(h), (x1, x2 + h * (d(H3, x3) * d(G1, x1) - d(H1, x1) * d(G3, x3)), x3))
        assert same(exact_flow(sp[3], c).at(h), (x1, x2, x3 + h * (d(H1, x1) * d(G2, x2) - d(H2, x2) * d(G1, x1))))

    @pytest.mark.parametrize("name", ["rigid-body", "lotka-volterra", "ho3-composite"])
    def test_subflows_solve_their_piece(self, name):
        """d/dt phi_t(x) = X(phi_t(x)) and phi_0 = id for every piece (exactness of the sub-flows)."""
        system = model(name)
        coords = system.coordinates
        for piece in system.splitting.pieces:
            flow = exact_flow(piece, coords)
            assert flow.at(0) == tuple(coords)
            along = dict(zip(coords, flow.expressions))
            for i, comp in enumerate(piece.field.to_sympy()):
                lhs = sympy.diff(flow.expressions[i], TIME)
                rhs = sympy.sympify(comp).subs(along, simultaneous=True)
                assert sympy.simplify(lhs - rhs) == 0

    def test_lotka_volterra_subflows_are_exponentials(self, lotka_volterra):
        """Piece 1 = X_{x1,G}: x2 -> x2 e^{-t x1}, x3 -> x3 e^{t x1} (and cyclically)."""
        sp, c = lotka_volterra.splitting, lotka_volterra.coordinates
        assert exact_flow(sp[1], c).expressions == (x1, x2 * sympy.exp(-t * x1), x3 * sympy.exp(t * x1))
        assert exact_flow(sp[2], c).expressions == (x1 * sympy.exp(t * x2), x2, x3 * sympy.exp(-t * x2))
        assert exact_flow(sp[3], c).expressions == (x1 * sympy.exp(-t * x3), x2 * sympy.exp(t * x3), x3)
        for piece in sp.pieces:
            f = exact_flow(piece, c)
            assert f.kind == "linear" and not f.polynomial

    def test_ho3_composite_subflows_are_polynomial(self, ho3_composite):
        sp, c = ho3_composite.splitting, ho3_composite.coordinates
        f2 = exact_flow(sp[2], c)
        assert f2.kind == "nilpotent" and f2.polynomial
        assert same(f2.expressions, (x1 + 2 * t * x3 / m + t**2 * x2 / m**2, x2, x3 + t * x2 / m))

    def test_non_polynomial_shear(self):
        """A pendulum H = x2^2/2 - cos(x1): shear flows with a general (sin) velocity."""
        S_ = System("x1 x2", ["x2^2/2 - cos(x1)"])
        f = exact_flow(S_.splitting[2], S_.coordinates)
        assert f.kind == "shear" and not f.polynomial
        assert same(f.at(h), (x1, x2 - h * sympy.sin(x1)))
        ys = composed_map(S_.splitting, "TVT")
        assert is_symplectic(ys, S_.coordinates)

    @pytest.mark.parametrize(
        "G",
        ["x1 + x2^2*x3^2", "x1 + x2^3 + x3^3", "x1*x2*x3 + x2^2*x3^2"],
    )
    def test_no_exact_flow(self, G):
        """A single-split piece X_{x1, G} that is nonlinear in the coordinates it moves (x2, x3)."""
        S_ = System("x1 x2 x3", ["x1 + x2 + x3", G], split="single")
        piece = S_.splitting[1]
        assert piece.moving == (1, 2)
        with pytest.raises(NoExactFlowError, match=r"piece 1 .*neither free of nor linear in"):
            exact_flow(piece, S_.coordinates)
        with pytest.raises(NoExactFlowError):
            composed_map(S_.splitting, "12321")
        with pytest.raises(NoExactFlowError):
            step_function(S_.splitting, "123")


# --------------------------------------------------------------------------------------------------
# composed maps: operator order, Eqs. (PV1), (equiv1)-(equiv2), time reversal, Condition1
# --------------------------------------------------------------------------------------------------
class TestComposedMap:
    def test_position_verlet_PV1(self, ho):
        """Eq. (PV1) built by hand from Eqs. (XT), (VT): half drift, full kick, half drift."""
        q_half = x1 + h / 2 * x2 / m
        p_new = x2 - h * m * omega**2 * q_half
        q_new = q_half + h / 2 * p_new / m
        assert same(composed_map(ho.splitting, "TVT"), (q_new, p_new))
        assert same(composed_map(ho.splitting, "121"), (q_new, p_new))
        assert is_symplectic(composed_map(ho.splitting, "TVT"), ho.coordinates)  # Eq. (Symplectic)

    def test_velocity_verlet(self, ho):
        p_half = x2 - h / 2 * m * omega**2 * x1
        q_new = x1 + h * p_half / m
        p_new = p_half - h / 2 * m * omega**2 * q_new
        assert same(composed_map(ho.splitting, "VTV"), (q_new, p_new))

    def test_operator_order_on_non_palindromic_word(self, ho):
        """'12' = e^{hX_1} e^{hX_2} as operators: the STATE is moved by piece 1 first, then by piece 2."""
        sp, c = ho.splitting, ho.coordinates
        phi1 = exact_flow(sp[1], c).at(h)
        phi2 = exact_flow(sp[2], c).at(h)
        after1 = phi1
        after2 = tuple(e.subs(dict(zip(c, after1)), simultaneous=True) for e in phi2)
        expected = (x1 + h * x2 / m, x2 - h * m * omega**2 * (x1 + h * x2 / m))
        assert same(after2, expected)
        got = composed_map(sp, "12")
        assert same(got, expected)
        assert not same(got, composed_map(sp, "21"))
        # the operator (Lie series) reading: (e^{hX_1} e^{hX_2} f)(x) = f(phi_2(phi_1(x))) for f = x_i
        # -- check the O(h^2) term of x2: e^{hX1}e^{hX2} x2 = x2 + h X2 x2 + h X1 X2 x2 + ... ;
        #    X1 X2 x2 = X1(-m w^2 x1) = -w^2 x2
        series = sympy.series(got[1], h, 0, 3).removeO()
        assert sympy.expand(series - (x2 - h * m * omega**2 * x1 - h**2 * omega**2 * x2)) == 0
        # the numeric step applies the sub-flows in the same order
        step = step_function(sp, "12", PARAMS)
        x0 = np.array([0.3, -0.7])
        values = parameter_values(ho, PARAMS)
        f = sympy.lambdify((x1, x2, h), [e.subs(values) for e in got])
        assert np.allclose(step(x0, 0.1), f(*x0, 0.1), rtol=0, atol=1e-14)
        f21 = sympy.lambdify((x1, x2, h), [e.subs(values) for e in composed_map(sp, "21")])
        assert not np.allclose(step(x0, 0.1), f21(*x0, 0.1))

    @pytest.mark.parametrize("word", PAPER_WORDS + ("123", "213"))
    def test_composed_map_is_chain_of_subflows(self, ho3, word):
        """The ring-composed map equals applying the exact sub-flows left to right by substitution."""
        assert same(composed_map(ho3.splitting, word), chain(ho3.splitting, word))

    def test_composed_map_with_algebraic_coefficients(self, ho):
        """Forest-Ruth (coefficients in QQ(2^(1/3))) composed exactly equals the substitution chain."""
        assert same(composed_map(ho.splitting, "forest-ruth"), chain(ho.splitting, "forest-ruth"))

    @pytest.mark.parametrize("word", TVT_WORDS)
    def test_equiv1(self, ho, ho3, word):
        """Eq. (equiv1): the (x1, x2) part of Phi^{12321}, Phi^{13231}, Phi^{31213} is Phi^TVT of the oscillator."""
        assert composed_map(ho3.splitting, word)[:2] == composed_map(ho.splitting, "TVT")

    @pytest.mark.parametrize("word", VTV_WORDS)
    def test_equiv2(self, ho, ho3, word):
        """Eq. (equiv2): the (x1, x2) part of Phi^{23132}, Phi^{21312}, Phi^{32123} is Phi^VTV."""
        assert composed_map(ho3.splitting, word)[:2] == composed_map(ho.splitting, "VTV")

    def test_equiv_x3_decoupled_but_word_dependent(self, ho3):
        """Eq. (equiv1): 12321 and 31213 agree on (x1, x2) but their x3 updates differ (distinct schemes)."""
        a, b = composed_map(ho3.splitting, "12321"), composed_map(ho3.splitting, "31213")
        assert a[:2] == b[:2]
        assert sympy.expand(a[2] - b[2]) != 0
        for word in PAPER_WORDS:  # x3 never feeds back into (x1, x2)
            assert not any(e.has(x3) for e in composed_map(ho3.splitting, word)[:2])

    @pytest.mark.parametrize(
        "name, word", [("ho3", w) for w in PAPER_WORDS] + [("lotka-volterra", w) for w in LV_CLASSES] + [("ho", "TVT")]
    )
    def test_time_reversal_symbolic(self, name, word):
        """Phi_{-h} o Phi_h = id exactly for the symmetric words (Sect. 4.1, after Eq. ST2; Sect. 2.2 for TVT)."""
        system = model(name)
        coords = system.coordinates
        forward = composed_map(system.splitting, word)
        backward = composed_map(system.splitting, word, h=-h)
        roundtrip = [e.subs(dict(zip(coords, forward)), simultaneous=True) for e in backward]
        assert all(sympy.simplify(sympy.powsimp(sympy.expand(a - x))) == 0 for a, x in zip(roundtrip, coords))

    @pytest.mark.parametrize("name", ["ho3", "lotka-volterra"])
    def test_no_time_reversal_for_123(self, name):
        """The plain word 123 is not symmetric: Phi_{-h} o Phi_h != id (shown at one exact point)."""
        system = model(name)
        coords = system.coordinates
        forward = composed_map(system.splitting, "123")
        backward = composed_map(system.splitting, "123", h=-h)
        roundtrip = [e.subs(dict(zip(coords, forward)), simultaneous=True) for e in backward]
        point = {x1: sympy.Rational(1, 2), x2: sympy.Rational(1, 3), x3: sympy.Rational(2, 5), h: sympy.Rational(1, 7),
                 m: 2, omega: 3}
        deviation = [sympy.N((a - x).subs(point), 30) for a, x in zip(roundtrip, coords)]
        assert max(abs(d) for d in deviation) > 1e-6

    def test_time_reversal_adjoint(self, ho3):
        """Phi_{-h} o Phi_h = id for 123 followed by its adjoint 321 at -h... i.e. adjoint(123) undoes 123."""
        comp = composition("123")
        forward = composed_map(ho3.splitting, comp)
        undo = composed_map(ho3.splitting, comp.adjoint(), h=-h)
        roundtrip = [e.subs(dict(zip(ho3.coordinates, forward)), simultaneous=True) for e in undo]
        assert same(tuple(roundtrip), ho3.coordinates)


# --------------------------------------------------------------------------------------------------
# Eq. (Condition1) for every sub-flow and every composition of every built-in model
# --------------------------------------------------------------------------------------------------
WORDS_BY_MODEL = {
    "ho": ("121", "212", "12", "21", "forest-ruth"),
    "ho3": PAPER_WORDS + ("123", "321"),
    "rigid-body": ("12321", "123"),  # symbolic I1, I2, I3; all six words at exact rational I below
    "lotka-volterra": LV_CLASSES + ("123",),  # the other four paper words are conjugate (see LV_CLASSES)
    "ho3-composite": ("121", "212", "12"),
}


@pytest.mark.parametrize("name", sorted(WORDS_BY_MODEL))
def test_condition1_every_subflow(name):
    """Eq. (Condition1): every exact sub-flow has det(d phi_t / dx) = 1 (symbolic in t and the parameters)."""
    system = model(name)
    for piece in system.splitting.pieces:
        assert satisfies_nambu_condition(exact_flow(piece, system.coordinates).expressions, system.coordinates)


@pytest.mark.parametrize(
    "name, word", [(name, word) for name, words in sorted(WORDS_BY_MODEL.items()) for word in words]
)
def test_condition1_every_composition(name, word):
    """Eq. (Condition1) for the composed map Phi_h (symbolic det = 1): structure-preserving integrators."""
    system = model(name)
    assert satisfies_nambu_condition(composed_map(system.splitting, word), system.coordinates)


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_condition1_rigid_body_all_words(rigid_body, word):
    """Eq. (Condition1) for all six words on the rigid body with exact rational moments of inertia."""
    values = {s: RIGID_BODY_VALUES[s.name] for s in rigid_body.parameters}
    ys = [sympy.sympify(e).subs(values) for e in composed_map(rigid_body.splitting, word)]
    assert satisfies_nambu_condition(ys, rigid_body.coordinates)


@pytest.mark.parametrize("word", ["12321", "123"])
def test_condition1_literal_epsilon_identity(ho3, word):
    """Eq. (Condition1) as written, eps_lmn dy_i/dx_l dy_j/dx_m dy_k/dx_n = eps_ijk, for ho3's composed maps."""
    from itertools import permutations, product

    J = sympy.Matrix(composed_map(ho3.splitting, word)).jacobian(sympy.Matrix(ho3.coordinates))
    for i, j, k in product(range(3), repeat=3):
        lhs = sum(sympy.LeviCivita(a, b, c) * J[i, a] * J[j, b] * J[k, c] for a, b, c in permutations(range(3)))
        assert sympy.simplify(sympy.expand(lhs) - sympy.LeviCivita(i, j, k)) == 0


def test_condition1_fails_for_non_volume_preserving_map(ho3):
    """Control: a map that is not a composition of exact sub-flows (explicit Euler) violates Eq. (Condition1)."""
    euler = tuple(x + h * v for x, v in zip(ho3.coordinates, ho3.equations_of_motion()))
    assert not satisfies_nambu_condition(euler, ho3.coordinates)


# --------------------------------------------------------------------------------------------------
# numerics: order by observed convergence (Eq. ST2), numeric time reversal, step_function
# --------------------------------------------------------------------------------------------------
def oscillator_solution(x0, T, mass=PARAMS["m"], w=PARAMS["omega"]):
    """Exact solution of Eq. (NambuOHeqs) (and of Eq. HO1 for the first two components)."""
    q0, p0 = x0[0], x0[1]
    q = q0 * np.cos(w * T) + p0 / (mass * w) * np.sin(w * T)
    p = -mass * w * q0 * np.sin(w * T) + p0 * np.cos(w * T)
    out = [q, p]
    if len(x0) == 3:
        out.append(x0[2] + q**2 - q0**2)  # G = x3 - x1^2 is conserved
    return np.array(out)


def observed_order(system, comp, x0, T=1.0, steps=(8, 16, 32, 64)):
    """Slope of the log-log fit of the fixed-time error against the exact solution."""
    step = step_function(system.splitting, comp, PARAMS)
    exact = oscillator_solution(x0, T)
    hs, errors = [], []
    for n in steps:
        hh = T / n
        x = np.array(x0, dtype=float)
        for _ in range(n):
            x = step(x, hh)
        hs.append(hh)
        errors.append(np.max(np.abs(x - exact)))
    return np.polyfit(np.log(hs), np.log(errors), 1)[0]


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_second_order_ST2(ho3, word):
    """Eq. (ST2): the six symmetric words are second order (log-log slope of the global error ~ 2)."""
    assert observed_order(ho3, word, [0.4, -0.3, 0.4**2 + 0.05]) == pytest.approx(2.0, abs=0.15)


@pytest.mark.parametrize("word", ["TVT", "VTV"])
def test_second_order_verlet_ST1(ho, word):
    """Eq. (ST1): position / velocity Verlet are second order."""
    assert observed_order(ho, word, [0.4, -0.3]) == pytest.approx(2.0, abs=0.15)


def test_fourth_order_forest_ruth(ho):
    """Forest-Ruth / Yoshida triple jump of TVT: observed order ~ 4 on the oscillator."""
    assert observed_order(ho, "forest-ruth", [0.4, -0.3], T=2.0, steps=(8, 12, 16, 24)) == pytest.approx(4.0, abs=0.25)


def test_fourth_order_yoshida_paper_word(ho3):
    assert observed_order(ho3, "yoshida:12321", [0.4, -0.3, 0.2], T=2.0, steps=(8, 12, 16, 24)) == pytest.approx(
        4.0, abs=0.25
    )


@pytest.mark.parametrize("name, word", [("ho", "lie-trotter"), ("ho", "21"), ("ho3", "lie-trotter"), ("ho3", "312")])
def test_first_order_lie_trotter(name, word):
    system = model(name)
    x0 = [0.4, -0.3] if system.N == 2 else [0.4, -0.3, 0.2]
    comp = composition(word, len(system.splitting))
    assert observed_order(system, comp, x0, steps=(16, 32, 64, 128)) == pytest.approx(1.0, abs=0.15)


def test_local_error_order_ST2(ho3):
    """One-step error of Phi^{12321} against the exact flow is O(h^3) (Eq. ST2), of 123 O(h^2)."""
    x0 = np.array([0.4, -0.3, 0.2])
    hs = np.array([0.1, 0.05, 0.025, 0.0125])
    for word, expected in [("12321", 3.0), ("123", 2.0)]:
        step = step_function(ho3.splitting, word, PARAMS)
        errors = [np.max(np.abs(step(x0, hh) - oscillator_solution(x0, hh))) for hh in hs]
        assert np.polyfit(np.log(hs), np.log(errors), 1)[0] == pytest.approx(expected, abs=0.15)


@pytest.mark.parametrize("name", ["ho", "ho3", "rigid-body", "lotka-volterra", "ho3-composite"])
def test_numeric_time_reversal(name):
    system = model(name)
    n = len(system.splitting)
    x0 = np.array([0.7, 0.4, 1.1][: system.N])
    params = {k: float(v) for k, v in RIGID_BODY_VALUES.items()} if name == "rigid-body" else {}
    params.update({p: 1.7 for p in ("m", "omega") if p in {s.name for s in system.parameters}})
    step = step_function(system.splitting, composition("strang", n), params)
    back = step(step(x0, 0.3), -0.3)
    assert np.allclose(back, x0, rtol=0, atol=1e-13)
    plain = step_function(system.splitting, composition("lie-trotter", n), params)
    assert not np.allclose(plain(plain(x0, 0.3), -0.3), x0, rtol=0, atol=1e-6)


@pytest.mark.parametrize("name", ["ho3", "rigid-body", "lotka-volterra", "ho3-composite"])
def test_step_function_matches_composed_map(name):
    """The numpy step (sub-flows lambdified one by one) equals the exact composed map, also batched."""
    system = model(name)
    word = "12321" if len(system.splitting) == 3 else "121"
    params = {"m": 2.0, "omega": 1.5} if "m" in {p.name for p in system.parameters} else {}
    if name == "rigid-body":
        params = {"I1": 1.0, "I2": 2.0, "I3": 3.0}
    exact = composed_map(system.splitting, word)
    values = parameter_values(system, params)
    f = sympy.lambdify((*system.coordinates, h), [sympy.sympify(e).subs(values) for e in exact])
    step = step_function(system.splitting, word, params)
    x0 = np.array([0.7, 0.4, 1.1])
    assert np.allclose(step(x0, 0.2), f(*x0, 0.2), rtol=1e-13, atol=1e-13)
    batch = np.array([[0.7, 0.1], [0.4, 0.2], [1.1, 0.3]])
    out = step(batch, 0.2)
    assert out.shape == (3, 2)
    assert np.allclose(out[:, 1], f(0.1, 0.2, 0.3, 0.2), rtol=1e-13, atol=1e-13)


def test_parameter_values(ho3):
    assert parameter_values(ho3) == {m: 1.0, omega: 1.0}
    assert parameter_values(ho3, {"m": 2}) == {m: 2.0, omega: 1.0}
    with pytest.raises(NambuBCHError, match="unknown parameter"):
        parameter_values(ho3, {"mass": 2})


def test_invariants_bounded_numerically(ho3, lotka_volterra):
    """Long runs of symmetric words keep the Hamiltonians near their initial values (no drift)."""
    step = step_function(ho3.splitting, "12321", PARAMS)
    x = np.array([0.4, -0.3, 0.4**2])
    for _ in range(2000):
        x = step(x, 0.05)
    assert abs(x[2] - x[0] ** 2) < 1e-2  # G = x3 - x1^2 stays near 0
    step = step_function(lotka_volterra.splitting, "12321")
    x = np.array([0.7, 0.4, 1.1])
    H0, G0 = x.sum(), x.prod()
    for _ in range(2000):
        x = step(x, 0.05)
    assert abs(x.sum() - H0) < 1e-2 and abs(x.prod() - G0) < 1e-2
