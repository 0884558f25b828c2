"""Benchmark of nambu_bch.shadow: both routes, and the direct route against a plain-sympy baseline.

Run:  /work/venv/bin/python benchmarks/bench_shadow.py --targets  (the targets of the exact-data redesign, below)
      /work/venv/bin/python benchmarks/bench_shadow.py --targets --rows=ab  (target rows a and b only)
      /work/venv/bin/python benchmarks/bench_shadow.py            (the rows below, then the issue-14 rows)
      /work/venv/bin/python benchmarks/bench_shadow.py --issue14  (the issue-14 rows only)
      /work/venv/bin/python benchmarks/bench_shadow.py --printing (text/LaTeX/JSON: flint factors vs sympy.factor)
      /work/venv/bin/python benchmarks/bench_shadow.py --phases   (target b by phase: symbolic vs I = (1, 2, 3), h^8)
      /work/venv/bin/python benchmarks/bench_shadow.py --issue14 --rows=ab  (rows a and b only)
      /work/venv/bin/python benchmarks/bench_shadow.py --growth   (the cost per two orders h^6..h^12 by phase, with
                                                                   the sizes that bound each phase)
      /work/venv/bin/python benchmarks/bench_shadow.py --compare=BASELINE,. [--repeats=3]  (targets b and d in two
                                                                   checkouts, interleaved, each call cold)

Prints, measured in this one run (process CPU time, best of a few repeats):
* all six ho3 words through the FI route and the direct route at O(h^2);
* the direct route at O(h^6) for ho3 and O(h^4) for the rigid body;
* the same computation done with plain sympy from the start (the baseline, written below, run in a
  child process with a 60 s limit: when it hits the limit the ratio is printed as a lower bound), and
  the ratio baseline / ours.
The baseline calls nothing of the package's arithmetic: it builds the pieces' fields (determinants),
the composed map of the exact sub-flows as a series in ``h`` (Lie series, expanded sympy expressions),
the modified field by backward error analysis, and solves the polynomial ansatz order by order with
``sympy.linsolve`` (the free unknowns set to zero: a member of the family, not necessarily ours); its
result is checked, outside the timing, by ``X_{H_S,G_S} = X_eff`` in exact ring arithmetic.

The targets (``--targets``, :func:`targets`) time ours and the baseline cold, each in a fresh process,
in one run, and print CPU and wall seconds, peak RSS and the load average with every row.

The issue-14 rows (docs/history/performance.md, Sect. 3) time the whole ``shadow_hamiltonians`` call
in a fresh child process each (cold, CPU seconds), ours against the package's previous
elimination (``nambu_bch.algebra.elimination.FAST_PATHS = False``: sympy's sparse
``DomainMatrix.rref`` over the full coefficient field; this also switches off
the python-flint arithmetic over ``QQ(params)``: the elimination, the fraction-free fields and the
effective field's brackets, docs/history/performance.md Sect. 5), and for row c also against the
plain-sympy baseline; the two results are compared (members alpha = 0 and 1).
"""

from __future__ import annotations

import multiprocessing as mp
import sys
import time
from itertools import product

import sympy

from timing import cpu  # benchmarks/timing.py (the script's directory is on sys.path)

from nambu_bch import PAPER_WORDS, System, liouville_field, model
from nambu_bch.bch import effective_field
from nambu_bch.shadow import shadow_hamiltonians

H = sympy.Symbol("h")



def _liouville(xs, *fs):
    """``X_{f_1 .. f_{N-1}}`` (Eq. gLiouville) as expanded sympy expressions: ``X^i = det(e_i; grad f_1; ..)``."""
    grads = [[sympy.diff(f, x) for x in xs] for f in fs]
    out = []
    for i in range(len(xs)):
        rows = [[1 if j == i else 0 for j in range(len(xs))]] + grads
        out.append(sympy.expand(sympy.Matrix(rows).det()))
    return out


def _lie(field, f, xs):
    """``L_X f = sum_i X^i df/dx_i``, expanded."""
    return sympy.expand(sum(c * sympy.diff(f, x) for c, x in zip(field, xs) if c != 0))


def plain_sympy_map(system, word, top):
    """The composed map of the exact sub-flows as a series in ``h`` through ``h^top``, all in plain sympy.

    Each piece's field is built from its Liouville terms (determinants); the exact flow of ``c h X`` pulls a
    function back by its Lie series ``exp(c h L_X) f`` (Taylor's theorem for the flow, exact order by order in
    ``h``), and the composition pulls back through the steps in reverse.  Returns ``[[phi_0^i, .., phi_top^i]]``
    per coordinate (``Phi(x)_i = sum_m h^m phi_m^i``).
    """
    from nambu_bch.integrators.composition import composition_for

    xs = list(system.coordinates)
    comp = composition_for(word, system.splitting)  # the word's pieces and step coefficients only
    fields = {}
    for piece in system.splitting.pieces:
        parts = [_liouville(xs, *term) for term in piece.terms]
        fields[piece.number] = [sympy.expand(sum(c)) for c in zip(*parts)]
    out = []
    for x in xs:
        g = [x] + [sympy.Integer(0)] * top  # coefficients of h^0 .. h^top
        for k, c in zip(reversed(comp.pieces), reversed(comp.coefficients)):
            X = fields[k]
            new = [sympy.Integer(0)] * (top + 1)
            for m, gm in enumerate(g):
                term, fact = gm, sympy.Integer(1)
                for kk in range(0, top + 1 - m):
                    if term == 0:
                        break
                    new[m + kk] += fact * term
                    term = _lie(X, term, xs)
                    fact = fact * c / (kk + 1)
            g = [sympy.expand(t) for t in new]
        out.append(g)
    return out


def plain_sympy_field(system, word, order):
    """``Z_0 .. Z_order`` of the modified field (backward error analysis) from :func:`plain_sympy_map`.

    ``exp(h L_Y) x = Phi(x)`` with ``Y = sum_l h^l Z_l``: ``[h^n] (h L_Y)^k x = U(k, n)``,
    ``U(1, n) = Z_(n-1)``, ``U(k, n) = sum_l L_(Z_l) U(k-1, n-1-l)``, so
    ``Z_j = phi_(j+1) - sum_(k>=2) U(k, j+1)/k!`` needs only ``Z_l``, ``l < j``.
    """
    xs = list(system.coordinates)
    phi = plain_sympy_map(system, word, order + 1)
    Z, memo = [], {}

    def U(k, n):
        if k == 1:
            return Z[n - 1]
        if (k, n) not in memo:
            total = [sympy.Integer(0)] * len(xs)
            for l in range(0, n - k + 1):
                prev = U(k - 1, n - 1 - l)
                total = [t + _lie(Z[l], p, xs) for t, p in zip(total, prev)]
            memo[(k, n)] = [sympy.expand(t) for t in total]
        return memo[(k, n)]

    for j in range(order + 1):
        rest = [sympy.Integer(0)] * len(xs)
        for k in range(2, j + 2):
            rest = [r + u / sympy.factorial(k) for r, u in zip(rest, U(k, j + 1))]
        Z.append([sympy.expand(phi[i][j + 1] - rest[i]) for i in range(len(xs))])
    return Z


def baseline(system, word, order, degrees=None):
    """The direct route with plain sympy only (N = 3): the map and the modified field of :func:`plain_sympy_field`,
    unknown coefficients, expanded expressions, ``sympy.linsolve`` per order, the free unknowns set to zero.

    ``degrees``: ``order -> ansatz degree``; default the least degree reaching the right-hand side's degree.
    Nothing of the package is called but the system's data (coordinates, Hamiltonians, pieces) and the word's
    step coefficients.
    """
    xs = list(system.coordinates)
    Hs = [sympy.expand(Hk) for Hk in system.hamiltonians]
    eff = plain_sympy_field(system, word, order)
    gdeg = [sympy.Poly(Hk, *xs).total_degree() - 1 for Hk in Hs]
    corrections = {}
    for j in range(1, order + 1):
        rhs = list(eff[j])
        for a, b in product(range(1, j), repeat=2):
            if a + b == j and (0, a) in corrections and (1, b) in corrections:
                rhs = [r - c for r, c in zip(rhs, _liouville(xs, corrections[(0, a)], corrections[(1, b)]))]
        if all(r == 0 for r in rhs):
            continue
        rdeg = max(sympy.Poly(r, *xs).total_degree() for r in rhs if r != 0)
        D = degrees[j] if degrees else max(1, rdeg + 1 - min(gdeg))
        monos = [sympy.Mul(*(x**e for x, e in zip(xs, exps))) for exps in product(range(D + 1), repeat=len(xs)) if sum(exps) <= D]
        cH = sympy.symbols(f"a{j}_0:{len(monos)}")
        cG = sympy.symbols(f"b{j}_0:{len(monos)}")
        dH = sympy.Add(*(c * mo for c, mo in zip(cH, monos)))
        dG = sympy.Add(*(c * mo for c, mo in zip(cG, monos)))
        lhs = [p + q for p, q in zip(_liouville(xs, dH, Hs[1]), _liouville(xs, Hs[0], dG))]
        eqs = []
        for l, r in zip(lhs, rhs):
            eqs += sympy.Poly(sympy.expand(l - r), *xs).coeffs()
        sols = sympy.linsolve(eqs, cH + cG)
        if not sols:
            return None
        zero = {c: sympy.Integer(0) for c in cH + cG}  # the free unknowns (linsolve's parameters) set to zero
        values = [v.xreplace(zero) for v in next(iter(sols))]
        corrections[(0, j)] = sympy.expand(sympy.Add(*(v * mo for v, mo in zip(values[: len(monos)], monos))))
        corrections[(1, j)] = sympy.expand(sympy.Add(*(v * mo for v, mo in zip(values[len(monos):], monos))))
    return tuple(sympy.expand(Hk + sum(H**j * corrections.get((a, j), 0) for j in range(1, order + 1)))
                 for a, Hk in enumerate(Hs))


def check_solution(system, word, order, shadows):
    """Is X_{H_S,G_S} = X_eff through h^order?  (exact ring arithmetic, backward-error X_eff)"""
    eff = effective_field(system.splitting, word, order)
    alg = eff[0].algebra
    X = liouville_field(alg, *(alg.convert(sympy.expand(S)) for S in shadows))
    ih = alg.n + alg.constants.index(H)
    for j in range(order + 1):
        for comp, Z in zip(X.components, eff[j].components):
            part = {mono[:ih] + (0,) + mono[ih + 1:]: c for mono, c in comp.items() if mono[ih] == j}
            if alg.ring.from_dict(part) != Z:
                return False
    return True


N4 = ["x1**2/2 + x2**2/2 + x3**2/2 + x4**2/2", "x1**2/2 + x2**2 + 3*x3**2/2 + 2*x4**2", "x1 + x2 + x3 + x4"]


def make_system(name):
    """The systems of the benchmark by name (catalog models, rigid body with I = 1, 2, 3, N = 4 single split)."""
    if name == "rigid-body[I=1,2,3]":
        return model("rigid-body").substitute({"I1": 1, "I2": 2, "I3": 3})
    if name == "n4-single":
        return System("x1 x2 x3 x4", N4, name="n4-single", split="single")
    return model(name)


def _timed_baseline(args, queue):
    name, word, order, degrees = args
    system = make_system(name)
    t = time.process_time()
    out = baseline(system, word, order, degrees)
    queue.put((time.process_time() - t, out is not None and check_solution(system, word, order, out)))


def baseline_with_limit(name, word, order, degrees, limit):
    """The baseline in a child process; ``(seconds, valid)`` or ``(limit, None)`` when it exceeds ``limit``."""
    queue = mp.Queue()
    proc = mp.Process(target=_timed_baseline, args=((name, word, order, degrees), queue))
    proc.start()
    proc.join(limit)
    if proc.is_alive():
        proc.terminate()
        proc.join()
        return limit, None
    return queue.get()


def _timed_ours(args, queue):
    name, word, order, fast = args
    from nambu_bch.algebra import elimination

    elimination.FAST_PATHS = fast
    system = make_system(name)
    t = time.process_time()
    fam = shadow_hamiltonians(system, word, order)
    dt = time.process_time() - t
    queue.put((dt, [tuple(map(str, fam.member(alpha=a))) for a in (0, 1)], fam.degree))


def _peak_mb(pid):
    """The peak resident set (``VmHWM``) of a live process in MB, or None (not Linux, gone)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            return next(int(line.split()[1]) / 1024 for line in f if line.startswith("VmHWM:"))
    except (OSError, StopIteration, ValueError):
        return None


def _child(target, args, limit, stopped=None):
    """``target(args, queue)`` in a fresh process; its result, or ``None`` after ``limit`` seconds.

    ``stopped``: a dict that receives the peak RSS in MB (``"rss"``) of a child stopped at the limit.
    """
    import queue as queues

    queue = mp.Queue()
    proc = mp.Process(target=target, args=(args, queue))
    proc.start()
    try:
        out = queue.get(timeout=limit)  # before join: a child with a large result waits until it is read
    except queues.Empty:
        out = None
    if proc.is_alive():
        if out is None and stopped is not None:
            stopped["rss"] = _peak_mb(proc.pid)
        proc.terminate()
    proc.join()
    return out


ISSUE14 = [  # (row, system, word, order, goal in s)
    ("a: rigid body, symbolic I, 12321, h^8", "rigid-body", "12321", 8, 3.0),
    ("b: rigid body, symbolic I, yoshida:12321, h^4", "rigid-body", "yoshida:12321", 4, 3.0),
    ("b: ho3 yoshida:12321, h^8", "ho3", "yoshida:12321", 8, 3.0),
    ("c: rigid body, I = 1, 2, 3, 12321, h^8", "rigid-body[I=1,2,3]", "12321", 8, None),
    ("c: rigid body, I = 1, 2, 3, 12321, h^10", "rigid-body[I=1,2,3]", "12321", 10, None),
    ("c: rigid body, I = 1, 2, 3, 12321, h^12", "rigid-body[I=1,2,3]", "12321", 12, None),
    ("d: N = 4 single split, 1234321, h^4", "n4-single", "1234321", 4, 5.0),
    ("d: N = 4 single split, 1234321, h^6", "n4-single", "1234321", 6, 30.0),
]


def issue14(limit: float = 150.0, only=None):
    """The issue-14 rows: ours and the previous elimination, each cold in a child process (CPU s).

    ``only``: the row letters to run (e.g. ``"ab"``; ``--rows=ab`` on the command line), default all.
    """
    import os

    print(f"the --issue14 rows (cold child process each, CPU s; load average {os.getloadavg()[0]:.1f})")
    rows = []
    for label, name, word, order, goal in ISSUE14:
        if only and label[0] not in only:
            continue
        ours = _child(_timed_ours, (name, word, order, True), limit)
        before = _child(_timed_ours, (name, word, order, False), limit)
        t_ours = ours[0] if ours else None
        t_before = before[0] if before else limit
        same = None if not (ours and before) else ours[1] == before[1] or _same_members(name, ours[1], before[1])
        line = (f"{label}: ours {'>' + str(limit) if t_ours is None else f'{t_ours:.2f}'} s, previous elimination "
                f"{'>' if before is None else ''}{t_before:.2f} s")
        if t_ours:
            line += f", ratio {'>' if before is None else ''}{t_before / t_ours:.1f}x"
        if goal:
            line += f", goal < {goal:g} s: {'met' if t_ours is not None and t_ours < goal else 'not met'}"
        line += f"  (same members: {same})"
        if name == "rigid-body[I=1,2,3]" and order == 8 and ours:
            t_base, ok = baseline_with_limit(name, word, order, ours[2], 60.0)
            line += (f"; plain sympy (exact map + sympy.linsolve) {'>' if ok is None else ''}{t_base:.2f} s, "
                     f"ratio {'>' if ok is None else ''}{t_base / t_ours:.1f}x (goal >= 50x; baseline valid: {ok})")
        print(line, flush=True)
        rows.append((label, t_ours, t_before, same))
    return rows


def _timed_run(args, queue):
    """One call in a fresh process: ``(CPU s, wall s, peak RSS in MB, members)`` of ours, or of the plain baseline."""
    import resource

    side, name, word, order, *verify = args
    system = make_system(name)
    t, w = time.process_time(), time.perf_counter()
    if side == "ours":  # the family and its shadows as sympy expressions (what the baseline returns)
        fam = shadow_hamiltonians(system, word, order)
        out = fam.shadows
    else:
        out = baseline(system, word, order)
    cpu_s, wall_s = time.process_time() - t, time.perf_counter() - w
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux
    if side == "ours":
        members = [tuple(map(str, fam.member(alpha=a))) for a in (0, 1)]
        if verify:  # outside the timed part: X_{H_S,G_S} = X_eff through h^order for both members (exact ring)
            members = all(check_solution(system, word, order, fam.member(alpha=a)) for a in (0, 1))
    else:  # checked outside the timed part (exact ring arithmetic, the package's X_eff)
        members = out is not None and check_solution(system, word, order, out)
    queue.put((cpu_s, wall_s, rss, members))


def _load() -> str:
    import os

    return "load " + "/".join(f"{v:.1f}" for v in os.getloadavg())


def _shown(run, limit) -> str:
    if run is None:
        return f"> {limit:g} s (stopped)"
    return f"{run[0]:.2f} s CPU, {run[1]:.2f} s wall, peak RSS {run[2]:.0f} MB"


TARGET_ORDERS = {"ho3": (6, 8, 10, 12), "rigid-body": (6, 8, 10, 12), "lotka-volterra": (6, 8, 10, 12)}


def targets(limit: float = 600.0, only=None):
    """The targets of the exact-data redesign, each side cold in a fresh process, in this one run.

    Rows (``only``: the letters to run, e.g. ``"ab"``):
    a. rigid body I = (1, 2, 3), 12321, h^8: ours against :func:`baseline` (plain sympy throughout), goal >= 50x;
    b. symbolic rigid body against I = (1, 2, 3) at h^8 (goal <= 2x), and symbolic h^10 (goal <= 60 s CPU);
    c. the N = 4 single split, 1234321, h^8: finishes, peak RSS (goal < 1 GB);
    d. cost per two orders, h^6 to h^12, for ho3, the symbolic rigid body and Lotka-Volterra (goal <= 2x).
    """
    print(f"targets (each side cold in a fresh process; {_load()})", flush=True)
    ok = True
    ours_123 = None
    if not only or "a" in only:
        ours_123 = _child(_timed_run, ("ours", "rigid-body[I=1,2,3]", "12321", 8), limit)
        plain = _child(_timed_run, ("plain", "rigid-body[I=1,2,3]", "12321", 8), limit)
        line = f"a: rigid body I = (1, 2, 3), 12321, h^8: ours {_shown(ours_123, limit)}; plain sympy {_shown(plain, limit)}"
        if ours_123:
            base = plain[0] if plain else limit
            ratio = base / ours_123[0]
            wall = (plain[1] if plain else limit) / ours_123[1]
            line += (f"; ratio {'>' if plain is None else ''}{ratio:.1f}x CPU, {'>' if plain is None else ''}{wall:.1f}x wall "
                     f"(goal >= 50x: {'met' if ratio >= 50 else 'not met'}; baseline valid: "
                     f"{None if plain is None else plain[3]})")
            ok = ok and (plain is None or plain[3] is True)
        print(line + f"  [{_load()}]", flush=True)
    if not only or "b" in only:
        if ours_123 is None:
            ours_123 = _child(_timed_run, ("ours", "rigid-body[I=1,2,3]", "12321", 8), limit)
        sym8 = _child(_timed_run, ("ours", "rigid-body", "12321", 8), limit)
        line = f"b: symbolic rigid body, 12321, h^8: {_shown(sym8, limit)}"
        if sym8 and ours_123:
            ratio = sym8[0] / ours_123[0]
            line += f"; against I = (1, 2, 3): {ratio:.1f}x CPU (goal <= 2x: {'met' if ratio <= 2 else 'not met'})"
        print(line + f"  [{_load()}]", flush=True)
        sym10 = _child(_timed_run, ("ours", "rigid-body", "12321", 10), limit)
        line = f"b: symbolic rigid body, 12321, h^10: {_shown(sym10, limit)}"
        line += f" (goal <= 60 s CPU: {'met' if sym10 and sym10[0] <= 60 else 'not met'})"
        print(line + f"  [{_load()}]", flush=True)
    if not only or "c" in only:
        stopped: dict = {}
        n4 = _child(_timed_run, ("ours", "n4-single", "1234321", 8, True), limit, stopped)
        line = f"c: N = 4 single split, 1234321, h^8: {_shown(n4, limit)}"
        if n4:
            line += (f" (finishes; goal peak RSS < 1 GB: {'met' if n4[2] < 1024 else 'not met'}; "
                     f"X_(H_S,G_S) = X_eff through h^8 for alpha = 0, 1: {n4[3]})")
            ok = ok and n4[3] is True
        elif stopped.get("rss") is not None:
            line += f", peak RSS {stopped['rss']:.0f} MB when stopped (goal: finishes, < 1 GB: not met)"
        print(line + f"  [{_load()}]", flush=True)
    if not only or "d" in only:
        for name, orders in TARGET_ORDERS.items():
            runs = [(k, _child(_timed_run, ("ours", name, "12321", k), limit)) for k in orders]
            parts, worst = [], 0.0
            for (k0, r0), (k1, r1) in zip(runs, runs[1:]):
                if r0 and r1:
                    ratio = r1[0] / r0[0]
                    worst = max(worst, ratio)
                    parts.append(f"h^{k0}->h^{k1} {ratio:.1f}x")
                else:
                    parts.append(f"h^{k0}->h^{k1} n/a")
            times = ", ".join(f"h^{k} " + ("stopped" if r is None else f"{r[0]:.2f} s") for k, r in runs)
            print(f"d: {name}, 12321, CPU per order: {times}; per two orders: {', '.join(parts)} "
                  f"(goal <= 2x: {'met' if worst and worst <= 2 and all(r for _, r in runs) else 'not met'})  [{_load()}]",
                  flush=True)
    return ok


def _timed_printing(args, queue):
    """The text, LaTeX and JSON of one family in a fresh process, CPU seconds of the three outputs only: the
    coefficients factored by python-flint (``"flint"``, the package's way) or by ``sympy.factor`` per coefficient
    (``"sympy"``: ``NAMBU_BCH_DISABLE_FLINT=1`` switched on after the solve, which the printing reads)."""
    import os

    how, name, word, order = args
    fam = shadow_hamiltonians(make_system(name), word, order)
    if how == "sympy":
        os.environ["NAMBU_BCH_DISABLE_FLINT"] = "1"
    t = time.process_time()
    outputs = (fam.to_text(), fam.to_latex(), str(fam.to_dict()))
    queue.put((time.process_time() - t, outputs))


PRINTING = [("rigid-body", "12321", 4), ("rigid-body", "12321", 6), ("ho3", "12321", 8), ("lotka-volterra", "12321", 8)]


def printing(limit: float = 900.0):
    """Text + LaTeX + JSON of a family, coefficients factored by flint against ``sympy.factor``: each side cold in a
    fresh process, interleaved, the outputs compared byte for byte (CPU seconds of the printing alone)."""
    print(f"printing: text + LaTeX + JSON, flint factors vs sympy.factor (CPU s of the outputs; {_load()})", flush=True)
    same = True
    for name, word, order in PRINTING:
        ours = _child(_timed_printing, ("flint", name, word, order), limit)
        plain = _child(_timed_printing, ("sympy", name, word, order), limit)
        line = f"{name}, {word}, h^{order}: flint {'stopped' if ours is None else f'{ours[0]:.2f} s'}, " \
               f"sympy.factor {'stopped' if plain is None else f'{plain[0]:.2f} s'}"
        if ours and plain:
            line += f", ratio {plain[0] / ours[0]:.1f}x, outputs identical: {ours[1] == plain[1]}"
            same = same and ours[1] == plain[1]
        print(line + f"  [{_load()}]", flush=True)
    return same


def _same_members(name, u, v):
    """The members printed differently: equal as expressions (algebraic fields have no unique normal form)."""
    return all(sympy.expand(sympy.together(sympy.sympify(p) - sympy.sympify(q))) == 0
               for mu, mv in zip(u, v) for p, q in zip(mu, mv))


def main(limit: float = 60.0):
    ho3 = model("ho3")
    print("nambu_bch.shadow benchmark (process CPU seconds, best of 3)")

    t_fi, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, 2, route="fi") for w in PAPER_WORDS])
    t_di, _ = cpu(lambda: [shadow_hamiltonians(ho3, w, 2, route="direct") for w in PAPER_WORDS])
    print(f"ho3, six words, O(h^2): FI route {t_fi:.3f} s, direct route {t_di:.3f} s, both {t_fi + t_di:.3f} s")

    rows = []
    for label, name, word, order in [("ho3 12321 O(h^6)", "ho3", "12321", 6), ("ho3 32123 O(h^4)", "ho3", "32123", 4),
                                     ("rigid-body 12321 O(h^2)", "rigid-body", "12321", 2),
                                     ("rigid-body 12321 O(h^4)", "rigid-body", "12321", 4)]:
        system = make_system(name)
        t_ours, fam = cpu(lambda: shadow_hamiltonians(system, word, order), repeat=2)
        ours_ok = check_solution(system, word, order, fam.member(alpha=0))
        t_base, ok = baseline_with_limit(name, word, order, fam.degree, limit)
        bound = ">" if ok is None else ""
        rows.append((label, t_ours, t_base, ok, ours_ok))
        print(f"{label}: ours {t_ours:.3f} s, plain-sympy baseline {bound}{t_base:.3f} s, "
              f"ratio {bound}{t_base / t_ours:.1f}x  (baseline valid: {'timed out' if ok is None else ok}, ours valid: {ours_ok})")
    return rows


#: the phases of a direct-route call, timed by wrapping these functions (module, attribute path, label); nested
#: phases are counted inside their parent too (``frac_rref.rref`` inside the elimination)
PHASES = [
    ("nambu_bch.bch.backward", "modified_field_of_map", "backward error analysis (X_eff)"),
    ("nambu_bch.shadow.direct_route", "operator_columns", "operator columns (Liouville fields)"),
    ("nambu_bch.shadow.direct_route", "_Solver._cross", "cross terms"),
    ("nambu_bch.algebra.ansatz", "Ansatz.solve_canonical", "eliminations (both members)"),
    ("nambu_bch.algebra.frac_rref", "rref", "  of which Gauss-Jordan on flint pairs"),
    ("nambu_bch.algebra.frac_rref", "to_field", "flint pair -> sympy field element (all)"),
    ("nambu_bch.algebra.ansatz", "Ansatz.member", "alpha = 1 member by reduction"),
    ("nambu_bch.shadow.direct_route", "_Solver._family", "alpha-family combination"),
    ("nambu_bch.shadow.direct_route", "DirectResult.shadow", "sympy sums of H_S, G_S"),
]


def _timed_phases(args, queue):
    """One ``shadow_hamiltonians(...).shadows`` in a fresh process: ``(CPU s, {label: CPU s})`` by :data:`PHASES`."""
    name, word, order = args
    spent = _install_phase_timers()
    system = make_system(name)
    t = time.process_time()
    shadow_hamiltonians(system, word, order).shadows
    queue.put((time.process_time() - t, dict(spent)))


def _install_phase_timers():
    """Wrap the functions of :data:`PHASES` so that each adds its CPU seconds to the returned counter (by label)."""
    import importlib
    from collections import Counter

    spent: Counter = Counter()
    for module, path, label in PHASES:
        owner = importlib.import_module(module)
        *outer, attr = path.split(".")
        for part in outer:
            owner = getattr(owner, part)
        if attr not in owner.__dict__:  # a phase an older tree does not have (compared trees print the same table)
            continue
        inner = owner.__dict__[attr]
        wrapped = inner.__func__ if isinstance(inner, staticmethod) else inner

        def timed(*a, _f=wrapped, _label=label, **k):
            t = time.process_time()
            try:
                return _f(*a, **k)
            finally:
                spent[_label] += time.process_time() - t

        setattr(owner, attr, staticmethod(timed) if isinstance(inner, staticmethod) else timed)
    return spent


def phases(limit: float = 600.0):
    """Target b by phase: the symbolic rigid body and I = (1, 2, 3), 12321, h^8, each cold in a fresh process."""
    print(f"target b by phase (CPU s, each side cold in a fresh process; {_load()})", flush=True)
    runs = [(name, _child(_timed_phases, (name, "12321", 8), limit)) for name in ("rigid-body", "rigid-body[I=1,2,3]")]
    if not all(r for _, r in runs):
        print("stopped at the limit", flush=True)
        return False
    (_, (sym, ps)), (_, (num, pn)) = runs
    print(f"{'phase':42s} {'symbolic I':>11s} {'I = (1,2,3)':>12s}")
    for _, _, label in PHASES:
        print(f"{label:42s} {ps.get(label, 0.0):11.3f} {pn.get(label, 0.0):12.3f}")
    print(f"{'whole call':42s} {sym:11.3f} {num:12.3f}   ratio {sym / num:.1f}x  [{_load()}]", flush=True)
    return True


#: the phases of :data:`PHASES` that run inside another one (left out of the sum that gives "rest")
NESTED = ("  of which Gauss-Jordan on flint pairs", "flint pair -> sympy field element (all)")
GROWTH_ORDERS = (6, 8, 10, 12)
GROWTH_SYSTEMS = ("rigid-body", "rigid-body[I=1,2,3]", "lotka-volterra")


def _sizes(fam) -> dict:
    """The sizes that bound a direct-route call's phases, read off its exact result (outside the timed part).

    unknowns / rank: summed over the solved orders (``slots * C(D + n, n)`` columns, rank = columns - kernel);
    top unknowns: of the highest order; exact terms: the corrections' (monomial, numerator term) pairs, the size of
    the exact output; output terms: the terms of the printed sums ``H_S, G_S``; numerator / denominator degree: the
    largest total degree in the parameters of a coefficient of the corrections (0 without parameters).
    """
    R = fam.details
    n, slots = R.algebra.n, len(R.hamiltonians)
    from nambu_bch.algebra.ansatz import Ansatz

    solved = [o for o in R.orders if o.status == "solved"]
    unknowns = [Ansatz.size(n, o.degree, slots) for o in solved]
    rank = sum(u - o.kernel_dim for u, o in zip(unknowns, solved))
    exact, num_deg, den_deg = 0, 0, 0
    fraction = getattr(R.algebra.domain, "is_FractionField", False)
    for c in R.corrections.values():
        for v in c.values():
            if not fraction:  # a rational number
                exact += 1
                continue
            numer, denom = v.numer, v.denom
            exact += len(numer)
            num_deg = max(num_deg, max(sum(e) for e in numer.keys()))
            den_deg = max(den_deg, max(sum(e) for e in denom.keys()))
    terms = sum(len(sympy.Add.make_args(S)) for S in fam.shadows)
    return {"unknowns (all orders)": sum(unknowns), "unknowns (top order)": unknowns[-1] if unknowns else 0,
            "rank (all orders)": rank, "exact output terms": exact, "printed output terms": terms,
            "numerator degree (params)": num_deg, "denominator degree (params)": den_deg}


def _timed_growth(args, queue):
    """One ``shadow_hamiltonians(...).shadows`` by phase (:func:`_timed_phases`) and its :func:`_sizes`."""
    name, word, order = args
    spent = _install_phase_timers()
    system = make_system(name)
    t = time.process_time()
    fam = shadow_hamiltonians(system, word, order)
    fam.shadows
    whole = time.process_time() - t
    queue.put((whole, dict(spent), _sizes(fam)))


def growth(limit: float = 900.0, systems=GROWTH_SYSTEMS, orders=GROWTH_ORDERS):
    """The cost per two orders, phase by phase, next to the sizes that bound each phase (target d of the exact-data redesign).

    For each system and each order of ``orders`` one cold process computes ``shadow_hamiltonians(system, "12321",
    order).shadows`` with the phases of :data:`PHASES` timed (CPU s), then reads the sizes of :func:`_sizes`; the
    table prints each row per order and its growth factor per two orders.  ``rest`` is the whole call less the
    outermost phases (conversions of the input, the ansatz and row interning, the effective field's setup).
    No algorithm is cheaper than writing its output, so a phase that grows like the output terms is at its floor
    in growth; one that grows faster is the one to cut.
    """
    print(f"growth per two orders, 12321 (CPU s by phase, each order cold in a fresh process; {_load()})", flush=True)
    ok = True
    for name in systems:
        runs = {}
        for k in orders:
            r = _child(_timed_growth, (name, "12321", k), limit)
            if r is None:
                print(f"{name} h^{k}: stopped at {limit:g} s", flush=True)
                ok = False
                break
            runs[k] = r
        ks = [k for k in orders if k in runs]
        if not ks:
            continue
        rows = []
        for _, _, label in PHASES:
            rows.append((label, [runs[k][1].get(label, 0.0) for k in ks], True))
        outer = [label for _, _, label in PHASES if label not in NESTED]
        rows.append(("rest", [runs[k][0] - sum(runs[k][1].get(l, 0.0) for l in outer) for k in ks], True))
        rows.append(("whole call", [runs[k][0] for k in ks], True))
        for label in runs[ks[0]][2]:
            rows.append((label, [runs[k][2][label] for k in ks], False))
        heads = "".join(f"{'h^%d' % k:>9s}" for k in ks)
        steps = "".join(f"{'%d->%d' % (a, b):>8s}" for a, b in zip(ks, ks[1:]))
        print(f"\n{name}  [{_load()}]\n{'':40s}{heads}  per two orders:{steps}")
        for label, values, is_time in rows:
            shown = "".join(f"{v:9.3f}" if is_time else f"{v:9d}" for v in values)
            ratios = "".join(f"{b / a:7.2f}x" if a > 0 else f"{'-':>8s}" for a, b in zip(values, values[1:]))
            print(f"{label:40s}{shown}  {'':15s}{ratios}")
        sys.stdout.flush()
    return ok


#: the rows of :func:`compare`: targets b (the rigid body with symbolic and numeric moments at h^8) and d
COMPARE_ROWS = [(name, k) for name in GROWTH_SYSTEMS for k in GROWTH_ORDERS]
#: the phase :func:`compare` prints beside the whole call (the one this session's change is in)
COMPARE_PHASE = "cross terms"


def _one(name, order):
    """``--one NAME ORDER``: one ``shadow_hamiltonians(..).shadows`` in this process, its phases timed
    (:data:`PHASES`), printed as one JSON line ``{"cpu": s, "wall": s, "phases": {label: s}}``."""
    import json

    spent = _install_phase_timers()
    system = make_system(name)
    t, w = time.process_time(), time.perf_counter()
    shadow_hamiltonians(system, "12321", order).shadows
    print(json.dumps({"cpu": time.process_time() - t, "wall": time.perf_counter() - w, "phases": dict(spent)}))


def compare(trees, repeats: int = 1, limit: float = 900.0):
    """The rows of :data:`COMPARE_ROWS` in each checkout of ``trees``, interleaved (tree after tree for each row and
    repeat), each call cold in a fresh process (``PYTHONPATH`` the checkout): the best CPU s per tree, the ratio to
    the first tree, and the growth per two orders of each tree for the rows of target d.  Every call runs with the
    phase timers of :data:`PHASES` (the same small overhead in every tree); the best CPU s of :data:`COMPARE_PHASE`
    is printed beside the call's."""
    import json
    import os
    import subprocess

    print(f"both trees interleaved, each call cold in a fresh process, best CPU s of {repeats}; trees: "
          + ", ".join(f"[{i}] {t}" for i, t in enumerate(trees)) + f"  [{_load()}]", flush=True)
    best: dict = {}
    for name, order in COMPARE_ROWS:
        for _ in range(repeats):
            for i, tree in enumerate(trees):
                env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
                run = subprocess.run([sys.executable, os.path.abspath(__file__), "--one", name, str(order)],
                                     env=env, capture_output=True, text=True, timeout=limit)
                out = json.loads(run.stdout.strip().splitlines()[-1]) if run.returncode == 0 else None
                cpu_s = out["cpu"] if out else float("nan")
                phase_s = out["phases"].get(COMPARE_PHASE, 0.0) if out else float("nan")
                key = (name, order, i)
                best[key] = min(best.get(key, cpu_s), cpu_s)
                best[key + ("phase",)] = min(best.get(key + ("phase",), phase_s), phase_s)
        values = [best[(name, order, i)] for i in range(len(trees))]
        phase = [best[(name, order, i, "phase")] for i in range(len(trees))]
        print(f"{name:22s} h^{order:<3d}" + "".join(f" [{i}] {v:7.3f} s" for i, v in enumerate(values))
              + "".join(f"  [{i}]/[0] {v / values[0]:.2f}" for i, v in enumerate(values) if i)
              + f"  | {COMPARE_PHASE}:" + "".join(f" [{i}] {v:6.3f} s" for i, v in enumerate(phase))
              + "".join(f"  [{i}]/[0] {v / phase[0]:.2f}" for i, v in enumerate(phase) if i and phase[0] > 0)
              + f"  [{_load()}]", flush=True)
    for name in GROWTH_SYSTEMS:
        for i in range(len(trees)):
            ts = [best[(name, k, i)] for k in GROWTH_ORDERS]
            steps = ", ".join(f"h^{a}->h^{b} {y / x:.2f}x" for a, b, x, y in zip(GROWTH_ORDERS, GROWTH_ORDERS[1:], ts, ts[1:]))
            print(f"per two orders, {name} [{i}]: {steps}")
    b = [best[("rigid-body", 8, i)] / best[("rigid-body[I=1,2,3]", 8, i)] for i in range(len(trees))]
    print("target b, symbolic / numeric at h^8: " + ", ".join(f"[{i}] {v:.1f}x" for i, v in enumerate(b)), flush=True)
    return True


if __name__ == "__main__":
    ok = True
    if "--one" in sys.argv:
        at = sys.argv.index("--one")
        _one(sys.argv[at + 1], int(sys.argv[at + 2]))
        sys.exit(0)
    if any(a.startswith("--compare=") for a in sys.argv):
        trees = next(a.split("=", 1)[1] for a in sys.argv if a.startswith("--compare=")).split(",")
        repeats = int(next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--repeats=")), 1))
        sys.exit(0 if compare(trees, repeats) else 1)
    if "--growth" in sys.argv:
        sys.exit(0 if growth() else 1)
    if "--phases" in sys.argv:
        sys.exit(0 if phases() else 1)
    if "--printing" in sys.argv:
        sys.exit(0 if printing() else 1)
    if "--targets" in sys.argv:
        only = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--rows=")), None)
        sys.exit(0 if targets(only=only) else 1)
    if "--issue14" not in sys.argv:
        ok = all(r[3] is not False and r[4] for r in main())
    only = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--rows=")), None)
    ok = all(r[3] is not False for r in issue14(only=only)) and ok
    sys.exit(0 if ok else 1)
