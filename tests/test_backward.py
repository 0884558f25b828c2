"""Backward error analysis (nambu_bch/bch/backward.py): what the modified field's recursion computes.

``Z_j^i = [h^(j+1)] Phi^* x_i - sum_{k >= 2} [h^(j+1)] (hY)^k x_i / k!`` with
``[h^m] U_k = sum_l Z_l [h^(m-1-l)] U_{k-1}``
(Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.1).  A symmetric composition has ``Z_l = 0``
for every odd ``l`` (ibid., Theorem IX.3.2), so the recursion applies only the non-zero ``Z_l``.
"""

from __future__ import annotations

import pytest

from nambu_bch import model
from nambu_bch.algebra import backend as backend_module
from nambu_bch.bch import backward as backward_module
from nambu_bch.bch import effective_field


def test_modified_field_applies_no_zero_field(monkeypatch):
    """The ho3 system (the paper's Eqs. Ex1, H, G) with Strang's 12321 through h^4: no zero Z_l is ever applied,
    and the odd Z_j vanish (a symmetric method); Z_2 is the same with the Laurent and the plain ring."""
    applied = []
    for cls in (backward_module._FlintSeries, backward_module._BackendSeries):
        original = cls.apply
        monkeypatch.setattr(cls, "apply", lambda self, X, f, _o=original: applied.append(self.is_zero(X)) or _o(self, X, f))
    splitting = model("ho3").splitting
    X = effective_field(splitting, "12321", order=4)
    assert applied and not any(applied)
    assert all(X[j].is_zero() for j in (1, 3)) and not X[2].is_zero() and not X[4].is_zero()
    assert X[2].to_sympy() == effective_field(splitting, "12321", order=2, fast=False)[2].to_sympy()


@pytest.fixture(scope="module")
def symbolic_rigid_body():
    """The rigid body with symbolic moments I1, I2, I3 (QQ(I1, I2, I3), the Laurent backend) and 12321 to h^6."""
    splitting = model("rigid-body").splitting
    return splitting, effective_field(splitting, "12321", order=6)


def test_series_stay_in_flint_until_the_end(monkeypatch, symbolic_rigid_body):
    """On flint, backward error analysis of the symbolic rigid body never goes through the backend's ``apply``
    (which converts its argument to flint and its result back, once per Lie derivative): the pull-back's coefficients
    are handed to the modified field once (3 coordinates x h^0..h^7) and each ``Z_j`` component is converted back once
    (3 x h^0..h^6), with no Laurent reduction on the way (only the inverses ``1/I_k`` occur).  The result is the one of the backend's own arithmetic, to h^6."""
    from nambu_bch.algebra import _flint

    if not _flint.available():
        pytest.skip("python-flint is switched off")
    splitting, X = symbolic_rigid_body
    calls = []
    monkeypatch.setattr(backend_module.PolynomialBackend, "apply", lambda *a: calls.append("apply"))
    unload = backward_module._FlintSeries.unload
    monkeypatch.setattr(backward_module._FlintSeries, "unload", lambda self, f: calls.append("unload") or unload(self, f))
    assert effective_field(splitting, "12321", order=6) == X
    assert calls == ["unload"] * (24 + 21)
    monkeypatch.undo()
    monkeypatch.setattr(backward_module, "_series_arithmetic", backward_module._BackendSeries)
    assert effective_field(splitting, "12321", order=6) == X


def test_flint_series_reduce_like_the_backend(monkeypatch):
    """The harmonic oscillator's pieces ``x2/m d/dx1`` and ``-m omega^2 x1 d/dx2`` multiply ``m`` by ``1/m``: the flint
    series bring such products to the canonical Laurent form (the backend's ``reduce``), and the modified field is
    the one of the backend's own arithmetic and of the plain ring over QQ(m, omega), to h^4."""
    from nambu_bch.algebra import _flint

    if not _flint.available():
        pytest.skip("python-flint is switched off")
    splitting = model("ho").splitting
    reduced = []
    reduce = backend_module.PolynomialBackend.reduce

    def recording(self, p):
        out = reduce(self, p)
        reduced.append(out != p)
        return out

    monkeypatch.setattr(backend_module.PolynomialBackend, "reduce", recording)
    flint_result = effective_field(splitting, "121", order=4)
    assert any(reduced)  # some product of the series held both m and 1/m
    monkeypatch.setattr(backward_module, "_series_arithmetic", backward_module._BackendSeries)
    assert effective_field(splitting, "121", order=4) == flint_result
    assert effective_field(splitting, "121", order=4, fast=False) == flint_result


def test_flint_apply_converts_each_monomial_once():
    """On flint (python-flint on), ``X f`` of the Laurent backend comes back with Python-int exponents (flint's fmpz
    must not reach sympy's ring), the same as sympy's own product, and each monomial's exponents are converted
    once per backend (kept for the next application)."""
    from nambu_bch.algebra import _flint

    if not _flint.available():
        pytest.skip("python-flint is switched off")
    splitting = model("rigid-body").splitting
    algebra = splitting.system.algebra
    fields = dict(enumerate((p.field for p in splitting.pieces), 1))
    backend = backend_module.field_backend(algebra, fields, laurent=True)
    assert backend.flint_q is not None
    X = backend.fields[1]
    x1, x2, x3 = algebra.coordinates
    f = backend.function(x1 * x2 * x3 + x2**2)  # X_1 = (x2 x3 (I3 - I2) / (I2 I3), 0, 0): X_1 f = x2^2 x3^2 (..)
    Xf = backend.apply(X, f)
    assert Xf and all(type(e) is int for m in Xf for e in m)
    known = dict(backend._exponents)
    assert len(known) == len(Xf) and backend.apply(X, f) == Xf and backend._exponents == known
    plain = sum((c * backend.derivative(f, i) for i, c in enumerate(backend.values(X)) if c), backend.zero)
    assert Xf == backend.reduce(plain)
