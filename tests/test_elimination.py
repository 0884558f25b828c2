"""The exact elimination module (nambu_bch/algebra/elimination.py): the fast routes against sympy's plain path.

The reduced row echelon form of a matrix is unique, so every route must give the same
pivots, the same particular solution (free columns zero), the same kernel basis and the
same certificate as sympy's sparse Gauss-Jordan ``DomainMatrix.rref`` over the full domain
(``FAST_PATHS = False``).  The routes under test:

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
from hypothesis import given, settings
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
    return _switch(route, monkeypatch)


def _switch(route, monkeypatch):
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


@pytest.mark.parametrize("domain_name, route", ROUTES)
def test_solve_affine_matches_plain_domainmatrix(domain_name, route, route_switch):
    """solve_affine: same consistency, pivots, particular solutions, kernel and certificate as the plain path,
    and each verified by substitution."""

    @settings(max_examples=40, deadline=None, derandomize=True)
    @given(systems(domain_name))
    def check(system):
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

    check()


@pytest.mark.parametrize("domain_name, route", ROUTES)
def test_rank_nullspace_normal_form_match_plain(domain_name, route, route_switch):
    """rank, nullspace, kernel_rref and normal_form agree with the plain path (the rows of the random systems)."""

    @settings(max_examples=30, deadline=None, derandomize=True)
    @given(systems(domain_name))
    def check(system):
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

    check()


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
