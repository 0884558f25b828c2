"""The package's one exact zero test of a sympy expression (cheap structural tests first).

An expression is zero when its expansion is ``0``; else, when it holds algebraic
numbers such as ``2**(1/3)`` (the triple-jump coefficients of Yoshida, Phys. Lett. A
150 (1990) 262, Eq. 5.5), when rationalising the denominators (``radsimp``) brings the
expansion to ``0``; else when ``simplify`` proves it.  ``simplify`` only ever answers
``0`` for an expression that is zero, so a ``True`` is exact; a ``False`` means that
none of the three found the zero.
"""

from __future__ import annotations

import sympy


def has_radicals(expr) -> bool:
    """``expr`` contains an algebraic number such as ``2**(1/3)`` (a number raised to a non-integer power).

    >>> has_radicals(sympy.cbrt(2) * sympy.Symbol("x")), has_radicals(sympy.Symbol("x") ** 2 / 3)
    (True, False)
    """
    return any(p.base.is_Number and not p.exp.is_Integer for p in sympy.sympify(expr).atoms(sympy.Pow))


def is_zero(expr) -> bool:
    """Exact zero test: ``expand``, then ``radsimp`` for radicals, then ``simplify``.

    >>> x = sympy.Symbol("x"); c = sympy.cbrt(2)
    >>> is_zero((x + 1)**2 - x**2 - 2*x - 1), is_zero(1/(2 - c) - (4 + 2*c + c**2)/6), is_zero(sympy.sin(x)**2 + sympy.cos(x)**2 - 1)
    (True, True, True)
    >>> is_zero(x - 1)
    False
    """
    expr = sympy.expand(sympy.sympify(expr))
    if expr == 0:
        return True
    if has_radicals(expr) and sympy.expand(sympy.radsimp(sympy.together(expr))) == 0:
        return True
    return sympy.simplify(expr) == 0
