"""Runge--Kutta methods in the numeric backend and through ``shadow_hamiltonians``.

The generated Newton iteration (:func:`nambu_bch.numeric.runge_kutta.iterate_runge_kutta`) against the plain numpy
reference ``rk_iterate``; compiled and interpreted runs bit for bit; Kahan's linearly implicit step
``x' = x + h (I - h/2 f'(x))^-1 f(x)`` (Celledoni, McLachlan, Owren, Quispel, J. Phys. A 46 (2013) 025201)
equal to the three-stage tableau on the rigid body; the invariants the methods keep (implicit midpoint and the Gauss
methods keep quadratic invariants, HLW Sect. IV.2: on the rigid body H and G) confirmed by iteration; the one entry
point ``shadow_hamiltonians`` returning a family for the tableaux (docs/runge_kutta.md, "The shadow question").
"""

from __future__ import annotations

import numpy as np
import pytest

from nambu_bch.errors import InvalidRunError, NambuBCHError, NumericalRangeError
from nambu_bch.integrators.runge_kutta import TABLEAUX, runge_kutta_method
from nambu_bch.numeric import check, iterate, iterate_chunks
from nambu_bch.numeric.runge_kutta import iterate_runge_kutta, rk_iterate
from nambu_bch.shadow import shadow_hamiltonians

P = {"I1": 1.0, "I2": 2.0, "I3": 3.0}
X0 = [1.0, 0.5, 0.2]


def _invariants(x):
    H = x[:, 0] ** 2 / 2 + x[:, 1] ** 2 / 4 + x[:, 2] ** 2 / 6
    G = (x ** 2).sum(axis=1) / 2
    return H, G


@pytest.mark.parametrize("method", ["midpoint", "gauss4", "gauss6", "trapezoid", "kahan", "rk4"])
def test_generated_step_matches_reference(method):
    x = iterate("rigid-body", method, 0.1, 60, X0, P, every=20, backend="numpy")
    ref = rk_iterate("rigid-body", method, 0.1, 60, X0, P, every=20)
    assert x.shape == (4, 3)
    assert np.abs(x - ref).max() < 1e-13


def test_compiled_equals_interpreted_bit_for_bit():
    pytest.importorskip("numba")
    a = iterate_runge_kutta("rigid-body", "gauss4", 0.1, 50, X0, P, every=10, backend="numba")
    b = iterate_runge_kutta("rigid-body", "gauss4", 0.1, 50, X0, P, every=10, backend="numpy")
    assert np.array_equal(a, b)


@pytest.mark.parametrize("method", ["midpoint", "gauss4"])
def test_quadratic_invariants_kept_by_iteration(method):
    """Midpoint and Gauss keep H and G of the rigid body (quadratic invariants) to round-off; RK4 does not."""
    x = iterate("rigid-body", method, 0.2, 200, X0, P, backend="numpy")
    H, G = _invariants(x)
    assert np.abs(H - H[0]).max() < 1e-13 and np.abs(G - G[0]).max() < 1e-13
    y = iterate("rigid-body", "rk4", 0.2, 200, X0, P, backend="numpy")
    Hy, _ = _invariants(y)
    assert np.abs(Hy - Hy[0]).max() > 1e-8


@pytest.mark.parametrize("method", ["rk4", "kahan"])
def test_explicit_and_kahan_loops_compiled_equal_interpreted_bit_for_bit(method, monkeypatch):
    """The two entry points besides Newton's (compiled above): compiled equals interpreted bit for bit, plain and
    compensated, one trajectory and a batch; and a run of one kind compiles its own entry point only."""
    pytest.importorskip("numba")
    import nambu_bch.numeric.runge_kutta as rk
    from nambu_bch.systems.spec import as_system

    monkeypatch.setattr(rk, "_MODULES", {})  # new dispatchers, none compiled (numba's cache may still be warm)
    for x in (X0, np.array([X0, [0.3, -0.2, 1.0]]).T):
        for kahan in (False, True):
            a = iterate_runge_kutta("rigid-body", method, 0.1, 50, x, P, every=10, kahan=kahan, backend="numba")
            b = iterate_runge_kutta("rigid-body", method, 0.1, 50, x, P, every=10, kahan=kahan, backend="numpy")
            assert np.array_equal(a, b)
    module = rk._MODULES[as_system("rigid-body"), "numba"]
    compiled = [f for f in rk._RK_ENTRIES.values() if getattr(module, f).signatures]
    assert compiled == [rk._RK_ENTRIES["explicit" if method == "rk4" else "kahan"]]

def test_each_entry_point_reaches_only_what_its_step_needs():
    """numba compiles a function with every function it calls: an explicit run reaches the field alone (not Newton's
    iteration, the linear solve or the Jacobian), Kahan's and Newton's runs the field and its Jacobian."""
    import ast

    from nambu_bch.numeric.codegen import runge_kutta_source
    from nambu_bch.numeric.runge_kutta import _RK_ENTRIES, _RK_FUNCTIONS
    from nambu_bch.systems.spec import as_system

    tree = ast.parse(runge_kutta_source(as_system("rigid-body")))
    defs = {f.name: f for f in tree.body if isinstance(f, ast.FunctionDef)}

    def calls(name):
        return {n.func.id for n in ast.walk(defs[name])
                if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id in defs}

    assert set(defs) == set(_RK_FUNCTIONS) == {"rk_field", "rk_jacobian", *_RK_ENTRIES.values()}
    assert calls("rk_run_explicit") == {"rk_field"}
    assert calls("rk_run_kahan") == calls("rk_run_newton") == {"rk_field", "rk_jacobian"}
    assert calls("rk_field") == calls("rk_jacobian") == set()


def test_auto_interprets_a_short_run_until_its_own_entry_point_is_compiled(monkeypatch):
    """A compiled Newton loop does not make a short explicit run compile its own (seconds): ``backend="auto"``
    interprets it, and calls the compiled explicit loop once that one exists."""
    from types import SimpleNamespace

    import nambu_bch.numeric.runge_kutta as rk
    from nambu_bch.numeric.kernels import numba_available
    from nambu_bch.systems.spec import as_system

    if not numba_available():
        pytest.skip("numba not installed or disabled")
    called = []

    def loop(compiled):
        def run(*args):
            if not compiled:
                raise AssertionError("a short run compiled a loop")
            called.append(args[7])  # steps
            return args[7]
        run.signatures = ["(float64[::1], ...)"] if compiled else []
        return run

    fake = SimpleNamespace(rk_run_newton=loop(True), rk_run_kahan=loop(False), rk_run_explicit=loop(False))
    monkeypatch.setattr(rk, "_MODULES", {(as_system("rigid-body"), "numba"): fake})
    interpreted = iterate_runge_kutta("rigid-body", "rk4", 0.1, 10, X0, P, backend="auto")
    assert np.array_equal(interpreted, iterate_runge_kutta("rigid-body", "rk4", 0.1, 10, X0, P, backend="numpy"))
    assert called == []
    fake.rk_run_explicit = loop(True)
    iterate_runge_kutta("rigid-body", "rk4", 0.1, 10, X0, P, backend="auto")
    assert called == [10]

def test_kahan_is_one_linear_solve_per_step():
    stats = {}
    iterate_runge_kutta("rigid-body", "kahan", 0.1, 30, X0, P, backend="numpy", stats=stats)
    assert stats["linear_solves"] == 30 and stats["newton_iterations"] == 30
    with pytest.raises(NambuBCHError, match="quadratic"):
        iterate("fpu-beta", "kahan", 0.1, 3, backend="numpy")


def test_batch_chunks_and_compensation():
    X = np.array([X0, [0.3, -0.2, 1.0]]).T
    batch = iterate("rigid-body", "midpoint", 0.1, 20, X, P, every=5, backend="numpy")
    one = iterate("rigid-body", "midpoint", 0.1, 20, X[:, 1], P, every=5, backend="numpy")
    assert batch.shape == (5, 3, 2) and np.array_equal(batch[:, :, 1], one)
    full = iterate("rigid-body", "gauss4", 0.1, 23, X0, P, every=2, kahan=True, backend="numpy")
    blocks = list(iterate_chunks("rigid-body", "gauss4", 0.1, 23, X0, P, every=2, kahan=True, backend="numpy",
                                 chunk_samples=3))
    numbers = np.concatenate([n for n, _ in blocks])
    assert list(numbers) == [0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 23]
    assert np.array_equal(np.concatenate([s for _, s in blocks]), full)


def test_newton_failure_names_h_and_step():
    with pytest.raises(NumericalRangeError, match=r"at step 1 \(h = 50\); lower h"):
        iterate("rigid-body", "gauss6", 50.0, 5, [3.0, 2.0, 1.0], P, backend="numpy")
    with pytest.raises(InvalidRunError, match="float64 only"):
        iterate("rigid-body", "midpoint", 0.1, 3, X0, P, dps=30)


def test_interpreted_math_error_is_a_range_error():
    """The interpreter's ``math.sin(inf)`` (an explicit stage past the float64 range) raises ValueError where the
    compiled loop gets nan: the run refuses it as the compiled one does, naming the method and h."""
    with pytest.raises(NumericalRangeError, match=r"rk4 on .*float64 range \(h = 1e\+200\); lower h"):
        iterate_runge_kutta("pendulum", "rk4", 1e200, 3, [1.0, 0.2], backend="numpy")


def test_method_names_and_symmetry():
    assert runge_kutta_method("Gauss4") is TABLEAUX["gauss4"] and runge_kutta_method("12321") is None
    # every collocation method of the table is symmetric except the explicit ones and implicit Euler
    # (Lobatto IIIA and IIIB alike: HLW Sect. V.2)
    assert [n for n, t in TABLEAUX.items() if t.symmetric] == ["midpoint", "trapezoid", "gauss4", "gauss6",
                                                              "lobatto-iiib-2", "lobatto-iiia-3", "lobatto-iiib-3",
                                                              "kahan"]


def test_shadow_hamiltonians_of_a_tableau():
    """docs/runge_kutta.md table: gauss4 on ho3 has a pair through h^4 (odd orders vanish: symmetric method);
    midpoint on the rigid body is obstructed at h^2 with the divergence functional as certificate."""
    F = shadow_hamiltonians("ho3", "gauss4", order=4)
    assert F.exists and F.free_parameters == ["alpha"] and F.composition is TABLEAUX["gauss4"]
    assert "O(h^6)" in F.to_text()
    D = F.to_dict()
    assert D["integrator"] == "gauss4" and D["exists"] is True
    R = shadow_hamiltonians("rigid-body", TABLEAUX["midpoint"], order=2, existence=False)
    assert R.exists is None and R.failed_order == 2
    cert = R.to_dict()["certificate"]
    assert cert["kind"] == "left-null-functional" and cert["value"] == "(I1 - I2)*(I1 - I3)*(I2 - I3)/(4*I1**2*I2**2*I3**2)"
    with pytest.raises(NambuBCHError, match="route='direct'"):
        shadow_hamiltonians("ho3", "midpoint", route="fi")


def test_check_runs_a_runge_kutta_method():
    r = check("rigid-body", "midpoint", 0.1, 200, X0, P, include=("H", "G"))
    assert r.max_abs_error["H"] < 1e-13 and r.max_abs_error["G"] < 1e-13


def test_compare_ranks_families_and_draws_them():
    """compare puts compositions and Runge--Kutta methods in one table and in the curves the figure draws
    (docs/runge_kutta.md, compare); a non-polynomial field (the pendulum) still runs, without the exact leading term."""
    from nambu_bch.design.compare import compare

    C = compare("ho", ["121", "midpoint", "rk4", "kahan"], t_end=1.0, steps=(10, 20))
    rows = {r["integrator"]: r for r in C.rows}
    assert (rows["midpoint"]["leading_power"], rows["rk4"]["leading_power"]) == (2, 4)
    assert rows["rk4"]["cost"] == 4.0 and rows["kahan"]["cost"] == 2.0 and rows["midpoint"]["cost"] >= 1.0
    assert set(C.curves) == set(rows) and "midpoint" in C.table()
    assert all(p["evaluations"] > 0 and p["error"] > 0 for pts in C.curves.values() for p in pts)
    P = compare("pendulum", ["TVT", "gauss4"], t_end=1.0, steps=(10, 20))
    assert P.rows[1]["leading_power"] is None and P.rows[1]["slope"] < -3.5


def test_long_runge_kutta_run_is_refused_up_front():
    from nambu_bch.errors import ResourceLimitError
    from nambu_bch.numeric.runge_kutta import MAX_RK_STEPS

    with pytest.raises(ResourceLimitError, match="trajectory-steps of gauss4"):
        iterate("rigid-body", "gauss4", 0.1, MAX_RK_STEPS // 2, np.ones((3, 3)), P, backend="numpy")
