"""The declared arithmetic: the coefficient fields (:mod:`nambu_bch.algebra.fields`) and the ring protocol.

The coefficient field names which of ``QQ``, ``QQ(params)``, ``QQ(theta)``, ``QQ(theta)(params)`` a sympy domain
is, with the flint context of ``QQ(params)`` (the fraction pairs of :mod:`nambu_bch.algebra.frac_rref`).
"""

from __future__ import annotations

import pickle

import pytest
import sympy
from sympy.polys.domains import EX, QQ, ZZ

from nambu_bch.algebra import PolynomialAlgebra, _flint, frac_rref
from nambu_bch.algebra.fields import CoefficientField

a, b = sympy.symbols("a b")
THETA = QQ.algebraic_field(sympy.cbrt(2))
FIELDS = {  # domain -> (rational, rational functions, algebraic, number field, parameters, extension)
    "QQ": (QQ, (True, False, False, True, (), ())),
    "QQ(a,b)": (QQ.frac_field(a, b), (False, True, False, False, (a, b), ())),
    "QQ(i)": (QQ.algebraic_field(sympy.I), (False, False, True, True, (), (sympy.I,))),
    "QQ(2^(1/3))(a)": (THETA.frac_field(a), (False, False, True, False, (a,), (sympy.cbrt(2),))),
}


@pytest.mark.parametrize("name", sorted(FIELDS))
def test_coefficient_field_classifies_the_four_fields(name):
    domain, expected = FIELDS[name]
    F = CoefficientField.of(domain)
    assert (F.is_rational, F.is_rational_functions, F.is_algebraic, F.is_number_field, F.parameters,
            F.extension) == expected
    assert F == CoefficientField.of(domain) and hash(F) == hash(CoefficientField.of(domain))
    assert CoefficientField.of(F) is F
    assert F.to_sympy(F.convert(sympy.Rational(3, 7))) == sympy.Rational(3, 7)


def test_coefficient_field_refuses_other_domains():
    assert CoefficientField.recognise(EX) is None
    assert CoefficientField.recognise(QQ[a]) is None
    from nambu_bch.errors import NambuBCHError

    with pytest.raises(NambuBCHError, match=r"^coefficient domain EX is not QQ, QQ\(parameters\)"):
        CoefficientField.of(EX)
    assert CoefficientField.recognise(ZZ).ground is ZZ  # the integral bracket rings of the Laurent backend


def test_coefficient_field_elements_of_an_extension():
    F = CoefficientField.of(QQ.algebraic_field(sympy.I))
    i = F.convert(sympy.I)
    assert F.domain.is_zero(i * i + F.convert(1))  # i^2 + 1 = 0 in the normal form, no simplification


def test_flint_context_only_for_rational_functions(monkeypatch):
    monkeypatch.delenv("NAMBU_BCH_DISABLE_FLINT", raising=False)
    if not _flint.available():
        pytest.skip("python-flint is not installed")
    for name, (domain, _) in FIELDS.items():
        ctx = CoefficientField.of(domain).flint_context()
        assert (ctx is not None) == (name == "QQ(a,b)"), name
        assert ctx is frac_rref.context(domain)
    assert CoefficientField.of(QQ.frac_field(a, b)).flint_context().nvars() == 2
    assert frac_rref.context(EX) is None


def test_polynomial_algebra_has_its_coefficient_field():
    x, y = sympy.symbols("x y")
    A = PolynomialAlgebra([x, y], [a], extension=[sympy.cbrt(2)])
    F = A.coefficient_field
    assert F.parameters == (a,) and F.extension == (sympy.cbrt(2),) and F.domain == A.domain
    assert pickle.loads(pickle.dumps(A)).coefficient_field == F


# -- the ring protocol: one test body over every implementation ----------------------------------------------------
# Each case: the ring, two elements ``a``, ``b`` made from its generators (the first ``n`` the coordinates), a known
# zero written as a sympy expression (structural zero on the normal form), and sympy expressions of ``a`` and ``b``
# when the ring converts sympy expressions (FlintRing takes its own elements only).
x, y, m = sympy.symbols("x y m")


def _case_polynomial():
    R = PolynomialAlgebra([x, y], [m])
    return R, x**2 * y / m + 3 * y, x * y - 2, x * y - y * x


def _case_jets():
    from nambu_bch.shadow.jets import JetAlgebra

    R = JetAlgebra([x, y], "F", 4)
    (F,) = R.functions()
    return R, x * F + F.diff(y), F**2 - y, x * F - F * x


def _case_flint():
    from nambu_bch.algebra.flint_ring import FlintRing

    return FlintRing(("x", "y", "m"), 2), None, None, None


def _case_extended():
    from nambu_bch.algebra.extended import ExtendedRing

    H = sympy.sin(x) * y + sympy.exp(y) / (1 + x**2)
    R = ExtendedRing([x, y], [m], [H, sympy.cos(x)])
    return R, H, m * sympy.cos(x) ** 2 - x, sympy.sin(x) ** 2 + sympy.cos(x) ** 2 - 1


RINGS = {"PolynomialAlgebra": _case_polynomial, "JetAlgebra": _case_jets, "FlintRing": _case_flint,
         "ExtendedRing": _case_extended}


@pytest.fixture(params=sorted(RINGS), scope="module")
def ring_case(request):
    if request.param in ("FlintRing", "ExtendedRing") and _flint._import() is None:  # pragma: no cover
        pytest.skip("python-flint is not installed")
    R, a, b, zero = RINGS[request.param]()
    if a is None:  # built from the generators (the ring converts only its own elements)
        gx, gy, gm = R.gens
        a, b = gx**2 * gy * gm + 3 * gy, gx * gy - 2
    else:
        a, b, zero = R.convert(a), R.convert(b), R.convert(zero)
    return request.param, R, a, b, zero


def test_every_implementation_declares_the_protocol(ring_case):
    from nambu_bch.algebra.ring import ExactRing, declared_rings

    _, R, *_ = ring_case
    assert isinstance(R, ExactRing)  # the structural check of the Protocol
    assert isinstance(R, declared_rings())  # and the declaration


def test_ring_protocol(ring_case):
    """gens, zero, arithmetic, diff as commuting derivations with the Leibniz rule, convert/common, is_zero."""
    name, R, a, b, zero = ring_case
    n = R.n
    assert n == 2 and len(R.gens) >= n
    coords = R.gens[:n]
    for i in range(n):  # D_i x_j = delta_ij
        for j in range(n):
            d = R.diff(coords[j], i)
            assert R.is_zero(d - 1) if i == j else R.is_zero(d)
    assert R.is_zero(R.zero) and R.is_polynomial(R.zero)
    assert R.is_zero(coords[0] * coords[1] - coords[1] * coords[0])  # commutative
    assert not R.is_zero(a) and R.is_zero(a - a) and R.is_zero(a + R.zero - a)
    assert R.is_zero((a + b) * (a - b) - (a * a - b * b))
    for i in range(n):
        assert R.is_zero(R.diff(a * b, i) - (R.diff(a, i) * b + a * R.diff(b, i))), (name, i)  # Leibniz
        assert R.is_zero(R.diff(a + b, i) - R.diff(a, i) - R.diff(b, i))  # additive
        assert R.is_zero(R.diff(R.diff(a * b, 0), 1) - R.diff(R.diff(a * b, 1), 0))  # D_0 D_1 = D_1 D_0
    if zero is not None:
        assert R.is_polynomial(zero) and R.is_zero(zero)  # x*y - y*x, or sin^2 + cos^2 - 1 in the extended ring
    assert R.convert(a) is a or R.is_zero(R.convert(a) - a)
    pair = R.common(a, b)
    assert len(pair) == 2 and all(R.is_polynomial(v) for v in pair)
    assert R.is_zero(pair[0] - a) and R.is_zero(pair[1] - b)


def test_extended_ring_zero_is_structural():
    from nambu_bch.algebra.extended import ExtendedRing

    if _flint._import() is None:  # pragma: no cover
        pytest.skip("python-flint is not installed")
    R = ExtendedRing([x], [], [sympy.sin(x)])
    s, c = R.convert(sympy.sin(x)), R.convert(sympy.cos(x))
    assert R.is_zero(s * s + c * c - 1) and not R.is_zero(s * s - c * c)
    assert R.is_zero(R.diff(s, 0) - c) and R.is_zero(R.diff(c, 0) + s)


def test_check_ring_refuses_other_objects():
    from nambu_bch.algebra import VectorField, liouville_field
    from nambu_bch.algebra.ring import check_ring
    from nambu_bch.errors import NambuBCHError

    with pytest.raises(NambuBCHError, match=r"^algebra must be an exact ring \(a PolynomialAlgebra or FlintRing\), "):
        VectorField("not a ring", [x])
    with pytest.raises(NambuBCHError, match="exact ring"):
        liouville_field(object(), x)
    R = PolynomialAlgebra([x, y])
    assert check_ring(R, "algebra") is R


def test_polynomial_ring_is_the_same_ring_with_and_without_flint():
    """The direct route's fraction-free ring QQ[x, constants]: FlintRing or PolynomialAlgebra behind one factory,
    the same Liouville field (Eq. gLiouville) term by term through ``from_terms``/``terms``."""
    from nambu_bch.algebra import liouville_field
    from nambu_bch.algebra.flint_ring import FlintRing, polynomial_ring

    q, p, c = sympy.symbols("q p c")
    H = {(0, 2, 0): QQ(1, 2), (2, 0, 1): QQ(3)}  # p^2/2 + 3 c q^2
    fields = []
    for flint in ((False, True) if _flint._import() is not None else (False,)):
        R = polynomial_ring([q, p], [c], flint)
        assert isinstance(R, FlintRing) == flint and R.n == 2
        X = liouville_field(R, R.from_terms(H))
        fields.append([{m: QQ(int(v.numerator), int(v.denominator)) for m, v in R.terms(comp).items()}
                       for comp in X.components])
        assert R.is_zero(R.from_terms({})) and R.terms(R.from_terms({})) == {}
    assert fields[0] == [{(0, 1, 0): QQ(1)}, {(1, 0, 1): QQ(-6)}]  # X_H = (dH/dp, -dH/dq)
    assert all(f == fields[0] for f in fields)
