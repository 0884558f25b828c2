"""Tests of nambu_bch.systems: System, separable decomposition, full / single splittings, the catalog.

Literature values name the equation label of Horikoshi, *Shadow Hamiltonians of structure-preserving
integrators for Nambu mechanics*, that they check.
"""

from __future__ import annotations

from itertools import permutations

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import System, model, model_names
from nambu_bch.algebra import PolynomialAlgebra, VectorField, liouville_field
from nambu_bch.errors import (
    ExpressionParseError,
    InvalidSystemError,
    NambuBCHError,
    NotSeparableError,
    UnknownModelError,
)
from nambu_bch.systems import is_separable, separate

x1, x2, x3, x4, y = sympy.symbols("x1 x2 x3 x4 y")
m, omega, I1, I2, I3 = sympy.symbols("m omega I1 I2 I3")
FULL_SPLIT_MODELS = ["ho", "ho3", "rigid-body"]
ALL_MODELS = ["ho", "ho3", "rigid-body", "lotka-volterra", "ho3-composite", "pendulum", "henon-heiles", "fpu-beta", "toda",
              "exp-well", "rational", "kepler", "kepler-3d", "morse", "lennard-jones", "rigid-body-lp", "ho3-pair"]


def simplified(field):
    return tuple(sympy.simplify(c) for c in field.to_sympy())


def same(a, b) -> bool:
    return all(sympy.simplify(u - v) == 0 for u, v in zip(a, b)) and len(a) == len(b)


# --------------------------------------------------------------------------------------------------
# separable decomposition
# --------------------------------------------------------------------------------------------------
class TestSeparate:
    def test_ho3_G_and_H_AB_CD(self):
        """Eqs. (AB), (CD): H = A(x2) + B(x3), G = C(x3) + D(x1)."""
        H, G = model("ho3").hamiltonians
        assert separate(H, [x1, x2, x3], "H") == (0, x2**2 / (2 * m), m * omega**2 * x3 / 2)
        assert separate(G, [x1, x2, x3], "G") == (-x1**2, 0, x3)

    def test_constants_dropped_and_terms_grouped(self):
        parts = separate(sympy.sin(x1) + x1**2 + sympy.cos(x2) + 5 + m * omega, [x1, x2, x3])
        assert parts == (x1**2 + sympy.sin(x1), sympy.cos(x2), 0)

    def test_expanded_before_separation(self):
        """(x1 + 1)^2 + x2 is separable once expanded; x1 x2 - x2 x1 cancels."""
        assert separate((x1 + 1) ** 2 + x2, [x1, x2]) == (x1**2 + 2 * x1, x2)
        assert is_separable(x1 * x2 - x2 * x1 + x3, [x1, x2, x3])

    @pytest.mark.parametrize(
        "expr, term",
        [
            (x1 * x2 + x3, "x1*x2"),
            ((x1 + x2) ** 2, "2*x1*x2"),
            (x1 + sympy.sin(x1 + x3), "sin(x1 + x3)"),
            (x1 * x2 * x3, "x1*x2*x3"),
            (-2 * x1 * x2 + 2 * x3**2, "-2*x1*x2"),
        ],
    )
    def test_not_separable_names_coupling_term(self, expr, term):
        with pytest.raises(NotSeparableError) as info:
            separate(expr, [x1, x2, x3], "G")
        message = str(info.value)
        assert f"the term {term} couples" in message
        assert message.startswith("G = ")
        assert not is_separable(expr, [x1, x2, x3])

    @settings(deadline=None, max_examples=25)
    @given(st.lists(st.tuples(st.integers(-3, 3), st.integers(0, 3), st.integers(0, 2)), min_size=1, max_size=6))
    def test_separate_recovers_random_separable_sums(self, terms):
        coords = [x1, x2, x3]
        parts = [sympy.Integer(0)] * 3
        for c, e, i in terms:
            if e:  # constants are dropped
                parts[i] += c * coords[i] ** e
        got = separate(sum(parts) + 7, coords)
        assert all(sympy.expand(a - b) == 0 for a, b in zip(got, parts))
        assert sympy.expand(sum(got) - sum(parts)) == 0


# --------------------------------------------------------------------------------------------------
# full split, Eqs. (HGs), (X1)-(X3)
# --------------------------------------------------------------------------------------------------
class TestFullSplit:
    @pytest.mark.parametrize("name", FULL_SPLIT_MODELS)
    def test_pieces_sum_to_liouville_field_HGs(self, name):
        """Eq. (HGs): X_1 + ... + X_N = X_{H,G} (X_T + X_V = X_H for N = 2)."""
        system = model(name)
        sp = system.splitting
        assert sp.kind == "full"
        assert len(sp) == system.N
        assert sp.check_sum()
        total = VectorField.zero(system.algebra)
        for f in sp.fields:
            total = total + f
        assert total == liouville_field(system.algebra, *system.hamiltonians)

    @pytest.mark.parametrize("name", FULL_SPLIT_MODELS)
    def test_piece_i_is_a_shear_moving_x_i(self, name):
        """Eqs. (X1)-(X3): piece i moves only x_i, with a velocity free of x_i."""
        system = model(name)
        for i, piece in enumerate(system.splitting.pieces):
            assert piece.number == i + 1
            assert system.splitting[i + 1] is piece
            assert piece.moving == (i,)
            comps = piece.field.to_sympy()
            assert all(c == 0 for j, c in enumerate(comps) if j != i)
            assert not comps[i].has(system.coordinates[i])

    def test_ho3_pieces_hX1_hX3(self, ho3):
        """Eqs. (hX1)-(hX3): X_1 = X_{A,C}, X_2 = X_{B,D}, X_3 = X_{A,D}, with A, B, C, D of Eqs. (AB), (CD)."""
        A, B, C, D = x2**2 / (2 * m), m * omega**2 * x3 / 2, x3, -x1**2
        sp = ho3.splitting
        assert sp[1].terms == ((A, C),)
        assert sp[2].terms == ((B, D),)
        assert sp[3].terms == ((A, D),)
        assert same(sp[1].field.to_sympy(), (x2 / m, 0, 0))
        assert same(sp[2].field.to_sympy(), (0, -m * omega**2 * x1, 0))
        assert same(sp[3].field.to_sympy(), (0, 0, 2 * x1 * x2 / m))
        assert "X_{" in sp[1].label()

    def test_ho_pieces_XTXV(self, ho):
        """Eq. (XTXV): piece 1 = X_T = (1/m) x2 d/dx1 (moves q), piece 2 = X_V = -m w^2 x1 d/dx2."""
        sp = ho.splitting
        assert sp[1].terms == ((x2**2 / (2 * m),),)
        assert sp[2].terms == ((m * omega**2 * x1**2 / 2,),)
        assert same(sp[1].field.to_sympy(), (x2 / m, 0))
        assert same(sp[2].field.to_sympy(), (0, -m * omega**2 * x1))

    def test_rigid_body_euler_equations(self, rigid_body):
        """The full split of the free rigid body gives Euler's equations, one component per piece.

        With the catalog's order (H = sum x_i^2/2I_i first, G = |x|^2/2 second) Eq. (gLiouville) gives
        dx/dt = grad H x grad G = omega x L, i.e. dL_1/dt = (1/I2 - 1/I3) L2 L3 and cyclic
        (Euler's equations L' = L x omega with the opposite orientation, i.e. Nambu's {f, G, H} = -{f, H, G}).
        """
        sp = rigid_body.splitting
        L = (x1, x2, x3)
        I_ = (I1, I2, I3)
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            expected = [0, 0, 0]
            expected[i] = (1 / I_[j] - 1 / I_[k]) * L[j] * L[k]
            assert same(sp[i + 1].field.to_sympy(), expected)
            # two Liouville terms per piece: X_{H_j,G_k} + X_{H_k,G_j} (Eqs. X1-X3)
            assert len(sp[i + 1].terms) == 2
        eom = rigid_body.equations_of_motion()
        omega_vec = sympy.Matrix([L[i] / I_[i] for i in range(3)])
        cross = omega_vec.cross(sympy.Matrix(L))
        assert same(eom, tuple(cross))
        # both Hamiltonians (energy and |L|^2) are conserved
        for Hk in rigid_body.hamiltonians:
            assert rigid_body.algebra.is_zero(rigid_body.vector_field.apply(Hk))

    def test_generic_separable_N3_X1_X3(self):
        """Eqs. (X1)-(X3) for a generic polynomial separable pair (all six H_i, G_j non-zero)."""
        H = x1**2 + 3 * x2 + x3**3
        G = x1 - x2**2 + 2 * x3**2
        S_ = System("x1 x2 x3", [H, G])
        d = sympy.diff
        H1, H2, H3 = x1**2, 3 * x2, x3**3
        G1, G2, G3 = x1, -x2**2, 2 * x3**2
        sp = S_.splitting
        assert same(sp[1].field.to_sympy(), (d(H2, x2) * d(G3, x3) - d(H3, x3) * d(G2, x2), 0, 0))
        assert same(sp[2].field.to_sympy(), (0, d(H3, x3) * d(G1, x1) - d(H1, x1) * d(G3, x3), 0))
        assert same(sp[3].field.to_sympy(), (0, 0, d(H1, x1) * d(G2, x2) - d(H2, x2) * d(G1, x1)))
        assert set(sp[1].terms) == {(H2, G3), (H3, G2)}
        assert sp.check_sum()

    def test_N4_generalisation(self):
        """N = 4 with three separable Hamiltonians: pieces are shears summing to X_{H1,H2,H3}."""
        Hs = [x1**2 + x2, x3 + x4**2 + x1, x2**2 + x3**3 + x4]
        S_ = System("x1 x2 x3 x4", Hs)
        assert S_.N == 4 and S_.G == Hs[1]
        sp = S_.splitting
        assert len(sp) == 4 and sp.check_sum()
        coords = (x1, x2, x3, x4)
        total = [0] * 4
        parts = [separate(H, coords) for H in Hs]
        for i, piece in enumerate(sp.pieces):
            assert piece.moving == (i,)
            comps = piece.field.to_sympy()
            assert all(c == 0 for j, c in enumerate(comps) if j != i)
            assert not comps[i].has(coords[i])  # a shear: the velocity of x_i is free of x_i
            # the terms are X_{H1_{j1}, H2_{j2}, H3_{j3}} over distinct j's != i
            others = [j for j in range(4) if j != i]
            expected_terms = {
                tuple(part[j] for part, j in zip(parts, js))
                for js in permutations(others)
            }
            expected_terms = {t for t in expected_terms if all(f != 0 for f in t)}
            assert set(piece.terms) == expected_terms
            total[i] = comps[i]
        alg = PolynomialAlgebra(coords)
        assert same(tuple(total), liouville_field(alg, *Hs).to_sympy())
        assert same(S_.equations_of_motion(), tuple(total))

    def test_N4_moving_velocities_literal(self):
        """X^1 for N = 4 is sum over permutations of (j,k,l) of {2,3,4}: sgn * H1_j' H2_k' H3_l'."""
        Hs = [x2 + x3**2 + x4, x2**2 + x3 + x4**3, x2**3 + x3 + x4**2]
        comp = System("x1 x2 x3 x4", Hs).splitting[1].field.to_sympy()[0]
        J = sympy.Matrix([[sympy.diff(H, v) for v in (x2, x3, x4)] for H in Hs])
        assert sympy.expand(comp - J.det()) == 0

    def test_non_separable_full_split_names_term(self):
        """Asking the full split of ho3-composite's G = 2 x3^2 - 2 x1 x2 names the coupling term."""
        comp = model("ho3-composite")
        S_ = System(comp.coordinates, comp.hamiltonians, comp.parameters, split="full")
        with pytest.raises(NotSeparableError, match=r"G = .*the term -2\*x1\*x2 couples x1, x2"):
            S_.splitting

    def test_non_separable_n2_names_H(self):
        with pytest.raises(NotSeparableError, match=r"^H = x1\*x2 \+ x2\*\*2 .*the term x1\*x2"):
            System("x1 x2", ["x1*x2 + x2^2"]).splitting

    def test_non_separable_n4_names_the_hamiltonian_as_the_system_does(self):
        """The error names the Hamiltonian as System does (H, H2, H3 for N = 4)."""
        with pytest.raises(NotSeparableError, match=r"^H3 = x3\*x4 .*the term x3\*x4 couples x3, x4"):
            System("x1 x2 x3 x4", ["x1 + x2", "x3", "x3*x4"]).splitting
        with pytest.raises(NotSeparableError, match=r"^H = x1\*x2 .*the term x1\*x2"):
            System("x1 x2 x3 x4", ["x1*x2", "x3", "x4"]).splitting


# --------------------------------------------------------------------------------------------------
# single split (the paper's footnote)
# --------------------------------------------------------------------------------------------------
class TestSingleSplit:
    def test_lotka_volterra_pieces(self, lotka_volterra):
        """Cyclic Lotka-Volterra (Sect. Conclusions): H = x1+x2+x3, G = x1 x2 x3; piece i = X_{x_i, G}."""
        sp = lotka_volterra.splitting
        assert sp.kind == "single" and len(sp) == 3
        coords = (x1, x2, x3)
        G = x1 * x2 * x3
        for i, piece in enumerate(sp.pieces):
            assert piece.terms == ((coords[i], G),)
            assert piece.field == liouville_field(lotka_volterra.algebra, coords[i], G)
            assert piece.moving == tuple(j for j in range(3) if j != i)
            assert piece.field.components[i] == 0 or lotka_volterra.algebra.is_zero(piece.field.components[i])
        assert same(sp[1].field.to_sympy(), (0, -x1 * x2, x1 * x3))
        assert same(sp[2].field.to_sympy(), (x1 * x2, 0, -x2 * x3))
        assert same(sp[3].field.to_sympy(), (-x1 * x3, x2 * x3, 0))
        assert sp.check_sum()
        # the Lotka-Volterra equations dx_i/dt = x_i (x_{i+1} - x_{i-1})
        assert same(lotka_volterra.equations_of_motion(), (x1 * (x2 - x3), x2 * (x3 - x1), x3 * (x1 - x2)))

    def test_lie_poisson_rotations_are_written_without_a_matrix_exponential(self, monkeypatch):
        """Piece i of the Lie-Poisson rigid body (McLachlan 1993) rotates the other two axes by the angle t x_i / I_i:
        its flow is written in closed form, with no matrix exponential (a Jordan form and simplify, ~0.5 s a piece,
        paid by every first use of the model's splitting)."""
        from sympy.matrices.matrixbase import MatrixBase

        from nambu_bch.systems.piece_flows import piece_flow

        calls = []
        exp = MatrixBase.exp
        monkeypatch.setattr(MatrixBase, "exp", lambda self: calls.append(self) or exp(self))
        S = model("rigid-body-lp")
        t = sympy.Symbol("t")
        X = S.coordinates
        for i, piece in enumerate(S.splitting.pieces):
            flow = piece_flow.__wrapped__(piece, X)  # uncached: the work is counted
            a, b = (j for j in range(3) if j != i)
            w = X[i] / S.parameters[i] * (-1) ** i  # dx_a/dt = -w x_b, dx_b/dt = w x_a
            c, s = sympy.cos(t * w), sympy.sin(t * w)
            expected = list(X)
            expected[a], expected[b] = sympy.expand(X[a] * c - X[b] * s), sympy.expand(X[a] * s + X[b] * c)
            assert (flow.kind, flow.polynomial, flow.expressions) == ("rotation", False, tuple(expected))
        assert calls == []

    def test_ho3_composite(self, ho3_composite):
        """(q^2, p^2, qp) oscillator: H = x2/2m + m w^2 x1/2, G = 2 x3^2 - 2 x1 x2; pieces X_{H_i, G}."""
        sp = ho3_composite.splitting
        assert sp.kind == "single" and len(sp) == 2
        G = 2 * x3**2 - 2 * x1 * x2
        assert sp[1].terms == ((m * omega**2 * x1 / 2, G),)
        assert sp[2].terms == ((x2 / (2 * m), G),)
        assert sp.check_sum()
        assert sp[1].moving == (1, 2) and sp[2].moving == (0, 2)
        # d(q^2)/dt = 2qp/m, d(p^2)/dt = -2 m w^2 qp, d(qp)/dt = p^2/m - m w^2 q^2
        assert same(ho3_composite.equations_of_motion(), (2 * x3 / m, -2 * m * omega**2 * x3, x2 / m - m * omega**2 * x1))
        # consistent with q, p of the oscillator
        q, p, t = sympy.symbols("q p t")
        subs = {x1: q**2, x2: p**2, x3: q * p}
        qdot, pdot = p / m, -m * omega**2 * q
        for xi, expr in zip((q**2, p**2, q * p), ho3_composite.equations_of_motion()):
            lhs = sympy.diff(xi, q) * qdot + sympy.diff(xi, p) * pdot
            assert sympy.simplify(lhs - expr.subs(subs)) == 0

    def test_single_split_zero_pieces_skipped(self):
        """Coordinates on which H does not depend give no piece; numbering stays 1..n."""
        S_ = System("x1 x2 x3", ["x1 + x3", "x1*x2*x3"], split="single")
        sp = S_.splitting
        assert len(sp) == 2
        assert sp[1].terms[0][0] == x1 and sp[2].terms[0][0] == x3
        assert sp.check_sum()

    def test_single_split_needs_separable_H(self):
        with pytest.raises(NotSeparableError, match=r"H = .*x1\*x2"):
            System("x1 x2 x3", ["x1*x2 + x3", "x1 + x2 + x3"], split="single").splitting


# --------------------------------------------------------------------------------------------------
# System: construction, views, equations of motion
# --------------------------------------------------------------------------------------------------
class TestSystem:
    def test_ho3_equations_of_motion_NambuOHeqs(self, ho3):
        """Eq. (NambuOHeqs): dx1/dt = x2/m, dx2/dt = -m w^2 x1, dx3/dt = (2/m) x1 x2."""
        assert same(ho3.equations_of_motion(), (x2 / m, -m * omega**2 * x1, 2 * x1 * x2 / m))

    def test_ho3_hamiltonians_H_G(self, ho3):
        """Eqs. (H), (G)."""
        assert ho3.N == 3
        assert sympy.simplify(ho3.H - (x2**2 / (2 * m) + m * omega**2 * x3 / 2)) == 0
        assert sympy.simplify(ho3.G - (x3 - x1**2)) == 0
        assert ho3.coordinates == (x1, x2, x3) and ho3.parameters == (m, omega)

    def test_ho_HO1(self, ho):
        """Eq. (HO1) and Hamilton's equations; G is None for N = 2."""
        assert ho.N == 2 and ho.G is None
        assert sympy.simplify(ho.H - (x2**2 / (2 * m) + m * omega**2 * x1**2 / 2)) == 0
        assert same(ho.equations_of_motion(), (x2 / m, -m * omega**2 * x1))

    @pytest.mark.parametrize("name", ALL_MODELS)
    def test_hamiltonians_conserved_and_divergence_free(self, name):
        system = model(name)
        X_ = system.vector_field
        for H in system.hamiltonians:
            assert system.algebra.is_zero(X_.apply(H))
        assert system.algebra.is_zero(X_.divergence())

    def test_catalog(self):
        assert tuple(model_names()) == tuple(ALL_MODELS)
        assert model("ho3") is model("ho3")
        for name in ALL_MODELS:
            assert model(name).name == name

    def test_strings_and_symbols_equivalent(self):
        S1 = System("x1 x2 x3", ["x2^2/(2*m) + m*omega^2*x3/2", "x3 - x1^2"], "m omega")
        S2 = System([x1, x2, x3], [x2**2 / (2 * m) + m * omega**2 * x3 / 2, x3 - x1**2], [m, omega])
        S3 = System("x1, x2, x3", (S2.H, S2.G), "m, omega")
        assert S1.hamiltonians == S2.hamiltonians == S3.hamiltonians
        assert S1.coordinates == S2.coordinates == S3.coordinates

    def test_single_hamiltonian_as_string(self):
        S_ = System("x1 x2", "x2^2/2 + x1^4/4")
        assert S_.H == x2**2 / 2 + x1**4 / 4
        assert same(S_.equations_of_motion(), (x2, -x1**3))

    def test_parameters_in_denominators_exact(self):
        S_ = System("x1 x2", ["x2^2/(2*m) + k*x1^2/2"], "m k")
        assert same(S_.equations_of_motion(), (x2 / m, -sympy.Symbol("k") * x1))

    def test_symbols(self, ho3):
        names = ho3.symbols()
        assert names["x1"] == x1 and names["m"] == m and names["h"] == sympy.Symbol("h") and "alpha" in names

    def test_latex(self, ho3):
        tex = ho3.to_latex()
        assert tex.startswith("H = ") and "G = " in tex


# --------------------------------------------------------------------------------------------------
# bad input
# --------------------------------------------------------------------------------------------------
class TestBadInput:
    def test_stray_symbol_sympy_input(self):
        with pytest.raises(InvalidSystemError, match=r"Hamiltonian H = x1 \+ y uses \['y'\]"):
            System("x1 x2 x3", [x1 + y, x3])
        with pytest.raises(InvalidSystemError, match=r"Hamiltonian G = .* uses \['y'\]"):
            System("x1 x2 x3", [x1, x3 * y])

    def test_stray_symbol_string_input(self):
        with pytest.raises(ExpressionParseError, match=r"'x3\+y'.*the name 'y' is not declared"):
            System("x1 x2 x3", ["x1", "x3+y"])

    def test_stray_coordinate_not_declared(self):
        """A Hamiltonian in x4 on coordinates x1..x3 (coordinates do not match the Hamiltonians)."""
        with pytest.raises(InvalidSystemError, match="x4"):
            System("x1 x2 x3", [x1 + x4, x3])

    def test_step_symbol_in_hamiltonian(self):
        with pytest.raises(InvalidSystemError, match=r"\['h'\]"):
            System("x1 x2", [x1 * sympy.Symbol("h") + x2**2])

    @pytest.mark.parametrize(
        "coords, hams, expected",
        [
            ("x1 x2 x3", ["x1"], "needs 2 Hamiltonian\\(s\\), got 1"),
            ("x1 x2 x3", ["x1", "x2", "x3"], "needs 2 Hamiltonian\\(s\\), got 3"),
            ("x1 x2", ["x1", "x2"], "needs 1 Hamiltonian\\(s\\), got 2"),
            ("x1 x2 x3 x4", ["x1", "x2"], "needs 1 or 3 Hamiltonian\\(s\\), got 2 \\(two Hamiltonians on N > 3 need N = 3n"),
            ("x1 x2 x3 x4 x5", ["x1"], "needs 4 Hamiltonian\\(s\\), got 1 \\(one Hamiltonian needs an even N = 2d"),
            ("x1 x2 x3 x4 x5 x6", ["x1", "x2", "x3"], "needs 1, 2 or 5 Hamiltonian\\(s\\), got 3"),
        ],
    )
    def test_wrong_number_of_hamiltonians(self, coords, hams, expected):
        with pytest.raises(InvalidSystemError, match=expected):
            System(coords, hams)

    @pytest.mark.parametrize(
        "coords, params, name",
        [("h x2", "", "h"), ("x1 alpha", "", "alpha"), ("x1 x2", "h", "h"), ("x1 x2", "m alpha", "alpha")],
    )
    def test_reserved_names(self, coords, params, name):
        hams = ["x1 + x2"] if coords == "x1 x2" else [f"{coords.split()[0]} * {coords.split()[1]}"]
        with pytest.raises(InvalidSystemError, match=f"symbol '{name}' is reserved"):
            System(coords, hams, params)

    def test_unknown_model(self):
        with pytest.raises(UnknownModelError, match=r"unknown model 'pendulumm'.*ho3"):
            model("pendulumm")
        assert issubclass(UnknownModelError, NambuBCHError)

    @pytest.mark.parametrize(
        "kwargs, match",
        [
            (dict(coordinates="x1", hamiltonians=["x1"]), "at least 2 coordinates"),
            (dict(coordinates="x1 x1", hamiltonians=["x1"]), "distinct"),
            (dict(coordinates="x1 x2", hamiltonians=["x1*x2"], parameters="x1"), "distinct"),
            (dict(coordinates="x1 2x", hamiltonians=["x1"]), "'2x' is not a valid symbol name"),
            (dict(coordinates="x1 x2", hamiltonians=["m"], parameters="m"), "does not depend on any coordinate"),
            (dict(coordinates="x1 x2", hamiltonians=["x1 + x2"], split="both"), "split 'both' does not apply to a canonical system; accepted are full, fine"),
            (dict(coordinates="x1 x2", hamiltonians=[object()]), "not a sympy expression"),
        ],
    )
    def test_malformed_systems(self, kwargs, match):
        with pytest.raises(InvalidSystemError, match=match):
            System(**kwargs)

    def test_errors_are_value_errors(self):
        with pytest.raises(ValueError):
            System("x1 x2 x3", ["x1"])
