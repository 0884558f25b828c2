"""The fixed cost of a run: what iterate() does besides stepping, kept out of repeated and first runs.

The stability verdict of a step depends on its constants ``K`` alone
(:func:`nambu_bch.numeric.guards.check_stability`), so a kernel remembers the ``K`` that passed and a
repeated run with the same step and parameters does not form and diagonalise the step's matrix again;
an unstable ``K`` is never remembered (every such run is refused).
"""

import numpy as np
import pytest

import nambu_bch as nb
from nambu_bch.errors import UnstableStepError
from nambu_bch.numeric import guards, kernel


def test_a_stable_step_is_checked_once_per_kernel(monkeypatch):
    kern = kernel("ho", "121")
    K = kern.constants(0.0123, {"omega": 1.5})
    kern.stable_constants.discard(K.tobytes())
    calls = []
    matrix = guards.step_matrix
    monkeypatch.setattr(guards, "step_matrix", lambda *a: calls.append(1) or matrix(*a))
    for _ in range(3):
        nb.iterate("ho", "121", 0.0123, 5, [1.0, 0.0], params={"omega": 1.5}, backend="numpy")
    assert len(calls) == 1 and K.tobytes() in kern.stable_constants


def test_an_unstable_step_is_refused_every_time():
    kern = kernel("ho", "121")
    for _ in range(2):
        with pytest.raises(UnstableStepError, match="stability interval"):
            nb.iterate("ho", "121", 2.5, 5, [1.0, 0.0], backend="numpy")
    assert kern.constants(2.5).tobytes() not in kern.stable_constants


def test_a_coefficient_out_of_range_still_names_the_run():
    with pytest.raises(nb.NambuBCHError, match=r"h = 0\.1 with m = 1, omega = 1e\+200: a coefficient of the step"):
        nb.iterate("ho", "121", 0.1, 5, [1.0, 0.0], params={"omega": 1e200}, backend="numpy")
    assert np.isfinite(kernel("ho", "121").constants(0.1)).all()


# -- a kernel's loop as a C shared library (numeric.clib): numba's bits without importing numba --------------

import re  # noqa: E402

import sympy  # noqa: E402

from nambu_bch.numeric import clib  # noqa: E402
from nambu_bch.numeric.codegen import c_run_source  # noqa: E402

needs_cc = pytest.mark.skipif(clib.compiler() is None, reason="no C compiler on the PATH")
#: one flow of each kind: polynomial (ho3), shared exponentials with their series branch (lotka-volterra),
#: sin (pendulum)
CASES = [("ho3", "32123", 0.1), ("lotka-volterra", "12321", 0.01), ("pendulum", "121", 0.05)]


@pytest.fixture(scope="module")
def libraries(tmp_path_factory):
    """The three kernels of :data:`CASES` generated in a private cache of their own, each with its library."""
    mp = pytest.MonkeyPatch()
    mp.setenv("NAMBU_BCH_CACHE", str(tmp_path_factory.mktemp("clib_cache")))
    try:
        kernels = {}
        for name, word, h in CASES:
            kern = kernel(name, word)
            assert clib.build(kern)
            kernels[name] = (kern, word, h)
        yield kernels
    finally:
        mp.undo()


@needs_cc
@pytest.mark.parametrize("name", [c[0] for c in CASES])
def test_the_c_library_gives_the_compiled_bits(libraries, name):
    """The library's loop against the interpreter's (the compiled loop's bits: docs/numerics.md), sampled,
    from the model's default x0 -- bit for bit."""
    kern, word, h = libraries[name]
    fn = clib.load(kern)
    assert fn is not None
    K = kern.constants(h)
    x0, _ = guards.initial_state(kern.system, None)
    outs = []
    for run in (lambda x, out: clib.run(fn, x, K, 3000, 7, out),
                lambda x, out: kern.run(x, K, 3000, 7, out, backend="numpy")):
        x, out = np.array(x0, dtype=np.float64), np.empty((430, kern.N))
        out[0] = x
        assert run(x, out) == 3000
        outs.append((x, out))
    assert np.array_equal(outs[0][0], outs[1][0]) and np.array_equal(outs[0][1], outs[1][1])


@needs_cc
def test_auto_takes_the_library_for_one_trajectory(libraries, monkeypatch):
    kern, word, h = libraries["ho3"]
    calls = []
    monkeypatch.setattr(clib, "run", lambda *a: calls.append(1) or clib_run(*a))
    got = nb.iterate(kern.system, word, h, 60_000, [0.7, 0.7, 0.7], every=1000)
    assert calls and np.array_equal(got, nb.iterate(kern.system, word, h, 60_000, [0.7, 0.7, 0.7], every=1000,
                                                    backend="numpy"))
    calls.clear()
    nb.iterate(kern.system, word, h, 100, [0.7, 0.7, 0.7], backend="numpy")
    nb.iterate(kern.system, word, h, 100, [0.7, 0.7, 0.7], kahan=True)
    assert not calls  # an explicit backend, or Kahan summation: not the library


clib_run = clib.run


@needs_cc
def test_a_library_that_does_not_verify_is_not_loaded(libraries):
    kern, _, _ = libraries["pendulum"]
    library, record = clib.paths(kern)
    data = library.read_bytes()
    try:
        library.write_bytes(data[:-1] + bytes([data[-1] ^ 1]))  # one bit changed
        assert clib.load(kern) is None
        library.unlink()
        library.symlink_to(record)  # a link in its place
        assert clib.load(kern) is None
        library.unlink()
        assert clib.load(kern) is None  # absent
    finally:
        if library.is_symlink():
            library.unlink()
        library.write_bytes(data)
        library.chmod(0o600)
    assert clib.load(kern) is not None


def test_the_c_source_holds_no_user_text():
    """Names, coordinates and parameters of a user's system never reach the C source: state s_i, constants k_j."""
    qq, pp, kk = sympy.symbols("qq_marker pp_marker kk_marker")
    system = nb.System([qq, pp], [pp**2 / 2 + kk * qq**2 / 2], parameters=[kk], name="zz_marker")
    source = c_run_source(kernel(system, "121").program)
    assert "marker" not in source
    words = set(re.findall(r"[A-Za-z_]\w*", source.split("*/", 1)[1]))
    assert words <= {"include", "math", "h", "long", "run", "double", "restrict", "x", "const", "K", "steps",
                     "every", "out", "n", "j", "m", "r", "while", "for", "if", "break", "return", "isfinite",
                     "k0", "k1", "s0", "s1", "d0"}, words
    with pytest.raises(nb.NambuBCHError):
        kernel('ho3"; system("id', "121")  # an unknown model is refused before any source exists
    for params in ({'omega"); system("id': 1.0}, {"omega": "1); system(2"}):  # hostile names and values
        with pytest.raises(nb.NambuBCHError):
            nb.iterate("ho", "121", 0.1, 10, [1.0, 0.0], params=params)


@needs_cc
def test_the_library_can_be_turned_off(libraries, monkeypatch):
    kern, _, _ = libraries["ho3"]
    monkeypatch.setenv("NAMBU_BCH_DISABLE_CLIB", "1")
    assert clib.load(kern) is None and clib.compiler() is None and not clib.build(kern)
