"""Tests of the numeric backend: generated kernels, backends, sampling, Kahan, mpmath, cache, progress.

Numerical tests carry explicit tolerances; the numba and numpy paths are compared bit for bit on
polynomial flows (the generated code performs the same IEEE operations in the same order).
References: Horikoshi, Sect. 5.5, Eqs. (hX1e)-(hX3e), (12321).
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
import pytest

from nambu_bch import model
from nambu_bch.errors import (
    InvalidCompositionError,
    InvalidRunError,
    InvalidSystemError,
    NambuBCHError,
    NumericalRangeError,
)
from nambu_bch.integrators import step_function
from nambu_bch.numeric import iterate, kernel, n_samples, sample_steps, sample_times, step_program
from nambu_bch.numeric.codegen import c_source, python_source
from nambu_bch.numeric.kernels import numba_available, resolve_backend
from nambu_bch.progress import Progress

numba_only = pytest.mark.skipif(not numba_available(), reason="numba not installed or disabled")

POLY_CASES = [("ho", "TVT"), ("ho3", "32123"), ("ho3", "12321"), ("rigid-body", "forest-ruth"), ("ho3-composite", "121")]
X0 = {"ho": [1.0, 0.5], "ho3": [1.0, 1.0, 1.0], "rigid-body": [0.3, 0.8, -0.5], "ho3-composite": [1.0, 1.0, 1.0],
      "lotka-volterra": [0.9, 1.1, 1.0]}


# -- shapes and sampling ----------------------------------------------------------------------------------


def test_sampling_grid_includes_start_and_end():
    assert sample_steps(10, 5).tolist() == [0, 5, 10]
    assert sample_steps(10, 3).tolist() == [0, 3, 6, 9, 10]
    assert n_samples(0, 7) == 1 and sample_steps(0, 7).tolist() == [0]
    assert np.allclose(sample_times(0.1, 4, 2), [0.0, 0.2, 0.4])


def test_shapes_single_and_batch():
    x = iterate("ho3", "32123", 0.1, 10, [1.0, 1.0, 1.0], every=3)
    assert x.shape == (5, 3) and x.dtype == np.float64
    assert x[0].tolist() == [1.0, 1.0, 1.0]
    X0 = np.array([[1.0, 1.0, 1.0], [0.2, -0.4, 0.5], [2.0, 0.0, 3.0]]).T      # (N, batch) = (3, 3)
    xb = iterate("ho3", "32123", 0.1, 10, X0, every=3)
    assert xb.shape == (5, 3, 3)
    assert np.array_equal(xb[:, :, 0], x)                                       # batch member 0 == single run
    assert np.array_equal(xb[0], X0)
    assert iterate("ho3", "32123", 0.1, 0, [1.0, 2.0, 3.0]).tolist() == [[1.0, 2.0, 3.0]]


def test_every_subsamples_the_same_trajectory():
    full = iterate("ho3", "32123", 0.1, 100, [1.0, 1.0, 1.0])
    sparse = iterate("ho3", "32123", 0.1, 100, [1.0, 1.0, 1.0], every=7)
    assert np.array_equal(sparse, full[sample_steps(100, 7)])


@pytest.mark.parametrize("name,word", POLY_CASES + [("lotka-volterra", "12321")])
def test_matches_the_lambdified_step(name, word):
    """The generated kernel iterates the same map as nambu_bch.integrators.step_function."""
    system = model(name)
    step = step_function(system.splitting, word)
    x = np.array(X0[name])
    for _ in range(50):
        x = step(x, 0.05)
    ours = iterate(system, word, 0.05, 50, X0[name], every=50)[-1]
    assert np.allclose(ours, x, rtol=1e-13, atol=1e-13)


def test_pi_and_e_in_a_users_flow_run_on_every_generated_loop():
    """H = p^2/2 + pi q + E q^2/2: the hoisted constants hold pi and E, which the generated module defines (float64)
    and the mpmath namespace gives at the working precision (the kernel used to raise NameError: 'pi')."""
    import mpmath

    from nambu_bch import System

    system = System("q p", ["p**2/2 + pi*q + E*q**2/2"], name="constants")
    step = step_function(system.splitting, "121")
    x = np.array([0.3, -0.2])
    for _ in range(20):
        x = step(x, 0.1)
    assert np.allclose(iterate(system, "121", 0.1, 20, [0.3, -0.2], every=20, backend="numpy")[-1], x,
                       rtol=1e-13, atol=1e-13)
    fine = iterate(system, "121", "0.1", 20, ["0.3", "-0.2"], every=20, dps=40)[-1]
    assert max(abs(mpmath.mpf(a) - b) for a, b in zip(fine, x)) < 1e-13
    # at 40 digits the constants are mpmath's, not float64's: from q = p = 0 a step of position Verlet (121) kicks p
    # by -h (pi + E q) with q = 0, i.e. to -pi/10 at 40 digits (float64's pi is off by 1.2e-17)
    p1 = iterate(system, "121", "0.1", 1, ["0", "0"], every=1, dps=40)[-1][1]
    with mpmath.workdps(40):
        assert abs(mpmath.mpf(p1) + mpmath.pi / 10) < mpmath.mpf(10) ** -35


def test_operator_order_on_a_non_palindromic_word():
    """Word "123": piece 1 acts first, then 2, then 3 (left to right, Eqs. hX1e-hX3e)."""
    h = 0.3
    x1, x2, x3 = 1.0, 2.0, 0.5
    x1 = x1 + h * x2                    # piece 1: x1 += h x2 / m
    x2 = x2 - h * x1                    # piece 2: x2 -= h m omega^2 x1 (new x1)
    x3 = x3 + 2 * h * x1 * x2           # piece 3: x3 += 2 h x1 x2 / m (new x1, x2)
    got = iterate("ho3", "123", h, 1, [1.0, 2.0, 0.5])[-1]
    assert np.allclose(got, [x1, x2, x3], rtol=1e-15, atol=1e-15)
    other = iterate("ho3", "321", h, 1, [1.0, 2.0, 0.5])[-1]
    assert not np.allclose(other, got)


def test_parameters_enter_through_the_constants():
    a = iterate("ho3", "32123", 0.1, 200, [1.0, 1.0, 1.0], params={"m": 2.0, "omega": 0.5})
    step = step_function(model("ho3").splitting, "32123", {"m": 2.0, "omega": 0.5})
    x = np.array([1.0, 1.0, 1.0])
    for _ in range(200):
        x = step(x, 0.1)
    assert np.allclose(a[-1], x, rtol=1e-12)


# -- generated code -----------------------------------------------------------------------------------------


def test_step_program_hoists_constants():
    prog = step_program(model("ho3"), "12321")
    assert [u.piece for u in prog.updates] == [1, 2, 3, 2, 1]
    assert str(prog.updates[2].increments[0][1]) == "k2*s0*s1"      # Eq. (hX3e): x3 += (2h/m) x1 x2
    src = python_source(prog)
    assert "sympy" not in src and "def run(" in src and "def run_batch(" in src and "def run_numpy(" in src
    assert "s2 += d0" in src
    csrc = c_source(prog)
    assert "long run(" in csrc and "void run_batch(" in csrc


def test_exponential_flows_use_expm1():
    prog = step_program(model("lotka-volterra"), "12321")
    assert all("expm1" in str(d) for u in prog.updates for _, d in u.expanded())
    # one expm1 per sub-flow: each Lotka-Volterra piece scales one coordinate by e^u, another by e^-u
    assert all(len(u.pairs) == 1 and len(u.increments) == 2 for u in prog.updates)
    # one library call, only above the series range, in the one generated pair function: run, run_fma, run_kahan
    # and the batch loops' redo call it once per sub-flow (compiled, LLVM inlines it), the batch loops' branch-free
    # pass calls the select function once per sub-flow
    from nambu_bch.numeric.codegen import PAIR_FUNCTION, SELECT_FUNCTION

    src = python_source(prog)
    assert src.count("    e0 = _expm1(_au0)") == 1 and src.count("= _expm1(") == 1
    assert src.count(f"def {PAIR_FUNCTION}(") == 1 and src.count(f" = {PAIR_FUNCTION}(") == 5 * len(prog.updates)
    assert src.count(f"def {SELECT_FUNCTION}(") == 1 and src.count(f" = {SELECT_FUNCTION}(") == 2 * len(prog.updates)
    compiled = [f for f in src.split("\ndef ")[1:] if not f.startswith("run_numpy")]  # numpy twins stay inline
    assert sum("_zu0 = " in f for f in compiled) == 2 and not any("_zu1" in f for f in compiled)
    assert src.count("_np_expm1(") == 2 * len(prog.updates)        # run_numpy and its Kahan form


@numba_only
def test_exponential_helpers_are_compiled_with_each_loops_flags():
    """A loop compiled with contraction calls helpers compiled with contraction (its inline statements were
    contracted: the same bits), the others and the interpreter the plain ones; the batch redo always the plain pair.
    Only dispatchers are made here, nothing is compiled."""
    from nambu_bch.numeric.codegen import PAIR_FUNCTION, SELECT_FUNCTION

    k = kernel(model("lotka-volterra"), "12321")
    flags = lambda f: set(f.targetoptions.get("fastmath") or ())  # noqa: E731
    for name in ("run", "run_kahan", "run_batch", "run_batch_kahan"):
        for fma in (False, True):
            scope = k.function(name + ("+contract" if fma else "")).py_func.__globals__
            helper = scope[SELECT_FUNCTION if name.startswith("run_batch") else PAIR_FUNCTION]
            assert flags(helper) == ({"contract"} if fma else set()), (name, fma)
            assert flags(scope[PAIR_FUNCTION]) == ({"contract"} if fma and "batch" not in name else set())
    assert flags(k.module.__dict__[SELECT_FUNCTION]) == flags(k.module.__dict__[PAIR_FUNCTION]) == set()


@pytest.mark.parametrize("name,word", [("ho3", "32123"), ("lotka-volterra", "12321")])
def test_numba_loops_copy_rows_element_by_element(name, word):
    """The compiled loops move states between arrays only by element loops, never by a slice assignment
    (``S0[:nb] = X[0, b0:b0 + nb]``): numba compiles a slice assignment's broadcasting error path, which
    doubled the batch kernels' compile time (docs/suite_time.md).  The numpy fallback keeps its
    whole-array statements.  Checked on the parsed source: no subscript-with-slice target outside run_numpy*."""
    import ast

    import nambu_bch.numeric.scan as scan_module  # the batch scan, compiled once for every kernel (not generated)

    tree = ast.parse(python_source(step_program(model(name), word)))
    compiled = [f for f in tree.body if isinstance(f, ast.FunctionDef) and not f.name.startswith(("run_numpy", "constants"))]
    # the shared-exponential functions and the row copy of the batch loops with shared exponentials (compiled too)
    pairs = {"_expm1_pair", "_expm1_select", "_copy"} if name == "lotka-volterra" else set()
    assert {f.name for f in compiled} == {"run", "run_fma", "run_kahan", "run_batch", "run_batch_kahan"} | pairs
    compiled += [f for f in ast.parse(Path(scan_module.__file__).read_text()).body if isinstance(f, ast.FunctionDef)]
    assert [f.name for f in compiled][-1:] == ["scan"]
    sliced = [ast.unparse(t) for f in compiled for node in ast.walk(f) if isinstance(node, (ast.Assign, ast.AugAssign))
              for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
              if isinstance(t, ast.Subscript) and any(isinstance(s, ast.Slice) for s in ast.walk(t.slice))]
    assert sliced == []
    # the copies are there: each state row is gathered from X into the chunk and scattered back (per row)
    batch = ast.unparse(next(f for f in compiled if f.name == "run_batch"))
    N = model(name).N
    if pairs:  # one call of the compiled element loop per row (what numba compiles once, LLVM inlines)
        copy = ast.unparse(next(f for f in compiled if f.name == "_copy"))
        assert "_dst[b] = _src[b]" in copy and "for b in range(nb)" in copy
        assert all(f"_copy(S{i}, X[{i}, b0:b0 + nb], nb)" in batch and f"_copy(X[{i}, b0:b0 + nb], S{i}, nb)" in batch
                   for i in range(N))
        return
    assert all(f"row = X[{i}, b0:b0 + nb]" in batch and f"S{i}[b] = row[b]" in batch and f"row[b] = S{i}[b]" in batch
               for i in range(N))


def test_shared_exponential_is_accurate_for_both_signs():
    """e = expm1(|u|), f = -e/(1+e) reproduces expm1(u), expm1(-u) to a few ulps for |u| from 1e-300 to 700
    (against mpmath at 50 digits), so sharing the exponential loses nothing."""
    import math

    import mpmath

    worst = 0.0
    for u in [1e-300, 1e-17, 1e-9, 1e-3, 0.3, 1.0, 5.0, 40.0, 700.0]:
        for sign in (1, -1):
            x = sign * u
            e = math.expm1(abs(x))
            f = -e / (1.0 + e)
            a, b = (e, f) if x >= 0 else (f, e)
            with mpmath.workdps(50):
                for got, want in ((a, mpmath.expm1(x)), (b, mpmath.expm1(-x))):
                    worst = max(worst, float(abs((mpmath.mpf(got) - want) / want)))
    assert worst < 4 * 2.0**-52, worst


def test_series_pair_is_accurate():
    """The shared pair of the generated kernels (codegen.pair_lines, evaluated by expm1_pair): for
    |u| <= SERIES_LIMIT the series of cosh - 1 and sinh give expm1(|u|) within 1.5 ulp of mpmath at
    40 digits (measured 1.11), and the Newton-corrected f = -e/(1+e) gives expm1(-|u|) within 2 ulp
    (measured 1.35; libm's expm1 with -e/fl(1+e): 0.82 and 2.25); beyond it libm's expm1 and
    -e/(1+e) stay within 4 * 2^-52 relative, up to |u| = 700."""
    import math

    import mpmath

    from nambu_bch.numeric.codegen import SERIES_LIMIT, expm1_pair

    rng = np.random.default_rng(7)
    small = np.concatenate([rng.uniform(0, SERIES_LIMIT, 3000), 10.0 ** rng.uniform(-300, np.log10(SERIES_LIMIT), 1000),
                            [SERIES_LIMIT, np.nextafter(SERIES_LIMIT, 0), 5e-324, 2.0**-26, 2.0**-27]])
    large = np.concatenate([rng.uniform(SERIES_LIMIT, 5, 300), [np.nextafter(SERIES_LIMIT, 1), 40.0, 700.0]])
    worst_ulp, worst_rel = [0.0, 0.0], 0.0
    with mpmath.workdps(40):
        for values, series in ((small, True), (large, False)):
            for u in values:
                for x in (float(u), -float(u)):
                    got = expm1_pair(x)
                    for g, want in zip(got, (mpmath.expm1(x), mpmath.expm1(-x))):
                        if want == 0:
                            assert g == 0
                            continue
                        err = abs(mpmath.mpf(g) - want)
                        if series:
                            which = 0 if want > 0 else 1
                            worst_ulp[which] = max(worst_ulp[which], float(err / math.ulp(float(want))))
                        else:
                            worst_rel = max(worst_rel, float(err / abs(want)))
    assert worst_ulp[0] <= 1.5 and worst_ulp[1] <= 2.0 and worst_rel < 4 * 2.0**-52, (worst_ulp, worst_rel)


def _c_library(tmp_path, program):
    """The benchmark's C reference of ``program`` (``bench_iterate_c``'s source), built with -O2 and loaded; skips
    the test when there is no C compiler."""
    import ctypes
    import shutil
    import subprocess

    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    (tmp_path / "step.c").write_text(c_source(program))
    subprocess.run([cc, "-O2", "-std=c99", "-shared", "-fPIC", "-o", str(tmp_path / "step.so"), str(tmp_path / "step.c"),
                    "-lm"], check=True, capture_output=True)
    return ctypes.CDLL(str(tmp_path / "step.so"))


@numba_only
def test_exponential_flows_agree_bitwise_in_the_series_range(tmp_path):
    """Lotka-Volterra with |u| <= SERIES_LIMIT: numba, the numpy batch, the scalar Python loop and
    the generated C give the same bits (the shared pair is plain arithmetic, no library call); the
    numba and C batch loops agree bit for bit also when some |u| leaves the series range."""
    import ctypes

    X = np.array([[0.9, 1.1, 1.0], [1.2, 0.7, 1.3], [0.5, 2.0, 1.5]]).T
    a = iterate("lotka-volterra", "12321", 0.05, 3000, X, every=1000, backend="numba")
    b = iterate("lotka-volterra", "12321", 0.05, 3000, X, every=1000, backend="numpy")
    c = iterate("lotka-volterra", "12321", 0.05, 3000, X[:, 1], every=1000, backend="numpy")
    assert np.array_equal(a, b) and np.array_equal(a[:, :, 1], c)
    assert np.abs(a).max() < 0.5 / 0.05                      # every |u| = c h x stayed in the series range
    k = kernel(model("lotka-volterra"), "12321")
    lib = _c_library(tmp_path, k.program)
    dp = ctypes.POINTER(ctypes.c_double)
    lib.run.argtypes = [dp, dp, ctypes.c_long]
    x = X[:, 1].copy()
    lib.run(x.ctypes.data_as(dp), k.constants(0.05).ctypes.data_as(dp), 3000)
    assert np.array_equal(x, a[-1, :, 1])
    # the batch loops (branch-free pass, redo of a chunk whose |u| left the series range) at h = 0.4
    lib.run_batch.argtypes = [dp, dp, ctypes.c_long, ctypes.c_long, ctypes.c_long]
    Y = np.random.default_rng(4).uniform(0.2, 2.0, size=(3, 700))
    Z = Y.copy()
    lib.run_batch(Z.ctypes.data_as(dp), k.constants(0.4).ctypes.data_as(dp), 30, Z.shape[1], 256)
    b = iterate("lotka-volterra", "12321", 0.4, 30, Y, every=30, backend="numba")
    assert np.array_equal(Z, b[-1]) and 0.4 * np.abs(b).max() > 0.5


@numba_only
def test_lotka_volterra_pieces_keep_G_like_the_library_pair():
    """Each piece X_{x_i, G} of the cyclic Lotka-Volterra splitting keeps G = x1 x2 x3 exactly (it scales
    x_{i+1} by e^-u and x_{i+2} by e^u); in float64 G drifts by round-off only.  The shared pair's f is
    -e/(1+e) rounded once (the Newton step of codegen.pair_lines), so (1+e)(1+f) = 1 to half an ulp of
    f and after 2e6 steps (h = 0.1) G has drifted 9.9e-14.  Measured with C loops against long double
    on the same orbit: libm's expm1 with -e/fl(1+e) 1.5e-13, the series e with -e/fl(1+e) 3.1e-13,
    an f from its own series 1.3e-12; the bound separates the last two from the first."""
    x = iterate("lotka-volterra", "12321", 0.1, 2_000_000, [0.7, 0.7, 0.7], every=2_000_000)
    G = x.prod(axis=1)
    assert abs(G[-1] / G[0] - 1) < 2e-13


def test_exponential_flows_mix_series_and_library_ranges():
    """h = 0.4 on Lotka-Volterra: |u| = c h x falls on both sides of SERIES_LIMIT within one run, so the
    numpy batch takes its masked library branch.  numba and the scalar Python loop (both libm's expm1)
    agree bit for bit; the numpy batch uses numpy's expm1, which differs from libm's in the last bit
    for ~10% of arguments: equal after one step, within 1e-12 after 50 (measured 2e-14).  Every piece
    X_{x_i, G} keeps G = x1 x2 x3 (it scales x_{i+1} by e^-u and x_{i+2} by e^u): conserved to round-off."""
    from nambu_bch.numeric.codegen import SERIES_LIMIT

    X = np.array([[0.9, 1.1, 1.0], [2.5, 0.4, 3.0], [0.2, 4.0, 0.6]]).T
    for steps in (1, 50):
        b = iterate("lotka-volterra", "12321", 0.4, steps, X, every=10, backend="numpy")
        c = np.stack([iterate("lotka-volterra", "12321", 0.4, steps, X[:, i], every=10, backend="numpy")
                      for i in range(3)], axis=-1)
        assert np.allclose(b, c, rtol=1e-12 if steps > 1 else 0, atol=0)
        if numba_available():
            assert np.array_equal(iterate("lotka-volterra", "12321", 0.4, steps, X, every=10, backend="numba"), c)
    u = 0.4 * np.abs(c)                                      # |u| of the full-step piece (coefficient 1)
    assert u.max() > SERIES_LIMIT and u.min() < SERIES_LIMIT
    if numba_available():  # the vectorised batch step redoes a chunk whose |u| left the series range: same bits
        kb = iterate("lotka-volterra", "12321", 0.4, 50, X, every=10, kahan=True, backend="numba")
        ks = np.stack([iterate("lotka-volterra", "12321", 0.4, 50, X[:, i], every=10, kahan=True, backend="numpy")
                       for i in range(3)], axis=-1)
        assert np.array_equal(kb, ks)
    assert np.abs(c.prod(axis=1) / X.prod(axis=0) - 1).max() < 1e-13


def test_generated_c_loop_gives_the_same_bits(tmp_path):
    """The C reference of the benchmark performs the same operations: bit-identical to the kernels."""
    import ctypes

    k = kernel(model("ho3"), "32123")
    lib = _c_library(tmp_path, k.program)
    dp = ctypes.POINTER(ctypes.c_double)
    lib.run.argtypes = [dp, dp, ctypes.c_long]
    K = k.constants(0.1)
    x = np.array([1.0, 1.0, 1.0])
    lib.run(x.ctypes.data_as(dp), K.ctypes.data_as(dp), 10_000)
    assert np.array_equal(x, iterate("ho3", "32123", 0.1, 10_000, [1.0, 1.0, 1.0], every=10_000)[-1])


# -- backends -------------------------------------------------------------------------------------------------


@numba_only
@pytest.mark.parametrize("name,word", POLY_CASES)
@pytest.mark.parametrize("kahan", [False, True])
def test_numba_and_numpy_agree_bitwise(name, word, kahan):
    x0 = X0[name]
    a = iterate(name, word, 0.05, 300, x0, every=7, kahan=kahan, backend="numba")
    b = iterate(name, word, 0.05, 300, x0, every=7, kahan=kahan, backend="numpy")
    assert np.array_equal(a, b)


@numba_only
@pytest.mark.parametrize("kahan", [False, True])
def test_batch_numba_numpy_and_single_agree_bitwise(kahan):
    """The compiled batch loop, the numpy one and the single run give the same bits: ho3/32123's plain batch loop, and
    the Kahan batch loop on ho/TVT -- the fast tier's one compile of that kind, ho's the cheaper (3.0 s cold against
    ho3/32123's 4.1 s, tools/compile_cost.py; docs/suite_time.md)."""
    name, word = ("ho", "TVT") if kahan else ("ho3", "32123")
    rng = np.random.default_rng(1)
    X = rng.normal(size=(model(name).N, 301))           # not a multiple of the chunk sizes
    a = iterate(name, word, 0.1, 50, X, every=10, kahan=kahan, backend="numba")
    b = iterate(name, word, 0.1, 50, X, every=10, kahan=kahan, backend="numpy", chunk=64)
    assert np.array_equal(a, b)
    single = iterate(name, word, 0.1, 50, X[:, 123], every=10, kahan=kahan)
    assert np.array_equal(a[:, :, 123], single)


def test_exponential_flows_agree_across_backends():
    X = np.array([[0.9, 1.1, 1.0], [1.2, 0.7, 1.3]]).T
    a = iterate("lotka-volterra", "12321", 0.05, 400, X, every=100)
    b = iterate("lotka-volterra", "12321", 0.05, 400, X, every=100, backend="numpy")
    assert np.allclose(a, b, rtol=1e-13, atol=0)
    c = iterate("lotka-volterra", "12321", 0.05, 400, X[:, 0], every=100, backend="numpy")
    assert np.allclose(a[:, :, 0], c, rtol=1e-13, atol=0)


@numba_only
def test_disable_numba_environment_variable(monkeypatch):
    a = iterate("ho3", "32123", 0.1, 500, [1.0, 1.0, 1.0], every=50)
    monkeypatch.setenv("NAMBU_BCH_DISABLE_NUMBA", "1")
    assert resolve_backend("auto") == "numpy"
    with pytest.raises(InvalidRunError, match="numba"):
        resolve_backend("numba")
    b = iterate("ho3", "32123", 0.1, 500, [1.0, 1.0, 1.0], every=50)
    assert np.array_equal(a, b)


def test_unknown_backend():
    with pytest.raises(InvalidRunError, match="backend 'cuda'"):
        iterate("ho", "TVT", 0.1, 10, [1.0, 0.0], backend="cuda")


@numba_only
def test_kernels_are_cached_on_disk(tmp_path, monkeypatch):
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path))
    k = kernel(model("ho"), "VTV")
    assert k.path.parent == tmp_path / "kernels" and k.path.read_text() == k.source
    k.compile()
    cached = list((tmp_path / "kernels").rglob("*.nbi"))
    assert cached, "numba wrote no cache index next to the generated module"
    again = kernel(model("ho"), "VTV")
    assert again is k


@numba_only
def test_auto_interprets_small_runs_until_compiling_pays(tmp_path, monkeypatch):
    """backend="auto": while a loop is neither compiled in the process nor in numba's disk
    cache, runs of INTERPRET_STEPS trajectory-steps in total take the interpreter -- the same statements
    on Python floats and the C library's functions, so the same bits as the compiled loop (checked here
    against backend="numba", and for the library functions of every kind of flow in
    test_numba_and_numpy_agree_bitwise / test_exponential_flows_mix_series_and_library_ranges);
    the next run beyond the budget compiles."""
    from nambu_bch.numeric.iterate import INTERPRET_STEPS as budget

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path))
    k = kernel(model("ho3"), "32123")
    a = iterate("ho3", "32123", 0.1, budget - 10, X0["ho3"], every=1000)
    assert k.compile_seconds == {} and k.interpreted == {"run": budget - 10}
    b = iterate("ho3", "32123", 0.1, 20, X0["ho3"])              # beyond the budget: compiled now
    assert "run" in k.compile_seconds and k.interpreted == {"run": budget - 10}
    assert np.array_equal(a, iterate("ho3", "32123", 0.1, budget - 10, X0["ho3"], every=1000, backend="numba"))
    assert np.array_equal(b, iterate("ho3", "32123", 0.1, 20, X0["ho3"], backend="numpy"))
    # Kahan is another loop with its own budget (its bits: test_numba_and_numpy_agree_bitwise[True-ho3-32123])
    c = iterate("ho3", "32123", 0.1, 300, X0["ho3"], kahan=True)
    assert "run_kahan" not in k.compile_seconds and k.interpreted["run_kahan"] == 300
    assert np.array_equal(c, iterate("ho3", "32123", 0.1, 300, X0["ho3"], kahan=True, backend="numpy"))


@numba_only
def test_auto_loads_a_loop_from_numbas_disk_cache(tmp_path, monkeypatch):
    """A loop in numba's cache on disk is ready (loading it takes milliseconds): "auto" runs it compiled,
    also in a new Kernel of the same source (a fresh process sees the same files)."""
    from nambu_bch.numeric import kernels as K

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path))
    monkeypatch.setenv("NAMBU_BCH_DISABLE_CLIB", "1")  # numba's cache is the subject, not the kernel's C library
    k = kernel(model("ho"), "TVT")
    assert not k.ready("run")
    k.compile()
    assert k.ready("run") and not k.ready("run_kahan")
    K._kernel.cache_clear()
    K._kernel_for_word.cache_clear()
    fresh = kernel(model("ho"), "TVT")
    assert fresh is not k and fresh.compile_seconds == {} and fresh.ready("run")
    x = iterate("ho", "TVT", 0.1, 100, X0["ho"])
    assert "run" in fresh.compile_seconds and fresh.interpreted == {}
    assert np.array_equal(x, iterate("ho", "TVT", 0.1, 100, X0["ho"], backend="numpy"))


def _host_fuses():
    """Whether the machine numba compiles for has fused multiply-add instructions."""
    from llvmlite import binding

    return bool(binding.get_host_cpu_features().get("fma", False))


@numba_only
def test_fma_contracts_only_when_asked_and_is_cached_apart(tmp_path, monkeypatch):
    """fma=True runs a second compiled loop that may fuse a*b + c: close to the default run, which keeps the
    interpreter's bits (and so does fma=True on the interpreter).  Each loop's machine code is cached
    under its own name, so a fresh Kernel loads both from disk without mixing them up: numba's cache
    key covers the bytecode and the signature, not the compile flags."""
    from nambu_bch.numeric import kernels as K

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path))
    run = lambda x0, **kw: iterate("ho", "TVT", 0.1, 3000, x0, every=1000, **kw)  # noqa: E731
    X = np.array([X0["ho"], [0.3, -0.2], [1e-3, 2.0]]).T
    plain, fused = run(X0["ho"], backend="numba"), run(X0["ho"], backend="numba", fma=True)
    plain_b, fused_b = run(X, backend="numpy", fma=True), run(X, backend="numba", fma=True)  # numpy: the compiled bits
    assert np.array_equal(plain, run(X0["ho"], backend="numpy", fma=True))
    assert np.allclose(fused, plain, rtol=1e-12, atol=1e-14) and np.allclose(fused_b, plain_b, rtol=1e-12, atol=1e-14)
    if _host_fuses():
        assert not np.array_equal(fused, plain) and not np.array_equal(fused_b, plain_b)
    k = kernel(model("ho"), "TVT")
    cached = {p.name.split("-")[0] for p in (tmp_path / "kernels" / "__pycache__").glob("*.nbi")}
    assert cached == {f"{k.path.stem}.{name}" for name in ("run", "run+contract", "run_batch+contract")}
    K._kernel.cache_clear()
    K._kernel_for_word.cache_clear()
    fresh = kernel(model("ho"), "TVT")
    assert fresh is not k and fresh.ready("run") and fresh.ready("run+contract") and not fresh.ready("run_kahan+contract")
    assert np.array_equal(run(X0["ho"], fma=True), fused) and np.array_equal(run(X0["ho"]), plain)
    assert np.array_equal(run(X, fma=True), fused_b)
    assert fresh.interpreted == {}


@numba_only
def test_auto_small_batches_take_numpy_only_where_it_gives_the_compiled_bits(tmp_path, monkeypatch):
    """numpy's expm1 differs from the C library's in the last bit for some arguments (see
    test_exponential_flows_mix_series_and_library_ranges): a small Lotka-Volterra batch is compiled,
    a small polynomial (ho3) batch runs on numpy arrays -- with the compiled loop's bits."""
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path))
    lv, ho3 = kernel(model("lotka-volterra"), "12321"), kernel(model("ho3"), "32123")
    assert not lv.numpy_matches_compiled and ho3.numpy_matches_compiled
    X = np.array([[1.0, 1.0, 1.0], [0.2, -0.4, 0.5], [2.0, 0.0, 3.0]]).T
    a = iterate("ho3", "32123", 0.1, 50, X, every=10)
    assert ho3.compile_seconds == {} and ho3.interpreted == {"run_batch": 50}
    # each column is the single run (interpreted too), whose bits are the compiled loop's
    # (test_batch_numba_numpy_and_single_agree_bitwise compares the compiled batch loop itself)
    assert all(np.array_equal(a[:, :, i], iterate("ho3", "32123", 0.1, 50, X[:, i], every=10)) for i in range(3))
    assert ho3.compile_seconds == {} and ho3.interpreted == {"run_batch": 50, "run": 150}
    from nambu_bch.numeric.iterate import _interpret_small

    assert _interpret_small(lv, 50, (3, 3), False) == ("numba", False)


def test_interpreter_arithmetic_errors_are_refused_or_compiled():
    """Lotka-Volterra at h = 0.5 from (1, 2, 3): math.expm1 overflows on the interpreter mid-run, where the
    compiled loop gives inf.  backend="numpy" refuses the run in one line (NumericalRangeError, not
    OverflowError); "auto" hands the segment to the compiled loop, so it reports what "numba" reports."""
    args = ("lotka-volterra", "12321", 0.5, 200, [1.0, 2.0, 3.0])
    with pytest.raises(NumericalRangeError, match="interpreter"):
        iterate(*args, check_stable=False, backend="numpy")
    if numba_available():
        with pytest.raises(NumericalRangeError) as compiled:
            iterate(*args, check_stable=False, backend="numba")
        with pytest.raises(NumericalRangeError) as auto:
            iterate(*args, check_stable=False)
        assert str(auto.value) == str(compiled.value) and "interpreter" not in str(auto.value)


# -- precision ---------------------------------------------------------------------------------------------------


def test_kahan_removes_accumulated_round_off_at_tiny_steps():
    """h = 1e-8: 10^4 increments of ~1e-8 lose ~1e-13 in plain float64; compensated sums stay at ~1e-16."""
    n, h = 10_000, 1e-8
    ref = iterate("ho3", "32123", h, n, [1.0, 1.0, 1.0], every=n, dps=40)[-1]
    ref = np.array([float(v) for v in ref])
    plain = iterate("ho3", "32123", h, n, [1.0, 1.0, 1.0], every=n)[-1]
    kahan = iterate("ho3", "32123", h, n, [1.0, 1.0, 1.0], every=n, kahan=True)[-1]
    err_plain, err_kahan = np.abs(plain - ref).max(), np.abs(kahan - ref).max()
    assert err_kahan <= 4.5e-16
    assert err_plain > 1e-14 > err_kahan


def test_mpmath_path():
    import mpmath

    x = iterate("ho3", "32123", 0.1, 300, [1.0, 1.0, 1.0], every=100, dps=40)
    assert x.shape == (4, 3) and x.dtype == object and isinstance(x[-1, 2], mpmath.mpf)
    f = iterate("ho3", "32123", 0.1, 300, [1.0, 1.0, 1.0], every=100)
    assert np.allclose(x.astype(float), f, rtol=0, atol=1e-13)
    # H_c (Table (table), 32123) is conserved to the working precision
    with mpmath.workdps(40):
        h = mpmath.mpf(0.1)
        Hc = [r[1] ** 2 / 2 + r[2] / 2 + h**2 * r[0] ** 2 / 8 for r in x]
        assert max(abs(v - Hc[0]) for v in Hc) < mpmath.mpf(10) ** -36
    # a decimal string step is read at dps digits (a slightly different map from float 0.1)
    y = iterate("ho3", "32123", "0.1", 300, ["1", "1", "1"], every=300, dps=40)
    assert abs(float(y[-1, 0] - x[-1, 0])) < 1e-12
    batch = iterate("ho", "TVT", 0.1, 10, [[1.0, 0.0], [0.0, 1.0]], dps=20)
    assert batch.shape == (11, 2, 2)


def test_precision_argument_errors():
    with pytest.raises(InvalidRunError, match="kahan"):
        iterate("ho", "TVT", 0.1, 10, [1.0, 0.0], kahan=True, dps=30)
    with pytest.raises(InvalidRunError, match="dps"):
        iterate("ho", "TVT", 0.1, 10, [1.0, 0.0], dps=5)


# -- progress -------------------------------------------------------------------------------------------------------


def test_progress_is_off_in_pipes_and_on_when_asked():
    stream = io.StringIO()
    p = Progress(10, "x", stream=stream, delay=0, interval=0)
    p.update(5)
    p.close()
    assert stream.getvalue() == ""                      # StringIO is not a TTY
    p = Progress(10, "x", enabled=True, stream=stream, delay=0, interval=0)
    p.update(5)
    p.close()
    assert "50%" in stream.getvalue() and stream.getvalue().endswith("\n")


def test_segmented_runs_with_progress_give_the_same_samples(monkeypatch, capsys):
    import importlib

    it = importlib.import_module("nambu_bch.numeric.iterate")   # the module, not the re-exported function
    monkeypatch.setattr(it, "_SEGMENT_WORK", 700)
    plain = iterate("ho3", "32123", 0.1, 5000, [1.0, 1.0, 1.0], every=30)
    segmented = iterate("ho3", "32123", 0.1, 5000, [1.0, 1.0, 1.0], every=30, progress=True)
    assert np.array_equal(plain, segmented)
    k1 = iterate("ho3", "32123", 0.1, 5000, [1.0, 1.0, 1.0], every=30, kahan=True)
    k2 = iterate("ho3", "32123", 0.1, 5000, [1.0, 1.0, 1.0], every=30, kahan=True, progress=True)
    assert np.array_equal(k1, k2)
    X = np.ones((3, 4))
    assert np.array_equal(iterate("ho3", "32123", 0.1, 999, X, every=10, progress=True),
                          iterate("ho3", "32123", 0.1, 999, X, every=10))
    capsys.readouterr()


# -- bad input -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs,error,text", [
    ({"steps": -1}, InvalidRunError, "steps"),
    ({"steps": 2.5}, InvalidRunError, "steps"),
    ({"steps": True}, InvalidRunError, "steps"),
    ({"every": 0}, InvalidRunError, "every"),
    ({"x0": [1.0, 1.0]}, InvalidRunError, "shape"),
    ({"x0": [[1.0], [2.0]]}, InvalidRunError, "shape"),
    ({"x0": "abc"}, InvalidRunError, "x0"),
    ({"h": "fast"}, InvalidRunError, "step h"),
    ({"h": 1j}, InvalidRunError, "step h"),
    ({"params": {"mass": 1.0}}, InvalidSystemError, "mass"),
    ({"params": [1.0]}, InvalidRunError, "params"),
    ({"word": "1x2"}, InvalidCompositionError, "1x2"),
    ({"word": "124"}, InvalidCompositionError, "4"),
    ({"system": "pendulum"}, NambuBCHError, "pendulum"),
    ({"system": 3}, InvalidSystemError, "system"),
])
def test_bad_arguments(kwargs, error, text):
    args = {"system": "ho3", "word": "32123", "h": 0.1, "steps": 10, "x0": [1.0, 1.0, 1.0]}
    args.update(kwargs)
    with pytest.raises(error, match=text):
        iterate(**args)


def test_errors_are_value_errors_for_callers():
    with pytest.raises(ValueError):
        iterate("ho3", "32123", float("nan"), 10, [1.0, 1.0, 1.0])
    with pytest.raises(NumericalRangeError):
        iterate("ho3", "32123", 0.1, 10, [1.0, float("inf"), 1.0])


def test_cache_dir_env(tmp_path, monkeypatch):
    from nambu_bch.numeric.kernels import cache_dir

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path / "c"))
    assert cache_dir() == tmp_path / "c" / "kernels" and os.path.isdir(cache_dir())


# -- properties (hypothesis) -------------------------------------------------------------------------------------------

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

finite = st.floats(min_value=-100.0, max_value=100.0, allow_nan=False, allow_infinity=False, allow_subnormal=False)


@settings(max_examples=25, deadline=None)
@given(x0=st.lists(finite, min_size=3, max_size=3), a=st.integers(0, 60), b=st.integers(0, 60),
       h=st.floats(min_value=-1.5, max_value=1.5, allow_nan=False).filter(lambda v: v == 0 or abs(v) > 1e-3))
def test_runs_compose_bit_for_bit(x0, a, b, h):
    """Phi^(a+b) x0 == Phi^b (Phi^a x0) exactly: the state is the whole memory of the kernel."""
    x0 = [0.0 if abs(v) < 1e-100 else v for v in x0]
    whole = iterate("ho3", "32123", h, a + b, x0, every=max(a + b, 1))[-1]
    first = iterate("ho3", "32123", h, a, x0, every=max(a, 1))[-1]
    assert np.array_equal(iterate("ho3", "32123", h, b, first, every=max(b, 1))[-1], whole)


@settings(max_examples=20, deadline=None)
@given(X=st.lists(st.lists(finite, min_size=5, max_size=5), min_size=3, max_size=3), steps=st.integers(0, 40),
       every=st.integers(1, 15))
def test_backends_agree_on_random_batches(X, steps, every):
    X = np.array(X)
    X[np.abs(X) < 1e-100] = 0.0
    a = iterate("ho3", "32123", 0.1, steps, X, every=every)
    b = iterate("ho3", "32123", 0.1, steps, X, every=every, backend="numpy")
    assert a.shape == (len(sample_steps(steps, every)), 3, 5) and np.array_equal(a, b)


def test_user_symbols_named_like_generated_ones():
    """Coordinates s0, s1 and spring constants k0, k1 do not collide with the kernel's own names."""
    from nambu_bch import System

    S = System("s1 s0", ["s0**2/(2*k1) + k0*s1**2/2"], "k0 k1", name="springs")
    x = iterate(S, "121", 0.1, 400, [1.0, 0.0], params={"k0": 4.0, "k1": 0.5}, every=400)[-1]
    step = step_function(S.splitting, "121", {"k0": 4.0, "k1": 0.5})
    y = np.array([1.0, 0.0])
    for _ in range(400):
        y = step(y, 0.1)
    assert np.allclose(x, y, rtol=1e-12, atol=1e-12)


# -- the batch path reads x0 in place, fuses the sample-0 copy and the result check ------------------


@pytest.mark.parametrize("backend", [pytest.param("numba", marks=numba_only), "numpy"])
def test_batch_reads_x0_in_place_and_leaves_it_unchanged(backend):
    """The batch kernels read the caller's x0 (no copy) and never write it; x0 in any layout, dtype or
    read-only gives the same bits, and every column equals its own single-trajectory run."""
    from nambu_bch.numeric.iterate import SCAN_BATCH

    rng = np.random.default_rng(14)
    X = rng.normal(size=(3, SCAN_BATCH + 77))           # above SCAN_BATCH: the one-pass scan guards it
    keep = X.copy()
    a = iterate("ho3", "32123", 0.1, 40, X, every=7, backend=backend)
    assert np.array_equal(X, keep) and np.array_equal(a[0], X)
    frozen = X.copy()
    frozen.flags.writeable = False
    for variant in (np.asfortranarray(X), frozen, X.tolist()):
        assert np.array_equal(iterate("ho3", "32123", 0.1, 40, variant, every=7, backend=backend), a)
    ints = np.arange(3 * 9).reshape(3, 9) % 4 - 1          # int64: converted, same as its float64 copy
    assert np.array_equal(iterate("ho3", "32123", 0.1, 40, ints, every=7, backend=backend),
                          iterate("ho3", "32123", 0.1, 40, ints.astype(float), every=7, backend=backend))
    for b in (0, 1234, X.shape[1] - 1):
        assert np.array_equal(a[:, :, b], iterate("ho3", "32123", 0.1, 40, X[:, b], every=7, backend=backend))
    assert np.array_equal(iterate("ho3", "32123", 0.1, 0, X, backend=backend), X[None])   # steps = 0: x0 only


@pytest.mark.parametrize("backend", [pytest.param("numba", marks=numba_only), "numpy"])
def test_out_receives_the_samples_in_place(backend):
    """out= is filled in place and returned, every element written (garbage in it does not matter),
    with the bits of a run that allocates its own result: single, batch, Kahan, progress segments.  The Kahan batch
    on ho/TVT, whose Kahan batch loop the fast tier compiles (test_batch_numba_numpy_and_single_agree_bitwise[True])."""
    X = np.random.default_rng(5).normal(size=(3, 50))
    cases = (("ho3", "32123", X, {}), ("ho", "TVT", X[:2], {"kahan": True}), ("ho3", "32123", X[:, 3], {}),
             ("ho3", "32123", X[:, 3], {"kahan": True}))
    for name, word, x0, kw in cases:
        want = iterate(name, word, 0.1, 40, x0, every=7, backend=backend, **kw)
        out = np.full(want.shape, np.nan)
        got = iterate(name, word, 0.1, 40, x0, every=7, backend=backend, out=out, **kw)
        assert got is out and np.array_equal(out, want)
    out = np.full((1, 3, 50), 7.0)
    assert np.array_equal(iterate("ho3", "32123", 0.1, 0, X, out=out, backend=backend), X[None])


def test_out_is_refused_unless_it_can_take_the_samples_in_place():
    """A wrong dtype, shape or layout, a read-only array, an array overlapping x0 or an mpmath run: one
    InvalidRunError line naming out, and the bad array is left as it was."""
    X = np.ones((3, 8))
    good = (2, 3, 8)
    frozen = np.zeros(good)
    frozen.flags.writeable = False
    bad = [np.zeros(good, dtype=np.float32), np.zeros((3, 3, 8)), np.zeros(good, order="F"), frozen,
           np.zeros((2, 3, 16))[:, :, ::2], [[0.0] * 8] * 3, "out"]
    for out in bad:
        with pytest.raises(InvalidRunError, match="^out must be") as info:
            iterate("ho3", "32123", 0.1, 5, X, every=5, out=out)
        assert "\n" not in str(info.value)
        assert out is frozen or not isinstance(out, np.ndarray) or not out.any()
    overlap = np.ones((3, 3, 8))
    with pytest.raises(InvalidRunError, match="shares memory with x0"):
        iterate("ho3", "32123", 0.1, 5, overlap[1], every=5, out=overlap[:2])        # a batch
    with pytest.raises(InvalidRunError, match="shares memory with x0"):
        iterate("ho3", "32123", 0.1, 5, overlap[0, :, 0], every=5, out=overlap.reshape(-1)[:6].reshape(2, 3))
    with pytest.raises(InvalidRunError, match="mpmath"):
        iterate("ho3", "32123", 0.1, 5, [1.0, 1.0, 1.0], every=5, dps=20, out=np.empty((2, 3)))


def test_segmented_kahan_batch_carries_the_compensation(monkeypatch, capsys):
    """A Kahan batch cut into progress segments (each starting from the last sample written, the
    compensation carried in place) gives the bits of the uncut run and of each state's own run.  On ho/TVT: the
    Kahan batch loop the fast tier compiles (test_batch_numba_numpy_and_single_agree_bitwise[True])."""
    import importlib

    X = np.random.default_rng(2).normal(size=(2, 40))
    whole = iterate("ho", "TVT", 0.01, 700, X, every=70, kahan=True)
    monkeypatch.setattr(importlib.import_module("nambu_bch.numeric.iterate"), "_SEGMENT_WORK", 5000)
    cut = iterate("ho", "TVT", 0.01, 700, X, every=70, kahan=True, progress=True)
    assert np.array_equal(whole, cut)
    assert np.array_equal(whole[:, :, 7], iterate("ho", "TVT", 0.01, 700, X[:, 7], every=70, kahan=True))
    capsys.readouterr()


@pytest.mark.parametrize("backend", [pytest.param("numba", marks=numba_only), "numpy"])
def test_batch_kernel_counts_non_finite_samples(backend):
    """Kernel.run_batch returns 0 for a finite run and a positive count when a sample overflows; with
    back=False the start states are only read, with start=True they are copied to out[0].

    ho3/32123's batch loop: the one the fast tier compiles anyway (test_compiled_scan_agrees_with_numpy_guards,
    test_batch_numba_numpy_and_single_agree_bitwise; tests/conftest.py LONG runs them in one worker); the count
    is the same statement in every kernel's batch loop."""
    k = kernel(model("ho3"), "32123")
    K = k.constants(2.5)                # omega h = 2.5: (x1, x2) grows like 4^n, x3 += h x1 x2 / m like 16^n
    X = np.array([[1.0, 1e100, 0.5], [0.0, 0.0, 0.25], [0.0, 0.0, 0.0]])
    keep = X.copy()
    out = np.full((3, 3, 3), -7.0)
    assert k.run_batch(X, K, 2, 1, out, backend=backend, start=True, back=False) == 0
    assert np.array_equal(X, keep) and np.array_equal(out[0], X) and np.all(np.isfinite(out))
    out = np.empty((3, 3, 3))
    with np.errstate(all="ignore"):
        assert k.run_batch(X, K, 300, 150, out, backend=backend, start=True, back=False) > 0
    assert np.array_equal(X, keep)
    Y = X[:, [0, 2]].copy()
    assert k.run_batch(Y, K, 2, 2, np.empty((2, 3, 2)), backend=backend) == 0 and not np.array_equal(Y, keep[:, [0, 2]])


@pytest.mark.parametrize("segment_work", [None, 3000])
def test_batch_overflow_names_the_same_steps_as_the_single_run(monkeypatch, segment_work):
    """A batch whose one large state overflows mid-run raises the message of that state's own run (the
    first non-finite sample), also when the run is cut into progress segments.

    At h = 2.5 (x1, x2) grows like 4^n and x3 like 16^n: the large state overflows near step 90, the others near
    step 250.  ho3/32123's batch loop, compiled once for the fast tier's batch tests (tests/conftest.py LONG)."""
    import importlib

    from nambu_bch.numeric.iterate import SCAN_BATCH

    X = np.ones((3, SCAN_BATCH + 10))
    X[:, 3000] = [1e100, 0.0, 0.0]
    with pytest.raises(NumericalRangeError, match="between steps") as single:
        iterate("ho3", "32123", 2.5, 2000, X[:, 3000], every=40, check_stable=False)
    if segment_work:
        monkeypatch.setattr(importlib.import_module("nambu_bch.numeric.iterate"), "_SEGMENT_WORK", segment_work)
    with pytest.raises(NumericalRangeError, match="between steps") as batch:
        iterate("ho3", "32123", 2.5, 2000, X, every=40, check_stable=False, progress=bool(segment_work))
    assert str(batch.value) == str(single.value)


def test_scan_states_finds_the_extreme_states_across_blocks():
    """guards.scan_states (numpy blocks) and the compiled Kernel.scan against the definition written
    out on whole arrays: first state of largest / smallest max-norm and product, smallest non-zero."""
    from nambu_bch.numeric.guards import scan_states

    rng = np.random.default_rng(5)
    X = rng.uniform(0.5, 1.5, size=(3, 5000)) * 10.0 ** rng.integers(-60, 60, size=(3, 5000))
    X[:, 4000] = X[:, 17]                                   # ties: the first one counts
    X[1, 2500] = 0.0
    X[:, 99] = 0.0
    A = np.abs(X)
    small = np.where(A > 0, A, np.inf).min(axis=0)
    prod = A[0] * A[1] * A[2]
    want = {int(A.max(0).argmax()), int(A.max(0).argmin()), int(prod.argmax()), int(prod.argmin()),
            int(small.argmin()), 0, X.shape[1] - 1}
    for block in (7, 1024, 8192):
        bad, sub, cols = scan_states(X, block)
        assert (bad, sub) == (0, 0) and set(cols.tolist()) == want
    if numba_available():
        bad, sub, cols = kernel(model("ho3"), "32123").scan(X)
        assert (bad, sub) == (0, 0) and set(cols.tolist()) == want
    Y = X.copy()
    Y[0, 10], Y[2, 4999] = np.nan, 1e-310
    assert scan_states(Y, 64)[:2] == (1, 1)
