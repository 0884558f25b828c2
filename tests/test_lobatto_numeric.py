"""Lobatto IIIA-IIIB pairs in float64 and on the command line: stepping, what they keep, JSON.

Sources: Hairer, Lubich, Wanner, *Geometric Numerical Integration* (HLW), Sect. II.2 (the pair; s = 2 is the
Stormer-Verlet method), Sect. VI.4 (symplectic), Sect. IX.8 (a symplectic method of order p keeps the truncated
modified Hamiltonian up to the next term of the series: with H_S through h^4, H_S(x_n) - H_S(x_0) = O(h^6)).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from nambu_bch.errors import NambuBCHError
from nambu_bch.integrators.runge_kutta import PARTITIONED, runge_kutta_method
from nambu_bch.numeric import check, iterate
from nambu_bch.numeric.runge_kutta import rk_iterate

X0 = [0.1, -0.2, 0.3, 0.25]


def test_pair_names_are_runge_kutta_methods():
    assert runge_kutta_method("Lobatto-IIIA-IIIB-3") is PARTITIONED["lobatto-iiia-iiib-3"]
    pair = PARTITIONED["lobatto-iiia-iiib-3"]
    assert pair.symmetric and not pair.is_explicit and pair.remainder_power(4) == 6


def test_s2_steps_like_stormer_verlet_212():
    """The float64 step of the s = 2 pair is the composition 212 (V/2, T, V/2) to round-off."""
    a = iterate("henon-heiles", "lobatto-iiia-iiib-2", 0.1, 100, X0, backend="numpy")
    b = iterate("henon-heiles", "212", 0.1, 100, X0)
    assert np.abs(a - b).max() < 1e-14


def test_generated_step_matches_reference():
    """The generated module (Newton on both tableaux' stages together) against the numpy reference step."""
    x = iterate("henon-heiles", "lobatto-iiia-iiib-3", 0.1, 40, X0, every=20, backend="numpy")
    ref = rk_iterate("henon-heiles", "lobatto-iiia-iiib-3", 0.1, 40, X0, every=20)
    assert np.abs(x - ref).max() < 1e-14


def test_h_moves_like_h4_and_shadow_like_h6():
    """s = 3 (order 4) on the oscillator over T = 4: halving h divides the spread of H by about 2^4 and that of
    H_S (through h^4) by about 2^6 (measured: 16.1 and 64.2)."""
    spread = {}
    for h in (0.2, 0.1):
        r = check("ho", "lobatto-iiia-iiib-3", h, int(round(4 / h)), [1.0, 0.0], order=4)
        spread[h] = r.max_abs_error["H"], r.max_abs_error["H_S"]
    ratio_H = spread[0.2][0] / spread[0.1][0]
    ratio_S = spread[0.2][1] / spread[0.1][1]
    assert 12 < ratio_H < 20 and 48 < ratio_S < 80
    assert spread[0.1][1] < 1e-2 * spread[0.1][0]


def test_pair_refused_on_a_nambu_system():
    with pytest.raises(NambuBCHError, match="partitioned method for canonical systems"):
        iterate("rigid-body", "lobatto-iiia-iiib-3", 0.1, 10, [1.0, 0.5, 0.2])


def test_cli_shadow_check_compare(capsys):
    from nambu_bch.cli._main import main

    assert main(["shadow", "--model", "ho", "--integrator", "lobatto-iiia-iiib-3", "--order", "4",
                 "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["integrator"] == "lobatto-iiia-iiib-3" and data["exists"] is True
    assert main(["check", "--model", "ho", "--integrator", "lobatto-iiia-iiib-2", "--h", "0.1", "--steps", "50",
                 "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["integrator"] == "lobatto-iiia-iiib-2"
    assert main(["compare", "--model", "ho", "--integrator", "lobatto-iiia-iiib-3", "--integrator", "212",
                 "--step-counts", "10,20", "--t-end", "2", "--format", "json"]) == 0
    rows = json.loads(capsys.readouterr().out)["integrators"]
    assert [r["order"] for r in rows] == [4, 2] and rows[0]["leading_power"] == 4
    # the pair's principal error norm over the bi-coloured trees of order 5 (computed; no published value)
    assert rows[0]["error_constant_exact"] == "sqrt(2530)/1440" and rows[0]["error_constant_kind"] == "A^(p+1)"
