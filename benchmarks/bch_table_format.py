"""The shipped BCH table's format, measured: what each encoding of its blocks costs, and what a request reads and pays.

Prints, with the load average (``os.getloadavg``) on every section:

* per block of degrees ``--from`` and up (the standard factors and each series' numerators, decoded from the
  shipped table): its raw size, zlib (level 9) as the bytes are and by byte planes (``table.byte_planes``), lzma
  (preset 9e) and bz2 (level 9), and the CPU time of decompressing it (zlib, then interleaving the planes back;
  lzma);
* the file's size with every compressed block above 16 kB, above ``table.PLANE_BYTES`` or none stored by planes;
* fresh processes of this checkout and, with ``--baseline CHECKOUT``, of another one, interleaved ``--rounds`` times:
  per degree of ``--degrees`` the first ``formal_bch("12", n)`` (CPU s, the bytes it read from the table, whether
  hashlib was imported), the warm call after ``clear_caches()`` (median CPU of ``--calls`` calls; the verified image
  kept) and the peak RSS (a degree beyond a checkout's table is left out for it);
* CPython's built-in SHA-256 and hashlib's over the whole file, and what importing hashlib costs a fresh process.

Run:  python benchmarks/bch_table_format.py [--baseline /path/to/other/checkout] [--degrees 10,20,22] [--from 17]
"""

from __future__ import annotations

import argparse
import bz2
import lzma
import os
import subprocess
import sys
import time
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PROBE = r"""
import os, statistics, sys, time
from nambu_bch import clear_caches
from nambu_bch.bch import formal_bch, table
n, calls = int(sys.argv[1]), int(sys.argv[2])
if n > table.max_degree():
    print("-")
    sys.exit()
table.clear_cache()
reads = []
pread = table._pread
table._pread = lambda fd, size, offset: reads.append(size) or pread(fd, size, offset)
t = time.process_time()
formal_bch("12", n)
first = time.process_time() - t
hashlib = "hashlib" in sys.modules
times = []
for _ in range(calls):
    clear_caches()
    t = time.process_time()
    formal_bch("12", n)
    times.append(time.process_time() - t)
with open("/proc/self/status") as fh:  # this process's own peak (ru_maxrss keeps the forking parent's across exec)
    peak = next(int(line.split()[1]) for line in fh if line.startswith("VmHWM:"))
print(first, sum(reads), hashlib, statistics.median(times), peak / 1024)
"""

HASHLIB = r"""
import sys, time
def rss():
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith("VmRSS:"))
assert "hashlib" not in sys.modules
before = rss()
t = time.process_time()
import hashlib
hashlib.sha256(b"")
print(time.process_time() - t, (rss() - before) / 1024)
"""


def _load() -> str:
    return f"load {os.getloadavg()[0]:.2f}"


def _cpu(function, repeat: int = 3) -> float:
    best = None
    for _ in range(repeat):
        t = time.process_time()
        function()
        elapsed = time.process_time() - t
        best = elapsed if best is None else min(best, elapsed)
    return best


def blocks():
    """``[(degree, name, decoded bytes, width, stored block)]`` of the shipped table, every block of every degree."""
    from nambu_bch.bch import table

    table.clear_cache()
    header = table._header()
    top = header["max_degree"]
    with table._LOCK:
        assert table._verify(header, top)
    out = []
    for d in range(1, top + 1):
        record = header["degrees"][d - 1]
        factors, series = header["blocks"][d - 1]
        size = 8 * record[0] if d > 1 else 0  # degree 1 has no standard factors
        out.append((d, "factors", bytes(table.unpack_block(factors, size, 4)), 4, bytes(factors)))
        for name, (block, width) in series.items():
            if width:
                out.append((d, name, bytes(table.unpack_block(block, width * record[0], width)), width, bytes(block)))
    return out


def encodings(first: int) -> None:
    from nambu_bch.bch import table

    print(f"# blocks of degree >= {first}, bytes (decompression CPU ms), {_load()}")
    print(f"{'d':>3} {'block':>8} {'raw':>9} {'zlib':>9} {'planes':>9} {'lzma':>9} {'bz2':>9} "
          f"{'zlib ms':>8} {'planes ms':>9} {'lzma ms':>8}")
    everything = blocks()
    for d, name, data, width, _ in everything:
        if d < first:
            continue
        plain = zlib.compress(data, 9)
        planes = zlib.compress(table.byte_planes(data, width), 9)
        packed = lzma.compress(data, preset=9 | lzma.PRESET_EXTREME)
        packed_bz2 = bz2.compress(data, 9)
        count = len(data) // width

        def interleave():
            out = bytearray(len(data))
            raw = zlib.decompress(planes)
            for k in range(width):
                out[k::width] = raw[k * count : (k + 1) * count]

        print(f"{d:>3} {name:>8} {len(data):>9} {len(plain):>9} {len(planes):>9} {len(packed):>9} {len(packed_bz2):>9} "
              f"{_cpu(lambda: zlib.decompress(plain)) * 1e3:>8.2f} {_cpu(interleave) * 1e3:>9.2f} "
              f"{_cpu(lambda: lzma.decompress(packed)) * 1e3:>8.2f}")
    # the file's blocks under each rule (the header is the same size whatever the rule)
    stored = sum(len(block) for *_, block in everything)
    size = Path(table.TABLE_PATH).stat().st_size
    rules = (("16 kB", 1 << 14), (f"PLANE_BYTES ({table.PLANE_BYTES})", table.PLANE_BYTES), ("never", None))
    sizes = [size - stored + sum(len(_pack(data, width, limit)) for _, _, data, width, _ in everything)
             for _, limit in rules]
    print(f"# the file ({size} bytes) with the blocks by planes above: "
          + ", ".join(f"{label} {bytes_}" for (label, _), bytes_ in zip(rules, sizes)))


def _pack(data: bytes, width: int, limit):
    """``table.pack_block`` with planes above ``limit`` (``None``: never)."""
    from nambu_bch.bch import table

    if len(data) <= table.RAW_BYTES:
        return data
    by_planes = limit is not None and len(data) > limit
    compressed = zlib.compress(table.byte_planes(data, width) if by_planes else data, 9)
    return compressed if len(compressed) < len(data) else data


def requests(trees: list, degrees: list, rounds: int, calls: int) -> None:
    print(f"# fresh processes, formal_bch('12', n): first call CPU ms, bytes read, hashlib imported, warm median "
          f"CPU ms of {calls} calls after clear_caches, peak RSS MB")
    for n in degrees:
        for r in range(rounds):
            for label, tree in trees:
                env = dict(os.environ, PYTHONPATH=str(tree))
                # run in the checkout: `python -c` puts the working directory first on sys.path
                fields = subprocess.run([sys.executable, "-c", PROBE, str(n), str(calls)], env=env, check=True,
                                        capture_output=True, text=True, cwd=tree).stdout.split()
                if fields == ["-"]:
                    print(f"{n:>3} {label:>9} beyond its table")
                    continue
                first, read, hashlib, warm, rss = fields
                print(f"{n:>3} {label:>9} first {float(first) * 1e3:8.2f} read {int(read):>8} hashlib {hashlib:>5} "
                      f"warm {float(warm) * 1e3:8.3f} rss {float(rss):6.1f}  {_load()}", flush=True)


def digests() -> None:
    import hashlib

    from nambu_bch.bch import table

    data = Path(table.TABLE_PATH).read_bytes()
    builtin = table._builtin_sha256
    cost = subprocess.run([sys.executable, "-c", HASHLIB], check=True, capture_output=True, text=True,
                          cwd=ROOT).stdout.split()
    print(f"# SHA-256 of the file ({len(data)} bytes), CPU ms: built-in "
          + (f"{_cpu(lambda: builtin(data).digest()) * 1e3:.2f}" if builtin else "-")
          + f", hashlib {_cpu(lambda: hashlib.sha256(data).digest()) * 1e3:.2f}; importing hashlib in a fresh process "
          f"{float(cost[0]) * 1e3:.2f} ms, {float(cost[1]):.1f} MB; {_load()}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, help="another checkout, its requests interleaved with this one's")
    ap.add_argument("--degrees", default="10,20,22")
    ap.add_argument("--from", dest="first", type=int, default=17, help="the lowest degree whose blocks are listed")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--calls", type=int, default=101)
    args = ap.parse_args(argv)
    if args.baseline is not None and not (args.baseline / "nambu_bch" / "bch" / "table.py").exists():
        print(f"error: {args.baseline} is not a checkout of this package (no nambu_bch/bch/table.py)", file=sys.stderr)
        return 2
    encodings(args.first)
    digests()
    trees = [("this", ROOT)] + ([("baseline", args.baseline.resolve())] if args.baseline else [])
    requests(trees, [int(d) for d in args.degrees.split(",") if d], args.rounds, args.calls)
    return 0


if __name__ == "__main__":
    sys.exit(main())
