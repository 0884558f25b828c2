"""Modified Nambu equations (Eqs. NambuOHeqs, NambuCQeqs, NambuSHeqs), their exact solutions (Eqs. OHsol, CQsol,
SHsol) checked symbolically, and against iterating the integrator (the content of Figs. 3-4).

Horikoshi, *Shadow Hamiltonians of structure-preserving integrators for Nambu mechanics*.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from sympy.simplify.fu import TR8

from nambu_bch import PAPER_WORDS, composed_map, model, step_function
from nambu_bch.errors import NambuBCHError, NoExactResultError, UnstableStepError
from nambu_bch.exact import F, modified_equations, modified_solution

x1, x2, x3, m, omega, h, t = sympy.symbols("x1 x2 x3 m omega h t")
x10, x20, x30 = sympy.symbols("x1_0 x2_0 x3_0")
a = sympy.sqrt(1 - omega**2 * h**2 / 4)
b = sympy.sqrt(1 - omega**2 * h**2 / 2)


def _same(u, v):
    return sympy.simplify(sympy.expand(u - v)) == 0


def test_NambuOHeqs():
    eqs = modified_equations(model("ho3"), "32123", "o")
    assert eqs == (x2 / m, -m * omega**2 * x1, 2 * x1 * x2 / m)


def test_NambuCQeqs_32123():
    """Eq. (NambuCQeqs): x1' = x2/m, x2' = -m omega^2 a^2 x1, x3' = 2 b^2 x1 x2/m for Phi^32123."""
    eqs = modified_equations(model("ho3"), "32123", "c")
    for got, want in zip(eqs, (x2 / m, -m * omega**2 * a**2 * x1, 2 * b**2 * x1 * x2 / m)):
        assert sympy.expand(got - want) == 0


def test_NambuSHeqs_32123():
    """Eq. (NambuSHeqs): the conserved-quantity equations times F(omega h)."""
    eqs = modified_equations(model("ho3"), "32123", "s")
    Fx = F(omega * h)
    want = (Fx * x2 / m, -m * omega**2 * a**2 * Fx * x1, 2 * b**2 * Fx * x1 * x2 / m)
    for got, w in zip(eqs, want):
        assert _same(got, w)


def _solves(sol) -> bool:
    """d/dt x(t) - rhs(x(t)) == 0 symbolically: t -> s/Omega makes the trig atoms plain, then product-to-sum."""
    s = sympy.Symbol("s")
    sub = dict(zip(sol.system.coordinates, sol.expressions))
    for e, r in zip(sol.expressions, sol.equations):
        d = sympy.diff(e, t) - sympy.sympify(r).subs(sub, simultaneous=True)
        d = sympy.expand(TR8(sympy.expand(d.subs(t, s / sol.frequency))))
        parts = sympy.collect(d, sorted(d.atoms(sympy.sin, sympy.cos), key=str), evaluate=False)
        if any(sympy.simplify(v) != 0 for v in parts.values()):
            return False
    return True


@pytest.mark.parametrize("name,word", [("ho3", "32123"), ("ho3", "12321"), ("ho3", "31213"), ("ho", "121"),
                                       ("ho", "12")])
@pytest.mark.parametrize("kind", ["o", "c", "s"])
def test_solutions_solve_the_equations(name, word, kind):
    sol = modified_solution(model(name), word, kind)
    assert _solves(sol)
    # and start at the initial state
    assert all(sympy.simplify(e.subs(t, 0) - s0) == 0 for e, s0 in zip(sol.expressions, sol.initial_symbols))


def _numerically_equal(u, v, points=3, digits=30):
    rng = np.random.default_rng(7)
    for _ in range(points):
        vals = {m: sympy.Rational(int(rng.integers(5, 20)), 10), omega: sympy.Rational(int(rng.integers(5, 15)), 10),
                h: sympy.Rational(int(rng.integers(1, 20)), 100), t: sympy.Rational(int(rng.integers(1, 500)), 10),
                x10: sympy.Rational(int(rng.integers(-9, 9)), 7), x20: sympy.Rational(int(rng.integers(-9, 9)), 5),
                x30: sympy.Rational(int(rng.integers(-9, 9)), 3)}
        du = sympy.N(u.subs(vals), digits)
        dv = sympy.N(v.subs(vals), digits)
        if abs(du - dv) > 10 ** (-digits + 8) * max(1, abs(dv)):
            return False
    return True


def _paper_x3(Omega, time):
    """The bracket of Eqs. (CQsol), (SHsol) (b = 1, Omega = omega, time = t gives Eq. (OHsol))."""
    return ((x10**2 / 2 - x20**2 / (2 * m**2 * Omega**2)) * sympy.cos(2 * Omega * time)
            + x10 * x20 / (m * Omega) * sympy.sin(2 * Omega * time)
            - x10**2 / 2 + x20**2 / (2 * m**2 * Omega**2))


def test_OHsol():
    sol = modified_solution(model("ho3"), "32123", "o")
    assert _same(sol.expressions[2], _paper_x3(omega, t) + x30)


def test_CQsol():
    """Eq. (CQsol): x3^c = b^2 [ ... ] with tilde omega = a omega, for Phi^32123."""
    sol = modified_solution(model("ho3"), "32123", "c")
    paper = b**2 * (_paper_x3(a * omega, t) + x30 / b**2)
    assert _numerically_equal(sol.expressions[2], paper)
    assert _same(sol.frequency, a * omega)


def test_SHsol():
    """Eq. (SHsol): x3^s is x3^c at tilde t = F(omega h) t."""
    sol = modified_solution(model("ho3"), "32123", "s")
    paper = b**2 * (_paper_x3(a * omega, F(omega * h) * t) + x30 / b**2)
    assert _numerically_equal(sol.expressions[2], paper)
    # tilde omega tilde t = 2 asin(omega h / 2) t / h: one step is a rotation by theta = 2 asin(omega h/2)
    assert _same(sol.frequency, 2 * sympy.asin(omega * h / 2) / h)


@pytest.mark.parametrize("name,word", [("ho3", w) for w in PAPER_WORDS] + [("ho", "121"), ("ho", "212")])
def test_shadow_solution_at_t_equal_h_is_the_map(name, word):
    """x^s(h) = Phi_h(x0) exactly: cos(2 asin(omega h/2)) = 1 - omega^2 h^2/2 etc. (exactness to all orders)."""
    system = model(name)
    sol = modified_solution(system, word, "s")
    phi = composed_map(system.splitting, word)
    back = dict(zip(sol.initial_symbols, system.coordinates))
    for e, p in zip(sol.expressions, phi):
        v = sympy.expand_trig(e.subs(t, h)).subs(back)
        assert sympy.simplify(v - p) == 0


def _iterate(system, word, x0, h_val, n):
    step = step_function(system.splitting, word)
    x = np.asarray(x0, dtype=float)
    out = np.empty((len(x), n + 1))
    out[:, 0] = x
    for i in range(n):
        x = step(x, h_val)
        out[:, i + 1] = x
    return out


@pytest.mark.parametrize("word", ["32123", "12321"])
def test_shadow_solution_tracks_the_integrator_figs_3_4(word):
    """Figs. 3-4: over 10^4 steps at h = 0.1 from (1, 1, 1), x^s matches the integrator to round-off in every
    component, while x^o and x^c drift away (beats)."""
    system = model("ho3")
    n, hv = 10_000, 0.1
    traj = _iterate(system, word, [1.0, 1.0, 1.0], hv, n)
    times = hv * np.arange(n + 1)
    err = {}
    for kind in "ocs":
        f = modified_solution(system, word, kind).numeric(h=hv)
        out = f(times, np.array([1.0, 1.0, 1.0]))
        assert out.shape == (3, n + 1)
        err[kind] = np.abs(out - traj)
    assert err["s"].max() < 1e-10
    assert err["o"].max() > 0.1 and err["c"].max() > 0.1
    # the drift grows: late errors are much larger than early ones (no such growth for x^s)
    assert err["c"][2, -1000:].max() > 100 * err["c"][2, :11].max()
    assert err["o"][2, -1000:].max() > 100 * err["o"][2, :11].max()


def test_shadow_solution_on_ho_with_parameters():
    system = model("ho")
    hv, n = 0.3, 2000
    traj = _iterate(system, "121", [0.3, -1.2], hv, n)
    params = {"m": 1.0, "omega": 1.0}
    f = modified_solution(system, "121", "s").numeric(params=params, h=hv)
    assert np.abs(f(hv * np.arange(n + 1), [0.3, -1.2]) - traj).max() < 1e-11


def test_numeric_scalar_time_and_errors():
    f = modified_solution(model("ho3"), "32123", "s").numeric(h=0.1)
    assert f(0.0, [1.0, 2.0, 3.0]).shape == (3,)
    assert np.allclose(f(np.array([0.0]), [1.0, 2.0, 3.0])[:, 0], [1.0, 2.0, 3.0])
    with pytest.raises(NambuBCHError, match="initial state"):
        f(np.array([0.0]), [1.0, 2.0])
    with pytest.raises(UnstableStepError):
        modified_solution(model("ho3"), "32123", "c").numeric(h=2.5)
    with pytest.raises(NambuBCHError):
        modified_solution(model("ho3"), "32123", "shadow")
    with pytest.raises(NambuBCHError):
        modified_equations(model("ho3"), "32123", "x")


def test_no_closed_form_for_rigid_body():
    with pytest.raises(NoExactResultError):
        modified_solution(model("rigid-body"), "12321", "o")


def test_shadow_solution_stretches_the_conserved_one_without_solving_again(monkeypatch):
    """Eq. (SHsol): ``x^s(t) = x^c(F(omega h) t)``; kind "s" takes the (cached) closed form of kind "c" instead of
    solving the same equations a second time -- and gives what that second solution gave."""
    from nambu_bch.exact import solutions

    system = model("ho")
    conserved = modified_solution(system, "TVT", "c")
    solved = []
    real = solutions._closed_form
    monkeypatch.setattr(solutions, "_closed_form", lambda *a: solved.append(a) or real(*a))
    shadow = solutions._solution.__wrapped__(system, "TVT", "s")   # past the cache: the work of a first call
    assert solved == []
    base, x0, Omega = real(system, modified_equations(system, "TVT", "c"), solutions.TIME)
    factor = solutions.exact_shadow_hamiltonians(system, "TVT").factor
    assert shadow.expressions == tuple(e.subs(solutions.TIME, factor * solutions.TIME) for e in base)
    assert shadow.initial_symbols == x0 == conserved.initial_symbols and shadow.frequency == factor * Omega


@pytest.mark.parametrize("name,word,kind", [("ho3", "32123", "o"), ("ho", "121", "c")])
def test_closed_form_in_the_exact_field_is_sympys_closed_form(name, word, kind):
    """The coefficients computed in ``Q(parameters, h, x_0)`` (``W**2 = det`` as field arithmetic) give the very
    expressions -- same sympy structure, same printed form -- that expanding and collecting in sympy gives
    (Eqs. OHsol, CQsol)."""
    from nambu_bch.exact import solutions

    system = model(name)
    eqs = modified_equations(system, word, kind)
    exact, x0, Omega = solutions._closed_form(system, eqs, solutions.TIME)
    rhs = [sympy.expand(r) for r in eqs]
    lc = solutions.linear_core(system.coordinates, rhs, system.name)
    W = sympy.Dummy("Omega", positive=True)
    trig = (sympy.cos(W * t), sympy.sin(W * t), sympy.cos(2 * W * t), sympy.sin(2 * W * t))
    y = tuple(system.coordinates[i] for i in lc.core)
    collected, _, _ = solutions._closed_form_sympy(system.coordinates, rhs, x0, lc, W, trig, y, solutions.TIME)
    assert exact == collected
    assert [sympy.srepr(e) for e in exact] == [sympy.srepr(e) for e in collected]


def test_closed_form_takes_sympys_route_outside_the_rationals():
    """An algebraic coefficient (``2**(1/3)``, a Yoshida weight) is not in ``Q(symbols)``: the exact route declines
    and sympy's expansion is used (the field would treat the radical as an independent symbol)."""
    from nambu_bch.exact import solutions

    data = [sympy.Integer(0), sympy.Integer(1), -sympy.cbrt(2) * omega**2, sympy.Integer(0), sympy.cbrt(2) * omega**2,
            x10, x20]
    assert solutions._exact_parts(data, 0, (0, 1), (), (sympy.S(1),) * 5) is None
    assert solutions._exact_parts([sympy.Integer(0), 1 / m, -m * omega**2, sympy.Integer(0), omega**2, x10, x20], 0,
                                  (0, 1), (), (sympy.cos(t), sympy.sin(t), 2, 3, t)) is not None


def test_composed_map_is_composed_once_per_word():
    """The composed map (an immutable tuple) is memoised per (splitting, composition, step): the conserved
    quantities, ``is_invariant`` and the testing helpers ask for the same map (``clear_caches`` forgets it:
    tests/test_public_api.py checks that every ``lru_cache`` is listed in ``CACHES``)."""
    splitting = model("ho").splitting
    phi = composed_map(splitting, "121")
    assert composed_map(splitting, "121") is phi
    assert composed_map(splitting, "121", h=sympy.Rational(1, 10)) == tuple(e.subs(h, sympy.Rational(1, 10)) for e in phi)
