"""Structure conditions for maps ``x -> y(x)``: Eq. (Symplectic) and Eq. (Condition1).

* Symplectic (N = 2, or canonical 2n): ``(dy/dx) eps (dy/dx)^T = eps``.
* Nambu structure, Eq. (Condition1): ``eps_{l m n} dy_i/dx_l dy_j/dx_m dy_k/dx_n
  = eps_{ijk}``.  Contracting a Levi-Civita tensor with a matrix in every slot
  multiplies it by the determinant, so the left side equals
  ``det(dy/dx) eps_{ijk}`` and the condition is exactly ``det(dy/dx) = 1``
  (for every N).  :func:`satisfies_nambu_condition` checks the determinant;
  the tests also check the tensor identity literally for N = 3.
"""

from __future__ import annotations

import sympy

from ..checks import check_sequence
from ..errors import NambuBCHError
from ..parsing import as_expression, as_symbols
from .brackets import nambu_bracket
from .polynomial import PolynomialAlgebra
from .zero import is_zero


def _checked(map_components, coordinates) -> tuple:
    """The map's components and the coordinates as tuples, of the same length, else one line naming the argument."""
    coordinates = as_symbols(coordinates, "coordinates")
    if not coordinates:
        raise NambuBCHError("a map needs at least one coordinate, got none")
    map_components = check_sequence(map_components, "map_components", "expressions")
    if len(map_components) != len(coordinates):
        raise NambuBCHError(
            f"a map of {len(coordinates)} coordinates needs {len(coordinates)} components, got {len(map_components)}"
        )
    return map_components, coordinates


def _components(map_components, coordinates) -> list:
    """The map's components as sympy expressions; text is parsed in the coordinates and the step ``h``."""
    symbols = (*coordinates, sympy.Symbol("h"))
    return [as_expression(y, symbols, f"map component {i + 1}") for i, y in enumerate(map_components)]


def jacobian(map_components, coordinates) -> sympy.Matrix:
    """``dy_i/dx_j`` of a map given as sympy expressions ``y_i(x)``."""
    map_components, coordinates = _checked(map_components, coordinates)
    return sympy.Matrix(_components(map_components, coordinates)).jacobian(sympy.Matrix(coordinates))


def _ring_condition(map_components, coordinates):
    """Eq. (Condition1) exactly in sparse polynomial rings; ``None`` unless every ``y_i`` is polynomial.

    With ``y_i = P_i / D_i`` (``D_i`` free of the coordinates), ``det dy/dx = {P_1, ..., P_N} / prod D_i``
    (Eq. NB), so the condition is ``{P_1, ..., P_N} = prod D_i`` in ``QQ[x, parameters]`` -- no rational
    function arithmetic, which is what makes the sympy determinant slow.
    """
    ys = _components(map_components, coordinates)
    others = sorted(set().union(*(y.free_symbols for y in ys)) - set(coordinates), key=str)
    try:
        fractions = PolynomialAlgebra(coordinates, parameters=others)
        flat = PolynomialAlgebra(coordinates, constants=others)
    except Exception:  # coordinates that are not plain symbols: use the sympy route
        return None
    values = [fractions.convert(y) for y in ys]
    if not all(fractions.is_polynomial(v) for v in values):
        return None
    numerators, denominator = [], flat.ring.one
    for v in values:
        den = sympy.Integer(1)
        for c in v.values():
            den = sympy.lcm(den, sympy.denom(fractions.domain.to_sympy(c)))
        numerators.append(flat.convert(sympy.expand(fractions.to_sympy(v) * den)))
        denominator = denominator * flat.convert(den)
    if not all(flat.is_polynomial(p) for p in numerators + [denominator]):
        return None
    return not (nambu_bracket(flat, *numerators) - denominator)


def satisfies_nambu_condition(map_components, coordinates) -> bool:
    """Eq. (Condition1): the map preserves the Nambu bracket (``det dy/dx = 1``).

    Polynomial maps (coefficients rational in the parameters) are checked exactly in a sparse
    polynomial ring, where the determinant is the Nambu bracket ``{y_1, ..., y_N}``; other maps by sympy.
    """
    map_components, coordinates = _checked(map_components, coordinates)
    result = _ring_condition(map_components, coordinates)
    if result is not None:
        return result
    return is_zero(jacobian(map_components, coordinates).det(method="berkowitz") - 1)


def is_symplectic(map_components, coordinates) -> bool:
    """Eq. (Symplectic): ``J eps J^T = eps`` with the canonical ``eps`` of ``(q.., p..)``."""
    map_components, coordinates = _checked(map_components, coordinates)
    n = len(coordinates)
    if n % 2:
        raise NambuBCHError(f"symplecticity needs an even number of coordinates, got {n}")
    J = jacobian(map_components, coordinates)
    k = n // 2
    eps = sympy.zeros(n)
    for i in range(k):
        eps[i, i + k], eps[i + k, i] = 1, -1
    return all(is_zero(e) for e in (J * eps * J.T - eps))
