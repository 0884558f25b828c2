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

from ..errors import NambuBCHError


def jacobian(map_components, coordinates) -> sympy.Matrix:
    """``dy_i/dx_j`` of a map given as sympy expressions ``y_i(x)``."""
    if len(map_components) != len(coordinates):
        raise NambuBCHError(
            f"a map of {len(coordinates)} coordinates needs {len(coordinates)} components, got {len(map_components)}"
        )
    return sympy.Matrix(map_components).jacobian(sympy.Matrix(coordinates))


def _is_zero(expr) -> bool:
    expr = sympy.expand(expr)
    return expr == 0 or sympy.simplify(expr) == 0


def satisfies_nambu_condition(map_components, coordinates) -> bool:
    """Eq. (Condition1): the map preserves the Nambu bracket (``det dy/dx = 1``)."""
    return _is_zero(jacobian(map_components, coordinates).det(method="berkowitz") - 1)


def is_symplectic(map_components, coordinates) -> bool:
    """Eq. (Symplectic): ``J eps J^T = eps`` with the canonical ``eps`` of ``(q.., p..)``."""
    n = len(coordinates)
    if n % 2:
        raise NambuBCHError(f"symplecticity needs an even number of coordinates, got {n}")
    J = jacobian(map_components, coordinates)
    k = n // 2
    eps = sympy.zeros(n)
    for i in range(k):
        eps[i, i + k], eps[i + k, i] = 1, -1
    return all(_is_zero(e) for e in (J * eps * J.T - eps))
