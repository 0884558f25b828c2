"""Any system a physicist brings: canonical d >= 1, non-polynomial, canonical triplets, Lie-Poisson.

Each value names its source: the paper's equations (Horikoshi, Eqs. SHPV1, CL1, NB), Hairer-Lubich-Wanner,
*Geometric Numerical Integration* (HLW), Sect. III.4.2 (symmetric BCH formula) and Sect. IX.4 (modified
Hamiltonians of splitting methods), Nambu (1973) Sect. III (canonical triplets).
"""

from __future__ import annotations

import json

import numpy as np

import pytest
import sympy

import nambu_bch as nb
from nambu_bch.algebra import PolynomialAlgebra, liouville_field, nambu_bracket
from nambu_bch.algebra.brackets import triplet_field
from nambu_bch.bch.backward import effective_field
from nambu_bch.bch.concrete import effective_field_bch
from nambu_bch.errors import InvalidSystemError, NambuBCHError, NoExactFlowError, NotSeparableError
from nambu_bch.integrators.flows import exact_flow
from nambu_bch.algebra.zero import is_zero
from nambu_bch.shadow.generic import bch_shadow, poisson_structure, substitute
from nambu_bch.systems import System, infer_bracket

import shared_results as shared

x1, x2 = sympy.symbols("x1 x2")
h, alpha = sympy.symbols("h alpha")
T, V = sympy.Function("T"), sympy.Function("V")


def d(f, x, k=1):
    return sympy.Derivative(f(x), (x, k))


# ---------------------------------------------------------------------------------------------
# 1. the bracket follows from N and the number of Hamiltonians
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("N, k, kind", [(2, 1, "canonical"), (4, 1, "canonical"), (6, 1, "canonical"), (3, 2, "nambu"),
                                        (4, 3, "nambu"), (6, 2, "triplets"), (9, 2, "triplets"), (6, 5, "nambu")])
def test_infer_bracket(N, k, kind):
    assert infer_bracket(N, k) == kind


@pytest.mark.parametrize("N, k, bracket, fragment", [
    (3, 1, None, "one Hamiltonian needs an even N = 2d"),
    (5, 1, None, "one Hamiltonian needs an even N = 2d"),
    (4, 2, None, "two Hamiltonians on N > 3 need N = 3n"),
    (8, 2, None, "two Hamiltonians on N > 3 need N = 3n"),
    (4, 1, "nambu", "bracket='nambu' does not fit"),
    (6, 2, "canonical", "bracket='canonical' does not fit"),
    (4, 1, "lie-poisson", "takes 1 Hamiltonian on N = 3"),
    (3, 2, "poisson", "accepted are canonical, nambu, triplets, lie-poisson"),
])
def test_bad_counts_one_line(N, k, bracket, fragment):
    with pytest.raises(InvalidSystemError, match=fragment) as info:
        infer_bracket(N, k, bracket)
    assert "\n" not in str(info.value)


def test_ambiguous_cases_accept_an_explicit_bracket():
    assert infer_bracket(2, 1, "nambu") == "nambu" and infer_bracket(3, 2, "triplets") == "triplets"


def test_system_carries_the_bracket_into_json():
    S = System("q1 q2 p1 p2", ["p1**2/2 + p2**2/2 + q1**2*q2"])
    assert S.bracket == "canonical" and S.dof == 2 and S.split == "full"
    from nambu_bch.render import system_dict

    assert system_dict(S)["bracket"] == "canonical"
    assert system_dict(nb.model("ho3-pair"))["bracket"] == "triplets"
    fam = nb.shadow_hamiltonians(S, "121", order=2)
    assert fam.to_dict()["bracket"] == "canonical"
    assert nb.shadow_hamiltonians(nb.model("ho3"), "12321").to_dict()["bracket"] == "nambu"


def test_canonical_equations_q_first_p_last():
    """One Hamiltonian on N = 2d: dq/dt = dH/dp, dp/dt = -dH/dq (Eq. Poisson, canonical order)."""
    S = nb.model("henon-heiles")
    q1, q2, p1, p2 = S.coordinates
    assert S.equations_of_motion() == (p1, p2, -q1 - 2 * q1 * q2, -q1**2 + q2**2 - q2)


def test_canonical_split_T_then_V_and_fine_split():
    S = nb.model("fpu-beta")
    assert [p.moving for p in S.splitting.pieces] == [(0, 1, 2), (3, 4, 5)]
    assert S.splitting.check_sum()
    fine = System(S.coordinates, S.hamiltonians, S.parameters, split="fine")
    # T = p1^2/2 + p2^2/2 + p3^2/2 falls into three independent parts, V couples q1, q2, q3
    assert [p.moving for p in fine.splitting.pieces] == [(0,), (1,), (2,), (3, 4, 5)]
    assert fine.splitting.check_sum()
    for p in fine.splitting.pieces:
        assert exact_flow(p, S.coordinates).kind == "shear"


def test_non_separable_canonical_refused_in_one_line():
    S = System("q p", ["q*p + p**2/2"])
    with pytest.raises(NotSeparableError, match=r"not separable into T\(p\) \+ V\(q\): the term p\*q mixes") as info:
        S.splitting
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["ho3-pair", "henon-heiles"])
def test_fi_route_refused_for_canonical_and_triplets(name):
    with pytest.raises(NambuBCHError, match="the FI route needs the Nambu bracket"):
        nb.shadow_hamiltonians(nb.model(name), "121" if name == "henon-heiles" else "12321", route="fi")


def test_piece_without_exact_flow_refused_in_one_line():
    S = System("x1 x2 x3", ["x1**2 + x2 + x3", "x2**2*x3**2 + x1"], split="single")
    with pytest.raises(NoExactFlowError, match=r"piece 1 .* neither free of nor linear .*accepted: shears") as info:
        nb.iterate(S, "12321", h=0.1, steps=10, x0=(1.0, 1.0, 1.0))
    assert "\n" not in str(info.value)


def test_triplet_bracket_is_the_sum_of_jacobians():
    """Nambu (1973), Sect. III: {f, g, k} = sum over triplets of the 3x3 Jacobians."""
    xs = sympy.symbols("x1:7")
    A = PolynomialAlgebra(xs)
    H = xs[1] ** 2 / 2 + xs[2] / 2 + xs[4] ** 2 / 2 + xs[5] / 2 + 3 * xs[0] * xs[3]
    G = xs[2] - xs[0] ** 2 + xs[5] - xs[3] ** 2
    X = triplet_field(A, H, G).to_sympy()
    for i in range(6):
        t = 3 * (i // 3)
        J = sympy.Matrix([[sympy.diff(f, xs[j]) for j in range(t, t + 3)] for f in (xs[i], H, G)]).det()
        assert sympy.expand(X[i] - J) == 0
    assert liouville_field(A, H, G).to_sympy() == X  # inferred from 2 Hamiltonians on N = 6


def test_fundamental_identity_fails_for_triplets_but_holds_for_nambu():
    """The FI: X_{f1,f2} is a derivation of the bracket.  It holds for N = 3 (Takhtajan) and fails for the
    sum over triplets (Nambu 1973, Sect. III; the paper's conclusions)."""
    def defect(xs, bracket):
        f1, f2 = xs[0] * xs[3], xs[1] + xs[4] ** 2
        g = (xs[2] * xs[4], xs[0] + xs[5], xs[1] * xs[3])
        X = lambda F: bracket(F, f1, f2)  # noqa: E731
        lhs = X(bracket(*g))
        rhs = bracket(X(g[0]), g[1], g[2]) + bracket(g[0], X(g[1]), g[2]) + bracket(g[0], g[1], X(g[2]))
        return sympy.expand(lhs - rhs)

    xs = sympy.symbols("x1:7")
    A6 = PolynomialAlgebra(xs)

    def trip(f, g, k):
        comps = triplet_field(A6, g, k).to_sympy()
        return sympy.expand(sum(c * sympy.diff(f, x) for c, x in zip(comps, xs)))

    assert defect(xs, trip) != 0
    ys = sympy.symbols("y1:4")
    A3 = PolynomialAlgebra(ys)
    zs = (*ys, *ys)  # the same test polynomials folded onto three coordinates
    assert defect(zs, lambda f, g, k: A3.to_sympy(nambu_bracket(A3, f, g, k))) == 0


def test_triplet_split_pieces_are_exact_shears():
    S = nb.model("ho3-pair")
    assert [p.moving for p in S.splitting.pieces] == [(0, 3), (1, 4), (2, 5)]
    assert S.splitting.check_sum()
    for p in S.splitting.pieces:
        assert exact_flow(p, S.coordinates).kind == "shear"


def test_lie_poisson_rigid_body_pieces_are_rotations():
    """McLachlan (1993): with only H split, piece i rotates about axis i by the angle t x_i / I_i."""
    S = nb.model("rigid-body-lp")
    assert S.bracket == "lie-poisson" and S.split == "single"
    assert sympy.expand(S.G - sum(x**2 for x in S.coordinates) / 2) == 0
    t = sympy.Symbol("t")
    X1, X2, X3 = S.coordinates
    I1 = S.parameters[0]
    flow = exact_flow(S.splitting[1], S.coordinates)
    assert flow.kind == "rotation" and not any(e.has(sympy.I) for e in flow.expressions)
    c, s = sympy.cos(t * X1 / I1), sympy.sin(t * X1 / I1)
    assert [sympy.expand(e) for e in flow.expressions] == [X1, sympy.expand(X2 * c - X3 * s), sympy.expand(X2 * s + X3 * c)]
    # the flow solves its own equations (d/dt of the flow = the piece's field at the flowed point)
    field = S.splitting[1].field.to_sympy()
    sub = dict(zip(S.coordinates, flow.expressions))
    for e, f in zip(flow.expressions, field):
        assert sympy.simplify(sympy.diff(e, t) - f.subs(sub, simultaneous=True)) == 0


# ---------------------------------------------------------------------------------------------
# 2./3. non-polynomial shadow Hamiltonians and the generic answer
# ---------------------------------------------------------------------------------------------
def test_generic_answer_h2_position_verlet():
    """H_S of position Verlet (121, T in half steps) for H = T(p) + V(q):
    h^2 (T'' V'^2 / 12 - V'' T'^2 / 24): the symmetric BCH formula
    log(e^{A/2} e^B e^{A/2}) = A + B - [A,[A,B]]/24 - [B,[A,B]]/12 (HLW Sect. III.4.2) with [X_A, X_B] = X_{{B,A}}."""
    R = shared.generic("121", 2)
    expected = d(T, x2, 2) * d(V, x1) ** 2 / 12 - d(V, x1, 2) * d(T, x2) ** 2 / 24
    assert sympy.expand(R.series[2] - expected) == 0
    assert R.series[1] == 0 and R.verified_orders == 2
    # velocity Verlet (212): the roles exchanged
    S = nb.shadow.generic.generic_system()
    R2 = bch_shadow(System(S.coordinates, S.hamiltonians, name="g", split="full"), "212", 2)
    assert sympy.expand(R2.series[2] - (d(V, x1, 2) * d(T, x2) ** 2 / 12 - d(T, x2, 2) * d(V, x1) ** 2 / 24)) == 0


def test_generic_answer_h4_position_verlet():
    """The h^4 term of position Verlet as a polynomial in the derivatives of T and V (derived here, checked against
    backward error analysis for undefined T, V inside generic_shadow, and against the harmonic oscillator below)."""
    R = shared.generic("121", 4)
    Tp, Tpp, Tppp, Tpppp = (d(T, x2, k) for k in (1, 2, 3, 4))
    Vq, Vqq, Vqqq, Vqqqq = (d(V, x1, k) for k in (1, 2, 3, 4))
    expected = (sympy.Rational(7, 5760) * Tp**4 * Vqqqq - Tp**2 * Tpp * Vq * Vqqq / 80 - Tp**2 * Tpp * Vqq**2 / 240
                + Tp * Tppp * Vq**2 * Vqq / 120 + Tpp**2 * Vq**2 * Vqq / 60 - Tpppp * Vq**4 / 720)
    assert sympy.expand(R.series[4] - expected) == 0 and R.series[3] == 0


def test_generic_answer_gives_eq_SHPV1_for_the_oscillator():
    """Eq. (SHPV1): T = p^2/(2m), V = m omega^2 q^2/2, position Verlet; and the direct route's linear solve at h^4."""
    m, w = sympy.symbols("m omega")
    R = shared.generic("121", 4)
    H2 = substitute(R.series[2], T=x2**2 / (2 * m), V=m * w**2 * x1**2 / 2)
    assert sympy.expand(H2 - (m * w**4 * x1**2 / 12 - w**2 * x2**2 / (24 * m))) == 0
    fam = nb.shadow_hamiltonians(nb.model("ho"), "121", order=4)
    H4 = substitute(R.series[4], T=x2**2 / (2 * m), V=m * w**2 * x1**2 / 2)
    assert sympy.expand(fam.H_S - nb.model("ho").H - h**2 * H2 - h**4 * H4) == 0


def test_position_verlet_oscillator_exact_invariant():
    """Independent of any BCH: the exact quadratic invariant Q of the position-Verlet matrix (M^T Q M = Q, m = omega = 1)
    is a multiple of H_S through h^4 (the ratio of its q^2 and p^2 coefficients agrees)."""
    M = (sympy.Matrix([[1, h / 2], [0, 1]]) * sympy.Matrix([[1, 0], [-h, 1]]) * sympy.Matrix([[1, h / 2], [0, 1]]))
    a = sympy.Symbol("a")
    Q = sympy.Matrix([[a, 0], [0, 1]])
    sol = sympy.solve(sympy.expand(M.T * Q * M - Q)[0, 0], a)
    ratio_exact = sympy.series(sol[0], h, 0, 6).removeO()  # q^2 : p^2
    R = shared.generic("121", 4)
    HS = sum(h**k * substitute(R.series[k], T=x2**2 / 2, V=x1**2 / 2) for k in (0, 2, 4))
    cq, cp = sympy.expand(HS).coeff(x1, 2), sympy.expand(HS).coeff(x2, 2)
    assert sympy.expand(sympy.series(cq / cp, h, 0, 6).removeO() - ratio_exact) == 0


CONCRETE = [
    ("pendulum", x2**2 / 2, -sympy.cos(x1)),
    ("exp-well", x2**2 / 2, sympy.exp(x1) - x1),
    ("rational", x2**2 / 2, -1 / (1 + x1**2)),
]


@pytest.mark.parametrize("name, Tc, Vc", CONCRETE)
def test_concrete_equals_generic_substituted_to_h4(name, Tc, Vc):
    """The concrete H_S (BCH on the model's own functions, verified against backward error analysis to h^4)
    equals the generic answer with T, V substituted."""
    S = nb.model(name)
    fam = nb.shadow_hamiltonians(S, "121", order=4)
    assert fam.exists and fam.details.orders[1].status == "solved"
    R = shared.generic("121", 4)
    expected = sum(h**k * substitute(R.series[k], T=Tc, V=Vc) for k in (2, 4))
    assert is_zero(fam.H_S - S.H - expected)


def test_pendulum_two_routes_to_X_eff():
    """X_{H_S} = X_eff through h^4 by the formal BCH series on fields and by backward error analysis."""
    S = nb.model("pendulum")
    R = shared.bch("pendulum", "121", 4, verify=False)
    Xb, Xf = effective_field(S.splitting, "121", 4), effective_field_bch(S.splitting, "121", 4)
    for j in range(5):
        XS = (sympy.diff(R.series[j], x2), -sympy.diff(R.series[j], x1))
        for a, b, c in zip(XS, Xb[j].to_sympy(), Xf[j].to_sympy()):
            assert is_zero(a - b) and is_zero(a - c)


def test_polynomial_canonical_direct_solve_equals_bch():
    """Henon-Heiles (d = 2), position Verlet to h^4: the exact linear solve (direct route) and the BCH series on
    Hamiltonians give the same H_S up to a constant (the kernel of X_. is the constants)."""
    S = nb.model("henon-heiles")
    direct = nb.direct_route(S, "121", order=4).shadow()[0]
    bch = bch_shadow(S, "121", 4).H_S
    diff = sympy.expand(direct - bch)
    assert not diff.free_symbols - {h}


def test_toda_h2_and_fpu_h2():
    for name in ("toda", "fpu-beta"):
        fam = shared.family(name, "121", 2)
        assert fam.exists and fam.details.orders[1].status == "solved"


def test_non_polynomial_without_poisson_structure_refused():
    S = System("x1 x2 x3", ["x2**2/2 + cos(x3)", "x3 - x1**2"])
    with pytest.raises(NambuBCHError, match="needs polynomial Hamiltonians unless every piece is Hamiltonian") as info:
        nb.shadow_hamiltonians(S, "12321", order=2)
    assert "\n" not in str(info.value)


# ---------------------------------------------------------------------------------------------
# 4. canonical triplets: existence order by order, with certificates
# ---------------------------------------------------------------------------------------------
def _pair(kappa):
    S = nb.model("ho3-pair")
    return System(S.coordinates, [H.subs("kappa", kappa) for H in S.hamiltonians], (), name=f"ho3-pair-{kappa}")


@pytest.mark.parametrize("kappa", [0, sympy.Rational(1, 3)])
def test_triplets_12321_exist_to_h4_checked_against_backward(kappa):
    S = _pair(kappa)
    fam = nb.shadow_hamiltonians(S, "12321", order=4)
    assert fam.exists and fam.free_parameters == ["alpha"]
    X = effective_field(S.splitting, "12321", 4)
    alg = S.algebra.with_constants(h, alpha)
    XS = liouville_field(alg, fam.H_S, fam.G_S).to_sympy()
    total = [sum(h**j * X[j].to_sympy()[i] for j in range(5)) for i in range(6)]
    for a, b in zip(XS, total):
        err = sympy.expand(a - b)
        assert all(sympy.degree(t, h) > 4 for t in sympy.Add.make_args(err) if t != 0)


@pytest.mark.parametrize("kappa", [0, sympy.Rational(1, 3)])
def test_triplets_123_obstructed_at_h1_with_certificate(kappa):
    S = _pair(kappa)
    fam = nb.shadow_hamiltonians(S, "123", order=2)
    assert not fam.exists and fam.failed_order == 1 and fam.certificate
    # the certificate is a functional on fields: it kills every X_{dH,G} + X_{H,dG} of the ansatz ...
    R = fam.details.orders[-1]
    xs = S.coordinates

    def ell(field):
        total = 0
        for (x, mono), c in fam.certificate.items():
            comp = sympy.expand(field[xs.index(x)])
            total += c * sympy.Poly(comp, *xs).coeff_monomial(mono) if comp != 0 else 0
        return sympy.expand(total)

    alg = S.algebra
    for mono in [xs[0] ** 2, xs[3] * xs[4], xs[5], xs[1] ** 2]:
        assert ell(liouville_field(alg, mono, S.G).to_sympy()) == 0
        assert ell(liouville_field(alg, S.H, mono).to_sympy()) == 0
    # ... but not the h^1 field of the map (backward error analysis, independent of the solve)
    Z1 = effective_field(S.splitting, "123", 1)[1].to_sympy()
    assert ell(Z1) == R.obstruction_value != 0


# ---------------------------------------------------------------------------------------------
# 5. Lie-Poisson: shadow pairs, G_S = G from the BCH series, numerics
# ---------------------------------------------------------------------------------------------
def test_lie_poisson_bch_member_with_casimir_kept():
    """Only H split: the pieces are Hamiltonian for {f, g}_G = {f, g, G} (a Poisson bracket), so the BCH series on
    H_i gives a shadow pair with G_S = G, checked against backward error analysis to h^4."""
    S = nb.model("rigid-body-lp")
    hams, fixed = poisson_structure(S)
    assert fixed == (S.G,) and sympy.expand(sum(hams) - S.H) == 0
    R = bch_shadow(S, "12321", 4)
    assert R.verified_orders == 4 and R.shadows[1] == S.G
    fam = nb.shadow_hamiltonians(S, "12321", order=4)   # the polynomial α-family of the direct solve
    assert fam.exists and fam.free_parameters == ["alpha"]


def _fit(hs, errs):
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


def test_pendulum_truncated_shadow_conserved_like_h_k_plus_2():
    """The order-k truncation of H_S drifts by O(h^{k+2}) over a fixed time (log-log slopes ~ 4 and ~ 6)."""
    S = nb.model("pendulum")
    R = shared.bch("pendulum", "121", 4, verify=False)
    hs = np.array([0.4, 0.2, 0.1, 0.05])
    slopes = {}
    for k in (2, 4):
        H_S = sympy.lambdify((x1, x2, h), sum(h**j * R.series[j] for j in range(k + 1)), "numpy")
        errs = []
        for step in hs:
            xs = nb.iterate(S, "121", h=float(step), steps=int(round(20 / step)), x0=(1.0, 0.5))
            vals = H_S(xs[:, 0], xs[:, 1], step)
            errs.append(np.max(np.abs(vals - vals[0])))
        slopes[k] = _fit(hs, errs)
    assert 3.6 < slopes[2] < 4.4 and 5.5 < slopes[4] < 6.5, slopes


def test_pendulum_map_converges_at_order_2():
    """Global error at t = 5 against a fine triple-jump (order 4) reference: slope ~ 2."""
    S = nb.model("pendulum")
    ref = nb.iterate(S, "yoshida:121", h=0.001, steps=5000, x0=(1.0, 0.5))[-1]
    hs = np.array([0.2, 0.1, 0.05, 0.025])
    errs = [np.max(np.abs(nb.iterate(S, "121", h=float(s), steps=int(round(5 / s)), x0=(1.0, 0.5))[-1] - ref)) for s in hs]
    assert 1.8 < _fit(hs, errs) < 2.2


def test_rigid_body_lp_check_runs_and_keeps_the_casimir():
    """The issue's crash: `check` on the Lie-Poisson splitting (complex TypeError before the real rotations)."""
    S = nb.model("rigid-body-lp")
    res = nb.check(S, "12321", h=0.1, steps=2000, x0=(1.0, 1.0, 1.0), params={"I1": 1, "I2": 2, "I3": 3}).to_dict()
    err = res["max_abs_error"]
    assert err["G"] < 1e-12          # rotations preserve |x|^2 exactly (round-off only)
    assert err["H_S"] < err["H"] / 100


def test_cli_bracket_flag_and_models(capsys):
    from nambu_bch.cli import main

    assert main(["models", "--model", "ho3-pair", "--format", "text"]) == 0
    out = capsys.readouterr().out
    assert "bracket = triplets" in out and "piece 3: moves x3, x6" in out
    assert main(["models", "--H", "x1^2/2", "--coords", "x1 x2 x3", "--bracket", "lie-poisson", "--format", "text"]) == 0
    assert "bracket = lie-poisson" in capsys.readouterr().out
    assert main(["shadow", "--H", "x2^2/2 - cos(x1)", "--format", "json"]) == 0
    x1, x2, h = sympy.symbols("x1 x2 h")
    H_S = sympy.sympify(json.loads(capsys.readouterr().out)["H_S"], locals={"x1": x1, "x2": x2, "h": h})
    # position Verlet on the pendulum (HLW Sect. IX.4): H + h^2 (T''V'^2/12 - V''T'^2/24)
    assert sympy.simplify(H_S - (x2**2 / 2 - sympy.cos(x1) + h**2 * (sympy.sin(x1)**2 / 12 - sympy.cos(x1) * x2**2 / 24))) == 0
    code = main(["shadow", "--H", "x1^2 + x2^2", "--coords", "x1 x2 x3"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "one Hamiltonian needs an even N = 2d" in err[0]
    code = main(["shadow", "--H", "x1", "--G", "x2", "--coords", "x1 x2 x3 x4"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "need N = 3n" in err[0]


# ---------------------------------------------------------------------------------------------
# the generic Nambu answer (arbitrary separable H_i(x_i), G_i(x_i), full split): none at h^2
# ---------------------------------------------------------------------------------------------
def test_generic_nambu_jets_reproduce_the_rigid_body_field():
    """The jet evaluation of Z_2 (12321) with H_i = x_i^2/(2 I_i), G_i = x_i^2/2 substituted equals the concrete
    effective field of the rigid body (formal BCH on its fields): the jet machinery is checked independently."""
    r = shared.nambu_h2("12321")
    S = nb.model("rigid-body")
    subs = {}
    for i, (x, I) in enumerate(zip(S.coordinates, S.parameters), start=1):
        for k in range(7):
            subs[sympy.Symbol(f"h{i}_{k}")] = sympy.diff(x**2 / (2 * I), x, k)
            subs[sympy.Symbol(f"g{i}_{k}")] = sympy.diff(x**2 / 2, x, k)
    X = shared.backward_field("rigid-body", "12321", 2)[2].to_sympy()
    assert all(is_zero(z.xreplace(subs) - c) for z, c in zip(r.Z2, X))   # rational functions: decided by cancel


@pytest.mark.parametrize("word", ["12321", "21312", "31213"])
def test_generic_nambu_no_universal_shadow_pair_at_h2(word):
    """New result: no differential polynomial in the H_i, G_i solves X_{dH,G} + X_{H,dG} = Z_2 (graded ansatz, complete
    for such formulas).  The certificate is a functional that kills every ansatz field and not Z_2."""
    from nambu_bch.shadow.generic_nambu import JetRing

    r = shared.nambu_h2(word)
    assert not r.consistent and r.certificate
    J = JetRing(6)
    Ht = sum(J.jet[("h", i, 0)] for i in (1, 2, 3))
    Gt = sum(J.jet[("g", i, 0)] for i in (1, 2, 3))
    cert = [(i, J.R.from_expr(mono), c) for (i, mono), c in r.certificate.items()]

    def ell(X):
        total = 0
        for i, mono, c in cert:
            (m,) = mono.keys()
            total += c * X[i - 1].get(m, 0)
        return total

    from itertools import combinations_with_replacement as cwr

    def ansatz(nh, ng):  # every monomial of bidegree (nh, ng) and derivative multidegree (2, 2, 2)
        jets = {f: [(f, i, k) for i in (1, 2, 3) for k in range(6)] for f in "hg"}

        def multidegree(keys):
            return tuple(sum(k for _, i, k in keys if i == j) for j in (1, 2, 3))

        by_degree = {}  # the g-parts by their multidegree, each list in the order cwr makes them
        for gs in cwr(jets["g"], ng):
            by_degree.setdefault(multidegree(gs), []).append(gs)
        for hs in cwr(jets["h"], nh):
            for gs in by_degree.get(tuple(2 - d for d in multidegree(hs)), ()):
                yield sympy.prod([J.jet[key] for key in hs + gs], start=J.R.one)

    count = 0
    for dH in ansatz(3, 2):
        assert ell(J.field(dH, Gt)) == 0
        count += 1
    for dG in ansatz(2, 3):
        assert ell(J.field(Ht, dG)) == 0
        count += 1
    assert count == r.unknowns
    Z2 = tuple(J.R.from_expr(z) for z in r.Z2)
    assert ell(Z2) != 0


def test_jet_total_derivative_is_the_chain_rule_in_one_pass(monkeypatch):
    """``JetRing.D`` is ``sum_k d p / d f_j^{(k)} f_j^{(k+1)}`` (the same dict, term order included) without the ring's
    ``diff`` and generator ``index`` per jet (each a comparison of ring elements, most of ``generic_nambu_h2``'s time)."""
    from sympy.polys.rings import PolyElement, PolyRing

    from nambu_bch.shadow.generic_nambu import JetRing

    J = JetRing(3)
    h1, h2, g1, g2 = (J.jet[k] for k in (("h", 1, 0), ("h", 1, 1), ("g", 1, 0), ("g", 1, 2)))
    p = 3 * h1**2 * g2 - h2 * g1 + 5 * h1 * h2 * J.jet[("g", 2, 1)] + 7
    expected = [J.R.zero for _ in (1, 2, 3)]
    for j in (1, 2, 3):
        for f in "hg":
            for k in range(3):
                expected[j - 1] += p.diff(J.jet[(f, j, k)]) * J.jet[(f, j, k + 1)]
    monkeypatch.setattr(PolyElement, "diff", lambda *a: pytest.fail("D called PolyElement.diff"))
    monkeypatch.setattr(PolyRing, "index", lambda *a: pytest.fail("D called PolyRing.index"))
    for j in (1, 2, 3):
        assert list(J.D(p, j).items()) == list(expected[j - 1].items())
    with pytest.raises(NambuBCHError, match="jet order 3 too small"):
        J.D(J.jet[("h", 1, 3)], 1)


# ---------------------------------------------------------------------------------------------
# every new system: X_{H_S(,G_S)} = X_eff by both routes; truncated H_S drifts like h^4; the map has order 2
# ---------------------------------------------------------------------------------------------
NEW = [("pendulum", "121", (1.0, 0.5)), ("exp-well", "121", (0.5, 0.3)), ("rational", "121", (0.8, 0.2)),
       ("henon-heiles", "121", (0.1, 0.2, 0.3, 0.1)), ("fpu-beta", "121", (0.3, -0.2, 0.1, 0.0, 0.2, -0.1)),
       ("toda", "121", (0.3, -0.2, 0.1, 0.2, 0.0, -0.2)), ("ho3-pair", "12321", (1.0, 0.5, 1.0, 0.5, -0.3, 0.25)),
       ("rigid-body-lp", "12321", (1.0, 1.0, 1.0))]


def _values(S):
    # kappa = 1 would make a normal mode of ho3-pair free (omega^2 = 1 - kappa = 0): take kappa = 1/3
    return {"fpu-beta": {"beta": 1}, "ho3-pair": {"kappa": 1 / 3}, "rigid-body-lp": {"I1": 1, "I2": 2, "I3": 3}}.get(S.name, {})


@pytest.mark.parametrize("name, word, x0", NEW, ids=[n for n, _, _ in NEW])
def test_new_system_shadow_equals_X_eff_two_routes(name, word, x0):
    S = nb.model(name)
    fam = shared.family(name, word, 2)
    assert fam.exists
    alg = S.algebra.with_constants(h, alpha)
    # converted once here: the canonical branch of liouville_field converts H again for each coordinate
    X = liouville_field(alg, *map(alg.convert, fam.shadows))
    Xb, Xf = shared.backward_field(name, word, 2), shared.bch_field(name, word, 2)
    if all(alg.is_polynomial(c) for c in X.components) and all(
            F.algebra.is_polynomial(c) for F in (*Xb, *Xf) for c in F.components):
        # polynomial systems (fpu-beta, henon-heiles, ho3-pair): the h^j part of X_{H_S} read off the exponents of h in
        # the exact ring QQ(parameters)[x, h, alpha], compared with h^j X_eff^(j) moved into that ring (== is exact
        # there); the same equalities as the sympy route below, without expanding the fields as sympy expressions
        R, k = alg.ring, alg.n + alg.constants.index(h)
        for i in range(S.N):
            for j in range(3):
                part = R({e: c for e, c in X.components[i].items() if e[k] == j})
                hj = R.gens[k] ** j
                assert part == Xb[j].components[i].set_ring(R) * hj and part == Xf[j].components[i].set_ring(R) * hj, (
                    name, i, j)
        return
    XS = [sympy.expand(c) for c in X.to_sympy()]
    for i in range(S.N):
        for j in range(3):
            part = XS[i].coeff(h, j) if j else XS[i].subs(h, 0)
            assert is_zero(part - Xb[j].to_sympy()[i]) and is_zero(part - Xf[j].to_sympy()[i]), (name, i, j)


@pytest.mark.parametrize("name, word, x0", NEW, ids=[n for n, _, _ in NEW])
def test_new_system_numerics(name, word, x0):
    """Order-2 truncation of H_S (and G_S, alpha = 1/2) drifts like h^4 over t = 4; the map converges at order 2
    (global error at t = 2 against a triple-jump run with a tiny step)."""
    S = nb.model(name)
    vals = _values(S)
    fam = shared.family(name, word, 2)
    subs = {sympy.Symbol(k): sympy.nsimplify(v) for k, v in vals.items()} | {alpha: sympy.Rational(1, 2)}
    fs = [sympy.lambdify((*S.coordinates, h), Q.subs(subs), "numpy") for Q in fam.shadows]
    hs = np.array([0.2, 0.1, 0.05])
    drift, glob = [], []
    ref = nb.iterate(S, f"yoshida:{word}", h=0.002, steps=1000, x0=x0, params=vals)[-1]
    for s in hs:
        xs = nb.iterate(S, word, h=float(s), steps=int(round(4 / s)), x0=x0, params=vals)
        drift.append(max(np.max(np.abs(f(*xs.T, s) - f(*xs[0], s))) for f in fs))
        glob.append(np.max(np.abs(xs[int(round(2 / s))] - ref)))
    assert 3.5 < _fit(hs, drift) < 4.6, (name, drift)
    assert 1.8 < _fit(hs, glob) < 2.3, (name, glob)
