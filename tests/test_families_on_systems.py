"""The method families on systems: force-gradient compositions, processed kernels, ABA864/ABA1064.

Sources pinned here:
* Chin, Phys. Lett. A 226 (1997) 344, algorithm 4A: order 4 (the gradient term c = 1/72);
* Takahashi & Imada, J. Phys. Soc. Jpn. 53 (1984) 3765: the kernel A(1/2) B~ A(1/2) has effective order 4 once
  processed (Blanes, Casas & Ros, SIAM J. Sci. Comput. 21 (1999) 711);
* Blanes, Casas, Farres, Laskar, Makazaga & Murua, Appl. Numer. Math. 68 (2013) 58: ABA864 has generalised order
  (8, 6, 4), ABA1064 (10, 6, 4) -- the names of the methods state them.
No published table of error constants for PEFRL, Chin's 4A or the Takahashi-Imada kernel in the package's norm was
found: the values pinned below are computed here (exact data, printed to 4 digits), not published.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch.design import gradient_effective_field, gradient_shadow
from nambu_bch.design.gradient_system import gradient_structure
from nambu_bch.errors import InvalidCompositionError, InvalidRunError, InvalidSystemError, NambuBCHError
from nambu_bch.numeric import gradient_check, iterate_gradient, iterate_processed

HH_X0 = (0.1, -0.2, 0.3, 0.25)


# ------------------------------------------------------------------------------------------------
# catalogue: ABA864, ABA1064


@pytest.mark.parametrize("name, orders", [("aba864", (8, 6, 4)), ("aba1064", (10, 6, 4))])
def test_aba_methods_have_their_published_generalized_order(name, orders):
    """Blanes et al. 2013: the eps, eps^2, eps^3 error terms are O(h^(r+1)) with (r_1, r_2, r_3) = the name's digits.
    The decimals satisfy the conditions to their own accuracy, far below the first term that does not vanish."""
    from nambu_bch.design.structure import generalized_order
    from nambu_bch.integrators.tables import TABLES

    comp = nb.composition(name)
    assert comp.error_bound < 1e-15 and comp.order == 4 and comp.symmetric and comp.pieces[0] == 1
    G = generalized_order(name, powers=3, max_degree=orders[0] + 1)
    assert G.orders == orders == TABLES[name].generalized
    assert min(G.constant(m) for m in (1, 2, 3)) > 1e-7   # well above the bound: the order is not one more


def test_aba864_constants_as_computed():
    """Computed here (no published table in this norm): the eps^m constants of ABA864."""
    from nambu_bch.design.structure import generalized_order

    G = generalized_order("aba864", powers=3, max_degree=9)
    assert [round(G.constant(m), 6) for m in (1, 2, 3)] == [0.0002, 0.002991, 0.029427]


# ------------------------------------------------------------------------------------------------
# structure, X_eff by two routes, shadow Hamiltonians


@pytest.mark.parametrize("model", ["ho", "henon-heiles", "pendulum"])
def test_chin_4a_effective_field_two_routes_agree_exactly(model):
    formal = gradient_effective_field(model, "chin-4a", order=4)
    backward = gradient_effective_field(model, "chin-4a", order=4, route="backward")
    assert formal == backward
    assert [any(Z) for Z in formal.coefficients] == [True, False, False, False, True]   # order 4, symmetric


def test_chin_4a_leading_term_on_the_oscillator():
    m, omega, x1, x2 = sympy.symbols("m omega x1 x2")
    Z4 = gradient_effective_field("ho", "chin-4a", order=4)[4]
    assert sympy.expand(Z4[0] + omega**4 * x2 / (720 * m)) == 0 and sympy.expand(Z4[1] + m * omega**6 * x1 / 1080) == 0


def test_plain_composition_matches_the_package_backward_error_analysis():
    """A composition without gradient terms: the word-series route equals nb.effective_field (another engine)."""
    X = gradient_effective_field("henon-heiles", "121", order=3)
    Y = nb.effective_field(nb.model("henon-heiles").splitting, "121", order=3)
    for j in range(4):
        assert all(sympy.expand(a - b) == 0 for a, b in zip(X[j], Y[j].to_sympy()))


def test_shadow_hamiltonian_of_chin_4a():
    m, omega, x1, x2 = sympy.symbols("m omega x1 x2")
    S = gradient_shadow("ho", "chin-4a", order=4)   # every X_{H_j} = Z_j is checked inside, exactly
    assert S.terms[1] == S.terms[2] == S.terms[3] == 0
    assert sympy.expand(S.terms[4] - (m * omega**6 * x1**2 / 2160 - omega**4 * x2**2 / (1440 * m))) == 0
    assert S.to_dict()["H"][0] == str(S.terms[0])


def test_gradient_potential_is_minus_the_squared_force():
    q1, q2, p1, p2 = sympy.symbols("q1 q2 p1 p2")
    S = gradient_structure("henon-heiles")
    V = S.V
    assert sympy.expand(S.G + sympy.diff(V, q1) ** 2 + sympy.diff(V, q2) ** 2) == 0


@pytest.mark.parametrize("model", ["rigid-body", "ho3"])
def test_force_gradient_refused_where_the_pieces_have_no_structure(model):
    with pytest.raises(InvalidSystemError, match="canonical system") as info:
        gradient_effective_field(model, "chin-4a", order=2)
    assert "\n" not in str(info.value)


def test_force_gradient_refused_for_a_non_quadratic_kinetic_energy():
    S = nb.System("q p", ["p**4/4 + q**2/2"], name="quartic-kinetic")
    with pytest.raises(InvalidSystemError, match="quadratic in the momenta"):
        iterate_gradient(S, "chin-4a", 0.1, 2, (1.0, 0.0))


def test_bad_route_and_decimal_coefficients_refused():
    with pytest.raises(InvalidCompositionError, match="route"):
        gradient_effective_field("ho", "chin-4a", route="magic")
    with pytest.raises(InvalidCompositionError, match="exact coefficients"):
        gradient_effective_field("ho", "pefrl", order=2)
    complex_jump = "1:1/4+I/4,2:1/2+I/2,1:1/2,2:1/2-I/2,1:1/4-I/4"
    with pytest.raises(InvalidCompositionError, match="real coefficients"):
        gradient_effective_field("ho", complex_jump, order=2)
    with pytest.raises(InvalidCompositionError, match="real coefficients"):
        iterate_gradient("ho", complex_jump, 0.1, 2, (1.0, 0.0))


# ------------------------------------------------------------------------------------------------
# numerics


def _errors(run, hs, T=1.0):
    exact = np.array([np.cos(T), -np.sin(T)])
    return [float(np.linalg.norm(run(h, int(round(T / h)))[-1] - exact)) for h in hs]


def test_iterate_runs_chin_4a_at_fourth_order():
    e = _errors(lambda h, n: nb.iterate("ho", "chin-4a", h, n, [1.0, 0.0]), (0.1, 0.05))
    assert np.log2(e[0] / e[1]) == pytest.approx(4, abs=0.1)


def test_processed_kernel_has_its_effective_order():
    """The Takahashi-Imada kernel alone is second order; P K^n P^-1 (iterate's default for it) is fourth order."""
    bare = _errors(lambda h, n: iterate_gradient("ho", "takahashi-imada", h, n, [1.0, 0.0]), (0.1, 0.05))
    processed = _errors(lambda h, n: nb.iterate("ho", "takahashi-imada", h, n, [1.0, 0.0]), (0.1, 0.05))
    assert np.log2(bare[0] / bare[1]) == pytest.approx(2, abs=0.1)
    assert np.log2(processed[0] / processed[1]) == pytest.approx(4, abs=0.1)
    assert processed[1] < bare[1] / 100


def test_processed_samples_and_batch_shapes():
    x = iterate_processed("ho", "takahashi-imada", 0.1, 7, (1.0, 0.0), every=3)
    assert x.shape == (4, 2)
    X = iterate_gradient("ho", "chin-4a", 0.1, 4, [[1.0, 0.5], [0.0, 0.1]])
    assert X.shape == (5, 2, 2)
    single = iterate_gradient("ho", "chin-4a", 0.1, 4, [0.5, 0.1])
    assert np.array_equal(X[:, :, 1], single)


def test_iterate_refuses_kernel_options_for_gradient_methods():
    with pytest.raises(InvalidRunError, match="kahan= applies to the compiled"):
        nb.iterate("ho", "chin-4a", 0.1, 2, [1.0, 0.0], kahan=True)


def test_gradient_check_drift_slopes():
    """H drifts like h^4 and H_S through h^4 like h^6 (symmetric: the next term is h^6)."""
    R = gradient_check("henon-heiles", "chin-4a", 0.2, 20, HH_X0)
    assert R.energy_slope == pytest.approx(4, abs=0.15) and R.shadow_slope == pytest.approx(6, abs=0.2)
    P = gradient_check("ho", "takahashi-imada", 0.2, 20, (1.0, 0.0), halvings=1)
    assert P.processed and P.energy_slope == pytest.approx(4, abs=0.2) and np.isnan(P.shadow_slope)
    assert P.kernel_energy_slope == pytest.approx(2, abs=0.2) and "kernel alone" in str(P)
    assert json.loads(json.dumps(R.to_dict()))["shadow_order"] == 4


# ------------------------------------------------------------------------------------------------
# compare and the command line


@pytest.fixture(scope="module")
def comparison():
    return nb.compare("ho", ["121", "pefrl", "chin-4a", "takahashi-imada"], t_end=2.0, steps=(10, 20, 40), samples=50)


def test_compare_rows_for_the_new_families(comparison):
    rows = {r["integrator"]: r for r in comparison.rows}
    chin, ti = rows["chin-4a"], rows["takahashi-imada"]
    assert chin["order"] == 4 and chin["family"] == "force-gradient" and chin["slope"] == pytest.approx(-4, abs=0.2)
    assert (chin["cost"], chin["fsal_extra"]) == (5, 1)     # B A B~ A B: the gradient kick counts 2, first = last
    assert ti["order"] == 4 and ti["family"] == "processed" and (ti["cost"], ti["fsal_extra"]) == (3, 5)
    pts = comparison.curves["takahashi-imada"]   # against h: the two processor uses per run bend the cost axis
    assert np.log2(pts[-2]["error"] / pts[-1]["error"]) == pytest.approx(4, abs=0.2)
    assert rows["pefrl"]["slope"] == pytest.approx(-4, abs=0.2)


def test_rkn_constants_in_the_rows_of_a_canonical_system(comparison):
    """On T(p) + V(q) the rows carry the constants modulo the RKN relations, by which PEFRL was optimised (the RKN
    value 0.1597 of docs/integrators.md, "Structured pieces"); a Nambu system has no such rows."""
    from nambu_bch.design.compare import _has_rkn_structure

    rows = {r["integrator"]: r for r in comparison.rows}
    assert round(rows["pefrl"]["error_constant_rkn"], 4) == 0.1597 and rows["pefrl"]["order_rkn"] == 4
    assert rows["121"]["error_constant_rkn"] == rows["121"]["error_constant"]      # below degree 4 nothing changes
    assert rows["chin-4a"]["error_constant_rkn"] < rows["chin-4a"]["error_constant"]
    assert not _has_rkn_structure(nb.model("ho3")) and _has_rkn_structure(nb.model("pendulum"))


def test_error_constants_as_computed(comparison):
    """Computed (no published table in this norm): Chin 4A, the processed Takahashi-Imada kernel, PEFRL."""
    rows = {r["integrator"]: r for r in comparison.rows}
    assert round(rows["chin-4a"]["error_constant"], 4) == 0.3266
    assert round(rows["takahashi-imada"]["error_constant"], 4) == 0.0888
    assert round(rows["pefrl"]["error_constant"], 4) == 0.3920


def test_cli_check_and_compare(capsys):
    from nambu_bch.cli import main

    assert main(["check", "--model", "ho", "--integrator", "chin-4a", "--h", "0.2", "--steps", "10", "--x0", "1,0",
                 "--format", "json"]) in (0, None)
    data = json.loads(capsys.readouterr().out)
    assert data["integrator"] == "chin-4a" and data["shadow_order"] == 4
    assert main(["check", "--model", "rigid-body", "--integrator", "chin-4a"]) == 2
    err = capsys.readouterr().err
    assert "canonical system" in err and "Traceback" not in err
    assert main(["compare", "--model", "ho", "--integrator", "chin-4a", "--integrator", "121", "--t-end", "1",
                 "--step-counts", "10,20"]) in (0, None)
    assert "chin-4a" in capsys.readouterr().out


def test_cli_check_refuses_options_that_do_not_apply(capsys):
    from nambu_bch.cli import main

    assert main(["check", "--model", "ho", "--integrator", "chin-4a", "--alpha", "1"]) == 2
    assert "--alpha does not apply" in capsys.readouterr().err


def test_errors_are_one_line_nambu_errors():
    for call in (lambda: iterate_gradient("ho", "chin-4a", "x", 2), lambda: gradient_check("ho", "chin-4a", 0.1, 10**9),
                 lambda: gradient_shadow("ho", "chin-4a", order=99)):
        with pytest.raises(NambuBCHError) as info:
            call()
        assert "\n" not in str(info.value)


def test_work_precision_figure_with_the_new_families(comparison):
    import matplotlib.pyplot as plt

    fig = comparison.figure()
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    plt.close(fig)
    assert any("chin-4a" in t and "force-gradient" in t for t in labels)
    assert any("takahashi-imada" in t and "processed" in t for t in labels)
