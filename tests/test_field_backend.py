"""The vector-field backend protocol (nambu_bch.algebra.backend): three representations, one arithmetic.

Every value is checked against an independent computation with plain sympy ``diff`` on the components
(Eq. CL1: ``[X, Y]^i = X^j d_j Y^i - Y^j d_j X^i``) and, where the paper prints it, against the paper.
"""

import pytest
import sympy

from nambu_bch import System, model
from nambu_bch.algebra import (
    ExpressionBackend,
    FieldBackend,
    VectorField,
    field_backend,
)
from nambu_bch.errors import NambuBCHError

x1, x2, x3, m, omega = sympy.symbols("x1 x2 x3 m omega")


def _backends(splitting):
    """Laurent, the system's ring over QQ(parameters), and sympy expressions, on the same pieces."""
    algebra = splitting.system.algebra
    fields = {p.number: p.field for p in splitting.pieces}
    return algebra, fields, [
        field_backend(algebra, fields),
        field_backend(algebra, fields, laurent=False),
        ExpressionBackend(algebra, fields),
    ]


def _sympy_bracket(X, Y, coords):
    """Eq. (CL1) with sympy alone."""
    return tuple(sympy.expand(sum(X[j] * sympy.diff(Y[i], x) - Y[j] * sympy.diff(X[i], x)
                                  for j, x in enumerate(coords))) for i in range(len(coords)))


def _same(a, b):
    return all(sympy.simplify(u - v) == 0 for u, v in zip(a, b))


@pytest.mark.parametrize("name", ["ho3", "rigid-body", "lotka-volterra", "ho"])
def test_three_backends_agree_with_plain_sympy(name):
    """bracket, nested bracket, apply and combine agree across the three backends and with sympy diff."""
    S = model(name).splitting
    algebra, fields, backends = _backends(S)
    laurent, plain, expression = backends
    assert laurent.laurent and not plain.laurent and plain.ring == algebra.ring
    assert all(isinstance(B, FieldBackend) for B in backends)
    coords = algebra.coordinates
    raw = {k: X.to_sympy() for k, X in fields.items()}
    f = sum(x**3 for x in coords) + coords[0] * coords[-1]
    keys = sorted(fields)
    for a in keys:
        for b in keys:
            expected = _sympy_bracket(raw[a], raw[b], coords)
            for B in backends:
                value = B.bracket(B.fields[a], B.fields[b])
                assert _same(B.to_vector_field(value).to_sympy(), expected), (name, a, b, type(B).__name__)
                assert B.is_zero(value) == all(e == 0 for e in expected)
    a, b = keys[0], keys[-1]
    nested_expected = _sympy_bracket(raw[a], _sympy_bracket(raw[a], raw[b], coords), coords)
    applied = sympy.expand(sum(c * sympy.diff(f, x) for c, x in zip(raw[a], coords)))
    for B in backends:
        nested = B.bracket(B.fields[a], B.bracket(B.fields[a], B.fields[b]))
        assert _same(B.combine([(sympy.Rational(3, 7), nested)]).to_sympy(), [sympy.Rational(3, 7) * e for e in nested_expected])
        assert B.scaled_combine(7, [(3, nested)]) == B.combine([(sympy.Rational(3, 7), nested)])
        assert sympy.expand(B.function_to_sympy(B.apply(B.fields[a], B.function(f))) - applied) == 0
        assert B.is_zero_function(B.apply(B.fields[a], B.zero))
        assert sympy.expand(B.function_to_sympy(B.function(f)) - f) == 0


@pytest.mark.parametrize("name", ["rigid-body", "ho", "lotka-volterra"])
def test_laurent_apply_on_flint_is_the_pure_paths_polynomial(name, monkeypatch):
    """``apply`` of the Laurent backend with its products on flint's fmpq_mpoly is the ring element of the pure
    path (python-flint switched off), term for term -- including a function that holds ``p`` where the field holds
    ``p_inv`` (the product is brought back to the Laurent normal form) -- and equals plain sympy ``diff``."""
    pytest.importorskip("flint")
    S = model(name).splitting
    algebra, fields = S.system.algebra, {p.number: p.field for p in S.pieces}
    coords, params = algebra.coordinates, algebra.parameters
    f = sum(x**3 for x in coords) + coords[0] * coords[-1] * (params[0] if params else 1) + sympy.Rational(2, 3)
    g = sympy.Integer(5)  # a constant: X g = 0
    values = {}
    for off in ("1", ""):
        monkeypatch.setenv("NAMBU_BCH_DISABLE_FLINT", off)
        B = field_backend(algebra, fields)
        assert B.laurent and (B.flint_q is None) == (off == "1")
        values[off] = [(B.apply(X, B.function(f)), B.apply(X, B.function(g))) for X in B.fields.values()]
        for k, X in B.fields.items():
            raw = fields[k].to_sympy()
            expected = sympy.expand(sum(c * sympy.diff(f, x) for c, x in zip(raw, coords)))
            assert sympy.expand(B.function_to_sympy(B.apply(X, B.function(f))) - expected) == 0
    assert values["1"] == values[""]
    assert all(not b for _, b in values[""])


def test_bch4_bracket_value_on_ho3():
    """Eq. (BCH4): [X1, [X1, X2]] = 2 omega^2 x2 / m d/dx1 on ho3, [X1, [X1, X3]] = 0, in every backend."""
    _, _, backends = _backends(model("ho3").splitting)
    for B in backends:
        X = B.bracket(B.fields[1], B.bracket(B.fields[1], B.fields[2]))
        assert B.to_vector_field(X).to_sympy() == (2 * omega**2 * x2 / m, 0, 0)
        assert B.is_zero(B.bracket(B.fields[1], B.bracket(B.fields[1], B.fields[3])))


def test_vector_field_methods_run_on_the_backend():
    """VectorField.bracket/apply delegate to the algebra's backends; values equal sympy diff (Eq. CL1)."""
    S = model("rigid-body").splitting
    X, Y = S[1].field, S[2].field
    coords = S.system.coordinates
    assert _same(X.bracket(Y).to_sympy(), _sympy_bracket(X.to_sympy(), Y.to_sympy(), coords))
    pend = System("x1 x2", ["x2**2/2 - cos(x1)"], [], name="pendulum").splitting
    P, Q = pend[1].field, pend[2].field
    assert P.bracket(Q).to_sympy() == (sympy.sin(x1), -x2 * sympy.cos(x1))
    assert P.apply(sympy.sin(x1)) == x2 * sympy.cos(x1)


def test_non_monomial_denominator_is_refused_by_the_laurent_representation():
    """1/(m + 1): field_backend falls back to the system's ring; converting such a field into a Laurent backend
    raises the package's error, naming the field."""
    system = System("x1 x2", ["x2**2/(2*(m + 1)) + m*x1**2/2"], "m", name="shifted")
    fields = {p.number: p.field for p in system.splitting.pieces}
    assert not field_backend(system.algebra, fields).laurent
    laurent = field_backend(model("ho").algebra, {p.number: p.field for p in model("ho").splitting.pieces})
    alien = VectorField(laurent.algebra, [x2 / (m + 1), 0])
    with pytest.raises(NambuBCHError, match="not a monomial"):
        laurent.from_vector_field(alien)
    with pytest.raises(NambuBCHError, match="not a monomial"):
        laurent.function(x2 / (m + 1))
    with pytest.raises(NambuBCHError, match="not a polynomial"):
        laurent.function(sympy.cos(x1))


def test_jet_ring_is_a_backend_instance():
    """generic_nambu's jet ring: the backend's bracket with the total derivative equals the bracket computed
    with sympy on the generic functions H_i(x_i) (jets h{i}_k = H_i^(k)(x_i))."""
    from nambu_bch.shadow.generic_nambu import JetRing

    J = JetRing(4)
    B = J.backend
    assert isinstance(B, FieldBackend)
    h = {i: J.jet[("h", i, 0)] for i in (1, 2, 3)}
    g = {i: J.jet[("g", i, 0)] for i in (1, 2, 3)}
    X, Y = J.field(h[2], g[3]), J.field(h[1], g[2])
    Z = B.values(B.bracket(B.field(X), B.field(Y)))
    xs = (x1, x2, x3)
    Hf = {i: sympy.Function(f"H{i}")(xs[i - 1]) for i in (1, 2, 3)}
    Gf = {i: sympy.Function(f"G{i}")(xs[i - 1]) for i in (1, 2, 3)}
    subs = {}
    for i in (1, 2, 3):
        for k in range(5):
            subs[sympy.Symbol(f"h{i}_{k}")] = sympy.diff(Hf[i], xs[i - 1], k)
            subs[sympy.Symbol(f"g{i}_{k}")] = sympy.diff(Gf[i], xs[i - 1], k)

    def to_functions(p):
        return p.as_expr().xreplace(subs)

    Xs, Ys = [to_functions(c) for c in X], [to_functions(c) for c in Y]
    expected = _sympy_bracket(Xs, Ys, xs)
    assert [sympy.expand(to_functions(z) - e) for z, e in zip(Z, expected)] == [0, 0, 0]


def test_expression_backend_keeps_rational_functions_cancelled():
    """Rational components (the 'rational' model, V = -1/(1 + x1^2)) are kept as p/q in lowest terms, a
    canonical form: the bracket agrees with Eq. (CL1) computed by sympy alone, and a field that vanishes
    only after cancellation is recognised as zero."""
    S = model("rational").splitting
    algebra = S.system.algebra
    E = ExpressionBackend(algebra, {p.number: p.field for p in S.pieces})
    XY = E.bracket(E.fields[1], E.fields[2])
    expected = _sympy_bracket(*(E.fields[k] for k in (1, 2)), algebra.coordinates)
    assert _same(XY, expected)
    assert all(sympy.cancel(c) == c for c in XY)                      # already in lowest terms
    hidden_zero = 1 / (1 + x1) - (1 - x1) / (1 - x1**2)
    assert E.function(hidden_zero) == 0
    assert E.is_zero(E.from_vector_field(VectorField(algebra, [hidden_zero, hidden_zero])))
