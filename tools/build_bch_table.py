"""Build the BCH table of :mod:`nambu_bch.bch.table` with the package's own engine, and pin its SHA-256.

Computes ``log(e^A e^B)``, ``log(e^{A/2} e^B e^{A/2})`` and ``log(e^{B/2} e^A e^{B/2})`` to
``--degree`` with the engines of :func:`nambu_bch.bch.formal.formal_bch` (the table bypassed), writes
``nambu_bch/bch/data/bch_series.bin`` (format: :mod:`nambu_bch.bch.table`) and sets
``TABLE_SHA256`` in ``nambu_bch/bch/table.py`` to the SHA-256 of its header.  Then it reads the new
table back through the package and checks that every series it serves to ``--degree`` equals the
engine's result exactly (the three stored series against the engine results the table was written from, kept
for that: the reverse ``log(e^B e^A)`` against an engine run of its own).  Prints the bytes each degree costs
(as stored).

Run:  python tools/build_bch_table.py [--degree 22]
"""

from __future__ import annotations

import argparse
import hashlib
import re
import struct
import sys
from math import gcd
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _width(values) -> int:
    """Bytes per entry: 1, 2, 4 or 8 when the values fit (numpy reads those in bulk), else the least that fits."""
    if not any(values):
        return 0
    bits = max(v.bit_length() if v >= 0 else (-v - 1).bit_length() for v in values) + 1  # two's complement
    nbytes = (bits + 7) // 8
    for w in (1, 2, 4, 8):
        if nbytes <= w:
            return w
    return nbytes


def series_numerators(name: str, n: int, words: list, results: dict | None = None) -> dict:
    """``{degree: (T_d, [n_w over the degree's Lyndon words in lexicographic order])}`` of a stored series,
    computed by :func:`nambu_bch.bch.formal.formal_bch`'s engines (never read from a table); the engine's
    result is kept in ``results[name]`` when ``results`` is given."""
    from nambu_bch.bch import formal, table
    from nambu_bch.bch.lyndon import tree_leaves
    from nambu_bch.integrators import composition

    letters, coefficients = table.SERIES[name]
    comp = composition(name)  # as formal_bch(name) reads it: the check compares the results whole
    assert comp.pieces == tuple(a + 1 for a in letters) and list(comp.coefficients) == list(coefficients), name
    result = formal._formal_engine(comp, n)
    if results is not None:
        results[name] = result
    out = {}
    for d in range(1, n + 1):
        rank = {w: k for k, w in enumerate(words[d])}
        den, items = result.scaled_terms(d)
        column = [0] * len(words[d])
        for numerator, tree in items:
            column[rank[tuple(k - 1 for k in tree_leaves(tree))]] = numerator
        common = den
        for v in column:
            common = gcd(common, v)
        out[d] = (den // common, [v // common for v in column])
    return out


def build(n: int, path: Path, results: dict | None = None) -> tuple:
    """Write the table to degree ``n`` at ``path``; ``(SHA-256 of the header, {degree: bytes}, header bytes)``.
    With ``results`` (a dict) the engine's result of each stored series is kept there by name."""
    from nambu_bch.bch import table
    from nambu_bch.bch.lyndon import lyndon_words, standard_factorization

    words = {d: lyndon_words(2, d) for d in range(1, n + 1)}
    index, k = {}, 0
    for d in range(1, n + 1):  # global index: degree by degree, lexicographic within a degree
        for w in words[d]:
            index[w] = k
            k += 1
    columns = {name: series_numerators(name, n, words, results) for name in table.SERIES}
    # T_d in a fixed number of bytes (16 to degree 20 and beyond): a table built to a lower degree has the same
    # records for the degrees both hold
    t_bytes = max(16, *((columns[name][d][0].bit_length() + 7) // 8 for name in table.SERIES for d in columns[name]))
    record = struct.Struct(table.record_format(len(table.SERIES), t_bytes))
    blocks, records = [], []
    offset = 0
    costs = {}
    for d in range(1, n + 1):  # degree by degree: a request to degree n reads one contiguous piece
        start = offset

        def add(data: bytes, width: int) -> list:
            nonlocal offset
            data = table.pack_block(data, width)
            blocks.append(data)
            offset += len(data)
            return [offset - len(data), len(data)]

        factors = [standard_factorization(w) for w in words[d]] if d > 1 else []
        fields = [len(words[d]), 0] + add(b"".join(index[u].to_bytes(4, "little") for u, _ in factors)
                                          + b"".join(index[v].to_bytes(4, "little") for _, v in factors), 4)
        for name in table.SERIES:
            T, column = columns[name][d]
            w = _width(column)
            data = b"".join(v.to_bytes(w, "little", signed=True) for v in column) if w else b""
            fields += add(data, w) + [w, T.to_bytes(t_bytes, "little")]
        fields[1] = offset  # the end of the degree's bytes
        records.append(record.pack(*fields, hashlib.sha256(b"".join(blocks)[start:]).digest()))
        costs[d] = offset - start
    names = b"".join(name.encode("ascii").ljust(table.NAME_BYTES, b"\0") for name in table.SERIES)
    raw = table.PREAMBLE.pack(table.FORMAT_VERSION, 2, len(table.SERIES), n, t_bytes) + names + b"".join(records)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(table.MAGIC + len(raw).to_bytes(4, "little") + raw + b"".join(blocks))
    return hashlib.sha256(raw).hexdigest(), costs, len(raw)


def pin(digest: str) -> None:
    source = ROOT / "nambu_bch" / "bch" / "table.py"
    text = source.read_text()
    new, count = re.subn(r'^TABLE_SHA256 = "[0-9a-f]{64}"$', f'TABLE_SHA256 = "{digest}"', text, flags=re.M)
    assert count == 1, "TABLE_SHA256 line not found in nambu_bch/bch/table.py"
    source.write_text(new)


def check(n: int, computed: dict) -> int:
    """Every series the table serves, to degree ``n``, equals the engine's: ``computed`` holds the engine's results
    of the stored series (those the table was written from), the reverse product is computed here."""
    from nambu_bch.bch import formal, table
    from nambu_bch.integrators import composition

    table.clear_cache()
    assert table.max_degree() == n
    specs = ["12", "21", "121", "212"]
    for spec in specs:
        served = formal.formal_bch(spec, n)
        engine = computed.pop(spec) if spec in computed else formal._formal_engine(composition(spec), n)
        # FormalBCH's data degree by degree, compared as tuples: its == builds a canonical key that visits every
        # node of every tree in Python (minutes at degree 22)
        assert (served.composition, served.generators, served.max_degree, served.degrees) == (
            engine.composition, engine.generators, engine.max_degree, engine.degrees), spec
        for d in range(1, n + 1):
            assert served.scaled_terms(d) == engine.scaled_terms(d), (spec, d)
        served = engine = None  # one degree-n series pair in memory at a time
    return len(specs)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--degree", type=int, default=22)
    args = ap.parse_args(argv)
    from nambu_bch.bch import table

    path = Path(table.TABLE_PATH)
    computed = {}
    digest, costs, header_bytes = build(args.degree, path, computed)
    pin(digest)
    import importlib

    importlib.reload(table)
    checked = check(args.degree, computed)
    total = 0
    print(f"# {path.relative_to(ROOT)}: header {header_bytes} bytes, SHA-256 {digest}")
    print("# degree  bytes (Lyndon factors + numerators of the three series)  cumulative")
    for d, b in costs.items():
        total += b
        print(f"{d:>8} {b:>10} {total:>12}")
    print(f"# {path.stat().st_size} bytes in all; {checked} series checked against the engine at degree {args.degree}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
