"""The exact side of a complex-coefficient step: which sub-flows continue to a complex time, and the coefficients.

Shared by the interpreted run (:mod:`~nambu_bch.numeric.complex_iterate`) and the compiled one
(:mod:`~nambu_bch.numeric.complex_codegen`), below both.  A factor ``exp(c h X_k)`` with ``c`` not real is the
sub-flow of piece ``k`` continued analytically to the complex time ``c h``; that continuation is unique only where
the sub-flow is an entire function of the state and the time (Blanes, Casas & Murua, SeMA J. 50 (2010) 47, Sect. 2).
"""

from __future__ import annotations

import numpy as np
import sympy

from ..errors import InvalidRunError, NumericalRangeError
from ..integrators.flows import TIME

#: The functions an entire sub-flow may contain (analytic on all of ``C^N x C``: no branch cut, no pole).
ENTIRE = (sympy.exp, sympy.sin, sympy.cos, sympy.sinh, sympy.cosh)


def _entire_obstacle(expr, variables):
    """``None`` if ``expr`` is an entire function of ``variables``, else the sub-expression that is not (a power
    other than a natural one, or a function other than :data:`ENTIRE`, of something depending on them)."""
    for node in sympy.preorder_traversal(expr):
        if not (node.free_symbols & variables):
            continue
        if isinstance(node, sympy.Pow) and not (node.exp.is_Integer and node.exp >= 0):
            return node
        if isinstance(node, sympy.Function) and not isinstance(node, ENTIRE):
            return node
    return None


def check_entire(system, comp, k, exprs) -> None:
    """Refuse, in one line, a sub-flow ``exprs`` of piece ``k`` that is not an entire function of the state and the
    time: its continuation to a complex time would depend on the path around a branch cut or a pole."""
    variables = {*system.coordinates, TIME}
    bad = next((b for b in (_entire_obstacle(e, variables) for e in exprs) if b is not None), None)
    if bad is not None:
        raise InvalidRunError(
            f"composition {comp.name!r} has complex coefficients, and the flow of piece {k} of {system.name} contains "
            f"{bad}, which has a branch cut or a pole in the complex plane: a complex time step is defined only for "
            "sub-flows built from polynomials, exp, sin and cos")


def coefficient_value(comp, c) -> complex:
    """The exact coefficient ``c`` of ``comp`` as complex128 (17 significant digits, then rounded), or one
    :class:`~nambu_bch.errors.NumericalRangeError` line when it is beyond the range of complex128."""
    value = complex(sympy.N(c, 17))
    if not (np.isfinite(value.real) and np.isfinite(value.imag)):
        raise NumericalRangeError(f"the coefficient {str(c)[:40]} of {comp.name[:60]!r} is beyond the complex128 range")
    return value
