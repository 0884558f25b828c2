"""Hypothesis strategies shared by the test files (import as ``from strategies import ...``; tests/conftest.py puts
this directory on ``sys.path``, since the suite runs with ``--import-mode=importlib``)."""

from __future__ import annotations

import copy
import functools

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


# --------------------------------------------------------------------------------------------
# adversarial values for the fuzz tests of the public surface (tests/test_fuzz_api.py, tests/test_fuzz_cli.py)
# --------------------------------------------------------------------------------------------
#: Sets this marker module in ``sys.modules`` when evaluated as Python: a test that finds it there knows that a string
#: it passed was run as code (the probe has no other effect, so a run that executes it does no harm).
CODE_MARKER = "nambu_bch_fuzz_code_ran"
PAYLOADS = (
    f"__import__('sys').modules.setdefault('{CODE_MARKER}', __import__('sys'))",
    f"x1 + __import__('sys').modules.setdefault('{CODE_MARKER}', 1).__class__.__name__.__len__()",
    f"(lambda: __import__('sys').modules.setdefault('{CODE_MARKER}', 1))()",
    "().__class__.__bases__[0].__subclasses__()",
    "x1.__class__.__init__.__globals__",
    "open('nambu_bch_fuzz_open', 'w')",
    "1:1/2 # __import__('os')",
    "$(id)", "`id`", "; id", "\\input{/etc/passwd}",
)
#: Numbers and expressions that are large or costly to evaluate; each must be refused from an estimate, or be fast.
TOWERS = (
    "exp(exp(exp(2.5)))", "x2^2/2+x1^2*cos(exp(exp(exp(2.5))))", "10^10^10", "99999999^500", "1e999999",
    "sin(sin(sin(sin(sin(sin(sin(sin(x1))))))))+x2^2/2", "(x1+x2+1)^1000", "9" * 5000,
)
UNICODE = ("ｘ1", "٣", "３", "x\u200b1", "x1\u202e", "🙂", "Ω", "\u00e9", "x₁", "ℌ")
CONTROL = ("", " ", "\x00", "\n", "x1\nx2", "\r", "\t", "\x1b[31m", "\x7f", "\ufeff")
BAD_NAMES = ("nonexistent", "HO3", "ho3 ", " ho3", "ho4", "rigid_body", "ho3-", "-", "none", "None", "../ho3", "ho3\x00")
BAD_WORDS = ("0", "4", "1234", "12a21", "123210", "yoshida:yoshida:121", "suzuki:9", "1:1/2,2:", "1:nan,2:1,3:1",
             "1:1e999,2:1,3:1", "strang:", "TVT", "121", "1" * 500, ":", ",", "yoshida:" * 30)
PLAIN_TEXT = ("ho3", "ho", "12321", "x1", "x1**2", "x1^2/2", "m", "h", "alpha", "1/2", "0.1", "nan", "inf", "-inf",
              "True", "None", "1 2 3", "x1 x2 x3", "1,1,1", "direct", "fi", "png")


@functools.lru_cache(maxsize=None)  # one strategy object per process: building one is slow
def adversarial_text(max_size=12):
    """Hostile and odd strings: payloads, towers, unicode, control characters, bad names and words, random text.

    No string starts with ``/`` or ``~`` (a value may reach a path argument: it must stay relative) and no string
    holds more than ``max_size // 3 + 1`` ``..`` steps (the callers run below a deeper working directory)."""
    fixed = (*PAYLOADS, *TOWERS, *UNICODE, *CONTROL, *BAD_NAMES, *BAD_WORDS, *PLAIN_TEXT, "x" * 10_000)
    return st.one_of(
        st.sampled_from(fixed),
        st.text(max_size=max_size),
        st.text(alphabet="0123456789x123+-*/^().,:_ ", max_size=max_size),
    ).filter(lambda s: not s.startswith(("/", "~")))


@functools.lru_cache(maxsize=None)  # one strategy object per process: building one is slow
def adversarial_scalars():
    """Numbers and singletons of every kind: bools, zero and negative counts, huge ints, nan/inf/-0.0, numpy and sympy
    scalars.  Finite numbers are small (at most 3 in absolute value, or huge enough to be refused), so that a value
    accepted as a count, an order or a size keeps the call fast."""
    import math

    import numpy as np
    import sympy

    values = (
        None, True, False, 0, 1, 2, 3, -1, -2, 10**400, -(10**400), 2**64, 2**63 - 1,
        0.0, -0.0, 0.5, -0.1, 1.5, 1e-300, 5e-324, 1e308, -1e308, math.nan, math.inf, -math.inf, 1j, complex("nan"),
        np.float64("nan"), np.float32(0.5), np.int64(2), np.int8(-1), np.bool_(True), np.uint64(2**64 - 1),
        sympy.Integer(2), sympy.Rational(1, 2), sympy.nan, sympy.oo, sympy.zoo, sympy.Symbol("x1"), sympy.Symbol("h"),
        sympy.I, sympy.sqrt(2), sympy.Float("1e400"), b"12321", bytearray(b"x1"), Ellipsis, NotImplemented,
    )
    return st.sampled_from(values)


@functools.lru_cache(maxsize=None)  # one strategy object per process: building one is slow
def adversarial_containers():
    """Containers of the wrong length, shape or dtype, nested and empty."""
    import numpy as np

    arrays = st.sampled_from((
        "zeros0", "ones22", "ones3", "nan3", "inf3", "str1", "complex3", "object3", "bool3", "int3", "ones333", "ones1",
        "big3",
    )).map(lambda kind: {
        "zeros0": lambda: np.zeros(0), "ones22": lambda: np.ones((2, 2)), "ones3": lambda: np.ones(3),
        "nan3": lambda: np.full(3, np.nan), "inf3": lambda: np.full(3, np.inf), "str1": lambda: np.array(["x1"]),
        "complex3": lambda: np.ones(3, dtype=complex), "object3": lambda: np.array([None, 1, "x"], dtype=object),
        "bool3": lambda: np.ones(3, dtype=bool), "int3": lambda: np.arange(3), "ones333": lambda: np.ones((3, 3, 3)),
        "ones1": lambda: np.ones(1), "big3": lambda: np.full(3, 1e308),
    }[kind]())
    leaves = st.one_of(adversarial_scalars(), adversarial_text(6))
    nested = st.recursive(
        leaves,
        lambda inner: st.one_of(
            st.lists(inner, max_size=4), st.lists(inner, max_size=3).map(tuple),
            st.dictionaries(st.one_of(adversarial_text(4), adversarial_scalars()).filter(_hashable), inner, max_size=3),
            st.frozensets(st.sampled_from((1, 2, 3, "x1")), max_size=3),
        ),
        max_leaves=6,
    )
    fixed = st.sampled_from(((), [], {}, set(), [None], [[[]]], (1, 2, 3), [1.0, 1.0, 1.0], [1.0, 1.0], [1, 1, 1, 1],
                             {1: 2}, {"m": PAYLOADS[0]}, [PAYLOADS[0]], (PAYLOADS[0],) * 3, {"m": 10**400},
                             {"omega": "nan"}, {"zz": 1.0}, range(3))).map(copy.deepcopy)  # a callee may mutate it
    return st.one_of(arrays, nested, fixed)


def _hashable(value):
    try:
        hash(value)
    except TypeError:
        return False
    return True


@functools.lru_cache(maxsize=None)  # one strategy object per process: building one is slow
def adversarial_values():
    """Any adversarial argument: scalars, text, containers, and objects of an unrelated type."""
    objects = st.sampled_from((object(), int, print, lambda *a: None, type("Odd", (), {})(), ValueError("x")))
    return st.one_of(adversarial_scalars(), adversarial_text(), adversarial_containers(), objects)
