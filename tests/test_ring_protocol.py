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
    with pytest.raises(TypeError, match="not QQ"):
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
