"""Shadow Hamiltonians along a trajectory (:func:`nambu_bch.shadow_along`).

Tier 3 (numerical): the deviation of the truncated shadow pair of order k along a run of the
second-order symmetric scheme 12321 shrinks like h^{k+2} (Hairer, Lubich, Wanner, Sect. IX.8;
Horikoshi, Sect. 5.5); a trajectory computed by an independent numpy loop gives the same values.
"""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

import nambu_bch as nb
from nambu_bch.errors import InvalidRunError, NambuBCHError, NumericalRangeError
from nambu_bch.numeric import fit_order, sample_times

RIGID = {"I1": 1.0, "I2": 2.0, "I3": 3.0}


def _shears(model, params):
    """The exact sub-flows of the full split, written by hand: piece i adds t * f_i(other coordinates) to x_i."""
    if model == "ho3":  # Eqs. hX1e-hX3e with m = omega = 1
        return [lambda x, t: (x[0] + t * x[1], x[1], x[2]),
                lambda x, t: (x[0], x[1] - t * x[0], x[2]),
                lambda x, t: (x[0], x[1], x[2] + t * 2 * x[0] * x[1])]
    I1, I2, I3 = params["I1"], params["I2"], params["I3"]
    return [lambda x, t: (x[0] + t * x[1] * x[2] * (I3 - I2) / (I2 * I3), x[1], x[2]),
            lambda x, t: (x[0], x[1] + t * x[0] * x[2] * (I1 - I3) / (I1 * I3), x[2]),
            lambda x, t: (x[0], x[1], x[2] + t * x[0] * x[1] * (I2 - I1) / (I1 * I2))]


def _hand_loop(model, h, steps, x0, params=None):
    """The symmetric scheme 12321 (half steps of 1 and 2, a full step of 3) as a plain Python loop."""
    f1, f2, f3 = _shears(model, params)
    x = tuple(float(v) for v in x0)
    out = [x]
    for _ in range(steps):
        x = f1(f2(f3(f2(f1(x, h / 2), h / 2), h), h / 2), h / 2)
        out.append(x)
    return np.array(out)


@pytest.mark.parametrize("model, params, order, x0", [
    ("ho3", None, 2, (1.0, 1.0, 1.0)),
    ("ho3", None, 4, (1.0, 1.0, 1.0)),
    ("rigid-body", RIGID, 2, (1.0, 0.5, 0.2)),
])
def test_shadow_deviation_shrinks_like_h_to_the_order_plus_two(model, params, order, x0):
    hs, dev = [0.2, 0.1, 0.05], {"H_S": [], "G_S": []}
    for h in hs:
        x = nb.iterate(model, "12321", h, round(10 / h), x0, params)
        r = nb.shadow_along(model, "12321", x, h, order=order, params=params)
        for q in dev:
            dev[q].append(r.max_abs_error[q])
    for q, errors in dev.items():
        slope = fit_order(hs, errors, q).order
        assert abs(slope - (order + 2)) < 0.3, (q, errors, slope)


@pytest.mark.parametrize("model, params", [("ho3", None), ("rigid-body", RIGID)])
def test_a_trajectory_from_another_code_gives_the_same_values(model, params):
    h, steps, x0 = 0.1, 300, (1.0, 0.5, 0.2)
    ours = nb.iterate(model, "12321", h, steps, x0, params)
    theirs = _hand_loop(model, h, steps, x0, params)
    np.testing.assert_allclose(theirs, ours, rtol=1e-12, atol=1e-12)  # the same method, rounded differently
    a = nb.shadow_along(model, "12321", ours, h, params=params)
    b = nb.shadow_along(model, "12321", theirs, h, params=params)
    assert sorted(a.values) == sorted(b.values) == ["G", "G_S", "H", "H_S"]
    for q in a.values:
        np.testing.assert_allclose(b.values[q], a.values[q], rtol=1e-12, atol=1e-12)
        assert b.max_abs_error[q] == pytest.approx(a.max_abs_error[q], rel=1e-6, abs=1e-13)
    # the values are those of the symbolic pair itself, evaluated point by point
    fam = nb.shadow_hamiltonians(nb.model(model), "12321", order=2)
    subs = {"h": h, "alpha": 0.5, **(params or {"m": 1.0, "omega": 1.0})}
    H_S = fam.H_S.subs(subs)
    for n in (0, 117, steps):
        point = dict(zip(nb.model(model).coordinates, theirs[n]))
        assert b.values["H_S"][n] == pytest.approx(float(H_S.subs(point)), rel=1e-13, abs=1e-15)


def test_record_to_dict_text_and_pickle():
    h, steps, every = 0.1, 200, 5
    x = nb.iterate("ho3", "12321", h, steps, (1.0, 1.0, 1.0), every=every)
    r = nb.shadow_along("ho3", "12321", x, h, t=sample_times(h, steps, every), which=("H_S", "G_S", "H_c"))
    d = json.loads(json.dumps(r.to_dict()))
    assert d["model"] == "ho3" and d["integrator"] == "12321" and d["n_samples"] == x.shape[0]
    assert d["t_span"] == pytest.approx(h * steps)
    assert set(d["max_abs_error"]) == set(d["drift_rate"]) == set(d["drift"]) == {"H_S", "G_S", "H_c"}
    assert d["drift"]["H_S"]["rate"] == d["drift_rate"]["H_S"] == r.drift["H_S"].rate
    assert "values" not in d and len(r.to_dict(values=True)["values"]["G_S"]) == x.shape[0]
    assert "max |H_S(t) - H_S(0)|" in str(r) and "order 2" in str(r)
    copy = pickle.loads(pickle.dumps(r))
    assert copy.to_dict(values=True) == r.to_dict(values=True) and str(copy) == str(r)
    np.testing.assert_array_equal(copy.errors("G_S"), r.errors("G_S"))


def test_undefined_quantities_named_in_skipped():
    x = nb.iterate("rigid-body", "123", 0.1, 20, (1.0, 0.5, 0.2), RIGID)  # not symmetric: no pair at order 2
    r = nb.shadow_along("rigid-body", "123", x, 0.1, params=RIGID, which=("H", "H_S"))
    assert list(r.values) == ["H"] and "H_S" in r.skipped


@pytest.mark.parametrize("kwargs, error, words", [
    ({"trajectory": np.ones((10, 2))}, InvalidRunError, "shape (n_samples, 3)"),
    ({"trajectory": np.ones(3)}, InvalidRunError, "shape (n_samples, 3)"),
    ({"trajectory": np.ones((2, 3))}, InvalidRunError, "n_samples >= 3"),
    ({"trajectory": [[1, 2, "a"]] * 4}, InvalidRunError, "trajectory must be"),
    ({"trajectory": np.full((4, 3), np.nan)}, NumericalRangeError, "trajectory holds a non-finite"),
    ({"t": np.arange(3.0)}, InvalidRunError, "t must be an array of shape (5,)"),
    ({"t": np.array([0.0, 1.0, 1.0, 2.0, 3.0])}, InvalidRunError, "strictly increasing"),
    ({"h": 0.0}, InvalidRunError, "h = 0"),
    ({"h": float("inf")}, NumericalRangeError, "h = inf"),
    ({"which": ("H", "K")}, InvalidRunError, "which must name"),
    ({"order": -1}, NambuBCHError, "order"),
    ({"trajectory": np.full((5, 3), 1e200)}, NumericalRangeError, "not finite along the trajectory"),
])
def test_bad_input_is_one_line_naming_it(kwargs, error, words):
    args = {"trajectory": np.ones((5, 3)), "h": 0.1, **kwargs}
    with pytest.raises(error) as info:
        nb.shadow_along("ho3", "12321", args.pop("trajectory"), args.pop("h"), **args)
    message = str(info.value)
    assert words in message and "\n" not in message
