"""Force-gradient pieces and processed kernels (nambu_bch.design.generalized).

Published values pinned here:
* Chin, Phys. Lett. A 226 (1997) 344, algorithm 4A: order 4 with B~ = B + (h^2/48)[B,[A,B]];
* Takahashi & Imada, J. Phys. Soc. Jpn. 53 (1984) 3765: the kernel A(1/2) B~ A(1/2), B~ = B + (h^2/24)[B,[A,B]],
  has effective order 4 with a processor (the processed kernel of Takahashi & Imada; Blanes, Casas & Ros,
  SIAM J. Sci. Comput. 21 (1999) 711, on processing).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from nambu_bch.design import error_analysis
from nambu_bch.design.generalized import effective_order, gradient_analysis, gradient_composition
from nambu_bch.errors import InvalidCompositionError, InvalidOrderError

R = sympy.Rational


@pytest.mark.parametrize("spec", ["121", "212", "forest-ruth", "1:1/3,2:1/2,1:2/3,2:1/2"])
def test_series_engine_agrees_with_the_lyndon_defects(spec):
    """Plain compositions: the word-series log gives the LEM of error_analysis exactly (two independent routes)."""
    G, E = gradient_analysis(spec), error_analysis(spec, 2)
    assert G.order == E.order and sympy.simplify(G.squared - E.squared) == 0


def test_chin_4a_is_fourth_order_and_only_with_its_gradient_term():
    assert gradient_analysis("chin-4a").order == 4
    plain = [(2, R(1, 6)), (1, R(1, 2)), (2, R(2, 3)), (1, R(1, 2)), (2, R(1, 6))]
    assert gradient_analysis(plain).order == 2
    wrong_sign = [(2, R(1, 6)), (1, R(1, 2)), (2, R(2, 3), R(-1, 72)), (1, R(1, 2)), (2, R(1, 6))]
    assert gradient_analysis(wrong_sign).order == 2
    rkn = gradient_analysis("chin-4a", structure="rkn")
    assert rkn.order == 4 and rkn.value < gradient_analysis("chin-4a").value


def test_gradient_sign_on_the_harmonic_oscillator():
    """Numerically, for H = p^2/2 + q^2/2: the middle kick of the modified potential V - (h^2/48)|V'|^2 (c = +1/72 in
    the package's convention) gives a local error O(h^5); V + (h^2/48)|V'|^2 gives O(h^3)."""
    def step(h, s):
        kick = lambda k: np.array([[1.0, 0.0], [-k, 1.0]])
        drift = np.array([[1.0, h / 2], [0.0, 1.0]])
        return kick(h / 6) @ drift @ kick(2 * h / 3 * (1 + s * h * h / 24)) @ drift @ kick(h / 6)

    def rate(s):
        errors = []
        for h in (0.1, 0.05):
            exact = np.array([[np.cos(h), np.sin(h)], [-np.sin(h), np.cos(h)]])
            errors.append(np.abs(step(h, s) - exact).max())
        return np.log2(errors[0] / errors[1])

    assert rate(-1) == pytest.approx(5, abs=0.1) and rate(+1) == pytest.approx(3, abs=0.1)


def test_takahashi_imada_kernel_has_effective_order_four():
    e = effective_order("takahashi-imada")
    assert e.order == 4 and e.processor[2] == [R(-1, 24)]   # Z_2 = -(1/24)[A, B]
    assert gradient_analysis("takahashi-imada").order == 2    # unprocessed: second order
    assert effective_order([(1, R(1, 2)), (2, 1), (1, R(1, 2))]).order == 2   # without the gradient term


def test_processing_never_lowers_the_order():
    for spec in ("121", "forest-ruth"):
        assert effective_order(spec).order >= error_analysis(spec, 2).order


def test_gradient_composition_refuses_bad_input():
    with pytest.raises(InvalidCompositionError, match="goes with piece 2"):
        gradient_composition([(1, 1, R(1, 24)), (2, 1)])
    with pytest.raises(InvalidCompositionError, match="sum to"):
        gradient_composition([(1, R(1, 2)), (2, 1)])
    with pytest.raises(InvalidCompositionError, match="piece 1 or 2"):
        gradient_composition([(3, 1)])
    with pytest.raises(InvalidOrderError, match="max_degree"):
        gradient_analysis("121", max_degree=30)
    with pytest.raises(InvalidCompositionError, match="exact coefficients"):
        effective_order("blanes-moan")
