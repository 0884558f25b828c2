"""Kahan's method on the Euler top: its closed-form integrals and measure, exactly, and the density bracket.

Sources: E. Celledoni, R. I. McLachlan, B. Owren, G. R. W. Quispel, *Geometric properties of Kahan's method*,
J. Phys. A 46 (2013) 025201 (the Runge-Kutta and Rosenbrock forms x' = x + h (I - h/2 f'(x))^{-1} f(x) of the map;
invariant measures of Kahan maps, proved there for constant Poisson structures -- the Euler top's measure
dx/(D_1 D_2) was found by this package, and is checked here); R. Hirota, K. Kimura, J. Phys. Soc. Japan 69 (2000) 627 and
M. Petrera, Y. B. Suris, arXiv:0707.4382 (the integrals of the discrete Euler top as ratios
(a_j x_i^2 - a_i x_j^2) / (1 - h^2/4 a_i a_j x_k^2)).  The closed forms are checked against the map itself (zero by
normal form of polynomials, denominators cleared), not against the printed equations.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from nambu_bch import System, model
from nambu_bch.algebra import PolynomialAlgebra, VectorField, liouville_field
from nambu_bch.bseries.kahan import (euler_top_closed_forms, euler_top_coefficients, euler_top_density, kahan_map)
from nambu_bch.bseries.modified import modified_equation, runge_kutta_shadow
from nambu_bch.errors import InvalidCompositionError, NambuBCHError
from nambu_bch.numeric.runge_kutta import rk_iterate, rk_step_function
from nambu_bch.shadow.density_bracket import density_field, density_shadow, divided_by_density

h, alpha = sympy.Symbol("h"), sympy.Symbol("alpha")
P = {"I1": 1.0, "I2": 2.0, "I3": 3.0}
VALUES = {sympy.Symbol(k): v for k, v in P.items()}


@pytest.fixture(scope="module")
def closed():
    return euler_top_closed_forms()


@pytest.fixture(scope="module")
def density_result():
    S = model("rigid-body")
    return S, density_shadow(S, "kahan", euler_top_density(S), 4)


def test_map_solves_the_polarised_equation(closed):
    """The map P/Delta (Cramer's rule) satisfies Kahan's (x' - x)/h = Q(x, x') exactly at a rational point."""
    E = closed
    x = E.map.algebra.coordinates
    a = E.alphas
    point = {x[0]: 1, x[1]: sympy.Rational(1, 2), x[2]: sympy.Rational(-7, 10), a[0]: 3, a[1]: -2,
             a[2]: sympy.Rational(5, 7), h: sympy.Rational(1, 10)}
    y = E.map(point)
    X = [point[s] for s in x]
    A = [point[s] for s in a]
    H_ = point[h]
    Q = [A[0] * (X[1] * y[2] + y[1] * X[2]) / 2, A[1] * (X[2] * y[0] + y[2] * X[0]) / 2,
         A[2] * (X[0] * y[1] + y[0] * X[1]) / 2]
    assert all((yi - xi) / H_ - qi == 0 for yi, xi, qi in zip(y, X, Q))


def test_hirota_kimura_integrals_are_exact_invariants(closed):
    """(a_j x_i^2 - a_i x_j^2) / (1 - h^2/4 a_i a_j x_k^2), k = 1, 2, 3, are integrals of the map (generic a_i);
    the unmodified numerators are not (Hirota-Kimura; Celledoni-McLachlan-Owren-Quispel 2013)."""
    K = closed.map
    assert all(K.keeps_ratio(N, D) for N, D in closed.integrals)
    assert not any(K.keeps_ratio(N, 1) for N, _ in closed.integrals)


def test_invariant_measure_jacobian_relation(closed):
    """det DPhi(x) = phi(x')/phi(x) exactly for phi = D_1 D_2 (and D_2 D_3, D_3 D_1: D_i/D_j is a function of the
    integrals); not for phi = 1 or a single D_k: Kahan's map keeps dx/phi, not dx."""
    K = closed.map
    D1, D2, D3 = (D for _, D in closed.integrals)
    assert K.keeps_measure(closed.density) and closed.density == D1 * D2
    assert K.keeps_measure(D2 * D3) and K.keeps_measure(D3 * D1)
    assert not K.keeps_measure(1) and not K.keeps_measure(D1)


def test_rigid_body_specialisation():
    """The package's rigid body is the Euler top with a1 = (I3 - I2)/(I2 I3) (cyclic); phi is 1 + O(h^2)."""
    S = model("rigid-body")
    I1, I2, I3 = S.parameters
    a = euler_top_coefficients(S)
    assert [sympy.cancel(ai - bi) for ai, bi in zip(a, ((I3 - I2) / (I2 * I3), (I1 - I3) / (I1 * I3),
                                                        (I2 - I1) / (I1 * I2)))] == [0, 0, 0]
    phi = euler_top_density(S)
    assert phi.subs(h, 0) == 1 and sympy.degree(phi, h) == 4
    with pytest.raises(NambuBCHError, match="not an Euler top"):
        euler_top_coefficients("lotka-volterra")


def test_general_map_equals_the_kahan_tableau():
    """Rosenbrock form = Runge-Kutta form on a quadratic field (CMOQ 2013): the exact map of Lotka-Volterra at a
    rational point against the float64 step of the tableau 'kahan' (Newton to round-off)."""
    S = model("lotka-volterra")
    K = kahan_map(S.vector_field)
    point = dict(zip(S.coordinates, (1, sympy.Rational(1, 2), sympy.Rational(3, 4))))
    point[h] = sympy.Rational(1, 10)
    exact = np.array([float(v) for v in K(point)])
    step = rk_step_function(S, "kahan")
    assert np.max(np.abs(step(np.array([1.0, 0.5, 0.75]), 0.1) - exact)) < 1e-14


def test_lotka_volterra_kahan_map_keeps_the_flow_s_measure():
    """Kahan's map of the cyclic Lotka-Volterra field x1' = x1 (x2 - x3) (cyclic) keeps dx/(x1 x2 x3) exactly, like the
    flow, and not dx; G = x1 x2 x3 itself is not an integral of the map."""
    K = kahan_map(model("lotka-volterra").vector_field)
    A = K.algebra
    assert K.keeps_measure(A.convert("x1*x2*x3")) and not K.keeps_measure(1)
    assert not K.keeps_ratio(A.convert("x1*x2*x3"), 1)


def test_kahan_map_refusals():
    x = sympy.symbols("x1 x2")
    A = PolynomialAlgebra(x, (), (h,))
    with pytest.raises(InvalidCompositionError, match="quadratic vector fields; the field has degree 3"):
        kahan_map(VectorField(A, [A.convert(x[1] ** 3), A.convert(x[0])]))
    with pytest.raises(NambuBCHError, match="needs a VectorField"):
        kahan_map([1, 2])
    K = kahan_map(model("lotka-volterra").vector_field)
    with pytest.raises(NambuBCHError, match="a point must give exact numbers for x1, x2, x3, h"):
        K({"x1": 1})
    with pytest.raises(NambuBCHError, match="a point must give exact numbers"):
        K({s: "1" for s in (*K.algebra.coordinates, h)})


# -- the density bracket ------------------------------------------------------------------------------------------

def test_standard_bracket_is_obstructed_by_the_divergence():
    """Standard bracket: no pair at h^2.  The certificate is the x1 x2 x3 coefficient of the divergence of Z_2
    (every X_{H_S,G_S} is divergence-free; Kahan's Z_2 is not)."""
    S = model("rigid-body")
    I1, I2, I3 = S.parameters
    x1, x2, x3 = S.coordinates
    R = runge_kutta_shadow(S, "kahan", 2)
    assert not R.exists and R.failed_order == 2
    o = R.orders[1]
    assert o.certificate == {(x1, x1**2 * x2 * x3): 1, (x2, x1 * x2**2 * x3): 1, (x3, x1 * x2 * x3**2): 1}
    assert sympy.cancel(o.obstruction_value + (I1 - I2) * (I1 - I3) * (I2 - I3) / (2 * I1**2 * I2**2 * I3**2)) == 0
    assert modified_equation(S, "kahan", 2)[2].divergence()


def test_density_bracket_admits_a_pair(density_result):
    """Density bracket with rho = phi: g = f~/phi (as an h-series) is divergence-free, phi g = f~ + O(h^5), and
    X_{H_S,G_S} = g + O(h^5) exactly (member alpha = 0): f~ = phi X_{H_S,G_S} + O(h^5)."""
    S, R = density_result
    assert R.exists and [o.status for o in R.orders] == ["vanishes", "solved", "vanishes", "solved"]
    g = R.effective
    assert all(not Z.divergence() for Z in g)
    M = modified_equation(S, "kahan", 4)
    A = M[0].algebra
    k = A.n + A.constants.index(h)
    hgen = A.ring.gens[k]
    phi = A.convert(euler_top_density(S))

    def low(p):  # the part of p below h^5
        return A.ring.from_dict({m: c for m, c in p.items() if m[k] < 5}) if p else p

    series = [sum((hgen ** j * Z.components[i] for j, Z in enumerate(g)), A.zero) for i in range(3)]
    assert all(low(phi * c) == low(w) for c, w in zip(series, M.field.components))
    B = R.algebra  # coordinates, then h, alpha: the member alpha = 0 drops every monomial with alpha
    ka = B.n + B.constants.index(alpha)

    def member0(p):
        return B.ring.from_dict({m: c for m, c in p.items() if m[ka] == 0}) if p else p

    hb = B.ring.gens[B.n + B.constants.index(h)]
    HS, GS = (member0(Hk + hb ** 2 * R.corrections[(slot, 2)] + hb ** 4 * R.corrections[(slot, 4)])
              for slot, Hk in enumerate(R.hamiltonians))
    X = liouville_field(B, HS, GS)
    for got, want in zip(X.components, series):
        lifted = B.ring.from_dict({m + (0,): c for m, c in want.items()})
        assert not any(m[B.n] < 5 for m in (got - lifted).keys())


def test_inverse_density_is_obstructed():
    """rho X_{H,G} keeps dx/rho, so the bracket's density is phi, not 1/phi: with rho = 2 - phi (= 1/phi + O(h^4)) the
    h^2 obstruction doubles (the same certificate, value twice the standard bracket's)."""
    S = model("rigid-body")
    I1, I2, I3 = S.parameters
    R = density_shadow(S, "kahan", sympy.expand(2 - euler_top_density(S)), 2)
    assert R.failed_order == 2
    assert sympy.cancel(R.orders[1].obstruction_value + (I1 - I2) * (I1 - I3) * (I2 - I3) / (I1**2 * I2**2 * I3**2)) == 0


def test_density_field_is_rho_times_the_nambu_field():
    S = model("rigid-body")
    A = S.algebra
    assert density_field(A, S.H, S.hamiltonians[1], 1) == S.vector_field
    assert density_field(A, S.H, S.hamiltonians[1], "2*x1") == S.vector_field.scale(A.convert("2*x1"))


def test_midpoint_with_kahans_density_is_obstructed():
    """The density must be the method's: implicit midpoint keeps dx, so phi X_{H_S,G_S} fails for it at h^2."""
    S = model("rigid-body")
    assert density_shadow(S, "midpoint", euler_top_density(S), 2).failed_order == 2


def test_density_one_is_the_standard_question():
    R0 = density_shadow("ho3", "midpoint", 1, 2)
    R1 = runge_kutta_shadow("ho3", "midpoint", 2)
    assert R0.exists and R1.exists and [sympy.expand(a - b) for a, b in zip(R0.shadow(), R1.shadow())] == [0, 0]


def test_density_refusals():
    S = model("rigid-body")
    M = modified_equation(S, "kahan", 2)
    with pytest.raises(NambuBCHError, match="the density must be 1 at h = 0"):
        divided_by_density(M.coefficients, "2 + h*x1", 2)
    with pytest.raises(NambuBCHError, match="the density must be a polynomial"):
        divided_by_density(M.coefficients, "1/(1 + h*x1)", 2)
    with pytest.raises(NambuBCHError, match="three-bracket"):
        density_shadow("ho", "midpoint", 1, 2)
    with pytest.raises(NambuBCHError):
        density_shadow(S, "kahan", "__import__('os')", 2)


# -- measured: the pair is kept to O(h^6), H only to O(h^2); the volume follows phi --------------------------------

def _spread(S, expr, X):
    fn = sympy.lambdify(S.coordinates, expr)
    v = np.array([fn(*x) for x in X])
    return np.max(np.abs(v - v[0]))


def test_measured_shadow_pair_and_energy(density_result):
    """Along Kahan orbits (h = 0.2, 0.1, 10 time units) the h^4-truncated pair varies like h^6 (ratio ~ 64), H and G
    like h^2 (ratio ~ 4); nothing drifts (the map keeps the Hirota-Kimura integrals exactly)."""
    S, R = density_result
    HS, GS = (e.subs(alpha, 0).subs(VALUES) for e in R.shadow())
    spreads = {}
    for hh in (0.2, 0.1):
        X = rk_iterate(S, "kahan", hh, int(round(10 / hh)), [1.0, 0.5, -0.7], P)
        spreads[hh] = [_spread(S, e, X) for e in (S.H.subs(VALUES), HS.subs(h, hh), GS.subs(h, hh))]
    ratios = [a / b for a, b in zip(spreads[0.2], spreads[0.1])]
    assert 3 < ratios[0] < 5 and ratios[1] > 40 and ratios[2] > 40
    assert spreads[0.1][1] < 1e-3 * spreads[0.1][0]


def test_measured_volume_follows_phi():
    """prod det DPhi along 40 steps equals phi(x_n)/phi(x_0) (finite-difference Jacobians), and differs from 1."""
    S = model("rigid-body")
    hh = 0.2
    phi = sympy.lambdify(S.coordinates, euler_top_density(S).subs(VALUES).subs(h, hh))
    step = rk_step_function(S, "kahan", P)
    x0 = x = np.array([1.0, 0.5, -0.7])
    logdet = 0.0
    for _ in range(40):
        J = np.empty((3, 3))
        for i in range(3):
            d = np.zeros(3)
            d[i] = 1e-6
            J[:, i] = (step(x + d, hh) - step(x - d, hh)) / 2e-6
        logdet += np.log(np.linalg.det(J))
        x = step(x, hh)
    want = np.log(phi(*x) / phi(*x0))
    assert abs(logdet - want) < 1e-7 and abs(logdet) > 1e-5
