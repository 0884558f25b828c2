"""Tests of the diagnostics, the studies and the paper's figures.

Literature values: Table (table) (H_c, G_c of 32123), Eqs. (OHsol), (CQsol), (SHsol), Figs. 1-4 of
Horikoshi, Sect. 5.5.  Numerical tests: observed order by log-log fit, bounded drift.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from nambu_bch.errors import InvalidRunError, NambuBCHError
from nambu_bch.numeric.diagnostics import check, drift_rate, fit_order, observed_order, quantities
from nambu_bch.numeric.figures import paper_figures
from nambu_bch.numeric.studies import h_scan, precision_study, truncation_study


@pytest.fixture(scope="module")
def paper_check():
    """The CLI's `check` run: Phi^{32123} on ho3, h = 0.1, 10^5 steps, x(0) = (1, 1, 1)."""
    return check("ho3", "32123", 0.1, 100_000, [1.0, 1.0, 1.0])


def test_check_reports_the_paper_errors(paper_check):
    d = paper_check.to_dict()
    assert d["h"] == 0.1 and d["steps"] == 100_000
    err = d["max_abs_error"]
    for key in ("H", "G", "H_c", "G_c", "H_S_exact", "G_S_exact", "x3_o", "x3_c", "x3_s"):
        assert key in err, key
    # Figs. 1-2: H, G oscillate with O(h^2) amplitude; H_c, G_c (Table (table)) are conserved
    assert 1.0e-3 < err["H"] < 1.4e-3 and 4.5e-3 < err["G"] < 5.5e-3
    assert err["H_c"] < 1e-12 and err["G_c"] < 1e-12
    assert err["H_S_exact"] < 1e-12 and err["G_S_exact"] < 1e-12
    # Figs. 3-4: x^o and x^c beat against the numerical solution, x^s does not (Eqs. OHsol, CQsol, SHsol)
    assert err["x3_o"] > 1.0 and err["x3_c"] > 1.0
    assert err["x3_s"] < 1e-9
    if "H_S" in err:                                   # truncated BCH shadow Hamiltonian of order 2: O(h^4)
        assert err["H_S"] < 1e-4


def test_check_result_is_json(paper_check):
    text = json.dumps(paper_check.to_dict(), allow_nan=False)
    back = json.loads(text)
    assert isinstance(back["max_abs_error"]["H"], float)
    assert back["model"] == "ho3" and back["integrator"] == "32123"
    assert "H_c" in str(paper_check)


def test_check_leaves_out_what_does_not_exist():
    r = check("rigid-body", "12321", 0.05, 1000, [0.3, 0.8, -0.5], {"I1": 1.0, "I2": 2.0, "I3": 3.0},
              include=("H", "G", "H_c", "G_c", "o", "c", "s"))
    assert set(r.max_abs_error) == {"H", "G"}
    r = check("ho", "TVT", 0.1, 1000, [1.0, 0.0], include=("H", "G", "H_c", "G_c", "s"))
    assert "G" not in r.max_abs_error and "G_c" not in r.max_abs_error
    assert r.max_abs_error["H_c"] < 1e-13 and r.max_abs_error["x1_s"] < 1e-11


def test_check_rejects_batches():
    with pytest.raises(InvalidRunError, match="one initial state"):
        check("ho", "TVT", 0.1, 10, [[1.0, 0.0], [0.0, 1.0]])


def test_quantities_of_32123():
    """Table (table): H_c = H + m omega^4 h^2 x1^2 / 8, G_c = G + omega^2 h^2 x1^2 / 2."""
    import sympy

    x1, x2, x3 = sympy.symbols("x1 x2 x3")
    q = quantities("ho3", "32123", 0.1, which=("H_c", "G_c"))
    assert sympy.simplify(q["H_c"] - (x2**2 / 2 + x3 / 2 + sympy.Float(0.01, 30) * x1**2 / 8)) .is_zero or \
        abs(float((q["H_c"] - (x2**2 / 2 + x3 / 2 + 0.01 * x1**2 / 8)).subs({x1: 1, x2: 1, x3: 1}))) < 1e-15
    assert abs(float((q["G_c"] - (x3 - x1**2 + 0.01 * x1**2 / 2)).subs({x1: 0.7, x2: 1, x3: 2}))) < 1e-15


def test_observed_order_is_two_for_the_paper_schemes():
    for word in ("32123", "12321"):
        fit = observed_order("ho3", word, [0.1, 0.05, 0.025, 0.0125], 4.0, [1.0, 1.0, 1.0])
        assert fit.order == pytest.approx(2.0, abs=0.05)
    fit = observed_order("ho3", "32123", [0.1, 0.05, 0.025], 4.0, [1.0, 1.0, 1.0], quantity="H")
    assert fit.order == pytest.approx(2.0, abs=0.05)


def test_observed_order_four_for_forest_ruth_without_exact_solution():
    """Rigid body has no closed-form reference: the reference is a 64x finer run of the same scheme."""
    fit = observed_order("rigid-body", "forest-ruth", [0.2, 0.1, 0.05], 2.0, [0.3, 0.8, -0.5],
                         params={"I1": 1.0, "I2": 2.0, "I3": 3.0})
    assert fit.order == pytest.approx(4.0, abs=0.2)
    assert fit.to_dict()["quantity"] == "x"


def test_observed_order_first_order_word():
    fit = observed_order("ho", "12", [0.02, 0.01, 0.005], 1.0, [1.0, 0.0])
    assert fit.order == pytest.approx(1.0, abs=0.05)


def test_observed_order_unknown_quantity():
    with pytest.raises(InvalidRunError, match="G_c"):
        observed_order("ho", "TVT", [0.1, 0.05], 1.0, [1.0, 0.0], quantity="G_c")


def test_drift_rate_and_order_fits():
    t = np.linspace(0, 100, 1001)
    fit = drift_rate(t, 1e-6 * t + 1e-3 * np.cos(30 * t))
    assert fit.rate == pytest.approx(1e-6, rel=0.1)
    assert fit.drift == pytest.approx(1e-4, rel=0.2)
    assert drift_rate(t, np.zeros_like(t)).rate == 0.0
    assert fit_order([1e-1, 1e-2], [3e-4, 3e-8]).order == pytest.approx(4.0)
    with pytest.raises(InvalidRunError):
        drift_rate([0, 1], [0, 1])
    with pytest.raises(InvalidRunError):
        fit_order([0.1, 0.05], [0.0, 1e-3])
    with pytest.raises(NambuBCHError):
        fit_order([0.1], [1e-3])


# -- studies ------------------------------------------------------------------------------------------------


def test_h_scan_finds_the_stability_limit():
    """omega h -> 2 is the stability limit of the oscillators (position/velocity Verlet and 32123)."""
    scan = h_scan("ho3", "32123", steps=500)
    assert scan.stability_limit == pytest.approx(1.999)
    assert not scan.stable[scan.hs >= 2.0].any() and scan.stable[scan.hs < 2.0].all()
    H = scan.max_abs_error["H"]
    small = scan.hs < 0.1
    slope = np.polyfit(np.log(scan.hs[small]), np.log(H[small]), 1)[0]
    assert slope == pytest.approx(2.0, abs=0.1)               # O(h^2) energy error
    assert np.nanmax(scan.max_abs_error["H_c"][scan.hs < 1.0]) < 1e-12
    rows = scan.to_dict()["rows"]
    assert rows[-1]["stable"] is False and rows[-1]["H"] is None
    json.dumps(scan.to_dict(), allow_nan=False)


def test_precision_study_kahan_beats_plain():
    study = precision_study(steps=100_000, every=100, mp_steps=1000, dps=30, repeats=1)
    rows = {r["arithmetic"]: r for r in study.rows()}
    assert set(rows) == {"float64", "float64+kahan", "mpmath dps=30"}
    assert rows["mpmath dps=30"]["extrapolated"] is True
    assert rows["mpmath dps=30"]["max|dH_c|"] < 1e-25
    assert rows["float64+kahan"]["max|dH_c|"] <= rows["float64"]["max|dH_c|"]
    assert rows["float64"]["max|dH_c|"] < 1e-11
    json.dumps(study.to_dict(), allow_nan=False)


def test_truncation_study_error_falls_with_order():
    study = truncation_study(orders=(2, 4), steps=20_000, every=10)
    rows = study.rows()
    assert rows[0]["max|dH_S|"] > 100 * rows[1]["max|dH_S|"]      # O(h^4) -> O(h^6), h = 0.1
    assert all(r["derive_seconds"] >= 0 for r in rows)


# -- figures ------------------------------------------------------------------------------------------------


def test_paper_figures_are_written(tmp_path):
    paths = paper_figures(tmp_path, t_short=10.0, t_long=1000.0)
    assert sorted(paths) == ["fig1", "fig2", "fig3", "fig4"]
    for p in paths.values():
        data = p.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_paper_figures_refuse_an_unknown_format(tmp_path):
    with pytest.raises(InvalidRunError, match="format"):
        paper_figures(tmp_path, fmt="bmp")
    assert list(tmp_path.iterdir()) == []


def test_committed_figures_exist():
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "docs" / "figures"
    for k in range(1, 5):
        f = root / f"fig{k}.png"
        assert f.exists() and f.stat().st_size < 400_000


def test_truncated_shadow_residual_scales_like_h4():
    """The order-2 BCH shadow Hamiltonian of a symmetric scheme is conserved up to O(h^4) (Eq. BCH2 truncated)."""
    errs = []
    for h in (0.1, 0.05):
        r = check("ho3", "32123", h, int(round(20 / h)), [1.0, 1.0, 1.0], include=("H_S", "G_S"))
        assert "H_S" in r.max_abs_error  # the BCH family exists for 32123 on ho3 (Eqs. SH32123, SG32123)
        errs.append(r.max_abs_error["H_S"])
    assert fit_order([0.1, 0.05], errs).order == pytest.approx(4.0, abs=0.2)
