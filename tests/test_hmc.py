"""Hybrid Monte Carlo with the splitting schemes (nambu_bch.numeric.hmc): exact checks of reversibility and volume,
statistical checks against known expectations, and the refusals.

Known values: under exp(-H) with H = p^2/2 + q^2/2, <q^2> = 1; with V = q^4/4, <q^2> = 2 Gamma(3/4)/Gamma(1/4)
(the moments of exp(-q^4/4)).  The estimates are deterministic (fixed seeds); the tolerance is five standard
errors of the estimate itself (the spread over groups of chains).
"""

import math
import pickle

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch.errors import InvalidCompositionError, InvalidRunError, NambuBCHError, ResourceLimitError
from nambu_bch.numeric import hybrid_monte_carlo, kernel

Q2_QUARTIC = 2 * math.gamma(0.75) / math.gamma(0.25)


@pytest.fixture(scope="module")
def triplet():
    """Lundstrum's generalized HMC in its simplest form: (q, p, r), H = V(q) + p^2/2 + r^2/2, G = r + q^2/2."""
    return nb.System(["q", "p", "r"], ["q**4/4 + p**2/2 + r**2/2", "r + q**2/2"])


def within(estimate, exact, bars=5):
    return abs(estimate.value - exact) <= bars * estimate.error


def test_oscillator_hmc_and_shadow_hmc_recover_the_exact_second_moment():
    plain = hybrid_monte_carlo("ho", "212", 1.0, 2, chains=400, iterations=30, seed=3)
    shadow = hybrid_monte_carlo("ho", "212", 1.0, 2, target="H_S", order=4, chains=400, iterations=30, seed=3)
    assert within(plain.expectation(lambda x: x[0] ** 2), 1.0)
    assert within(shadow.expectation(lambda x: x[0] ** 2), 1.0)
    # exp(-H_S) itself is a different density: its q-variance is 1/(1 - h^2/12 - h^4/120) at m = omega = 1
    raw = float((shadow.samples[:, 0] ** 2).mean())
    assert abs(raw - 1 / (1 - 1 / 12 - 1 / 120)) < 0.05 and abs(raw - 1) > 0.05
    assert shadow.acceptance > plain.acceptance  # H_S is conserved to O(h^6) here, H only to O(h^2)
    assert plain.refresh_acceptance == 1.0 and not plain.log_weights.any()


def test_nambu_triplet_samples_the_quartic_marginal(triplet):
    run = hybrid_monte_carlo(triplet, "12321", 0.5, 2, refresh=["p", "r"], flip=["p"], chains=1000, iterations=30,
                             seed=5)
    assert within(run.expectation(lambda x: x[0] ** 2), Q2_QUARTIC)
    assert within(run.expectation(lambda x: x[2] ** 2), 1.0) and within(run.expectation(lambda x: x[1] ** 2), 1.0)
    assert run.diverged == 0 and 0.5 < run.acceptance < 1


def test_flip_of_p_reverses_the_nambu_scheme_numerically(triplet):
    """R Phi_h R Phi_h = id with R the flip of p: the property the exact piece check certifies, seen on floats."""
    kern = kernel(triplet, "12321")
    K = kern.constants(0.3)
    X = np.random.default_rng(0).standard_normal((3, 50))
    Y = X.copy()
    out = np.empty((2, 3, 50))
    R = np.array([1.0, -1.0, 1.0])[:, None]
    kern.run_batch(Y, K, 5, 5, out, backend="numpy")
    Y *= R
    kern.run_batch(Y, K, 5, 5, out, backend="numpy")
    np.testing.assert_allclose(Y * R, X, rtol=0, atol=1e-12)
    Z = X.copy()  # flipping r as well does not reverse the scheme
    kern.run_batch(Z, K, 5, 5, out, backend="numpy")
    Z *= -np.abs(R)
    Z[0] *= -1
    kern.run_batch(Z, K, 5, 5, out, backend="numpy")
    Z[1:] *= -1
    assert np.abs(Z - X).max() > 1e-3


def test_the_refusals_name_what_is_wrong(triplet):
    with pytest.raises(InvalidCompositionError, match="does not reverse piece 2"):
        hybrid_monte_carlo(triplet, "12321", 0.5, 2, refresh=["p", "r"], flip=["p", "r"])
    with pytest.raises(InvalidRunError, match="cannot be drawn"):
        hybrid_monte_carlo(triplet, "12321", 0.5, 2, refresh=["q"], flip=["p"])
    with pytest.raises(InvalidRunError, match="only canonical systems have momenta"):
        hybrid_monte_carlo(triplet, "12321", 0.5, 2)
    with pytest.raises(InvalidCompositionError, match="palindromic"):
        hybrid_monte_carlo("ho", "12", 0.5, 2)
    with pytest.raises(InvalidRunError, match="names coordinates"):
        hybrid_monte_carlo("ho", "212", 0.5, 2, refresh=["z"])
    with pytest.raises(InvalidRunError, match="target"):
        hybrid_monte_carlo("ho", "212", 0.5, 2, target="G")
    with pytest.raises(InvalidCompositionError, match="does not reverse piece 1"):  # q' = p is odd under q, p -> -q, -p
        hybrid_monte_carlo("ho", "212", 0.5, 2, flip=["x1", "x2"])
    with pytest.raises(ResourceLimitError):
        hybrid_monte_carlo("ho", "212", 0.5, 2, chains=10**6, iterations=100)


def test_results_are_reproducible_values_that_pickle():
    a = hybrid_monte_carlo("ho", "212", 0.8, 3, chains=50, iterations=4, seed=11)
    b = hybrid_monte_carlo("ho", "212", 0.8, 3, chains=50, iterations=4, seed=11)
    assert a == b and pickle.loads(pickle.dumps(a)) == a
    d = a.to_dict()
    assert d["kind"] == "hybrid_monte_carlo" and "samples" not in d and len(a.to_dict(samples=True)["samples"]) == 4
    assert "acceptance" in str(a)
    assert issubclass(InvalidRunError, NambuBCHError)


def test_an_expectation_beyond_float64_is_refused():
    from nambu_bch.errors import NumericalRangeError

    run = hybrid_monte_carlo("ho", "212", 0.5, 2, chains=20, iterations=2, seed=0)
    with pytest.raises(NumericalRangeError, match="not finite"):
        run.expectation(lambda x: 1e308 + 0 * x[0])  # finite values whose sum overflows
