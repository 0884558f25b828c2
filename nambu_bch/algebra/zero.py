"""The package's one exact zero test of a sympy expression (cheap structural tests first).

Rational functions are decided by ``cancel``, also those in the jets ``F(x), F'(x), ...`` of undefined
one-argument functions (algebraically independent, so they count as symbols).  Otherwise an expression is zero when its
expansion is ``0``; else, when it holds algebraic numbers such as ``2**(1/3)`` (the
triple-jump coefficients of Yoshida, Phys. Lett. A 150 (1990) 262, Eq. 5.5), when
rationalising the denominators (``radsimp``) brings the expansion to ``0``; else, with
exponentials or trigonometric functions, when their rewriting as exponentials does; else
when ``simplify`` proves it.  Each tier only ever answers ``0`` for an expression that is
zero, so a ``True`` is exact; outside rational functions a ``False`` means that none of the
tiers found the zero.
"""

from __future__ import annotations

import sympy


def has_radicals(expr) -> bool:
    """``expr`` contains an algebraic number such as ``2**(1/3)`` (a number raised to a non-integer power).

    >>> has_radicals(sympy.cbrt(2) * sympy.Symbol("x")), has_radicals(sympy.Symbol("x") ** 2 / 3)
    (True, False)
    """
    return any(p.base.is_Number and not p.exp.is_Integer for p in sympy.sympify(expr, strict=True).atoms(sympy.Pow))


#: The witness points' coordinates: distinct, irregular rationals in (0, 1) (inside the domain of log, sqrt, 1/x).
_POINT = (sympy.Rational(7, 19), sympy.Rational(5, 13), sympy.Rational(11, 23), sympy.Rational(3, 7),
          sympy.Rational(13, 29), sympy.Rational(9, 17), sympy.Rational(17, 31), sympy.Rational(2, 11))


def witness(e, point=None, digits: int = 30, tolerance: float = 1e-12):
    """``(point, value)`` where ``e`` is clearly not zero, else ``None`` (a proof of non-zero-ness, never of zero).

    ``point`` maps the free symbols to distinct, irregular rationals (:data:`_POINT`) unless given.
    sympy's ``evalf`` tracks the cancellation in sums and raises its working precision until the result has
    the requested ``digits``; a zero expression therefore evaluates to below ``10^-digits`` of its terms' size,
    and a value above ``tolerance`` times that size is not round-off (``tolerance`` well above ``10^-digits``).
    Where the point is outside the domain (a pole, a complex value) or the evaluation does not give a number, no
    witness is claimed.

    >>> x = sympy.Symbol("x")
    >>> witness(sympy.sin(x)**2 - 1 + sympy.cos(x)**2) is None, witness(x**2 - x)[0]
    (True, {x: 7/19})
    """
    e = sympy.sympify(e, strict=True)
    if point is None:
        symbols = sorted(e.free_symbols, key=str)
        point = {x: _POINT[i % len(_POINT)] + i // len(_POINT) for i, x in enumerate(symbols)}
    try:
        value = e.evalf(digits, subs=point)
        scale = max((abs(t.evalf(digits, subs=point)) for t in sympy.Add.make_args(e)), default=sympy.Integer(0))
    except (TypeError, ValueError, ArithmeticError):  # noqa: BLE001 - outside the domain: no witness
        return None
    if not (value.is_Number and value.is_real and scale.is_Number and scale.is_finite) or value.has(sympy.nan):
        return None
    if abs(value) > sympy.Float(tolerance, digits) * max(scale, sympy.Integer(1)):
        return point, value
    return None


def _nonzero_at_a_point(e) -> bool:
    """``e`` evaluates, at 30 digits, to a real number clearly away from zero at a rational point (:func:`witness`)."""
    return witness(e) is not None


def _jets_as_symbols(expr):
    """``expr`` with each ``F(x)`` and ``Derivative(F(x), (x, k))`` (``F`` undefined, one symbol argument) replaced by
    a symbol of its own, or ``None`` when ``expr`` has no such atom or another applied undefined function.

    For an undefined (generic) ``F`` the jets ``F(x), F'(x), F''(x), ...`` are algebraically independent over the
    rational functions of the coordinates (Olver, *Applications of Lie Groups to Differential Equations*,
    Sect. 2.3), so a rational function of them is zero exactly when it is zero with the jets as free symbols.

    >>> x = sympy.Symbol("x"); T = sympy.Function("T")
    >>> _jets_as_symbols(T(x).diff(x)**2 - T(x)).free_symbols.isdisjoint({x})
    True
    """
    from sympy.core.function import AppliedUndef

    undefined = expr.atoms(AppliedUndef)
    if not undefined or not all(len(f.args) == 1 and f.args[0].is_Symbol for f in undefined):
        return None
    jets = set(undefined)
    for d in expr.atoms(sympy.Derivative):
        if not (isinstance(d.expr, AppliedUndef) and len(d.variable_count) == 1
                and d.variable_count[0][0] == d.expr.args[0]):
            return None
        jets.add(d)
    # xreplace matches the largest subtree first: a derivative is replaced whole, before the F(x) inside it
    return expr.xreplace({jet: sympy.Dummy() for jet in sorted(jets, key=sympy.default_sort_key)})


def is_zero(expr) -> bool:
    """Exact zero test, cheapest decisive tier first.

    1. A rational function of its symbols with rational coefficients is zero exactly when
       ``cancel`` gives ``0`` (decisive both ways: ``QQ(symbols)`` is a field); so is a rational function of the
       symbols and of the jets ``F(x), F'(x), ...`` of undefined one-argument functions (:func:`_jets_as_symbols`).
    2. Otherwise the expansion; then a witness of non-zero-ness (a rational point where the value,
       at 30 digits, is clearly not zero: :func:`_nonzero_at_a_point`) answers ``False`` before the
       expensive tiers; with algebraic numbers, the expansion after rationalising the denominators (``radsimp``).
    3. With ``exp`` and trigonometric functions, everything rewritten as exponentials and
       combined, which decides identities between polynomials in ``exp(a x)``, ``cos``, ``sin``.
    4. ``simplify`` as the last resort.

    >>> x = sympy.Symbol("x"); c = sympy.cbrt(2)
    >>> is_zero((x + 1)**2 - x**2 - 2*x - 1), is_zero(1/(2 - c) - (4 + 2*c + c**2)/6), is_zero(sympy.sin(x)**2 + sympy.cos(x)**2 - 1)
    (True, True, True)
    >>> is_zero(1/(1 + x) - 1/(x + 1)**2 * (x + 1)), is_zero(x - 1)
    (True, False)
    """
    expr = sympy.sympify(expr, strict=True)
    radicals = has_radicals(expr)
    if not radicals and expr.is_rational_function(*sorted(expr.free_symbols, key=str)):
        return sympy.cancel(sympy.together(expr)) == 0
    jets = None if radicals else _jets_as_symbols(expr)
    if jets is not None and jets.is_rational_function(*sorted(jets.free_symbols, key=str)):
        return sympy.cancel(sympy.together(jets)) == 0
    e = sympy.expand(expr)
    if e == 0:
        return True
    if _nonzero_at_a_point(e):
        return False
    if radicals and sympy.expand(sympy.radsimp(sympy.together(e))) == 0:
        return True
    if e.has(sympy.exp, sympy.sin, sympy.cos, sympy.tan, sympy.sinh, sympy.cosh, sympy.tanh):
        r = sympy.expand(sympy.powsimp(sympy.expand(e.rewrite(sympy.exp)), combine="exp"))
        if r == 0 or sympy.cancel(sympy.together(r)) == 0:
            return True
    return sympy.simplify(e) == 0
