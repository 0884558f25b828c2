"""Results print from their exact data: a direct-route family lays out its per-order corrections once.

The text, LaTeX and JSON of a family are the same bytes as the layout of its expanded sympy sums
(:func:`nambu_bch.printing.h_coefficients`) gives; the sums are not expanded and regrouped for them.
"""

from __future__ import annotations

import json
import pickle

import pytest

import nambu_bch as nb
from nambu_bch.printing import h_coefficients
from nambu_bch.shadow import family as family_module


def _outputs(F):
    return F.to_text(), F.to_latex(), json.dumps(F.to_dict(), sort_keys=True)


def _by_sums(F):
    """The outputs laid out from the sympy sums, as before the exact layout (the reference bytes)."""
    copy = pickle.loads(pickle.dumps(F))

    def layout(slot, with_base=False):
        base = 0 if with_base else copy.system.hamiltonians[slot]
        return h_coefficients(copy.shadows[slot], base, copy.system.coordinates)

    object.__setattr__(copy, "_layout", layout)
    return _outputs(copy)


@pytest.fixture(scope="module")
def families():
    return {
        "ho3 12321 h^4": nb.shadow_hamiltonians(nb.model("ho3"), "12321", order=4),
        "lotka-volterra 12321 h^2": nb.shadow_hamiltonians(nb.model("lotka-volterra"), "12321", order=2),
        "ho 121 h^4 fi": nb.shadow_hamiltonians(nb.model("ho"), "121", order=4, route="fi"),
        "ho3 32123 h^2": nb.shadow_hamiltonians(nb.model("ho3"), "32123", order=2),
        "pendulum 121 h^2": nb.shadow_hamiltonians(nb.model("pendulum"), "121", order=2),  # not polynomial: the sums
    }


@pytest.mark.parametrize("case", ["ho3 12321 h^4", "lotka-volterra 12321 h^2", "ho 121 h^4 fi", "ho3 32123 h^2",
                                  "pendulum 121 h^2"])
def test_outputs_are_the_layout_of_the_sums(families, case):
    F = families[case]
    assert _outputs(F) == _by_sums(F)


def test_direct_family_prints_without_regrouping_its_sums(monkeypatch):
    """Text, LaTeX and JSON of a direct-route family come from its exact corrections: the sympy sums are never
    expanded and split by powers of h, and each shadow is laid out once for all three outputs."""
    calls = []
    monkeypatch.setattr(family_module, "h_coefficients", lambda *a, **k: pytest.fail("the sum was regrouped"))
    real = family_module._exact_layout
    monkeypatch.setattr(family_module, "_exact_layout", lambda *a: calls.append((a[1], a[4])) or real(*a))
    F = nb.shadow_hamiltonians(nb.model("ho3"), "12321", order=4)
    F.to_text()
    F.to_latex()
    assert callable(F.__dict__["_shadows"])  # text and LaTeX did not build the sympy sums
    F.to_dict()
    F.to_text()
    # (H_S, G_S) with base H for text/LaTeX, each once; the JSON series (base 0) is read off the exact corrections
    assert sorted(calls) == [(0, False), (1, False)]


def test_layouts_are_not_pickled():
    F = nb.shadow_hamiltonians(nb.model("ho"), "121", order=2)
    F.to_text()
    copy = pickle.loads(pickle.dumps(F))
    assert "_layouts" not in copy.__dict__ and copy.to_text() == F.to_text() and copy == F


def test_conserved_quantities_keep_their_ring_elements():
    """The invariants are the exact ring elements the search found; H_c, G_c, ... are their sympy forms, converted on
    first access, left out of the pickle, and the same after a round trip (Eqs. CQ12321H, CQ12321G)."""
    nb.clear_caches()  # a result memoised by an earlier test of this process may have built its sympy forms already
    cq = nb.conserved_quantities(nb.model("ho3"), "12321")
    quantities, normalised = cq.exact
    assert len(normalised) == 2 and all(q.ring == quantities[0].ring for q in (*quantities, *normalised))
    assert "_sympy" not in cq.__dict__ and cq == pickle.loads(pickle.dumps(cq))  # equality reads the ring elements
    assert str(cq.G_c) == "h**2*x2**2/(4*m**2) - x1**2 + x3" and cq.hamiltonians_c == (cq.H_c, cq.G_c)
    copy = pickle.loads(pickle.dumps(cq))
    assert "_sympy" not in copy.__dict__ and copy.exact == cq.exact and copy.to_dict() == cq.to_dict()
