"""pytest helpers and plugin (entry point ``pytest11``): fixtures for the built-in models."""

from __future__ import annotations

import pytest

from .systems import model


@pytest.fixture
def ho():
    """The harmonic oscillator, Eq. (HO1)."""
    return model("ho")


@pytest.fixture
def ho3():
    """The paper's N = 3 oscillator (q, p, q^2), Eqs. (Ex1), (H), (G)."""
    return model("ho3")


@pytest.fixture
def rigid_body():
    return model("rigid-body")


@pytest.fixture
def lotka_volterra():
    return model("lotka-volterra")


@pytest.fixture
def ho3_composite():
    return model("ho3-composite")
