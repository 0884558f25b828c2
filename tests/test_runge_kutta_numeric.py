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
