"""Formal BCH: ours against Hofstätter's C program ``bch``, each row measured the same way on both sides.

The C program (github.com/HaraldHofstaetter/BCH) is NOT vendored: pass the path of a local checkout
holding its build (``bch`` and ``libbch.so``; ``--build`` runs its Makefile with
``CFLAGS=-O3 -fPIC -march=native -fopenmp -Wall`` first).  The peer runs single-threaded
(``OMP_NUM_THREADS=1``) in its fastest mode for each series:

* ``12``, ``log(e^A e^B)``: its dedicated routine ``BCH(N, 0)`` (``bch`` with the default ``expression=0``);
* ``121``, ``log(e^{A/2} e^B e^{A/2})``: its dedicated symmetric routine ``symBCH(N, 0)`` (``expression=1``);
* ``12321``, ``log(e^{A/2} e^{B/2} e^C e^{B/2} e^{A/2})``: three generators, its general ``lie_series``
  on the parsed expression (there is no dedicated routine).

Two measurements per row, the sides interleaved:

* warm, the call alone: on the C side the library routine called in this process through ctypes on
  ``libbch.so`` (the Lie series built and freed, nothing printed); on ours ``formal_bch`` in this process
  with numba started and every in-memory cache of the package cleared before each call
  (``nambu_bch.clear_caches``: Lyndon tables rebuilt, as the C routine rebuilds its own).  Where the
  shipped table serves the series (``12`` and ``121`` to its top degree, 22, column ``by`` = ``table``) that
  call reads the word (no sympy) and decodes the standard factors and the numerators of the degrees asked
  into machine integers, from the table's verified image: the header and the bytes of each degree, read
  and checked against their SHA-256 once per process (by the untimed call) and kept as checked, which
  ``clear_caches`` keeps as it keeps the package's imported modules (the table's data, not a computed
  result; the cold column is the process that reads and checks them); the terms' Python objects (ints
  and bracket trees) are built when asked for, and the
  column ``+terms`` is the CPU time of asking for all of them right after (``scaled_terms`` of every
  degree), so ``ours warm`` + ``+terms`` is the call with every term in hand.  The column ``engine`` is
  the same call with the table bypassed (``formal._formal_engine``: what the engine alone costs).  One
  untimed call on each side first; then ``--repeat`` calls each (at least :data:`SMALL_REPEAT` when our
  untimed call took under 10 ms: one sub-millisecond call is mostly noise on a loaded machine), alternating,
  the median CPU seconds reported; the previous round's result is freed before our timed call, and the
  engine's calls and the check that the table's series is the engine's run after those rounds, not between
  the two sides' calls.
* cold, whole processes: the ``bch`` process (``table_output=1``, its table written to a file) and
  ``python -c`` importing ``nambu_bch`` and calling ``formal_bch`` (interpreter start and imports
  included; the table's series import neither sympy nor numpy; numba's machine code from its on-disk cache
  where the engine runs; the series written to a file as ``word numerator denominator`` lines).  CPU
  (user + sys), wall seconds and peak RSS of each child from ``/usr/bin/time`` (the peak RSS of a child
  forked from this large process would be inflated otherwise).  Our children run with the package's bytecode
  cached, as an installed package has it (``PYTHONDONTWRITEBYTECODE`` is dropped from their environment and the
  untimed priming run writes it); the series is written from ``iter_scaled_words`` (the words built from the
  table's standard factors, as the C program writes its table from its own).
  The numba cache is primed once, untimed, at the start (the first use after an install compiles the
  engine; that is a one-time cost and not what this row measures).

Every row is checked: the C table (index, degree, standard factors, coefficient) is rebuilt into Lyndon
words and compared coefficient by coefficient with the file our cold process wrote.  The load average
(``os.getloadavg``) is printed with every row: on a loaded machine the ratios are noisy.

Run:  python benchmarks/bch_c_reference.py /path/to/BCH [--degrees 10,14,18,20] [--sym-degrees 11,15,19]
      [--three-degrees 9,11,13] [--repeat 3] [--build]
      (the table's top degrees: --degrees 21,22 --sym-degrees 21 --three-degrees "" --repeat 1; each row served by
      the table also runs the engine --repeat times, about 12 s a call at degree 22)
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import statistics
import subprocess
import sys
import time
from fractions import Fraction
from math import factorial, lcm
from pathlib import Path

os.environ["OMP_NUM_THREADS"] = "1"  # read by libgomp when libbch.so is loaded below: one thread

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the checkout, whatever the working directory

CFLAGS = "-O3 -fPIC -march=native -fopenmp -Wall"
TIME = Path("/usr/bin/time")
THREE = "log(exp(1/2*A)*exp(1/2*B)*exp(C)*exp(1/2*B)*exp(1/2*A))"
#: series: (our spec, generators, C command-line expression or None, what the C side calls)
SERIES = {
    "12": ("12", 2, None, "BCH"),
    "121": ("121", 2, "1", "symBCH"),
    "12321": ("12321", 3, THREE, "lie_series"),
}

OURS_COLD = r"""
import sys
from nambu_bch.bch import formal_bch
spec, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
B = formal_bch(spec, n)
digits = bytes.maketrans(bytes(range(10)), b"0123456789")  # the pieces here are 1, 2, 3: one digit each
with open(out, "w") as fh:
    for d in range(1, n + 1):
        den, items = B.iter_scaled_words(d)
        fh.writelines("%s %d %d\n" % (bytes(word).translate(digits).decode(), num, den) for num, word in items)
"""

COLD_PARTS = r"""
import sys, time
clock = time.process_time
t0 = clock()
from nambu_bch.bch import formal_bch
t1 = clock()
import numba
t2 = clock()
from nambu_bch.bch import modular
modular.lyndon_table(2, 3)  # the first compiled call: numba's dispatcher machinery and one cache load
t3 = clock()
formal_bch(sys.argv[1], int(sys.argv[2]))
t4 = clock()
print(t1 - t0, t2 - t1, t3 - t2, t4 - t3)
"""

#: warm calls per side for a row whose untimed call took under 10 ms
SMALL_REPEAT = 21

PRIME = "from nambu_bch.bch import formal_bch; formal_bch('123', 10); formal_bch('12', 16)"  # sparse engine


def build(checkout: Path) -> None:
    subprocess.run(["make", "-C", str(checkout), "clean"], check=True, capture_output=True)
    subprocess.run(["make", "-C", str(checkout), f"CFLAGS={CFLAGS}", "bch"], check=True, capture_output=True)


class Peer:
    """The C library in this process (ctypes): one call of its routine for a series, built and freed."""

    def __init__(self, checkout: Path):
        lib = ctypes.CDLL(str(checkout / "libbch.so"))
        lib.BCH.restype = lib.symBCH.restype = lib.lie_series.restype = lib.parse.restype = ctypes.c_void_p
        lib.BCH.argtypes = lib.symBCH.argtypes = [ctypes.c_int, ctypes.c_int]
        lib.lie_series.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
        lib.parse.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)]
        lib.free_lie_series.argtypes = [ctypes.c_void_p]
        lib.set_verbosity_level.argtypes = [ctypes.c_int]
        lib.dimension.argtypes = [ctypes.c_void_p]
        lib.set_verbosity_level(0)
        self.lib = lib

    def call(self, series: str, n: int) -> int:
        """Compute the series to degree ``n`` (the timed part), free it; returns the dimension it reported."""
        lib = self.lib
        if series == "12":
            ls = lib.BCH(n, 0)
        elif series == "121":
            ls = lib.symBCH(n, 0)
        else:
            k = ctypes.c_int(0)
            ex = lib.parse(THREE.encode(), b"ABCDEFGHIJKLMNOPQRSTUVWXYZ", ctypes.byref(k))
            ls = lib.lie_series(k.value, ex, n, 0)
        dim = lib.dimension(ls)
        lib.free_lie_series(ls)
        if series == "12321":
            lib.free_all_expressions()
        return dim


def timed_child(args, env, report: Path, stdout=subprocess.DEVNULL):
    """``(cpu s, wall s, peak RSS kB)`` of one child process, measured by ``/usr/bin/time``."""
    subprocess.run([str(TIME), "-f", "%U %S %e %M", "-o", str(report)] + args, stdout=stdout, env=env, check=True)
    user, system, wall, rss = report.read_text().split()[-4:]
    return float(user) + float(system), float(wall), int(rss)


def breakdown(spec: str, n: int, py_env) -> str:
    """Where our time goes: the phases of one warm call, the kernels with one prime instead of all, a cold start."""
    import numpy as np

    from nambu_bch import clear_caches
    from nambu_bch.bch import formal as formal_module
    from nambu_bch.bch import modular
    from nambu_bch.integrators import composition

    comp = composition(spec)
    generators = tuple(sorted(set(comp.pieces)))
    scalars = formal_module._Scalars(tuple(comp.coefficients))
    letters = [generators.index(k) for k in comp.pieces]
    big = lcm(*range(1, n + 1))
    dens = [factorial(d) * big * scalars.q**d for d in range(n + 1)]  # formal_bch's denominators
    clear_caches()
    stats = {}
    t = time.process_time()
    modular.lyndon_numerators(letters, scalars.values, scalars.q, len(generators), n, dens, stats)
    engine = time.process_time() - t
    t = time.process_time()
    formal_module._duval_trees(len(generators), n, tuple(generators))
    trees = time.process_time() - t
    parts = " ".join(f"{k} {v:.4f}" for k, v in stats["seconds"].items())
    # the two kernels again with one prime: what a single-modulus pass (one wide integer) could save at most
    g = len(generators)
    words, lengths, left, right = modular.lyndon_table(g, n)
    top = stats["solved_degree"]
    members, class_start = modular._class_order(g, n, top)
    single = []
    for k in (stats["primes"], 1):
        moduli = list(modular.PRIMES[:k])
        cpow, logk = modular._factor_tables(moduli, [int(v) for v in scalars.values], scalars.q, n)
        primes = np.array(moduli, dtype=np.int64)
        t = time.process_time()
        z = modular._word_coefficients(np.asarray(letters, dtype=np.int64), cpow, logk, primes, g, n, len(lengths),
                                       top)
        t1 = time.process_time()
        modular._solve(z, primes, np.zeros((k, n + 1), dtype=np.int64), words, lengths, left, right, members,
                       class_start, g, n, top)
        single.append(f"{k} primes: word coefficients {t1 - t:.4f} solve {time.process_time() - t1:.4f}")
    cold = subprocess.run([sys.executable, "-c", COLD_PARTS, spec, str(n)], check=True, env=py_env, cwd=ROOT,
                          capture_output=True, text=True).stdout.split()
    cold = " ".join(f"{k} {float(v):.3f}" for k, v in zip(("import_nambu_bch", "import_numba", "first_compiled_call",
                                                           "series"), cold))
    return (f"#   {spec} {n}: engine call {engine:.4f} s ({parts}; {stats['primes']} primes, "
            f"{stats['program_nodes']} lane-nodes), trees {trees:.4f} s\n#     {'; '.join(single)}\n"
            f"#     cold process CPU s: {cold}")


def served_breakdown(spec: str, n: int, calls: int = 2000) -> str:
    """Where a warm call served from the table goes: the median over ``calls`` calls (wall and CPU, per call) of the
    whole call after ``clear_caches``, of the call without clearing anything, and of its parts -- reading the word,
    serving the request from the decoded table (``_from_table``: the request matched, ``D_d``, the result objects),
    decoding degrees ``1..n`` from the verified image (after ``table.clear_decoded``)."""
    from nambu_bch import clear_caches
    from nambu_bch.bch import formal, formal_bch, table
    from nambu_bch.bch.light import parse_word

    word = parse_word(spec)
    numerators = [c.numerator for c in word.coefficients]
    denominators = [c.denominator for c in word.coefficients]
    series = table._request([k - 1 for k in word.pieces], [a * (2 // b) for a, b in zip(numerators, denominators)], 2)
    header = table._header()

    def median(before, call):
        wall, cpu = [], []
        for _ in range(calls):
            before()
            t, c = time.perf_counter_ns(), time.process_time_ns()
            call()
            cpu.append(time.process_time_ns() - c)
            wall.append(time.perf_counter_ns() - t)
        return f"{statistics.median(wall) / 1e3:.1f}/{statistics.median(cpu) / 1e3:.1f}"

    nothing = lambda: None  # noqa: E731
    formal_bch(spec, n)
    parts = [
        ("call after clear_caches", median(clear_caches, lambda: formal_bch(spec, n))),
        ("call", median(nothing, lambda: formal_bch(spec, n))),
        ("word", median(nothing, lambda: parse_word(spec))),
        ("serve", median(nothing, lambda: formal._from_table(word, numerators, denominators, n))),
        ("decode", median(table.clear_decoded, lambda: table._load(header, series[0], n))),
    ]
    return (f"#   served {spec} {n}, median us per call (wall/CPU) of {calls}, load {os.getloadavg()[0]:.2f}: "
            + ", ".join(f"{name} {value}" for name, value in parts))


def c_terms(path: Path, letters: int) -> dict:
    """``{Lyndon word (letters 0..): Fraction}`` from the C table (standard factors p1, p2 per basis element)."""
    words, out = {}, {}
    with open(path) as fh:
        for line in fh:
            fields = line.split()
            if len(fields) != 5:
                continue
            i, d, p1, p2 = int(fields[0]), int(fields[1]), int(fields[2]), int(fields[3])
            words[i] = (i,) if d == 1 and i < letters else words[p1] + words[p2]
            c = Fraction(fields[4])
            if c:
                out[words[i]] = c
    return out


def our_terms(path: Path) -> dict:
    out = {}
    with open(path) as fh:
        for line in fh:
            word, num, den = line.split()
            out[tuple(int(k) - 1 for k in word)] = Fraction(int(num), int(den))  # piece k is the letter k - 1
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkout", type=Path, help="local checkout of github.com/HaraldHofstaetter/BCH (not vendored)")
    ap.add_argument("--degrees", default="10,12,14,16,18,20",
                    help="log(e^A e^B); 21-22 take minutes (the C program's and the engine's calls)")
    ap.add_argument("--sym-degrees", default="11,15,19", help="log(e^{A/2} e^B e^{A/2})")
    ap.add_argument("--three-degrees", default="9,11,13", help="the three-generator word 12321")
    ap.add_argument("--repeat", type=int, default=3, help="warm calls per side (median reported)")
    ap.add_argument("--build", action="store_true", help="run the checkout's Makefile first (make clean; make bch)")
    ap.add_argument("--breakdown", action="store_true",
                    help="after each row of our own, print where the time goes (a served series: the warm call's parts; "
                         "the engine: phases, one prime, cold start)")
    ap.add_argument("--work", type=Path, default=Path("/tmp/bch_c_reference"))
    args = ap.parse_args(argv)
    checkout = args.checkout.resolve()
    if not (checkout / "Makefile").exists() or not (checkout / "bch.c").exists():
        print(f"error: {checkout} is not a checkout of HaraldHofstaetter/BCH (no Makefile / bch.c)", file=sys.stderr)
        return 2
    if args.build:
        build(checkout)
    exe = checkout / "bch"
    if not exe.exists() or not (checkout / "libbch.so").exists():
        print(f"error: no bch / libbch.so in {checkout}: build it (make) or pass --build", file=sys.stderr)
        return 2
    if not TIME.exists():
        print(f"error: {TIME} is needed to measure the children's CPU time and peak RSS", file=sys.stderr)
        return 2
    args.work.mkdir(parents=True, exist_ok=True)

    from nambu_bch import clear_caches
    from nambu_bch.bch import formal, formal_bch, table
    from nambu_bch.integrators import composition

    def engine(spec, n):
        return formal._formal_engine(composition(spec), n)

    def by(spec, n):
        comp = composition(spec)
        values = [int(c * 2) for c in comp.coefficients]  # the three series' coefficients are in (1/2)Z
        served = table._request([k - 1 for k in comp.pieces], values, 2) is not None
        return "table" if served and n <= table.max_degree() else "engine"

    peer = Peer(checkout)
    c_env = dict(os.environ, OMP_NUM_THREADS="1", LD_LIBRARY_PATH=str(checkout))
    py_env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    # our side as installed: `pip install .` compiles the package's bytecode, and the C side is compiled ahead too;
    # with PYTHONDONTWRITEBYTECODE in the environment every cold child would compile our modules from source first
    # (the untimed priming run below writes the bytecode instead)
    no_bytecode = py_env.pop("PYTHONDONTWRITEBYTECODE", None) is not None
    subprocess.run([sys.executable, "-c", PRIME], check=True, env=py_env, cwd=ROOT)  # numba's disk cache filled
    formal_bch("123", 10)  # numba started in this process (the sparse engine has run)

    jobs = [("12", int(d)) for d in args.degrees.split(",") if d]
    jobs += [("121", int(d)) for d in args.sym_degrees.split(",") if d]
    jobs += [("12321", int(d)) for d in args.three_degrees.split(",") if d]
    print(f"# C: {exe} (CFLAGS '{CFLAGS}' with --build), OMP_NUM_THREADS=1; ours: {sys.executable}")
    print(f"# ours cold: the package's bytecode cached, as `pip install .` leaves it"
          + (" (PYTHONDONTWRITEBYTECODE removed from the children's environment)" if no_bytecode else ""))
    print(f"# warm = the call alone, in-process, median CPU s of --repeat calls (at least {SMALL_REPEAT} when a call "
          "takes under 10 ms); cold = whole process, CPU s (wall s), peak RSS MB; ratio = ours / C")
    print(f"{'series':>6} {'N':>3} {'terms':>6} | {'C warm':>8} {'ours warm':>9} {'by':>6} {'ratio':>6} {'+terms':>8} "
          f"{'engine':>8} {'ratio':>6} | "
          f"{'C cold':>15} {'ours cold':>15} {'ratio':>6} | {'C MB':>6} {'ours MB':>7} {'ratio':>6} | same  load")
    rows = []
    for series, n in jobs:
        spec, letters, expression, _ = SERIES[series]
        peer.call(series, n)  # untimed: pages touched, code loaded
        clear_caches()
        t = time.process_time()
        formal_bch(spec, n)
        repeat = args.repeat if time.process_time() - t > 0.01 else max(args.repeat, SMALL_REPEAT)
        source = by(spec, n)
        if source == "table":
            engine(spec, n)
        c_warm, ours_warm, engine_warm, terms_warm = [], [], [], []
        served = None
        for _ in range(repeat):  # C and ours interleaved, nothing else between them
            t = time.process_time()
            peer.call(series, n)
            c_warm.append(time.process_time() - t)
            # the previous round's result freed here, untimed: assigning the new one would free it inside the
            # timed call (the C call frees only its own series, and so does ours)
            served = None
            clear_caches()
            t = time.process_time()
            served = formal_bch(spec, n)
            ours_warm.append(time.process_time() - t)
            t = time.process_time()
            for d in range(1, n + 1):
                served.scaled_terms(d)
            terms_warm.append(time.process_time() - t)
        if source == "table":  # the engine alone, in rounds of its own (its memory traffic not between the sides)
            computed = None
            for _ in range(repeat):
                computed = None
                clear_caches()
                t = time.process_time()
                computed = engine(spec, n)
                engine_warm.append(time.process_time() - t)
            assert served == computed, (spec, n)  # the table's series is the engine's, numerator by numerator
            served = computed = None
        clear_caches()
        c_table, our_table = args.work / f"c_{series}_{n}.txt", args.work / f"ours_{series}_{n}.txt"
        c_args = [str(exe), f"N={n}", "table_output=1"] + ([f"expression={expression}"] if expression else [])
        with open(c_table, "w") as fh:
            c_cold = timed_child(c_args, c_env, args.work / "c.time", stdout=fh)
        ours_cold = timed_child([sys.executable, "-c", OURS_COLD, spec, str(n), str(our_table)], py_env,
                                args.work / "ours.time")
        ours = our_terms(our_table)
        same = c_terms(c_table, letters) == ours
        cw, ow = statistics.median(c_warm), statistics.median(ours_warm)
        ew = statistics.median(engine_warm) if engine_warm else ow
        tw = statistics.median(terms_warm)
        load = os.getloadavg()
        row = dict(series=series, degree=n, terms=len(ours), c_warm=cw, ours_warm=ow, by=source, terms_warm=tw,
                   engine_warm=ew,
                   c_cold=c_cold[:2],
                   ours_cold=ours_cold[:2], c_rss_mb=c_cold[2] / 1024, ours_rss_mb=ours_cold[2] / 1024,
                   identical=same, load=load)
        rows.append(row)
        print(f"{series:>6} {n:>3} {len(ours):>6} | {cw:>8.6f} {ow:>9.6f} {source:>6} {ow / cw:>5.2f}x {tw:>8.6f} "
              f"{ew:>8.6f} {ew / cw:>5.2f}x | "
              f"{c_cold[0]:>6.3f} ({c_cold[1]:>5.2f}) {ours_cold[0]:>6.3f} ({ours_cold[1]:>5.2f}) "
              f"{ours_cold[0] / max(c_cold[0], 0.005):>5.1f}x | {c_cold[2] / 1024:>6.1f} {ours_cold[2] / 1024:>7.1f} "
              f"{ours_cold[2] / c_cold[2]:>5.1f}x | {str(same):5} {load[0]:.2f}", flush=True)
        if args.breakdown:
            print(served_breakdown(spec, n) if source == "table" else breakdown(spec, n, py_env), flush=True)
    print("# cold ratio: CPU seconds, C times below 0.005 s (its process start) counted as 0.005 s.")
    print("# " + json.dumps({"load_end": os.getloadavg(), "rows": len(rows), "all_identical": all(r["identical"]
                                                                                               for r in rows)}))
    return 0 if all(r["identical"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
