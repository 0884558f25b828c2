"""The shipped BCH table (nambu_bch.bch.table): served series equal the engine's exactly; a damaged,
replaced or missing table is not trusted (one warning, then the engine); the tool rebuilds it."""

from __future__ import annotations

import importlib.util
import os
import shutil
import warnings
from collections import defaultdict
from fractions import Fraction
from itertools import combinations
from math import comb, factorial
from pathlib import Path

import pytest

from nambu_bch.bch import formal, table
from nambu_bch.bch.formal import formal_bch
from nambu_bch.bch.lyndon import is_lyndon, standard_factorization
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


#: the served products as exponentials ``exp((values_i / q) X_{letters_i})``, letter 0 = piece 1
PRODUCTS = {"12": ((0, 1), (1, 1), 1), "21": ((1, 0), (1, 1), 1), "121": ((0, 1, 0), (1, 2, 1), 2),
            "212": ((1, 0, 1), (1, 2, 1), 2)}


def _prefix_coefficients(word, letters, values):
    """``{m: m! q^m [word[:m]] prod_i exp((values_i / q) X_{letters_i})}``, every prefix at once: the prefix split
    into runs of the factors' letters in order, each run of length ``k`` weighted ``values_i^k / k!`` (integers once
    scaled by ``m! q^m``: a multinomial times the values' powers)."""
    ways = {0: 1}
    for letter, value in zip(letters, values):
        after = dict(ways)
        for start, weight in ways.items():
            k = 0
            while start + k < len(word) and word[start + k] == letter:
                k += 1
                after[start + k] = after.get(start + k, 0) + weight * comb(start + k, k) * value**k
        ways = after
    return ways


def _log_word_coefficient(word, letters, values, q):
    """``[w] log P`` for ``P = prod_i exp((values_i / q) X_{letters_i})``, from
    ``log P = sum_k (-1)^(k-1) (P-1)^k / k``:
    the sum over the splittings ``w = v_1 .. v_k`` into non-empty words of ``(-1)^(k-1)/k prod [v_i] P`` (the
    word-coefficient form of the BCH series, Goldberg 1956), by dynamic programming over the cut points in integers
    scaled by ``j! q^j`` -- independent of the engines, which work in the Lyndon basis."""
    n = len(word)
    pieces = [(i, i + m, v) for i in range(n) for m, v in _prefix_coefficients(word[i:], letters, values).items()
              if m and v]
    row, total = {0: 1}, Fraction(0)
    for k in range(1, n + 1):
        after = defaultdict(int)
        for i, j, v in pieces:
            if i in row:
                after[j] += row[i] * comb(j, i) * v
        row = after
        if not row:
            break
        total += Fraction((-1) ** (k - 1) * row.get(n, 0), k)
    return total / (factorial(n) * q**n)


def _expansion(word):
    """The standard bracketing ``P_w`` expanded into words: ``{word: integer}``."""
    if len(word) == 1:
        return {word: 1}
    left, right = map(_expansion, standard_factorization(word))
    out = defaultdict(int)
    for x, a in left.items():
        for y, b in right.items():
            out[x + y] += a * b
            out[y + x] -= a * b
    return out


def _lyndon_coefficients(d, ones, product):
    """``{w: c_w}`` over the Lyndon words of length ``d`` with ``ones`` letters 1: since ``P_w = w + (larger words)``
    (Reutenauer, Free Lie Algebras, Thm. 5.1), ``[u] log P = sum_{w <= u} c_w [u] P_w`` is triangular over the
    Lyndon words ``u`` of the multidegree, solved from the smallest up."""
    words = sorted(w for w in (tuple(int(k in at) for k in range(d)) for at in combinations(range(d), ones))
                   if is_lyndon(w))
    expansions, out = {}, {}
    for u in words:
        c = _log_word_coefficient(u, *product)
        for w, cw in out.items():
            c -= cw * expansions[w].get(u, 0)
        out[u], expansions[u] = c, _expansion(u)
    return out


@pytest.fixture(scope="module")
def top_served():
    """``{spec: {degree: {Lyndon word (letters 0, 1): coefficient}, "degrees": served degrees}}`` served by one
    request to the table's top degree, for the two top degrees and the words with at most two of one letter.

    The words are picked once from the table's flat list of Lyndon words (what ``iter_scaled_words`` reads) and
    each series' stored numerators read at those places: building every word of degrees 21-22 as a tuple, four
    times, would cost most of a second."""
    table.clear_cache()
    top = table.max_degree()
    formal_bch("12", top).iter_scaled_words(top)  # builds the flat list of the words (bytes of piece numbers)
    words, starts = table._WORDS[(1, 2)][0], table._header()["starts"]
    picked = {d: [k for k in range(starts[d - 1], starts[d]) if min(words[k].count(1), words[k].count(2)) <= 2]
              for d in (top - 1, top)}
    out = {}
    for spec in PRODUCTS:
        served = formal_bch(spec, top)
        parts = served._scaled._parts  # per degree: D_d, D_d / T_d (signed), the stored numerators, first index
        out[spec] = {"degrees": served.degrees}
        for d in (top - 1, top):
            den, factor, stored, start = parts.get(d, (1, 0, (), 0))
            out[spec][d] = {tuple(k - 1 for k in words[i]): Fraction(stored[i - start] * factor, den)
                            for i in picked[d] if stored and stored[i - start]}
    table.clear_cache()
    return top, out


@pytest.mark.parametrize("spec", list(PRODUCTS))
def test_the_top_degrees_equal_an_independent_computation(spec, top_served):
    """At the table's two top degrees (21 and 22), the served coefficients of the Lyndon words with one or two of
    either letter equal the word coefficients of ``log P`` (Goldberg's splitting sum) solved in the Lyndon basis;
    the symmetric series have no even degree, and the reverse product is checked on its own (not derived from
    ``log(e^A e^B)`` as the table serves it).  Cheap: the full engine at degree 22 is the deep tier's
    (:func:`test_the_top_degrees_equal_the_engine`)."""
    top, served = top_served
    assert top >= 22
    for d in (top - 1, top):
        if len(spec) == 3 and d % 2 == 0:  # symmetric: odd degrees only
            assert d not in served[spec]["degrees"] and not served[spec][d]
            continue
        expected = {}
        for ones in (1, 2, d - 2, d - 1):
            expected.update(_lyndon_coefficients(d, ones, PRODUCTS[spec]))
        assert set(served[spec][d]) <= set(expected)
        assert {w: served[spec][d].get(w, 0) for w in expected} == expected, (spec, d)


def test_the_checker_agrees_with_the_engine_at_low_degree():
    """The independent computation above, on every multidegree of degree 7 against the engine."""
    for spec, product in PRODUCTS.items():
        den, items = _engine(spec, 7).scaled_words(7)
        engine = {tuple(k - 1 for k in w): Fraction(v, den) for v, w in items}
        expected = {}
        for ones in range(1, 7):
            expected.update(_lyndon_coefficients(7, ones, product))
        assert {w: engine.get(w, 0) for w in expected} == expected and set(engine) <= set(expected), spec


def test_the_top_degrees_equal_the_engine():
    """Deep tier: log(e^A e^B) to degree 22 and the symmetric series to 21, every numerator, denominator and tree as
    the engine computes them, degree by degree (``scaled_terms``: the FormalBCH equality's data, compared as tuples;
    the equality's canonical key visits every node of the 276,474 trees in Python, minutes at degree 22)."""
    top = table.max_degree()
    for spec, n in (("12", top), ("121", top - 1)):
        served, computed = formal_bch(spec, n), _engine(spec, n)
        assert (served.generators, served.max_degree, served.degrees) == (
            computed.generators, computed.max_degree, computed.degrees)
        for d in range(1, n + 1):
            assert served.scaled_terms(d) == computed.scaled_terms(d), (spec, d)
        served = computed = None


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
    # the first degree whose bytes lie beyond those read with the header
    beyond = next(d for d in range(1, table.max_degree() + 1)
                  if table._numerators_block(header, d, "12")[0] > len(header["first_blocks"]))
    data = bytearray(Path(table.TABLE_PATH).read_bytes())
    for index in (block, base + table._numerators_block(header, beyond, "12")[0]):  # degree 3 (verified, in
        data[index] ^= 1  # memory) and a degree not read yet
    Path(table.TABLE_PATH).write_bytes(bytes(data))
    nambu_bch.clear_caches()
    assert table._NUMERATORS == {} and table._FACTORS == []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert formal_bch("21", 5) == _engine("21", 5)  # from the image: the damaged degree 3 is not read
        assert not caught
        assert table.serve([0, 1], [1, 1], 1, (1, 2), beyond, [1] * (beyond + 1)) is None  # read and refused
    messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert len(messages) == 1 and f"degree {beyond} do not match" in messages[0], messages
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


@pytest.mark.parametrize("width", [1, 4, 8, 11])
def test_a_large_block_is_stored_by_byte_planes(monkeypatch, width):
    """Above PLANE_BYTES a compressed block holds the integers' byte planes (first bytes, then second bytes, ...):
    unpack_block interleaves them back into the integers as written; a smaller block is compressed as is."""
    import random
    import zlib

    monkeypatch.setattr(table, "PLANE_BYTES", 4 * table.RAW_BYTES)
    rng = random.Random(22)
    bits = 8 * width - (4 if width == 1 else 12)  # integers narrower than their width, as the numerators are
    for count in (table.PLANE_BYTES // width + 1, 3 * table.PLANE_BYTES // width):  # two sizes above PLANE_BYTES
        values = [rng.randrange(-(2**bits), 2**bits) for _ in range(count)]
        data = b"".join(v.to_bytes(width, "little", signed=True) for v in values)
        block = table.pack_block(data, width)
        assert len(block) < len(data) and bytes(table.unpack_block(block, len(data), width)) == data
        planes = zlib.decompress(block)
        assert planes == table.byte_planes(data, width) == b"".join(data[k::width] for k in range(width))
    small = bytes(2 * table.RAW_BYTES)
    assert zlib.decompress(table.pack_block(small, width)) == small  # at most PLANE_BYTES: not regrouped


def test_a_request_to_degree_10_reads_only_the_header_and_the_first_blocks(monkeypatch):
    """The table to degree 22 is 4 MB; a request to degree 10 reads its header and the first blocks (degrees 1-13)
    in one opening, and no more: one positional read of the lead and one of the header with the first blocks."""
    reads = []
    pread = table._pread
    monkeypatch.setattr(table, "_pread",
                        lambda fd, size, offset: reads.append((offset, size)) or pread(fd, size, offset))
    assert formal_bch("12", 10) == _engine("12", 10)
    header = table._header()
    lead = len(table.MAGIC) + 4
    assert reads == [(0, lead), (lead, header["base"] - lead + table._FIRST_BLOCKS)]
    assert header["degrees"][12][1] <= table._FIRST_BLOCKS < header["degrees"][-1][1] // 100


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
    nor bch.backward / bch.concrete, nor hashlib to degree 20 (CPython's own SHA-256 checks those 1.2 MB); the
    degrees 21-22 (2.9 MB more) are checked by hashlib's (costs about a second: the interpreter and sympy)."""
    import os
    import subprocess
    import sys

    code = ("import sys; from nambu_bch.bch import formal_bch; B = formal_bch('12', 20); "
            "print(len(B), sorted(m for m in ('numba', 'nambu_bch.bch.modular', 'nambu_bch.bch.backward', "
            "'nambu_bch.bch.concrete', 'hashlib') if m in sys.modules), len(formal_bch('12', 22)), "
            "'hashlib' in sys.modules)")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NAMBU_BCH_CACHE": str(tmp_path / "cache")}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    # the C program's counts for degrees 20 and 22 (bch_c_reference)
    assert run.stdout.split(None, 1) == ["76760", "[] 276474 True\n"]
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
