"""The tests directory on ``sys.path`` (shared helpers), and the run order: the long tests go first (roughly longest first), so that under ``pytest -n 2`` no worker is left
alone with one at the end.

Nothing here changes what a test does or asserts; the order among the other tests is kept (a stable sort).

Why this balances: ``--dist worksteal`` (pyproject ``addopts``) hands each of the two workers one contiguous half of
the collection, and a worker that runs dry steals the *last* half of the other's queue.  With the long tests at the
front they all start early in the first worker's queue, and what is stolen and run at the end are short tests, so
both workers finish within seconds of each other (measured: docs/suite_time.md).
"""

from __future__ import annotations

import sys
from pathlib import Path

# the suite's shared helpers (reference_fields.py, strategies.py) are imported by name from this directory; with
# ``--import-mode=importlib`` pytest does not put it on sys.path itself
sys.path.insert(0, str(Path(__file__).parent))

# (file, test name prefix) of the tests that take >= ~2 s each on the idle two-core machine, roughly longest first
# (a cold ``pytest -n 2 --durations=0`` of the suite, load 2-4; docs/suite_time.md).  Tests that reuse
# a result of a long one (tests/shared_results.py: computed once per worker process) follow it, so that both run
# early in the same worker instead of each computing it (the rest of their file may be stolen by the other worker).
LONG = (
    ("test_cache_safety.py", "test_"),                                      # 15-30 s each: numba recompiles in subprocesses
    ("test_docs.py", "test_api_reference_builds_without_warnings"),         # a Sphinx build in a subprocess
    ("test_bch_modular.py", "test_sparse_engine_equals_dense_engine"),      # 9 s at [12-12], cold: numba compile
    ("test_pickle.py", "test_results_come_back_from_spawned_workers"),      # a spawned worker imports and computes
    ("test_cli.py", "test_every_subcommand_runs_as_a_subprocess"),          # 14 s: nine subprocesses, two at a time
    ("test_packaging.py", "test_"),                                         # wheel and sdist built, installed, run
    ("test_fuzz_cli.py", "test_"),
    ("test_direct_route_fast.py", "test_rigid_body_symbolic_yoshida_family_over_base_field"),
    ("test_numeric_api_arguments.py", "test_default_x0_of_every_model_runs_a_long_orbit"),
    ("test_elimination.py", "test_solve_affine_matches_plain_domainmatrix"),  # 12 s at QQ<2^(1/3)>(a,b)
    ("test_notebooks.py", "test_notebook_executes"),                        # 3-8 s each, in a kernel process
    ("test_numeric.py", "test_exponential_flows_"),                         # 3-7 s each: Lotka-Volterra kernels, a C build
    ("test_testing.py", "test_example_suite_"),                             # two pytest subprocesses
    ("test_fi_route.py", "test_hull_members_have_the_brackets_field"),      # the rigid body's 992 h^4 hulls ...
    ("test_fi_route.py", "test_h4_hull_equals_brute_force_enumeration"),    # ... reused here
    ("test_modular_rref.py", "test_n4_single_split_h4_same_with_modular_and_flint"),
    ("test_shadow.py", "test_shadow_pair_reproduces_effective_field"),      # families and X_eff ...
    ("test_shadow.py", "test_rigid_body_full_split_has_polynomial_shadows_through_h4"),  # ... reused here
    ("test_shadow.py", "test_single_split_models_have_shadows"),            # ... and here
    ("test_shadow.py", "test_eight_representations_for_generic_functions"),
    ("test_any_system.py", "test_new_system_numerics"),                     # families of eight systems ...
    ("test_any_system.py", "test_new_system_shadow_equals_X_eff_two_routes"),  # ... reused here
    ("test_any_system.py", "test_toda_h2_and_fpu_h2"),                      # ... and here
    ("test_fi_route.py", "test_cli_bad_input_is_one_line[argv3"),           # counts 22272 brackets at h^6
    ("test_any_system.py", "test_concrete_equals_generic_substituted_to_h4"),
    ("test_shadow.py", "test_rigid_body_non_symmetric_word_is_obstructed_at_h1"),
    ("test_design.py", "test_optimize_finds_yoshidas_sixth_order_solution"),
    ("test_any_system.py", "test_lie_poisson_bch_member_with_casimir_kept"),
    ("test_shadow.py", "test_n4_full_split_is_obstructed"),
    ("test_numeric.py", "test_series_pair_is_accurate"),
    ("test_runge_kutta_numeric.py", "test_compiled_equals_interpreted_bit_for_bit"),  # cold: numba compiles the RK loops
)


#: Plugin distributions whose modules pytest marks for assertion rewriting (every module of a distribution with a
#: ``pytest11`` entry point).  None of them has an ``assert`` the suite relies on (the package has none at all), but
#: every pytest process re-parsed and rewrote ~150 of their modules as they were imported, ~0.7 s of CPU per process,
#: since ``PYTHONDONTWRITEBYTECODE`` keeps pytest from caching the result (docs/suite_time.md).
NOT_REWRITTEN = ("nambu_bch", "hypothesis", "_hypothesis_pytestplugin", "_hypothesis_globals", "_hypothesis_ftz_detector",
                 "xdist", "platformdirs")


def pytest_configure(config):
    """Assertion rewriting for the tests only: unmark :data:`NOT_REWRITTEN`.

    The test files (``python_files``) and conftest files are rewritten regardless of the marks, so a failing assert
    in a test is explained as before.  Uses the rewrite hook's own attributes (pytest 9); if they are not there,
    nothing changes.
    """
    hook = getattr(config.pluginmanager, "rewrite_hook", None)
    marked = getattr(hook, "_must_rewrite", None)
    cache = getattr(hook, "_marked_for_rewrite_cache", None)
    if isinstance(marked, set) and isinstance(cache, dict):
        marked.difference_update(NOT_REWRITTEN)
        cache.clear()


def pytest_collection_modifyitems(session, config, items):
    def rank(item) -> int:
        for i, (f, n) in enumerate(LONG):
            if item.path.name == f and item.name.startswith(n):
                return i
        return len(LONG)

    items.sort(key=rank)
