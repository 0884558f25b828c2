"""Results several tests check, computed once per test process (the suite's time).

Each function here calls the library exactly as the tests did before, with the same arguments; what changes is
only that a second test asking for the same result (the same model, word, order and options) reuses the first
answer instead of recomputing it.  Every result is immutable or only read by the tests (``ShadowFamily`` is a
frozen dataclass; the others are read, never assigned to), so sharing cannot let one test change what another sees.

Under ``pytest -n 2`` each worker process has its own copy: a result is computed once per worker that needs it.

Import from a test with ``sys.path`` holding this directory (tests/conftest.py puts it there).
"""

from __future__ import annotations

import ast
from functools import lru_cache
from pathlib import Path

import nambu_bch as nb
from nambu_bch.bch.backward import effective_field
from nambu_bch.bch.concrete import effective_field_bch
from nambu_bch.shadow.generic import bch_shadow, generic_shadow
from nambu_bch.shadow.generic_nambu import generic_nambu_h2


@lru_cache(maxsize=None)
def family(name: str, word: str, order: int = 2, route: str = "direct", **options):
    """``nambu_bch.shadow_hamiltonians(model(name), word, order, route=route, **options)``."""
    return nb.shadow_hamiltonians(nb.model(name), word, order, route=route, **options)


@lru_cache(maxsize=None)
def direct(name: str, word: str, order: int, **options):
    """``nambu_bch.direct_route(model(name), word, order, **options)``."""
    return nb.direct_route(nb.model(name), word, order, **options)


@lru_cache(maxsize=None)
def backward_field(name: str, word: str, order: int):
    """``X_eff`` of ``word`` on ``model(name)`` by backward error analysis (``effective_field``) through ``h^order``."""
    return effective_field(nb.model(name).splitting, word, order)


@lru_cache(maxsize=None)
def bch_field(name: str, word: str, order: int):
    """``X_eff`` of ``word`` on ``model(name)`` by the formal BCH series on fields (``effective_field_bch``)."""
    return effective_field_bch(nb.model(name).splitting, word, order)


@lru_cache(maxsize=None)
def generic(word: str = "121", order: int = 2):
    """``generic_shadow(word, order)``: the shadow Hamiltonian for ``H = T(p) + V(q)``, T and V undefined."""
    return generic_shadow(word, order)


@lru_cache(maxsize=None)
def bch(name: str, word: str, order: int, verify: bool = True):
    """``bch_shadow(model(name), word, order, verify=verify)``."""
    return bch_shadow(nb.model(name), word, order, verify=verify)


@lru_cache(maxsize=None)
def nambu_h2(word: str = "12321"):
    """``generic_nambu_h2(word)``: the generic Nambu answer at ``h^2`` (separable ``H_i, G_i``, full split)."""
    return generic_nambu_h2(word)


@lru_cache(maxsize=None)
def brackets(name: str, word: str, order: int):
    """``fi_brackets(model(name), word, order)``: the BCH brackets at ``h^order`` with their FI hulls (a tuple)."""
    from nambu_bch.shadow.fi_route import fi_brackets

    return tuple(fi_brackets(nb.model(name), word, order))


@lru_cache(maxsize=None)
def package_trees(package: str):
    """``{path: AST}`` of every module under the directory ``package`` (sorted by path), parsed once: the source
    scans of test_flint_seam.py, test_text_door.py and test_import_cycles.py read the same ~140 modules (about 1 s of
    parsing each); the mapping is read-only and the trees are only walked."""
    from types import MappingProxyType

    paths = sorted(Path(package).rglob("*.py"))
    return MappingProxyType({p: ast.parse(p.read_text(encoding="utf-8"), filename=str(p)) for p in paths})
