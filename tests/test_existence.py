"""Existence of shadow Hamiltonians decided in smooth functions (orbit averages), not only polynomials.

The criterion (nambu_bch/shadow/existence.py, docs/existence.md): at the first order h^j that the polynomial
ansatz does not solve, a shadow pair exists in smooth functions iff the orbit averages <R_j . grad H_a> vanish on
the periodic orbits of X_{H,G} (homological equation of averaging; Hairer-Lubich-Wanner, GNI, Sect. XI.2); a
non-zero average certifies non-existence and predicts the secular drift dH'/dt = h^j <R_j . grad H>.
Every value below is checked two independent ways (exact formula vs orbit quadrature; prediction vs iterated map).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

from nambu_bch import System, model
from nambu_bch.errors import InconsistentCoefficientsError, NambuBCHError
from nambu_bch.numeric.iterate import iterate
from nambu_bch.shadow import shadow_hamiltonians
from nambu_bch.shadow.averaging import orbit_average, orbit_functions, section_integral
from nambu_bch.shadow.direct_route import direct_route
from nambu_bch.shadow.existence import decide, exact_average, integrands, reversing_involutions

import shared_results as shared

# the issue's example: separable, closed orbits, both Hamiltonians quartic
EX17 = ["x1**2/2 + x2**2/2 + x2**4/4 + x3**2", "x1**2/2 + x1**4/8 + x2**2/2 + x3**2/2 + x3**4/4"]
Hs, Gs = sympy.symbols("H G")


@pytest.fixture(scope="module")
def ex17():
    return System("x1 x2 x3", EX17, name="ex17")


@pytest.fixture(scope="module")
def ex17_12321(ex17):
    return shadow_hamiltonians(ex17, "12321", 2)


# -- the averages themselves -----------------------------------------------------------------------------

def test_orbit_average_of_the_circle():
    """X_H for H = (x1^2 + x2^2)/2: circles of period 2 pi; <x1^2> = H = r^2/2 exactly, <x1 x2> = 0, <x1^4> = 3 r^4/8."""
    S = System("x1 x2", ["x1**2/2 + x2**2/2"])
    x1, x2 = S.coordinates
    F = orbit_functions(S, [x1**2, x1 * x2, x1**4], {})
    A = orbit_average(F, [0.6, 0.8])            # r = 1
    assert A.closed and abs(A.period - 2 * np.pi) < 1e-9
    assert abs(A.averages[0] - 0.5) < 1e-10 and abs(A.averages[1]) < 1e-10 and abs(A.averages[2] - 3 / 8) < 1e-10
    assert max(A.errors) < 1e-9
    # the exact route gives the same: x1^2 = X_H(p) + H, x1^4 = X_H(q) + 3 H^2 / 2
    assert exact_average(S, x1**2) == sympy.Symbol("H")
    assert sympy.expand(exact_average(S, x1**4) - sympy.Rational(3, 2) * sympy.Symbol("H") ** 2) == 0


def test_float_integrator_is_the_numpy_dormand_prince_bit_for_bit():
    """The orbit integrator steps with plain Python floats (speed); a Dormand-Prince 5(4) step written with numpy
    arrays (HNW I, Table II.5.2, the module's coefficients) gives the same bits on 40 steps of an orbit, and the
    error norm and dot products equal numpy's for every length (below and above the sequential limits)."""
    from nambu_bch.shadow import averaging as av

    S = System("x1 x2", ["x1**2/2 + x2**2/2 + x1**4/4"])
    x1, x2 = S.coordinates
    F = orbit_functions(S, [x1**2, x1 * x2**3], {})

    def numpy_step(y, k1, dt):
        ks = [k1]
        for i in range(1, 7):
            ks.append(F.rhs(y + dt * sum(a * k for a, k in zip(av._A[i], ks) if a)))
        return (y + dt * sum(b * k for b, k in zip(av._B5, ks) if b), dt * sum(e * k for e, k in zip(av._E, ks) if e),
                ks[6])

    y, yl = np.array([0.6, 0.8, 0.0, 0.0]), [0.6, 0.8, 0.0, 0.0]
    k, kl = F.rhs(y), F.values(yl)
    for dt in np.linspace(0.01, 0.3, 40):
        (y, err, k), (yl, errl, kl) = numpy_step(y, k, dt), av._rk_step(F.values, yl, kl, dt)
        assert y.tolist() == yl and err.tolist() == errl and k.tolist() == kl
    # the error norm and the dot products: numpy's values (bit for bit with numpy 2's summation order; a library
    # summing in another order would move them by rounding only, so this asserts a few units in the last place)
    rng = np.random.default_rng(5)

    def close(u, v):
        return abs(u - v) <= 4e-16 * d * abs(v)

    for d in range(1, 20):
        for _ in range(50):
            a, b, c = rng.standard_normal(d) * 10.0 ** rng.uniform(-8, 8, d), rng.uniform(0.5, 1, d), rng.uniform(1, 2, d)
            assert close(av._rms(a.tolist(), c.tolist()), float(np.sqrt(np.mean((a / c) ** 2))))
            assert close(av._dot(b.tolist(), c.tolist()), float(b @ c)) and close(av._norm(b.tolist()), float(np.linalg.norm(b)))


def test_ho3_exact_averages_match_quadrature():
    """ho3, Phi^{123}, h^1 (README: obstructed): the exact decomposition g = X(p) + c(H, G) gives
    <R_1.grad H> = omega^2 (m omega^2 G - 2H)/4 and <R_1.grad G> = (m omega^2 G - 2H)/(2m) on every periodic orbit;
    the orbit quadrature agrees on sampled orbits (m = 3/2, omega = 4/3)."""
    S = model("ho3")
    m, om = S.parameters
    R = direct_route(S, "123", 1)
    gs, j = integrands(R)
    assert j == 1
    cH, cG = (exact_average(S, g) for g in gs)
    assert sympy.simplify(cH - om**2 * (m * om**2 * Gs - 2 * Hs) / 4) == 0
    assert sympy.simplify(cG - (m * om**2 * Gs - 2 * Hs) / (2 * m)) == 0
    params = {m: sympy.Rational(3, 2), om: sympy.Rational(4, 3)}
    F = orbit_functions(S, gs, params)
    for x0 in ([0.3, 0.9, 0.5], [1.0, -0.2, 2.0]):
        A = orbit_average(F, x0)
        levels = dict(zip((Hs, Gs), A.hamiltonians))
        for c, a, e in zip((cH, cG), A.averages, A.errors):
            exact = float(c.subs(params).subs(levels))
            assert abs(a - exact) < 1e-8 and e < 1e-8 and abs(exact) > 1e-2


# -- certified non-existence: drift predicted = drift measured, at two step sizes ----------------------------

def _check_drift(F, j):
    ev = F.evidence
    assert F.exists is False and F.polynomial is False and ev["outcome"] == "none"
    m1, m2 = ev["measured_drift"]
    assert abs(m2["h"] - m1["h"] / 2) < 1e-15
    for name in m1["measured"]:
        p1, p2 = m1["predicted"][name], m2["predicted"][name]
        assert abs(p1) > 0
        # measured = predicted (the rate h^j <R.grad H>), to O(h) relative at the smaller step ...
        assert abs(m2["measured"][name] / p2 - 1) < 0.05, (name, m1, m2)
        # ... and rate proportional to h^j: halving h divides the measured drift by 2^j
        assert abs(m1["measured"][name] / m2["measured"][name] / 2**j - 1) < 0.1, (name, m1, m2)


def test_ho3_lie_trotter_certified_exactly_with_drift():
    """ho3, Phi^{123}: no shadow pair (certified by the exact averages); JSON carries exists false, polynomial false,
    the drift dH'/dt = h omega^2 (m omega^2 G - 2H)/4 and the measured drift at two step sizes."""
    F = shared.family("ho3", "123", 2)   # the same family test_shadow checks the certificate of
    assert F.failed_order == 1 and F.evidence["method"] == "exact"
    assert sympy.simplify(sympy.sympify(F.drift["H"]) - sympy.Symbol("h") * sympy.sympify(F.evidence["averages"]["H"])) == 0
    _check_drift(F, 1)
    d = json.loads(json.dumps(F.to_dict()))
    assert d["exists"] is False and d["polynomial"] is False and set(d["drift"]) == {"H", "G"}


def test_rigid_body_lie_trotter_certified_numerically_with_drift():
    """Free rigid body, Phi^{123} (README: obstructed at h^1): averages involve elliptic integrals (no exact
    decomposition); the quadrature gives a non-zero average far above its error estimate, and the iterated map
    drifts at the predicted rate."""
    F = shared.family("rigid-body", "123", 2)   # the family test_shadow checks the certificate of (fails at h^1)
    assert F.failed_order == 1 and F.evidence["method"] == "numerical"
    o = F.evidence["certificate_orbit"]
    assert all(abs(a) > 1000 * e for a, e in zip(o["averages"], o["errors"]))
    _check_drift(F, 1)
    assert json.loads(json.dumps(F.to_dict()))["evidence"]["orbits_closed"] >= 1


def test_issue_example_non_symmetric_word_drifts(ex17, monkeypatch):
    """The issue's system with Phi^{123} (drifts to overflow in the issue): certified non-existence at h^1."""
    # the drift runs on the interpreter (the compiled loop's bits): 1 s of CPU less than compiling this system's loop
    monkeypatch.setenv("NAMBU_BCH_DISABLE_NUMBA", "1")
    F = shadow_hamiltonians(ex17, "123", 1)
    assert F.failed_order == 1
    _check_drift(F, 1)


def test_inconsistent_word_is_refused_not_reported_as_an_obstruction():
    """ho3 with Phi^{12} (the README once said 'none at h^1'): piece 3 is missing, Z_0 != X_{H,G}; the word
    does not integrate this system at all, so it is refused up front, never answered."""
    with pytest.raises(InconsistentCoefficientsError, match=r"never applies piece\(s\) \[3\]"):
        shadow_hamiltonians(model("ho3"), "12", 1)


# -- smooth, not polynomial: the issue's example --------------------------------------------------------------

def test_issue_example_has_a_smooth_pair_not_polynomial(ex17, ex17_12321):
    """H = x1^2/2 + x2^2/2 + x2^4/4 + x3^2, G = x1^2/2 + x1^4/8 + x2^2/2 + x3^2/2 + x3^4/4, Phi^{12321}, h^2:
    the polynomial solve (degree 14, 1360 unknowns: within the default bounded work, about 1 s) is
    obstructed -- a certificate that no polynomial pair of degree <= 14 exists -- and the averages vanish exactly by
    reversibility (x_i -> -x_i fixes H, G and makes R_2.grad H, R_2.grad G odd; HGW Sect. XI.1), numerically too."""
    F = ex17_12321
    assert F.exists is True and F.polynomial is False and F.shadows == ()
    assert F.details.orders[-1].status == "obstructed" and F.degree[2] == 14
    ev = F.evidence
    assert ev["method"] == "symmetry" and ev["outcome"] == "smooth" and ev["orbits_closed"] >= 4
    assert all(max(abs(a) for a in o["averages"]) < 1e-9 for o in ev["orbits"] if o["closed"])
    # the symmetry itself, checked independently of the module's search
    R = F.details
    gs, j = integrands(R)
    x1 = ex17.coordinates[0]
    assert j == 2 and all(sympy.expand(g.subs(x1, -x1) + g) == 0 for g in gs)
    assert (0,) in reversing_involutions(ex17, gs)
    d = json.loads(json.dumps(F.to_dict()))
    assert d["exists"] is True and d["polynomial"] is False and d["drift"] is None
    assert "smooth" in F.to_text() and "undecided" not in repr(F)


def test_reversing_involutions_flip_signs_by_xreplace(monkeypatch):
    """The sign flips rho are applied by xreplace (symbols for symbols), never by subs: subs' pattern matching took
    ~0.3 s for the four flips of the issue example's two 50-80-term integrands (xreplace ~0.05 s)."""
    S = System("x1 x2", ["x1**2/2 + x2**4/4"])
    x1, x2 = S.coordinates
    monkeypatch.setattr(sympy.Basic, "subs", lambda *a, **k: pytest.fail("subs"))
    assert reversing_involutions(S, [x1 * x2**2]) == [(0,)]     # H even in both; g odd in x1 only


def test_bounded_work_refuses_an_elimination_above_the_cost_budget(ex17, ex17_12321, monkeypatch):
    """Bounded work: with max_unknowns given, an order whose elimination is estimated
    (elimination_cost of the built matrix) above direct_route.SOLVE_COST is refused up front, before anything is
    eliminated, and the averages decide; below the budget the solve runs (ex17, 12321, h^2: obstructed)."""
    import importlib

    from nambu_bch.algebra import elimination

    dr = importlib.import_module("nambu_bch.shadow.direct_route")
    budget, seen = dr.SOLVE_COST, []
    monkeypatch.setattr(dr, "elimination_cost", lambda *a: seen.append(elimination.elimination_cost(*a)) or seen[-1])
    monkeypatch.setattr(dr, "SOLVE_COST", 0)   # the estimate of the built matrix, recorded; nothing is eliminated
    assert direct_route(ex17, "12321", 2, max_unknowns=2000).orders[-1].status == "refused"
    cost = seen[-1]
    assert 10**7 < cost < budget  # 8.4e7 (blocks of the 2808 x 1360 matrix): solved by default ...
    # ... as the default run (shadow_hamiltonians, max_unknowns 2000, budget SOLVE_COST) did: obstructed
    assert ex17_12321.details.orders[-1].status == "obstructed" and ex17_12321.details.orders[-1].degree == 14
    eliminated = []
    original = elimination._rref
    monkeypatch.setattr(elimination, "_rref", lambda *a, **k: eliminated.append(a) or original(*a, **k))
    monkeypatch.setattr(dr, "SOLVE_COST", cost - 1)
    R = direct_route(ex17, "12321", 2, max_unknowns=2000)
    assert R.orders[-1].status == "refused" and R.orders[-1].degree == 14 and not eliminated
    F = shadow_hamiltonians(ex17, "12321", 2, existence=False)
    assert F.details.orders[-1].status == "refused" and "bounded-work budget" in F.obstruction
    assert "max_unknowns=" not in F.obstruction  # 1360 unknowns are within the default 2000
    assert direct_route(ex17, "12321", 2, max_unknowns=None).orders[-1].status == "obstructed"  # no budget


def test_issue_example_smooth_corrections_are_conserved(ex17, ex17_12321):
    """The smooth corrections a = int R_2.grad H dt (to the reversing section) make H + h^2 a, G + h^2 b conserved
    by the iterated Phi^{12321} to O(h^4): bounded, no secular drift (t = 60 from the issue's (0.7, 0.4, 0.3)),
    while H, G themselves oscillate at O(h^2); both scale as predicted when h is halved."""
    dec = ex17_12321.existence
    Hf = sympy.lambdify([ex17.coordinates], list(ex17.hamiltonians))
    out = {}
    for h in (0.1, 0.05):
        steps = int(round(60 / h))
        xs = iterate(ex17, "12321", h, steps, [0.7, 0.4, 0.3], every=steps // 12, progress=False)
        section = dec.section_for(xs[0])
        HG = np.array([Hf(x) for x in xs])
        corrected = HG + h**2 * np.array([dec.correction(x, section) for x in xs])
        out[h] = (np.abs(HG - HG[0]).max(axis=0), np.abs(corrected - corrected[0]).max(axis=0))
    # no secular drift over a longer run (the issue: t = 1000; here t = 400): the mean of H - H(0) over the first
    # and over the last tenth agree, and both are O(h^2)
    xs = iterate(ex17, "12321", 0.1, 4000, [0.7, 0.4, 0.3], progress=False)
    dH = np.array([Hf(x)[0] for x in xs[::4]]) - Hf(xs[0])[0]
    tenth = len(dH) // 10
    first, last = dH[:tenth].mean(), dH[-tenth:].mean()
    assert abs(last - first) < 0.05 * np.abs(dH).max() and np.abs(dH).max() < 0.02 * 0.1**2
    (raw1, cor1), (raw2, cor2) = out[0.1], out[0.05]
    assert np.all(cor1 < 0.01 * raw1) and np.all(cor2 < 0.01 * raw2)
    assert np.all(np.abs(raw1 / raw2 / 4 - 1) < 0.2)              # O(h^2) oscillation of H, G
    assert np.all(raw1 / raw2 > 3) and np.all(cor1 / cor2 > 8)    # the corrected ones: O(h^4)


def test_section_integral_solves_the_homological_equation(ex17, ex17_12321):
    """a(phi_s x) - a(x) = -int_0^s g: along one orbit the section integral decreases by the integral of g."""
    dec = ex17_12321.existence
    F = dec.functions
    x = np.array([0.3, -0.5, 0.4])
    i = dec.section_for(x)
    # a step along the orbit with the averaging integrator: y = phi_s(x), I = int_0^s g
    from nambu_bch.shadow.averaging import _rk_step
    y = [*x.tolist(), *[0.0] * F.m]
    for _ in range(200):
        y, _, _ = _rk_step(F.values, y, F.values(y), 0.0025)
    y = np.array(y)
    a0, a1 = section_integral(F, x, i), section_integral(F, y[:3], i)
    assert np.allclose(a1 - a0, -y[3:], atol=1e-8)


# -- polynomial results unchanged, options, bad input -------------------------------------------------------------

def test_polynomial_results_unchanged():
    """ho3 Phi^{12321} (Eqs. SH12321c, SG12321c): polynomial pair as before; JSON adds polynomial: true only."""
    F = shared.family("ho3", "12321", 2)
    assert F.exists is True and F.polynomial is True and F.existence is None
    d = F.to_dict()
    assert d["polynomial"] is True and "drift" not in d and "evidence" not in d


def test_existence_false_leaves_it_undecided():
    F = shadow_hamiltonians(model("ho3"), "123", 1, existence=False)
    assert F.exists is None and F.polynomial is False and "existence=False" in F.evidence["reason"]
    assert "undecided" in F.to_text() and F.to_dict()["exists"] is None


def test_bad_input():
    R = direct_route(model("ho3"), "123", 1)
    with pytest.raises(NambuBCHError, match="unknown parameter"):
        decide(R, params={"k": 1})
    with pytest.raises(NambuBCHError, match="orbits must be"):
        decide(R, orbits=0)
    with pytest.raises(NambuBCHError, match="points must be"):
        decide(R, points=[[1.0, 2.0]])
    with pytest.raises(NambuBCHError, match="existence must be"):
        shadow_hamiltonians(model("ho3"), "123", 1, existence="yes")
    with pytest.raises(NambuBCHError, match="max_unknowns"):
        direct_route(model("ho3"), "123", 1, max_unknowns=0)
    S = System("x1 x2", ["x1**2/2 + x2**2/2"])
    F = orbit_functions(S, [S.coordinates[0]], {})
    with pytest.raises(NambuBCHError, match="rtol"):
        orbit_average(F, [1.0, 0.0], rtol=1.0)
    assert not orbit_average(F, [0.0, 0.0]).closed          # an equilibrium: no orbit, said so


def test_cli_shadow_prints_the_outcome(capsys):
    """CLI `shadow`: JSON carries exists / polynomial / drift / evidence; --no-existence leaves it undecided."""
    from nambu_bch.cli import main

    assert main(["shadow", "--integrator", "123", "--order", "1", "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["exists"] is False and d["polynomial"] is False and d["evidence"]["method"] == "exact"
    assert sympy.simplify(sympy.sympify(d["drift"]["G"]) - sympy.sympify("h*(G*m*omega**2 - 2*H)/(2*m)")) == 0
    assert main(["shadow", "--integrator", "123", "--order", "1", "--no-existence", "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["exists"] is None and d["evidence"]["outcome"] == "undecided"


def test_criterion_needs_orbits_that_are_curves():
    """Nambu triplets (two Hamiltonians on N = 6): level sets are 4-dimensional, the orbit-average criterion
    does not apply, so a failed polynomial ansatz stays undecided at once (bounded work, no orbit numerics)."""
    S = model("ho3-pair")
    R = direct_route(S, "123", 1)
    assert not R.exists
    d = decide(R, measure=False)
    assert d.outcome == "undecided" and d.exists is None and "curves" in d.reason


def test_the_decision_is_a_list_of_strategies_in_the_documented_order(monkeypatch):
    """decide asks STRATEGIES in order (exact averages, then the symmetry argument, then quadrature; the last
    always answers); when the exact decomposition fails the next strategy decides, with the same orbits."""
    from nambu_bch.shadow import existence

    assert [s.__name__ for s in existence.STRATEGIES] == [
        "_needs_curves", "_vanishing", "_exact", "_symmetry", "_numerical_certificate", "_numerical_evidence",
        "_no_decision"]
    R = direct_route(model("ho3"), "12321", 2, max_unknowns=1)   # the solve refused: the averages decide
    d = decide(R, measure=False)
    assert (d.outcome, d.method) == ("smooth", "exact") and all(a == 0 for a in d.averages)
    monkeypatch.setattr(existence, "exact_average", lambda *args, **kwargs: None)
    s = decide(R, measure=False)
    assert (s.outcome, s.method) == ("smooth", "symmetry") and s.sections
    assert [o.x0 for o in s.orbits] == [o.x0 for o in d.orbits]
