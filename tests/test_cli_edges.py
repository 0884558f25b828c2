"""The command line at its edges: no silent acceptance, no abbreviation, no traceback, nothing echoed raw.

In process through ``main(argv)`` (capsys) except the four classes that need a real
process: stdout on a full device, stdout past the file-size limit, stderr closed, and
Ctrl-C right after the start.  Every file a test writes is under its ``tmp_path``.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest

from nambu_bch.cli import build_parser, main

REPO = Path(__file__).resolve().parents[1]


def run(capsys, *argv):
    """``(exit status, stdout, stderr)`` of ``main(argv)`` in process."""
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def refused(capsys, argv, *fragments):
    """Exit 2, one line on stderr containing every fragment, nothing on stdout; returns the line."""
    code, out, err = run(capsys, *argv)
    assert code == 2, (argv, code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, (argv, err)
    assert out == "", (argv, out)
    for fragment in fragments:
        assert fragment in lines[0], (argv, lines[0])
    return lines[0]


def _clean(line: str) -> bool:
    """No control character, no bidirectional override or other format character."""
    return all(unicodedata.category(ch)[0] != "C" for ch in line)


# --------------------------------------------------------------------------------------------
# every flag validated when given; a flag the request would ignore is refused
# --------------------------------------------------------------------------------------------
LIMIT_JUNK = ["junk", "0", "-1", "1.5", "1e3", "", " ", "nan", "inf", "-inf", "10**6", "0x10", "1_000", "+", "-",
              "--", "2 3", "1,2", "\u0663", "\uff13", "2\n", "None", "True", "[1]", "1/2", "x1", "9" * 32, "1000001",
              "\x00", "1;2", "$(id)", "`id`", "__import__('os')", "%d", "\\n", "\x1b[31m1"]


def test_fi_limit_is_validated_at_every_order(capsys):
    """``fi --limit junk`` used to be accepted and ignored unless --order K > 2: now every value is checked up front."""
    assert len(LIMIT_JUNK) == 36
    for value in LIMIT_JUNK:
        line = refused(capsys, ["fi", "--limit", value], "--limit")
        assert _clean(line), line


def test_flags_that_would_be_ignored_are_refused(capsys):
    refused(capsys, ["fi", "--limit", "2"], "--limit 2", "--order")  # only the h^K listing (K > 2) is limited
    refused(capsys, ["fi", "--model", "ho", "--integrator", "TVT", "--order", "2", "--limit", "3"], "--limit 3")
    refused(capsys, ["fi", "--order", "1"], "--order 1", "K >= 2")
    refused(capsys, ["fi", "--order", "0"], "--order 0")
    refused(capsys, ["shadow", "--standalone", "--format", "text"], "--standalone", "--format latex")
    refused(capsys, ["bch", "--standalone", "--format", "json"], "--standalone")
    refused(capsys, ["models", "--model", "ho", "--name", "mine"], "--name 'mine'", "--model")
    refused(capsys, ["models", "--param", "m"], "--param m without a value", "model ho3 has it already")
    refused(capsys, ["models", "--param", "zz"], "--param zz: model ho3 has parameters m, omega")
    refused(capsys, ["shadow", "--order", "2", "--order", "4"], "--order", "given twice")
    refused(capsys, ["models", "--model", "ho", "--model", "ho3"], "--model", "given twice")
    refused(capsys, ["check", "--format", "json", "--format=text"], "--format", "given twice")
    # the same flags where they apply
    code, out, _ = run(capsys, "fi", "--model", "ho3", "--order", "4", "--limit", "1", "--format", "text")
    assert code == 0 and "more brackets (raise --limit)" in out
    code, out, _ = run(capsys, "fi", "--order", "2", "--format", "text")  # --order 2 now shows the h^2 terms of ho3
    assert code == 0 and "h^2 term of 12321 on ho3" in out
    code, out, _ = run(capsys, "models", "--H", "x2^2/2 + x1^2/2", "--name", "mine", "--format", "text")
    assert code == 0 and out.startswith("mine ")


# --------------------------------------------------------------------------------------------
# the system analysed: named in every output, inferred coordinates checked against the expressions
# --------------------------------------------------------------------------------------------
def test_inferred_coordinates_that_contradict_the_expressions_are_refused(capsys):
    line = refused(capsys, ["shadow", "--H", "x2^2/2 + x1^2/2", "--G", "x1^2"], "x1, x2", "x1 x2 x3", "--coords 'x1 x2 x3'")
    assert "x3 appears in no Hamiltonian" in line
    refused(capsys, ["shadow", "--H", "x2^2/2 + x1^2/2", "--G", "x1^2", "--G", "x2"], "x1 x2 x3 x4", "x3, x4 appear")
    refused(capsys, ["models", "--H", "x1^2 + x2^2 + x3^2", "--bracket", "lie-poisson"], "x1, x2, x3",
            "--coords 'x1 x2 x3'")
    refused(capsys, ["models", "--H", "x2^2/2 + x4^4"], "--coords 'x1 x2 x3 x4'")
    # said explicitly, the same systems are analysed, and the output says on what
    code, out, _ = run(capsys, "models", "--H", "x2^2/2 + x1^2/2", "--G", "x1^2", "--coords", "x1 x2 x3", "--format", "text")
    assert code == 0 and "bracket = nambu" in out and "coordinates: x1, x2, x3" in out
    code, out, _ = run(capsys, "models", "--H", "x1^2 + x2^2 + x3^2", "--bracket", "lie-poisson", "--coords", "x1 x2 x3",
                       "--format", "text")
    assert code == 0 and "bracket = lie-poisson" in out
    # consistent inferences stay as they were: the free particle (x1 in no term, x2 is the top index)
    code, out, _ = run(capsys, "models", "--H", "x2^2/2", "--format", "text")
    assert code == 0 and "coordinates: x1, x2" in out
    code, out, _ = run(capsys, "models", "--H", "x2^2/(2*m) + m*x3/2", "--G", "x3 - x1^2", "--param", "m", "--format", "text")
    assert code == 0 and "coordinates: x1, x2, x3" in out


@pytest.mark.parametrize("argv", [
    ("shadow", "--model", "ho", "--integrator", "TVT"),
    ("bch", "--model", "ho", "--integrator", "TVT"),
    ("fi", "--model", "ho", "--integrator", "TVT"),
    ("conserved", "--model", "ho", "--integrator", "TVT"),
    ("exact", "--model", "ho", "--integrator", "TVT"),
])
def test_every_symbolic_output_names_the_system(capsys, argv):
    """Text and LaTeX start with the system (name, bracket, coordinates); the JSON carries them as keys."""
    code, text, _ = run(capsys, *argv, "--format", "text")
    assert code == 0 and text.startswith("system ho: canonical bracket on x1, x2 (parameters m, omega)\n"), text[:200]
    code, latex, _ = run(capsys, *argv, "--format", "latex")
    assert code == 0 and latex.startswith("\\begin{align*}\n&\\text{system ho: canonical bracket on}\\ (x_{1}, x_{2})")
    code, out, _ = run(capsys, *argv, "--format", "json")
    data = json.loads(out)
    assert code == 0 and data["coordinates"] == ["x1", "x2"] and data["bracket"] == "canonical"


def test_models_latex_names_the_bracket_and_coordinates(capsys):
    code, latex, _ = run(capsys, "models", "--model", "ho", "--format", "latex")
    assert code == 0 and "&\\text{ho: canonical bracket on}\\ (x_{1}, x_{2}):" in latex, latex[:300]


def test_numeric_outputs_name_the_system(capsys):
    code, text, _ = run(capsys, "check", "--H", "x2^2/(2*m) + m*x3/2", "--G", "x3 - x1^2", "--param", "m=2",
                        "--coords", "x1 x2 x3", "--steps", "10")
    assert code == 0 and text.startswith("system custom: nambu bracket on x1, x2, x3 (parameters m)\n")
    argv = ("compare", "--model", "ho", "--integrator", "TVT", "--integrator", "VTV", "--step-counts", "10,20", "--t-end", "1")
    code, text, _ = run(capsys, *argv)
    assert code == 0 and text.startswith("system ho: canonical bracket on x1, x2 (parameters m, omega)\n")
    code, out, _ = run(capsys, *argv, "--format", "json")
    data = json.loads(out)
    assert data["coordinates"] == ["x1", "x2"] and data["bracket"] == "canonical" and data["system"] == "ho"


# --------------------------------------------------------------------------------------------
# no abbreviations; the flag of another subcommand; "did you mean"
# --------------------------------------------------------------------------------------------
def test_no_abbreviation_of_any_flag(capsys):
    """``shadow --model pendulum --h 0.1`` printed the help and exited 0 (``--h`` abbreviated ``--help``)."""
    refused(capsys, ["shadow", "--model", "pendulum", "--h", "0.1"], "'--h'", "belongs to `nambu-bch check`",
            "`nambu-bch plot`", "did you mean '--H'")
    parser = build_parser()
    subparsers = next(a for a in parser._actions if a.dest == "command").choices
    tried = 0
    for name, sub in subparsers.items():
        flags = [f for f in sub._option_string_actions if f.startswith("--")]
        for flag in flags:
            prefix = flag[:-1]
            if len(prefix) > 2 and not any(f == prefix for f in flags):
                line = refused(capsys, [name, prefix, "1"] if sub._option_string_actions[flag].nargs != 0 else [name, prefix],
                               repr(prefix))
                assert "unrecognized argument" in line, line
                tried += 1
    assert tried > 100


def test_main_builds_its_parser_once_and_a_parse_leaves_it_unchanged(capsys, monkeypatch):
    """``main`` rebuilt the whole parser (ten subcommands registered, ~8 ms) on every call; it now reuses one.  Reuse
    is safe only if a parse changes nothing in the parser: a flag given once in each of two calls is not "given
    twice", an ``append`` flag does not accumulate across calls, and each call sees its own defaults."""
    from nambu_bch.cli import _main

    monkeypatch.setattr(_main, "_PARSER", [])
    built = []
    monkeypatch.setattr(_main, "build_parser", lambda: built.append(1) or build_parser())
    for _ in range(2):
        assert run(capsys, "models", "--model", "ho3", "--format", "json")[0] == 0
        args = _main._parser().parse_args(["compare", "--integrator", "121"])
        assert args.integrators == ["121"] and args.format == "text" and args.t_end == "10"
    refused(capsys, ["models", "--model", "ho3", "--model", "ho"], "given twice")
    assert run(capsys, "models", "--model", "ho")[0] == 0
    assert _main._parser().parse_args(["compare"]).integrators is None
    # the subcommand's run as its module holds it now (a monkeypatched run is called, as with a parser per call)
    import nambu_bch.cli.models as models

    monkeypatch.setattr(models, "run", lambda args: print("replaced"))
    assert run(capsys, "models")[:2] == (0, "replaced\n")
    assert built == [1]


def test_did_you_mean(capsys):
    refused(capsys, ["shadow", "--outpt", "x.tex"], "did you mean '--output'")
    refused(capsys, ["fi", "--lmit", "3"], "did you mean '--limit'")
    refused(capsys, ["check", "--limit", "3"], "belongs to `nambu-bch fi`")
    refused(capsys, ["shado"], "did you mean 'shadow'")
    refused(capsys, ["shadow", "--format", "jsn"], "did you mean 'json'")
    refused(capsys, ["shadow", "--route", "FI"], "did you mean 'fi'")
    refused(capsys, ["models", "--model", "lotka"], "did you mean 'lotka-volterra'")
    refused(capsys, ["models", "--model", "rigidbody"], "did you mean 'rigid-body'")
    refused(capsys, ["models", "--model", "zzz"], "unknown model 'zzz'; built-in models are")
    refused(capsys, ["bch", "--integrator", "strang:12321"], "'strang' takes no base word", "'12321'", "yoshida:WORD")
    refused(capsys, ["bch", "--integrator", "forest-ruth:12321"], "'forest-ruth' takes no base word")
    refused(capsys, ["bch", "--integrator", "tripple-jump:12321"], "did you mean 'triple-jump'", "suzuki:WORD")
    refused(capsys, ["bch", "--integrator", "sukuzi"], "did you mean 'suzuki'")
    refused(capsys, ["bch", "--integrator", "lie_trotter"], "did you mean 'lie-trotter'")


def test_model_lookup_suggests_in_python():
    import nambu_bch as nb

    with pytest.raises(nb.errors.UnknownModelError, match="did you mean 'rigid-body'"):
        nb.model("rigidbody")
    with pytest.raises(nb.errors.InvalidCompositionError, match="takes no base word"):
        nb.composition("strang:12321", 3)


# --------------------------------------------------------------------------------------------
# user strings echoed escaped
# --------------------------------------------------------------------------------------------
HOSTILE = "a\nb\x1b[31m\u202e\x07.txt"


def test_output_names_are_echoed_escaped(tmp_path, capsys):
    target = tmp_path / HOSTILE
    code, out, err = run(capsys, "models", "--model", "ho", "--output", target)
    assert code == 0 and out == "" and target.read_text().startswith("ho ")
    assert len(err.splitlines()) == 1 and _clean(err.strip()) and "\\x1b[31m\\u202e" in err, repr(err)
    for argv in (["bch", "--output", tmp_path / "missing" / HOSTILE],
                 ["models", "--output", tmp_path, "--model", HOSTILE],
                 ["plot", "--outdir", target / "sub"],
                 ["compare", "--model", "ho", "--figure", tmp_path / HOSTILE],
                 ["models", "--system", tmp_path / HOSTILE],
                 ["shadow", "--integrator", HOSTILE],
                 ["shadow", "--coords", HOSTILE, "--H", "x1"],
                 [HOSTILE],
                 ["shadow", HOSTILE]):
        line = refused(capsys, argv)
        assert _clean(line), (argv, line)


# --------------------------------------------------------------------------------------------
# bch: an output too large to print is refused before any work
# --------------------------------------------------------------------------------------------
def test_bch_order_beyond_the_listing_bound_is_refused_up_front(capsys, monkeypatch):
    import nambu_bch.bch as bch

    def no_work(*args, **kwargs):
        raise AssertionError("the series was computed")

    monkeypatch.setattr(bch, "formal_bch", no_work)
    refused(capsys, ["bch", "--order", "12"], "--order 12", "192346 terms", "largest --order for 3 pieces is 10")
    refused(capsys, ["bch", "--order", "11", "--format", "json"], "largest --order for 3 pieces is 10")
    from nambu_bch.cli.bch import _check_size
    from nambu_bch.integrators.composition import composition

    _check_size(composition("12321"), 10)  # the paper's word to h^10: 25486 terms, listed
    _check_size(composition("121"), 12)  # two pieces to h^12: 1377 terms


# --------------------------------------------------------------------------------------------
# the process: stdout full, file-size limit, stderr closed, Ctrl-C at start (one subprocess each)
# --------------------------------------------------------------------------------------------
def _env(tmp_path):
    return {**os.environ, "PYTHONPATH": str(REPO), "NAMBU_BCH_CACHE": str(tmp_path / "cache"), "MPLBACKEND": "Agg"}


def _child(tmp_path, *argv, **kwargs):
    return subprocess.run([sys.executable, "-m", "nambu_bch", *argv], cwd=tmp_path, env=_env(tmp_path),
                          capture_output="stdout" not in kwargs, text=True, timeout=600, **kwargs)


def test_stdout_on_a_full_device_is_one_line(tmp_path):
    with open("/dev/full", "w") as full:
        done = _child(tmp_path, "bch", "--model", "ho", "--order", "6", "--format", "text", stdout=full,
                      stderr=subprocess.PIPE)
    assert done.returncode == 2 and done.stderr.strip().splitlines() == [
        "nambu-bch bch: error: cannot write the result to stdout (No space left on device)"], done.stderr


def test_stdout_past_the_file_size_limit_is_one_line(tmp_path):
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (256, 256))

    with open(tmp_path / "out.txt", "w") as out:
        done = _child(tmp_path, "bch", "--model", "ho", "--order", "6", "--format", "text", stdout=out,
                      stderr=subprocess.PIPE, preexec_fn=limit)
    assert done.returncode == 2 and done.stderr.strip().splitlines() == [
        "nambu-bch bch: error: cannot write the result to stdout (File too large)"], done.stderr
    assert (tmp_path / "out.txt").stat().st_size <= 256


def test_closed_stderr_keeps_stdout_clean(tmp_path):
    """Started with ``2>&-`` the error line went to stdout with exit 1; now it is lost, stdout stays empty, exit 2."""
    done = _child(tmp_path, "shadow", "--order", "x", stdout=subprocess.PIPE, preexec_fn=lambda: os.close(2))
    assert done.returncode == 2 and done.stdout == ""


def test_ctrl_c_right_after_the_start_is_quiet(tmp_path):
    """SIGINT right after the start: killed before Python installs its handler, or one line and exit 130.

    The only traceback that can remain comes from the interpreter's own start-up (``site`` and the
    environment's ``.pth`` files), before the first line of the package runs: none from the package.
    """
    child = subprocess.Popen([sys.executable, "-m", "nambu_bch", "models"], cwd=tmp_path, env=_env(tmp_path),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=600)
    if "Traceback" in err:
        assert str(REPO / "nambu_bch") not in err and "<frozen site>" in err, err
    else:
        assert child.returncode in (130, -signal.SIGINT), (child.returncode, err)
        assert err in ("", "nambu-bch: interrupted\n", "nambu-bch models: interrupted\n"), err
