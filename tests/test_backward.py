"""Backward error analysis (nambu_bch/bch/backward.py): what the modified field's recursion computes.

``Z_j^i = [h^(j+1)] Phi^* x_i - sum_{k >= 2} [h^(j+1)] (hY)^k x_i / k!`` with ``[h^m] U_k = sum_l Z_l [h^(m-1-l)] U_{k-1}``
(Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.1).  A symmetric composition has ``Z_l = 0``
for every odd ``l`` (ibid., Theorem IX.3.2), so the recursion applies only the non-zero ``Z_l``.
"""

from __future__ import annotations

from nambu_bch import model
from nambu_bch.algebra import backend as backend_module
from nambu_bch.bch import effective_field


def test_modified_field_applies_no_zero_field(monkeypatch):
    """The ho3 system (the paper's Eqs. Ex1, H, G) with Strang's 12321 through h^4: no zero Z_l is ever applied,
    and the odd Z_j vanish (a symmetric method); Z_2 is the same with the Laurent and the plain ring."""
    applied = []
    cls = backend_module.PolynomialBackend
    original = cls.apply
    monkeypatch.setattr(cls, "apply", lambda self, X, f: applied.append(self.is_zero(X)) or original(self, X, f))
    splitting = model("ho3").splitting
    X = effective_field(splitting, "12321", order=4)
    assert applied and not any(applied)
    assert all(X[j].is_zero() for j in (1, 3)) and not X[2].is_zero() and not X[4].is_zero()
    assert X[2].to_sympy() == effective_field(splitting, "12321", order=2, fast=False)[2].to_sympy()
