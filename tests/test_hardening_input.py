"""The input side: never a silent wrong answer, never a way in, bounded work, one line on every fault.

Classes: words that leave out a piece, silent coercions, names and raw text, ``--output``,
bounded work, Ctrl-C / closed stdout; and "done when": the API raises only the package's exception
family for misuse, and the whole CLI keeps the one-line / exit-2 / nothing-executed contract.
Most CLI cases run in process through ``nambu_bch.cli.main(argv)``; a few subprocesses test signals and pipes.
"""

from __future__ import annotations

import json
import math
import os
import signal
import stat
import subprocess
import sys
import textwrap
import threading
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch.atomic import write_output
from nambu_bch.bch import effective_field, effective_field_bch, formal_bch
from nambu_bch.cli import main
from nambu_bch.errors import (
    InconsistentCoefficientsError,
    InvalidCompositionError,
    InvalidSystemError,
    NambuBCHError,
    ResourceLimitError,
    UnknownPieceError,
)
from nambu_bch.integrators import composition, composition_for, strang_word
from nambu_bch.systems.spec import load_system
from nambu_bch.parsing import parse_expression
from nambu_bch.systems.system import USER_NAME

REPO = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(REPO)}
# The first statement of the SIGINT tests' children: Ctrl-C as a terminal delivers it.  A child inherits an ignored
# SIGINT from a background job or a CI runner that ignores it, and Python then installs no handler: the signal would
# be lost, the child would run its whole computation and the test would fail for a reason outside the package.
TERMINAL_SIGINT = "import signal; signal.signal(signal.SIGINT, signal.default_int_handler)\n"
THREE_PIECES = ("ho3", "rigid-body", "lotka-volterra")  # (ho3-composite has two pieces)


def one_line(capsys, code, *fragments, status=2):
    """``main`` returned ``status`` with exactly one stderr line containing ``fragments``, no traceback, no stdout."""
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == status, captured.err
    assert len(lines) == 1 and "Traceback" not in captured.err, captured.err
    for f in fragments:
        assert f.lower() in lines[0].lower(), lines[0]
    assert captured.out == ""
    return lines[0]


# =============================================================================================
# item 1: a composition must use every piece, with total coefficient 1
# =============================================================================================
@pytest.mark.parametrize("name", THREE_PIECES)
@pytest.mark.parametrize("word", ["121", "212", "12", "1:1/2,2:1,1:1/2"])
def test_word_leaving_out_piece_3_is_refused_naming_it(name, word):
    """121, 212, 12 never apply piece 3 of a three-piece splitting: refused, naming piece 3."""
    S = nb.model(name)
    assert len(S.splitting) == 3
    with pytest.raises(InconsistentCoefficientsError, match=r"never applies piece\(s\) \[3\]"):
        composition_for(word, S)


@pytest.mark.parametrize("alias", ["TVT", "VTV", "pv", "velocity-verlet"])
def test_two_piece_aliases_exist_only_for_two_pieces(alias):
    with pytest.raises(InvalidCompositionError, match="only for two-piece splittings"):
        composition_for(alias, nb.model("ho3"))
    assert composition_for(alias, nb.model("ho")).pieces in ((1, 2, 1), (2, 1, 2))


ROUTES = {
    "shadow direct": lambda S, w: nb.shadow_hamiltonians(S, w, 2),
    "shadow fi": lambda S, w: nb.shadow_hamiltonians(S, w, 2, route="fi"),
    "fi_route": lambda S, w: nb.fi_route(S, w),
    "direct_route": lambda S, w: nb.direct_route(S, w, 2),
    "effective_field (backward)": lambda S, w: effective_field(S.splitting, w, 2),
    "effective_field_bch": lambda S, w: effective_field_bch(S.splitting, w, 2),
    "composed_map": lambda S, w: nb.composed_map(S.splitting, w),
    "step_function": lambda S, w: nb.step_function(S.splitting, w),
    "conserved_quantities": lambda S, w: nb.conserved_quantities(S, w),
    "is_invariant": lambda S, w: nb.is_invariant(S, w, S.hamiltonians[1]),
    "exact_shadow_hamiltonians": lambda S, w: nb.exact_shadow_hamiltonians(S, w),
    "modified_solution": lambda S, w: nb.modified_solution(S, w, "c"),
    "iterate": lambda S, w: nb.iterate(S, w, h=0.1, steps=10, x0=(1.0, 1.0, 1.0)),
    "check": lambda S, w: nb.check(S, w, 0.1, 10, (1.0, 1.0, 1.0)),
}


@pytest.mark.parametrize("route", list(ROUTES))
@pytest.mark.parametrize("word", ["121", "triple-jump:121", "212"])
def test_every_api_route_refuses_a_word_leaving_out_a_piece(route, word):
    """The one check (Composition.check via composition_for) is on every route: no route computes for 121 on ho3."""
    with pytest.raises(InconsistentCoefficientsError, match=r"piece\(s\) \[3\]"):
        ROUTES[route](nb.model("ho3"), word)


CLI_ROUTES = [
    ["shadow"], ["shadow", "--route", "fi"], ["bch", "--field"], ["bch", "--field", "--terms"], ["fi"], ["conserved"],
    ["exact"], ["check", "--steps", "10"], ["plot", "--steps", "10", "--short-steps", "10", "--every", "1"],
]


@pytest.mark.parametrize("argv", CLI_ROUTES, ids=lambda a: " ".join(a))
@pytest.mark.parametrize("word", ["121", "212", "TVT", "VTV", "12", "yoshida:121"])
def test_every_cli_route_refuses_a_word_leaving_out_a_piece(capsys, tmp_path, argv, word):
    argv = [*argv, "--model", "ho3", "--integrator", word]
    if argv[0] == "plot":
        argv += ["--outdir", str(tmp_path)]
    line = one_line(capsys, main(argv))
    assert ("piece(s) [3]" in line) or ("only for two-piece" in line), line
    assert not list(tmp_path.iterdir())  # plot wrote nothing


def test_composition_check_is_the_one_place():
    """Every route goes through composition_for -> Composition.check: no other copy of the check in the package."""
    sources = [p for p in (REPO / "nambu_bch").rglob("*.py") if p.name != "composition.py"]
    hits = [str(p.relative_to(REPO)) for p in sources if ".check(system.splitting)" in p.read_text()
            or ".check(splitting)" in p.read_text()]
    # numeric/* is maintained separately; it calls the same Composition.check
    assert all(h.startswith("nambu_bch/numeric/") for h in hits), hits


def _per_piece_sums(comp):
    sums = {}
    for k, c in comp.factors():
        sums[k] = sums.get(k, 0) + c
    return {k: sympy.nsimplify(sympy.expand(v)) for k, v in sums.items()}


@pytest.mark.parametrize("name", THREE_PIECES)
@pytest.mark.parametrize("alias", ["forest-ruth", "yoshida", "suzuki", "strang"])
def test_aliases_expand_over_the_systems_own_pieces(name, alias):
    """forest-ruth / yoshida / suzuki compose the system's Strang word 12321: every piece, total coefficient 1."""
    S = nb.model(name)
    comp = composition_for(alias, S)
    assert set(comp.pieces) == {1, 2, 3}
    assert _per_piece_sums(comp) == {1: 1, 2: 1, 3: 1}
    assert comp.symmetric
    assert comp.order == (2 if alias == "strang" else 4)


def test_suzuki_five_jump_coefficients_exact():
    """Suzuki, Phys. Lett. A 146 (1990) 319, Eq. (3.14): g1 = g2 = g4 = g5 = 1/(4 - 4^(1/3)), g3 = 1 - 4 g1,
    applied to Strang 121 (half steps of piece 1, adjacent half steps merged)."""
    comp = composition("suzuki")
    g = sympy.Symbol("g")  # each coefficient is p + q g with p, q rational
    g3 = 1 - 4 * g
    half = sympy.Rational(1, 2)
    expected_pieces = (1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1)
    expected = (g * half, g, g, g, (g + g3) * half, g3, (g3 + g) * half, g, g, g, g * half)
    assert comp.pieces == expected_pieces
    # a = p + q/(4 - 4^(1/3)) iff (a - p)(4 - 4^(1/3)) = q: expanded, both sides are normal forms over the basis
    # 1, 2^(1/3), 2^(2/3) of QQ(2^(1/3)) (sympy reduces products of rational powers of 2), so == decides it exactly
    for a, b in zip(comp.coefficients, expected):
        p, q = b.subs(g, 0), b.diff(g)
        assert sympy.expand((a - p) * (4 - sympy.root(4, 3))) == q and not a.has(sympy.Float)
    assert abs(float(comp.coefficients[5]) - (1 - 4 / (4 - 4 ** (1 / 3)))) < 1e-15  # g3 = -0.6580...
    assert comp.extension == (sympy.cbrt(2),)


@pytest.mark.parametrize("alias", ["suzuki", "forest-ruth"])
def test_jumps_on_ho3_are_fourth_order_two_ways(alias):
    """Fourth order of the expanded jumps, checked two independent ways: (a) the formal BCH series has no
    degree-2 and degree-3 terms (Yoshida 1990, Eq. 5.19; Suzuki 1990), (b) X_eff on ho3 by backward error
    analysis has Z_1 = Z_2 = Z_3 = 0 while Z_4 is not zero."""
    S = nb.model("ho3")
    comp = composition_for(alias, S)
    series = formal_bch(comp, 4)
    assert not series.terms(2) and not series.terms(3)
    X = effective_field(S.splitting, comp, 4)
    assert all(X[j].is_zero() for j in (1, 2, 3)) and not X[4].is_zero()


def test_nested_jumps_refused_in_one_line():
    """yoshida:yoshida:121 took 185 s and then raised a sympy CoercionFailed; now refused up front (item 8)."""
    for spec in ("yoshida:yoshida:121", "suzuki:yoshida:121", "triple-jump:suzuki", "yoshida:forest-ruth"):
        with pytest.raises(InvalidCompositionError, match="nested jumps"):
            composition(spec, 2)


def test_the_paper_words_still_pass():
    """Regression: the paper's six words (Sect. 5.1) and the default Strang word are accepted on ho3."""
    S = nb.model("ho3")
    for word in (*nb.PAPER_WORDS, "123", "lie-trotter", strang_word(3)):
        assert composition_for(word, S).name


# =============================================================================================
# item 4: no silent coercion
# =============================================================================================
@pytest.mark.parametrize("spec", [
    [(1.5, 1)], [(True, 1)], [("1", 1)], [(np.float64(1.0), 1)], [(1, None)], [(1, b"1")],
    [(1, [1])], [(10**30, 1)], [(0, 1)], [(-1, 1)],
])
def test_explicit_composition_no_coercion(spec):
    """composition([(1.5, 1)]) used to become piece 1; every such spec is refused now."""
    with pytest.raises(InvalidCompositionError):
        composition(spec)


@pytest.mark.parametrize("n", ["3", 2.0, True, 0, -1, 10**9])
def test_n_pieces_validated(n):
    with pytest.raises(InvalidCompositionError, match="n_pieces"):
        composition("strang", n)


def test_integral_sympy_piece_numbers_are_fine():
    assert composition([(sympy.Integer(1), Fraction(1, 2)), (2, 1), (1, "1/2")]).pieces == (1, 2, 1)


# =============================================================================================
# item 5: names and raw text
# =============================================================================================
HOSTILE_NAMES = [r"\input{/etc/passwd}", 'a"""b', "a'b", "x#y", "a\nb", "a b", "ｘ1", "1abc", "", "a" * 65, "$x$", "a{b}"]


@pytest.mark.parametrize("bad", HOSTILE_NAMES)
def test_system_names_validated_at_the_door(capsys, tmp_path, bad):
    one_line(capsys, main(["models", "--H", "x2^2/2 + x1^2/2", "--name", bad]), "--name")
    toml = tmp_path / "s.toml"
    toml.write_text(f'name = {json.dumps(bad)}\ncoordinates = "x1 x2"\nH = "x2^2/2 + x1^2/2"\n')  # JSON escapes are TOML's
    with pytest.raises(InvalidSystemError, match="name"):
        load_system(toml)


def test_latex_injection_never_reaches_latex(tmp_path, capsys):
    """``\\input{/etc/passwd}`` as --name, TOML name, --integrator, --coords, --param: exit 2, nothing printed."""
    toml = tmp_path / "x.toml"
    toml.write_text('name = "\\\\input{/etc/passwd}"\ncoordinates = "x1 x2"\nH = "x2^2/2 + x1^2/2"\n')
    for argv in (
        ["models", "--format", "latex", "--H", "x2^2/2 + x1^2/2", "--name", r"\input{/etc/passwd}"],
        ["models", "--format", "latex", "--system", str(toml)],
        ["bch", "--integrator", r"\input{/etc/passwd}"],
        ["fi", "--integrator", r"1:1/2\input{/etc/passwd},2:1,3:1,1:1/2"],
        ["models", "--H", "x2^2/2 + x1^2/2", "--coords", r"\input x2"],
        ["models", "--H", "x2^2/2 + x1^2/2", "--param", r"\input=1"],
    ):
        one_line(capsys, main(argv))


def test_comment_in_integrator_text_refused(capsys):
    """A '#' was dropped by Python's tokenizer inside the coefficient parser, so junk passed (item 5)."""
    one_line(capsys, main(["bch", "--integrator", "1:1/2 # import os,2:1,3:1,1:1/2"]), "'#'")
    with pytest.raises(NambuBCHError, match="'#'"):
        parse_expression("1/2 # anything", [])


@pytest.mark.parametrize("name", ["ｘ1", "x\u0301", "lambda", "None", "_x", "x" * 33, "x-1", "x.y"])
def test_symbol_names_ascii_identifiers_only(name):
    """Non-ASCII identifiers would be NFKC-normalised by Python (ｘ1 -> x1); keywords cannot be symbols."""
    with pytest.raises(InvalidSystemError):
        nb.System(f"{name} x2", ["x2**2/2"])


# =============================================================================================
# item 7: --output
# =============================================================================================
def test_output_keeps_mode_and_replaces_atomically(tmp_path, capsys):
    out = tmp_path / "r.txt"
    out.write_text("old")
    os.chmod(out, 0o600)
    assert main(["models", "--model", "ho", "--output", str(out)]) == 0
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o600 and out.read_text().startswith("ho ")
    assert [p.name for p in tmp_path.iterdir()] == ["r.txt"]  # no temporary file left


def test_output_new_file_gets_umask_mode(tmp_path):
    mask = os.umask(0o027)
    try:
        write_output(tmp_path / "new.txt", "x")
    finally:
        os.umask(mask)
    assert stat.S_IMODE(os.stat(tmp_path / "new.txt").st_mode) == 0o640


def test_output_follows_symlink_and_keeps_it(tmp_path, capsys):
    target = tmp_path / "target.txt"
    target.write_text("old")
    os.chmod(target, 0o640)
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    assert main(["models", "--model", "ho", "--output", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text().startswith("ho ") and stat.S_IMODE(os.stat(target).st_mode) == 0o640


def test_output_dangling_symlink_and_directory_refused(tmp_path, capsys):
    link = tmp_path / "dangling"
    link.symlink_to(tmp_path / "nowhere")
    one_line(capsys, main(["models", "--output", str(link)]), "symbolic link")
    assert link.is_symlink() and not (tmp_path / "nowhere").exists()
    one_line(capsys, main(["models", "--output", str(tmp_path)]), "directory")
    loop = tmp_path / "loop"
    loop.symlink_to(loop)
    one_line(capsys, main(["models", "--output", str(loop)]), "--output")


def test_output_through_devices_stays_a_device(capsys):
    assert main(["models", "--model", "ho", "--output", os.devnull]) == 0
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
    capsys.readouterr()
    one_line(capsys, main(["models", "--output", "/dev/full"]), "/dev/full", "no space left")
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


def test_output_through_a_fifo_is_a_stream(tmp_path, capsys):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(Path(fifo).read_text()))
    reader.start()
    assert main(["models", "--model", "ho", "--output", str(fifo)]) == 0
    reader.join(60)
    assert received and received[0].startswith("ho ") and stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_dev_stdout_is_written_through_as_a_subprocess(tmp_path):
    done = subprocess.run([sys.executable, "-m", "nambu_bch", "models", "--model", "ho", "--output", "/dev/stdout"],
                          env=ENV, capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0 and done.stdout.startswith("ho ") and "Traceback" not in done.stderr


# =============================================================================================
# item 8: bounded work, refused up front from a size estimate
# =============================================================================================
def test_bounded_work_cli(capsys, tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("coordinates = " + "[" * 30000 + "]" * 30000 + "\n")
    fourteen = ["--H", "x1^2/2 + x2^2/2"] + sum((["--G", f"x{k}^2/2 + x{k + 1}^2/2"] for k in range(2, 14)), [])
    cases = [
        (["bch", "--model", "ho", "--integrator", "yoshida:yoshida:121"], "nested jumps"),
        (["models", "--H", "(x1+x2+1)**1000"], "501501 terms"),  # binomial(1002, 2)
        (["models", *fourteen], "at most 7"),
        (["models", "--H", "x2^2/2 + 99999999^500*x1^2"], "bits"),
        (["models", "--system", "/dev/zero"], "not a regular file"),
        (["models", "--system", str(deep)], "nested too deeply"),
        (["shadow", "--model", "ho", "--integrator", "1" * 300], "at most 200"),
        (["check", "--steps", "1" + "0" * 30], "--steps"),
        (["models", "--coords", " ".join(f"x{i}" for i in range(1, 12)), "--H", "x1"], "at most 8"),
    ]
    for argv, fragment in cases:
        one_line(capsys, main(argv), fragment)


def test_bounded_work_api():
    with pytest.raises(ResourceLimitError, match="unknowns"):
        nb.shadow_hamiltonians(nb.model("ho3"), "12321", degree=10**6)
    with pytest.raises(ResourceLimitError, match="unknowns"):
        nb.direct_route(nb.model("rigid-body"), "12321", 2, degree=40)
    with pytest.raises(InvalidSystemError, match="at most 8"):
        nb.System(" ".join(f"x{i}" for i in range(1, 14)), [f"x{i}**2/2 + x{i + 1}**2/2" for i in range(1, 13)])
    with pytest.raises(InvalidCompositionError, match="factors"):
        composition("1" * 201 + "2")


SIN8 = "sin(sin(sin(sin(sin(sin(sin(sin(x1))))))))"


@pytest.mark.parametrize("argv, fragment", [
    (["models", "--H", "x2^2/2+x1^2*cos(exp(exp(exp(2.5))))"], "exp(exp(exp(5/2))) may be as large as 2^2.82e+05"),
    (["check", "--H", "x2^2/2+x1^2*cos(exp(exp(exp(2.5))))"], "2^1400"),
    (["shadow", "--H", "x2^2/2 + x1*exp(exp(10))"], "exp(exp(10))"),
    (["shadow", "--H", f"{SIN8}+x2^2/2", "--order", "4"], "differentiates sin(sin(sin(sin(sin(sin(sin(sin(x1)))))))) up to 5"),
    (["shadow", "--H", "x2^2/2 + sin(sin(sin(sin(x1))))", "--order", "8"], "at most 4000 are accepted"),
])
def test_towers_and_nests_refused_up_front_cli(capsys, argv, fragment):
    """Constant towers (the parser's tree bound) and deep nests at high order (the derivative estimate): one line."""
    one_line(capsys, main(argv), fragment)


def test_nest_refused_before_any_bracket_is_computed(monkeypatch):
    """The estimate comes first: neither the BCH series nor backward error analysis is touched."""
    import nambu_bch.shadow.generic as generic

    def touched(*args, **kwargs):
        raise AssertionError("work started before the estimate refused the request")

    monkeypatch.setattr(generic, "formal_bch", touched)
    monkeypatch.setattr(generic, "effective_field", touched)
    system = nb.System("x1 x2", [f"x2**2/2 + {SIN8}"])
    with pytest.raises(ResourceLimitError, match="at most 4000"):
        nb.shadow_hamiltonians(system, "121", order=4)
    with pytest.raises(ResourceLimitError):
        generic.bch_shadow(system, "121", order=4)


def test_derivative_estimate_counts_faa_di_bruno_terms():
    """The derivative estimate bounds the number of terms sympy produces where that is cheap to count; the
    work estimate keeps what finishes in about a minute (sin^8 at h^2, sin^2 at h^8, the pendulum at h^6)."""
    from nambu_bch.shadow.generic import MAX_BCH_WORK, bch_work, check_work, derivative_terms

    x1, x2 = sympy.symbols("x1 x2")
    for expr, k in ((sympy.sin(sympy.sin(x1)), 4), (sympy.exp(x1**2), 3), (sympy.cos(x1) * sympy.exp(x1), 3)):
        counted = len(sympy.Add.make_args(sympy.expand(sympy.diff(expr, x1, k))))
        assert derivative_terms(expr, [x1], k) >= counted
    nest = x1
    for _ in range(8):
        nest = sympy.sin(nest)
    assert [derivative_terms(nest, [x1], k) for k in (3, 5)] == [36, 1128]
    # sum over bracket lengths j of (Lyndon words of length j over 2 letters) x (terms of the j-th derivative)
    assert bch_work(nb.System("x1 x2", [x2**2 / 2 + nest]), 2, [x2**2 / 2, nest], 2) == (2 * 1 + 1 * 8 + 2 * 36, nest)
    assert check_work(nb.System("x1 x2", [x2**2 / 2 + nest]), 2, [nest], 2) == 82 <= MAX_BCH_WORK
    assert check_work(nb.model("pendulum"), 2, [x2**2 / 2, -sympy.cos(x1)], 6) == 2 + 1 + 2 + 3 + 6 + 9 + 18
    sin2 = sympy.sin(sympy.sin(x1))
    assert check_work(nb.System("x1 x2", [x2**2 / 2 + sin2]), 2, [sin2], 8) == 2776 <= MAX_BCH_WORK
    assert check_work(nb.model("ho3"), 3, nb.model("ho3").hamiltonians, 8) == 0  # polynomial: not estimated


def test_expansion_estimate_two_ways():
    """The parser's size estimate equals sympy's own count where expansion is cheap (exact for sums of distinct
    letters: binomial(n + t - 1, t - 1) monomials), and bounds it otherwise."""
    from nambu_bch.parsing import expansion_size

    x1, x2, x3 = sympy.symbols("x1 x2 x3")
    for expr in ((x1 + x2 + 1) ** 7, (x1 + x2 + x3) ** 5, (x1 + 1) ** 3 * (x2 + 2) ** 2):
        terms, degree = expansion_size(expr)
        expanded = sympy.Poly(sympy.expand(expr), x1, x2, x3)
        assert terms == len(expanded.terms()) and degree == expanded.total_degree()
    assert expansion_size((x1 + x2 + 1) ** 1000) == (math.comb(1002, 2), 1000)


# =============================================================================================
# item 10: Ctrl-C and a closed stdout
# =============================================================================================
def test_keyboard_interrupt_in_main_is_one_line(monkeypatch, capsys):
    import nambu_bch.cli.models as models

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(models, "run", interrupted)
    assert main(["models"]) == 130
    err = capsys.readouterr().err
    assert err.strip() == "nambu-bch models: interrupted"


def test_interrupt_during_import_is_one_line():
    """SIGINT delivered while the command line imports sympy (deterministic: an import hook sends it)."""
    code = TERMINAL_SIGINT + textwrap.dedent("""
        import os, signal, sys
        sys.argv[0] = "nambu-bch"                      # as the console script
        class Hook:
            def find_spec(self, name, path=None, target=None):
                if name == "sympy":
                    os.kill(os.getpid(), signal.SIGINT)
                return None
        sys.meta_path.insert(0, Hook())
        from nambu_bch.cli import main
        sys.exit(main(["shadow", "--format", "text"]))   # needs sympy (models may answer from its cache)
    """)
    done = subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True, text=True, timeout=600)
    assert done.returncode == 130, done.stderr
    # with the lazy package sympy is imported inside main(), whose handler names the subcommand
    assert done.stderr == "nambu-bch shadow: interrupted\n" and done.stdout == ""


def test_library_import_keeps_pythons_sigint_handler():
    code = TERMINAL_SIGINT + "import nambu_bch; print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)"
    done = subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True, text=True, timeout=600)
    assert done.stdout.strip() == "True", done.stderr


def test_sigint_while_computing_is_one_line():
    """SIGINT delivered while ``nambu-bch shadow --model rigid-body --order 8`` computes (the child says on stdout
    when the computation starts, so the signal is sent then instead of after a fixed sleep)."""
    code = TERMINAL_SIGINT + textwrap.dedent("""
        import sys
        import nambu_bch.shadow as shadow
        sys.argv[0] = "nambu-bch"                      # as the console script
        real = shadow.shadow_hamiltonians
        def marked(*args, **kwargs):                   # the subcommand looks it up at call time
            print("computing", flush=True)
            return real(*args, **kwargs)
        shadow.shadow_hamiltonians = marked
        from nambu_bch.cli import main
        sys.exit(main(["shadow", "--model", "rigid-body", "--order", "8"]))
    """)
    proc = subprocess.Popen([sys.executable, "-c", code], env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline() == "computing\n"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=600)
    finally:
        proc.kill()
    assert proc.returncode == 130 and len(err.strip().splitlines()) == 1 and "interrupted" in err, err


def test_closed_stdout_pipe_is_quiet():
    """``nambu-bch bch --order 8 --format text | head -c1``: the reader leaves after one byte of 145 kB."""
    proc = subprocess.Popen([sys.executable, "-m", "nambu_bch", "bch", "--order", "8", "--format", "text"],
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    first = os.read(proc.stdout.fileno(), 1)
    proc.stdout.close()
    err = proc.stderr.read()
    proc.stderr.close()
    assert proc.wait(timeout=600) == 141 and first == b"s" and err == b"", err  # the text starts "system ho3: ..."


def test_stdout_closed_from_the_start_is_quiet():
    done = subprocess.run([sys.executable, "-c", "import os, sys; os.close(1); sys.stdout = None; "
                           "from nambu_bch.cli import main; sys.exit(main(['models']))"],
                          env=ENV, capture_output=False, stderr=subprocess.PIPE, text=True, timeout=600)
    assert done.returncode == 141 and done.stderr == "", done.stderr


# =============================================================================================
# done when: the API raises only the package's exception family on misuse
# =============================================================================================
S3 = nb.model("ho3")
API_MISUSE = {
    "composition float piece": lambda: nb.composition([(1.5, 1)]),
    "composition coefficient None": lambda: nb.composition([(1, None)]),
    "composition n_pieces str": lambda: nb.composition("strang", "3"),
    "composition huge piece": lambda: nb.composition([(10**30, 1)]),
    "composition nested jump": lambda: nb.composition("yoshida:yoshida:121"),
    "composition bytes": lambda: nb.composition(b"121"),
    "model list": lambda: nb.model([]),
    "model None": lambda: nb.model(None),
    "System coordinates int": lambda: nb.System(3, ["x1"]),
    "System parameters int": lambda: nb.System("x1 x2", ["x1*x2"], parameters=5),
    "System name int": lambda: nb.System("x1 x2", ["x1*x2"], name=3),
    "System name latex": lambda: nb.System("x1 x2", ["x1*x2"], name="\\input{/etc/passwd}"),
    "System hamiltonians int": lambda: nb.System("x1 x2", 5),
    "System hamiltonian set": lambda: nb.System("x1 x2", [{1}]),
    "System 13 coordinates": lambda: nb.System(" ".join(f"x{i}" for i in range(1, 14)), ["x1"] * 12),
    "effective_field splitting str": lambda: effective_field("ho3", "12321", 2),
    "effective_field splitting None": lambda: effective_field(None, "12321", 2),
    "effective_field_bch splitting None": lambda: effective_field_bch(None, "12321", 2),
    "formal_bch degree str": lambda: formal_bch("12321", "3"),
    "formal_bch degree huge": lambda: formal_bch("12321", 10**6),
    "shadow degree huge": lambda: nb.shadow_hamiltonians(S3, "12321", degree=10**6),
    "shadow degree float": lambda: nb.shadow_hamiltonians(S3, "12321", degree=2.5),
    "shadow order float": lambda: nb.shadow_hamiltonians(S3, "12321", order=2.5),
    "shadow order bool": lambda: nb.shadow_hamiltonians(S3, "12321", order=True),
    "shadow system None": lambda: nb.shadow_hamiltonians(None, "12321"),
    "conserved system None": lambda: nb.conserved_quantities(None, "12321"),
    "conserved degree huge": lambda: nb.conserved_quantities(S3, "12321", degree=10**6),
    "exact system None": lambda: nb.exact_shadow_hamiltonians(None, "12321"),
    "exact system 3": lambda: nb.exact_shadow_hamiltonians(3, "12321"),
    "fi_route system None": lambda: nb.fi_route(None, "12321"),
    "direct_route system None": lambda: nb.direct_route(None, "12321"),
    "composed_map splitting None": lambda: nb.composed_map(None, "121"),
    "step_function splitting None": lambda: nb.step_function(None, "121"),
    "F huge int": lambda: nb.F(10**400),
    "F string": lambda: nb.F("x"),
    "parse symbols int": lambda: parse_expression("x", 5),
    "parse symbols str": lambda: parse_expression("x", "x"),
    "parse huge power": lambda: parse_expression("99999999^500", []),
    "parse expansion": lambda: parse_expression("(x1+x2+1)**1000", sympy.symbols("x1 x2")),
    "load_system directory": lambda: load_system("/"),
    "load_system device": lambda: load_system("/dev/zero"),
    "write_output directory": lambda: write_output("/", "x"),
    "write_output NUL": lambda: write_output("a\x00b", "x"),
    "iterate steps bool": lambda: nb.iterate(S3, "32123", h=0.1, steps=True, x0=(1, 1, 1)),
    "check every 0": lambda: nb.check(S3, "32123", 0.1, 10, (1, 1, 1), every=0),
}


@pytest.mark.parametrize("call", list(API_MISUSE))
def test_api_misuse_raises_the_package_family(call):
    """Each of these raised TypeError, AttributeError, OverflowError, ValueError or hung before."""
    with pytest.raises(NambuBCHError) as info:
        API_MISUSE[call]()
    message = str(info.value)
    assert "\n" not in message and 0 < len(message) < 600, message


def test_unknown_piece_error_names_the_piece():
    with pytest.raises(UnknownPieceError, match=r"piece\(s\) \[3\]"):
        composition_for("12321", nb.model("ho"))


# =============================================================================================
# done when: the whole CLI, every subcommand and every option that takes text, hostile values
# =============================================================================================
def _hostile(marker):
    return [
        f"__import__('os').system('touch {marker}')",
        f"open('{marker}', 'w').write('x')",
        f"x1 # open('{marker}','w')",
        f"$(touch {marker})",
        f"`touch {marker}`",
        f"; touch {marker}",
        r"\input{/etc/passwd}",
        "1e999999",
        "99999999^500",
        "9" * 5000,
        "nan",
        "inf",
        "-inf",
        "",
        "ｘ１",
        "\U0001F4A5",
        "x1\nx2",
        "a" * 10000,
        "\x00",
    ]


# option -> (argv prefix the option is added to, subcommands having it); values must all be refused
TEXT_OPTIONS = {
    "--model": ([], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--system": ([], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--H": ([], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--G": (["--H", "x2^2/2 + x3/2"], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--coords": (["--H", "x2^2/2 + x1^2/2"], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--param": ([], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--name": (["--H", "x2^2/2 + x1^2/2"], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--split": ([], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--format": ([], ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--integrator": ([], ("bch", "fi", "shadow", "conserved", "exact", "check", "plot")),
    "--order": ([], ("bch", "shadow", "exact", "check")),
    "--route": ([], ("shadow",)),
    "--degree": ([], ("shadow", "conserved")),
    "--h": ([], ("check", "plot")),
    "--steps": ([], ("check", "plot")),
    "--x0": ([], ("check", "plot")),
    "--every": ([], ("check", "plot")),
    "--alpha": ([], ("check",)),
    "--short-steps": ([], ("plot",)),
    "--dpi": ([], ("plot",)),
    "--fig-format": ([], ("plot",)),
}
CLI_CASES = [(sub, opt) for opt, (_, subs) in TEXT_OPTIONS.items() for sub in subs]


@pytest.mark.parametrize("sub,option", CLI_CASES, ids=[f"{s}{o}" for s, o in CLI_CASES])
def test_hostile_text_every_subcommand_and_option(sub, option, tmp_path, capsys, monkeypatch):
    """Exit 2, one stderr line, no traceback, nothing on stdout, and nothing executed (no marker file)."""
    monkeypatch.chdir(tmp_path)
    marker = tmp_path / "MARKER"
    prefix, _ = TEXT_OPTIONS[option]
    outdir = ["--outdir", str(tmp_path / "figs")] if sub == "plot" else []
    for value in _hostile(marker):
        if option == "--name" and USER_NAME.match(value):
            continue  # 'nan', 'inf' are valid names: accepted, and safe
        if option == "--coords" and value == "x1\nx2":
            continue  # whitespace-separated coordinates x1, x2: a valid system
        if option == "--param" and value and "=" not in value:
            value = "m=" + value  # a value for a declared parameter (a bare name is a declaration)
        argv = [sub, *prefix, option, value, *outdir]
        code = main(argv)
        captured = capsys.readouterr()
        lines = captured.err.strip().splitlines()
        assert code == 2, (argv, captured.err[-500:])
        assert len(lines) == 1 and "Traceback" not in captured.err, (argv, captured.err[-2000:])
        assert len(lines[0]) < 800, (argv, len(lines[0]))
        assert captured.out == "", argv
    assert not marker.exists() and not Path("/tmp/MARKER").exists()
    assert not (tmp_path / "figs").exists() or not list((tmp_path / "figs").iterdir())


@pytest.mark.parametrize("option", ["--output", "--outdir", "--system"])
@pytest.mark.parametrize("value", ["", "   ", "a\x00b", "x" * 5000, "/nonexistent-dir-i10in/sub/file"])
def test_hostile_paths(option, value, tmp_path, capsys, monkeypatch):
    """Path options: empty, NUL, over-long or unreachable paths are one line and exit 2."""
    monkeypatch.chdir(tmp_path)
    sub = "plot" if option == "--outdir" else "models"
    if option == "--outdir" and value.startswith("/nonexistent"):
        value = "/proc/version/sub"  # an existing file as a parent: the directory cannot be created
    code = main([sub, option, value])
    line = one_line(capsys, code, option)
    assert len(line) < 800


@pytest.mark.parametrize("flag", ["--steps", "--every", "--dpi", "--short-steps"])
@pytest.mark.parametrize("value", ["\uff13", "\u0663", "1e3", "0x10", "1.0", "+-1"])
def test_integer_flags_take_ascii_digits_only(flag, value, tmp_path, capsys):
    """int() reads '３' (fullwidth) and '٣' (Arabic-Indic) as 3: refused, not silently coerced (item 4)."""
    one_line(capsys, main(["plot", flag, value, "--outdir", str(tmp_path)]), flag)


def test_empty_system_flags_are_not_ignored(capsys):
    """--H '' and --x0 '' used to fall back to the default model / state silently."""
    one_line(capsys, main(["models", "--H", ""]), "--H")
    one_line(capsys, main(["check", "--x0", ""]), "--x0")
