"""Errors of a complex-coefficient splitting along long runs, and the speed of its compiled and interpreted runs.

Default: the numbers docs/integrators.md ("Complex coefficients") quotes: for the Strang step 12321 of ho3 composed
at the complex times (1 + i)h/2 and (1 - i)h/2, x0 = (1, 1, 1), the largest |Q(x_n) - Q(x_0)| and the slope of that
modulus (``nambu_bch.numeric.check``, complex128) for Q = H, G and the truncated shadow pair H_S^[k], G_S^[k]
(alpha = 1/2), on the complex map and on its real projection x_{n+1} = Re Phi_h(x_n); then the slope of the
projected run's |H(x_n) - H(x_0)| at h and h/2.  These are errors of exact arithmetic carried out in complex128,
not timings: they do not depend on the machine's load (nor on the backend: one state gets the same bits on all).

``--speed``: steps per second on ho3, h = 0.1, x0 = (1, 1, 1), one trajectory, of the complex triple jump
S_{g1 h} S_{g2 h} S_{g1 h} of the Strang step 12321 (g1 = 1/(2 - 2^(1/3) e^(2 pi i/3)), g2 = 1 - 2 g1; Hansen &
Ostermann, BIT 49 (2009) 527; Castella et al., BIT 49 (2009) 487; 13 sub-flows) run by ``iterate_complex`` compiled
(backend "numba", complex map and real projection) and interpreted (backend "numpy", the cmath reference), beside
the real compiled runs of ``iterate``: 12321 (5 sub-flows) and Yoshida's real triple jump of 12321 (13 sub-flows).
Each contender is warm (compiled and loaded before timing), called in turn in every round (a change of load hits
all alike), ``--repeats`` rounds; every row prints the median and best wall time and the best CPU time as steps
per second, with the load average before and after.

Run:  python benchmarks/complex_drift.py            # the errors
      python benchmarks/complex_drift.py --speed    # the speeds
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
import sympy  # noqa: E402

from nambu_bch.integrators.composition import composition  # noqa: E402
from nambu_bch.numeric import iterate, iterate_complex  # noqa: E402
from nambu_bch.numeric.diagnostics import complex_check  # noqa: E402

S3 = "1:1/4+I/4,2:1/4+I/4,3:1/2+I/2,2:1/4+I/4,1:1/2,2:1/4-I/4,3:1/2-I/2,2:1/4-I/4,1:1/4-I/4"
X0 = [1.0, 1.0, 1.0]


def drift() -> None:
    print("ho3, S_{(1+i)h/2} S_{(1-i)h/2} of 12321, h = 0.1, x0 = (1, 1, 1)")
    for t_end in (200, 2000):
        for order in (2, 4):
            for project in (False, True):
                r = complex_check("ho3", S3, 0.1, int(t_end / 0.1), X0, order=order, project=project)
                errors = ", ".join(f"{k} {v:.2e}" for k, v in r.max_abs_error.items())
                slopes = ", ".join(f"{k} {v:.1e}" for k, v in r.drift_rate.items())
                print(f"t = {t_end:5d}  k = {order}  {'Re Phi_h' if project else 'Phi_h   '}  max |dQ|: {errors};  slope: {slopes}")
    for h in (0.1, 0.05):
        r = complex_check("ho3", S3, h, int(1000 / h), X0, project=True, include=("H",))
        print(f"projected run, t = 1000, h = {h}: max |dH| {r.max_abs_error['H']:.2e}, slope {r.drift_rate['H']:.2e}")


def complex_triple_jump():
    """The complex triple jump of the Strang step 12321 on three pieces, adjacent factors of piece 1 merged (exact)."""
    g = 1 / (2 - 2 ** sympy.Rational(1, 3) * (-sympy.Rational(1, 2) + sympy.sqrt(3) * sympy.I / 2))
    pairs = []
    for a in (g, 1 - 2 * g, g):
        for k, c in ((1, a / 2), (2, a / 2), (3, a), (2, a / 2), (1, a / 2)):
            if pairs and pairs[-1][0] == k:
                pairs[-1] = (k, pairs[-1][1] + c)
            else:
                pairs.append((k, c))
    return composition(pairs)


def speed(repeats: int, scale: float) -> None:
    tj = complex_triple_jump()
    big, small = int(2_000_000 * scale), int(2_000 * scale)
    work = {  # name: (call, steps per call)
        "real 12321, iterate numba": (lambda n: iterate("ho3", "12321", 0.1, n, X0, every=n, backend="numba"),
                                      10 * big),
        "real triple-jump:12321, iterate numba": (
            lambda n: iterate("ho3", "triple-jump:12321", 0.1, n, X0, every=n, backend="numba"), 4 * big),
        "complex triple jump, iterate_complex numba": (
            lambda n: iterate_complex("ho3", tj, 0.1, n, X0, every=n, backend="numba"), big),
        "complex triple jump, numba, project=True": (
            lambda n: iterate_complex("ho3", tj, 0.1, n, X0, every=n, project=True, backend="numba"), big),
        "complex triple jump, iterate_complex numpy": (
            lambda n: iterate_complex("ho3", tj, 0.1, n, X0, every=n, backend="numpy"), small),
    }
    compiled = {}
    for name, (fn, _) in work.items():  # warm: compile or load every loop before any timing
        start = time.perf_counter()
        fn(10)
        compiled[name] = time.perf_counter() - start
    load = os.getloadavg()
    wall = {name: [] for name in work}
    cpu = {name: [] for name in work}
    for _ in range(repeats):
        for name, (fn, n) in work.items():
            w, c = time.perf_counter(), time.process_time()
            fn(n)
            wall[name].append((time.perf_counter() - w) / n)
            cpu[name].append((time.process_time() - c) / n)
    after = os.getloadavg()
    print(f"ho3, h = 0.1, one trajectory, {repeats} rounds; load average {load[0]:.2f} before, {after[0]:.2f} after "
          f"({os.cpu_count()} CPUs)")
    print(f"{'run':45s} {'steps':>9s} {'median steps/s':>15s} {'best steps/s':>13s} {'best CPU steps/s':>17s} "
          f"{'first call s':>12s}")
    for name, (_, n) in work.items():
        med, best, best_cpu = float(np.median(wall[name])), min(wall[name]), min(cpu[name])
        print(f"{name:45s} {n:9d} {1 / med:15.4g} {1 / best:13.4g} {1 / max(best_cpu, 1e-300):17.4g} "
              f"{compiled[name]:12.2f}")
    rate = {name: 1 / float(np.median(wall[name])) for name in work}
    c_fast = rate["complex triple jump, iterate_complex numba"]
    print(f"compiled / interpreted complex: {c_fast / rate['complex triple jump, iterate_complex numpy']:.4g}x; "
          f"real triple jump / complex triple jump (both compiled, 13 sub-flows): "
          f"{rate['real triple-jump:12321, iterate numba'] / c_fast:.3g}x; "
          f"real 12321 / complex triple jump: {rate['real 12321, iterate numba'] / c_fast:.3g}x")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed", action="store_true", help="time the compiled and interpreted runs instead")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scale", type=float, default=1.0, help="multiply the step counts (e.g. 0.1 for a quick run)")
    args = parser.parse_args(argv)
    if args.speed:
        speed(max(1, args.repeats), max(1e-3, args.scale))
    else:
        drift()


if __name__ == "__main__":
    main()
