"""Poisson and Nambu brackets and the Liouville vector fields built from them.

* Poisson bracket, Eq. (Poisson): ``{A,B} = dA/dx1 dB/dx2 - dA/dx2 dB/dx1``
  (canonical ``(q_1..q_n, p_1..p_n)`` for ``2n`` coordinates).
* Nambu bracket, Eq. (NB): ``{A_1,...,A_N} = d(A_1..A_N)/d(x_1..x_N)``, the
  Jacobian determinant, for any ``N >= 2`` (``N = 2`` is the Poisson bracket).
* Liouville field, Eq. (gLiouville): ``X_{H_1..H_{N-1}} f = {f, H_1, ..., H_{N-1}}``,
  i.e. ``X^i = {x_i, H_1, ..., H_{N-1}}``; for ``N = 2`` this is ``X_H`` of
  Section 2.2 with ``X_T = (1/m) x2 d/dx1`` (Eq. XTXV).

References
----------
Horikoshi, *Shadow Hamiltonians of structure-preserving integrators for Nambu
mechanics*, Eqs. (Poisson), (NB), (gLiouville); Takhtajan (1994) for the
fundamental identity these brackets satisfy.
"""

from __future__ import annotations

from itertools import permutations

import sympy

from ..errors import NambuBCHError
from .polynomial import PolynomialAlgebra
from .ring import check_ring
from .vector_field import VectorField


def permutation_sign(perm) -> int:
    """The sign (+1 or -1) of a permutation of ``0..n-1`` given as a sequence."""
    sign, seen = 1, list(perm)
    for i in range(len(seen)):
        while seen[i] != i:
            j = seen[i]
            seen[i], seen[j] = seen[j], seen[i]
            sign = -sign
    return sign


def _gradient(algebra: PolynomialAlgebra, f):
    f = algebra.convert(f)
    return [algebra.diff(f, i) for i in range(algebra.n)]


def _determinant(algebra: PolynomialAlgebra, rows):
    """Leibniz expansion, skipping zero entries (the rows are sparse gradients)."""
    n = len(rows)
    flat = algebra.common(*(entry for row in rows for entry in row))
    rows = [flat[i * n:(i + 1) * n] for i in range(n)]
    total = None
    for perm in permutations(range(n)):
        product = None
        for r, c in enumerate(perm):
            entry = rows[r][c]
            if algebra.is_zero(entry):
                product = None
                break
            product = entry if product is None else product * entry
        if product is not None:
            term = product if permutation_sign(perm) > 0 else -product
            total = term if total is None else total + term
    if total is None:
        return algebra.zero if algebra.is_polynomial(flat[0]) else sympy.Integer(0)
    return total if algebra.is_polynomial(total) else sympy.expand(total)


def nambu_bracket(algebra: PolynomialAlgebra, *functions):
    """The Nambu bracket ``{A_1, ..., A_N}`` (Eq. NB) as a Jacobian determinant.

    Examples
    --------
    >>> import sympy
    >>> x = sympy.symbols("x1:4")
    >>> A = PolynomialAlgebra(x)
    >>> A.to_sympy(nambu_bracket(A, x[0], x[1], x[2]))
    1
    """
    check_ring(algebra, "algebra")
    if len(functions) != algebra.n:
        raise NambuBCHError(f"the Nambu bracket on {algebra.n} coordinates takes {algebra.n} functions, got {len(functions)}")
    return _determinant(algebra, [_gradient(algebra, f) for f in functions])


def poisson_bracket(algebra: PolynomialAlgebra, A, B):
    """The canonical Poisson bracket (Eq. Poisson), coordinates ordered ``(q_1..q_n, p_1..p_n)``.

    Examples
    --------
    >>> import sympy
    >>> q, p = sympy.symbols("x1 x2")
    >>> alg = PolynomialAlgebra([q, p])
    >>> alg.to_sympy(poisson_bracket(alg, q, p))
    1
    """
    check_ring(algebra, "algebra")
    if algebra.n % 2:
        raise NambuBCHError(f"the Poisson bracket needs an even number of coordinates, got {algebra.n}")
    n = algebra.n // 2
    gA, gB = _gradient(algebra, A), _gradient(algebra, B)
    terms = [algebra.common(gA[k], gB[k + n], gA[k + n], gB[k]) for k in range(n)]
    total = sum((a * b - c * d for a, b, c, d in terms[1:]), terms[0][0] * terms[0][1] - terms[0][2] * terms[0][3])
    return total if algebra.is_polynomial(total) else sympy.expand(total)


def liouville_field(algebra: PolynomialAlgebra, *hamiltonians) -> VectorField:
    """``X_{H_1..H_{N-1}}`` with ``X^i = {x_i, H_1, ..., H_{N-1}}`` (Eq. gLiouville).

    For ``N = 2`` and canonical ``2n`` coordinates with one Hamiltonian this is
    ``X_H f = {f, H}`` (Section 2.2).

    Examples
    --------
    >>> import sympy
    >>> x1, x2, x3, m = sympy.symbols("x1 x2 x3 m")
    >>> A = PolynomialAlgebra([x1, x2, x3], [m])
    >>> liouville_field(A, x2**2/(2*m), x3).to_sympy()   # X_{A,C}, Eq. hX1
    (x2/m, 0, 0)
    """
    check_ring(algebra, "algebra")
    if len(hamiltonians) == 1 and algebra.n % 2 == 0 and algebra.n > 2:
        # {q_k, H} = dH/dp_k and {p_k, H} = -dH/dq_k (Eq. Poisson with f a coordinate): H converted and
        # differentiated once, not once per coordinate; the same normal form as poisson_bracket's
        n = algebra.n // 2
        grad = _gradient(algebra, hamiltonians[0])
        components = [grad[k + n] for k in range(n)] + [-grad[k] for k in range(n)]
        return VectorField(algebra, [c if algebra.is_polynomial(c) else sympy.expand(c) for c in components])
    if len(hamiltonians) == 2 and algebra.n % 3 == 0 and algebra.n > 3:
        return triplet_field(algebra, *hamiltonians)
    if len(hamiltonians) != algebra.n - 1:
        raise NambuBCHError(
            f"a Liouville field on {algebra.n} coordinates needs {algebra.n - 1} Hamiltonians, got {len(hamiltonians)}"
        )
    grads = [_gradient(algebra, H) for H in hamiltonians]
    components = []
    for i in range(algebra.n):
        unit = [algebra.ring.one if j == i else algebra.zero for j in range(algebra.n)]
        components.append(_determinant(algebra, [unit, *grads]))
    return VectorField(algebra, components)


def triplet_field(algebra: PolynomialAlgebra, H, G) -> VectorField:
    """``X_{H,G}`` for Nambu's canonical triplets: ``{f, H, G} = sum_t d(f, H, G)/d(x_3t+1, x_3t+2, x_3t+3)``.

    The bracket on ``N = 3n`` coordinates is the sum of the 3x3 Jacobians over the
    consecutive triplets ``(x1, x2, x3), (x4, x5, x6), ...``; for ``n >= 2`` it does
    not satisfy the fundamental identity (Nambu 1973, Sect. III; Horikoshi, Sect. 6).

    Examples
    --------
    >>> import sympy
    >>> x = sympy.symbols("x1:7")
    >>> A = PolynomialAlgebra(x)
    >>> triplet_field(A, x[1] + x[4], x[2] + x[5]).to_sympy()
    (1, 0, 0, 1, 0, 0)
    """
    n = algebra.n
    if n % 3:
        raise NambuBCHError(f"canonical triplets need N = 3n coordinates, got N = {n}")
    gH, gG = _gradient(algebra, H), _gradient(algebra, G)
    components = []
    for i in range(n):
        t = 3 * (i // 3)
        local = [algebra.ring.one if j == i else algebra.zero for j in range(t, t + 3)]
        components.append(_determinant(algebra, [local, gH[t:t + 3], gG[t:t + 3]]))
    return VectorField(algebra, components)
