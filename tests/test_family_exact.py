"""A direct-route ``ShadowFamily`` keeps the exact corrections and builds its sympy sums on first access.

The family of :func:`~nambu_bch.shadow.api.shadow_hamiltonians` (direct route) holds the route's exact sparse
corrections (``details``); ``shadows``, ``H_S``, ``G_S`` and the printed forms build the sympy expressions once,
on first access.  Reading the free parameters needs no sympy sum (``DirectResult.has_symbol``); a family pickled
before its first access comes back equal to one built eagerly.
"""

from __future__ import annotations

import importlib
import pickle

import pytest
import sympy

from nambu_bch import model, shadow_hamiltonians
from nambu_bch.symbols import ALPHA

dr = importlib.import_module("nambu_bch.shadow.direct_route")  # the package exports the function of the same name


@pytest.fixture
def counted(monkeypatch):
    """Count the calls of ``DirectResult.shadow`` (the conversion of the exact corrections to sympy)."""
    calls = []
    original = dr.DirectResult.shadow

    def shadow(self, upto=None):
        calls.append(upto)
        return original(self, upto)

    monkeypatch.setattr(dr.DirectResult, "shadow", shadow)
    return calls


def test_shadows_built_on_first_access_only(counted):
    F = shadow_hamiltonians(model("ho3"), "12321", order=4)
    assert counted == [] and F.free_parameters == ["alpha"] and F.exists and F.polynomial
    H_S = F.H_S
    assert len(counted) == 1
    text, latex, data = F.to_text(), F.to_latex(), F.to_dict()
    assert len(counted) == 1 and F.H_S is H_S and F.shadows == (H_S, F.G_S)
    assert "free parameters: alpha" in text and r"H_{S}" in latex and data["H_S"] == str(H_S)


@pytest.mark.parametrize("name, word, order", [("ho3", "12321", 4), ("ho", "121", 4), ("rigid-body", "12321", 2),
                                                ("lotka-volterra", "12321", 4), ("pendulum", "121", 2)])
def test_free_parameters_from_exact_data_equal_sympy(name, word, order):
    """``has_symbol`` on the exact data agrees with ``has`` on the built sums (polynomial and non-polynomial routes)."""
    R = dr.direct_route(model(name), word, order)
    assert R.exists
    assert R.has_symbol(ALPHA) == any(S.has(ALPHA) for S in R.shadow())
    for s in model(name).parameters + model(name).coordinates:
        assert R.has_symbol(s) == any(S.has(s) for S in R.shadow()), s


def test_pending_family_pickles_to_the_built_one(counted):
    F = shadow_hamiltonians(model("rigid-body"), "12321", order=2)
    copy = pickle.loads(pickle.dumps(F))  # before any sympy sum exists
    assert counted == []
    built = shadow_hamiltonians(model("rigid-body"), "12321", order=2)
    assert built.shadows == copy.shadows and copy.shadows == F.shadows
    assert copy.to_text() == built.to_text() and copy.to_dict() == built.to_dict()
    again = pickle.loads(pickle.dumps(copy))  # after: the sums travel as they are
    assert again.__dict__["_shadows"] == copy.shadows and sympy.expand(again.H_S - F.H_S) == 0


def test_gauge_built_on_first_access_only():
    """The kernel bases stay exact vectors until read (family ``gauge``, ``OrderSolution.gauge``), also through pickle."""
    F = shadow_hamiltonians(model("ho3"), "12321", order=4)
    solved = [o for o in F.details.orders if o.status == "solved"]
    assert solved and all(o.convert_gauge is not None for o in solved)
    copy = pickle.loads(pickle.dumps(F))
    directions = F.gauge[2]
    assert solved[0].convert_gauge is None and solved[1].convert_gauge is not None
    assert len(directions) == solved[0].kernel_dim and all(len(d) == 2 for d in directions)
    assert copy.gauge == F.gauge and list(F.gauge) == [2, 4] and copy.to_dict()["gauge"] == F.to_dict()["gauge"]
