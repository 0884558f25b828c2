"""The numerical shadow Hamiltonian of Skeel and Hardy (:func:`nambu_bch.numeric.numerical_shadow`).

Tier 3 (numerical), Skeel and Hardy, SIAM J. Sci. Comput. 23 (2001) 1172; Engle, Skeel and Drees,
J. Comput. Phys. 206 (2005) 432: the estimate of order 2k agrees with the package's symbolic shadow
Hamiltonian truncated after h^2 up to O(h^4); along a run it fluctuates like h^{2k}; it is conserved
exactly for a quadratic Hamiltonian; a trajectory from a hand-written numpy loop, given with its forces and
potential energies, gives the same values as the system's own run.
"""

from __future__ import annotations

import json
import pickle
from fractions import Fraction

import numpy as np
import pytest

import nambu_bch as nb
from nambu_bch.cli import main
from nambu_bch.errors import InvalidOrderError, InvalidRunError, InvalidSystemError, NumericalRangeError
from nambu_bch.numeric import NumericalShadow, fit_order, numerical_shadow
from nambu_bch.numeric.skeel_hardy import stencil

HH0 = (0.1, -0.2, 0.3, 0.25)  # Henon-Heiles, energy ~0.09: a regular orbit well inside the escape energy 1/6


def _hh_force(q):
    x, y = q[..., 0], q[..., 1]
    return -np.stack([x + 2 * x * y, y + x * x - y * y], axis=-1)


def _hh_potential(q):
    x, y = q[..., 0], q[..., 1]
    return (x * x + y * y) / 2 + x * x * y - y ** 3 / 3


def _numpy_verlet(h, steps, q0, p0):
    """Velocity Verlet for Henon-Heiles written out by hand (no package code): positions, momenta, forces."""
    q, p = np.array(q0, dtype=float), np.array(p0, dtype=float)
    f = _hh_force(q)
    Q, P, F = [q], [p], [f]
    for _ in range(steps):
        p = p + h / 2 * f
        q = q + h * p
        f = _hh_force(q)
        p = p + h / 2 * f
        Q.append(q), P.append(p), F.append(f)
    return np.array(Q), np.array(P), np.array(F)


def _split(x):
    d = x.shape[1] // 2
    return x[:, :d], x[:, d:]


def test_stencil_is_the_centred_derivative_of_fornberg_table_1():
    # Fornberg, Math. Comp. 51 (1988) 699, Table 1, first derivative, centred, orders 2, 4, 6, 8
    assert stencil(1) == (Fraction(1, 2),)
    assert stencil(2) == (Fraction(2, 3), Fraction(-1, 12))
    assert stencil(3) == (Fraction(3, 4), Fraction(-3, 20), Fraction(1, 60))
    assert stencil(4) == (Fraction(4, 5), Fraction(-1, 5), Fraction(4, 105), Fraction(-1, 280))


@pytest.mark.parametrize("model, x0", [("ho", (1.0, 0.5)), ("henon-heiles", HH0)])
def test_order_4_agrees_with_the_symbolic_shadow_hamiltonian_to_h4(model, x0):
    """H~_4 - H_S^[2] (symbolic, truncated after h^2) is O(h^4): its spread and its mean along the run."""
    hs, spread, offset = [0.2, 0.1, 0.05], [], []
    for h in hs:
        x = nb.iterate(model, "212", h, round(10 / h), x0)
        r = numerical_shadow(*_split(x), model, h, order=4)
        s = nb.shadow_along(model, "212", x, h, order=2, which=["H_S"])
        diff = r.values - s.values["H_S"][r.indices]
        spread.append(np.ptp(diff))
        offset.append(abs(diff.mean()))
    assert abs(fit_order(hs, spread, "spread").order - 4) < 0.3, spread
    assert abs(fit_order(hs, offset, "offset").order - 4) < 0.3, offset


@pytest.fixture(scope="module")
def hh_runs():
    """Henon-Heiles velocity Verlet runs over t = 20 at h = 0.2, 0.1, 0.05."""
    return {h: nb.iterate("henon-heiles", "212", h, round(20 / h), HH0) for h in (0.2, 0.1, 0.05)}


@pytest.mark.parametrize("order", [2, 4, 6, 8])
def test_fluctuation_falls_like_h_to_the_order(hh_runs, order):
    """max - min of H~_{2k} along the run ~ h^{2k} (order 8: 2.5e-7, 1.2e-9, 5e-12, still well above rounding)."""
    hs = (0.2, 0.1, 0.05)
    spreads = [np.ptp(numerical_shadow(*_split(hh_runs[h]), "henon-heiles", h, order=order).values) for h in hs]
    slope = fit_order(hs, spreads, f"H~_{order}").order
    assert abs(slope - order) < 0.35, (spreads, slope)


def test_quadratic_hamiltonian_is_conserved_to_rounding():
    """For the oscillator the samples are M^n y_0 and H~_{2k} is a quadratic form invariant under M."""
    x = nb.iterate("ho", "212", 0.5, 2000, [1.0, 0.0], {"omega": 1.3, "m": 0.7})
    for order in (2, 4, 8):
        r = numerical_shadow(*_split(x), "ho", 0.5, order=order, params={"omega": 1.3, "m": 0.7})
        assert r.max_abs_error["H~"] < 1e-12 and r.max_abs_error["H"] > 1e-2


def test_exact_modified_hamiltonian_of_the_oscillator_is_approached():
    """Velocity Verlet on q'' = -q is the time-h flow of H~ = c(h) (p^2 / (1 - h^2/4) + q^2) / 2 with
    c = theta sqrt(1 - h^2/4) / h, cos theta = 1 - h^2/2 (the step matrix has eigenvalues e^{+-i theta}, and it
    conserves the quadratic form in brackets; Hairer, Lubich, Wanner, Sect. I.5); H~_{2k} differs from it by
    O(h^{2k})."""
    for order in (2, 4, 6):
        hs, err = [0.4, 0.2, 0.1], []
        for h in hs:
            x = nb.iterate("ho", "212", h, round(10 / h), [1.0, 0.0])
            r = numerical_shadow(*_split(x), "ho", h, order=order)
            q, p = x[r.indices, 0], x[r.indices, 1]
            c = np.arccos(1 - h * h / 2) * np.sqrt(1 - h * h / 4) / h
            err.append(np.max(np.abs(r.values - c * (p ** 2 / (1 - h * h / 4) + q ** 2) / 2)))
        assert abs(fit_order(hs, err, "H~_2k - H~").order - order) < 0.3, (order, err)


def test_outside_trajectory_with_forces_gives_the_same_values():
    """A numpy Verlet loop given with its forces and V(q_n) = the package's own run, evaluated from the system."""
    h, steps = 0.1, 300
    Q, P, F = _numpy_verlet(h, steps, HH0[:2], HH0[2:])
    from_arrays = numerical_shadow(Q, P, F, h, order=6, potential=_hh_potential(Q))
    from_system = numerical_shadow(Q, P, "henon-heiles", h, order=6)
    x = nb.iterate("henon-heiles", "212", h, steps, HH0)
    own = numerical_shadow(*_split(x), "henon-heiles", h, order=6)
    assert np.array_equal(from_arrays.indices, own.indices) and from_arrays.model == "arrays"
    assert np.max(np.abs(from_arrays.values - from_system.values)) < 1e-13
    assert np.max(np.abs(from_arrays.values - own.values)) < 1e-12
    assert from_arrays.H is None and from_system.H is not None


def test_other_words_and_a_dropped_constant():
    """Position Verlet (121) and a fourth-order triple jump on the Morse oscillator, whose splitting leaves out
    the constant 1 of V = (1 - e^{-q})^2: H~ tracks H to O(h^2) resp. O(h^4) in value, not only in spread
    (for the triple jump H~ = H + O(h^4), so only an estimate of order > 4 separates the two)."""
    for word, h, order, bound in (("121", 0.05, 4, 5e-3), ("triple-jump:121", 0.05, 8, 5e-5)):
        x = nb.iterate("morse", word, h, 400, [0.5, 0.2])
        r = numerical_shadow(*_split(x), "morse", h, order=order, word=word)
        assert np.max(np.abs(r.values - r.H)) < bound, (word, np.max(np.abs(r.values - r.H)))
        assert r.max_abs_error["H~"] < 1e-2 * r.max_abs_error["H"]


def test_a_non_symmetric_word():
    """Symplectic Euler (12) has a modified Hamiltonian with odd powers of h; H fluctuates by O(h), the estimate of
    order 4 by O(h^4): on the pendulum at h = 0.1, 0.05: 1.0e-2, 5.5e-3 against 5.7e-7, 3.7e-8."""
    hs, spread = [0.1, 0.05], []
    for h in hs:
        x = nb.iterate("pendulum", "12", h, 400, [0.5, 0.2])
        r = numerical_shadow(*_split(x), "pendulum", h, word="12")
        assert r.max_abs_error["H~"] < 1e-3 * r.max_abs_error["H"]
        spread.append(r.max_abs_error["H~"])
    assert abs(fit_order(hs, spread, "H~_4").order - 4) < 0.3, spread


def test_result_travels():
    x = nb.iterate("henon-heiles", "212", 0.1, 50, HH0)
    r = numerical_shadow(*_split(x), "henon-heiles", 0.1, order=8)
    assert isinstance(r, NumericalShadow) and (r.indices[0], r.indices[-1]) == (4, 46)
    d = json.loads(json.dumps(r.to_dict(values=True)))
    assert {"order", "first_index", "last_index", "max_abs_error", "drift_rate", "drift", "values", "H"} <= set(d)
    assert d["order"] == 8 and len(d["values"]) == 43
    assert "Skeel-Hardy" in str(r)
    back = pickle.loads(pickle.dumps(r))
    assert np.array_equal(back.values, r.values) and back.drift["H~"] == r.drift["H~"]


def test_refusals_are_one_line():
    x = nb.iterate("henon-heiles", "212", 0.1, 40, HH0)
    q, p = _split(x)
    F, U = _hh_force(q), _hh_potential(q)
    cases = [
        (lambda: numerical_shadow(q, p, "ho3", 0.1), InvalidSystemError, "canonical"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.1, order=5), InvalidOrderError, "order"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.1, order=True), InvalidOrderError, "order"),
        (lambda: numerical_shadow(q, p[:, :1], "henon-heiles", 0.1), InvalidRunError, "same shape"),
        (lambda: numerical_shadow(q[:6], p[:6], "henon-heiles", 0.1), InvalidRunError, "at least 7"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.0), InvalidRunError, "non-zero"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.2), InvalidRunError, "not one step"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.1, word="121"), InvalidRunError, "not one step"),
        (lambda: numerical_shadow(q[::2], p[::2], "henon-heiles", 0.2), InvalidRunError, "every = 1"),
        (lambda: numerical_shadow(q, p, F, 0.1), InvalidRunError, "potential"),
        (lambda: numerical_shadow(q, p, F, 0.1, potential=U, word="121"), InvalidRunError, "velocity Verlet"),
        (lambda: numerical_shadow(q, p, F[:, :1], 0.1, potential=U), InvalidRunError, "shape of q"),
        (lambda: numerical_shadow(q, p, -F, 0.1, potential=U), InvalidRunError, "not one step"),
        (lambda: numerical_shadow(q, p, F, 0.1, potential=U[:-1]), InvalidRunError, "potential"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.1, potential=U), InvalidRunError, "potential"),
        (lambda: numerical_shadow(np.where(q > 0, np.nan, q), p, "henon-heiles", 0.1), NumericalRangeError, "q"),
        (lambda: numerical_shadow(q, p, "henon-heiles", 0.1, check_steps="no"), InvalidRunError, "check_steps"),
        (lambda: numerical_shadow("q", p, "henon-heiles", 0.1), InvalidRunError, "q"),
    ]
    for call, error, word in cases:
        with pytest.raises(error) as info:
            call()
        assert "\n" not in str(info.value) and word in str(info.value), str(info.value)
    # the step check can be switched off (a trajectory saved with less precision, say)
    assert numerical_shadow(q, p, "henon-heiles", 0.1, word="121", check_steps=False).values.size == 37


def test_one_dimensional_arrays_are_one_degree_of_freedom():
    x = nb.iterate("pendulum", "212", 0.1, 60, [0.5, 0.0])
    r = numerical_shadow(x[:, 0], x[:, 1], "pendulum", 0.1)
    assert r.values.size == 57 and r.max_abs_error["H~"] < 1e-2 * r.max_abs_error["H"]


def test_cli_check_adds_the_numerical_shadow_in_a_subprocess(cli_run, tmp_path):
    done = cli_run("check", "--model", "ho", "--integrator", "212", "--x0", "1,0", "--steps", "200",
                   "--numerical-shadow", "6", "--format", "json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    shadow = data["numerical_shadow"]
    assert (shadow["order"], shadow["first_index"], shadow["last_index"], shadow["n_values"]) == (6, 3, 197, 195)
    assert shadow["max_abs_error"]["H~"] < 1e-12 < 1e-4 < shadow["max_abs_error"]["H"]  # quadratic: conserved
    assert set(shadow["drift"]["H~"]) == {"rate", "stderr", "intercept", "span", "drift"}
    assert data["max_abs_error"]["H"] > 0  # the check report is unchanged around the new key


@pytest.mark.parametrize("argv, word", [
    (("--numerical-shadow", "5"), "one of 2, 4, 6, 8"),
    (("--numerical-shadow", "4", "--every", "2"), "every step"),
    (("--numerical-shadow", "4", "--model", "ho3", "--x0", "1,1,1"), "canonical"),
    (("--numerical-shadow", "4", "--steps", "5"), "at least 6 steps"),
])
def test_cli_refusals_are_one_line_and_status_2(argv, word, capsys):
    base = ("check",) if "--model" in argv else ("check", "--model", "henon-heiles", "--integrator", "212", "--x0",
                                                  "0.1,-0.2,0.3,0.25")
    argv = base + argv
    assert main(list(argv)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and word in err and "Traceback" not in err, err
