"""Exact shadow Hamiltonians: Eqs. (Xeff1), (SHPV2), (Xeff2), (ESH12321), (ESG12321), Table (table), and their
consistency with the BCH alpha-family, Eqs. (SH12321c), (SG12321c), to h^2 and h^4.

Horikoshi, *Shadow Hamiltonians of structure-preserving integrators for Nambu mechanics*.
"""

from __future__ import annotations

import pytest
import sympy

from nambu_bch import PAPER_WORDS, System, liouville_field, model
from nambu_bch.bch import effective_field
from nambu_bch.errors import NambuBCHError, NoExactResultError
from nambu_bch.exact import F, exact_shadow_hamiltonians
from nambu_bch.exact.exact_shadow import truncate_h

x1, x2, x3, m, omega, h, alpha = sympy.symbols("x1 x2 x3 m omega h alpha")
H = x2**2 / (2 * m) + m * omega**2 * x3 / 2  # Eq. (H)
G = x3 - x1**2  # Eq. (G)
ORDER = 8


def _hseries_coeff(expr, j):
    return sympy.expand(expr).coeff(h, j)


def _field_of_series(system, hams, order):
    """X_{H_S, G_S} of truncated series, truncated at h^order (alpha kept symbolic)."""
    algebra = system.algebra.with_constants(alpha)
    return [truncate_h(c, order) for c in liouville_field(algebra, *hams).to_sympy()]


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_alpha_family_reproduces_X_eff_to_h8(word):
    """Eq. (Xeff2): X_{F^alpha H_c, F^(1-alpha) G_c} = X_eff, order by order to h^8, for every alpha."""
    ho3 = model("ho3")
    ex = exact_shadow_hamiltonians(ho3, word)
    HS, GS = ex.series(ORDER)
    X = _field_of_series(ho3, (HS, GS), ORDER)
    Z = effective_field(ho3.splitting, word, ORDER)
    for j in range(ORDER + 1):
        for got, want in zip(X, Z[j].to_sympy()):
            assert sympy.expand(_hseries_coeff(got, j) - want) == 0, (word, j)
    assert ex.verified_order >= ORDER


@pytest.mark.parametrize("word", ["121", "212", "TVT", "VTV"])
def test_ho_SHPV2(word):
    """Eqs. (Xeff1), (SHPV2): H_S^e = F(omega h) H_c reproduces X_eff of Verlet on the oscillator to h^8."""
    ho = model("ho")
    ex = exact_shadow_hamiltonians(ho, word)
    assert ex.G_S is None
    assert sympy.simplify(ex.H_S - F(omega * h) * ex.H_c) == 0
    HS, _ = ex.series(ORDER)
    X = [truncate_h(c, ORDER) for c in liouville_field(ho.algebra, HS).to_sympy()]
    Z = effective_field(ho.splitting, word, ORDER)
    for j in range(ORDER + 1):
        for got, want in zip(X, Z[j].to_sympy()):
            assert sympy.expand(_hseries_coeff(got, j) - want) == 0


def test_SHPV1_from_the_exact_form():
    """Eq. (SHPV1): the h^2 term of F(omega h) H_c is -omega^2 h^2 x2^2/(24m) + m omega^4 h^2 x1^2/12."""
    HS, _ = exact_shadow_hamiltonians(model("ho"), "121").series(3)
    H2 = x2**2 / (2 * m) + m * omega**2 * x1**2 / 2
    assert sympy.expand(HS - H2 - (-omega**2 * h**2 * x2**2 / (24 * m) + m * omega**4 * h**2 * x1**2 / 12)) == 0


def test_closed_forms_contain_F_exactly():
    ex = exact_shadow_hamiltonians(model("ho3"), "12321")
    Fx = F(omega * h)
    assert ex.factor == Fx
    assert sympy.simplify(ex.H_S - Fx**alpha * H) == 0
    assert sympy.simplify(ex.G_S - Fx ** (1 - alpha) * (G + h**2 * x2**2 / (4 * m**2))) == 0
    assert ex.H_S.has(sympy.asin(h * omega / 2)) and ex.H_S.has(alpha)
    assert r"\alpha" in ex.to_latex() and ex._repr_latex_().startswith("$")
    d = ex.to_dict()
    assert d["free_parameters"] == ["alpha"]
    assert sympy.simplify(sympy.sympify(d["H_S"], locals=model("ho3").symbols()) - ex.H_S) == 0


def test_ESH12321_ESG12321():
    """Eqs. (ESH12321), (ESG12321): the h^2 expansions of the exact alpha-family for Phi^12321."""
    HS, GS = exact_shadow_hamiltonians(model("ho3"), "12321").series(3)
    ESH = H + alpha * omega**2 * h**2 * x2**2 / (12 * m) + alpha * m * omega**4 * h**2 * x3 / 12
    ESG = (G + h**2 * x2**2 / (4 * m**2) + (1 - alpha) * omega**2 * h**2 * x3 / 6
           - (1 - alpha) * omega**2 * h**2 * x1**2 / 6)
    assert sympy.expand(HS - ESH) == 0
    assert sympy.expand(GS - ESG) == 0


def test_consistent_with_BCH_family_at_h2():
    """After Eq. (SG12321c): replacing x3 in the third term of Eq. (ESH12321) using G_S^e = const and x3 in
    Eq. (ESG12321) using H_S^e = const (constants dropped) gives the BCH family, Eqs. (SH12321c), (SG12321c)."""
    HS, GS = exact_shadow_hamiltonians(model("ho3"), "12321").series(2)
    H2, G2 = _hseries_coeff(HS, 2), _hseries_coeff(GS, 2)
    # to leading order: G = const  =>  x3 = x1^2 + const;   H = const  =>  x3 = -x2^2/(m^2 omega^2) + const
    H2_sub = sympy.expand(H2.subs(x3, x1**2))
    G2_sub = sympy.expand(G2.subs(x3, -x2**2 / (m**2 * omega**2)))
    SH = alpha * omega**2 * x2**2 / (12 * m) + alpha * m * omega**4 * x1**2 / 12  # Eq. (SH12321c)
    SG = x2**2 / (12 * m**2) + alpha * x2**2 / (6 * m**2) - (1 - alpha) * omega**2 * x1**2 / 6  # Eq. (SG12321c)
    assert sympy.expand(H2_sub - SH) == 0
    assert sympy.expand(G2_sub - SG) == 0
    # both are shadow Hamiltonians of the same X_eff to h^2
    ho3 = model("ho3")
    Xbch = _field_of_series(ho3, (H + h**2 * SH, G + h**2 * SG), 2)
    Xex = _field_of_series(ho3, (HS, GS), 2)
    assert all(sympy.expand(a - b) == 0 for a, b in zip(Xbch, Xex))


def test_order_four_shadow_equation():
    """The h^4 terms of the exact family solve the order-4 shadow equation
    X_{H_4, G_0} + X_{H_2, G_2} + X_{H_0, G_4} = Z_4 (and odd orders vanish), for every alpha."""
    ho3 = model("ho3")
    algebra = ho3.algebra.with_constants(alpha)
    HS, GS = exact_shadow_hamiltonians(ho3, "12321").series(4)
    Hj = [_hseries_coeff(HS, j) for j in range(5)]
    Gj = [_hseries_coeff(GS, j) for j in range(5)]
    assert Hj[1] == Hj[3] == Gj[1] == Gj[3] == 0
    total = None
    for a, b in ((4, 0), (2, 2), (0, 4)):
        X = liouville_field(algebra, Hj[a], Gj[b])
        total = X if total is None else total + X
    Z4 = effective_field(ho3.splitting, "12321", 4)[4]
    assert all(sympy.expand(a - b) == 0 for a, b in zip(total.to_sympy(), Z4.to_sympy()))


def _bch_family(word, order):
    from nambu_bch.shadow import shadow_hamiltonians

    fam = shadow_hamiltonians(model("ho3"), word, order=order)
    assert fam.exists
    return fam


@pytest.mark.parametrize("word,order", [(w, 2) for w in PAPER_WORDS] + [("12321", 4), ("32123", 4)])
def test_cross_check_with_bch_shadow_module(word, order):
    """nambu_bch.shadow.shadow_hamiltonians (the BCH family) and the exact family give the same field to h^order."""
    fam = _bch_family(word, order)
    ho3 = model("ho3")
    syms = sorted({s for e in (fam.H_S, fam.G_S) for s in sympy.sympify(e).free_symbols
                   if s not in (*ho3.coordinates, *ho3.parameters, h)}, key=str)
    algebra = ho3.algebra.with_constants(*syms)
    Xbch = [truncate_h(c, order) for c in liouville_field(algebra, fam.H_S, fam.G_S).to_sympy()]
    HS, GS = exact_shadow_hamiltonians(ho3, word).series(order)
    Xex = _field_of_series(ho3, (HS, GS), order)
    assert all(sympy.expand(a - b) == 0 for a, b in zip(Xbch, Xex))


def test_cross_check_x3_replacement_gives_the_bch_family():
    """The h^2 terms of the exact family after the x3 replacement (text after Eq. SG12321c) are the BCH family
    computed by nambu_bch.shadow, Eqs. (SH12321c), (SG12321c), with the same alpha."""
    fam = _bch_family("12321", 2)
    HS, GS = exact_shadow_hamiltonians(model("ho3"), "12321").series(2)
    H2 = sympy.expand(_hseries_coeff(HS, 2).subs(x3, x1**2))
    G2 = sympy.expand(_hseries_coeff(GS, 2).subs(x3, -x2**2 / (m**2 * omega**2)))
    assert sympy.expand(_hseries_coeff(fam.H_S, 2) - H2) == 0
    assert sympy.expand(_hseries_coeff(fam.G_S, 2) - G2) == 0


def test_user_defined_oscillator_without_omega_parameter():
    """m = 1, omega = 2 substituted: the frequency of the harmonic core plays the part of omega."""
    S = System("x1 x2 x3", ["x2**2/2 + 2*x3", "x3 - x1**2"], (), name="ho3-numeric")
    ex = exact_shadow_hamiltonians(S, "32123")
    assert ex.frequency == 2
    assert ex.factor == F(2 * h)


def test_composite_oscillator_is_verified_not_assumed():
    """The (q^2, p^2, qp) oscillator passes the same h^8 check with its own H_c, G_c."""
    ex = exact_shadow_hamiltonians(model("ho3-composite"), "121")
    assert ex.verified_order == 8


@pytest.mark.parametrize("name", ["rigid-body", "lotka-volterra"])
def test_no_exact_factor_form(name):
    with pytest.raises(NoExactResultError):
        exact_shadow_hamiltonians(model(name), "12321" if name == "rigid-body" else "121")


def test_bad_word():
    with pytest.raises(NambuBCHError):
        exact_shadow_hamiltonians(model("ho3"), "1234")
