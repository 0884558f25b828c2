"""Decomposition of a separable function ``H = H_1(x_1) + ... + H_N(x_N) + const``."""

from __future__ import annotations

import sympy

from ..errors import NotSeparableError
from ..parsing import as_expression, as_symbols


def separate(expr, coordinates, name: str = "H") -> tuple:
    """The per-coordinate pieces ``(H_1(x_1), ..., H_N(x_N))`` of a separable ``expr``.

    Constant terms (free of every coordinate) are dropped: they do not enter
    any Liouville field.

    Raises
    ------
    NotSeparableError
        naming the first term that couples two or more coordinates.

    Examples
    --------
    >>> import sympy
    >>> x1, x2, x3, m = sympy.symbols("x1 x2 x3 m")
    >>> separate(x3 - x1**2, [x1, x2, x3], "G")
    (-x1**2, 0, x3)
    """
    coords = as_symbols(coordinates, "coordinates")
    pieces = [sympy.Integer(0)] * len(coords)
    for term in sympy.Add.make_args(sympy.expand(as_expression(expr, coords, name))):
        used = [i for i, x in enumerate(coords) if term.has(x)]
        if len(used) > 1:
            names = ", ".join(str(coords[i]) for i in used)
            raise NotSeparableError(
                f"{name} = {expr} is not separable: the term {term} couples {names}; "
                "split only the other Hamiltonian (split='single') or pass a separable one"
            )
        if used:
            pieces[used[0]] += term
    return tuple(pieces)


def is_separable(expr, coordinates) -> bool:
    try:
        separate(expr, coordinates)
    except NotSeparableError:
        return False
    return True
