"""The exact elimination module (nambu_bch/algebra/elimination.py): the fast routes against sympy's plain path.

The reduced row echelon form of a matrix is unique, so every route must give the same
pivots, the same particular solution (free columns zero), the same kernel basis and the
same certificate as sympy's sparse Gauss-Jordan ``DomainMatrix.rref`` over the full domain
(``FAST_PATHS = False``).  The routes under test:

* over ``QQ``, the sparse Gauss-Jordan in column order that runs first (``_rref_sparse``, within its budget of
  entry updates, else the block goes on to the dense routes);
* dense ``fmpq_mat.rref`` of python-flint over ``QQ`` (and, with ``NAMBU_BCH_DISABLE_FLINT=1``,
  the pure-sympy path the package keeps when python-flint is absent);
* without python-flint, the multi-modular elimination over ``QQ`` (``algebra/modular_rref.py``; route
  ``modular``: every ``QQ`` block, however small, sent there by ``MODULAR_MIN = 1``);
* ``QQ<2^(1/3)>`` and ``QQ<2^(1/3)>(a, b)`` written over ``QQ`` / ``QQ(a, b)`` with the basis
  ``1, theta, theta^2`` when the matrix lies in the base field (``_AlgebraicSplit``).

Values in ``QQ<theta>(a, b)`` have no unique normal form in sympy (``2a/(2b)`` and ``a/b``
are different fraction objects), so values are compared by their difference, and every
solution is also checked by substitution (``L x = b``, ``L k = 0``, ``y L = 0``, ``y b != 0``).
The shadow Hamiltonians of the rigid body (Nambu 1973; Horikoshi Sect. 5) with the
Yoshida triple jump (coefficients in ``QQ<2^(1/3)>``; Yoshida, Phys. Lett. A 150 (1990)) and with
``I = (1, 2, 3)`` are compared between the two paths as well.
"""

from __future__ import annotations

import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sympy.polys.domains import QQ

from nambu_bch import model
from nambu_bch.algebra import elimination as E
from nambu_bch.shadow import shadow_hamiltonians

a, b = sympy.symbols("a b")
THETA = sympy.cbrt(2)
DOMAINS = {
    "QQ": QQ,
    "QQ(a,b)": QQ.frac_field(a, b),
    "QQ<2^(1/3)>": QQ.algebraic_field(THETA),
    "QQ<2^(1/3)>(a,b)": QQ.algebraic_field(THETA).frac_field(a, b),
}
BASE_VALUES = [sympy.Integer(1), sympy.Integer(-2), sympy.Rational(3, 5), a, b, 1 / a, a + b, b / (a - b), a**2 / b]
EXTENSION_VALUES = [THETA, THETA**2 / 3, 1 + THETA, a * THETA, THETA**2 / b]


@pytest.fixture(params=["flint", "modular", "sympy-only"])
def flint_switch(request, monkeypatch):
    """The python-flint route, and without python-flint the multi-modular and the pure-sympy routes."""
    return _switch(request.param, monkeypatch)


@pytest.fixture
def route_switch(route, monkeypatch):
    """The route of a ``(domain_name, route)`` parameter (see ``ROUTES``)."""
    return _switch(route, monkeypatch, dense=True)


def _switch(route, monkeypatch, dense=False):
    """Select a route; ``dense=True`` (the random systems) also switches off the sparse pass over ``QQ``, so that
    ``flint`` is flint's dense ``fmpq_mat.rref`` alone (the sparse pass has its own tests below)."""
    if route in ("sympy-only", "modular") or dense:
        monkeypatch.setattr(E, "SPARSE_RATIO", None)
    if route in ("sympy-only", "modular"):
        monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", "1")
        monkeypatch.setattr(E, "MODULAR_MIN", 1 if route == "modular" else 10**9)
    else:
        monkeypatch.delenv("NAMBU_BCH_DISABLE_FLINT", raising=False)
        if not E.flint_available():
            pytest.skip("python-flint is not installed")
    return route


def _allowed(domain, expr, extension=False):
    params = getattr(domain, "is_FractionField", False)
    if expr.free_symbols and not params:
        return False
    return not extension or domain.is_AlgebraicField or (params and domain.domain.is_AlgebraicField)


@st.composite
def systems(draw, domain_name):
    """A random sparse system: columns of ``L`` (entries from the base field, or, sometimes, the extension)
    and right-hand sides (entries from the whole domain)."""
    domain = DOMAINS[domain_name]
    base = [v for v in BASE_VALUES if _allowed(domain, v)]
    if domain_name == "QQ<2^(1/3)>(a,b)":  # keep sympy's plain path (polynomial gcds over QQ<theta>) quick
        base = [v for v in base if v not in (b / (a - b), a**2 / b)]
    ext = [v for v in EXTENSION_VALUES if _allowed(domain, v, extension=True)]
    size = 4 if domain_name == "QQ<2^(1/3)>(a,b)" else 6  # sympy's plain path over QQ<theta>(a, b) is slow
    nrows = draw(st.integers(1, size))
    ncols = draw(st.integers(1, size))
    matrix_values = base + (ext if ext and draw(st.booleans()) and draw(st.booleans()) else [])
    rhs_values = base + ext

    def sparse(values, n):
        entries = draw(st.dictionaries(st.integers(0, n - 1), st.sampled_from(values), max_size=n))
        return {i: domain.from_sympy(v) for i, v in entries.items()}

    columns = [sparse(matrix_values, nrows) for _ in range(ncols)]
    if draw(st.booleans()) and ncols > 1:  # a dependent column: a non-trivial kernel
        s = domain.from_sympy(draw(st.sampled_from(base)))
        columns.append({i: s * v for i, v in columns[0].items()})
    rhs = [sparse(rhs_values, nrows) for _ in range(draw(st.integers(1, 3)))]
    if draw(st.booleans()):  # a consistent right-hand side: L times a vector
        x = {j: domain.from_sympy(draw(st.sampled_from(rhs_values))) for j in range(len(columns))}
        rhs.append(_apply(columns, x, domain))
    return domain, nrows, columns, rhs


def _apply(columns, x, domain):
    out: dict = {}
    for j, col in enumerate(columns):
        for i, v in col.items():
            out[i] = out.get(i, domain.zero) + v * x.get(j, domain.zero)
    return {i: v for i, v in out.items() if v}


def _same(u: dict, v: dict, domain) -> bool:
    keys = set(u) | set(v)
    return all(not (u.get(k, domain.zero) - v.get(k, domain.zero)) for k in keys)


def _reference(fn, *args):
    old = E.FAST_PATHS
    E.FAST_PATHS = False
    try:
        return fn(*args)
    finally:
        E.FAST_PATHS = old


DOMAIN_NAMES = list(DOMAINS)
# The modular route only ever eliminates over QQ (directly, or as the base field of QQ<theta>), python-flint over QQ
# and over QQ(parameters) (algebra/frac_rref.py); over QQ<theta>(parameters) all switches run the same code, so that
# field runs once, with python-flint switched off
ROUTES = [pytest.param(name, route, id=f"{route}-{name}")
          for name in DOMAIN_NAMES for route in ("flint", "modular", "sympy-only")
          if route == "sympy-only" or not DOMAINS[name].is_FractionField
          or (route == "flint" and DOMAINS[name].domain.is_QQ)]


#: The random systems' tests: the route's switch (a function-scoped fixture) holds for every example of the test.
SYSTEM_SETTINGS = dict(deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.mark.parametrize("domain_name, route", ROUTES)
@settings(max_examples=40, **SYSTEM_SETTINGS)
@given(data=st.data())
def test_solve_affine_matches_plain_domainmatrix(domain_name, route, route_switch, data):
    """solve_affine: same consistency, pivots, particular solutions, kernel and certificate as the plain path,
    and each verified by substitution."""
    system = data.draw(systems(domain_name))
    domain, nrows, columns, rhs = system
    L = E.SparseMatrix.from_columns(columns, nrows, domain)
    new = E.solve_affine(L, rhs)
    ref = _reference(E.solve_affine, L, rhs)
    assert (new.consistent, new.failing_rhs, new.pivots) == (ref.consistent, ref.failing_rhs, ref.pivots)
    assert len(new.kernel) == len(ref.kernel)
    for k_new, k_ref in zip(new.kernel, ref.kernel):
        assert _same(k_new, k_ref, domain)
        assert not _apply(columns, k_new, domain)  # L k = 0
    if new.consistent:
        for x_new, x_ref, bk in zip(new.particular, ref.particular, rhs):
            assert _same(x_new, x_ref, domain)
            assert _same(_apply(columns, x_new, domain), bk, domain)  # L x = b
    else:
        y = new.certificate
        assert _same(y, ref.certificate, domain)
        for col in columns:  # y L = 0
            assert not sum((y[i] * v for i, v in col.items() if i in y), domain.zero)
        bk = rhs[new.failing_rhs]
        assert sum((y[i] * v for i, v in bk.items() if i in y), domain.zero)  # y b != 0


@pytest.mark.parametrize("domain_name, route", ROUTES)
@settings(max_examples=30, **SYSTEM_SETTINGS)
@given(data=st.data())
def test_rank_nullspace_normal_form_match_plain(domain_name, route, route_switch, data):
    """rank, nullspace, kernel_rref and normal_form agree with the plain path (the rows of the random systems)."""
    system = data.draw(systems(domain_name))
    domain, nrows, columns, rhs = system
    ncols = len(columns)
    vectors = [{j: col[i] for j, col in enumerate(columns) if i in col} for i in range(nrows)]
    rows = {i: v for i, v in enumerate(vectors) if v}
    M = E.SparseMatrix(rows, nrows, ncols, domain)
    assert E.rank(E.SparseMatrix.from_rows(vectors, ncols, domain)) == _reference(E.rank, M)
    kern = E.nullspace(M)
    ref = _reference(E.nullspace, M)
    assert len(kern) == len(ref) and all(_same(u, v, domain) for u, v in zip(kern, ref))
    for k in kern:
        assert all(not sum((r[j] * k[j] for j in r if j in k), domain.zero) for r in rows.values())
    priority = list(reversed(range(ncols)))
    if kern:
        basis = E.kernel_rref(kern, priority, domain)
        ref_basis = _reference(E.kernel_rref, kern, priority, domain)
        assert len(basis) == len(ref_basis) and all(_same(u, v, domain) for u, v in zip(basis, ref_basis))
        vec = {j: domain.one for j in range(ncols)}
        assert _same(E.normal_form(vec, kern, priority, domain), _reference(E.normal_form, vec, kern, priority, domain), domain)


def test_algebraic_split_round_trip():
    """split/join are inverse: v = sum_i theta^i b_i with b_i in QQ(a, b) (theta = 2^(1/3), minimal polynomial x^3 - 2)."""
    K = DOMAINS["QQ<2^(1/3)>(a,b)"]
    S = E._AlgebraicSplit.of(K)
    assert S.k == 3 and S.base == QQ.frac_field(a, b)
    for expr in [(THETA * a + 2) / (3 * b * THETA), (a - THETA**2 * b) / (a - b) ** 2 + THETA / a, 1 / (a**2 - 2) + THETA**2]:
        v = K.from_sympy(expr)
        parts = S.split(v)
        assert not (S.join(parts) - v)
        assert sympy.simplify(sum(S.base.to_sympy(p) * THETA**i for i, p in enumerate(parts)) - expr) == 0
    # a denominator outside QQ(a, b) does not split: the plain path is used
    assert S.split(K.from_sympy(1 / (a + THETA))) is None


def _members(family):
    return [family.member(alpha=0), family.member(alpha=1)]


@pytest.mark.parametrize(
    "values, word, order",
    [({}, "yoshida:12321", 2),  # QQ<2^(1/3)>(I1, I2, I3): the split route
     ({"I1": 1, "I2": 2, "I3": 3}, "yoshida:12321", 4),  # QQ<2^(1/3)>: split, then flint over QQ
     ({"I1": 1, "I2": 2, "I3": 3}, "12321", 6)],  # QQ: flint
)
def test_rigid_body_shadows_match_plain_path(values, word, order, flint_switch):
    """Rigid body (catalog model 'rigid-body'): the shadow pair's members alpha = 0, 1 are the same with the fast
    routes and with sympy's plain elimination, and the kernel dimensions agree, order by order."""
    system = model("rigid-body").substitute(values)
    fast = shadow_hamiltonians(system, word, order)
    ref = _reference(shadow_hamiltonians, system, word, order)
    assert fast.exists and ref.exists
    for m_fast, m_ref in zip(_members(fast), _members(ref)):
        for p, q in zip(m_fast, m_ref):
            assert sympy.expand(sympy.together(p - q)) == 0
    assert [o.kernel_dim for o in fast.details.orders] == [o.kernel_dim for o in ref.details.orders]


def test_elimination_cost_counts_blocks_and_weights_parameter_fields():
    """elimination_cost: sum over the blocks of r c min(r, c), counted here by hand for a matrix with a 3 x 2 block
    (rows 0, 1, 2; columns 0, 1), a 1 x 1 block (row 3, column 2) and a zero column: 3*2*2 + 1 = 13 over QQ and over
    QQ<2^(1/3)> (eliminated over QQ), FIELD_WEIGHT times that over QQ(a, b); the blocks are those _rref eliminates."""
    for name, weight in (("QQ", 1), ("QQ<2^(1/3)>", 1), ("QQ(a,b)", E.FIELD_WEIGHT)):
        K = DOMAINS[name]
        one = K.one
        columns = [{0: one, 1: one}, {1: one, 2: one + one}, {3: one}, {}]
        assert E.elimination_cost(columns, 4, K) == 13 * weight
    rows = {0: {0: QQ(1), 1: QQ(1)}, 1: {1: QQ(1)}, 2: {1: QQ(2)}, 3: {2: QQ(1)}}
    blocks = E._blocks(rows, 4)
    assert sorted(map(sorted, blocks.values())) == [[0, 1, 2], [3]]



# -- the one sparse matrix type ----------------------------------------------------------------------------------

@settings(max_examples=25, deadline=None)
@given(st.lists(st.dictionaries(st.integers(0, 4), st.integers(-3, 3), max_size=4), min_size=1, max_size=5),
       st.dictionaries(st.integers(0, 4), st.integers(-3, 3), max_size=3))
def test_sparse_matrix_from_columns_and_from_rows_agree(cols, b):
    """``SparseMatrix`` built from columns or from its rows is the same matrix: same entries (zeros dropped), same
    ``solve_affine``, ``nullspace`` and ``rank``; its ``columns()`` give the columns back."""
    cols = [{i: QQ(v) for i, v in c.items()} for c in cols]
    b = {i: QQ(v) for i, v in b.items()}
    M = E.SparseMatrix.from_columns(cols, 5, QQ)
    T = E.SparseMatrix.from_rows([M.rows.get(i, {}) for i in range(5)], len(cols), QQ)
    assert M.ncols == len(cols) and all(v for r in M.rows.values() for v in r.values())
    assert T == M
    assert E.solve_affine(M, [b]) == E.solve_affine(T, [b])
    assert E.nullspace(M) == E.nullspace(T) and E.rank(M) == E.rank(T) == len(E.solve_affine(M, []).pivots)
    assert [{i: v for i, v in c.items() if v} for c in M.columns()] == [{i: v for i, v in c.items() if v} for c in cols]


@pytest.mark.parametrize("call", [lambda: E.solve_affine([{0: QQ(1)}], [{0: QQ(1)}]),
                                  lambda: E.nullspace({0: {0: QQ(1)}}),
                                  lambda: E.rank([{0: QQ(1)}])],
                         ids=["solve_affine-columns", "nullspace-row-dict", "rank-row-vectors"])
def test_elimination_takes_only_a_sparse_matrix(call):
    """The bare-dict shapes (columns, ``{row: {col: v}}``, row vectors) are refused in one line of the package's
    exception family, naming the function and what it accepts."""
    with pytest.raises(E.NambuBCHError, match=r"^\w+: expects a SparseMatrix .*, got (list|dict)$"):
        call()


@pytest.mark.parametrize("args,fragment", [(({0: {0: QQ(1)}}, 0, 1), "row index 0 outside"),
                                           (({0: {3: QQ(1)}}, 1, 2), "column index 3 (row 0) outside 0..1"),
                                           (({}, -1, 2), "nrows must be a non-negative integer"),
                                           (({}, 1, True), "ncols must be a non-negative integer")])
def test_sparse_matrix_refuses_entries_outside_its_shape(args, fragment):
    with pytest.raises(E.NambuBCHError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        E.SparseMatrix(*args, QQ)


# -- the sparse pass over QQ -------------------------------------------------------------------------------------

@st.composite
def qq_blocks(draw):
    """A random sparse matrix over QQ (rows ``{column: value}``), sometimes with rows that are combinations of others
    (rank deficiency, fill-in when they are eliminated)."""
    nrows, ncols = draw(st.integers(1, 9)), draw(st.integers(1, 9))
    entry = st.builds(lambda p, q: QQ(p, q), st.integers(-7, 7), st.integers(1, 5))
    rows = {i: draw(st.dictionaries(st.integers(0, ncols - 1), entry, max_size=3)) for i in range(nrows)}
    if draw(st.booleans()) and nrows > 2:
        c1, c2 = draw(entry), draw(entry)
        mix = {j: c1 * rows[0].get(j, QQ(0)) + c2 * rows[1].get(j, QQ(0)) for j in range(ncols)}
        rows[nrows - 1] = mix
    rows = {i: {j: v for j, v in r.items() if v} for i, r in rows.items()}
    return {i: r for i, r in rows.items() if r}, nrows, ncols


@settings(max_examples=40, deadline=None, derandomize=True)
@given(qq_blocks())
def test_sparse_pass_is_the_reduced_echelon_form(block):
    """The sparse Gauss-Jordan in column order gives the unique reduced echelon form: the same rows (entries in
    column order), values and pivots as sympy's ``DomainMatrix.rref``; with no budget left it gives up (``None``)."""
    rows, nrows, ncols = block
    if not rows:
        return
    R, pivots = E._rref_sparse(rows, ncols, QQ, None)
    ref, ref_pivots = E._sdm(rows, nrows, ncols, QQ).rref()
    assert pivots == tuple(ref_pivots)
    assert R == {k: dict(sorted(r.items())) for k, r in ref.rep.to_sdm().items()}
    assert all(list(r) == sorted(r) for r in R.values())
    if len(rows) > 1 and pivots:
        assert E._rref_sparse(rows, ncols, QQ, -1) is None


def _banded(n, m):
    """An n x m matrix over QQ with three entries per row (a band), the sparsity of the direct route's blocks."""
    return {i: {j % m: QQ(1 + (i * j) % 5, 1 + j % 3) for j in (i, i + 1, i + 7)} for i in range(n)}


def test_sparse_matrices_over_qq_are_eliminated_sparsely(monkeypatch):
    """A sparse 150 x 100 block (three entries a row) is reduced by the sparse pass within its budget, without the dense
    routes; with the sparse pass switched off (``SPARSE_RATIO = None``) flint's dense route gives the same form."""
    rows = _banded(150, 100)
    dense = []
    original = E._rref_flint_qq
    monkeypatch.setattr(E, "_rref_flint_qq", lambda *a: dense.append(a) or original(*a))
    R, pivots = E._rref_block(rows, 150, 100, QQ)
    assert not dense
    monkeypatch.setattr(E, "SPARSE_RATIO", None)
    if E.flint_available():
        assert E._rref_block(rows, 150, 100, QQ) == (R, pivots) and dense
    ref, ref_pivots = E._sdm(rows, 150, 100, QQ).rref()
    assert pivots == tuple(ref_pivots) and R == {k: dict(sorted(r.items())) for k, r in ref.rep.to_sdm().items()}


def test_dense_matrices_over_qq_leave_the_sparse_pass(monkeypatch):
    """A nearly full 40 x 40 block never enters the sparse pass (more than SPARSE_ROW_ENTRIES entries a row); a 60 x 60
    block with five scattered entries a row enters it, fills in, gives up within its budget; the dense route (flint,
    or without it the multi-modular one) eliminates both, with the same result as sympy's."""
    full = {i: {j: QQ((i + 1) * (j + 2) % 11 + (i == j), 1 + (i + j) % 4) for j in range(40)} for i in range(40)}
    scattered = {i: {(i * 7 + 13 * k * k + k) % 60: QQ(1 + (i + k) % 6, 1 + k) for k in range(5)} for i in range(60)}
    spent = []
    original = E._rref_sparse
    monkeypatch.setattr(E, "_rref_sparse", lambda *a: spent.append(original(*a)) or spent[-1])
    for rows, n, entered in ((full, 40, False), (scattered, 60, True)):
        rows = {i: {j: v for j, v in r.items() if v} for i, r in rows.items()}  # sympy's SDM holds no zeros
        spent.clear()
        R, pivots = E._rref_block(rows, n, n, QQ)
        assert spent == ([None] if entered else [])
        ref, ref_pivots = E._sdm(rows, n, n, QQ).rref()
        assert pivots == tuple(ref_pivots) and R == {k: dict(sorted(r.items())) for k, r in ref.rep.to_sdm().items()}
