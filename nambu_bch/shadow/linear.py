"""Exact sparse linear algebra for the shadow-Hamiltonian equations: solve, kernel, normal forms, certificates.

Both routes reduce to an affine system ``L x = b`` over the coefficient field
``K = QQ(parameters)`` (columns = unknown monomial coefficients of the
corrections, and affine weights in the FI route; rows = coordinates of a field
or of a formal sum).  Everything here is sympy ``DomainMatrix`` arithmetic
over ``K`` -- rref, nullspace -- never ``sympy.solve``.

* :func:`solve_affine` returns a particular solution and a kernel basis of
  ``L``, or, when ``b`` is not in the image, a *certificate*: a left null
  vector ``y`` (``y L = 0``) with ``y b != 0``.  Such a ``y`` is a linear
  functional that annihilates every field the ansatz can produce but not the
  right-hand side, so it proves that no solution exists within the ansatz.
* :func:`normal_form` reduces a solution modulo the kernel with a column
  priority: the result is the unique solution that is zero on the
  highest-priority columns the kernel can clear.  The package's
  parametrisation of shadow families is built from two such normal forms
  (see :mod:`nambu_bch.shadow.direct_route`).

References
----------
sympy ``DomainMatrix`` (``sympy/polys/matrices``); Horikoshi, Sect. 4.2
(the identification ``X_eff = X_{H_S,G_S}``, Eq. L2, is linear order by order).
"""

from __future__ import annotations

from dataclasses import dataclass

from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.sdm import SDM


@dataclass(frozen=True)
class AffineSolution:
    """Result of :func:`solve_affine`.

    Attributes
    ----------
    consistent : bool
    particular : list of dict or None
        One sparse solution ``{column: value}`` per right-hand side (free columns zero).
    kernel : list of dict
        A basis of ``ker L`` (sparse vectors), one per free column.
    certificate : dict or None
        ``{row: value}`` with ``y L = 0`` and ``y b_k != 0`` for the first failing ``k``.
    failing_rhs : int or None
    """

    consistent: bool
    particular: list | None
    kernel: list
    certificate: dict | None
    failing_rhs: int | None
    pivots: tuple


def _sdm(rows: dict, nrows: int, ncols: int, domain) -> DomainMatrix:
    return DomainMatrix.from_rep(SDM({i: dict(r) for i, r in rows.items() if r}, (nrows, ncols), domain))


def solve_affine(columns: list, rhs: list, nrows: int, domain) -> AffineSolution:
    """Solve ``L x = b_k`` for every ``k`` exactly; ``L`` given by sparse columns.

    Parameters
    ----------
    columns : list of dict ``{row: value}``
        The columns of ``L`` (values in ``domain``).
    rhs : list of dict ``{row: value}``
        The right-hand sides ``b_k``.
    nrows : int
    domain : sympy domain (``QQ`` or ``QQ(params)``)

    Returns
    -------
    AffineSolution

    Examples
    --------
    >>> from sympy.polys.domains import QQ
    >>> S = solve_affine([{0: QQ(1)}, {0: QQ(1)}], [{0: QQ(2)}], 1, QQ)
    >>> S.consistent, {c: int(v) for c, v in S.particular[0].items()}, [{c: int(v) for c, v in k.items()} for k in S.kernel]
    (True, {0: 2}, [{1: 1, 0: -1}])
    >>> {r: int(v) for r, v in solve_affine([{0: QQ(1)}], [{1: QQ(1)}], 2, QQ).certificate.items()}
    {1: 1}
    """
    ncols = len(columns)
    rows: dict = {}
    for j, col in enumerate(columns):
        for i, v in col.items():
            if v:
                rows.setdefault(i, {})[j] = v
    for k, b in enumerate(rhs):
        for i, v in b.items():
            if v:
                rows.setdefault(i, {})[ncols + k] = v
    M = _sdm(rows, nrows, ncols + len(rhs), domain)
    R, pivots = M.rref()
    R = R.rep.to_sdm()
    col_pivots = [p for p in pivots if p < ncols]
    pivot_row = {p: r for r, p in enumerate(pivots)}
    free = [j for j in range(ncols) if j not in pivot_row]
    kernel = []
    for f in free:
        vec = {f: domain.one}
        for p in col_pivots:
            v = R.get(pivot_row[p], {}).get(f)
            if v:
                vec[p] = -v
        kernel.append(vec)
    bad = [p - ncols for p in pivots if p >= ncols]
    if bad:
        k = bad[0]
        return AffineSolution(False, None, kernel, _certificate(columns, rhs[k], nrows, domain), k, tuple(col_pivots))
    particular = []
    for k in range(len(rhs)):
        sol = {}
        for p in col_pivots:
            v = R.get(pivot_row[p], {}).get(ncols + k)
            if v:
                sol[p] = v
        particular.append(sol)
    return AffineSolution(True, particular, kernel, None, None, tuple(col_pivots))


def _certificate(columns, b, nrows, domain) -> dict:
    """A sparsest-found left null vector ``y`` of ``L`` with ``y . b != 0``."""
    rows = {j: {i: v for i, v in col.items() if v} for j, col in enumerate(columns)}
    LT = _sdm(rows, len(columns), nrows, domain)
    R, pivots = LT.rref()
    R = R.rep.to_sdm()
    pivot_row = {p: r for r, p in enumerate(pivots)}
    best = None
    for f in range(nrows):
        if f in pivot_row:
            continue
        y = {f: domain.one}
        for p in pivots:
            v = R.get(pivot_row[p], {}).get(f)
            if v:
                y[p] = -v
        value = sum((y[i] * b[i] for i in y if i in b), domain.zero)
        if value and (best is None or len(y) < len(best)):
            best = y
    return best


def normal_form(vector: dict, kernel: list, priority: list, domain) -> dict:
    """Reduce ``vector`` modulo ``span(kernel)`` so that it vanishes on the highest-priority columns possible.

    Parameters
    ----------
    vector : dict ``{column: value}``
    kernel : list of dict
    priority : list of int
        Columns, most important to clear first.
    domain : sympy domain

    Returns
    -------
    dict -- ``vector + k`` for the unique ``k`` in the span that clears the
    greedy-lexicographically first set of priority columns.

    Examples
    --------
    >>> from sympy.polys.domains import QQ
    >>> {c: int(v) for c, v in normal_form({0: QQ(2)}, [{0: QQ(-1), 1: QQ(1)}], [0, 1], QQ).items()}
    {1: 2}
    """
    if not kernel:
        return dict(vector)
    position = {c: i for i, c in enumerate(priority)}
    rows = {r: {position[c]: v for c, v in vec.items() if v} for r, vec in enumerate(kernel)}
    K = _sdm(rows, len(kernel), len(priority), domain)
    R, pivots = K.rref()
    R = R.rep.to_sdm()
    x = {position[c]: v for c, v in vector.items() if v}
    for r, p in enumerate(pivots):
        v = x.get(p)
        if v:
            for c, w in R.get(r, {}).items():
                x[c] = x.get(c, domain.zero) - v * w
                if not x[c]:
                    del x[c]
    return {priority[c]: v for c, v in x.items()}


def kernel_rref(kernel: list, priority: list, domain) -> list:
    """A basis of ``span(kernel)`` in reduced echelon form for the column order ``priority``."""
    if not kernel:
        return []
    position = {c: i for i, c in enumerate(priority)}
    rows = {r: {position[c]: v for c, v in vec.items() if v} for r, vec in enumerate(kernel)}
    R, pivots = _sdm(rows, len(kernel), len(priority), domain).rref()
    R = R.rep.to_sdm()
    return [{priority[c]: v for c, v in R.get(r, {}).items()} for r in range(len(pivots))]


def rank(vectors: list, ncols: int, domain) -> int:
    """Rank of sparse row vectors."""
    if not vectors:
        return 0
    rows = {r: {c: v for c, v in vec.items() if v} for r, vec in enumerate(vectors)}
    return len(_sdm(rows, len(vectors), ncols, domain).rref()[1])
