"""The shipped BCH table (nambu_bch.bch.table): served series equal the engine's exactly; a damaged,
replaced or missing table is not trusted (one warning, then the engine); the tool rebuilds it."""

from __future__ import annotations

import importlib.util
import os
import shutil
import warnings
from pathlib import Path

import pytest

from nambu_bch.bch import formal, table
from nambu_bch.bch.formal import formal_bch
from nambu_bch.integrators import composition

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def fresh_table():
    table.clear_cache()
    yield
    table.clear_cache()


def _engine(spec, n):
    return formal._formal_engine(composition(spec), n)


@pytest.mark.parametrize("spec", ["12", "21", "121", "212", "TVT", "VTV", "13", "31", "1:1/2,3:1,1:1/2"])
@pytest.mark.parametrize("n", [1, 2, 7, 11])
def test_served_series_equal_the_engine(spec, n):
    """Numerators, denominators D_d = d! lcm(1..n) q^d and trees, degree by degree (FormalBCH equality)."""
    served = formal_bch(spec, n)
    assert table._HEADER and table._HEADER[0] is not None  # read from the table
    computed = _engine(spec, n)
    assert served == computed
    assert served.to_text() == computed.to_text()
    for d in range(1, n + 1):
        assert served.scaled_terms(d) == computed.scaled_terms(d)


def test_eq_bch1_from_the_table():
    """Eq. (BCH1) for TVT and Lie-Trotter's [X1, X2]/2, served from the table."""
    assert formal_bch("121", 3).terms(3) == _engine("121", 3).terms(3)
    assert str(formal_bch("12", 2).terms(2)) == "[(1/2, (1, 2))]"


@pytest.mark.parametrize("spec", ["123", "1:1/3,2:1,1:2/3", "1:1/2,2:1/2,1:1/2,2:1/2", "12321"])
def test_other_compositions_are_not_served(spec):
    comp = composition(spec)
    generators = tuple(sorted(set(comp.pieces)))
    letters = [generators.index(k) for k in comp.pieces]
    scalars = formal._Scalars(tuple(comp.coefficients))
    assert table.serve(letters, scalars.values, scalars.q, generators, 4, [1] * 5) is None


def test_beyond_the_table_is_not_served():
    n = table.max_degree() + 1
    assert n > 1
    assert table.serve([0, 1], [1, 1], 1, (1, 2), n, [1] * (n + 1)) is None


def _damaged(tmp_path, monkeypatch, edit):
    path = tmp_path / "bch_series.bin"
    shutil.copyfile(table.TABLE_PATH, path)
    data = bytearray(path.read_bytes())
    edit(data)
    path.write_bytes(bytes(data))
    monkeypatch.setattr(table, "TABLE_PATH", str(path))


def _offsets():
    """``(start of the blocks, start of the degree-3 block of log(e^A e^B))`` in the shipped file."""
    header = table._header()
    return header["base"], header["base"] + table._numerators_block(header, 3, "12")[0]


def _flip(index):
    return lambda data: data.__setitem__(index, data[index] ^ 1)


@pytest.mark.parametrize("what", ["block", "header", "truncated", "missing", "fifo", "symlink"])
def test_a_damaged_or_replaced_table_is_not_trusted(tmp_path, monkeypatch, what):
    """A flipped bit in a block (its SHA-256 in the header fails) or in the header (the package's SHA-256
    fails), a cut or a missing file: one warning line, then the engine's series."""
    base, block = _offsets()
    table.clear_cache()
    if what == "block":
        _damaged(tmp_path, monkeypatch, _flip(block))
    elif what == "header":
        _damaged(tmp_path, monkeypatch, _flip(base - 2))
    elif what == "truncated":
        _damaged(tmp_path, monkeypatch, lambda data: data.__delitem__(slice(40, None)))
    elif what == "fifo":  # refused before it is opened: reading it would wait for a writer
        os.mkfifo(tmp_path / "fifo.bin")
        monkeypatch.setattr(table, "TABLE_PATH", str(tmp_path / "fifo.bin"))
    elif what == "symlink":  # never followed, even to the genuine table
        (tmp_path / "link.bin").symlink_to(table.TABLE_PATH)
        monkeypatch.setattr(table, "TABLE_PATH", str(tmp_path / "link.bin"))
    else:
        monkeypatch.setattr(table, "TABLE_PATH", str(tmp_path / "absent.bin"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert formal_bch("12", 6) == _engine("12", 6)
        assert formal_bch("21", 5) == _engine("21", 5)  # not read again in this process: no second warning
    messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert len(messages) == 1 and "\n" not in messages[0] and "is not used" in messages[0], messages
    assert table._HEADER == [None]


def test_the_verified_image_outlives_clear_caches_and_the_file(tmp_path, monkeypatch):
    """The degrees checked once are kept as the bytes that were checked: after ``clear_caches`` they are decoded
    again from memory (the file, damaged since, is not read for them), while a degree not read yet comes from the
    file and is checked first (a damaged one: one warning, not served).  ``table.clear_cache`` forgets the
    image."""
    import nambu_bch

    _damaged(tmp_path, monkeypatch, lambda data: None)
    table.clear_cache()
    assert formal_bch("12", 5) == _engine("12", 5)
    header = table._header()
    base, block = _offsets()
    degree_14 = base + table._numerators_block(header, 14, "12")[0]
    assert degree_14 - base > len(header["first_blocks"])  # beyond the bytes read with the header
    data = bytearray(Path(table.TABLE_PATH).read_bytes())
    for index in (block, degree_14):  # degree 3 (verified, in memory) and degree 14 (not read yet)
        data[index] ^= 1
    Path(table.TABLE_PATH).write_bytes(bytes(data))
    nambu_bch.clear_caches()
    assert table._NUMERATORS == {} and table._FACTORS == []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert formal_bch("21", 5) == _engine("21", 5)  # from the image: the damaged degree 3 is not read
        assert not caught
        assert table.serve([0, 1], [1, 1], 1, (1, 2), 14, [1] * 15) is None  # degree 14 read and refused
    messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert len(messages) == 1 and "degree 14 do not match" in messages[0], messages
    table.clear_cache()  # the image forgotten: the file is read again, and its damaged degree 3 is refused
    with pytest.warns(RuntimeWarning, match="degree 3 do not match"):
        assert formal_bch("12", 5) == _engine("12", 5)


def test_the_image_grows_across_reads():
    """Degrees 1-5 from the bytes read with the header, then 6-15 read from the file in a second piece: the same
    series as one request to degree 15 (offsets of a piece that does not start at degree 1)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        whole = [formal_bch("12", 15).scaled_words(d) for d in (6, 13, 14, 15)]
        table.clear_cache()
        formal_bch("212", 5)
        assert len(table._header()["blocks"]) == 5
        assert [formal_bch("12", 15).scaled_words(d) for d in (6, 13, 14, 15)] == whole
    assert len(table._header()["blocks"]) == 15


@pytest.mark.parametrize("kind", ["empty", "small", "zeros", "noise"])
def test_a_block_is_raw_exactly_when_its_size_is_its_decoded_size(kind):
    """pack_block stores a block of at most RAW_BYTES bytes, or one zlib does not shorten, as is; a compressed block
    is shorter than its data, so unpack_block needs no flag."""
    import random

    data = {"empty": b"", "small": b"\0" * table.RAW_BYTES, "zeros": b"\0" * 4 * table.RAW_BYTES,
            "noise": random.Random(26).randbytes(4 * table.RAW_BYTES)}[kind]
    block = table.pack_block(data)
    assert table.unpack_block(block, len(data)) == data
    assert (block == data) == (kind != "zeros") and (len(block) == len(data)) == (block == data)


def test_a_request_to_degree_10_decompresses_only_its_large_blocks(monkeypatch):
    """The shipped table stores the small blocks raw: after clear_caches a request to degree 10 calls zlib only for
    the blocks whose decoded size exceeds RAW_BYTES (two: the standard factors of degrees 9 and 10)."""
    import zlib

    import nambu_bch

    before = formal_bch("12", 10)
    nambu_bch.clear_caches()
    calls = []
    decompress = zlib.decompress
    monkeypatch.setattr(zlib, "decompress", lambda data: calls.append(len(data)) or decompress(data))
    served = formal_bch("12", 10)
    degrees = table._header()["degrees"]
    at = table._header()["series"]["12"]
    large = sum((8 * r[0] > table.RAW_BYTES) + (r[at + 2] * r[0] > table.RAW_BYTES) for r in degrees[1:10])
    assert len(calls) == large == 2
    monkeypatch.undo()
    assert served == before  # decoded again, from the same bytes


def test_the_tool_rebuilds_the_low_degrees_exactly(tmp_path):
    """tools/build_bch_table.py at degree 9 (formal_bch's engines at that degree: the dense one) writes the same
    blocks as the shipped table (built at its top degree by the sparse engine)."""
    spec = importlib.util.spec_from_file_location("build_bch_table", ROOT / "tools" / "build_bch_table.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    path = tmp_path / "low.bin"
    tool.build(9, path)
    shipped = table._header()
    with open(path, "rb") as fh:
        fh.read(len(table.MAGIC))
        size = int.from_bytes(fh.read(4), "little")
    raw = path.read_bytes()[len(table.MAGIC) + 4 : len(table.MAGIC) + 4 + size]
    _, letters, n_series, top, t_bytes = table.PREAMBLE.unpack_from(raw)
    import struct

    record = struct.Struct(table.record_format(n_series, t_bytes))
    low = list(record.iter_unpack(raw[len(raw) - top * record.size :]))
    assert (letters, top) == (2, 9)
    assert low == shipped["degrees"][:9]  # block places, widths, denominators, SHA-256 of each degree
    end = shipped["degrees"][8][1]
    with open(table.TABLE_PATH, "rb") as fh:
        fh.seek(shipped["base"])
        assert path.read_bytes()[len(table.MAGIC) + 4 + size :] == fh.read(end)


def test_threads_share_the_decoded_table():
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda spec: formal_bch(spec, 9), ["12", "21", "121", "212"] * 2))
    for spec, result in zip(["12", "21", "121", "212"] * 2, results):
        assert result == _engine(spec, 9), spec


def test_a_fresh_process_serves_without_numba_or_the_effective_field_modules(tmp_path):
    """The cold path: the table's series in a fresh interpreter imports neither numba nor the compiled engine,
    nor bch.backward / bch.concrete (costs about a second: the interpreter and sympy)."""
    import os
    import subprocess
    import sys

    code = ("import sys; from nambu_bch.bch import formal_bch; B = formal_bch('12', 20); "
            "print(len(B), sorted(m for m in ('numba', 'nambu_bch.bch.modular', 'nambu_bch.bch.backward', "
            "'nambu_bch.bch.concrete') if m in sys.modules))")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NAMBU_BCH_CACHE": str(tmp_path / "cache")}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split(None, 1) == ["76760", "[]\n"]  # the C program's count for degree 20 (bch_c_reference)
    assert "Warning" not in run.stderr


@pytest.mark.parametrize("spec", ["12", "21", "121", "212", "13", "1:1/2,3:1,1:1/2"])
def test_words_are_the_leaves_of_the_trees(spec):
    """``scaled_words`` (built from the table's standard factors, no tree walked) equals the leaves of
    ``scaled_terms``, and the engine's ``scaled_words``, degree by degree."""
    from nambu_bch.bch.lyndon import tree_leaves

    served = formal_bch(spec, 9)
    den, items = served.iter_scaled_words(9)
    assert table._TREES == {} and den == served.scaled_terms(9)[0]  # words without a single tree built
    engine = _engine(spec, 9)
    for d in range(1, 10):
        den, items = served.scaled_terms(d)
        assert served.scaled_words(d) == (den, [(n, tree_leaves(t)) for n, t in items]) == engine.scaled_words(d)
    assert list(served.iter_scaled_words(0)[1]) == []
