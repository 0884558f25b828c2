"""Compositions with complex coefficients on a system: X_eff over QQ(i), shadow pairs over QQ(i), complex numerics.

Every result is checked two independent ways: backward error analysis against the formal BCH series (exact
equality of ring elements over QQ(i)), the direct route against the FI route (zero by normal form), the shadow
pair against X_eff (``assert_shadow_pair`` in the ring over QQ(i)), and, for the harmonic oscillator, the
matrix logarithm of the exact complex step matrix; the complex128 run against that matrix's powers.

Methods: ``S2 = S_{gh} S_{conj(g) h}`` with ``g = (1 + i)/2`` on the Strang step (Castella, Chartier, Descombes,
Vilmart, BIT 49 (2009) 487, Sect. 3: compositions of a symmetric step with complex conjugate times), on two and
three pieces; the complex triple jump "A 4-4 c" of SplittingOrderConditions.jl's CheckMethods notebook,
gamma_1 = 1/(2 - 2^(1/3) e^(2 pi i/3)) (Hansen & Ostermann, BIT 49 (2009) 527).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch.bch.backward import effective_field
from nambu_bch.bch.concrete import effective_field_bch
from nambu_bch.cli import main
from nambu_bch.errors import InvalidRunError, NambuBCHError
from nambu_bch.numeric import iterate_complex
from nambu_bch.testing import assert_shadow_pair

#: S_{gh} S_{conj(g)h} of the Strang step 121, g = (1 + i)/2: order 2, its h^3 term imaginary.
S2 = "1:1/4+I/4,2:1/2+I/2,1:1/2,2:1/2-I/2,1:1/4-I/4"
#: The same on the three-piece Strang step 12321.
S3 = "1:1/4+I/4,2:1/4+I/4,3:1/2+I/2,2:1/4+I/4,1:1/2,2:1/4-I/4,3:1/2-I/2,2:1/4-I/4,1:1/4-I/4"
_G = "1/(2-2^(1/3)*(-1/2+sqrt(3)*I/2))"
#: CheckMethods "A 4-4 c": the complex triple jump of the Strang step 121 (palindromic, order 4).
TRIPLE_JUMP = f"1:{_G}/2,2:{_G},1:(1-{_G})/2,2:1-2*{_G},1:(1-{_G})/2,2:{_G},1:{_G}/2"
x1, x2, m, omega, h = sympy.symbols("x1 x2 m omega h")


def _is_zero_in(algebra, expr) -> bool:
    """Zero decided by the normal form of the ring over the coefficients' field."""
    value = algebra.convert(sympy.expand(expr))
    assert algebra.is_polynomial(value), expr
    return algebra.is_zero(value)


# ------------------------------------------------------------------------------------------------
# 1. X_eff over QQ(i)


@pytest.mark.parametrize("name, spec, order", [("ho", S2, 4), ("ho3", S3, 3), ("rigid-body", S3, 2)])
def test_effective_field_over_qq_i_two_routes(name, spec, order):
    """Backward error analysis and the formal BCH series give the same X_eff, elements of QQ(i)(params)[x]."""
    splitting = nb.model(name).splitting
    X = effective_field(splitting, spec, order)
    Y = effective_field_bch(splitting, spec, order)
    assert X == Y
    assert X[1].is_zero()                           # the order condition of order 2: sum of [X_i, X_j] terms cancel
    assert "I" in str(X[0].algebra.domain)          # QQ<I>(params)
    assert any(sympy.im(c) != 0 for Z in X.coefficients for c in Z.to_sympy()) or name == "rigid-body"


def test_effective_field_of_the_oscillator_is_the_log_of_the_complex_step_matrix():
    """Third route for ho: X_eff = log(M(h))/h of the exact 2x2 step matrix, the shears exp(c h A_k) = 1 + c h A_k."""
    A = {1: sympy.Matrix([[0, 1 / m], [0, 0]]), 2: sympy.Matrix([[0, 0], [-m * omega**2, 0]])}
    M = sympy.eye(2)
    for k, c in nb.composition(S2).factors():       # operator order = the order the sub-flows act: left to right
        M = (sympy.eye(2) + c * h * A[k]) * M
    E = (M - sympy.eye(2)).applyfunc(sympy.expand)
    top = 6
    def truncated(e):
        e = sympy.expand(e)
        return sum((e.coeff(h, k) * h**k for k in range(top)), sympy.Integer(0))

    log, power = sympy.zeros(2), sympy.eye(2)
    for n in range(1, top):                           # E = O(h): log(1 + E) = sum (-1)^(n+1) E^n / n through h^5
        power = (power * E).applyfunc(truncated)
        log += (-1) ** (n + 1) * power / n
    X = effective_field(nb.model("ho").splitting, S2, 4)
    for j in range(5):
        Lj = log.applyfunc(lambda e: sympy.expand(e).coeff(h, j + 1))
        field = Lj * sympy.Matrix([x1, x2])
        assert all(sympy.expand(a - b) == 0 for a, b in zip(field, X[j].to_sympy())), j
    assert X[3].to_sympy() == (-sympy.I * omega**4 * x1 / 16, sympy.I * omega**4 * x2 / 16)


def test_coefficients_reach_the_domain_through_one_conversion_of_the_generator(monkeypatch):
    """A composition's coefficients, elements of a number field K = QQ(theta) (here sympy's QQ_I), become scalars of
    the backend as polynomials in theta's image: one ``from_sympy`` (a minimal polynomial and a primitive-element
    computation each, ~20 ms) per field, not one per number; the values are from_sympy's own."""
    from nambu_bch.algebra.backend import PolynomialBackend

    comp = nb.composition(S2)
    backend = PolynomialBackend.build(nb.model("ho").algebra.with_constants(h, extension=comp.extension), {})
    calls = []
    from_sympy = type(backend.domain).from_sympy
    monkeypatch.setattr(type(backend.domain), "from_sympy", lambda self, a: calls.append(a) or from_sympy(self, a))
    values = backend.constants(comp.coefficients)
    assert len(calls) == 1
    assert values == [backend.domain.from_sympy(c) for c in comp.coefficients]


@pytest.fixture(scope="module")
def triple_jump_field():
    return effective_field(nb.model("ho").splitting, TRIPLE_JUMP, 4)


def test_complex_triple_jump_has_order_four_on_a_system(triple_jump_field):
    """CheckMethods "A 4-4 c" (order 4): Z_1 = Z_2 = Z_3 = 0, Z_4 complex; the BCH route agrees exactly."""
    X = triple_jump_field
    assert [X[j].is_zero() for j in range(4)] == [False, True, True, True] and not X[4].is_zero()
    assert X.composition.extension == (sympy.cbrt(2), sympy.sqrt(3), sympy.I)
    assert X == effective_field_bch(nb.model("ho").splitting, TRIPLE_JUMP, 4)


# ------------------------------------------------------------------------------------------------
# 2. shadow pairs over QQ(i)


@pytest.fixture(scope="module")
def ho3_families():
    return {route: nb.shadow_hamiltonians("ho3", S3, order=3, route=route) for route in ("direct", "fi")}


def test_shadow_pair_over_qq_i_direct_and_fi_agree(ho3_families):
    """ho3, S3 through h^3: both routes give the same alpha-family (zero by normal form over QQ(i)), and it is a
    shadow pair of X_eff (X_{H_S,G_S} - X_eff = O(h^4) in the ring over QQ(i))."""
    D, F = ho3_families["direct"], ho3_families["fi"]
    assert D.exists and F.exists
    alg = nb.model("ho3").algebra.with_constants(h, nb.symbols.ALPHA, extension=(sympy.I,))
    assert _is_zero_in(alg, D.H_S - F.H_S) and _is_zero_in(alg, D.G_S - F.G_S)
    assert D.G_S.has(sympy.I)                        # the h^3 correction is imaginary
    assert_shadow_pair("ho3", S3, D.H_S, D.G_S, order=3)


def test_complex_shadow_pair_prints_i_and_reads_back(ho3_families):
    """Text prints ``I``, LaTeX ``i``; the JSON strings read back (sympify, the model's symbols) to the same pair."""
    D = ho3_families["direct"]
    assert "I*h**3" in D.to_text() and r"\frac{i h^{3}" in D.to_latex()
    data = json.loads(json.dumps(D.to_dict()))
    names = {s: sympy.Symbol(s) for s in ("x1", "x2", "x3", "m", "omega", "h", "alpha")}
    alg = nb.model("ho3").algebra.with_constants(h, nb.symbols.ALPHA, extension=(sympy.I,))
    assert _is_zero_in(alg, sympy.sympify(data["G_S"], locals=names) - D.G_S)
    assert "I" in data["series"]["G_S"]["3"]


def test_results_over_qq_i_pickle_to_equal_values(ho3_families):
    """Rings over QQ(i) reduce to their description (docs/architecture.md): a worker's result equals the original."""
    import pickle

    D = ho3_families["direct"]
    X = effective_field(nb.model("ho").splitting, S2, 3)
    assert pickle.loads(pickle.dumps(D)) == D and pickle.loads(pickle.dumps(X)) == X


def test_a_complex_coefficient_is_printed_as_real_and_imaginary_parts():
    """``factor`` would pull ``I`` out of ``a + b I`` (``I*(b - a I)``); the layout keeps ``factor(a) + I factor(b)``."""
    from nambu_bch.printing import laid_out

    x, mass = sympy.symbols("x m")
    [(k, c)] = laid_out({4: sympy.expand((3 + 2 * sympy.I) * (mass + 1) * x**2 / (2 * sympy.cbrt(2)))}, [x])
    assert k == 4 and sympy.expand(c - (3 + 2 * sympy.I) * (mass + 1) * x**2 / (2 * sympy.cbrt(2))) == 0
    assert str(c) == "x**2*(3*2**(2/3)*(m + 1)/4 + 2**(2/3)*I*(m + 1)/2)"     # real part + I * imaginary part


def test_fi_route_over_an_algebraic_field():
    """The FI route solves over the composition's field: yoshida:121 (QQ(2^(1/3))) and S2 (QQ(i)) match the direct
    route (before, it converted the commutators' coefficients into QQ(params) and failed)."""
    for spec, order in (("yoshida:121", 4), (S2, 3)):
        D = nb.shadow_hamiltonians("ho", spec, order=order)
        F = nb.shadow_hamiltonians("ho", spec, order=order, route="fi")
        ext = nb.composition(spec).extension
        alg = nb.model("ho").algebra.with_constants(h, extension=ext)
        assert _is_zero_in(alg, D.H_S - F.H_S), spec


def test_complex_coefficients_refused_on_non_polynomial_hamiltonians():
    """The non-polynomial routes keep rational scalars: one line naming the system's Hamiltonian."""
    with pytest.raises(NambuBCHError, match="polynomial Hamiltonians only, and pendulum has"):
        nb.shadow_hamiltonians("pendulum", S2, order=3)
    X = effective_field(nb.model("pendulum").splitting, S2, 3)   # X_eff itself is exact sympy there
    assert X == effective_field_bch(nb.model("pendulum").splitting, S2, 3)


# ------------------------------------------------------------------------------------------------
# 3. numerics in complex128


def _step_matrix(spec, hv):
    """The exact step of ho (m = omega = 1) as a complex matrix: the shears 1 + c h A_k, applied left to right."""
    A = {1: np.array([[0, 1], [0, 0]], dtype=complex), 2: np.array([[0, 0], [-1, 0]], dtype=complex)}
    M = np.eye(2, dtype=complex)
    for k, c in nb.composition(spec).factors():
        M = (np.eye(2) + complex(c) * hv * A[k]) @ M
    return M


def test_iterate_runs_complex_compositions_in_complex128():
    """iterate dispatches to iterate_complex; one state and a batch agree; the samples are powers of the step matrix."""
    x = nb.iterate("ho", S2, 0.1, 40, [1.0, 0.5], every=10)
    assert x.dtype == np.complex128 and x.shape == (5, 2) and abs(x[-1].imag).max() > 1e-7
    M = _step_matrix(S2, 0.1)
    expected = np.linalg.matrix_power(M, 40) @ np.array([1.0, 0.5])
    assert np.allclose(x[-1], expected, rtol=0, atol=1e-13)
    batch = iterate_complex("ho", S2, 0.1, 40, np.array([[1.0, 0.0], [0.5, 1.0]]), every=10)
    assert batch.shape == (5, 2, 2) and np.allclose(batch[:, :, 0], x, rtol=0, atol=1e-14)
    real = iterate_complex("ho", S2, 0.1, 40, [1.0, 0.5], project=True)
    assert real.dtype == np.float64 and np.allclose(real[1], (M @ np.array([1.0, 0.5])).real, atol=1e-15)


def test_complex_runs_refuse_what_they_cannot_do():
    with pytest.raises(InvalidRunError, match="kahan=True applies to float64 runs"):
        nb.iterate("ho", S2, 0.1, 10, [1.0, 0.0], kahan=True)
    with pytest.raises(InvalidRunError, match="branch cut or a pole"):
        iterate_complex("kepler", "1:1/2+I/2,2:1,1:1/2-I/2", 0.01, 2, None)
    with pytest.raises(InvalidRunError, match="compiled float64 kernels take real ones"):
        list(nb.numeric.iterate_chunks("ho", S2, 0.1, 10, [1.0, 0.0]))


def test_check_of_a_complex_method_measures_the_complex_shadow_pair():
    """ho, S2, t up to 20: the complex map keeps the complex H_S^[k] to O(h^(k+1)) without drift, far better than H
    (O(h^2)); halving h divides max |H_S^[2](x_n) - H_S^[2](x_0)| by about 2^3 (measured 8.0)."""
    r1 = nb.check("ho", S2, 0.1, 200, [1.0, 0.0], order=2, include=("H", "H_S"))
    r2 = nb.check("ho", S2, 0.05, 400, [1.0, 0.0], order=2, include=("H", "H_S"))
    assert r1.arithmetic == "complex128" and r1.to_dict()["arithmetic"] == "complex128"
    assert r1.max_abs_error["H_S"] < r1.max_abs_error["H"] / 10
    assert 7 < r1.max_abs_error["H_S"] / r2.max_abs_error["H_S"] < 9
    assert 3.5 < r1.max_abs_error["H"] / r2.max_abs_error["H"] < 4.5


# ------------------------------------------------------------------------------------------------
# 4. the command line


def test_cli_shadow_and_check_take_complex_integrators(capsys):
    assert main(["shadow", "--model", "ho", "--integrator", S2, "--order", "3", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    names = {s: sympy.Symbol(s) for s in ("x1", "x2", "m", "omega", "h")}
    assert sympy.sympify(data["series"]["H_S"]["3"], locals=names) == -sympy.I * omega**4 * x1 * x2 / 16
    assert main(["check", "--model", "ho", "--integrator", S2, "--steps", "50", "--x0", "1,0", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["arithmetic"] == "complex128" and data["max_abs_error"]["H_S"] < data["max_abs_error"]["H"]
    assert main(["shadow", "--model", "pendulum", "--integrator", S2, "--format", "text"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "polynomial Hamiltonians only" in err


def test_compare_measures_a_complex_map_against_the_real_reference():
    """``compare`` keeps the complex final state: its error is the modulus of the complex difference (no cast to real,
    no ComplexWarning), and it falls like h^2 for this second-order complex method."""
    import warnings

    from nambu_bch.design import compare

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = compare("ho", [S2], t_end=1.0, steps=(10, 20, 40))
    row = c.rows[0]
    errors = [p["error"] for p in c.curves[S2]]
    assert all(e > 0 for e in errors) and abs(row["slope"] + 2) < 0.2
