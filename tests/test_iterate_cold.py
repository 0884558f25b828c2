"""The fixed cost of a run: what iterate() does besides stepping, kept out of repeated and first runs.

The stability verdict of a step depends on its constants ``K`` alone
(:func:`nambu_bch.numeric.guards.check_stability`), so a kernel remembers the ``K`` that passed and a
repeated run with the same step and parameters does not form and diagonalise the step's matrix again;
an unstable ``K`` is never remembered (every such run is refused).
"""

import numpy as np
import pytest

import nambu_bch as nb
from nambu_bch.errors import UnstableStepError
from nambu_bch.numeric import guards, kernel


def test_a_stable_step_is_checked_once_per_kernel(monkeypatch):
    kern = kernel("ho", "121")
    K = kern.constants(0.0123, {"omega": 1.5})
    kern.stable_constants.discard(K.tobytes())
    calls = []
    matrix = guards.step_matrix
    monkeypatch.setattr(guards, "step_matrix", lambda *a: calls.append(1) or matrix(*a))
    for _ in range(3):
        nb.iterate("ho", "121", 0.0123, 5, [1.0, 0.0], params={"omega": 1.5}, backend="numpy")
    assert len(calls) == 1 and K.tobytes() in kern.stable_constants


def test_an_unstable_step_is_refused_every_time():
    kern = kernel("ho", "121")
    for _ in range(2):
        with pytest.raises(UnstableStepError, match="stability interval"):
            nb.iterate("ho", "121", 2.5, 5, [1.0, 0.0], backend="numpy")
    assert kern.constants(2.5).tobytes() not in kern.stable_constants


def test_a_coefficient_out_of_range_still_names_the_run():
    with pytest.raises(nb.NambuBCHError, match=r"h = 0\.1 with m = 1, omega = 1e\+200: a coefficient of the step overflows"):
        nb.iterate("ho", "121", 0.1, 5, [1.0, 0.0], params={"omega": 1e200}, backend="numpy")
    assert np.isfinite(kernel("ho", "121").constants(0.1)).all()
