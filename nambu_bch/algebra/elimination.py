"""Exact sparse elimination over a field: affine solve with certificate, nullspace, rank, echelon and normal forms.

The one place in the package where linear systems are eliminated.  The shadow
routes reduce to an affine system ``L x = b`` over the coefficient field
``K = QQ(parameters)`` (columns = unknown monomial coefficients of the
corrections, and affine weights in the FI route; rows = coordinates of a field
or of a formal sum); the invariant search needs the nullspace of ``Phi - id``
and ranks; the Liouville-term canonicaliser needs the rank of integer
exponent vectors.  Everything here is an exact reduced row echelon form
(:func:`_rref`), never ``sympy.solve``.  Vectors are sparse dicts
``{index: value}`` with values in the domain.

The echelon form is unique, so its routes are interchangeable and give identical
results: the matrix is split into the blocks of its sparsity graph; over ``QQ`` a sparse block (at most
:data:`SPARSE_ROW_ENTRIES` entries a row) is first eliminated sparsely (:func:`_rref_sparse`, in column order, within
a budget of entry updates), otherwise, or past that budget, densely by python-flint's ``fmpq_mat`` (a dependency;
``NAMBU_BCH_DISABLE_FLINT=1`` switches it off), without it multi-modularly in numpy with an exact check of the
result (:mod:`nambu_bch.algebra.modular_rref`, blocks of at least :data:`MODULAR_MIN` rows and columns); over ``QQ<theta>`` or
``QQ<theta>(parameters)`` (triple-jump coefficients) a matrix with entries in the base
field is eliminated there, right-hand sides split along ``1, theta, ..``
(:class:`_AlgebraicSplit`); everything else is sympy's sparse Gauss-Jordan
``DomainMatrix.rref`` over the field.  ``FAST_PATHS = False`` keeps to the last one.

* :func:`solve_affine` returns a particular solution and a kernel basis of
  ``L``, or, when ``b`` is not in the image, a *certificate*: a left null
  vector ``y`` (``y L = 0``) with ``y b != 0``.  Such a ``y`` is a linear
  functional that annihilates every field the ansatz can produce but not the
  right-hand side, so it proves that no solution exists within the ansatz.
  ``certificate=False`` skips that (second) elimination.
* :func:`nullspace` and :func:`rank` of a :class:`SparseMatrix` (the one matrix type all three take).
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
sympy ``DomainMatrix`` (``sympy/polys/matrices``); FLINT ``fmpq_mat_rref``; Markowitz (1957) and Duff, Erisman &
Reid, *Direct Methods for Sparse Matrices*, ch. 7 (the sparse pass); Cabay (1971) and von zur Gathen &
Gerhard, *Modern Computer Algebra*, ch. 5 (the modular route); Horikoshi, Sect. 4.2
(the identification ``X_eff = X_{H_S,G_S}``, Eq. L2, is linear order by order).
"""

from __future__ import annotations

from dataclasses import dataclass

from sympy.polys.domains import QQ
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.sdm import SDM

from ..errors import NambuBCHError
from . import _flint
from .fields import CoefficientField


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


@dataclass(frozen=True)
class SparseMatrix:
    """A sparse matrix over a field, the one shape :func:`solve_affine`, :func:`nullspace` and :func:`rank` take.

    Attributes
    ----------
    rows : dict ``{row: {column: value}}`` -- the non-zero entries (zero values and empty rows left out)
    nrows, ncols : int -- the shape; every row index lies in ``range(nrows)``, every column in ``range(ncols)``
    domain : sympy domain -- the field of the values (``QQ``, ``QQ(params)``, ``QQ<theta>`` ..)

    Build it from row vectors (:meth:`from_rows`) or from column vectors (:meth:`from_columns`, the unknowns of
    an ansatz); the constructor checks the shape, so an index outside it fails here, in one line, and not
    inside an elimination.

    >>> M = SparseMatrix.from_columns([{0: QQ(1)}, {0: QQ(2), 1: QQ(0)}], 2, QQ)
    >>> M.rows, M.nrows, M.ncols
    ({0: {0: 1, 1: 2}}, 2, 2)
    >>> rank(M)
    1
    """

    rows: dict
    nrows: int
    ncols: int
    domain: object

    def __post_init__(self):
        for name in ("nrows", "ncols"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise NambuBCHError(f"SparseMatrix: {name} must be a non-negative integer, got {value!r}")
        clean = {}
        for i, row in self.rows.items():
            if not (isinstance(i, int) and 0 <= i < self.nrows):
                raise NambuBCHError(f"SparseMatrix: row index {i!r} outside 0..{self.nrows - 1}")
            kept = {j: v for j, v in row.items() if v}
            if any(not (isinstance(j, int) and 0 <= j < self.ncols) for j in kept):
                bad = next(j for j in kept if not (isinstance(j, int) and 0 <= j < self.ncols))
                raise NambuBCHError(f"SparseMatrix: column index {bad!r} (row {i}) outside 0..{self.ncols - 1}")
            if kept:
                clean[i] = kept
        object.__setattr__(self, "rows", clean)

    @classmethod
    def from_rows(cls, vectors, ncols: int, domain) -> "SparseMatrix":
        """The matrix whose ``r``-th row is ``vectors[r]`` (a sparse dict ``{column: value}``)."""
        return cls(dict(enumerate(vectors)), len(vectors), ncols, domain)

    @classmethod
    def from_columns(cls, columns, nrows: int, domain) -> "SparseMatrix":
        """The matrix whose ``j``-th column is ``columns[j]`` (a sparse dict ``{row: value}``)."""
        rows: dict = {}
        for j, col in enumerate(columns):
            for i, v in col.items():
                if v:
                    rows.setdefault(i, {})[j] = v
        return cls(rows, nrows, len(columns), domain)

    def columns(self) -> list:
        """The columns as sparse dicts ``{row: value}``, one per column."""
        cols = [{} for _ in range(self.ncols)]
        for i, row in self.rows.items():
            for j, v in row.items():
                cols[j][i] = v
        return cols


def _require_matrix(name: str, matrix) -> None:
    """Refuse, in one line, anything but a :class:`SparseMatrix` (the one matrix shape the elimination takes)."""
    if not isinstance(matrix, SparseMatrix):
        raise NambuBCHError(f"{name}: expects a SparseMatrix (SparseMatrix.from_rows / from_columns), "
                            f"got {type(matrix).__name__}")


def _sdm(rows: dict, nrows: int, ncols: int, domain) -> DomainMatrix:
    return DomainMatrix.from_rep(SDM({i: dict(r) for i, r in rows.items() if r}, (nrows, ncols), domain))


#: Largest matrix (rows x columns) eliminated densely by python-flint's ``fmpq_mat``; larger ones stay sparse.
FLINT_DENSE_LIMIT = 4_000_000

#: Without python-flint, ``QQ`` blocks with at least this many non-zero rows and columns (and at most
#: :data:`FLINT_DENSE_LIMIT` entries) are eliminated multi-modularly (:mod:`nambu_bch.algebra.modular_rref`);
#: smaller ones by sympy's sparse ``DomainMatrix.rref`` (faster there: 0.2 vs 0.4 ms at 22 x 16, 3.5 vs 1.2 ms at
#: 44 x 32, 31 vs 4 ms at 89 x 64, random sparse entries p/q with |p| <= 9, q <= 6).
MODULAR_MIN = 24

#: ``False`` sends every elimination to sympy's sparse ``DomainMatrix.rref`` over the given domain (the
#: reference path the tests compare the faster routes with).
FAST_PATHS = True

def flint_available() -> bool:
    """python-flint is installed and not disabled by ``NAMBU_BCH_DISABLE_FLINT=1`` (read at every call).

    python-flint is a dependency; when it is missing or switched off every elimination runs on the
    package's multi-modular RREF or sympy's ``DomainMatrix``, with the same results (both paths are tested).
    """
    return _flint.available()


def _rref_flint_qq(rows: dict, nrows: int, ncols: int):
    """Reduced echelon form over ``QQ`` with flint's dense ``fmpq_mat.rref`` (exact, fraction-free inside)."""
    native = _flint.qq_is_fmpq(QQ.dtype)  # sympy's ground types are flint: no conversion
    fmpq = _flint.fmpq
    M = _flint.fmpq_mat(nrows, ncols)
    for i, row in rows.items():
        for j, v in row.items():
            M[i, j] = v if native else fmpq(v)
    R, rank = M.rref()
    # Read only what the reduced form can hold: a row's pivot is its first non-zero entry, and besides the
    # pivot (one) a row has entries only in the non-pivot columns to its right.  Reading all rank x ncols
    # entries (R.entries()) makes a Python object of every zero and took about as long as the rref itself.
    pivots, j = [], 0
    for i in range(rank):
        while not R[i, j]:
            j += 1
        pivots.append(j)
    pivot_set = set(pivots)
    free = [c for c in range(ncols) if c not in pivot_set]
    one = QQ.one
    out = {}
    for i, p in enumerate(pivots):
        row = {p: one}
        for c in free:
            if c > p:
                v = R[i, c]
                if v:
                    row[c] = v if native else QQ(int(v.p), int(v.q))
        out[i] = row
    return out, tuple(pivots)


class _AlgebraicSplit:
    """``K = QQ<theta>`` or ``QQ<theta>(params)`` as ``k`` copies of its base ``B = QQ`` or ``QQ(params)``.

    ``1, theta, .., theta^(k-1)`` (``k`` the degree of the minimal polynomial of
    ``theta``, irreducible over ``B`` too) is a basis of ``K`` over ``B``.  Hence a matrix
    with entries in ``B`` has the same reduced echelon form over ``B`` and over ``K``
    (Gauss-Jordan never leaves ``B``), and ``L x = b`` with ``L`` over ``B`` and
    ``b = sum_i theta^i b_i`` is the ``k`` systems ``L x_i = b_i``, ``x = sum_i theta^i x_i``
    (same pivots, same free columns).  This replaces arithmetic in ``K`` -- a polynomial gcd
    over an algebraic number field at every operation -- by arithmetic in ``B``.
    """

    def __init__(self, domain, algebraic, base):
        self.domain, self.algebraic, self.base = domain, algebraic, base
        self.k = len(algebraic.mod.to_list()) - 1  # ANP coefficients are on powers of the primitive element
        self.params = not domain.is_AlgebraicField
        self._factors: dict = {}

    @classmethod
    def of(cls, domain):
        field = CoefficientField.recognise(domain)
        if field is None or not field.is_algebraic:
            return None
        return cls(domain, field.ground, QQ.frac_field(*field.parameters) if field.parameters else QQ)

    def split(self, v):
        """``[b_0, .., b_{k-1}]`` in ``B`` with ``v = sum_i theta^i b_i``, or ``None`` (denominator not in ``B``)."""
        if not self.params:
            rep = v.to_list()
            return [QQ.convert(rep[-1 - i]) if i < len(rep) else QQ.zero for i in range(self.k)]
        num, den = v.numer, v.denom
        dB = {}
        for m, c in den.items():
            rep = c.to_list()
            if len(rep) > 1:
                return None
            dB[m] = rep[0]
        field = self.base.field
        den_b = field.ring.from_dict(dB)
        parts = [{} for _ in range(self.k)]
        for m, c in num.items():
            rep = c.to_list()
            for i in range(len(rep)):
                if rep[-1 - i]:
                    parts[i][m] = rep[-1 - i]
        return [field.new(field.ring.from_dict(p), den_b) if p else self.base.zero for p in parts]

    def split_rows(self, rows: dict):
        """The rows over ``B`` when every entry lies in ``B``; else ``None``."""
        out = {}
        for i, row in rows.items():
            new = {}
            for j, v in row.items():
                parts = self.split(v)
                if parts is None or any(parts[1:]):
                    return None
                if parts[0]:
                    new[j] = parts[0]
            out[i] = new
        return out

    def join(self, parts):
        """``sum_i theta^i parts[i]`` in ``K`` (``parts`` in ``B``), built as one fraction over ``B``'s denominators.

        The common denominator ``d`` lies in ``B``; rational common factors of ``d`` and the
        numerator's components are divided out over ``B``.  When every irreducible factor of
        ``d`` over ``QQ`` is linear (irreducible over ``K`` too) nothing more can cancel and the
        fraction is used as it is; otherwise sympy cancels it over ``K``.
        """
        A, K = self.algebraic, self.domain
        if not self.params:
            return A.new([QQ.convert(parts[i]) if parts[i] else QQ.zero for i in reversed(range(self.k))])
        nz = [(i, p) for i, p in enumerate(parts) if p]
        if not nz:
            return K.zero
        if len(nz) == 1 and nz[0][0] == 0:
            return self.lift(nz[0][1])
        d = nz[0][1].denom
        for _, p in nz[1:]:
            d = d.lcm(p.denom)
        nums = {i: p.numer * d.exquo(p.denom) for i, p in nz}
        g = d
        for num in nums.values():
            g = g.gcd(num)
        if g != 1:
            d = d.exquo(g)
            nums = {i: num.exquo(g) for i, num in nums.items()}
        lc = d.LC
        if lc != 1:  # a monic denominator, as sympy's own arithmetic in K leaves it
            d = d.quo_ground(lc)
            nums = {i: num.quo_ground(lc) for i, num in nums.items()}
        coeffs: dict = {}
        for i, num in nums.items():
            for m, c in num.items():
                coeffs.setdefault(m, [QQ.zero] * self.k)[i] = c
        field = K.field
        numer = field.ring.from_dict({m: A.new(v[::-1]) for m, v in coeffs.items()})
        denom = field.ring.from_dict({m: A.new([c]) for m, c in d.items()})
        if self._linear_factors(d):
            return field.raw_new(numer, denom)
        return field.new(numer, denom)

    def _linear_factors(self, d) -> bool:
        key = tuple(sorted(d.items()))
        if key not in self._factors:
            self._factors[key] = all(max(map(sum, f.monoms())) <= 1 for f, _ in d.factor_list()[1])
        return self._factors[key]

    def lift(self, v):
        """``v`` in ``B`` as an element of ``K``: the same fraction (coprime over ``QQ``, hence over ``K``),
        denominator made monic."""
        if not self.params:
            return self.algebraic.convert(v)
        A, field = self.algebraic, self.domain.field
        lc = v.denom.LC
        coeffs = lambda p: {m: A.new([q / lc]) for m, q in p.items()}  # noqa: E731
        return field.raw_new(field.ring.from_dict(coeffs(v.numer)), field.ring.from_dict(coeffs(v.denom)))


def _blocks(live: dict, link: int) -> dict:
    """The rows of ``{row: {column: value}}`` (no zero entries) grouped by the connected components of the graph
    joining a row and a column ``< link`` with a non-zero entry: ``{component: [rows]}`` (key ``None``: rows
    with entries in columns ``>= link`` only)."""
    parent = list(range(link))
    first = {}  # row -> one of its columns < link (None: none)
    for i, r in live.items():  # union-find with path halving, inlined (a call per entry cost more than the rest)
        root = None
        for j in r:
            if j >= link:
                continue
            while parent[j] != j:
                parent[j] = parent[parent[j]]
                j = parent[j]
            if root is None:
                root = j
            elif j != root:
                parent[j] = root
        first[i] = root
    groups: dict = {}
    for i, j in first.items():
        if j is not None:
            while parent[j] != j:
                parent[j] = parent[parent[j]]
                j = parent[j]
        groups.setdefault(j, []).append(i)
    return groups


#: Cost of one field operation over ``QQ(parameters)`` (a rational function, gcds) in units of one over ``QQ``
#: (flint or the modular route), measured on the rigid body with symbolic I: order 8, 572 unknowns, estimate 4.7e5,
#: 2.7 s of ``solve_affine`` over ``QQ(I1, I2, I3)`` (2.9e-6 s per unit) against 1.2e-9 s per unit over ``QQ`` (N = 4
#: at h^6: estimate 2.1e8, 0.5 s per solve).  ``QQ<theta>`` is eliminated over ``QQ`` (:class:`_AlgebraicSplit`).
FIELD_WEIGHT = 2500


def elimination_cost(columns: list, nrows: int, domain=QQ) -> int:
    """An estimate of the work of :func:`solve_affine` on the matrix with these sparse columns (``{row: value}``).

    The matrix is eliminated block by block (:func:`_rref`); a dense Gauss-Jordan elimination of an
    ``r x c`` block takes at most ``min(r, c)`` pivot steps of ``r c`` operations each, so the estimate is
    ``sum over blocks of r c min(r, c)`` operations over ``QQ``, times :data:`FIELD_WEIGHT` over a field of
    parameters (the bounded-work guard of the direct route compares it with its budget before anything is
    eliminated).

    >>> elimination_cost([{0: QQ(1)}, {0: QQ(2), 1: QQ(1)}, {2: QQ(1)}], 3)   # blocks 2 x 2 and 1 x 1
    9
    """
    rows: dict = {}
    for j, col in enumerate(columns):
        for i, v in col.items():
            if v:
                rows.setdefault(i, {})[j] = v
    total = 0
    for members in _blocks(rows, len(columns)).values():
        r, c = len(members), len({j for i in members for j in rows[i]})
        total += r * c * min(r, c)
    field = CoefficientField.recognise(domain)
    return total if field is not None and field.is_number_field else total * FIELD_WEIGHT


def signed_sums(sums: dict, domain) -> dict | None:
    """``{key: sum(s * v for s, v in pairs)}`` for ``sums = {key: [(s, v), ..]}`` (``s`` integers), computed over the base
    field when ``domain`` is ``QQ<theta>(params)``; ``None`` for any other domain (the caller adds in ``domain``).

    In ``K = B<theta>`` with ``B = QQ(params)`` every addition cancels a fraction with a polynomial gcd over
    the number field (sympy's subresultants: seconds for one sum of two rigid-body coefficients).  On the
    basis ``1, theta, ..`` over ``B`` (:class:`_AlgebraicSplit`) a sum is ``k`` sums in ``B`` (gcds over ``QQ``),
    joined into ``K`` once per key.  Zero sums are left out.  ``None`` also when a value does not split (a
    denominator outside ``B``).

    >>> import sympy
    >>> K = QQ.algebraic_field(sympy.cbrt(2)).frac_field(sympy.Symbol("a"))
    >>> t, a = K.from_sympy(sympy.cbrt(2)), K.from_sympy(sympy.Symbol("a"))
    >>> out = signed_sums({0: [(1, t / a), (-1, 1 / a)], 1: [(1, a), (-1, a)]}, K)
    >>> list(out), out[0] == (t - 1) / a
    ([0], True)
    """
    split = _AlgebraicSplit.of(domain) if FAST_PATHS else None
    if split is None or not split.params:
        return None
    out = {}
    base = split.base
    for key, pairs in sums.items():
        acc = [base.zero] * split.k
        for sign, v in pairs:
            if not v:
                continue
            parts = split.split(v)
            if parts is None:
                return None
            for i, part in enumerate(parts):
                if part:
                    acc[i] = acc[i] + part if sign == 1 else acc[i] + sign * part
        value = split.join(acc)
        if value:
            out[key] = value
    return out


def _rref(rows: dict, nrows: int, ncols: int, domain, lift: bool = True, link: int | None = None):
    """The reduced row echelon form of ``{row: {column: value}}``, block by block: ``(R, pivots)``.

    The rows and columns fall into blocks, the connected components of the graph in which a
    row and a column ``< link`` are joined when the entry is non-zero; the reduced echelon form
    of a block-diagonal matrix is the union of those of its blocks (rows ordered by pivot),
    each computed by :func:`_rref_block`.  Columns ``>= link`` (right-hand sides) join no blocks:
    they are carried along in every block, so that a pivot in such a column means that the
    block's part of that right-hand side is not in the span of the block's columns, and ``R``
    is then no longer one echelon form (two blocks may have their pivots in the same column).
    """
    if not FAST_PATHS:
        return _rref_block(rows, nrows, ncols, domain, lift)
    link = ncols if link is None else link
    live = {i: {j: v for j, v in r.items() if v} for i, r in rows.items()}
    live = {i: r for i, r in live.items() if r}
    groups = _blocks(live, link)
    if len(groups) <= 1:
        return _rref_block(live, nrows, ncols, domain, lift)
    out = []
    for members in groups.values():
        cols = {j for i in members for j in live[i]}
        sparse = _sparse_first({i: live[i] for i in members}, len(members), len(cols), domain)
        if sparse is not None:  # the sparse pass keeps the matrix's own column indices: nothing to renumber
            out += sparse[0].values()
            continue
        cols = sorted(cols)
        index = {c: k for k, c in enumerate(cols)}
        block = {k: {index[j]: v for j, v in live[i].items()} for k, i in enumerate(members)}
        R, _ = _rref_block(block, len(members), len(cols), domain, lift)
        out += [{cols[j]: v for j, v in row.items()} for row in R.values()]
    out.sort(key=min)
    return dict(enumerate(out)), tuple(min(row) for row in out)


#: The sparse elimination (:func:`_rref_sparse`) runs first on a ``QQ`` block of ``r`` rows, ``c`` columns and ``e``
#: non-zero entries when the rows hold at most :data:`SPARSE_ROW_ENTRIES` entries on average, and gives up after
#: ``r c min(r, c) / SPARSE_RATIO + 4 e`` entry updates (a dense elimination's operation count over this ratio, plus
#: a few per entry); the block then goes to the dense route.  One entry update in Python costs about 1 us, one
#: operation of flint's dense ``fmpq_mat.rref`` 1 to 4 ns.  Measured on every ``QQ`` block of the direct route for
#: Lotka-Volterra h^12 (3 to 5 entries a row; sparse 0.17 s, dense 0.45 s), the N = 4 single split h^6 (10 to 15 a row;
#: the sparse pass needs 1/180 to 1/340 of the dense count and loses: 1.5 s against 0.68 s) and the rigid body
#: I = (1, 2, 3) h^10 (small blocks; 0.08 s against 0.05 s), these two constants gave 0.17 s, 0.68 s and 0.08 s.
#: ``SPARSE_RATIO = None`` switches the sparse pass off, ``0`` runs it to the end on every ``QQ`` block.
SPARSE_RATIO = 1500
SPARSE_ROW_ENTRIES = 6


def _sparse_first(rows: dict, nrows: int, ncols: int, domain):
    """:func:`_rref_sparse` of a ``QQ`` block (no zero entries) when its rows are sparse enough and it finishes
    within its budget (:data:`SPARSE_RATIO`, :data:`SPARSE_ROW_ENTRIES`); ``None`` otherwise (then the dense route)."""
    if not (FAST_PATHS and domain.is_QQ and SPARSE_RATIO is not None and nrows * ncols <= FLINT_DENSE_LIMIT):
        return None
    entries = sum(map(len, rows.values()))
    if SPARSE_RATIO == 0:
        return _rref_sparse(rows, ncols, domain, None)
    if entries > SPARSE_ROW_ENTRIES * len(rows):
        return None
    r = len(rows)
    return _rref_sparse(rows, ncols, domain, r * ncols * min(r, ncols) // SPARSE_RATIO + 4 * entries)


def _rref_sparse(rows: dict, ncols: int, domain, budget: int | None):
    """The reduced row echelon form by sparse Gauss-Jordan in column order: ``(R, pivots)``; ``None`` past ``budget``.

    The columns are taken in increasing order; the pivot of column ``j`` is the shortest row (then the
    lowest index) among the rows not yet used whose entry at ``j`` is non-zero, and ``j`` is eliminated from the
    other such rows only (forward elimination, no fill-in above the pivots).  Taking the columns in order makes
    ``j`` a pivot exactly when it is independent of the columns before it, so the pivots are those of the
    reduced echelon form; choosing the shortest row keeps the fill-in small on the sparse matrices of the
    shadow routes.  Back substitution in the reverse order of the pivots then clears the entries above them:
    a pivot row has non-pivot entries only to the right of its pivot, and the result is the unique reduced
    echelon form (the same ``R`` as every other route, rows by pivot, entries by column).

    ``budget``: the number of entry updates (one ``a - c b``) after which the elimination stops and returns
    ``None`` (the caller then eliminates densely); ``None`` for no limit.

    References
    ----------
    Markowitz, Management Sci. 3 (1957) 255 (pivots that keep the fill-in small); Duff, Erisman & Reid,
    *Direct Methods for Sparse Matrices* (2nd ed., 2017), ch. 7 (pivoting for sparsity; here the column
    order is fixed by the echelon form and only the row is chosen).
    """
    rows = {i: dict(r) for i, r in rows.items()}
    one = domain.one
    holders: dict = {}  # column -> the rows not yet used as pivots with a non-zero entry there
    for i, row in rows.items():
        for j in row:
            holders.setdefault(j, set()).add(i)
    spent = 0
    order = []  # (pivot column, its row) in increasing column order
    for j in sorted(holders):
        candidates = holders.pop(j)
        if not candidates:
            continue
        i = min(candidates, key=lambda t: (len(rows[t]), t))
        pivot_row = rows[i]
        inv = one / pivot_row[j]
        pivot_row = rows[i] = {k: v * inv for k, v in pivot_row.items()}
        for k in pivot_row:
            if k != j:
                holders[k].discard(i)
        spent += (len(candidates) - 1) * len(pivot_row)
        if budget is not None and spent > budget:
            return None
        for t in candidates:
            if t == i:
                continue
            row = rows[t]
            _subtract_multiple(row, row.pop(j), pivot_row, j, holders, t)
        order.append((j, i))
    row_of = dict(order)
    for j, i in reversed(order):  # later pivot rows are reduced already: substituting them adds no pivot entries
        row = rows[i]
        for k in [k for k in row if k != j and k in row_of]:
            c = row.pop(k)
            below = rows[row_of[k]]
            spent += len(below)
            if budget is not None and spent > budget:
                return None
            _subtract_multiple(row, c, below, k)
    out = {n: dict(sorted(rows[i].items())) for n, (_, i) in enumerate(order)}
    return out, tuple(j for j, _ in order)


def _subtract_multiple(row: dict, c, pivot_row: dict, skip, holders=None, index=None) -> None:
    """``row <- row - c * pivot_row`` in place on every column but ``skip`` (whose entry the caller removed), zeros
    dropped; with ``holders`` (column -> the rows with a non-zero entry there) row ``index`` is kept in it."""
    for k, v in pivot_row.items():
        if k == skip:
            continue
        x = row.get(k)
        if x is None:
            row[k] = -c * v
            if holders is not None:
                holders[k].add(index)
        else:
            x = x - c * v
            if x:
                row[k] = x
            else:
                del row[k]
                if holders is not None:
                    holders[k].discard(index)


def _rref_block(rows: dict, nrows: int, ncols: int, domain, lift: bool = True):
    """The reduced row echelon form of the sparse matrix ``{row: {column: value}}``: ``(R, pivots)``.

    ``R`` is ``{row: {column: value}}`` (the ``rank`` non-zero rows, pivot entries one),
    ``pivots`` the pivot columns.  The reduced echelon form is unique, so every route gives
    the same ``R`` (:func:`_rref` calls it on each block): over ``QQ`` the sparse pass (:func:`_rref_sparse`) when
    the rows are sparse and it stays within its budget (:data:`SPARSE_RATIO`), then dense ``fmpq_mat``
    (python-flint), else
    :func:`~nambu_bch.algebra.modular_rref.rref_qq` for blocks of at least :data:`MODULAR_MIN` rows and columns; over an algebraic
    extension, the base field when every entry lies in it (:class:`_AlgebraicSplit`);
    otherwise sympy's sparse Gauss-Jordan (``DomainMatrix.rref``).  ``lift=False``: the
    values of ``R`` may be left in the base field (for callers that need the pivots only).
    """
    rows = {i: {j: v for j, v in r.items() if v} for i, r in rows.items()}
    rows = {i: r for i, r in rows.items() if r}
    if not rows:
        return {}, ()
    sparse = _sparse_first(rows, nrows, ncols, domain)
    if sparse is not None:
        return sparse
    if FAST_PATHS and domain.is_QQ and nrows * ncols <= FLINT_DENSE_LIMIT:
        if flint_available():
            return _rref_flint_qq(rows, nrows, ncols)
        if min(len(rows), ncols) >= MODULAR_MIN:
            from .modular_rref import rref_qq

            return rref_qq(rows, nrows, ncols)
    split = _AlgebraicSplit.of(domain) if FAST_PATHS else None
    if split is not None:
        base_rows = split.split_rows(rows)
        if base_rows is not None:
            R, pivots = _rref_block(base_rows, nrows, ncols, split.base)
            if not lift:  # only the pivots are wanted
                return R, pivots
            return {i: {j: split.lift(v) for j, v in r.items()} for i, r in R.items()}, pivots
    if FAST_PATHS and flint_available():
        out = _rref_flint_frac(rows, ncols, domain)
        if out is not None:
            return out
    R, pivots = _sdm(rows, nrows, ncols, domain).rref()
    return R.rep.to_sdm(), tuple(pivots)


def _rref_flint_frac(rows: dict, ncols: int, domain):
    """Over ``QQ(params)``: Gauss-Jordan on flint ``fmpz_mpoly`` fractions (:mod:`nambu_bch.algebra.frac_rref`), the
    values converted back in sympy's normal form (identical elements); ``None`` for any other domain."""
    from . import frac_rref

    ctx = frac_rref.context(domain)
    if ctx is None:
        return None
    memo: dict = {}  # by identity: hashing a rational function hashes its polynomials, costlier than converting

    def pair(v):
        p = memo.get(id(v))  # the values are alive in ``rows`` throughout, so their ids are theirs
        if p is None:
            p = memo[id(v)] = frac_rref.from_field(v, ctx)
        return p

    R, pivots = frac_rref.rref({i: {j: pair(v) for j, v in r.items()} for i, r in rows.items()}, ncols, ctx)
    return {k: {j: frac_rref.to_field(v, domain) for j, v in r.items()} for k, r in R.items()}, pivots


def _kernel(R, pivots, ncols: int, domain) -> list:
    """The kernel basis read off a reduced echelon form ``R`` (an SDM) with ``pivots``: one vector per free column."""
    pivot_set = set(pivots)
    kernel = {f: {f: domain.one} for f in range(ncols) if f not in pivot_set}
    # one pass over the rows (by pivot, as the entries of each vector are ordered), not one per free column
    for r, p in enumerate(pivots):
        if p >= ncols:
            continue
        for f, v in R.get(r, {}).items():
            vec = kernel.get(f)
            if vec is not None and v:
                vec[p] = -v
    return list(kernel.values())


def solve_affine(matrix: SparseMatrix, rhs: list, *, certificate: bool = True) -> AffineSolution:
    """Solve ``L x = b_k`` for every ``k`` exactly, ``L`` a :class:`SparseMatrix`.

    Parameters
    ----------
    matrix : SparseMatrix
        ``L`` (values in its domain, ``QQ`` or ``QQ(params)`` ..).
    rhs : list of dict ``{row: value}``
        The right-hand sides ``b_k``.
    certificate : bool
        Look for a left null vector when inconsistent (a second elimination, of ``L^T``);
        with ``False`` the result's ``certificate`` is ``None``.

    Returns
    -------
    AffineSolution

    Examples
    --------
    >>> from sympy.polys.domains import QQ
    >>> S = solve_affine(SparseMatrix.from_columns([{0: QQ(1)}, {0: QQ(1)}], 1, QQ), [{0: QQ(2)}])
    >>> S.consistent, {c: int(v) for c, v in S.particular[0].items()}, [{c: int(v) for c, v in k.items()} for k in S.kernel]
    (True, {0: 2}, [{1: 1, 0: -1}])
    >>> {r: int(v) for r, v in solve_affine(SparseMatrix.from_columns([{0: QQ(1)}], 2, QQ), [{1: QQ(1)}]).certificate.items()}
    {1: 1}
    """
    _require_matrix("solve_affine", matrix)
    nrows, domain, ncols = matrix.nrows, matrix.domain, matrix.ncols
    rows = {i: dict(r) for i, r in matrix.rows.items()}
    columns = matrix.columns()
    split = _AlgebraicSplit.of(domain) if FAST_PATHS else None
    if split is not None:
        out = _solve_split(split, rows, columns, rhs, nrows, certificate)
        if out is not None:
            return out
    for k, b in enumerate(rhs):
        for i, v in b.items():
            if v:
                rows.setdefault(i, {})[ncols + k] = v
    R, pivots = _rref(rows, nrows, ncols + len(rhs), domain, link=ncols)
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


def _solve_split(split, rows, columns, rhs, nrows, certificate):
    """:func:`solve_affine` over ``K = B<theta>`` when ``L`` lies in ``B``: one elimination over ``B`` with the
    ``k`` components of every right-hand side (:class:`_AlgebraicSplit`); ``None`` when ``L`` or a
    right-hand side does not split."""
    base_rows = split.split_rows(rows)
    if base_rows is None:
        return None
    ncols, kd = len(columns), split.k
    for k, b in enumerate(rhs):
        for i, v in b.items():
            if not v:
                continue
            parts = split.split(v)
            if parts is None:
                return None
            for t, part in enumerate(parts):
                if part:
                    base_rows.setdefault(i, {})[ncols + kd * k + t] = part
    R, pivots = _rref(base_rows, nrows, ncols + kd * len(rhs), split.base, link=ncols)
    col_pivots = [p for p in pivots if p < ncols]
    pivot_row = {p: r for r, p in enumerate(pivots)}
    kernel = [{c: split.lift(v) for c, v in vec.items()} for vec in _kernel(R, pivots, ncols, split.base)]
    bad = [(p - ncols) // kd for p in pivots if p >= ncols]
    if bad:
        k = bad[0]
        y = _certificate(columns, rhs[k], nrows, split.domain) if certificate else None
        return AffineSolution(False, None, kernel, y, k, tuple(col_pivots))
    particular = []
    for k in range(len(rhs)):
        sol = {}
        for p in col_pivots:
            row = R.get(pivot_row[p], {})
            v = split.join([row.get(ncols + kd * k + t) for t in range(kd)])
            if v:
                sol[p] = v
        particular.append(sol)
    return AffineSolution(True, particular, kernel, None, None, tuple(col_pivots))


def _certificate(columns, b, nrows, domain) -> dict:
    """A sparsest-found left null vector ``y`` of ``L`` with ``y . b != 0``."""
    rows = {j: {i: v for i, v in col.items() if v} for j, col in enumerate(columns)}
    R, pivots = _rref(rows, len(columns), nrows, domain)
    best = None
    for y in _kernel(R, pivots, nrows, domain):  # the left null space, one vector per free row index
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
    R, pivots = _rref(rows, len(kernel), len(priority), domain)
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
    R, pivots = _rref(rows, len(kernel), len(priority), domain)
    return [{priority[c]: v for c, v in R.get(r, {}).items()} for r in range(len(pivots))]


def rank(matrix: SparseMatrix) -> int:
    """Rank of a :class:`SparseMatrix` over its domain.

    >>> from sympy.polys.domains import QQ
    >>> rank(SparseMatrix.from_rows([{0: QQ(1), 1: QQ(2)}, {0: QQ(2), 1: QQ(4)}, {2: QQ(1)}], 3, QQ))
    2
    """
    _require_matrix("rank", matrix)
    rows, nrows, ncols, domain = matrix.rows, matrix.nrows, matrix.ncols, matrix.domain
    if not nrows:
        return 0
    full = _full_rank_at_a_point(rows, nrows, ncols, domain) if FAST_PATHS else None
    if full is not None:
        return full
    return len(_rref(rows, nrows, ncols, domain, lift=False)[1])


#: The points tried by :func:`_full_rank_at_a_point` (parameter values, one tuple per try).
_RANK_POINTS = ((3, 5, 7, 11, 13, 17, 19, 23), (29, 31, 37, 41, 43, 47, 53, 59))


def _full_rank_at_a_point(rows: dict, nrows: int, ncols: int, domain):
    """``min(nrows, ncols)`` when the matrix over ``QQ(params)`` has full rank at a rational point, else ``None``.

    Certified, not probabilistic: a non-zero maximal minor at a point where no entry's denominator
    vanishes is a non-zero maximal minor over ``QQ(params)``, so the rank there, ``<= min(nrows, ncols)``,
    is that bound.  A smaller rank at the point proves nothing (the caller eliminates over the field).
    The rank at the point is an elimination over ``QQ`` (no polynomial gcds).
    """
    field = CoefficientField.recognise(domain)
    if field is None or not field.is_rational_functions or len(field.parameters) > 8:
        return None
    bound = min(nrows, ncols)
    for point in _RANK_POINTS:
        values = point[:len(domain.symbols)]
        at = {}
        for i, row in rows.items():
            new = {}
            for j, v in row.items():
                den = v.denom(*values)
                if not den:
                    break
                num = v.numer(*values)
                if num:
                    new[j] = QQ.convert(num) / QQ.convert(den)
            else:
                at[i] = new
                continue
            break  # a denominator vanishes here: the next point
        else:
            if len(_rref(at, nrows, ncols, QQ, lift=False)[1]) == bound:
                return bound
            return None
    return None


def nullspace(matrix: SparseMatrix) -> list:
    """A basis of ``{x : M x = 0}`` for a :class:`SparseMatrix` ``M``, one vector per free column.

    The vector of free column ``f`` is ``1`` at ``f``, zero at the other free
    columns and minus the reduced echelon entries at the pivots (Gauss-Jordan over the field).

    >>> from sympy.polys.domains import QQ
    >>> [{c: int(v) for c, v in k.items()} for k in nullspace(SparseMatrix({0: {0: QQ(1), 1: QQ(1)}}, 1, 3, QQ))]
    [{1: 1, 0: -1}, {2: 1}]
    """
    _require_matrix("nullspace", matrix)
    rows, nrows, ncols, domain = matrix.rows, matrix.nrows, matrix.ncols, matrix.domain
    R, pivots = _rref(rows, nrows, ncols, domain)
    return _kernel(R, pivots, ncols, domain)


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
