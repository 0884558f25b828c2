"""The numeric side: degenerate systems, non-finite results, generated source, the kernel cache, streaming.

Each test names the fault class it guards.  Values are checked two ways where a value is
produced (an exact identity, or the streamed result against the one-shot computation).
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import json
import os
import re
import subprocess
import sys
import tempfile
import tracemalloc
import warnings
from fractions import Fraction

import numpy as np
import pytest
import sympy

import nambu_bch
from nambu_bch import model
from nambu_bch.errors import InvalidSystemError, NambuBCHError, NumericalRangeError
from nambu_bch.integrators.composition import composition
from nambu_bch.numeric import kernels as K
from nambu_bch.numeric.codegen import python_source, source_hash, step_program
from nambu_bch.numeric.diagnostics import RunningStats, check, drift_rate, errors_along, quantities
from nambu_bch.numeric.iterate import iterate, iterate_chunks


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty cache root and no in-process memo of kernels or cache directories."""
    root = tmp_path / "cache"
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(root))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    _forget()
    yield root
    _forget()


def _forget():
    K._CACHE_DIRS.clear()
    K.CACHE_NOTES.clear()
    K._kernel.cache_clear()
    K._kernel_for_word.cache_clear()


def _exact_verlet(steps, h, x):
    """Position Verlet 121 on ho (m = omega = 1) in exact rationals: q += h/2 p; p -= h q; q += h/2 p."""
    q, p = Fraction(x[0]), Fraction(x[1])
    h = Fraction(h)
    for _ in range(steps):
        q += h / 2 * p
        p -= h * q
        q += h / 2 * p
    return float(q), float(p)


# -- item 5: no user text in generated source --------------------------------------------------------------

_INTERNAL = re.compile(r"(?:[skpcdytSQRefu]\d+|_[A-Za-z_0-9]*|a|abs|max|big|prod|small|nonfinite|subnormal|res|i|c|x|X|K|P|C|h|n|j|m|b|b0|b1|B|nb|chunk|lo|hi|steps|every|out|"
                       r"math|np|range|min|constants|run\w*|progress|"
                       # the batch loops' flags and the compiled scan's block reductions
                       r"start|back|bad|buf|off|over|scanning|acc|v\d*|N|W|row|g|nf|sb|top|I[bps]|i?[bps]m(?:ax|in)|m\d)")


def _identifiers(source):
    tree = ast.parse(source)
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    names |= {a.arg for n in ast.walk(tree) if isinstance(n, ast.arguments) for a in n.args}
    strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
    return names, strings


def test_generated_source_uses_internal_names_only(fresh_cache):
    """Item 5: a system whose name, coordinates and parameters are distinctive; none reaches the kernel."""
    qq, pp, kk = sympy.symbols("qq_marker pp_marker kk_marker")
    system = nambu_bch.System([qq, pp], [pp**2 / 2 + kk * qq**2 / 2], parameters=[kk], name="zz_marker")
    kern = K.kernel(system, "121")
    names, strings = _identifiers(kern.source)
    assert all(_INTERNAL.fullmatch(n) for n in names), sorted(n for n in names if not _INTERNAL.fullmatch(n))
    assert "marker" not in kern.source and "#" not in kern.source
    assert len(strings) == 1 and "marker" not in strings[0]  # the module docstring only
    # the run is still right: kk = 1 is the harmonic oscillator, position Verlet in exact rationals
    x = iterate(system, "121", 0.125, 40, [1.0, 0.5], params={"kk_marker": 1.0})[-1]
    assert np.allclose(x, _exact_verlet(40, Fraction(1, 8), (1, Fraction(1, 2))), rtol=0, atol=1e-14)
    # an exponential flow too (shared pairs, the vectorised batch step and its redo): internal names only
    a, b, c = sympy.symbols("aa_marker bb_marker cc_marker")
    lv = nambu_bch.System([a, b, c], [a + b + c, a * b * c], name="lv_marker", split="single")
    names, strings = _identifiers(K.kernel(lv, "12321").source)
    assert all(_INTERNAL.fullmatch(n) for n in names), sorted(n for n in names if not _INTERNAL.fullmatch(n))
    assert len(strings) == 1 and "marker" not in strings[0]


def test_hostile_name_and_word_execute_nothing(fresh_cache, tmp_path):
    """Item 5: a name and a coefficient text carrying code are refused or inert; the marker file never appears."""
    marker = tmp_path / "PWNED"
    payload = f'"""\nopen({str(marker)!r}, "w").write("x")\n"""'
    base = model("ho")
    try:
        system = nambu_bch.System(base.coordinates, list(base.hamiltonians), parameters=base.parameters,
                                  name=payload)
    except NambuBCHError:
        system = None
    if system is not None:
        kern = K.kernel(system, "121")
        assert payload not in kern.source and "PWNED" not in kern.source
        iterate(system, "121", 0.1, 10, [1.0, 0.0], backend="numpy")
    word = f"1:1/2,2:1,1:1/2 # __import__('os').system('touch {marker}')"  # the comment survived the parser
    try:
        kern = K.kernel(base, word)
    except NambuBCHError:
        kern = None
    if kern is not None:
        assert "PWNED" not in kern.source and "#" not in kern.source
        iterate(base, word, 0.1, 10, [1.0, 0.0], backend="numpy")
    assert not marker.exists()


def test_unsupported_function_is_refused_not_printed():
    """Item 5: the printer never emits a function outside the whitelist (here a user-defined one)."""
    from nambu_bch.numeric.codegen import StepProgram, Update, _validate

    s0, k0 = sympy.Symbol("s0", nambu_internal=True), sympy.Symbol("k0", nambu_internal=True)
    evil = sympy.Function("system")(s0)
    program = StepProgram("x", "1", 1, (sympy.Symbol("x"),), (), (s0,), ((k0, sympy.Symbol("h")),),
                          (Update(1, 1, ((0, k0 * evil),)),))
    with pytest.raises(InvalidSystemError, match="calls system"):
        _validate(program, model("ho"))


# -- item 2: degenerate systems -------------------------------------------------------------------------------


def test_all_pieces_zero_is_the_identity(fresh_cache):
    """Item 2: a rigid body with I1 = I2 = I3 given as numbers: every piece is zero, the step is the identity."""
    x1, x2, x3 = sympy.symbols("x1 x2 x3")
    r2 = (x1**2 + x2**2 + x3**2) / 2
    system = nambu_bch.System([x1, x2, x3], [r2, r2], name="sphere")
    assert not step_program(system, "12321").updates
    compile(python_source(step_program(system, "12321")), "<kernel>", "exec")  # was an IndentationError
    for backend in ("numpy", "numba"):
        x = iterate(system, "12321", 0.1, 50, [1.0, 2.0, 3.0], every=10, backend=backend)
        assert np.array_equal(x, np.tile([1.0, 2.0, 3.0], (6, 1)))


def test_rigid_body_default_parameters_run():
    """Item 2: default I1 = I2 = I3 = 1 (was KeyError 'ComplexInfinity'): runs; singular quantities are skipped."""
    r = check("rigid-body", "12321", 0.1, 200, [1.0, 2.0, 3.0])
    # all pieces vanish at I1 = I2 = I3: H and G are conserved exactly (the step is the identity)
    assert r.max_abs_error["H"] == 0.0 and r.max_abs_error["G"] == 0.0
    assert set(r.skipped) >= {"H_S", "G_S"} and all("singular" in v for v in r.skipped.values())
    assert "skipped" in r.to_dict() and "not evaluated" in str(r)
    x = iterate("rigid-body", "12321", 0.1, 200, [1.0, 2.0, 3.0], every=200)
    assert np.array_equal(x[-1], [1.0, 2.0, 3.0])


@pytest.mark.parametrize("params, phrase", [({"m": 0}, "divides by zero"), ({"omega": 1e200}, "overflows float64"),
                                            ({"m": 1e-320}, "float64")])
def test_bad_parameters_one_clear_error(params, phrase):
    """Item 2: m = 0 (was ZeroDivisionError) and omega = 1e200 (was OverflowError) are one NumericalRangeError."""
    with pytest.raises(NumericalRangeError, match=phrase):
        iterate("ho3", "32123", 0.1, 10, [1.0, 1.0, 1.0], params=params)


# -- item 3: non-finite results -------------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs, phrase", [
    ({"x0": [1e154, 1e154, 1.0]}, "not finite along the run"),
    ({"alpha": 1e300}, "alpha = 1e\\+300"),
    ({"alpha": float("nan")}, "alpha = nan is not finite"),
    ({"alpha": float("inf")}, "not finite"),
])
def test_check_non_finite_is_refused_without_warnings(kwargs, phrase):
    """Item 3: inf/nan diagnostics (were printed with exit 0 and 36 warnings) raise one NumericalRangeError."""
    args = {"x0": [1.0, 1.0, 1.0], **kwargs}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(NumericalRangeError, match=phrase):
            check("ho3", "32123", 0.1, 100, args["x0"], alpha=kwargs.get("alpha", 0.5))


#: Warnings a fresh interpreter does not print by default (``python -W default`` shows them).
_SILENT_BY_DEFAULT = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)


def _cli(*argv):
    """``nambu-bch ARGV`` through ``main(argv)`` in process, as a ``CompletedProcess``.

    Warnings are recorded and written to the captured stderr as the interpreter would print
    them (those it shows by default), so "no numpy warning on stderr" is tested as before.
    """
    import contextlib
    import io

    from nambu_bch.cli import main

    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(argv))
    shown = "".join(f"{w.filename}:{w.lineno}: {w.category.__name__}: {w.message}\n"
                    for w in caught if not issubclass(w.category, _SILENT_BY_DEFAULT))
    return subprocess.CompletedProcess(list(argv), code, out.getvalue(), err.getvalue() + shown)


@pytest.mark.parametrize("argv", [
    ("check", "--x0", "1e154,1e154,1"),
    ("check", "--alpha", "1e300"),
    ("check", "--model", "ho3", "--param", "m=0"),
    ("check", "--model", "ho3", "--param", "omega=1e200"),
])
def test_cli_non_finite_one_line_exit_2(argv):
    """Items 2-3 through the CLI: one line on stderr, exit 2, no traceback or numpy warning."""
    proc = _cli(*argv, "--steps", "50")
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "Warning" not in proc.stderr
    assert "Traceback" not in proc.stderr


def test_cli_rigid_body_default_runs():
    proc = _cli("check", "--model", "rigid-body", "--integrator", "12321", "--steps", "20", "--format", "json")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["max_abs_error"]["H"] == 0.0 and "H_S" in data["skipped"]


# -- item 6: the kernel cache ---------------------------------------------------------------------------------


def _files(root):
    kdir = root / "kernels"
    return kdir, sorted(kdir.glob("nambu_bch_kernel_*.py")), sorted(kdir.glob("nambu_bch_index_*.json"))


def test_cache_layout_modes_and_sympy_free_reload(fresh_cache):
    """Private directories; a second process loads the verified source without sympy."""
    kern = K.kernel(model("ho"), "121")
    kdir, sources, indexes = _files(fresh_cache)
    assert kern.directory == kdir and len(sources) == len(indexes) == 1
    for d in (fresh_cache, kdir, kdir / "__pycache__"):
        assert os.stat(d).st_mode & 0o077 == 0
    meta = json.loads(indexes[0].read_text())
    assert meta["sha256"] == hashlib.sha256(sources[0].read_bytes()).hexdigest()
    assert meta["module"] == f"nambu_bch_kernel_{source_hash(sources[0].read_text())}"
    _forget()
    import nambu_bch.numeric.codegen as codegen

    codegen._step_program.cache_clear()
    again = K.kernel(model("ho"), "121")
    assert again.from_cache and again.source == kern.source
    assert codegen._step_program.cache_info().currsize == 0  # no sympy derivation on a cache hit
    x = iterate(model("ho"), "121", 0.125, 40, [1.0, 0.5])[-1]
    assert np.allclose(x, _exact_verlet(40, Fraction(1, 8), (1, Fraction(1, 2))), rtol=0, atol=1e-14)


def test_modified_cached_kernel_is_regenerated(fresh_cache):
    """Item 6: an edited cached kernel (a wrong x1 after many steps) is detected by its digest and rewritten."""
    kern = K.kernel(model("ho"), "121")
    good = kern.source
    path = kern.path
    path.write_text(good.replace("k0 = K[0]", "k0 = 1.01 * K[0]", 1))
    _forget()
    again = K.kernel(model("ho"), "121")
    assert not again.from_cache and path.read_text() == good
    for backend in ("numpy", "numba"):
        x = iterate(model("ho"), "121", 0.125, 400, [1.0, 0.5], backend=backend)[-1]
        assert np.allclose(x, _exact_verlet(400, Fraction(1, 8), (1, Fraction(1, 2))), rtol=0, atol=1e-13)


@pytest.mark.parametrize("damage", ["empty source", "garbage source", "empty index", "garbage index", "wrong index"])
def test_corrupt_cache_entries_are_regenerated(fresh_cache, damage):
    """Item 6: zero-byte or garbage cache files are regenerated, never a traceback."""
    kern = K.kernel(model("ho3"), "32123")
    good = kern.source
    kdir, (source,), (index,) = _files(fresh_cache)
    if damage == "empty source":
        source.write_bytes(b"")
    elif damage == "garbage source":
        source.write_bytes(os.urandom(300))
    elif damage == "empty index":
        index.write_bytes(b"")
    elif damage == "garbage index":
        index.write_bytes(b"{\x00\xff not json")
    else:
        index.write_text(json.dumps({"module": "../../etc/passwd", "sha256": 1}))
    _forget()
    again = K.kernel(model("ho3"), "32123")
    assert not again.from_cache and source.read_text() == good
    ref = iterate("ho3", "32123", 0.1, 100, [1.0, 1.0, 1.0], backend="numpy")
    assert np.array_equal(iterate("ho3", "32123", 0.1, 100, [1.0, 1.0, 1.0], backend="numba"), ref)


def test_corrupt_numba_cache_entries_are_regenerated(fresh_cache):
    """Item 6: garbage or truncated numba .nbi/.nbc files are purged and compiled again."""
    pytest.importorskip("numba")
    ref = iterate("ho3", "32123", 0.1, 1000, [1.0, 1.0, 1.0], backend="numpy")
    assert np.array_equal(iterate("ho3", "32123", 0.1, 1000, [1.0, 1.0, 1.0], backend="numba"), ref)
    pycache = fresh_cache / "kernels" / "__pycache__"
    entries = sorted(pycache.glob("*.nb?"))
    assert any(e.suffix == ".nbi" for e in entries) and any(e.suffix == ".nbc" for e in entries)
    for e in entries:
        e.write_bytes(b"garbage\n" if e.suffix == ".nbi" else b"")
    code = ("import numpy as np; from nambu_bch.numeric.iterate import iterate; "
            "print(repr(iterate('ho3', '32123', 0.1, 1000, [1.0, 1.0, 1.0], backend='numba')[-1].tolist()))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "NAMBU_BCH_CACHE": str(fresh_cache)})
    assert proc.returncode == 0, proc.stderr
    assert eval(proc.stdout) == ref[-1].tolist()  # noqa: S307 - our own repr of a list of floats


def _plant(root, system, word, marker):
    """A consistent planted kernel (index + module with the right digests) that writes ``marker`` on import."""
    comp = composition(word, len(system.splitting)).check(system.splitting)
    program = step_program(system, comp)
    source = f"open({str(marker)!r}, 'w').write('ran')\n" + python_source(program)
    name = f"nambu_bch_kernel_{source_hash(source)}"
    kdir = root / "kernels"
    (kdir / "__pycache__").mkdir(parents=True, exist_ok=True)
    (kdir / f"{name}.py").write_text(source)
    from nambu_bch.numeric.guards import linear_part

    meta = {"template": K.TEMPLATE_VERSION, "module": name, "N": system.N,
            "sha256": hashlib.sha256(source.encode()).hexdigest(), "n_constants": len(program.constants),
            "n_parameters": len(system.parameters), "linear": list(linear_part(program))}
    (kdir / f"nambu_bch_index_{K.input_key(system, comp)}.json").write_text(json.dumps(meta))


def test_planted_kernel_in_group_writable_cache_is_not_run(fresh_cache, tmp_path):
    """Item 6: a cache directory others can write is refused; the kernel planted in it never runs."""
    marker = tmp_path / "planted-ran"
    _plant(fresh_cache, model("ho"), "121", marker)
    os.chmod(fresh_cache, 0o777)
    kern = K.kernel(model("ho"), "121")
    assert kern.directory != fresh_cache / "kernels" and not kern.from_cache
    assert "writable by group or others" in K.CACHE_NOTES[str(fresh_cache)]
    iterate(model("ho"), "121", 0.1, 10, [1.0, 0.0])
    assert not marker.exists()
    os.chmod(fresh_cache, 0o700)
    _forget()  # control: in a private directory the same planted (consistent) entry *would* be used
    K.kernel(model("ho"), "121")
    assert marker.exists()


def test_planted_kernel_in_foreign_cache_is_not_run(fresh_cache, tmp_path, monkeypatch):
    """Item 6: a cache owned by another user (here: we pretend to be another uid) is refused."""
    marker = tmp_path / "planted-ran"
    _plant(fresh_cache, model("ho"), "121", marker)
    import nambu_bch.private_dirs as private_dirs

    monkeypatch.setattr(private_dirs, "euid", lambda: os.stat(fresh_cache).st_uid + 4242)
    kern = K.kernel(model("ho"), "121")
    assert kern.directory != fresh_cache / "kernels" and "owned by uid" in K.CACHE_NOTES[str(fresh_cache)]
    assert not marker.exists()


def test_symlinked_cache_is_refused(fresh_cache, tmp_path):
    """Item 6: a cache root that is a symbolic link (e.g. planted in /tmp) is not followed."""
    target = tmp_path / "elsewhere"
    target.mkdir(mode=0o700)
    fresh_cache.symlink_to(target)
    kern = K.kernel(model("ho"), "121")
    assert "symbolic link" in K.CACHE_NOTES[str(fresh_cache)] and kern.directory != fresh_cache / "kernels"


# -- item 9: streaming ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("kahan", [False, True])
def test_iterate_chunks_equal_iterate(kahan):
    """Item 9: the blocks together are exactly the samples of one iterate() call (state and Kahan carried)."""
    full = iterate("ho3", "32123", 0.1, 1003, [1.0, 1.0, 1.0], every=3, kahan=kahan)
    blocks = list(iterate_chunks("ho3", "32123", 0.1, 1003, [1.0, 1.0, 1.0], every=3, kahan=kahan, chunk_samples=17))
    assert len(blocks) > 10
    numbers = np.concatenate([b[0] for b in blocks])
    samples = np.concatenate([b[1] for b in blocks])
    assert np.array_equal(numbers, nambu_bch.numeric.sample_steps(1003, 3)) and np.array_equal(samples, full)


def test_streamed_check_equals_one_shot():
    """Item 9: the streamed maxima and drift rates equal those of the whole arrays (two computations)."""
    h, steps = 0.1, 5000
    r = check("ho3", "32123", h, steps, [1.0, 1.0, 1.0], include=("H", "G", "H_c", "o", "s"), chunk_samples=97)
    samples = iterate("ho3", "32123", h, steps, [1.0, 1.0, 1.0])
    errs = errors_along(samples, quantities("ho3", "32123", h, which=("H", "G", "H_c")), model("ho3").coordinates)
    t = h * np.arange(steps + 1)
    for q, series in errs.items():
        assert r.max_abs_error[q] == float(np.max(np.abs(series)))
        assert r.drift_rate[q] == pytest.approx(drift_rate(t, series).rate, rel=1e-9, abs=1e-18)
    assert r.max_abs_error["x3_s"] < 1e-12 < 1e-3 < r.max_abs_error["x3_o"]


def test_running_stats_merge_is_exact():
    """Chan-Golub-LeVeque merging of blocks of unequal size reproduces the one-pass least squares."""
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.5, 1.5, 1000)) + 1e6
    y = 3e-9 * t + rng.normal(0, 1e-3, t.size)
    acc = RunningStats()
    for lo, hi in [(0, 1), (1, 7), (7, 500), (500, 1000)]:
        acc.add(t[lo:hi], y[lo:hi])
    slope = np.polyfit(t - t.mean(), y, 1)[0]
    assert acc.count == 1000 and acc.rate == pytest.approx(slope, rel=1e-9)
    assert acc.rate == pytest.approx(drift_rate(t, y).rate, rel=1e-9)


def test_check_memory_is_bounded():
    """Item 9: check with every step sampled holds one block, not the run (tracemalloc peak, not a timing)."""
    x0 = [1.0, 1.0, 1.0]
    # warm: compile, derive H_c (backend="auto" runs 10 steps on the interpreter while no compiled loop exists, so
    # the compile, tens of MB of Python objects, would fall inside the traced run when no earlier test compiled it)
    warm = "numba" if importlib.util.find_spec("numba") else "auto"
    check("ho3", "32123", 0.1, 10, x0, include=("H", "H_c"), backend=warm)
    steps = 1_000_000
    tracemalloc.start()
    try:
        r = check("ho3", "32123", 0.1, steps, x0, include=("H", "H_c"), chunk_samples=1 << 14)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    whole = (steps + 1) * 3 * 8  # the sample array alone of a non-streamed check: 24 MB
    assert peak < whole / 4, peak
    assert r.max_abs_error["H_c"] < 1e-12 and r.max_abs_error["H"] > 1e-4


def test_check_label_names_the_difference():
    """`check` prints max |x1^o - x1|, not max |x1_o|."""
    text = str(check("ho3", "32123", 0.1, 50, [1.0, 1.0, 1.0], include=("H", "o")))
    assert "max |x1^o - x1|" in text and "x1_o" not in text and "max |H(t) - H(0)|" in text


# -- plot: figures as a set, returned, streamed ----------------------------------


def test_paper_figures_returns_figures_with_parameters(tmp_path):
    """The matplotlib figures come back with the paths; titles show h, the parameters, x(0)."""
    from matplotlib.figure import Figure

    from nambu_bch.numeric.figures import paper_figures

    fs = paper_figures(tmp_path, t_short=5.0, t_long=200.0, every_long=10, dpi=40, params={"omega": 0.5})
    assert sorted(fs) == sorted(fs.figures) == ["fig1", "fig2", "fig3", "fig4"]
    assert all(isinstance(f, Figure) for f in fs.figures.values()) and all(p.is_file() for p in fs.values())
    title = fs.figures["fig1"].axes[0].get_title()
    assert "h = 0.1" in title and r"\omega = 0.5" in title and "x(0) = (1, 1, 1)" in title
    # each title names the system (a loop variable once shadowed its name: the titles read fig1, fig2, fig2, fig2)
    titles = {n: f.axes[0].get_title() for n, f in fs.figures.items()}
    assert [titles[n].split(", ")[0] for n in ("fig1", "fig2", "fig4")] == ["ho3"] * 3, titles
    assert titles["fig3"].startswith("the beat, ho3, "), titles
    # drawn at the resolution it is written at: laid out and rendered once per figure at one dpi
    assert all(f.dpi == 40 for f in fs.figures.values())
    drawn = paper_figures(None, t_short=5.0, t_long=200.0, every_long=10)
    assert dict(drawn) == {} and len(drawn.figures) == 4


def test_paper_figures_all_or_nothing(tmp_path):
    """Item 7: a figure that cannot be written leaves every existing file as it was and no temp file."""
    from nambu_bch.numeric.figures import paper_figures

    (tmp_path / "fig1.png").write_bytes(b"old figure 1")
    (tmp_path / "fig3.png").mkdir()  # os.replace onto a directory fails
    with pytest.raises(NambuBCHError, match="no figure was written"):
        paper_figures(tmp_path, t_short=5.0, t_long=200.0, every_long=10, dpi=40)
    assert (tmp_path / "fig1.png").read_bytes() == b"old figure 1"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig1.png", "fig3.png"]


def test_cli_plot_file_error_one_line(tmp_path):
    (tmp_path / "fig2.png").mkdir()
    proc = _cli("plot", "--outdir", str(tmp_path), "--steps", "2000", "--every", "10", "--short-steps", "50")
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr
    assert not (tmp_path / "fig1.png").exists()


def test_cli_plot_help_names_the_default_run():
    helptext = _cli("plot", "--help").stdout
    assert "32123 on ho3" in " ".join(helptext.split())


def test_long_plot_is_an_envelope_of_the_run(monkeypatch):
    """Item 9 (plot): beyond MAX_POINTS a curve is the per-bucket min/max; it keeps the run's extremes exactly."""
    from nambu_bch.numeric import figures

    monkeypatch.setattr(figures, "MAX_POINTS", 400)
    steps = 20_000
    env, size = figures._stream(model("ho3"), "32123", 0.1, steps, 1, (1.0, 1.0, 1.0), None, kinds="o")
    t, y = env["o"].arrays()
    assert size > 1 and len(y) <= 2 * (400 // 2) + 2
    sol = nambu_bch.exact.modified_solution(model("ho3"), "32123", "o").numeric(h=0.1)
    run = iterate("ho3", "32123", 0.1, steps, [1.0, 1.0, 1.0])
    diff = sol(0.1 * np.arange(steps + 1), np.ones(3))[2] - run[:, 2]
    assert y.max() == diff.max() and y.min() == diff.min() and env["o"].max_abs == np.abs(diff).max()


# -- the batch guards in one compiled pass ------------------------------------------------------------


def test_compiled_scan_agrees_with_numpy_guards():
    """The kernel's one-pass scan finds the same extreme states as the numpy extreme_states, and the
    same bad inputs (non-finite, subnormal) as check_inputs' numpy passes."""
    pytest.importorskip("numba")
    from nambu_bch.numeric.guards import extreme_states

    kern = K.kernel(model("ho3"), "32123")
    rng = np.random.default_rng(3)
    X = rng.uniform(0.5, 1.5, size=(3, 6000)) * 10.0 ** rng.integers(-100, 100, size=(3, 6000))
    X[2, 17] = 0.0
    bad, sub, cols = kern.scan(X)
    assert (bad, sub) == (0, 0) and set(cols) == set(extreme_states(X))
    for value, phrase in [(np.nan, "non-finite"), (np.inf, "non-finite"), (1e-310, "underflows")]:
        Y = np.ones((3, 6000))
        Y[1, 4321] = value
        assert sum(kern.scan(Y)[:2]) == 1
        with pytest.raises(NumericalRangeError, match=phrase):
            iterate("ho3", "32123", 0.1, 5, Y, backend="numba")
    Y = np.ones((3, 6000))
    Y[1, 4000] = 1e200  # x3 += k x1 x2 ... overflows in one step: found among the scanned extremes
    with pytest.raises(NumericalRangeError, match="overflows float64"):
        iterate("ho3", "32123", 0.1, 5, Y, backend="numba")


def test_unwritable_source_file_still_runs(fresh_cache, monkeypatch):
    """Item 6: when the source cannot be written (full disk, read-only file system) the kernel runs from
    memory, compiled without numba's disk cache, and gives the same states."""
    pytest.importorskip("numba")

    def refuse(path, data):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(K, "_write_file", refuse)
    kern = K.kernel(model("ho"), "121")
    assert not kern.path.exists() and not kern.from_cache
    x = iterate(model("ho"), "121", 0.125, 500, [1.0, 0.5], backend="numba", every=500)[-1]
    assert np.allclose(x, _exact_verlet(500, Fraction(1, 8), (1, Fraction(1, 2))), rtol=0, atol=1e-13)


def test_figure_titles_carry_no_user_markup(tmp_path):
    """Item 5 (figures): a system name or parameter name with TeX commands reaches no title as markup."""
    from nambu_bch.numeric.figures import _param_tex, _plain

    assert _plain(r"$\input{/etc/passwd}$") == "inputetcpasswd"
    assert _param_tex(sympy.Symbol(r"\input{/etc/passwd}")) == r"\mathrm{inputetcpasswd}"
    assert _param_tex(sympy.Symbol("omega")) == r"\omega"
