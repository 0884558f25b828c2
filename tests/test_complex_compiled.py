"""The compiled complex128 loop of a composition with complex coefficients against the interpreted reference.

``iterate_complex(backend="numba")`` runs the step generated from the exact sub-flows
(:mod:`nambu_bch.numeric.complex_codegen`); ``backend="numpy"`` lambdifies the same sub-flows and steps one state on
``cmath``.  Both do the same complex128 operations in the same order (products ``(ac - bd, ad + bc)`` unfused, the
parameter factors rounded once), so one trajectory agrees bit for bit over 10^3 steps, for the complex map and for
its real projection (Blanes, Casas & Murua, SeMA J. 50 (2010) 47, Sect. 4), on ho3 (Horikoshi, Sect. 5.5) and on
the rigid body.  The method: the Strang step 12321 at the complex times (1 + i)h/2 and (1 - i)h/2, its two middle
factors merged (Castella, Chartier, Descombes, Vilmart, BIT 49 (2009) 487, Sect. 3).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch import model
from nambu_bch.errors import InvalidRunError, NumericalRangeError
from nambu_bch.integrators.composition import composition_for
from nambu_bch.numeric import complex_codegen, complex_iterate, iterate_complex, numba_available
from nambu_bch.numeric.complex_codegen import ComplexKernel, complex_kernel, complex_program, complex_source

numba_only = pytest.mark.skipif(not numba_available(), reason="numba not installed or disabled")

#: S_{(1+i)h/2} S_{(1-i)h/2} of the Strang step 12321 with the adjacent piece-3 factors merged: five sub-flows.
W = "1:1/2+I/2,2:1/2+I/2,3:1,2:1/2-I/2,1:1/2-I/2"
X0 = [0.7, -0.3, 1.1]
#: Rigid-body moments whose parameter factors ((I3 - I2)/(I2 I3) = 1/6, ...) are not dyadic.
INERTIA = {"I1": 1.0, "I2": 2.0, "I3": 3.0}


@pytest.fixture(scope="module")
def ho3_loop():
    """The compiled single-state loop of W on ho3 (one numba compilation, ~1-4 s cold; cached on disk after)."""
    if not numba_available():
        pytest.skip("numba not installed or disabled")
    kern = complex_kernel("ho3", W)
    kern.compile()
    return kern


@numba_only
@pytest.mark.parametrize("project", [False, True])
def test_compiled_ho3_run_gives_the_reference_bits(ho3_loop, project):
    """10^3 steps sampled every 7th, default and non-dyadic parameters: the compiled samples are the reference's."""
    for params in (None, {"m": 3.0, "omega": 0.7}):
        fast = iterate_complex("ho3", W, 0.1, 1000, X0, params, 7, project=project, backend="numba")
        ref = iterate_complex("ho3", W, 0.1, 1000, X0, params, 7, project=project, backend="numpy")
        assert fast.dtype == ref.dtype == (np.float64 if project else np.complex128)
        assert fast.shape == ref.shape == (144, 3)
        np.testing.assert_array_equal(fast, ref)
    # once the loop is compiled in this process, "auto" takes it even for a short run: the same samples
    short = iterate_complex("ho3", W, 0.1, 10, X0, project=project)
    np.testing.assert_array_equal(short, iterate_complex("ho3", W, 0.1, 10, X0, project=project, backend="numpy"))


@numba_only
def test_a_complex_loop_gets_no_c_library(ho3_loop):
    """numeric.clib prints the real step program only: compiling a complex loop (with a C compiler present) neither
    builds nor loads a library for it."""
    from nambu_bch.numeric.clib import paths

    assert ho3_loop.library() is None
    assert not paths(ho3_loop)[0].exists() and not paths(ho3_loop)[1].exists()


@numba_only
def test_iterate_and_check_pass_the_backend_on(ho3_loop):
    """``iterate`` and ``check`` hand a complex word and their ``backend`` to the complex run."""
    fast = nb.iterate("ho3", W, 0.1, 200, X0, every=50, backend="numba")
    np.testing.assert_array_equal(fast, iterate_complex("ho3", W, 0.1, 200, X0, every=50, backend="numpy"))
    r1 = nb.check("ho3", W, 0.1, 200, X0, include=("H", "G"), backend="numba")
    r2 = nb.check("ho3", W, 0.1, 200, X0, include=("H", "G"), backend="numpy")
    assert r1.max_abs_error == r2.max_abs_error and r1.arithmetic == "complex128"


@numba_only
def test_compiled_run_refuses_an_escaping_orbit_like_the_reference(ho3_loop):
    """h = 3: the complex orbit overflows between the same samples on both backends, in the same one line."""
    messages = []
    for backend in ("numba", "numpy"):
        with pytest.raises(NumericalRangeError) as info:
            iterate_complex("ho3", W, 3.0, 3000, [1.0, 1.0, 1.0], every=10, backend=backend)
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "between steps 180 and 190" in messages[0]


@numba_only
def test_compiled_rigid_body_and_batches():
    """The rigid body (non-dyadic moments): one state bit for bit, complex and projected; the compiled batch loop gives
    each column the single-state bits, and numpy's batch (its complex products fused) agrees to 1e-13 relative.
    (At h = 0.1 this complex orbit from X0 escapes after ~740 steps.)"""
    X = np.array([[0.7, 0.3], [-0.3, 0.2], [1.1, -0.4]])
    for project in (False, True):
        fast = iterate_complex("rigid-body", W, 0.05, 1000, X0, INERTIA, 7, project=project, backend="numba")
        ref = iterate_complex("rigid-body", W, 0.05, 1000, X0, INERTIA, 7, project=project, backend="numpy")
        np.testing.assert_array_equal(fast, ref)
        batch = iterate_complex("rigid-body", W, 0.05, 1000, X, INERTIA, 7, project=project, backend="numba")
        np.testing.assert_array_equal(batch[:, :, 0], fast)
        vector = iterate_complex("rigid-body", W, 0.05, 1000, X, INERTIA, 7, project=project, backend="numpy")
        assert np.abs(batch - vector).max() <= 1e-13 * np.abs(vector).max()


def test_auto_interprets_a_short_run_without_generating_a_kernel(monkeypatch):
    """A run below INTERPRET_FACTOR_STEPS whose loop is not compiled never touches the compiled path; a batch then
    steps each column on cmath (the single-state bits)."""
    def refuse(*args, **kwargs):
        raise AssertionError("a short run generated a complex kernel")

    monkeypatch.setattr(complex_codegen, "complex_kernel", refuse)
    word = "1:1/4+I/4,2:1/2+I/2,1:1/2,2:1/2-I/2,1:1/4-I/4"
    one = iterate_complex("ho", word, 0.1, 20, [1.0, 0.5])
    batch = iterate_complex("ho", word, 0.1, 20, np.array([[1.0, 0.0], [0.5, 1.0]]))
    np.testing.assert_array_equal(batch[:, :, 0], one)


def test_backend_names_are_checked(monkeypatch):
    with pytest.raises(InvalidRunError, match="backend 'fast' is not one of auto, numba, numpy"):
        iterate_complex("ho", "1:1/2+I/2,2:1,1:1/2-I/2", 0.1, 2, [1.0, 0.0], backend="fast")
    with pytest.raises(InvalidRunError, match="backend must be one of"):
        iterate_complex("ho", "1:1/2+I/2,2:1,1:1/2-I/2", 0.1, 2, [1.0, 0.0], backend=None)
    monkeypatch.setenv("NAMBU_BCH_DISABLE_NUMBA", "1")
    with pytest.raises(InvalidRunError, match="backend 'numba' was requested but numba is not installed"):
        iterate_complex("ho", "1:1/2+I/2,2:1,1:1/2-I/2", 0.1, 2, [1.0, 0.0], backend="numba")
    monkeypatch.setattr(complex_iterate, "INTERPRET_FACTOR_STEPS", 0)  # even a "large" run: numpy without numba
    assert iterate_complex("ho", "1:1/2+I/2,2:1,1:1/2-I/2", 0.1, 2, [1.0, 0.0]).shape == (3, 2)


def test_a_coefficient_beyond_complex128_is_refused_on_both_backends():
    for backend in ("numpy", "numba") if numba_available() else ("numpy",):
        with pytest.raises(NumericalRangeError, match=r"coefficient I \+ exp\(800\) of .* beyond the complex128 range"):
            iterate_complex("ho", "1:exp(800)+I,2:1,1:1-exp(800)-I", 0.1, 3, [1.0, 0.0], backend=backend)


def test_reference_rounds_each_parameter_factor_once():
    """With I = (1, 2, 3) the factor (I3 - I2)/(I2 I3) of the rigid body's first sub-flow is 1/6 rounded once (it was
    printed to 15 digits, 0.166666666666667, an error of 2 ulps carried into every step)."""
    f = complex_iterate.complex_subflows(model("rigid-body"), W, INERTIA)[0][0]
    assert f(0j, 1 + 0j, 1 + 0j, 1 + 0j)[0] == 1 / 6


def test_generated_source_holds_no_model_name():
    """The model's coordinates (x1..x3), parameters (I1..I3) and time (t) reach the source only as internal names."""
    source = complex_source(complex_program("rigid-body", W))
    names = set(re.findall(r"\b[A-Za-z_]\w*\b", source.partition('"""')[2].partition('"""')[2]))
    assert not names & {"x1", "x2", "x3", "I1", "I2", "I3", "t"}
    assert {n for n in names if re.fullmatch(r"[vwktp]\d+", n)} >= {"v0", "v1", "w0", "k0", "t0", "p0"}
    prog = complex_program("rigid-body", W)
    assert [f[2] for f in prog.factors] == [0.5 + 0.5j, 0.5 + 0.5j, 1 + 0j, 0.5 - 0.5j, 0.5 - 0.5j]
    I1, I2, I3 = model("rigid-body").parameters          # the hoisted factors (I_k - I_j)/(I_j I_k), exact
    values = {I1: 1, I2: 2, I3: 3}
    assert {e.xreplace(values) for _, e in prog.constants} == {sympy.Rational(1, 6), sympy.Rational(-2, 3),
                                                                 sympy.Rational(1, 2)}


def test_generated_step_of_a_user_system_with_constants(tmp_path, monkeypatch):
    """A user's H = p^2/2 + sqrt(k) q^2/2 + pi q: the hoisted factors -sqrt(k) and -pi evaluate in the generated module,
    whose loop, run on the interpreter here (plain Python on cmath), follows the reference to rounding."""
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path / "cache"))
    S = nb.System("q p", ["p**2/2 + sqrt(k)*q**2/2 + pi*q"], name="spring", parameters="k")
    word = "1:1/2+I/2,2:1,1:1/2-I/2"
    kern = complex_kernel(S, word)
    T, K = kern.constants(0.1, {"k": 2.0})
    assert sorted(K.tolist()) == [-np.pi, -np.sqrt(2.0)]
    out = np.empty((21, 2), dtype=np.complex128)
    out[0] = x = np.array([1.0, 0.0], dtype=np.complex128)
    assert kern.module.run(x, T, K, 20, 1, out, False) == 20
    ref = iterate_complex(S, word, 0.1, 20, [1.0, 0.0], {"k": 2.0}, backend="numpy")
    assert np.abs(out - ref).max() <= 1e-14 * np.abs(ref).max() and np.abs(ref[-1].imag).max() > 1e-4


def test_complex_kernel_source_is_verified_in_the_cache(tmp_path, monkeypatch):
    """The complex module goes through the kernels' verified cache: read back when intact, regenerated when modified."""
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path / "cache"))
    system = model("ho3")
    comp = composition_for(W, system.splitting)
    first = ComplexKernel(system, comp)
    assert not first.from_cache and first.path.is_file()
    again = ComplexKernel(system, comp)
    assert again.from_cache and again.source == first.source
    first.path.write_text(first.source.replace("return n", "return 0"))
    third = ComplexKernel(system, comp)
    assert not third.from_cache and third.source == first.source
    T, K = third.constants(0.1)
    assert T.dtype == np.complex128 and T[0] == (0.5 + 0.5j) * 0.1 and K.dtype == np.float64
    with pytest.raises(InvalidRunError, match="has real coefficients"):
        complex_kernel(system, "12321")
