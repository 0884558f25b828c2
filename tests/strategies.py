"""Hypothesis strategies shared by the test files (import as ``from strategies import ...``; tests/conftest.py puts
this directory on ``sys.path``, since the suite runs with ``--import-mode=importlib``)."""

from __future__ import annotations

from hypothesis import strategies as st
from sympy import Rational as R

from nambu_bch.integrators import Composition


@st.composite
def compositions(draw, max_generators=3, max_factors=5, numerators=4, denominators=5):
    """A random consistent rational composition: pieces ``1..g`` with coefficients ``p/q`` (``|p| <= numerators``,
    ``1 <= q <= denominators``; zeros, negatives and repeated letters allowed), the last coefficient of every piece
    chosen so that the piece's coefficients sum to one."""
    g = draw(st.integers(1, max_generators))
    pieces = draw(st.lists(st.integers(1, g), min_size=1, max_size=max_factors))
    coeffs = [R(draw(st.integers(-numerators, numerators)), draw(st.integers(1, denominators))) for _ in pieces]
    for k in set(pieces):
        last = max(i for i, p in enumerate(pieces) if p == k)
        coeffs[last] = 1 - sum(c for i, (p, c) in enumerate(zip(pieces, coeffs)) if p == k and i != last)
    return Composition(tuple(pieces), tuple(coeffs), "random")
