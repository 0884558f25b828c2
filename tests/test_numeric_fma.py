"""The fused loop of ``iterate(fma=True)`` for one trajectory: its multiply-adds written out, each rounded once.

``run_fma`` adds every increment that is a product ``p*q`` by ``fma(p, q, s)`` (``llvm.fma``, correctly rounded
on every machine), so its samples are those of the same statements with an exact ``a*b + c`` rounded once --
computed here with fractions on the interpreter.
"""

from fractions import Fraction

import numpy as np
import pytest
import sympy

from nambu_bch import model
from nambu_bch.numeric import iterate, kernel, numba_available
from nambu_bch.numeric.codegen import fused_product, print_python

numba_only = pytest.mark.skipif(not numba_available(), reason="numba not installed or disabled")


def exact_fma(a, b, c):
    """``a*b + c`` rounded once (finite arguments): exact rationals, one correctly rounded conversion."""
    return float(Fraction(a) * Fraction(b) + Fraction(c))


def test_products_split_at_their_last_multiply():
    k0, k1, s0, s1 = sympy.symbols("k0 k1 s0 s1")
    printer = lambda e: print_python(e, "_")  # noqa: E731
    assert fused_product(k0 * s0 * s1, printer) == ("k0*s0", "s1")
    assert fused_product(-k1 * s0, printer) == ("-k1", "s0")
    assert fused_product(k0 * s0 + s1, printer) is None  # a sum: added unfused
    assert fused_product(sympy.exp(s0), printer) is None


@numba_only
def test_fused_single_loop_rounds_each_multiply_add_once():
    """ho3 32123 (Sect. 5.5): the compiled fused loop equals the interpreted one with an exact fma, bit for bit,
    and differs from the default loop (two roundings per update) in the last bits."""
    S = model("ho3")
    x0 = np.array([0.7, -0.3, 1.1])
    fused = iterate(S, "32123", 0.1, 300, x0, every=100, fma=True, backend="numba")
    plain = iterate(S, "32123", 0.1, 300, x0, every=100, backend="numba")
    kern = kernel(S, "32123")
    K = [float(v) for v in kern.constants(0.1)]
    ref = np.empty_like(fused)
    ref[0] = x0
    namespace = dict(kern.module.__dict__, _fma=exact_fma)  # the same statements, interpreted
    run_fma = type(kern.module.run_fma)(kern.module.run_fma.__code__, namespace)
    assert run_fma([float(v) for v in x0], K, 300, 100, ref) == 300
    assert np.array_equal(fused, ref)
    assert not np.array_equal(fused, plain) and np.allclose(fused, plain, rtol=1e-12, atol=1e-14)
