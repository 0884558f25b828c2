"""Pausing Python's cyclic garbage collector while the BCH code builds large acyclic data (tuples and ints).

One place for the sparse engine (:mod:`~nambu_bch.bch.formal`) and the table's trees (:mod:`~nambu_bch.bch.table`).
"""

from __future__ import annotations

import gc
from contextlib import contextmanager


@contextmanager
def no_full_collection():
    """Pause the cyclic garbage collector while the sparse engine builds its (acyclic) tuples and ints.

    Tens of thousands of new objects otherwise trigger a full collection that walks every object
    of the interpreter (sympy's caches: about 70 ms, more than the whole computation at degree
    16); nothing allocated here forms a cycle, so nothing is left for the collector to find."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
