"""Pausing Python's cyclic garbage collector while exact code builds large acyclic data.

One place for the sparse engine (:mod:`~nambu_bch.bch.formal`), the table's trees (:mod:`~nambu_bch.bch.table`) and
the direct route's solve and sums (:mod:`~nambu_bch.shadow.direct_route`).
"""

from __future__ import annotations

import gc
from contextlib import contextmanager


@contextmanager
def no_full_collection():
    """Pause the cyclic garbage collector while a computation builds many acyclic objects (tuples, ints, ring elements).

    Tens of thousands of new objects otherwise trigger full collections that walk every object
    of the interpreter (sympy's caches: about 70 ms each, more than the whole BCH computation at degree
    16); what is allocated inside forms no cycles, so nothing is left for the collector to find, and the
    collector resumes (with its usual thresholds) when the block ends."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
