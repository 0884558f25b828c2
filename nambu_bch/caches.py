"""One :func:`clear_caches` for every module-level cache of the package (memory, not the disk caches).

The package memoises exact work that is expensive and deterministic: Lyndon bases
and BCH coefficients (:mod:`nambu_bch.bch`), resolved compositions and exact
sub-flows (:mod:`nambu_bch.integrators`), FI hulls and formal columns
(:mod:`nambu_bch.shadow`), exact conserved quantities and shadow Hamiltonians
(:mod:`nambu_bch.exact`), step programs and compiled kernels
(:mod:`nambu_bch.numeric`), the built-in models (:mod:`nambu_bch.systems`).
:data:`CACHES` lists each one; ``tests/test_public_api.py`` checks that no
``functools.lru_cache`` or module-level cache dictionary is missing from it.
Disk caches (generated kernels, the ``models`` listing) live under
``$NAMBU_BCH_CACHE`` and are verified on reading; they are not touched here.  Nor is
the BCH table's verified image (:mod:`nambu_bch.bch.table`: the shipped file's header and
the degrees' bytes, each checked against its SHA-256 once per process): it is the
package's data as read, like an imported module; what was decoded from it is emptied
(``table.clear_decoded``), and ``table.clear_cache()`` forgets the image too.

>>> from nambu_bch import clear_caches, model
>>> S = model("ho3"); clear_caches(); model("ho3") is S, model("ho3").hamiltonians == S.hamiltonians
(False, True)
"""

from __future__ import annotations

import sys

#: ``(module, attribute)``: an ``lru_cache`` function (``cache_clear``), a module's ``clear_cache()``,
#: or a dict / ``WeakKeyDictionary`` (``clear``).  Modules not imported yet hold nothing and are skipped.
CACHES = (
    ("nambu_bch.algebra._flint", "_FMPZ_CONTEXTS"),
    ("nambu_bch.algebra._flint", "_FMPQ_CONTEXTS"),
    ("nambu_bch.algebra._flint", "_QQ_IS_FMPQ"),
    ("nambu_bch.algebra.fields", "_number_field"),
    ("nambu_bch.algebra.polynomial", "_converted"),
    ("nambu_bch.algebra.polynomial", "_times"),
    ("nambu_bch.bch.concrete", "clear_cache"),          # _EVALUATORS
    ("nambu_bch.compiled", "_NUMBA_DIRS"),
    ("nambu_bch.bch.formal", "clear_cache"),            # _PATTERN_CACHE
    ("nambu_bch.bch.formal", "_fits"),
    ("nambu_bch.bch.formal", "_lyndon_trees"),
    ("nambu_bch.bch.formal", "_digit_permutation"),
    ("nambu_bch.bch.formal", "_lyndon_table"),
    ("nambu_bch.bch.formal", "_lyndon_inverse"),
    ("nambu_bch.bch.formal", "_class_pairs"),
    ("nambu_bch.bch.formal", "_duval_trees"),
    ("nambu_bch.bch.formal", "_fits_dense"),
    ("nambu_bch.bch.modular", "lyndon_table"),
    ("nambu_bch.bch.table", "clear_decoded"),           # _TREES, _WORDS, _FACTORS, _NUMERATORS (not the verified image)
    ("nambu_bch.bch.modular", "_surjection_sum"),
    ("nambu_bch.bch.modular", "_class_order"),
    ("nambu_bch.bch.modular", "_tanh_half_coefficients"),
    ("nambu_bch.bch.lyndon", "_witt_dimension"),
    ("nambu_bch.bch.lyndon", "_lyndon_words"),
    ("nambu_bch.bch.lyndon", "standard_factorization"),
    ("nambu_bch.bch.lyndon", "lyndon_expansion"),
    ("nambu_bch.bseries.rooted_trees", "order"),
    ("nambu_bch.bseries.rooted_trees", "symmetry"),
    ("nambu_bch.bseries.rooted_trees", "density"),
    ("nambu_bch.bseries.rooted_trees", "trees"),
    ("nambu_bch.design.defects", "rkn_ideal"),
    ("nambu_bch.design.defects", "rkn_annihilator"),
    ("nambu_bch.exact.exact_shadow", "_exact_shadow"),
    ("nambu_bch.exact.invariants", "_conserved"),
    ("nambu_bch.exact.solutions", "_lambdify"),
    ("nambu_bch.exact.solutions", "_solution"),
    ("nambu_bch.integrators.composition", "_composition_from_text"),
    ("nambu_bch.integrators.compose", "_composed_map"),
    ("nambu_bch.systems.piece_flows", "piece_flow"),
    ("nambu_bch.integrators.composition", "_catalog_build"),
    ("nambu_bch.numeric.codegen", "_step_program"),
    ("nambu_bch.numeric.complex_codegen", "_KERNELS"),
    ("nambu_bch.numeric.complex_codegen", "_complex_program"),
    ("nambu_bch.numeric.kernels", "_CACHE_DIRS"),
    ("nambu_bch.numeric.kernels", "_generator_digest"),
    ("nambu_bch.numeric.kernels", "_kernel_for_word"),
    ("nambu_bch.numeric.kernels", "_kernel"),
    ("nambu_bch.numeric.precision", "clear_cache"),     # _MPMATH
    ("nambu_bch.numeric.runge_kutta", "_MODULES"),
    ("nambu_bch.shadow.fi_route", "clear_cache"),       # _RAW_OPS, _FORMS, _MONOMIAL_COLUMNS, _EVALUATORS, _OPERATOR
    ("nambu_bch.shadow.fundamental_identity", "_MEMO"),
    ("nambu_bch.shadow.liouville_terms", "clear_cache"),  # _CONTEXTS, canonical_key, _dependent
    ("nambu_bch.systems.catalog", "_CACHE"),
)


def clear_caches() -> None:
    """Empty every in-memory cache of the package (:data:`CACHES`); results computed later are the same.

    Useful to measure a computation from scratch, or to free memory after a large one.
    """
    for module_name, attribute in CACHES:
        module = sys.modules.get(module_name)
        if module is None:  # never imported: nothing cached
            continue
        obj = getattr(module, attribute)  # AttributeError: CACHES is out of date (a bug; tested)
        if hasattr(obj, "cache_clear"):
            obj.cache_clear()
        elif callable(obj):
            obj()
        else:
            obj.clear()
