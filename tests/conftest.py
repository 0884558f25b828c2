"""Run order only: the few long tests go first, so that under ``pytest -n 2`` no worker is left alone with one at the end.

Nothing here changes what a test does or asserts; the order among the other tests is kept (a stable sort).
"""

from __future__ import annotations

# (file, test name prefix) of the tests that take 5-11 s each on the two-core machine (``--durations``)
LONG = (
    ("test_notebooks.py", "test_notebook_executes"),
    ("test_design.py", "test_optimize_finds_yoshidas_sixth_order_solution"),
    ("test_any_system.py", "test_concrete_equals_generic_substituted_to_h4"),
    ("test_bch_modular.py", "test_sparse_engine_equals_dense_engine"),
)


def pytest_collection_modifyitems(session, config, items):
    def first(item) -> int:
        return 0 if any(item.path.name == f and item.name.startswith(n) for f, n in LONG) else 1

    items.sort(key=first)
