"""Exact representations behind the BCH engine (nambu_bch.algebra.backend): Laurent polynomials, the system's
ring, the sympy backend, caches."""


import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import System, model
from nambu_bch.bch import clear_cache, effective_field, effective_field_bch
from nambu_bch.algebra.backend import ExpressionBackend, FieldBackend, PolynomialBackend, field_backend

from reference_fields import effective_field_reference

x1, x2, x3 = sympy.symbols("x1 x2 x3")
I1, I2, I3 = sympy.symbols("I1 I2 I3")


def _rigid_engine():
    S = model("rigid-body").splitting
    return S, PolynomialBackend.build(S.system.algebra, {p.number: p.field for p in S.pieces})


laurent_terms = st.lists(
    st.tuples(
        st.integers(-5, 5), st.integers(1, 4),           # rational coefficient
        st.integers(0, 2), st.integers(0, 2),            # powers of x1, x2
        st.integers(-2, 2), st.integers(-2, 2), st.integers(-2, 2),  # Laurent powers of I1, I2, I3
    ),
    min_size=1, max_size=5,
)


def _expr(terms):
    return sum(sympy.Rational(p, q) * x1**a * x2**b * I1**i * I2**j * I3**k for p, q, a, b, i, j, k in terms)


@settings(max_examples=40, deadline=None)
@given(laurent_terms, laurent_terms)
def test_property_laurent_round_trip_and_products(t1, t2):
    """algebra -> Laurent ring -> algebra is the identity, products agree with QQ(I1,I2,I3) arithmetic, and the
    canonical Laurent form makes the zero test exact (p * p_inv == 1)."""
    S, F = _rigid_engine()
    A = S.system.algebra
    e1, e2 = _expr(t1), _expr(t2)
    p1, p2 = F._from_algebra(A.convert(e1)), F._from_algebra(A.convert(e2))
    assert F.to_algebra(p1) == A.convert(e1)
    assert F.to_algebra(F.reduce(p1 * p2)) == A.convert(sympy.expand(e1 * e2))
    assert not F.reduce(p1 * p2 - p2 * p1)
    i1, i1_inv = F.ring.gens[4], F.ring.gens[5]
    assert F.reduce(i1 * i1_inv) == F.ring.one


def test_laurent_brackets_equal_vector_field_brackets():
    """Eq. (CL1) convention: the Laurent bracket equals VectorField.bracket on the rigid body pieces."""
    S, F = _rigid_engine()
    for a in (1, 2, 3):
        for b in (1, 2, 3):
            fast = F.combine([(1, F.bracket(F.fields[a], F.fields[b]))])
            assert fast == S[a].field.bracket(S[b].field)
    nested = F.bracket(F.fields[1], F.bracket(F.fields[2], F.fields[3]))
    assert F.combine([(sympy.Rational(3, 7), nested)]) == S[1].field.bracket(S[2].field.bracket(S[3].field)).scale(
        sympy.Rational(3, 7))


def test_non_monomial_denominators_fall_back_to_the_system_ring():
    """1/(m + 1) is not a Laurent coefficient: the polynomial backend runs on the system's ring over QQ(m), and
    both routes still agree with each other and with the VectorField reference recursion (h^4)."""
    system = System("x1 x2", ["x2**2/(2*(m + 1)) + m*x1**2/2"], "m", name="shifted")
    fields = {p.number: p.field for p in system.splitting.pieces}
    backend = field_backend(system.algebra, fields)
    assert isinstance(backend, PolynomialBackend) and isinstance(backend, FieldBackend) and not backend.laurent
    assert backend.ring == system.algebra.ring
    A, B = effective_field_bch(system.splitting, "121", 4), effective_field(system.splitting, "121", 4)
    C = effective_field_reference(system.splitting, "121", 4)
    assert all(A[j] == B[j] == C[j] for j in range(5))


def test_pendulum_uses_the_sympy_backend():
    """Non-polynomial fields (cos x1): expanded sympy backend; BCH route == backward (graded sympy) ==
    reference recursion, to h^4; the h^2 field is X_{H_2} of Eq. (SHPV),
    H_2 = -{{V,T},T}/24 + {{T,V},V}/12 = -V'' p^2/24 + V'^2/12 with V = -cos q."""
    system = System("x1 x2", ["x2**2/2 - cos(x1)"], [], name="pendulum")
    fields = {p.number: p.field for p in system.splitting.pieces}
    assert isinstance(field_backend(system.algebra, fields), ExpressionBackend)
    A = effective_field_bch(system.splitting, "121", 4)
    B = effective_field(system.splitting, "121", 4)
    C = effective_field_reference(system.splitting, "121", 2)
    for j in range(5):
        assert [sympy.simplify(a - b) for a, b in zip(A[j].to_sympy(), B[j].to_sympy())] == [0, 0]
    for j in range(3):
        assert [sympy.simplify(a - b) for a, b in zip(A[j].to_sympy(), C[j].to_sympy())] == [0, 0]
    q, p = x1, x2
    H2 = sympy.sin(q) ** 2 / 12 - sympy.cos(q) * p**2 / 24
    expected = (sympy.diff(H2, p), -sympy.diff(H2, q))
    assert [sympy.simplify(a - b) for a, b in zip(A[2].to_sympy(), expected)] == [0, 0]


@pytest.mark.parametrize("word", ["12321", "123"])
def test_generic_separable_system_both_routes(word):
    """Undefined H_i(x_i), G_j(x_j): BCH route == backward error analysis at h^2 for 12321 and 123."""
    H = [sympy.Function(f"H{i}")(x) for i, x in enumerate((x1, x2, x3), 1)]
    G = [sympy.Function(f"G{i}")(x) for i, x in enumerate((x1, x2, x3), 1)]
    S = System([x1, x2, x3], [sum(H), sum(G)], [], name="generic").splitting
    A, B = effective_field_bch(S, word, 2), effective_field(S, word, 2)
    for j in range(3):
        assert [sympy.expand(a - b) for a, b in zip(A[j].to_sympy(), B[j].to_sympy())] == [0, 0, 0]


def test_caches_do_not_change_results():
    """Evaluators are shared per splitting across compositions; clearing them changes nothing."""
    S = model("ho3").splitting
    first = [effective_field_bch(S, w, 4) for w in ("12321", "32123", "123")]
    clear_cache()
    again = [effective_field_bch(S, w, 4) for w in ("123", "32123", "12321")][::-1]
    assert all(X[j] == Y[j] for X, Y in zip(first, again) for j in range(5))


@pytest.mark.parametrize("fast", [True, False])
def test_rigid_body_h6_representations(fast):
    """Rigid body to h^6: Laurent and QQ(I1, I2, I3) representations of the BCH route agree with
    backward error analysis, and every odd coefficient of the symmetric word vanishes."""
    S = model("rigid-body").splitting
    X = effective_field_bch(S, "12321", 6, fast=fast)
    Y = effective_field(S, "12321", 6)
    assert all(X[j] == Y[j] for j in range(7))
    assert all(X[j].is_zero() for j in (1, 3, 5)) and not X[6].is_zero()
