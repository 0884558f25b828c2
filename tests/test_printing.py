"""Printing of results: sympy printer hooks, H + h^2(...) layout, progress bars, lazy CLI.

Values come from Horikoshi, Eqs. (SH12321c), (SG12321c), (BCH2), (ESH12321), (ESG12321) and Table (table);
each printed form is checked against the result it prints (parsed back), not only by its look.
"""

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from nambu_bch import (
    conserved_quantities,
    effective_field,
    exact_shadow_hamiltonians,
    formal_bch,
    model,
    shadow_hamiltonians,
)
from nambu_bch.printing import Printable, flatten, h_coefficients, latex_text, series_text

REPO = Path(__file__).resolve().parents[1]
h, alpha = sympy.symbols("h alpha")


@pytest.fixture(scope="module")
def results():
    ho3 = model("ho3")
    return {
        "family": shadow_hamiltonians(ho3, "12321"),
        "conserved": conserved_quantities(ho3, "31213"),
        "exact": exact_shadow_hamiltonians(ho3, "12321"),
        "bch": formal_bch("12321", 3),
        "field": effective_field(ho3.splitting, "12321", 2),
    }


def test_one_mixin_gives_every_hook(results):
    """sympy.latex / sympy.sstr / str / _repr_latex_ all come from the one Printable mixin (no copies)."""
    for name, obj in results.items():
        cls = type(obj)
        assert isinstance(obj, Printable), name
        for hook in ("_latex", "_sympystr", "__str__", "_repr_latex_"):
            assert getattr(cls, hook) is getattr(Printable, hook), (name, hook)
        tex = obj.to_latex()
        assert sympy.latex(obj) == tex and tex.startswith("\\begin{aligned}") and tex.endswith("\\end{aligned}")
        assert obj._repr_latex_() == "$$" + tex + "$$"
        assert sympy.sstr(obj) == str(obj) == obj.to_text()
        assert not str(obj).startswith(cls.__name__) and str(obj) != repr(obj)  # readable, not a repr
        assert r"\mathtt" not in sympy.latex(obj)


def test_shadow_family_is_printed_as_the_paper_writes_it(results):
    """Eqs. (SH12321c), (SG12321c): H_S = H + h^2(...) + O(h^4), G_S = G + h^2(...) + O(h^4)."""
    F = results["family"]
    flat = flatten(F.to_latex())
    assert flat.startswith(r"H_{S} = H + h^{2}\left(") and r"G_{S} = G + h^{2}\left(" in flat and "O(h^{4})," in flat
    # the text form, parsed back, is the family itself
    ho3 = model("ho3")
    names = {**ho3.symbols(), "H": ho3.H, "G": ho3.G}
    for line, S in zip(str(F).splitlines()[:2], F.shadows):
        lhs, rhs = line.split(" = ", 1)
        assert rhs.endswith(" + O(h^4)")
        assert sympy.expand(sympy.sympify(rhs[: -len(" + O(h^4)")], locals=names) - S) == 0, lhs


def test_conserved_is_H_minus_as_in_table(results):
    """Table (table), row 31213: H_c = H - h^2 omega^2 x2^2/(4m), printed with H first (not -h^2.../4m + ...)."""
    cq = results["conserved"]
    flat = flatten(cq.to_latex())
    assert flat.startswith(r"H_{c} = H - \frac{h^{2} \omega^{2} x_{2}^{2}}{4 m}, G_{c} = G - \frac{h^{2} x_{2}^{2}}{4 m^{2}},")
    assert str(cq).splitlines()[:2] == ["H_c = H - h**2*omega**2*x2**2/(4*m)", "G_c = G - h**2*x2**2/(4*m**2)"]


def test_exact_series_ascending_with_even_remainder(results):
    """Eq. (ESH12321) through h^4: H + h^2(...) + h^4(...) + O(h^6) (F(omega h) is even), not h^2(...) first / O(h^5)."""
    ex = results["exact"]
    flat = flatten(ex.to_latex(order=4))
    assert r"H_{S}^{e} = H + h^{2}\left(" in flat and "O(h^{6})" in flat and "O(h^{5})" not in flat
    row = [line for line in ex.to_text(order=4).splitlines() if line.startswith("H_S^e = H")][0]
    assert row.index("h**2") < row.index("h**4") and row.endswith("O(h^6)")
    assert ex.remainder_power(4) == 6
    # a non-symmetric word keeps its odd powers: the remainder after h^3 is O(h^4)
    lt = exact_shadow_hamiltonians(model("ho"), "lie-trotter")
    assert lt.remainder_power(3) == 4 and lt.remainder_power(2) == 3


def test_h_coefficients_resum_exactly(results):
    """Each collected form sums back to the expression it prints (two ways: coefficients, and sympy's own Poly)."""
    F = results["family"]
    for S, H in zip(F.shadows, model("ho3").hamiltonians):
        coeffs = h_coefficients(S, H, model("ho3").coordinates)
        assert sympy.expand(H + sum(c * h**k for k, c in coeffs) - S) == 0
        assert {k for k, _ in coeffs} == {m[0] for m in sympy.Poly(sympy.expand(S - H), h).monoms()}
    # not polynomial in h: reported as such, printed as H + (difference)
    x = sympy.Symbol("x")
    assert h_coefficients(x / (1 - h), x, [x]) is None
    assert series_text("H", x / (1 - h), x, [x]).startswith("H + (")


def test_bch_and_field_print_term_by_term(results):
    """Eq. (BCH2): 3 + 8 terms in the Lyndon basis; the text form lists the same brackets."""
    B, X = results["bch"], results["field"]
    text = str(B)
    assert text.startswith("X_eff = X1 + X2 + X3 + (-1/24)*h**2*[X1,[X1,X2]]") and text.endswith("O(h^4)")
    assert text.count("h**2") == len(B.terms(3)) == 8
    tex = B.to_latex()
    assert tex.count("\\\\") >= 1  # broken into lines
    assert str(X).splitlines()[0] == "X_eff = Z_0 + h**2*Z_2 + O(h^4)"
    assert r"h^{2}\left(" in flatten(X.to_latex())


def test_latex_lines_fit_the_width(results):
    """Every line of every block is within the layout width (estimated), except a single unbreakable term."""
    from nambu_bch.printing import WIDTH, width

    rb = shadow_hamiltonians(model("rigid-body"), "12321")
    for obj in [*results.values(), rb]:
        for line in obj.to_latex().split("\\\\\n"):
            line = line.replace("\\begin{aligned}\n", "").replace("\n\\end{aligned}", "")
            assert width(line) <= WIDTH + 12 or " + " not in line.strip("&\\quad "), line


def test_user_text_cannot_reach_latex_unescaped():
    r"""A system name with LaTeX specials is neutralised (no \input, braces balanced)."""
    evil = r"x}\input{/etc/passwd}$%&#~^"
    out = latex_text(evil)
    assert "\\input" not in out and "$" not in out and "%" not in out and "&" not in out
    assert out.count("{") == out.count("}")


# -- progress (item 3) ----------------------------------------------------------------------------------------------
def test_progress_bar_captured_off_a_tty():
    """A tqdm bar drawn into a StringIO when enabled; nothing when automatic (a StringIO is not a terminal)."""
    from nambu_bch.progress import Progress, stages

    stream = io.StringIO()
    with Progress(2000, "iterate ho3 32123", enabled=True, stream=stream, delay=0, interval=0) as p:
        for k in (500, 1000, 2000):
            p.update(k)
    out = stream.getvalue()
    assert "iterate ho3 32123" in out and "50%" in out and "2000/2000" in out and out.endswith("\n")
    quiet = io.StringIO()
    with Progress(2000, "x", stream=quiet, delay=0, interval=0) as p:
        p.update(2000)
    assert quiet.getvalue() == ""
    stream = io.StringIO()
    assert list(stages([1, 2, 3], "orders", enabled=True, stream=stream, delay=0)) == [1, 2, 3]
    assert "3/3" in stream.getvalue()


def test_direct_route_shows_orders_and_progress_false_silences(monkeypatch, capsys):
    """shadow_hamiltonians(progress=True) draws a bar over the orders on stderr; progress=False draws nothing."""
    import nambu_bch.progress as progress

    monkeypatch.setattr(progress, "DELAY", 0.0)
    F = shadow_hamiltonians(model("ho"), "121", order=4, progress=True)
    err = capsys.readouterr().err
    assert "shadow 121 on ho: orders" in err and "4/4" in err
    G = shadow_hamiltonians(model("ho"), "121", order=4, progress=False)
    assert capsys.readouterr().err == ""
    assert F.shadows == G.shadows


def test_cli_no_progress_flag(monkeypatch, capsys):
    """--no-progress turns off a bar that would otherwise be drawn (here: a Jupyter-like stderr)."""
    import nambu_bch.progress as progress
    from nambu_bch.cli import main

    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(progress, "_in_jupyter", lambda: True)
    monkeypatch.delenv("NAMBU_BCH_PROGRESS", raising=False)
    assert main(["shadow", "--model", "ho", "--integrator", "121", "--order", "4", "--format", "text"]) == 0
    shown = capsys.readouterr()
    assert "orders" in shown.err
    assert main(["shadow", "--model", "ho", "--integrator", "121", "--order", "4", "--format", "text", "--no-progress"]) == 0
    quiet = capsys.readouterr()
    assert quiet.err == "" and quiet.out == shown.out
    assert "NAMBU_BCH_PROGRESS" not in os.environ  # restored after the run


# -- instant help (item 5) ------------------------------------------------------------------------------------------
def _python(code, cache):
    env = {**os.environ, "PYTHONPATH": str(REPO), "NAMBU_BCH_CACHE": str(cache)}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done


PROBE = ("import sys\nfrom nambu_bch.cli import main\ncode = main({argv!r})\n"
         "print(sorted(m for m in ('sympy', 'numpy', 'numba') if m in sys.modules), file=sys.stderr)\n")


def test_help_and_errors_import_neither_sympy_nor_numpy(tmp_path):
    """--help, a subcommand's --help and a bad flag answer without importing sympy/numpy (lazy imports), and so does
    importing the package with its pytest entry point.  One process for all of them: the heavy modules are listed
    after each step, so the first step that imports one is named."""
    argvs = [["--help"], ["shadow", "--help"], ["models", "--help"], ["shadow", "--order", "x"]]
    # nambu_bch._pytest_plugin: the pytest11 entry point, which pytest imports at the start of every test run
    code = ("import sys\nimport nambu_bch, nambu_bch._pytest_plugin\nfrom nambu_bch.cli import main\n"
            "def heavy():\n    return sorted(m for m in ('sympy', 'numpy', 'numba') if m in sys.modules)\n"
            "print('@@', 'import', heavy(), file=sys.stderr)\n"
            f"for argv in {argvs!r}:\n    main(argv)\n    print('@@', argv, heavy(), file=sys.stderr)\n"
            "from nambu_bch import model\nprint('sympy' in sys.modules, model('ho').N)\n")
    done = _python(code, tmp_path)
    steps = [line for line in done.stderr.splitlines() if line.startswith("@@ ")]
    assert steps == ["@@ import []"] + [f"@@ {argv} []" for argv in argvs], done.stderr
    assert done.stdout.splitlines()[-1].split() == ["True", "2"]  # the package imports lazily, and still works


def test_models_listing_is_cached_and_identical(tmp_path, monkeypatch, capsys):
    """The built-in listing: computed once (sympy), then read from the cache without sympy, byte for byte; computed
    again (here, in another process with another hash seed, with an empty cache) it is the same bytes."""
    argv = ["models", "--format", "json"]
    first = _python(PROBE.format(argv=argv), tmp_path)
    second = _python(PROBE.format(argv=argv), tmp_path)
    assert "sympy" in first.stderr.splitlines()[-1] and second.stderr.strip().splitlines()[-1] == "[]"
    assert first.stdout == second.stdout and '"ho3"' in first.stdout
    from nambu_bch.cli import main

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path / "empty"))
    assert main(argv) == 0
    assert capsys.readouterr().out == first.stdout


def test_models_cache_is_not_trusted_in_a_shared_directory(tmp_path, monkeypatch, capsys):
    """A cache directory writable by others (or a planted file in it) is never read back: the listing is
    computed, so another local user cannot choose what `nambu-bch models` prints."""
    import os

    from nambu_bch.cli import main
    from nambu_bch.cli.cache import _key

    root = tmp_path / "shared"
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(root))
    assert main(["models", "--format", "text"]) == 0
    honest = capsys.readouterr().out
    planted = root / "cli" / (_key(("models", "text", False)) + ".txt")
    files = list((root / "cli").glob("*.txt"))
    assert len(files) == 1
    files[0].write_text("planted\n")
    os.chmod(root / "cli", 0o777)             # group/other-writable: untrusted
    assert main(["models", "--format", "text"]) == 0
    assert capsys.readouterr().out == honest
    os.chmod(root / "cli", 0o700)
    os.chmod(files[0], 0o666)                 # the file itself writable by others: untrusted
    assert main(["models", "--format", "text"]) == 0
    assert capsys.readouterr().out == honest
    del planted


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.lists(st.tuples(st.sampled_from([-3, -1, 1, 2, sympy.Rational(5, 7)]),
                          st.sampled_from([1, sympy.Symbol("I1"), 1 / sympy.Symbol("I2"),
                                           1 / (sympy.Symbol("I1") - sympy.Symbol("I3"))]),
                          st.tuples(st.integers(0, 2), st.integers(0, 2), st.integers(0, 3))),
                min_size=0, max_size=8))
def test_coefficients_by_monomial_equal_poly_terms(terms):
    """The linear-time grouping of printing._coefficients gives Poly(expr, *gens).terms(): same monomials, same
    order, equal coefficients (the layout of Eqs. (SH12321c), (SG12321c) rests on it)."""
    from nambu_bch.printing import _coefficients

    x1, x2, h = sympy.symbols("x1 x2 h")
    expr = sympy.expand(sum((c * k * x1**a * x2**b * h**j for c, k, (a, b, j) in terms), sympy.Integer(0)))
    gens = (x1, x2, h)
    ours = _coefficients(expr, gens)
    plain = [(m, c) for m, c in sympy.Poly(expr, *gens).terms() if c != 0] if expr != 0 else []
    assert [m for m, _ in ours] == [m for m, _ in plain]
    assert all(sympy.cancel(a - b) == 0 for (_, a), (_, b) in zip(ours, plain))
    assert _coefficients(expr + x1 / (1 + x2), gens) is None  # not a polynomial: the caller factors instead
