"""Exact sparse elimination over a field: affine solve with certificate, nullspace, rank, echelon and normal forms.

The one place in the package where linear systems are eliminated.  The shadow
routes reduce to an affine system ``L x = b`` over the coefficient field
``K = QQ(parameters)`` (columns = unknown monomial coefficients of the
corrections, and affine weights in the FI route; rows = coordinates of a field
or of a formal sum); the invariant search needs the nullspace of ``Phi - id``
and ranks; the Liouville-term canonicaliser needs the rank of integer
exponent vectors.  Everything here is sympy ``DomainMatrix`` arithmetic
(sparse Gauss-Jordan ``rref``) over ``K``, never ``sympy.solve``.  Vectors are
sparse dicts ``{index: value}`` with values in the domain.

* :func:`solve_affine` returns a particular solution and a kernel basis of
  ``L``, or, when ``b`` is not in the image, a *certificate*: a left null
  vector ``y`` (``y L = 0``) with ``y b != 0``.  Such a ``y`` is a linear
  functional that annihilates every field the ansatz can produce but not the
  right-hand side, so it proves that no solution exists within the ansatz.
  ``certificate=False`` skips that (second) elimination.
* :func:`nullspace` and :func:`rank` of sparse row vectors.
* :func:`normal_form` reduces a solution modulo the kernel with a column
  priority: the result is the unique solution that is zero on the
  highest-priority columns the kernel can clear.  The package's
  parametrisation of shadow families is built from two such normal forms
  (see :mod:`nambu_bch.shadow.direct_route`); :func:`kernel_rref` is the
  reduced echelon basis for such a priority.
* :class:`Echelon` is the incremental reduced echelon form used to build
  bases one vector at a time (the FI route's hulls).

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


def _kernel(R, pivots, ncols: int, domain) -> list:
    """The kernel basis read off a reduced echelon form ``R`` (an SDM) with ``pivots``: one vector per free column."""
    pivot_row = {p: r for r, p in enumerate(pivots)}
    col_pivots = [p for p in pivots if p < ncols]
    kernel = []
    for f in range(ncols):
        if f in pivot_row:
            continue
        vec = {f: domain.one}
        for p in col_pivots:
            v = R.get(pivot_row[p], {}).get(f)
            if v:
                vec[p] = -v
        kernel.append(vec)
    return kernel


def solve_affine(columns: list, rhs: list, nrows: int, domain, *, certificate: bool = True) -> AffineSolution:
    """Solve ``L x = b_k`` for every ``k`` exactly; ``L`` given by sparse columns.

    Parameters
    ----------
    columns : list of dict ``{row: value}``
        The columns of ``L`` (values in ``domain``).
    rhs : list of dict ``{row: value}``
        The right-hand sides ``b_k``.
    nrows : int
    domain : sympy domain (``QQ`` or ``QQ(params)``)
    certificate : bool
        Look for a left null vector when inconsistent (a second elimination, of ``L^T``);
        with ``False`` the result's ``certificate`` is ``None``.

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
    kernel = _kernel(R, pivots, ncols, domain)
    bad = [p - ncols for p in pivots if p >= ncols]
    if bad:
        k = bad[0]
        y = _certificate(columns, rhs[k], nrows, domain) if certificate else None
        return AffineSolution(False, None, kernel, y, k, tuple(col_pivots))
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
    """Rank of sparse row vectors ``{column: value}`` (columns ``0..ncols-1``).

    >>> from sympy.polys.domains import QQ
    >>> rank([{0: QQ(1), 1: QQ(2)}, {0: QQ(2), 1: QQ(4)}, {2: QQ(1)}], 3, QQ)
    2
    """
    if not vectors:
        return 0
    rows = {r: {c: v for c, v in vec.items() if v} for r, vec in enumerate(vectors)}
    return len(_sdm(rows, len(vectors), ncols, domain).rref()[1])


def nullspace(rows: dict, nrows: int, ncols: int, domain) -> list:
    """A basis of ``{x : M x = 0}`` for the sparse matrix ``M = {row: {column: value}}``, one vector per free column.

    The vector of free column ``f`` is ``1`` at ``f``, zero at the other free
    columns and minus the reduced echelon entries at the pivots (Gauss-Jordan over the field).

    >>> from sympy.polys.domains import QQ
    >>> [{c: int(v) for c, v in k.items()} for k in nullspace({0: {0: QQ(1), 1: QQ(1)}}, 1, 3, QQ)]
    [{1: 1, 0: -1}, {2: 1}]
    """
    R, pivots = _sdm(rows, nrows, ncols, domain).rref()
    return _kernel(R.rep.to_sdm(), pivots, ncols, domain)


class Echelon:
    """Incremental reduced row echelon form of sparse vectors ``{key: value}`` over a field.

    >>> from sympy.polys.domains import QQ
    >>> E = Echelon(QQ)
    >>> E.insert({"x": QQ(1), "y": QQ(2)}), E.insert({"x": QQ(2), "y": QQ(4)}), E.insert({"y": QQ(1)})
    (True, False, True)
    >>> len(E.rows)
    2
    """

    def __init__(self, domain):
        self.domain = domain
        self.rows: dict = {}  # pivot key -> row (pivot coefficient one, no other pivot keys)

    def reduce(self, vec: dict) -> dict:
        v = {k: c for k, c in vec.items() if c}
        for p in [k for k in v if k in self.rows]:
            c = v.get(p)
            if not c:
                continue
            for k, r in self.rows[p].items():
                s = v.get(k, self.domain.zero) - c * r
                if s:
                    v[k] = s
                else:
                    v.pop(k, None)
        return v

    def insert(self, vec: dict) -> bool:
        """Add ``vec`` if independent of the rows so far; ``True`` if it was."""
        v = self.reduce(vec)
        if not v:
            return False
        p = min(v)
        inv = self.domain.one / v[p]
        v = {k: c * inv for k, c in v.items()}
        for q, row in self.rows.items():
            c = row.get(p)
            if c:
                for k, r in v.items():
                    s = row.get(k, self.domain.zero) - c * r
                    if s:
                        row[k] = s
                    else:
                        row.pop(k, None)
        self.rows[p] = v
        return True
