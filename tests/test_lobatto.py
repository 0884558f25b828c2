"""Lobatto IIIA-IIIB as a partitioned pair for canonical systems: tableaux, modified equations, shadow Hamiltonians.

Sources: Hairer, Lubich, Wanner, *Geometric Numerical Integration* (HLW), Sect. II.2 (Lobatto IIIA-IIIB pairs;
s = 2 is the Stormer-Verlet method) and Sect. III.2 (partitioned Runge-Kutta methods and their order), Sect. VI.4
(the pair is symplectic, so a modified Hamiltonian exists at every order, Sect. IX.3).
"""

from __future__ import annotations

import pytest
import sympy

from nambu_bch import model
from nambu_bch.bch.concrete import effective_field_by_cost
from nambu_bch.bseries.modified import modified_equation, modified_equation_by_taylor, runge_kutta_shadow
from nambu_bch.errors import InvalidCompositionError
from nambu_bch.integrators.runge_kutta import PARTITIONED, TABLEAUX, PartitionedTableau, partitioned_tableau

h = sympy.Symbol("h")


def test_lobatto_pairs_are_symplectic_partners():
    """b_i a^_ij + b^_j a_ji = b_i b^_j and b = b^ (HLW Sect. VI.4, the symplecticity condition of a pair)."""
    for pair in PARTITIONED.values():
        A, Ah, b = pair.q.A, pair.p.A, pair.q.b
        s = pair.stages
        assert pair.p.b == b and pair.p.stages == s
        assert all(b[i] * Ah[i][j] + b[j] * A[j][i] - b[i] * b[j] == 0 for i in range(s) for j in range(s))
    assert TABLEAUX["lobatto-iiia-3"].c == (0, sympy.Rational(1, 2), 1)


@pytest.mark.parametrize("system", ["ho", "henon-heiles"])
def test_s2_is_stormer_verlet_212(system):
    """s = 2: the modified field equals the package's effective field of the composition 212 (V/2, T, V/2: the
    kick-drift-kick Stormer-Verlet) exactly through h^4, and differs from 121's at h^2."""
    S = model(system)
    M = modified_equation(S, "lobatto-iiia-iiib-2", 4)
    E = effective_field_by_cost(S.splitting, "212", 4)
    assert all(M[j] == E[j] for j in range(5)) and not M[2].is_zero()
    assert M[2] != effective_field_by_cost(S.splitting, "121", 2)[2]


@pytest.mark.parametrize("system", ["ho", "henon-heiles"])
def test_s3_has_order_four_and_a_shadow_hamiltonian(system):
    """s = 3: f~ = f + h^4 Z_4 + O(h^6) (order 4, symmetric); the direct route returns H_S through h^4."""
    S = model(system)
    R = runge_kutta_shadow(S, "lobatto-iiia-iiib-3", 4)
    M = R.effective
    assert [M[j].is_zero() for j in range(1, 5)] == [True, True, True, False]
    assert R.exists and [o.status for o in R.orders] == ["vanishes"] * 3 + ["solved"]
    (HS,) = R.shadow()
    assert sympy.expand(HS.subs(h, 0) - S.H) == 0 and sympy.degree(HS, h) == 4


def test_s3_shadow_hamiltonian_against_the_exact_step():
    """Independent of the backward analysis: the s = 3 step on the oscillator, from its stage equations solved by
    sympy, keeps the h^4-truncated H_S to O(h^7) per step (H itself only to O(h^5))."""
    S = model("ho")
    q, p = S.coordinates
    m, omega = S.parameters
    pair = PARTITIONED["lobatto-iiia-iiib-3"]
    K = sympy.symbols("K1:4")
    L = sympy.symbols("L1:4")
    Q = [q + h * sum(a * k for a, k in zip(row, K)) for row in pair.q.A]
    P = [p + h * sum(a * l for a, l in zip(row, L)) for row in pair.p.A]
    eqs = [K[i] - P[i] / m for i in range(3)] + [L[i] + m * omega**2 * Q[i] for i in range(3)]
    sol = sympy.solve(eqs, K + L, dict=True)[0]
    q1 = q + h * sum(b * sol[k] for b, k in zip(pair.q.b, K))
    p1 = p + h * sum(b * sol[l] for b, l in zip(pair.p.b, L))
    (HS,) = runge_kutta_shadow(S, pair, 4).shadow()
    for F, lowest in ((HS, 7), (S.H, 5)):
        change = sympy.cancel(F.subs({q: q1, p: p1}, simultaneous=True) - F)
        num, den = sympy.fraction(change)
        assert sympy.Poly(den, h).eval(0) != 0
        assert min(mono[0] for mono in sympy.Poly(num, h).monoms()) == lowest


def test_pair_with_equal_tableaux_is_the_plain_method():
    pair = PartitionedTableau("gauss4-twice", TABLEAUX["gauss4"], TABLEAUX["gauss4"], 4, "test")
    S = model("ho")
    assert all(a == b for a, b in zip(modified_equation_by_taylor(S, pair, 4), modified_equation(S, "gauss4", 4)))


def test_refusals():
    with pytest.raises(InvalidCompositionError, match="partitioned method for canonical systems"):
        modified_equation("rigid-body", "lobatto-iiia-iiib-3", 2)
    with pytest.raises(InvalidCompositionError, match="unknown partitioned Runge-Kutta pair 'lobatto'"):
        partitioned_tableau("lobatto")
    assert partitioned_tableau(PARTITIONED["lobatto-iiia-iiib-2"]) is PARTITIONED["lobatto-iiia-iiib-2"]
    with pytest.raises(InvalidCompositionError, match="same number of stages, got 2 and 3"):
        PartitionedTableau("x", TABLEAUX["gauss4"], TABLEAUX["gauss6"], 2, "")
    with pytest.raises(InvalidCompositionError, match="two ButcherTableau"):
        PartitionedTableau("x", "gauss4", TABLEAUX["gauss4"], 2, "")


def test_cli_refuses_the_pair_where_only_compositions_are_taken(capsys):
    """The composition-only subcommands (bch, ...) refuse a pair's name in one line that says where it runs."""
    from nambu_bch.cli._main import main

    assert main(["bch", "--model", "ho", "--integrator", "lobatto-iiia-iiib-3"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'lobatto-iiia-iiib-3' is a partitioned Runge-Kutta pair" in err
    assert "on canonical systems" in err


def test_a_pair_is_refused_off_canonical_systems_and_on_the_fi_route():
    import pytest

    import nambu_bch as nb
    from nambu_bch.errors import NambuBCHError

    with pytest.raises(NambuBCHError, match="partitioned method for canonical systems"):
        nb.shadow_hamiltonians("rigid-body", "lobatto-iiia-iiib-2", order=2)
    with pytest.raises(NambuBCHError, match="FI route"):
        nb.shadow_hamiltonians("ho", "lobatto-iiia-iiib-2", order=2, route="fi")
