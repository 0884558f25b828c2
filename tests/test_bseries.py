"""Modified equations of Runge--Kutta methods (B-series), Kahan's method, and their shadow question.

Published values: Hairer, Lubich, Wanner, *Geometric Numerical Integration* (HLW), Sect. IX.1 -- explicit Euler
``f~ = f - h/2 f'f + h^2 (1/12 f''(f,f) + 1/3 f'f'f) + O(h^3)`` and implicit midpoint
``f~ = f + h^2 (1/12 f'f'f - 1/24 f''(f,f)) + O(h^4)``; the Lotka-Volterra example of HLW p. 340 reproduced in
BSeries.jl's documentation ("Modified equations" tutorial).  Kahan's Euler-top integrals: Celledoni, McLachlan,
Owren, Quispel, J. Phys. A 46 (2013) 025201 (after Hirota-Kimura), checked here exactly against the map.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from nambu_bch import System, model
from nambu_bch.algebra import PolynomialAlgebra, VectorField, liouville_field
from nambu_bch.bseries import rooted_trees as T
from nambu_bch.bseries.modified import (elementary_differentials, modified_equation, modified_equation_by_taylor,
                                        runge_kutta_shadow)
from nambu_bch.errors import InvalidCompositionError, NambuBCHError, NumericalRangeError
from nambu_bch.integrators.runge_kutta import TABLEAUX
from nambu_bch.numeric.runge_kutta import rk_iterate, rk_step_function

LEAF, BUSHY, TALL = (), ((), ()), (((),),)
h = sympy.Symbol("h")


def _b(name, upto):
    return T.modified_coefficients(T.rk_coefficients(TABLEAUX[name], upto), upto)


def test_explicit_euler_hlw_ix1():
    """HLW IX.1: f2 = -1/2 f'f, f3 = 1/12 f''(f,f) + 1/3 f'f'f (b(t)/sigma(t) with sigma(bushy) = 2)."""
    b = _b("euler", 3)
    assert b[((),)] == sympy.Rational(-1, 2)
    assert b[BUSHY] / T.symmetry(BUSHY) == sympy.Rational(1, 12)
    assert b[TALL] / T.symmetry(TALL) == sympy.Rational(1, 3)


def test_implicit_midpoint_hlw_ix1():
    """HLW IX.1: implicit midpoint has no h^1 term and f3 = 1/12 f'f'f - 1/24 f''(f,f); symmetric: no even trees."""
    b = _b("midpoint", 5)
    assert ((),) not in b
    assert b[TALL] / T.symmetry(TALL) == sympy.Rational(1, 12)
    assert b[BUSHY] / T.symmetry(BUSHY) == sympy.Rational(-1, 24)
    assert not any(T.order(t) % 2 == 0 for t in b)  # odd powers of h vanish (symmetric method, HLW IX.2)


def test_exact_flow_has_no_modification():
    """The exact flow's B-series a(t) = 1/gamma(t) (HLW Sect. III.1) is its own modified field: only b(•) = 1."""
    exact = {t: sympy.Rational(1, T.density(t)) for n in range(1, 7) for t in T.trees(n)}
    assert T.modified_coefficients(exact, 6) == {LEAF: 1}


@pytest.mark.parametrize("name", ["gauss4", "gauss6"])
def test_gauss_modified_field_starts_at_its_order(name):
    """A method of order p has f~ = f + O(h^p) (HLW IX.1); the first correction is nonzero."""
    p = TABLEAUX[name].order
    b = _b(name, p + 1)
    assert all(T.order(t) == 1 or T.order(t) == p + 1 for t in b) and len(b) > 1


def test_elementary_differentials_of_a_scalar_field():
    """y' = y^2: F(•) = y^2, F([•]) = f'f = 2y^3, F([•,•]) = f''(f,f) = 2y^4, F([[•]]) = 4y^4."""
    S = System("x1 x2", ["x2**2/2 + x1**3/3"])  # canonical: x1' = x2, x2' = -x1^2
    F = elementary_differentials(S.vector_field, 3)
    A = S.algebra
    got = {t: tuple(A.to_sympy(c) for c in F[t]) for t in F}
    x1, x2 = S.coordinates
    assert got[LEAF] == (x2, -x1**2)
    assert got[((),)] == (-x1**2, -2 * x1 * x2)
    assert sympy.expand(got[BUSHY][1] - (-2 * x2**2)) == 0 and got[BUSHY][0] == 0


@pytest.mark.parametrize("system", ["ho", "rigid-body", "lotka-volterra", "ho3"])
@pytest.mark.parametrize("method", ["euler", "implicit-euler", "midpoint", "trapezoid", "rk4", "kahan"])
def test_bseries_equals_taylor_backward_analysis(system, method):
    """The B-series route and the Taylor expansion of the map (independent) give the same exact field, h^0..h^3."""
    M = modified_equation(system, method, 3)
    Z = modified_equation_by_taylor(system, method, 3)
    assert all(M[j] == Z[j] for j in range(4))


def test_gauss_bseries_equals_taylor_with_radicals():
    """Gauss4 expanded with sqrt(3) adjoined: the same rational field through h^4."""
    M = modified_equation("lotka-volterra", "gauss4", 4)
    Z = modified_equation_by_taylor("lotka-volterra", "gauss4", 4)
    assert all(M[j] == Z[j] for j in range(5)) and not M[4].is_zero()


def test_lotka_volterra_explicit_euler_hlw_p340():
    """HLW p. 340 / BSeries.jl tutorial: p' = (2 - q) p, q' = (p - 1) q; the h^1 term is -1/2 f'f, by hand."""
    p, q = sympy.symbols("x1 x2")
    f = sympy.Matrix([(2 - q) * p, (p - 1) * q])
    ff = f.jacobian([p, q]) * f
    A = PolynomialAlgebra([p, q], (), (h,))
    field = VectorField(A, list(f))
    F = elementary_differentials(field, 2)
    b = _b("euler", 2)
    first = [sympy.Rational(b[((),)]) * A.to_sympy(c) for c in F[((),)]]
    assert [sympy.expand(x + y / 2) for x, y in zip(first, ff)] == [0, 0]


def test_refusals():
    with pytest.raises(InvalidCompositionError, match="'kahan' is a Runge-Kutta method only on quadratic vector fields"):
        modified_equation(System("x1 x2", ["x2**2/2 + x1**4/4"]), "kahan", 2)
    with pytest.raises(NambuBCHError, match="needs a polynomial vector field"):
        modified_equation(System("x1 x2", ["x2**2/2 - cos(x1)"]), "midpoint", 2)
    with pytest.raises(NambuBCHError, match="order must be"):
        modified_equation("ho", "midpoint", -1)
    with pytest.raises(NambuBCHError, match="order must be an integer between 0 and 8, got 9"):
        modified_equation("ho", "midpoint", 9)
    with pytest.raises(InvalidCompositionError, match="unknown Runge-Kutta method"):
        modified_equation("ho", "12321", 2)


# -- Kahan's method on the Euler top ------------------------------------------------------------------------------

def _euler_top_alphas():
    S = model("rigid-body")
    I1, I2, I3 = S.parameters
    x1, x2, x3 = S.coordinates
    f = S.vector_field.to_sympy()
    alphas = [sympy.cancel(f[0] / (x2 * x3)), sympy.cancel(f[1] / (x3 * x1)), sympy.cancel(f[2] / (x1 * x2))]
    return S, alphas


def _kahan_integral(S, alphas):
    """(a2 x1^2 - a1 x2^2) / (1 - h^2/4 a1 a2 x3^2): the Euler-top integral of Kahan's map (step h)."""
    x1, x2, x3 = S.coordinates
    a1, a2, _ = alphas
    return a2 * x1**2 - a1 * x2**2, 1 - h**2 / 4 * a1 * a2 * x3**2


def test_kahan_euler_top_integral_is_exact_for_the_map():
    """Kahan's map x~ - x = h/2 (polarised quadratic field) conserves the closed-form integral exactly.

    The step is linear in x~: A x~ = x, so x~ = P / Q by Cramer's rule (Q = det A).  N is a quadratic form and D =
    1 - c x3^2, so N(x~) = N(P) / Q^2 and D(x~) = (Q^2 - c P3^2) / Q^2, and N(x~)/D(x~) = N/D is the polynomial
    identity N(P) D = N (Q^2 - c P3^2), decided in QQ(I1, I2, I3)[x1, x2, x3, h] (normal forms, no simplification).
    """
    S, alphas = _euler_top_alphas()
    x1, x2, x3 = S.coordinates
    y = sympy.symbols("y1 y2 y3")
    a1, a2, a3 = alphas
    eqs = [y[0] - x1 - h / 2 * a1 * (y[1] * x3 + x2 * y[2]), y[1] - x2 - h / 2 * a2 * (y[2] * x1 + x3 * y[0]),
           y[2] - x3 - h / 2 * a3 * (y[0] * x2 + x1 * y[1])]
    A, b = sympy.linear_eq_to_matrix(eqs, y)
    K = sympy.QQ.frac_field(*S.parameters)

    def poly(e):
        return sympy.Poly(e, x1, x2, x3, h, domain=K)

    def det3(M):
        return (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0])
                + M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]))

    Ap, bp = [[poly(A[i, j]) for j in range(3)] for i in range(3)], [poly(v) for v in b]
    Q = det3(Ap)
    P = [det3([[bp[r] if col == i else Ap[r][col] for col in range(3)] for r in range(3)]) for i in range(3)]
    assert all((sum((Ap[r][col] * P[col] for col in range(3)), poly(0)) - bp[r] * Q).is_zero for r in range(3))
    N, D = (poly(e) for e in _kahan_integral(S, alphas))
    c = poly(h**2 / 4 * a1 * a2)
    N_image = poly(a2) * P[0]**2 - poly(a1) * P[1]**2   # N(x~) Q^2
    assert (N_image * D - N * (Q**2 - c * P[2]**2)).is_zero
    assert not (N_image - N * Q**2).is_zero             # the flow's integral N alone is not kept by the map


def test_kahan_modified_field_keeps_the_integral_order_by_order():
    """The B-series modified field of the tableau 'kahan' annihilates N/D through h^4: X~N D - N X~D = O(h^5)."""
    S, alphas = _euler_top_alphas()
    M = modified_equation(S, "kahan", 4)
    A = M[0].algebra
    N, D = (A.convert(e) for e in _kahan_integral(S, alphas))
    X = M.field
    defect = X.apply(N) * D - N * X.apply(D)
    k = A.n + A.constants.index(h)  # h is a generator of the ring (over QQ(I1, I2, I3)): its exponent in each monomial
    assert defect and all(m[k] >= 5 for m in defect.monoms())
    # the plain invariant a2 x1^2 - a1 x2^2 is not kept at h^2
    assert M[2].apply(N)


def test_kahan_iteration_keeps_the_integral_to_round_off():
    S, alphas = _euler_top_alphas()
    P = {"I1": 1.0, "I2": 2.0, "I3": 3.0}
    values = {sympy.Symbol(k): v for k, v in P.items()}
    N, D = _kahan_integral(S, alphas)
    step = 0.1
    integral = sympy.lambdify(S.coordinates, (N / D).subs(values).subs(h, step))
    energy = sympy.lambdify(S.coordinates, S.H.subs(values))
    X = rk_iterate(S, "kahan", step, 400, [1.0, 0.5, -0.7], P, every=4)
    I = np.array([integral(*x) for x in X])
    E = np.array([energy(*x) for x in X])
    assert np.max(np.abs(I - I[0])) < 1e-13
    assert np.max(np.abs(E - E[0])) > 1e-6  # H itself is not kept by Kahan's map


# -- the shadow question ------------------------------------------------------------------------------------------

def test_midpoint_rigid_body_has_no_shadow_pair():
    """Implicit midpoint keeps H and G (quadratic invariants) but its h^2 field has divergence
    x1 x2 x3 (I1-I2)(I1-I3)(I2-I3)/(2 I1^2 I2^2 I3^2) != 0: no X_{H_S,G_S} (every one is divergence-free).
    The direct route's certificate is that divergence's x1 x2 x3 coefficient."""
    S = model("rigid-body")
    I1, I2, I3 = S.parameters
    x1, x2, x3 = S.coordinates
    R = runge_kutta_shadow(S, "midpoint", 2)
    assert not R.exists and R.failed_order == 2 and R.orders[0].status == "vanishes"
    o = R.orders[1]
    assert o.certificate == {(x1, x1**2 * x2 * x3): 1, (x2, x1 * x2**2 * x3): 1, (x3, x1 * x2 * x3**2): 1}
    assert sympy.simplify(o.obstruction_value - (I1 - I2) * (I1 - I3) * (I2 - I3) / (4 * I1**2 * I2**2 * I3**2)) == 0
    M = modified_equation(S, "midpoint", 2)
    A = M[0].algebra
    div = A.to_sympy(M[2].divergence())
    assert sympy.simplify(div - x1 * x2 * x3 * (I1 - I2) * (I1 - I3) * (I2 - I3) / (2 * I1**2 * I2**2 * I3**2)) == 0
    for Hk in S.hamiltonians:  # but H and G are exact invariants of the modified field
        assert all(not Z.apply(A.convert(Hk)) for Z in M.coefficients)


def test_midpoint_volume_change_measured():
    """The map's Jacobian determinant: (det DPhi_h - 1)/h^3 -> div Z_2 (h -> 0), measured on the float64 iteration."""
    S = model("rigid-body")
    P = {"I1": 1.0, "I2": 2.0, "I3": 3.0}
    values = {sympy.Symbol(k): v for k, v in P.items()}
    M = modified_equation(S, "midpoint", 2)
    div = sympy.lambdify(S.coordinates, M[0].algebra.to_sympy(M[2].divergence()).subs(values))
    step = rk_step_function(S, "midpoint", P)
    x0 = np.array([1.0, 0.5, -0.7])
    errors = []
    for hh in (0.1, 0.05, 0.025):
        J = np.empty((3, 3))
        for i in range(3):
            d = np.zeros(3)
            d[i] = 1e-6
            J[:, i] = (step(x0 + d, hh) - step(x0 - d, hh)) / 2e-6
        errors.append(abs((np.linalg.det(J) - 1) / hh**3 - div(*x0)))
    assert errors[2] < errors[1] < errors[0] and errors[2] < 0.01 * abs(div(*x0))


@pytest.mark.parametrize("method", ["midpoint", "gauss4"])
def test_gauss_iteration_keeps_h_and_g_to_round_off(method):
    """Gauss methods keep quadratic invariants (HLW Sect. IV.2): H and G of the rigid body to round-off."""
    S = model("rigid-body")
    P = {"I1": 1.0, "I2": 2.0, "I3": 3.0}
    values = {sympy.Symbol(k): v for k, v in P.items()}
    X = rk_iterate(S, method, 0.1, 300, [1.0, 0.5, -0.7], P, every=5)
    for Hk in S.hamiltonians:
        q = sympy.lambdify(S.coordinates, Hk.subs(values))
        values_k = np.array([q(*x) for x in X])
        assert np.max(np.abs(values_k - values_k[0])) < 1e-13


@pytest.mark.parametrize("system, method", [("ho3", "midpoint"), ("lotka-volterra", "midpoint"),
                                            ("rigid-body", "gauss4")])
def test_shadow_pair_field_equals_modified_field(system, method):
    """Where the pair exists, X_{H_S,G_S} equals the modified field through h^4 (both members alpha = 0, 1)."""
    S = model(system)
    R = runge_kutta_shadow(S, method, 4)
    assert R.exists
    M = modified_equation(S, method, 4)
    alpha = sympy.Symbol("alpha")
    for a in (0, 1):
        pair = [sympy.expand(e.subs(alpha, a)) for e in R.shadow()]
        X = liouville_field(S.algebra, *pair).to_sympy()
        for got, want in zip(X, M.to_sympy()):
            diff = sympy.expand(got - want)
            assert all(sympy.degree(t, h) >= 5 for t in sympy.Add.make_args(diff)) or diff == 0


def test_euler_has_no_pair_and_gauss4_has_one_through_h4_only():
    """Explicit Euler is obstructed at h^1 (it does not keep H); gauss4 on the rigid body is solved through h^4 and
    obstructed at h^6, where its field's divergence is first non-zero (h^5 vanishes: a symmetric method)."""
    assert runge_kutta_shadow("rigid-body", "euler", 1).failed_order == 1
    R = runge_kutta_shadow("rigid-body", "gauss4", 6)
    assert [o.status for o in R.orders] == ["vanishes"] * 3 + ["solved", "vanishes", "obstructed"]
    M = R.effective
    assert all(not Z.divergence() for Z in M.coefficients[:6]) and M[6].divergence()


def test_rk_iterate_refuses_blow_up():
    with pytest.raises(NumericalRangeError, match="left the float64 range"):
        rk_iterate("rigid-body", "euler", 0.5, 10**4, [10.0, 20.0, -30.0], {"I1": 1.0, "I2": 2.0, "I3": 3.0})


@pytest.mark.parametrize("name", ["midpoint", "gauss4", "gauss6", "kahan"])
def test_cli_refuses_runge_kutta_names_in_one_line(name, capsys):
    """The subcommands of compositions only (bch): an RK name is refused with exit 2 and one line saying where it is
    available (shadow, check and compare take it: tests/test_runge_kutta_cli.py)."""
    from nambu_bch.cli import main

    assert main(["bch", "--model", "rigid-body", "--integrator", name]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and f"{name!r} is a Runge-Kutta method" in err and "shadow_hamiltonians" in err


def test_wrong_arguments_are_one_line():
    """An array given as the order or the method is shown on one line (the messages echo the value)."""
    from nambu_bch.errors import InvalidOrderError

    for call in (lambda: modified_equation("ho", "midpoint", np.ones((2, 2))),
                 lambda: modified_equation("ho", np.ones((2, 2)), 2),
                 lambda: rk_iterate("ho", "midpoint", 0.1, 3, [1.0, 0.0], params=np.ones((2, 2)))):
        with pytest.raises(NambuBCHError) as info:
            call()
        assert "\n" not in str(info.value)
    with pytest.raises(InvalidOrderError, match=r"got array\(\[\[1\., 1\.\], \[1\., 1\.\]\]\)"):
        modified_equation("ho", "midpoint", np.ones((2, 2)))


def test_direct_route_checks_a_given_field():
    """direct_route(effective=...) refuses something that is not h^0..h^order fields on the system's coordinates."""
    from nambu_bch import direct_route

    M = modified_equation("ho", "midpoint", 2)
    with pytest.raises(NambuBCHError, match=r"coefficients of h\^0 \.\. h\^4"):
        direct_route("ho", "midpoint", 4, effective=M)
    with pytest.raises(NambuBCHError, match="vector fields on ho3's coordinates"):
        direct_route("ho3", "midpoint", 2, effective=[1, 2, 3])
    R = direct_route("ho", "midpoint", 2, effective=M)   # a plain label is enough
    assert R.exists and R.composition == "midpoint"


def test_results_pickle():
    import pickle

    M = modified_equation("rigid-body", "midpoint", 2)
    back = pickle.loads(pickle.dumps(M))
    assert all(a == b for a, b in zip(M.coefficients, back.coefficients)) and back.tree_coefficients == M.tree_coefficients
    assert pickle.loads(pickle.dumps(TABLEAUX["gauss4"])) == TABLEAUX["gauss4"]


def test_taylor_route_truncated_composition_equals_compose_then_cut():
    """The Taylor route's truncated substitution gives the polynomials of ``compose`` followed by the cut, over
    QQ(sqrt(3)) (Gauss4's coefficients) too; the shared stage values give each tree's elementary weight."""
    from nambu_bch.bseries import rooted_trees as T
    from nambu_bch.bseries.modified import _compose_cut, _polynomial_field
    from nambu_bch.integrators.runge_kutta import TABLEAUX

    f = _polynomial_field(model("lotka-volterra"), TABLEAUX["gauss4"])
    alg = f.algebra.with_constants(extension=[sympy.sqrt(3)])
    gens, n = alg.ring.gens, alg.n
    hi = n + alg.constants.index(h)
    top = 3
    fields = [alg.convert(f.algebra.to_sympy(c)) for c in f.components]
    s3 = alg.domain.from_sympy(sympy.sqrt(3))
    values = [gens[0] + s3 * gens[hi] * gens[1] + gens[hi] ** 4, gens[1] - gens[hi] ** 2 * gens[0] ** 2]

    def cut(p):
        return alg.ring.from_dict({m: c for m, c in p.items() if m[hi] <= top})

    want = [cut(fk.compose(list(zip(gens[:n], values)))) for fk in fields]
    assert _compose_cut(fields, values, hi, top, alg.ring) == want
    weights = T.rk_coefficients(TABLEAUX["gauss4"], 5)
    assert all(weights[t] == T.elementary_weight(t, TABLEAUX["gauss4"]) for t in weights)
