"""The ``nambu-bch`` command line.

Every subcommand and flag runs at least once, checking exit codes and that JSON
output reads back with ``sympy.sympify`` using the model's symbol names.  The
runs go through ``main(argv)`` in process (stdout and stderr captured): a
subprocess adds nothing to them but the interpreter start and the imports.  One
subprocess per subcommand (``python -m nambu_bch``; the fast tier runs
``models``, the deep tier the others: tests/conftest.py ``DEEP``) and the console script
keep the entry points honest.  Bad input:
one line on stderr, exit code 2, no traceback, including an injection attempt
that must not create a file.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path


import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from nambu_bch.cli import main

REPO = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(REPO)}
x1, x2, x3, m, omega, h, alpha = sympy.symbols("x1 x2 x3 m omega h alpha")


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------
def subprocess_cli(*args, cwd=REPO, executable=None):
    """``python -m nambu_bch ARGS`` (or the console script ``executable``) as a subprocess."""
    command = [executable] if executable else [sys.executable, "-m", "nambu_bch"]
    return subprocess.run([*command, *map(str, args)], cwd=cwd, env=ENV, capture_output=True, text=True, timeout=600)


def cli(*args):
    """``main(ARGS)`` in process, as a ``CompletedProcess`` (exit status, captured stdout and stderr)."""
    out, err = io.StringIO(), io.StringIO()
    argv = [str(a) for a in args]
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return subprocess.CompletedProcess(argv, code, out.getvalue(), err.getvalue())


def cli_many(*argvs):
    """Several CLI invocations in process, one after the other."""
    return [cli(*argv) for argv in argvs]


# one run of every subcommand through the interpreter's entry point (python -m nambu_bch)
SMOKE = (
    ("models", "--model", "ho"),
    ("bch", "--model", "ho", "--integrator", "TVT", "--format", "text"),
    ("fi", "--format", "text"),
    ("shadow", "--model", "ho", "--integrator", "TVT", "--format", "json"),
    ("conserved", "--model", "ho", "--integrator", "TVT", "--format", "text"),
    ("exact", "--model", "ho", "--integrator", "TVT", "--format", "text"),
    ("check", "--model", "ho", "--steps", "10", "--format", "json"),
    ("plot", "--help"),
    ("compare", "--model", "ho", "--integrator", "TVT", "--integrator", "VTV", "--step-counts", "10,20", "--t-end", "1"),
    ("sample", "--model", "ho", "--integrator", "TVT", "--chains", "20", "--iterations", "3", "--seed", "1"),
)


@pytest.mark.parametrize("argv", SMOKE, ids=[argv[0] for argv in SMOKE])
def test_every_subcommand_runs_as_a_subprocess(argv):
    """``python -m nambu_bch SUBCOMMAND ...``: exit 0, output on stdout, no traceback; the symbolic output is byte for
    byte the in-process one (numeric reports carry timings, help text the terminal width)."""
    done = subprocess_cli(*argv)
    assert done.returncode == 0 and "Traceback" not in done.stderr, (argv, done.stderr[-2000:])
    assert done.stdout.strip(), argv
    if argv[0] in ("models", "bch", "fi", "shadow", "conserved", "exact"):
        assert done.stdout == cli(*argv).stdout, argv


def ok(done):
    assert done.returncode == 0, f"exit {done.returncode}\nstdout: {done.stdout[-2000:]}\nstderr: {done.stderr[-3000:]}"
    assert "Traceback" not in done.stderr
    return done.stdout


def bad(done, *fragments):
    """Exit code 2, exactly one line on stderr naming the input, no traceback."""
    assert done.returncode == 2, f"exit {done.returncode}\nstdout: {done.stdout}\nstderr: {done.stderr}"
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "Traceback" not in done.stderr
    for f in fragments:
        assert f.lower() in lines[0].lower(), lines[0]
    return lines[0]


def symbols_of(data):
    names = list(data.get("coordinates", [])) + list(data.get("parameters", [])) + ["h", "alpha"]
    return {n: sympy.Symbol(n) for n in names}


def read(data, key):
    """``data[key]`` read back with sympy using the result's own symbol names."""
    value = data[key]
    return None if value is None else sympy.sympify(value, locals=symbols_of(data))


def read_json(text, *keys):
    data = json.loads(text)
    for key in keys:
        if data.get(key) is not None:
            expr = read(data, key)
            assert expr.free_symbols <= set(symbols_of(data).values()), (key, expr)
    return data


# --------------------------------------------------------------------------------------------
# help, version, models, bch (subprocesses)
# --------------------------------------------------------------------------------------------
SUBCOMMANDS = ("models", "bch", "fi", "shadow", "conserved", "exact", "check", "plot")


def test_help_version_and_console_script(tmp_path):
    runs = cli_many(("--help",), ("--version",), ())
    top = ok(runs[0])
    for name in SUBCOMMANDS:
        assert name in top
    assert ok(runs[1]).startswith("nambu-bch ")
    bad(runs[2], "subcommand")
    script = Path(sys.executable).with_name("nambu-bch")
    if script.exists():  # the console script of pyproject's [project.scripts]
        assert "shadow" in ok(subprocess_cli("--help", executable=str(script), cwd=tmp_path))


def test_help_of_every_subcommand_has_an_example(capsys):
    for name in SUBCOMMANDS:
        assert main([name, "--help"]) == 0
        out = capsys.readouterr().out
        assert "example" in out and f"nambu-bch {name}" in out, name


def test_models(tmp_path):
    toml = tmp_path / "osc.toml"
    toml.write_text('coordinates = "x1 x2"\nH = "x2^2/(2*m) + k*x1^4/4"\n[parameters]\nm = 1\nk = "1/2"\n')
    out = tmp_path / "models.json"
    runs = cli_many(
        ("models",),
        ("models", "--format", "json", "--output", out),
        ("models", "--model", "ho3", "--format", "latex"),
        ("models", "--system", toml, "--format", "json"),
    )
    text = ok(runs[0])
    for name in ("ho", "ho3", "rigid-body", "lotka-volterra", "ho3-composite"):
        assert name in text
    assert "piece 3: moves x3" in text
    ok(runs[1])
    assert runs[1].stdout == "" and "wrote" in runs[1].stderr
    data = json.loads(out.read_text())
    assert [d["model"] for d in data["models"]][:5] == ["ho", "ho3", "rigid-body", "lotka-volterra", "ho3-composite"]
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".tmp")]  # atomic write left no temp file
    ho3 = data["models"][1]
    assert read(ho3, "G") == x3 - x1**2
    assert [sympy.sympify(c, locals=symbols_of(ho3)) for c in ho3["pieces"][2]["field"]] == [0, 0, 2 * x1 * x2 / m]
    latex = ok(runs[2])
    assert r"\frac{x_{2}^{2}}{2 m}" in latex and "rigid" not in latex
    user = json.loads(ok(runs[3]))["models"][0]
    assert user["model"] == "osc" and user["parameters"] == ["m", "k"]  # file values feed check/plot only
    assert read(user, "H") == x2**2 / (2 * m) + sympy.Symbol("k") * x1**4 / 4


def test_bch(tmp_path):
    tex = tmp_path / "bch.tex"
    runs = cli_many(
        ("bch", "--format", "json"),
        ("bch", "--model", "ho", "--integrator", "TVT", "--order", "2", "--field", "--terms", "--format", "text"),
        ("bch", "--H", "x2^2/(2*m) + m*x3/2", "--G", "x3 - x1^2", "--coords", "x1,x2,x3", "--param", "m",
         "--integrator", "123", "--order", "1", "--field", "--output", tex),
        ("bch", "--model", "ho3", "--integrator", "1:1/2,2:1,3:1,1:1/2", "--format", "json", "--field", "--param", "m=2"),
    )
    data = read_json(ok(runs[0]))
    assert data["integrator"] == "12321" and data["max_degree"] == 3
    third = [(sympy.Rational(t["coefficient"]), t["bracket"]) for t in data["terms"] if t["degree"] == 3]
    assert len(third) == 8 and (sympy.Rational(1, 6), "[[X1,X3],X2]") in third  # Eq. (BCH2), Lyndon basis
    text = ok(runs[1])
    assert "-1/24  [X1,[X1,X2]]" in text and "1/12  [[X1,X2],X2]" in text  # Eq. (BCH1)
    assert "Z_2 = (-omega**2*x2/(12*m), -m*omega**4*x1/6)" in text  # Eq. (SHPV1)
    assert "Liouville terms" in text
    ok(runs[2])
    latex = tex.read_text()
    assert r"\frac{h}{2}" in latex or r"\frac{1}{2}" in latex
    data = read_json(ok(runs[3]))
    assert data["model"] == "ho3[m=2]" and data["parameters"] == ["omega"]
    Z0 = [sympy.sympify(c, locals=symbols_of(data)) for c in data["X_eff"][0]]
    assert Z0 == [x2 / 2, -2 * omega**2 * x1, x1 * x2]


# --------------------------------------------------------------------------------------------
# conserved, exact
# --------------------------------------------------------------------------------------------
def test_conserved_and_exact(tmp_path):
    toml = tmp_path / "ho3.toml"
    toml.write_text(
        'name = "my-ho3"\ncoordinates = ["x1", "x2", "x3"]\nH = "x2^2/(2*m) + m*omega^2*x3/2"\nG = "x3 - x1^2"\n'
        'parameters = ["m", "omega"]\nsplit = "full"\n'
    )
    runs = cli_many(
        ("conserved", "--integrator", "31213", "--format", "json"),
        ("conserved", "--system", toml, "--integrator", "32123", "--degree", "2"),
        ("exact", "--format", "json", "--order", "2"),
        ("exact", "--model", "ho", "--integrator", "TVT", "--format", "text"),
        ("exact", "--model", "lotka-volterra"),
    )
    data = read_json(ok(runs[0]), "H_c", "G_c")  # Table (table), row 31213
    assert sympy.expand(read(data, "H_c") - (read(data, "H") - omega**2 / (4 * m) * h**2 * x2**2)) == 0
    assert sympy.expand(read(data, "G_c") - (read(data, "G") - h**2 * x2**2 / (4 * m**2))) == 0
    latex = ok(runs[1])  # Table (table), row 32123
    assert r"G_{c} &= G + \frac{h^{2} \omega^{2} x_{1}^{2}}{2}" in latex  # printed as the paper's row: G_c = G + ...
    data = read_json(ok(runs[2]), "H_S", "G_S", "H_c", "G_c", "H_S_series", "G_S_series")
    ESH = read(data, "H") + alpha * omega**2 / (12 * m) * h**2 * x2**2 + alpha * m * omega**4 / 12 * h**2 * x3  # Eq. (ESH12321)
    ESG = read(data, "G") + h**2 * x2**2 / (4 * m**2) + (1 - alpha) * omega**2 / 6 * h**2 * (x3 - x1**2)  # Eq. (ESG12321)
    assert sympy.expand(read(data, "H_S_series") - ESH) == 0 and sympy.expand(read(data, "G_S_series") - ESG) == 0
    assert data["free_parameters"] == ["alpha"]
    assert "asin" in ok(runs[3])
    bad(runs[4], "lotka-volterra")


# --------------------------------------------------------------------------------------------
# shadow, fi
# --------------------------------------------------------------------------------------------
def test_shadow(tmp_path):
    out = tmp_path / "family.json"
    runs = cli_many(
        ("shadow",),
        ("shadow", "--format", "json", "--output", out),
        ("shadow", "--integrator", "32123", "--route", "fi", "--format", "json"),
        ("shadow", "--model", "ho", "--integrator", "TVT", "--order", "4", "--format", "json"),
        ("shadow", "--H", "x2^2/(2*m) + m*x3/2", "--G", "x3 - x1^2", "--param", "m", "--split", "full",
         "--name", "mine", "--degree", "2", "--format", "text"),
        ("shadow", "--integrator", "123", "--format", "json"),
    )
    latex = ok(runs[0])  # the default: Eqs. (SH12321c), (SG12321c) as LaTeX
    assert latex.startswith("\\begin{align*}\n&\\text{system ho3: nambu bracket on}\\ (x_{1}, x_{2}, x_{3})")  # what was analysed
    assert "\\begin{align*}\nH_{S} &= H + h^{2}" in latex and r"\alpha" in latex and "G_{S} &= G + " in latex
    ok(runs[1])
    data = read_json(out.read_text(), "H", "G", "H_S", "G_S")
    assert data["model"] == "ho3" and data["integrator"] == "12321" and data["order"] == 2 and data["exists"] is True
    assert data["coordinates"] == ["x1", "x2", "x3"] and data["free_parameters"] == ["alpha"]
    SH = read(data, "H") + alpha * omega**2 / (12 * m) * h**2 * x2**2 + alpha * m * omega**4 / 12 * h**2 * x1**2
    SG = (read(data, "G") + h**2 * x2**2 / (12 * m**2) + alpha / (6 * m**2) * h**2 * x2**2
          - (1 - alpha) * omega**2 / 6 * h**2 * x1**2)
    assert sympy.expand(read(data, "H_S") - SH) == 0 and sympy.expand(read(data, "G_S") - SG) == 0
    data = read_json(ok(runs[2]), "H_S", "G_S")
    assert data["integrator"] == "32123" and data["route"] == "fi" and data["exists"] is True
    from nambu_bch import model
    from nambu_bch.testing import assert_shadow_pair

    assert_shadow_pair(model("ho3"), "32123", read(data, "H_S"), read(data, "G_S"), order=2)
    data = read_json(ok(runs[3]), "H_S")
    assert data["G_S"] is None and data["G"] is None and data["order"] == 4
    assert_shadow_pair(model("ho"), "TVT", read(data, "H_S"), order=4)
    text = ok(runs[4])
    assert text.startswith("system mine: nambu bracket on x1, x2, x3 (parameters m)\n12321 on mine, order 2, route direct")
    assert "H_S = " in text
    data = read_json(ok(runs[5]))  # non-symmetric word: no polynomial shadow pair at h^1
    assert data["exists"] is False and data["H_S"] is None and "h^1" in data["obstruction"]


# Eqs. (1AX)-(2BY), transcribed from the paper's LaTeX source ({} are Nambu brackets).
PAPER_FI = {
    "1AX": "+{{E,C,D},A,B},F +{E,C,D},{F,A,B} +{E,A,B},{F,C,D} +E,{{F,C,D},A,B}",
    "1AY": "+{{E,C,D},A,B},F +{E,C,D},{F,A,B} -{A,E,{F,C,D}},B -A,{B,E,{F,C,D}}",
    "1BX": "-{A,{E,C,D},F},B -A,{B,{E,C,D},F} +{E,A,B},{F,C,D} +E,{{F,C,D},A,B}",
    "1BY": "-{A,{E,C,D},F},B -A,{B,{E,C,D},F} -{A,E,{F,C,D}},B -A,{B,E,{F,C,D}}",
    "2AX": "-{{C,E,F},A,B},D -{C,E,F},{D,A,B} -{C,A,B},{D,E,F} -C,{{D,E,F},A,B}",
    "2AY": "-{{C,E,F},A,B},D -{C,E,F},{D,A,B} +{A,C,{D,E,F}},B +A,{B,C,{D,E,F}}",
    "2BX": "+{A,{C,E,F},D},B +A,{B,{C,E,F},D} -{C,A,B},{D,E,F} -C,{{D,E,F},A,B}",
    "2BY": "+{A,{C,E,F},D},B +A,{B,{C,E,F},D} +{A,C,{D,E,F}},B +A,{B,C,{D,E,F}}",
}


def test_fi_forms_match_the_paper():
    from nambu_bch.shadow.fundamental_identity import formal_form as fi_form

    for label, text in PAPER_FI.items():
        got = " ".join(("+" if sign > 0 else "-") + ",".join(slots) for sign, slots in fi_form(label))
        assert got == text, label


def test_fi():
    runs = cli_many(("fi",), ("fi", "--model", "ho3", "--integrator", "12321", "--format", "json"), ("fi", "--format", "text"))
    latex = ok(runs[0])
    for label in PAPER_FI:
        assert rf"\overset{{\rm {label}}}" in latex
    assert "ho3" not in latex  # no system chosen: the generic forms only
    data = json.loads(ok(runs[1]))
    assert data["model"] == "ho3" and [f["label"] for f in data["forms"]] == list(PAPER_FI)
    assert len(data["representations"]) == 4  # Eq. (BCH4): the non-vanishing h^2 terms
    names = symbols_of(data)
    B = m * omega**2 * x3 / 2
    rep = next(r for r in data["representations"] if r["coefficient"] == "-1/24")  # [X_AC,[X_AC,X_BD]]
    (term,) = rep["forms"]["1AX"]  # Eq. (CL5), first form: X_{B, -2 x2^2/m^2}
    assert sympy.sympify(term["coefficient"]) == sympy.Rational(-1, 24)
    assert [sympy.sympify(s, locals=names) for s in term["slots"]] == [B, -2 * x2**2 / m**2]
    (term,) = rep["forms"]["2BX"]  # Eq. (CL5), second form: X_{omega^2 x2^2/m, C}
    assert [sympy.sympify(s, locals=names) for s in term["slots"]] == [omega**2 * x2**2 / m, x3]
    assert "2BY: [X_{A,B},[X_{C,D},X_{E,F}]] = X_{{A,{C,E,F},D},B}" in ok(runs[2])


# --------------------------------------------------------------------------------------------
# check, plot
# --------------------------------------------------------------------------------------------
def test_check(tmp_path):
    runs = cli_many(
        ("check", "--integrator", "32123", "--h", "0.1", "--steps", "2000", "--x0", "1,1,1",
         "--param", "m=1", "--param", "omega=1", "--every", "10", "--format", "json"),
        ("check", "--model", "rigid-body", "--param", "I1=1", "--param", "I2=2", "--param", "I3=3", "--steps", "500",
         "--x0", "1 0.5 0.2", "--order", "2", "--alpha", "1/3", "--format", "text", "--output", tmp_path / "rb.txt"),
    )
    data = json.loads(ok(runs[0]))
    assert data["h"] == 0.1 and data["steps"] == 2000 and data["every"] == 10
    errors = data["max_abs_error"]
    for key in ("H", "G", "H_c", "G_c"):
        assert isinstance(errors[key], (int, float)), key
    assert errors["H_c"] < 1e-10 and errors["G_c"] < 1e-10 and errors["H"] > 1e-5  # Figs. 1-2
    assert errors["H_S"] < errors["H"] / 100 and errors["x3_s"] < 1e-10 < errors["x3_c"]  # Figs. 3-4
    ok(runs[1])
    assert "rigid-body 12321: h = 0.1, 500 steps" in (tmp_path / "rb.txt").read_text()


def test_plot(tmp_path):
    done = cli("plot", "--model", "ho3", "--integrator", "32123", "--outdir", tmp_path / "figs", "--steps", "2000",
               "--short-steps", "200", "--h", "0.1", "--x0", "1,1,1", "--every", "10", "--param", "m=1", "--dpi", "40",
               "--fig-format", "png", "--format", "json", "--output", tmp_path / "plot.json")
    ok(done)
    data = json.loads((tmp_path / "plot.json").read_text())
    assert len(data["files"]) == 4
    for f in data["files"]:
        assert Path(f).exists() and Path(f).read_bytes()[:4] == b"\x89PNG"


# --------------------------------------------------------------------------------------------
# bad input: a few subprocesses (incl. injection) and every flag in-process
# --------------------------------------------------------------------------------------------
def test_bad_input_as_subprocess(tmp_path):
    """Bad input through the interpreter's entry point (one subprocess: the injection attempt, exit 2, one line, no
    file created), and the same kind of runs in process (a missing system file, an unknown flag)."""
    target = tmp_path / "pwned"
    injection = subprocess_cli("conserved", "--H", f"__import__('os').system('touch {target}')", "--coords", "x1 x2")
    bad(injection, "--H", "not accepted")
    assert not target.exists() and not Path("/tmp/pwned").exists()
    bad(cli("models", "--system", tmp_path / "missing.toml"), "--system", "missing.toml")
    bad(cli("bch", "--frobnicate"), "--frobnicate")


def test_bad_input_is_refused_before_the_subcommands_own_imports(monkeypatch):
    """A subcommand reads its flags before it imports its machinery (``nambu_bch.exact``, ``nambu_bch.shadow``, the
    numeric diagnostics: about 0.5 s of a cold process), so a bad flag is answered without them; here they cannot be
    imported at all."""
    for name in ("nambu_bch.exact", "nambu_bch.shadow", "nambu_bch.shadow.fi_route", "nambu_bch.numeric.diagnostics",
                 "nambu_bch.numeric.hmc"):
        monkeypatch.setitem(sys.modules, name, None)  # importing it raises ImportError
    for sub in ("conserved", "exact", "fi", "shadow", "check", "sample"):
        bad(cli(sub, "--model", "hoo"), "unknown model 'hoo'")
    bad(cli("shadow", "--integrator", "12x"), "unknown composition '12x'")


def test_the_version_is_looked_up_only_for_version(monkeypatch):
    """Building the parser does not read the installed version (``importlib.metadata``: ~50 ms of every run)."""
    import nambu_bch
    from nambu_bch.cli._main import build_parser

    monkeypatch.setitem(vars(nambu_bch), "__version__", None)  # restored (or removed) afterwards
    del vars(nambu_bch)["__version__"]
    looked_up = []
    monkeypatch.setattr(nambu_bch, "_version", lambda: looked_up.append(1) or "9.9")
    build_parser()
    assert looked_up == []
    assert ok(cli("--version")) == "nambu-bch 9.9\n" and looked_up == [1]


def _toml(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text) if isinstance(text, str) else path.write_bytes(text)
    return str(path)


def bad_cases(tmp_path):
    """``(argv, fragment)``: every flag with a bad value; the message must contain ``fragment``."""
    good = 'coordinates = "x1 x2"\nH = "x2^2/2 + x1^2/2"\n'
    return [
        # subcommand and parser level
        ([], "subcommand"),
        (["frobnicate"], "invalid choice"),
        (["models", "--nope"], "--nope"),
        # --model / --system / --H / --G / --coords / --param / --split / --name
        (["models", "--model", "hoo"], "unknown model 'hoo'"),
        (["models", "--model", ""], "--model"),
        (["models", "--system", str(tmp_path / "none.toml")], "cannot read"),
        (["models", "--system", str(tmp_path)], "a directory"),
        (["models", "--system", _toml(tmp_path, "syntax.toml", "coordinates = [")], "not valid toml"),
        (["models", "--system", _toml(tmp_path, "binary.toml", b"\xff\xfe\x00")], "not valid toml"),
        (["models", "--system", _toml(tmp_path, "key.toml", good + "hamiltonain = 1\n")], "unknown key"),
        (["models", "--system", _toml(tmp_path, "nocoords.toml", 'H = "x1"\n')], "coordinates"),
        (["models", "--system", _toml(tmp_path, "noH.toml", 'coordinates = "x1 x2"\n')], "'H'"),
        (["models", "--system", _toml(tmp_path, "both.toml", good + 'hamiltonians = ["x1"]\n')], "not both"),
        (["models", "--system", _toml(tmp_path, "inject.toml", 'coordinates = "x1 x2"\nH = "x1.__class__"\n')], "attribute"),
        (["models", "--system", _toml(tmp_path, "num.toml", 'coordinates = "x1 x2"\nH = 3\n')], "strings"),
        (["models", "--system", _toml(tmp_path, "pval.toml", good + '[parameters]\nm = "abc"\n')], "parameter m"),
        (["models", "--system", _toml(tmp_path, "split.toml", good + 'split = "half"\n')], "split"),
        (["models", "--system", _toml(tmp_path, "big.toml", "# " + "x" * 70000 + "\n")], "at most"),
        (["models", "--system", _toml(tmp_path, "ok.toml", good), "--param", "q=1"], "--param q"),
        (["models", "--system", _toml(tmp_path, "ok2.toml", good), "--model", "ho"], "only one"),
        (["models", "--H", "x1 +", "--coords", "x1 x2"], "--H"),
        (["models", "--H", "x1**x1**x1**x1**9999", "--coords", "x1 x2"], "--H"),
        (["models", "--H", "x2^2/2 + x1^2/2", "--model", "ho"], "only one"),
        (["models", "--H", "(x1*x2)^2"], "not separable"),
        (["models", "--H", "x2^2/2 + y", "--coords", "x1 x2"], "'y' is not declared"),
        (["models", "--G", "x3 - x1^2"], "--G needs --H"),
        (["models", "--H", "x2^2/2", "--G", "q", "--coords", "x1 x2 x3"], "--G"),
        (["models", "--H", "x2^2/2", "--G", "x3", "--coords", "x1 x2"], "needs 1 hamiltonian"),
        (["models", "--H", "x2^2/2 + x1^2", "--coords", "x1 1x"], "--coords"),
        (["models", "--H", "x2^2/2 + x1^2", "--coords", "x1 h"], "reserved"),
        (["models", "--H", "x2^2/2 + x1^2", "--coords", ""], "--coords"),
        (["models", "--H", "x2^2/2 + x1^2", "--param", "2m"], "--param"),
        (["models", "--H", "x2^2/2 + x1^2", "--param", "h"], "reserved"),
        (["models", "--H", "x2^2/2 + x1^2", "--param", "m=x1"], "--param m"),
        (["models", "--H", "x2^2/2 + x1^2", "--param", "m=1/0"], "--param m"),
        (["models", "--model", "ho3", "--param", "I1=2"], "model ho3 has parameters m, omega"),
        (["models", "--model", "ho3", "--split", "half"], "invalid choice"),
        (["models", "--model", "rigid-body", "--split", "single", "--H", "x1"], "only one"),
        (["models", "--H", "x2^2/2 + x1^2", "--name", "   "], "--name"),
        # --integrator / --order / --route / --degree / --format / --output / --field / --terms
        (["bch", "--model", "ho", "--integrator", "12321"], "piece(s) [3]"),
        (["bch", "--integrator", "abc"], "unknown composition 'abc'"),
        (["bch", "--integrator", "1:x,2:1,3:1"], "coefficient"),
        (["bch", "--integrator", "1:1/3,2:1,3:1"], "sum to 1"),
        (["bch", "--integrator", "yoshida:12"], "triple jump"),
        (["bch", "--order", "abc"], "--order"),
        (["bch", "--order", "99"], "--order 99"),
        (["bch", "--order", "2.5"], "--order"),
        (["bch", "--field", "--terms", "--format", "pdf"], "invalid choice"),
        (["bch", "--output", str(tmp_path / "no" / "such" / "dir.tex")], "--output"),
        (["bch", "--field=1"], "--field"),
        (["bch", "--terms=yes"], "--terms"),
        (["fi", "--integrator", "1:1/2,2:1"], "sum to 1"),
        (["fi", "--model", "ho", "--format", "html"], "invalid choice"),
        (["models", "--format", "latex", "--output", ""], "--output"),
        (["shadow", "--route", "magic"], "invalid choice"),
        (["shadow", "--degree", "0"], "--degree"),
        (["shadow", "--order", "-3"], "--order"),
        (["conserved", "--degree", "x"], "--degree"),
        (["exact", "--order", "1e9"], "--order"),
        # numeric flags
        (["check", "--h", "0"], "--h"),
        (["check", "--h", "-0.1"], "--h"),
        (["check", "--h", "abc"], "--h"),
        (["check", "--h", "1e400"], "--h"),
        (["check", "--steps", "0"], "--steps"),
        (["check", "--steps", "1.5"], "--steps"),
        (["check", "--steps", str(10**12)], "--steps"),
        (["check", "--every", "-1"], "--every"),
        (["check", "--format", "latex"], "invalid choice"),
        (["plot", "--h", "nan"], "--h"),
        (["plot", "--steps", "many"], "--steps"),
        (["plot", "--dpi", "0"], "--dpi"),
        (["plot", "--fig-format", "gif"], "invalid choice"),
        (["plot", "--short-steps", "-5"], "--short-steps"),
        (["check", "--steps", "10", "--every", "20"], "--every 20"),
        (["check", "--alpha", "a"], "--alpha"),
        (["plot", "--outdir", _toml(tmp_path, "afile", "x")], "--outdir"),
    ]


def test_bad_input_every_flag_in_process(tmp_path, capsys):
    for argv, fragment in bad_cases(tmp_path):
        code = main(argv)
        captured = capsys.readouterr()
        lines = captured.err.strip().splitlines()
        assert code == 2, (argv, captured.err)
        assert len(lines) == 1 and "Traceback" not in captured.err, (argv, captured.err)
        assert fragment.lower() in lines[0].lower(), (argv, lines[0])
        assert captured.out == "", (argv, captured.out)


def test_bad_numeric_state_in_process(capsys):
    for argv, fragment in [
        (["check", "--x0", "1,2"], "--x0"),
        (["check", "--x0", "a,b,c"], "--x0"),
        (["check", "--x0", "1,1,1e400"], "--x0"),
        (["check", "--model", "ho", "--param", "k=1"], "--param k"),
        (["plot", "--x0", "1,1"], "--x0"),
    ]:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and fragment in err, (argv, err)


GARBAGE = st.lists(
    st.sampled_from(list("x12+-*/^().e_ ,'\"[]:;=<>!%&|~@#") + ["**", "sin(", "__", "import", "x1", "x2"]), max_size=20
).map("".join)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(GARBAGE, st.sampled_from(["--H", "--param", "--coords", "--integrator"]))
def test_garbage_in_main_is_exit_0_or_2(capsys, text, flag):
    """Whatever the text of a flag, main() returns 0 or 2 with one stderr line, never raises."""
    argv = {
        "--H": ["models", "--H", text, "--coords", "x1 x2"],
        "--param": ["models", "--H", "x2^2/2 + x1^2/2", "--param", text],
        "--coords": ["models", "--H", "x2^2/2 + x1^2/2", "--coords", text],
        "--integrator": ["bch", "--model", "ho", "--integrator", text, "--order", "1"],
    }[flag]
    code = main(argv)
    captured = capsys.readouterr()
    assert code in (0, 2), (argv, captured.err)
    if code == 2:
        assert len(captured.err.strip().splitlines()) == 1 and "Traceback" not in captured.err, (argv, captured.err)
