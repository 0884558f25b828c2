"""The FI route at every order: recursive hulls of nested FI representations, h^4 / h^6 families.

Every value is checked two independent ways:
* the recursive affine hull (``fi_nested``) against the brute-force enumeration of the labelled
  representations (per-term choices of Eqs. CL2a/CL2b, as Eqs. 1AX-2BY at depth 2), and against
  the paper's h^2 forms (Eqs. CL5-CL8) computed by the older labelled code;
* each representation (base and every direction) against the concrete commutator of vector fields
  (the fundamental identity, Eq. CL2: the base has the bracket's field, directions have field zero);
* the h^4 / h^6 families against the backward-error effective field (independent of the BCH route)
  and against the direct route's solution space.
"""

from __future__ import annotations

import importlib
import json
from itertools import product

import pytest
import sympy

from nambu_bch import PAPER_WORDS, liouville_field, model
from nambu_bch.algebra import VectorField
from nambu_bch.bch import formal_bch
from nambu_bch.bch.expansion import term_evaluator
from nambu_bch.bch.lyndon import is_bracket
from nambu_bch.cli import main
from nambu_bch.errors import InvalidOrderError, NambuBCHError
from nambu_bch.shadow import direct_route, fi_route, shadow_hamiltonians
from nambu_bch.shadow.fi_nested import Echelon, RawOps, nested_hull
from nambu_bch.shadow.fundamental_identity import commutator_terms
from nambu_bch.testing import assert_shadow_pair

import shared_results as shared

fi_module = importlib.import_module("nambu_bch.shadow.fi_route")
fi_nested_module = importlib.import_module("nambu_bch.shadow.fi_nested")
fi_brackets = fi_module.fi_brackets

h, alpha = sympy.symbols("h alpha")


def zero(expr) -> bool:
    return sympy.expand(expr) == 0


def ops_for(S):
    atoms, _ = fi_module._atoms(S)
    return RawOps(S.algebra, atoms)


def raw_field(ops, raw) -> VectorField:
    """Evaluate a raw formal sum: ``sum_k c_k X_{slots_k}`` as a concrete vector field."""
    alg = ops.algebra
    total = VectorField.zero(alg)
    for c, slots in ops.items(raw):
        total = total + liouville_field(alg, *slots).scale(c)
    return total


def in_hull(ops, hull, raw) -> bool:
    """Is ``raw`` in ``base + span(directions)``?"""
    E = Echelon(ops.domain)
    for _, d in hull.directions:
        E.insert(d)
    diff = dict(raw)
    for k, v in hull.base.items():
        diff[k] = diff.get(k, ops.domain.zero) - v
    return not E.reduce(diff)


def labelled_representations(ops, tree):
    """All labelled FI representations of a tree, by brute force: one way (CL2a/CL2b) per pair of terms.

    Uses ``fundamental_identity.commutator_terms`` on concrete term lists (the package's h^2 code path),
    not the raw bilinear maps of ``fi_nested``; terms with a zero slot (zero both ways) are dropped.
    """
    alg = ops.algebra
    if not is_bracket(tree):
        return [("", [(tuple(alg.convert(s) for s in tree), sympy.Integer(1))])]
    out = []
    for l1, r1 in labelled_representations(ops, tree[0]):
        for l2, r2 in labelled_representations(ops, tree[1]):
            pairs = [(t, u) for t in r1 for u in r2]
            for ways in product("ab", repeat=len(pairs)):
                terms = []
                for ((ts, tc), (us, uc)), w in zip(pairs, ways):
                    for term in commutator_terms(alg, ts, us, w, tc * uc):
                        if all(term.slots):
                            terms.append((term.slots, term.coefficient))
                out.append((f"[{l1},{l2}]{''.join(ways)}", terms))
    return out


def to_raw(ops, terms) -> dict:
    out: dict = {}
    for slots, c in terms:
        for k, v in ops.from_slots(slots, ops.coefficient(c)).items():
            out[k] = out.get(k, ops.domain.zero) + v
    return {k: v for k, v in out.items() if v}


def affine_dimension(ops, raws) -> int:
    E = Echelon(ops.domain)
    base = raws[0]
    for r in raws[1:]:
        d = dict(r)
        for k, v in base.items():
            d[k] = d.get(k, ops.domain.zero) - v
        E.insert(d)
    return len(E.rows)


# ---------------------------------------------------------------------------------------------
# 1. The recursive hull
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["ho3", "rigid-body", "lotka-volterra"])
def test_h2_hull_equals_affine_hull_of_eqs_1AX_to_2BY(name):
    """h^2: the recursive hull spans exactly the eight labelled forms of Eqs. (1AX)-(2BY) (CL5-CL8 for ho3)."""
    S = model(name)
    ops = ops_for(S)
    R = fi_route(S, "12321")
    for comm in R.commutators:
        a, b, c = comm.leaves
        hull = nested_hull(ops, (a, (b, c)))
        old = [rep.formal for rep in comm.representations]  # the labelled code (vanishing rule applied)
        E_old, E_new = Echelon(ops.domain), Echelon(ops.domain)
        for r in old[1:]:
            E_old.insert((r - old[0]).terms)
        for _, d in hull.directions:
            E_new.insert(ops.reduce(d).terms)
        assert len(E_old.rows) == len(E_new.rows)
        assert not E_old.reduce((ops.reduce(hull.base) - old[0]).terms)  # same affine space
        for _, d in hull.directions:
            assert not E_old.reduce(ops.reduce(d).terms)
    if name == "ho3":  # Eqs. (CL5)-(CL8): two distinct forms each, a line
        assert [len(c.representations) for c in R.commutators] == [2, 2, 2, 2]


@pytest.mark.parametrize("name, word", [("ho3", "12321"), ("ho3", "21312"), ("rigid-body", "12321")])
def test_h4_hull_equals_brute_force_enumeration(name, word):
    """h^4: every labelled representation (one way per pair of terms) lies in the hull, and they span it."""
    S = model(name)
    ops = ops_for(S)
    brackets = list(shared.brackets(name, word, 4))
    if name == "ho3":
        assert len(brackets) == 6
    else:  # 992 brackets: the first three of hull dimension 4 and three of dimension 3
        brackets = [b for b in brackets if b.hull.dimension == 4][:3] + [b for b in brackets if b.hull.dimension == 3][:3]
        assert len(brackets) == 6
    for b in brackets:
        reps = labelled_representations(ops, b.tree)
        raws = [to_raw(ops, terms) for _, terms in reps]
        assert all(in_hull(ops, b.hull, r) for r in raws)
        assert affine_dimension(ops, raws) == b.hull.dimension
    assert max(b.hull.dimension for b in brackets) >= 2  # not only trivial hulls


@pytest.mark.parametrize("name, word, order", [("ho3", "12321", 4), ("ho3", "12321", 6), ("lotka-volterra", "12321", 4),
                                               ("rigid-body", "12321", 4)])
def test_hull_members_have_the_brackets_field(name, word, order):
    """Eq. (CL2) at every depth: the base evaluates to the bracket's vector field, every direction to zero."""
    S = model(name)
    ev = term_evaluator(S.splitting)
    brackets = list(shared.brackets(name, word, order))
    if name == "rigid-body":
        brackets = brackets[::40]  # 992 brackets at h^4: every 40th (25 of them), the hulls are shared anyway
    assert brackets
    for b in brackets:
        ops = b.ops
        assert raw_field(ops, b.hull.base) == ev.field(b.tree)
        assert all(raw_field(ops, d).is_zero() for _, d in b.hull.directions)


def test_direction_labels_name_the_flipped_pair():
    """A label ``b<i>.<j>`` is (b - a)(t_i, u_j): pair ``(i, j)`` of the subtrees' sorted supports switched to Eq. CL2b."""
    S = model("ho3")
    ops = ops_for(S)
    AC, BD = S.splitting[1].terms[0], S.splitting[2].terms[0]
    tree = (AC, (AC, BD))  # Eq. (CL5)
    hull = nested_hull(ops, tree, {})
    left, right = nested_hull(ops, AC, {}), nested_hull(ops, (AC, BD), {})
    (label, d), = hull.directions
    i, j = map(int, label[1:].split("."))
    assert d == ops.flip(left.support[i], right.support[j])
    assert not ops.reduce(d).is_zero()  # the two distinct forms of Eq. (CL5) differ formally


def test_hull_size_is_refused_up_front(monkeypatch):
    S = model("ho3")
    monkeypatch.setattr(fi_nested_module, "MAX_PAIRS", 1)
    with pytest.raises(NambuBCHError, match="route='direct'"):
        fi_brackets(S, "12321", 4)


# ---------------------------------------------------------------------------------------------
# 2. Families at h^4 and h^6
# ---------------------------------------------------------------------------------------------


def check_effective(S, word, order, shadows):
    """X_{H_S,G_S} against the backward-error effective field (independent of BCH and FI), h^0..h^order,
    with the package's own pytest helper (nambu_bch.testing.assert_shadow_pair, alpha symbolic)."""
    rest = list(shadows[1:])
    assert_shadow_pair(S, word, shadows[0], rest[0] if len(rest) == 1 else (rest or None), order=order)


@pytest.mark.parametrize("word", PAPER_WORDS)
def test_ho3_h4_fi_family_reproduces_X_eff_and_equals_direct(word):
    """ho3, six words, h^4: the FI alpha-family reproduces X_eff, equals the direct family, and reaches 3 of 5 dimensions."""
    S = model("ho3")
    F = shadow_hamiltonians(S, word, 4, route="fi")
    D = shadow_hamiltonians(S, word, 4)
    assert F.exists and F.free_parameters == ["alpha"]
    check_effective(S, word, 4, F.shadows)
    assert all(zero(a - b) for a, b in zip(F.shadows, D.shadows))
    (o3, o4) = F.details.orders
    assert o3.status == "vanishes" and o4.status == "solved" and o4.degree == 2
    assert (o4.fi_dim, o4.direct_dim) == (3, D.details.orders[3].kernel_dim) == (3, 5)  # a proper part
    alg = S.algebra
    for dH, dG in o4.kernel:  # FI homogeneous solutions are direct gauge directions
        assert (liouville_field(alg, dH, S.G) + liouville_field(alg, S.H, dG)).is_zero()
    assert any(zero(c) is False for c in o4.kernel[0])


def _span_rank(S, pairs) -> int:
    rows = [{(a, m): c for a, part in enumerate(pair) for m, c in sympy.Poly(sympy.expand(part), *S.coordinates).terms() if c}
            for pair in pairs]
    cols = sorted({k for r in rows for k in r}, key=str)
    return sympy.Matrix([[r.get(k, 0) for k in cols] for r in rows]).rank() if rows and cols else 0


def test_ho3_missing_gauge_is_0_H_and_G_0():
    """ho3, h^4: the direct gauge (5 dims) is the FI gauge (3 dims) plus (0, H) and (G, 0) (X_{H,H} = X_{G,G} = 0)."""
    S = model("ho3")
    o = fi_route(S, "12321", 4).orders[-1]
    gauge = direct_route(S, "12321", 4).orders[3].gauge
    trivial = [(0, S.H), (S.G, 0)]
    assert _span_rank(S, o.kernel) == 3 and _span_rank(S, gauge) == 5
    assert _span_rank(S, [*o.kernel, *trivial]) == 5 == _span_rank(S, [*o.kernel, *trivial, *gauge])
    assert _span_rank(S, [*o.kernel, trivial[0]]) == 4  # each of the two is missing on its own


@pytest.mark.parametrize("name, order", [("ho3", 6), ("lotka-volterra", 4)])
def test_fi_family_h6_and_lotka_volterra(name, order):
    S = model(name)
    F = shadow_hamiltonians(S, "12321", order, route="fi")
    assert F.exists
    check_effective(S, "12321", order, F.shadows)
    for o in F.details.orders:
        if o.status == "solved":
            assert 0 < o.fi_dim < o.direct_dim  # proper part (ho3: 3 of 5; LV: 5 of 11 at h^4)
    assert [o.status for o in F.details.orders] == ["vanishes", "solved"] * ((order - 2) // 2)


def _same_family(F, D) -> bool:
    """Equal as sets of pairs: the alpha-families agree up to a reparametrisation alpha -> a + b alpha (b != 0)."""
    a, b = sympy.symbols("a b")
    diffs = [sympy.expand(x.subs(alpha, a + b * alpha) - y) for x, y in zip(F.shadows, D.shadows)]
    eqs = [c for d in diffs if d != 0 for c in sympy.Poly(d, h, alpha, *F.system.coordinates).coeffs()]
    return not eqs or any(s.get(b, b) != 0 for s in sympy.solve(eqs, [a, b], dict=True))


@pytest.mark.parametrize("order", [2, 4])
def test_lotka_volterra_fi_family_is_the_direct_family(order):
    """LV, 12321, h^2 and h^4: the FI route returns the direct route's alpha-family (equal as sets of pairs), and
    its result says that at h^4 the FI representations alone reach only part of it (the alpha direction
    (G H^2, -G^2 H)/90 needs X_{H,H} = 0, which formal sums with H's pieces kept whole cannot see)."""
    S = model("lotka-volterra")
    F = shadow_hamiltonians(S, "12321", order, route="fi")
    D = shadow_hamiltonians(S, "12321", order)
    assert F.free_parameters == D.free_parameters == (["alpha"] if order == 4 else [])
    assert _same_family(F, D) and all(zero(x - y) for x, y in zip(F.shadows, D.shadows))
    check_effective(S, "12321", order, F.shadows)
    spans = {s["order"]: s for s in F.fi_span}
    assert spans[2]["reached"] is True and spans[2]["reason"] is None
    if order == 4:
        s4 = spans[4]
        assert s4["reached"] is False and (s4["fi_dim"], s4["gauge_dim"], s4["degree"]) == (5, 18, 7)
        assert s4["reason"] in F.notes and "X_{H,H} = 0" in s4["reason"]
        assert s4["reason"] in F.to_text() and F.to_dict()["fi_span"] == F.fi_span
        H, G = S.hamiltonians
        m0, m1 = F.details.orders[-1].members
        assert all(zero(90 * (x - y) - z) for x, y, z in zip(m1, m0, (G * H**2, -G**2 * H)))


def test_lotka_volterra_h6_fi_family_is_the_direct_family_or_says_why():
    """LV, h^6: with the whole h^4 family fed in the formal FI equation has no solution; the result returns the
    direct route's pair and says so (notes: the h^4 span and the failed FI ansatz)."""
    S = model("lotka-volterra")
    F = shadow_hamiltonians(S, "12321", 6, route="fi")
    D = shadow_hamiltonians(S, "12321", 6)
    assert F.exists and all(zero(x - y) for x, y in zip(F.shadows, D.shadows))
    assert F.failed_order == 6 and any("FI ansatz failed" in n for n in F.notes)
    assert any(not s["reached"] for s in F.fi_span)


@pytest.mark.parametrize("name, word, order", [("ho", "121", 4), ("ho", "12", 3), ("lotka-volterra", "123", 3),
                                               ("ho3-composite", "121", 4)])
def test_fi_family_other_words_and_N2(name, word, order):
    """Non-symmetric words (cross terms X_{dH_1,dG_1} at h^2) and N = 2 (Eq. CL1, one form): the FI family
    exists iff the direct one does and reproduces X_eff through h^order."""
    S = model(name)
    F = shadow_hamiltonians(S, word, order, route="fi")
    assert F.exists == shadow_hamiltonians(S, word, order).exists is True
    check_effective(S, word, order, F.shadows)
    assert [o.order for o in F.details.orders] == list(range(F.details.power + 1, order + 1))


def test_lotka_volterra_family_is_direct_at_the_same_degree():
    """LV, 12321: with degree=5 given, the FI alpha-family through h^4 is the direct route's at ansatz degree 5."""
    S = model("lotka-volterra")
    R = fi_route(S, "12321", 4, degree=5)
    D = direct_route(S, "12321", 4, degree=5)
    assert R.orders[-1].degree == 5 and D.orders[3].kernel_dim == R.orders[-1].direct_dim == 11
    assert all(zero(a - b) for a, b in zip(R.corrections, D.orders[1].corrections))
    assert all(zero(a - b) for a, b in zip(R.orders[-1].corrections, D.orders[3].corrections))


def test_rigid_body_fi_route_is_obstructed_at_h2_both_ways():
    """The rigid body has a direct family at h^2 but no FI one: the labelled forms (Eqs. 1AX-2BY) and the
    recursive hulls (generic solver) both find the formal system inconsistent."""
    S = model("rigid-body")
    R = fi_route(S, "12321", 4)
    assert not R.exists and R.certificate and not R.orders
    assert direct_route(S, "12321", 2).exists
    atoms, per_slot = fi_module._atoms(S)
    ctx = {"algebra": S.algebra, "atoms": atoms, "per_slot": per_slot}
    ops = RawOps(S.algebra, atoms)
    o = fi_module._solve_order(S, ctx, ops, {}, formal_bch("12321", 3), 2, {}, None)
    assert o.status == "obstructed" and o.certificate


def test_generic_solver_reproduces_eq_SH12321c_at_h2():
    """The hull-based solver at h^2 (no cross terms) gives the labelled route's family, Eqs. (SH12321c), (SG12321c)."""
    S = model("ho3")
    R = fi_route(S, "12321")
    ctx = dict(R._ctx)
    o = fi_module._solve_order(S, ctx, RawOps(S.algebra, ctx["atoms"]), {}, formal_bch("12321", 3), 2, {}, None)
    assert o.status == "solved"
    assert all(zero(a - b) for a, b in zip(o.corrections, R.corrections))
    # the same span of corrections: rank of the labelled route's kernel corrections = fi_dim
    vecs = [{(a, m): c for a, part in enumerate(pair) for m, c in sympy.Poly(part, *S.coordinates).terms()}
            for pair in R.kernel_corrections() if any(not zero(p) for p in pair)]
    cols = sorted({k for v in vecs for k in v})
    M = sympy.Matrix([[v.get(k, 0) for k in cols] for v in vecs]) if vecs else sympy.zeros(0, 0)
    assert M.rank() == o.fi_dim >= 1


def test_bad_orders():
    S = model("ho3")
    with pytest.raises(InvalidOrderError, match="direct"):
        fi_route(S, "12321", 7)
    with pytest.raises(InvalidOrderError, match="direct"):
        fi_route(S, "12321", 1)
    with pytest.raises(InvalidOrderError):
        fi_brackets(S, "12321", 0)
    with pytest.raises(InvalidOrderError):
        fi_brackets(S, "12321", True)


# ---------------------------------------------------------------------------------------------
# 3. CLI
# ---------------------------------------------------------------------------------------------


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_shadow_route_fi_order_4_json_keys_match_direct(capsys):
    code, out, _ = run(capsys, "shadow", "--model", "ho3", "--integrator", "12321", "--route", "fi", "--order", "4",
                       "--format", "json")
    assert code == 0
    fi = json.loads(out)
    code, out, _ = run(capsys, "shadow", "--model", "ho3", "--integrator", "12321", "--order", "4", "--format", "json")
    direct = json.loads(out)
    assert set(fi) == set(direct) and fi["route"] == "fi" and fi["exists"] is True
    names = model("ho3").symbols()
    assert zero(sympy.sympify(fi["H_S"], locals=names) - sympy.sympify(direct["H_S"], locals=names))


def test_cli_fi_order_4_lists_hulls_with_limit(capsys):
    code, out, _ = run(capsys, "fi", "--model", "ho3", "--integrator", "12321", "--order", "4", "--format", "json",
                       "--limit", "2")
    assert code == 0
    data = json.loads(out)
    assert data["total"] == 6 and len(data["brackets"]) == 2 and data["order"] == 4
    first = data["brackets"][0]
    assert set(first) == {"coefficient", "bracket", "dimension", "base", "directions"}
    assert first["coefficient"] == "-7/1440" and first["directions"][0]["label"] == "b0.0"
    code, out, _ = run(capsys, "fi", "--model", "ho3", "--integrator", "12321", "--order", "4", "--format", "text",
                       "--limit", "1")
    assert code == 0 and "... 5 more brackets" in out and "base (Eq. CL2a at every pair)" in out
    limited = fi_brackets(model("ho3"), "12321", 4, limit=2)  # only the hulls asked for are built
    assert [b.to_dict(2) for b in limited] == data["brackets"]
    assert fi_module.count_brackets(model("ho3"), "12321", 4) == 6 == len(fi_brackets(model("ho3"), "12321", 4))


@pytest.mark.parametrize("argv, fragment", [
    (("fi", "--model", "ho3", "--order", "4", "--limit", "0"), "--limit"),
    (("fi", "--model", "ho3", "--order", "9"), "between"),
    (("shadow", "--model", "ho3", "--route", "fi", "--order", "8"), "direct"),
    (("fi", "--model", "rigid-body", "--order", "6"), "up to 22272 brackets; pass --limit"),  # bounded work
])
def test_cli_bad_input_is_one_line(capsys, argv, fragment, monkeypatch):
    # the size is decided from the piece-level trees: no term bracket is evaluated before the refusal
    monkeypatch.setattr(fi_module, "_merged_trees", _no_term_brackets)
    code, out, err = run(capsys, *argv)
    assert code == 2 and len(err.strip().splitlines()) == 1 and fragment in err and "Traceback" not in err


def _no_term_brackets(*args):
    raise AssertionError("the brackets of Liouville terms were built before the refusal")


@pytest.mark.parametrize("name, word, orders", [
    ("ho3", "12321", (2, 3, 4, 5)), ("ho3", "123", (2, 3)), ("lotka-volterra", "12321", (2, 4)),
    ("rigid-body", "12321", (2, 3, 4)), ("rigid-body", "123", (2, 3)), ("ho3-composite", "121", (2, 4)),
])
def test_bracket_bound_is_the_enumerated_count(name, word, orders):
    """``bracket_bound`` (piece-level trees, products of the pieces' term counts, Eq. BCH3) equals the number of
    brackets ``count_brackets`` enumerates with every term bracket evaluated, on systems whose pieces share no term."""
    for order in orders:
        assert fi_module.bracket_bound(model(name), word, order) == fi_module.count_brackets(model(name), word, order)


def test_bracket_bound_bounds_the_count_when_pieces_share_terms():
    """ho3-pair's pieces share Liouville terms: expanded trees coincide and merge, so the bound is strict."""
    for order in (1, 2):
        bound, count = (f(model("ho3-pair"), "123", order) for f in (fi_module.bracket_bound, fi_module.count_brackets))
        assert bound > count > 0


# ---------------------------------------------------------------------------------------------
# 4. The comparison table of docs/fi_route.md is computed, not typed
# ---------------------------------------------------------------------------------------------


def test_doc_table_rows_are_computed():
    """Recompute rows of the table (tools/fi_route_table.py) and find them verbatim in docs/fi_route.md."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "tools" / "fi_route_table.py"
    spec = importlib.util.spec_from_file_location("fi_route_table", path)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    doc = script.DOC.read_text()
    rows = script.main_rows(systems=("ho3", "lotka-volterra"), words=("12321", "32123"), orders=(4,))
    lines = script.table(rows).splitlines()[2:]
    assert len(lines) == 4 and all(line in doc for line in lines)
    assert any("proper part" in line for line in lines)


# -- exact families, sympy forms on demand -------------------------------------------------------------------------

def test_fi_orders_keep_exact_families_and_feed_them_to_higher_orders(monkeypatch):
    """ho3, 12321, h^4: the higher order takes the lower family's alpha parts from the exact data (the sympy round
    trip ``_alpha_parts`` is never called); the sympy forms are built on first access and are those of the exact
    family: ``alpha_parts`` equals ``_alpha_parts`` of the sympy family, order by order."""

    def refuse(*args):
        raise AssertionError("a sympy round trip fed the higher orders")

    monkeypatch.setattr(fi_module, "_alpha_parts", refuse)
    R = fi_route(model("ho3"), "12321", 4)
    o = R.orders[-1]
    assert o.status == "solved" and R.__dict__["_corrections"] is None and o.__dict__["_corrections"] is None
    monkeypatch.undo()
    alg = R._ctx["algebra"]
    for fam, forms in ((R.family, R.corrections), (o.family, o.corrections)):
        assert fam.alpha_parts() == [fi_module._alpha_parts(alg, c) for c in forms]
    assert o.corrections == fi_module._family(o.members)
    assert [o.family.forms_of(p) for p in o._kernel_exact] == o.kernel and len(o.kernel) == o.fi_dim


def test_fi_results_pickle_their_exact_data_and_compare_by_it():
    """An FI result pickles without its sympy forms (rebuilt on access) and its copy is equal to it (``==`` on the
    exact families, the system by its defining data), order by order; the forms rebuilt are the same."""
    import pickle

    R = fi_route(model("ho3"), "12321", 4)
    forms = (R.corrections, [(o.corrections, o.members, o.kernel) for o in R.orders])
    state = R.__getstate__()
    assert state["_corrections"] is None and state["family"] is R.family
    assert all(o.__getstate__()["_corrections"] is None for o in R.orders if o.status == "solved")
    copy = pickle.loads(pickle.dumps(R))
    assert copy.__dict__["_corrections"] is None and copy == R and R == copy
    assert all(x == y for x, y in zip(copy.orders, R.orders))
    assert (copy.corrections, [(o.corrections, o.members, o.kernel) for o in copy.orders]) == forms


def test_fi_span_is_decided_exactly_over_an_algebraic_parameter_field():
    """ho3, yoshida:12321 (coefficients in QQ<2^(1/3)>(m, omega), whose fractions are not kept reduced): at h^4 the
    FI members are the family's (``reached``), decided on the difference of the exact members."""
    R = fi_route(model("ho3"), "yoshida:12321", 4)
    assert [s.reached for s in R.spans()] == [True, True]
