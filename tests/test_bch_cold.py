"""The table's series without sympy or numpy: the light word reader (nambu_bch.bch.light) agrees with the full
parser, a served result builds its sympy objects only when asked, and a fresh process imports neither."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest

from nambu_bch.bch import formal, light, table
from nambu_bch.bch.formal import formal_bch
from nambu_bch.errors import NambuBCHError
from nambu_bch.integrators import composition

ROOT = Path(__file__).resolve().parents[1]
comp_module = sys.modules["nambu_bch.integrators.composition"]

#: (spec, n_pieces): every form the light reader takes, and inputs it must leave to the full parser
SPECS = [
    ("12", None), ("21", None), ("121", None), ("212", None), ("12321", None), ("1221", None), ("1", None),
    ("123", 3), (" 121 ", None), ("TVT", None), ("vv", 2), ("Position-Verlet", None), ("VTV", 3),
    ("lie-trotter", 3), ("strang", 2), ("strang", None), ("strang", 10), ("1:1/2,2:1,1:1/2", None),
    ("1: 1/2 , 2:1, 1:1/2", None), ("2:1/3,1:1,2:2/3", None), ("1:1,2:1", 2), ("1:-1/2,2:1,1:3/2", None),
    ("1:2/4,2:1,1:1/2", None), ("01:1,2:1", None), ("1:01,2:1", None), ("1:1/2,2:1", None), ("1:1/0,2:1", None),
    ("1:0.5,2:1,1:0.5", None), ("1:1/2,\t2:1,1:1/2", None), ("102", None), ("0", None), ("", None),
    ("yoshida", None), ("1:sqrt(2)/2,2:1,1:1-sqrt(2)/2", None), ("12", 0), ("12", True), ("1" * 201, None),
    ("201:1", None), ("1:1,2:1,", None), ("tvt:12", None), ("x" * 401, None),
]


def _full(spec, n_pieces):
    try:
        return composition(spec, n_pieces)
    except NambuBCHError:
        return None


@pytest.mark.parametrize("spec,n_pieces", SPECS)
def test_the_light_reader_agrees_with_the_full_parser(spec, n_pieces):
    """Pieces, coefficients, name and symmetry as the full parser's; ``None`` for everything it refuses."""
    word = light.parse_word(spec, n_pieces)
    comp = _full(spec, n_pieces)
    if comp is None:
        assert word is None
        return
    if word is None:
        return  # a form left to the full parser
    assert word.pieces == comp.pieces and word.name == comp.name and word.symmetric == comp.symmetric
    assert [Fraction(int(c.p), int(c.q)) for c in comp.coefficients] == list(word.coefficients)
    assert word.composition() == comp
    assert all(word.remainder_power(k) == comp.remainder_power(k) for k in (1, 2, 3))


def test_the_light_reader_takes_the_plain_forms():
    for spec, n_pieces in [("12", None), ("TVT", None), ("strang", 3), ("1:1/2,2:1,1:1/2", None)]:
        assert light.parse_word(spec, n_pieces) is not None, spec


def test_the_grammar_constants_agree():
    assert (light.MAX_FACTORS, light.MAX_TEXT, light.MAX_PIECES) == (
        comp_module.MAX_FACTORS, comp_module.MAX_TEXT, comp_module.MAX_PIECES)
    assert light.ALIASES == comp_module._ALIASES and light._PUNCTUATION == comp_module._TEXT_PUNCTUATION


@pytest.mark.parametrize("spec", ["12", "21", "TVT", "212", "1:1/2,2:1,1:1/2"])
def test_a_served_series_builds_its_composition_when_asked(spec):
    table.clear_cache()
    B = formal_bch(spec, 6)
    assert isinstance(B._composition, light.Word) and isinstance(B._scaled, table.Served)
    assert len(B) == sum(len(B.scaled_terms(d)[1]) for d in range(1, 7))
    assert B.composition == composition(spec) and B.composition is B.composition
    engine = formal._formal_engine(composition(spec), 6)
    assert B == engine and hash(B) == hash(engine) and B.to_text() == engine.to_text()
    assert B.to_latex() == engine.to_latex() and B.degrees == engine.degrees
    copy = pickle.loads(pickle.dumps(formal_bch(spec, 6)))
    assert copy == engine and isinstance(copy._scaled, dict)


def test_errors_are_the_full_parsers():
    with pytest.raises(formal.InvalidOrderError, match="positive integer"):
        formal_bch("12", 0)
    with pytest.raises(NambuBCHError, match="n_pieces"):
        formal_bch("12", 3, n_pieces=0)
    with pytest.raises(NambuBCHError, match="sum to 1"):
        formal_bch("1:1/2,2:1", 3)


def test_a_fresh_process_serves_the_table_without_sympy_or_numpy(tmp_path):
    """``formal_bch('12', 18)`` in a fresh interpreter, every degree's terms and the text of the other three
    series: neither sympy nor numpy (nor numba) is imported, nor dataclasses (inspect) and json, which cost such a
    process more than reading the series."""
    code = (
        "import sys; from nambu_bch.bch import formal_bch; B = formal_bch('12', 18)\n"
        "n = sum(len(B.scaled_terms(d)[1]) for d in range(1, 19))\n"
        "texts = [formal_bch(s, 5).to_text() for s in ('21', '121', '212', 'TVT')]\n"
        "print(n, len(B), B.scaled_terms(3), texts[1][:40], sorted(m for m in ('sympy', 'numpy', 'numba', "
        "'dataclasses', 'inspect', 'json') if m in sys.modules))"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NAMBU_BCH_CACHE": str(tmp_path / "cache")}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    expected = formal_bch("12", 18)
    assert run.stdout.split(" ", 2)[:2] == [str(len(expected))] * 2
    assert f"{expected.scaled_terms(3)} {formal_bch('121', 5).to_text()[:40]} []\n" in run.stdout
    assert "Warning" not in run.stderr


def test_both_sha256_give_the_table_digest():
    """The built-in SHA-256 (a fresh process) and hashlib's (once imported) verify the same header."""
    import hashlib

    with open(table.TABLE_PATH, "rb") as fh:
        fh.seek(len(table.MAGIC))
        raw = fh.read(int.from_bytes(fh.read(4), "little"))
    assert hashlib.sha256(raw).hexdigest() == table.TABLE_SHA256 == table._sha256(raw).hexdigest()
    if table._builtin_sha256 is not None:
        assert table._builtin_sha256(raw).hexdigest() == table.TABLE_SHA256


def test_tree_leaves_with_and_without_sympy_agree():
    """The leaves of a served series' trees, by both of tree_leaves' walks (sympy imported or not)."""
    from nambu_bch.bch import lyndon

    trees = [t for d in range(1, 9) for _, t in formal_bch("12", 8).scaled_terms(d)[1]]
    assert [lyndon._pair_leaves(t) for t in trees] == [lyndon._leaves(t, lyndon._sympy_basic()) for t in trees]
    assert lyndon._pair_leaves(((1, 2), 2)) == (1, 2, 2) == lyndon.tree_leaves(((1, 2), 2))


def test_the_light_word_is_an_immutable_value():
    """A :class:`light.Word` compares, hashes and pickles by its fields and refuses assignment."""
    word = light.parse_word("TVT")
    assert word == light.parse_word("TVT") and hash(word) == hash(light.parse_word("TVT"))
    assert word != light.parse_word("121") and pickle.loads(pickle.dumps(word)) == word
    assert repr(word).startswith("Word(spec='TVT', n_pieces=None, pieces=(1, 2, 1)")
    with pytest.raises(AttributeError):
        word.pieces = (1,)
    with pytest.raises(AttributeError):
        formal_bch("12", 2).max_degree = 3


# --- nambu-bch bch: a series the table serves is printed without sympy or numpy ---------------------------------

LIGHT_REQUESTS = [
    ["--model", "ho", "--integrator", "TVT", "--format", "text", "--order", "5"],
    ["--model", "ho", "--format", "json"],
    ["--model", "pendulum", "--integrator", "1:1/2,2:1,1:1/2", "--format", "text", "--order", "8"],
    ["--model", "kepler", "--integrator", "12", "--format", "json", "--order", "4"],
    ["--model", "ho3-composite", "--integrator", "VTV", "--format", "text"],
    ["--model", "fpu-beta", "--integrator", "21", "--format", "json", "--order", "3"],
]


def _cli(argv, light, monkeypatch, capsys):
    from nambu_bch.cli import bch as bch_command
    from nambu_bch.cli import main

    if not light:
        monkeypatch.setattr(bch_command, "_light", lambda args: None)
    assert main(["bch", *argv]) == 0
    monkeypatch.undo()
    return capsys.readouterr()


def test_the_cli_models_of_two_pieces_are_the_built_ones():
    """Each entry of ``LIGHT_MODELS``: the system line and JSON head of the built model, which has two pieces; every
    built-in model of two pieces has an entry."""
    from nambu_bch import model, model_names, render
    from nambu_bch.cli._output import system_line
    from nambu_bch.cli.bch import LIGHT_MODELS

    two = [name for name in model_names() if len(model(name).splitting) == 2]
    assert sorted(LIGHT_MODELS) == sorted(two)
    for name, (line, head) in LIGHT_MODELS.items():
        system = model(name)
        assert line == system_line(system) and head == render.system_dict(system), name
        assert list(head) == list(render.system_dict(system)), name  # the JSON's key order


@pytest.mark.parametrize("argv", LIGHT_REQUESTS, ids=lambda a: " ".join(a))
def test_the_cli_light_path_prints_what_the_full_path_prints(argv, monkeypatch, capsys):
    light = _cli(argv, True, monkeypatch, capsys)
    full = _cli(argv, False, monkeypatch, capsys)
    assert light.out == full.out and light.err == full.err == ""


def test_the_cli_light_path_writes_output_files_as_the_full_path(tmp_path, monkeypatch, capsys):
    argv = ["--model", "ho", "--integrator", "TVT", "--format", "json", "--order", "3"]
    light = _cli([*argv, "--output", str(tmp_path / "light.json")], True, monkeypatch, capsys)
    full = _cli([*argv, "--output", str(tmp_path / "full.json")], False, monkeypatch, capsys)
    assert (tmp_path / "light.json").read_bytes() == (tmp_path / "full.json").read_bytes()
    assert light.err.replace("light.json", "full.json") == full.err and "wrote" in full.err
    assert light.out == full.out == ""


@pytest.mark.parametrize("argv", [
    ["--model", "ho", "--integrator", "TVT", "--format", "latex"],  # LaTeX: the full path
    ["--model", "ho", "--param", "m=2", "--format", "text"],  # a value substituted into the system
    ["--model", "ho", "--integrator", "1:1/3,2:1,1:2/3", "--format", "text"],  # not a series of the table
    ["--model", "ho", "--integrator", "TVT", "--field", "--format", "text"],  # X_eff on the system
    ["--format", "text"],  # ho3: three pieces
])
def test_the_cli_light_path_leaves_other_requests_to_the_full_path(argv):
    from nambu_bch.cli import build_parser
    from nambu_bch.cli._options import normalise
    from nambu_bch.cli.bch import _light

    assert _light(normalise(build_parser().parse_args(["bch", *argv]))) is None


def test_the_cli_prints_a_served_series_without_sympy_or_numpy(tmp_path):
    """``nambu-bch bch --model ho --integrator TVT`` as text and JSON in a fresh interpreter: neither sympy nor numpy
    (nor numba) is imported."""
    code = ("import sys; from nambu_bch.cli import main\n"
            "for fmt in ('text', 'json'):\n"
            "    assert main(['bch', '--model', 'ho', '--integrator', 'TVT', '--order', '6', '--format', fmt]) == 0\n"
            "print(sorted(m for m in ('sympy', 'numpy', 'numba') if m in sys.modules), file=sys.stderr)")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NAMBU_BCH_CACHE": str(tmp_path / "cache")}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stderr == "[]\n" and run.stdout.startswith("system ho: canonical bracket on x1, x2")
    assert '"integrator": "TVT"' in run.stdout and "h^6  " in run.stdout
