"""Stability of the numeric backend at the extremes.

h -> 0, omega h -> 2, omega h >= 2, 10^5-step runs, huge and tiny amplitudes, non-finite input.
Every failure must be a clear NambuBCHError subclass, never a silent NaN.
References: Horikoshi, Sect. 5.5 and Table (table) (H_c of 32123); Hairer, Lubich, Wanner, Sect. I.5.
"""

from __future__ import annotations

import numpy as np
import pytest

from nambu_bch.errors import NumericalRangeError, UnstableStepError
from nambu_bch.numeric import iterate, sample_times
from nambu_bch.numeric.diagnostics import drift_rate

X0 = [1.0, 1.0, 1.0]


def H(x):
    """Eq. (H) with m = omega = 1."""
    return x[..., 1] ** 2 / 2 + x[..., 2] / 2


def Hc(x, h, m=1.0, omega=1.0):
    """H_c of Phi^{32123}, Table (table): H + m omega^4 h^2 x1^2 / 8."""
    return x[..., 1] ** 2 / (2 * m) + m * omega**2 * x[..., 2] / 2 + m * omega**4 * h**2 * x[..., 0] ** 2 / 8


def Gc(x, h, omega=1.0):
    """G_c of Phi^{32123}, Table (table): G + omega^2 h^2 x1^2 / 2."""
    return x[..., 2] - x[..., 0] ** 2 + omega**2 * h**2 * x[..., 0] ** 2 / 2


# -- h -> 0 ----------------------------------------------------------------------------------------------------


def test_tiny_step_follows_the_vector_field():
    """h = 1e-8: after n steps x = x0 + n h X(x0) + O((n h)^2), X = (x2, -x1, 2 x1 x2) (Eq. NambuOHeqs)."""
    h, n = 1e-8, 10_000
    x = iterate("ho3", "32123", h, n, X0, every=n, kahan=True)[-1]
    t = n * h
    expected = np.array([1 + t, 1 - t, 1 + 2 * t])
    assert np.allclose(x, expected, rtol=0, atol=2 * t**2)
    assert abs(H(x) - H(np.array(X0))) < 2 * t**2 + 1e-15


def test_tiny_step_keeps_invariants_at_round_off():
    """Plain float64 loses up to ~eps/2 per addition of a 1e-8 increment (a drift <= n eps);
    compensated summation keeps H_c, G_c at a few eps."""
    h, n = 1e-8, 10_000
    eps = np.finfo(float).eps
    plain = iterate("ho3", "32123", h, n, X0, every=100)
    kahan = iterate("ho3", "32123", h, n, X0, every=100, kahan=True)
    for x, bound in ((plain, 4 * n * eps), (kahan, 8 * eps)):
        assert np.max(np.abs(Hc(x, h) - Hc(x[0], h))) < bound
        assert np.max(np.abs(Gc(x, h) - Gc(x[0], h))) < bound


# -- omega h -> 2 -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("omega_h", [1.9, 1.99, 1.999])
def test_close_to_the_stability_limit(omega_h):
    """Still stable: the iterates stay bounded and H_c is conserved relative to the amplitude."""
    x = iterate("ho3", "32123", omega_h, 20_000, X0, every=10)
    assert np.all(np.isfinite(x))
    scale = np.max(np.abs(x))
    assert scale < 1e6
    dHc = np.max(np.abs(Hc(x, omega_h) - Hc(x[0], omega_h)))
    assert dHc < 1e-13 * max(1.0, scale**2) * 20_000 ** 0.5


@pytest.mark.parametrize("name,word", [("ho", "TVT"), ("ho", "VTV"), ("ho3", "32123"), ("ho3", "12321"),
                                       ("ho3", "31213"), ("ho3-composite", "121")])
@pytest.mark.parametrize("omega_h", [2.0, 2.0000001, 2.5, 10.0, -2.0])
def test_unstable_steps_are_reported(name, word, omega_h):
    x0 = [1.0, 1.0] if name == "ho" else X0
    with pytest.raises(UnstableStepError, match="stability interval"):
        iterate(name, word, omega_h, 10, x0)


def test_stability_uses_the_parameters():
    iterate("ho3", "32123", 0.9, 10, X0, params={"omega": 2.0})              # omega h = 1.8
    with pytest.raises(UnstableStepError, match="omega\\*h = 2"):
        iterate("ho3", "32123", 1.0, 10, X0, params={"omega": 2.0})         # omega h = 2
    with pytest.raises(UnstableStepError):
        iterate("ho", "TVT", 1.5, 10, [1.0, 0.0], params={"omega": 2.0, "m": 3.0})


def test_unstable_run_without_the_guard_overflows_clearly():
    """With the guard off, omega h = 2.5 grows like 4^n and must end in NumericalRangeError, not NaN (one state and
    a batch)."""
    with pytest.raises(NumericalRangeError, match="between steps"):
        iterate("ho", "TVT", 2.5, 2000, [1.0, 0.0], every=50, check_stable=False)
    with pytest.raises(NumericalRangeError, match="overflow"):
        iterate("ho", "TVT", 2.5, 2000, [1.0, 0.0], check_stable=False, backend="numpy")
    # a batch: ho3/32123's batch loop at omega h = 2.5 (the same growth), the one the fast tier compiles for its
    # batch tests anyway (tests/conftest.py LONG); ho/TVT's batch loop would be a compile of its own (2.3 s cold)
    with pytest.raises(NumericalRangeError):
        iterate("ho3", "32123", 2.5, 2000, np.ones((3, 5)), every=100, check_stable=False)


# -- long runs -----------------------------------------------------------------------------------------------------


def test_long_run_has_no_secular_drift():
    """10^5 steps of Phi^{32123}, h = 0.1 (Figs. 1-2): H oscillates with amplitude ~ h^2/8, H_c stays at round-off."""
    h, n = 0.1, 100_000
    x = iterate("ho3", "32123", h, n, X0, every=10)
    t = sample_times(h, n, 10)
    dH = H(x) - H(x[0])
    dHc = Hc(x, h) - Hc(x[0], h)
    dGc = Gc(x, h) - Gc(x[0], h)
    assert 1.0e-3 < np.max(np.abs(dH)) < 1.4e-3
    assert np.max(np.abs(dHc)) < 1e-12 and np.max(np.abs(dGc)) < 1e-12
    fit = drift_rate(t, dH)
    assert abs(fit.drift) < 1e-5                      # no secular growth of the oscillating error
    assert abs(drift_rate(t, dHc).drift) < 1e-12


def test_long_batch_run():
    X = np.stack([np.linspace(0.5, 1.5, 50), np.linspace(-1, 1, 50), np.linspace(0, 2, 50)])
    x = iterate("ho3", "32123", 0.1, 100_000, X, every=10_000)
    assert x.shape == (11, 3, 50)
    drift = Hc(np.moveaxis(x, 1, -1), 0.1) - Hc(np.moveaxis(x[:1], 1, -1), 0.1)
    assert np.max(np.abs(drift)) < 1e-12


# -- amplitudes -------------------------------------------------------------------------------------------------------


def test_large_amplitude_within_range_scales_exactly():
    """The oscillator is linear in (x1, x2) and quadratic in x3: scaling by 2^k is exact in binary."""
    s = 2.0**450
    small = iterate("ho3", "32123", 0.1, 1000, [1.0, 1.0, 1.0], every=100)
    big = iterate("ho3", "32123", 0.1, 1000, [s, s, s * s], every=100)
    assert np.array_equal(big[:, :2], small[:, :2] * s)
    assert np.array_equal(big[:, 2], small[:, 2] * s * s)


@pytest.mark.parametrize("x0", [[1e200, 1e200, 1.0], [1e300, 1e10, 0.0], [1.0, 1e308, 1.0]])
def test_overflow_is_reported_before_the_run(x0):
    with pytest.raises(NumericalRangeError, match="overflows float64"):
        iterate("ho3", "32123", 0.1, 10, x0)


def test_overflow_in_exponential_flows():
    with pytest.raises(NumericalRangeError, match="overflows"):
        iterate("lotka-volterra", "12321", 0.1, 10, [1e4, 1.0, 1.0])


def test_tiny_amplitude_within_range_scales_exactly():
    s = 2.0**-500
    small = iterate("ho3", "32123", 0.1, 1000, [1.0, 1.0, 1.0], every=100)
    tiny = iterate("ho3", "32123", 0.1, 1000, [s, s, s * s * 2.0**200], every=100)
    assert np.array_equal(tiny[:, :2], small[:, :2] * s)


@pytest.mark.parametrize("x0", [[1e-200, 1e-200, 0.0], [1e-170, 1e-170, 0.0]])
def test_underflow_is_reported(x0):
    with pytest.raises(NumericalRangeError, match="underflows"):
        iterate("ho3", "32123", 0.1, 10, x0)


def test_subnormal_input_is_reported():
    with pytest.raises(NumericalRangeError, match="underflows"):
        iterate("ho3", "32123", 0.1, 10, [1e-310, 1.0, 1.0])


def test_mpmath_handles_what_float64_cannot():
    x = iterate("ho3", "32123", 0.1, 100, ["1e200", "1e200", "1"], every=100, dps=30)
    assert float(x[-1, 0] / 10**200) == pytest.approx(
        iterate("ho3", "32123", 0.1, 100, [1.0, 1.0, 0.0], every=100)[-1, 0], rel=1e-12)


# -- non-finite input ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs", [
    {"h": float("nan")}, {"h": float("inf")}, {"h": -float("inf")},
    {"x0": [float("nan"), 1.0, 1.0]}, {"x0": [1.0, float("inf"), 1.0]},
    {"x0": np.array([[1.0, np.nan], [1.0, 1.0], [1.0, 1.0]])},
    {"params": {"omega": float("nan")}}, {"params": {"m": float("inf")}},
])
def test_non_finite_inputs_are_rejected(kwargs):
    args = {"system": "ho3", "word": "32123", "h": 0.1, "steps": 10, "x0": X0}
    args.update(kwargs)
    with pytest.raises(NumericalRangeError, match="not finite|non-finite"):
        iterate(**args)


def test_step_whose_coefficients_overflow():
    with pytest.raises((NumericalRangeError, UnstableStepError)):
        iterate("ho3", "32123", 1e200, 10, X0, params={"omega": 1e150})
