"""The ``pytest11`` entry point ``nambu_bch``: the fixtures of :mod:`nambu_bch.testing`, importing nothing heavy.

pytest imports every installed ``pytest11`` plugin when it starts, in every project's test run, before it collects
anything.  This module therefore imports only pytest and the package's lazy ``__init__``; sympy and the models are
imported when a fixture is first used.  :mod:`nambu_bch.testing` re-exports the fixtures, so ``pytest -p
nambu_bch.testing`` provides the same ones.

Fixtures: ``ho``, ``ho3``, ``rigid_body``, ``lotka_volterra``, ``ho3_composite`` (the built-in
:func:`~nambu_bch.model` systems), ``paper_words`` (the six second-order words of Sect. 5.1) and ``symbols``
(name -> Symbol for ``x1..x3``, ``m``, ``omega``, ``I1..I3``, ``h``, ``alpha``).
"""

from __future__ import annotations

import pytest

__all__ = ["ho", "ho3", "rigid_body", "lotka_volterra", "ho3_composite", "paper_words", "symbols"]


def _model(name: str):
    from .systems import model

    return model(name)


@pytest.fixture
def ho():
    """The harmonic oscillator, Eq. (HO1); pieces 1 = T, 2 = V."""
    return _model("ho")


@pytest.fixture
def ho3():
    """The paper's N = 3 oscillator (q, p, q^2), Eqs. (Ex1), (H), (G); pieces Eqs. (hX1)-(hX3)."""
    return _model("ho3")


@pytest.fixture
def rigid_body():
    """The free rigid body, H = sum x_i^2/(2 I_i), G = |x|^2/2, full split."""
    return _model("rigid-body")


@pytest.fixture
def lotka_volterra():
    """Cyclic Lotka-Volterra, H = x1 + x2 + x3, G = x1 x2 x3, only H split."""
    return _model("lotka-volterra")


@pytest.fixture
def ho3_composite():
    """The (q^2, p^2, qp) oscillator of the conclusions, only H split."""
    return _model("ho3-composite")


@pytest.fixture
def paper_words():
    """The six symmetric second-order words of the paper's Sect. 5.1 / Table (table)."""
    from .integrators import PAPER_WORDS

    return PAPER_WORDS


@pytest.fixture
def symbols():
    """Name -> Symbol for the built-in models' symbols, the step ``h`` and ``alpha``."""
    import sympy

    names = "x1 x2 x3 m omega I1 I2 I3 h alpha"
    return {s.name: s for s in sympy.symbols(names)}
