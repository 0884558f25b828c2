"""Concrete X_eff(h): BCH route vs backward error analysis, literature values, numerical order convention."""


import numpy as np
import pytest
import sympy

from nambu_bch import model
from nambu_bch.algebra import liouville_field
from nambu_bch.bch import EffectiveField, effective_field, effective_field_bch
from nambu_bch.errors import InvalidOrderError, UnknownPieceError
from nambu_bch.integrators import PAPER_WORDS, composition, step_function

from reference_fields import effective_field_bch_reference, effective_field_reference

h = sympy.Symbol("h")
x1, x2, x3, m, omega = sympy.symbols("x1 x2 x3 m omega")

CASES = (
    [("ho", w) for w in ("121", "212", "12", "21", "lie-trotter", "strang", "forest-ruth")]
    + [("ho3", w) for w in PAPER_WORDS + ("lie-trotter", "321")]
    + [("rigid-body", w) for w in PAPER_WORDS + ("lie-trotter",)]
    + [("lotka-volterra", w) for w in PAPER_WORDS + ("lie-trotter",)]
    + [("ho3-composite", w) for w in ("121", "212", "lie-trotter")]
)


@pytest.mark.parametrize("name,word", CASES)
def test_bch_route_equals_backward_error_analysis_to_h6(name, word):
    """Eqs. (eL1), (eL2): the formal BCH series evaluated on the pieces == backward error analysis, h^0..h^6."""
    S = model(name).splitting
    comp = composition(word, len(S))
    bch = effective_field_bch(S, comp, 6)
    backward = effective_field(S, comp, 6)
    assert isinstance(bch, EffectiveField) and bch.order == 6 and len(bch.coefficients) == 7
    for j in range(7):
        assert bch[j] == backward[j], f"h^{j}"
    # (compared as sympy: with 2^(1/3) coefficients the result lives in an extended ring)
    assert [sympy.expand(a - b) for a, b in zip(bch[0].to_sympy(), S.system.vector_field.to_sympy())] == [0] * S.system.N
    if bch.composition.symmetric:
        assert all(bch[j].is_zero() for j in (1, 3, 5))


@pytest.mark.parametrize("name,word", [("ho3", "12321"), ("rigid-body", "31213"), ("lotka-volterra", "123"), ("ho", "forest-ruth")])
def test_fast_and_plain_representations_agree(name, word):
    """Laurent-polynomial backend == the system's own ring over QQ(parameters), both routes, == the two
    VectorField reference routes of tests/reference_fields.py (h^4)."""
    S = model(name).splitting
    word = composition(word, len(S))
    ref = effective_field_reference(S, word, 4)
    for X in (effective_field_bch(S, word, 4), effective_field_bch(S, word, 4, fast=False), effective_field(S, word, 4),
              effective_field(S, word, 4, fast=False), effective_field_bch_reference(S, word, 4)):
        assert all(X[j] == ref[j] for j in range(5))


def _F_series(x, order):
    """Eq. (factor1): F(x) = sum_n (n!)^2/(2n+1)! x^(2n)."""
    return sum(sympy.factorial(n) ** 2 / sympy.factorial(2 * n + 1) * x ** (2 * n) for n in range(order // 2 + 1))


@pytest.mark.parametrize("route", [effective_field_bch, effective_field])
def test_Xeff1_exact_shadow_of_position_verlet_to_h8(route):
    """Eqs. (Xeff1), (XHc), (factor1): X_eff = F(omega h) X_{H_c} for TVT on the oscillator, through h^8."""
    system = model("ho")
    X = route(system.splitting, "TVT", 8)
    F = _F_series(omega * h, 8)
    XHc = ((1 - omega**2 * h**2 / 4) * x2 / m, -m * omega**2 * x1)
    for i, total in enumerate(X.to_sympy()):
        exact = sympy.series(F * XHc[i], h, 0, 9).removeO()
        assert sympy.expand(total - exact) == 0


def test_SHPV1_h2_field():
    """Eq. (SHPV1): H_S = H - w^2 h^2 x2^2/(24 m) + m w^4 h^2 x1^2/12 + O(h^4) generates X_eff."""
    system = model("ho")
    X = effective_field_bch(system.splitting, "121", 3)
    expected = liouville_field(system.algebra, -omega**2 * x2**2 / (24 * m) + m * omega**4 * x1**2 / 12)
    assert X[2] == expected and X[3].is_zero()


@pytest.mark.parametrize("words,ho_word", [(("12321", "13231", "31213"), "TVT"), (("23132", "21312", "32123"), "VTV")])
def test_equiv1_equiv2_x1_x2_components_match_the_oscillator(words, ho_word):
    """Eqs. (equiv1), (equiv2): the (x1, x2) components of X_eff for ho3 equal those of TVT / VTV (h^6)."""
    ref = effective_field_bch(model("ho").splitting, ho_word, 6).to_sympy()
    for word in words:
        X = effective_field_bch(model("ho3").splitting, word, 6).to_sympy()
        assert [sympy.expand(a - b) for a, b in zip(X[:2], ref)] == [0, 0]


@pytest.mark.parametrize("name", ["ho3", "lotka-volterra"])
def test_order_8(name):
    """k = 8: both routes agree on every coefficient; odd orders of the symmetric word vanish."""
    S = model(name).splitting
    X, Y = effective_field_bch(S, "12321", 8), effective_field(S, "12321", 8)
    assert all(X[j] == Y[j] for j in range(9))
    assert not X[8].is_zero() and X[7].is_zero()


# -- operator order convention on a non-symmetric word ------------------------------------------------------

def _modified_flow_to_h2(X, system):
    """x + h Z_0 + h^2 (Z_1 + Z_0(Z_0)/2): the time-h flow of Z_0 + h Z_1, through h^2 (numpy function)."""
    Z0, Z1 = X[0], X[1]
    values = {p: sympy.Rational(13, 10) if str(p) != "I3" else sympy.Rational(7, 10) for p in system.parameters}
    exprs = []
    for i in range(system.N):
        second = Z1.to_sympy()[i] + system.algebra.to_sympy(Z0.apply(Z0.components[i])) / 2
        exprs.append((system.coordinates[i] + h * Z0.to_sympy()[i] + h**2 * second).subs(values))
    return sympy.lambdify((*system.coordinates, h), exprs, "numpy")


def _half_commutators(S, word):
    """Z_1 of a plain product word k_1 ... k_s: (1/2) sum_{i<j} [X_{k_i}, X_{k_j}] (BCH to first order, operator order)."""
    total = None
    for i in range(len(word)):
        for j in range(i + 1, len(word)):
            term = S[int(word[i])].field.bracket(S[int(word[j])].field).scale(sympy.Rational(1, 2))
            total = term if total is None else total + term
    return total


@pytest.mark.parametrize("name,word", [("rigid-body", "123"), ("rigid-body", "321"), ("ho", "12"), ("ho3", "132")])
def test_lie_trotter_operator_order_against_numeric_step(name, word):
    """Word "12" (step_function applies piece 1 first): X_eff = X_1 + X_2 + h/2 [X_1, X_2] + ..., so the
    local error of the step against the flow of Z_0 + h Z_1 is O(h^3); with [X_2, X_1] it would be O(h^2).
    (Every word uses every piece of its splitting: a word leaving one out is refused.)"""
    system = model(name)
    S = system.splitting
    X = effective_field_bch(S, word, 1)
    assert X[1] == _half_commutators(S, word)
    params = {str(p): (1.3 if str(p) != "I3" else 0.7) for p in system.parameters}
    step = step_function(S, word, params)
    right = _modified_flow_to_h2(X, system)
    wrong = _modified_flow_to_h2(EffectiveField((X[0], X[1].scale(-1)), 1, X.composition, S), system)
    x0 = np.array([0.3, -0.7, 0.5][: system.N])
    hs = np.array([0.04, 0.02, 0.01])
    err = [np.linalg.norm(step(x0, hh) - np.array(right(*x0, hh), dtype=float)) for hh in hs]
    bad = [np.linalg.norm(step(x0, hh) - np.array(wrong(*x0, hh), dtype=float)) for hh in hs]
    bad_slope = np.polyfit(np.log(hs), np.log(bad), 1)[0]
    assert 1.7 < bad_slope < 2.3, bad_slope
    assert err[-1] < bad[-1] / 20
    if max(err) > 1e-13:  # (for ho the step is quadratic in h, and the h^2 flow matches it exactly)
        slope = np.polyfit(np.log(hs), np.log(err), 1)[0]
        assert slope > 2.7, slope


def test_lie_trotter_first_coefficient_is_half_commutator():
    """Word "123": Z_1 = ([X_1, X_2] + [X_1, X_3] + [X_2, X_3])/2 exactly (operator order, integrators/composition.py)."""
    S = model("rigid-body").splitting
    X = effective_field_bch(S, "123", 2)
    assert X[1] == (S[1].field.bracket(S[2].field) + S[1].field.bracket(S[3].field)
                    + S[2].field.bracket(S[3].field)).scale(sympy.Rational(1, 2))
    assert not X[1].is_zero() and not X[2].is_zero()


# -- bad input -------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("order", [-1, 2.5, None, 10**6, 17, True, "2", float("inf"), float("nan")])
def test_bad_orders(order):
    with pytest.raises(InvalidOrderError):
        effective_field_bch(model("ho").splitting, "121", order)


def test_order_too_high_to_finish_is_refused_up_front():
    with pytest.raises(InvalidOrderError, match="Witt"):
        effective_field_bch(model("ho3").splitting, "suzuki:12321", 12)  # within the order range, beyond the estimate


@pytest.mark.parametrize("route", [effective_field, effective_field_bch])
def test_integral_orders_accepted(route):
    import numpy

    S = model("ho").splitting
    assert route(S, "121", 2.0).order == route(S, "121", sympy.Integer(2)).order == route(S, "121", numpy.int64(2)).order == 2


def test_unknown_piece():
    with pytest.raises(UnknownPieceError, match="3"):
        effective_field_bch(model("ho").splitting, "123", 2)


# -- route by cost -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("name,word,order,backward", [("ho3", "yoshida:12321", 4, True), ("ho", "yoshida:121", 4, True),
                                                        ("ho3", "12321", 2, False), ("ho", "121", 4, False),
                                                        ("ho3", "12321", 4, True), ("lotka-volterra", "12321", 6, True)])
def test_route_by_cost_gives_the_same_field_as_both_routes(monkeypatch, name, word, order, backward):
    """Algebraic coefficients take backward error analysis; rational ones too when it needs fewer Lie derivatives
    than the BCH route has Lyndon brackets (three pieces from h^4 on), else the BCH route.  The field is the
    same exact X_eff either way (compared with both routes)."""
    from nambu_bch.bch import concrete

    S = model(name).splitting
    both = effective_field(S, word, order), effective_field_bch(S, word, order)

    def refuse(*args, **kwargs):
        raise AssertionError("wrong route")

    monkeypatch.setattr(concrete, "effective_field_bch" if backward else "effective_field", refuse)
    X = concrete.effective_field_by_cost(S, word, order)
    assert all(X[j] == both[0][j] == both[1][j] for j in range(order + 1))
