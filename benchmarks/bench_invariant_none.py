"""The invariant search's shortcuts against the exact route they skip, interleaved in one process.

Two searches that the fast tier and every user's ``check`` run (``conserved_quantities``'s default degree):

* ``rigid-body 12321`` at degree 2 answers "none": the shortcut certifies it by the search matrix's full column
  rank at one rational point (:func:`nambu_bch.exact.invariants._no_invariant_at_a_point`); the exact route
  converts the map to ``K[x]``, ``K = QQ(I1, I2, I3, h)``, builds the images there and eliminates over ``K``;
* ``lotka-volterra 12321`` at degree 3 answers ``x1 x2 x3``: the shortcut reads the invariant monomials off the
  exponents of ``x_i -> x_i exp(a_i)`` (:func:`nambu_bch.exact.invariants._exponents`); the exact route expands
  every image (``_exp_images``) and eliminates.

Each row: the map composed once (untimed, shared), then ``--repeat`` rounds alternating the two routes on a
fresh ``_Setup`` copy of it, sympy's cache cleared before each; the median CPU seconds of ``_invariant_basis``
per route, the load average before the rounds, and whether the two bases agree.  ``--profile``: instead, each
case's ``conserved_quantities`` cold in a fresh process (empty cache) under cProfile, its CPU and the package's
functions by cumulative time.
Usage: ``python benchmarks/bench_invariant_none.py [--repeat N | --profile]``.
"""

from __future__ import annotations

import argparse
import copy
import os
import statistics
import subprocess
import sys
import tempfile
import time

from sympy.core.cache import clear_cache

from nambu_bch import composition, model
from nambu_bch.exact import invariants

CASES = (("rigid-body", "12321", 2), ("lotka-volterra", "12321", 3))


def _timed(setup, degree, exact: bool):
    setup = copy.copy(setup)  # the lazily converted map (setup.phi) is not shared between rounds
    setup.__dict__.pop("phi", None)
    saved = invariants._no_invariant_at_a_point, invariants._exponents
    if exact:
        invariants._no_invariant_at_a_point, invariants._exponents = (lambda *a: False), (lambda *a: None)
    try:
        clear_cache()  # sympy's expression cache would serve a repeated expand from the previous round
        start = time.process_time()
        basis = invariants._invariant_basis(setup, degree)
        return time.process_time() - start, basis
    finally:
        invariants._no_invariant_at_a_point, invariants._exponents = saved


_PROFILE = """
import cProfile, os, pstats, sys, time
from nambu_bch import model
from nambu_bch.exact import conserved_quantities
name, word = sys.argv[1:3]
profile, start = cProfile.Profile(), time.process_time()
profile.enable()
conserved_quantities(model(name), word)
profile.disable()
print(f"{name} {word}: CPU {time.process_time() - start:.2f} s, load {os.getloadavg()[0]:.2f}")
pstats.Stats(profile).sort_stats("cumulative").print_stats("nambu_bch", 12)
"""


def profile() -> None:
    for name, word, _ in CASES:
        with tempfile.TemporaryDirectory(prefix="bench_invariant_none_") as cache:
            env = dict(os.environ, NAMBU_BCH_CACHE=cache)
            subprocess.run([sys.executable, "-c", _PROFILE, name, word], env=env, check=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()
    if args.profile:
        profile()
        return
    print(f"{'search':28s} {'degree':>6s} {'shortcut CPU':>13s} {'exact CPU':>10s} {'load':>5s}  same basis")
    for name, word, degree in CASES:
        setup = invariants._Setup(model(name), composition(word, 3), degree)
        load = os.getloadavg()[0]
        fast, exact, same = [], [], True
        for _ in range(args.repeat):
            t_fast, b_fast = _timed(setup, degree, exact=False)
            t_exact, b_exact = _timed(setup, degree, exact=True)
            fast.append(t_fast)
            exact.append(t_exact)
            same &= b_fast == b_exact
        print(f"{name + ' ' + word:28s} {degree:6d} {statistics.median(fast):12.3f}s {statistics.median(exact):9.3f}s "
              f"{load:5.2f}  {same}")


if __name__ == "__main__":
    main()
