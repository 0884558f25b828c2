"""The tests directory on ``sys.path`` (shared helpers), and the run order: the long tests go first (roughly longest first), so that under ``pytest -n 2`` no worker is left
alone with one at the end.

Nothing here changes what a test does or asserts; the order among the other tests is kept (a stable sort).

Why this balances: ``--dist worksteal`` (pyproject ``addopts``) hands each of the two workers one contiguous half of
the collection, and a worker that runs dry steals the *last* half of the other's queue.  With the long tests at the
front they all start early in the first worker's queue, and what is stolen and run at the end are short tests, so
both workers finish within seconds of each other (measured: docs/suite_time.md).

It is also the one place where the suite is split into two tiers (docs/suite_time.md, "Two tiers"): the tests named
in :data:`DEEP` carry the marker ``deep``, which ``pyproject.toml`` deselects by default (``-m "not deep"``); the
*fast tier* (the README's test command) runs the rest, and ``pytest -m deep`` runs the *deep tier*.  The hypothesis
tests run in both: in the fast tier at a quarter of their example counts, in the deep tier at the full counts.
"""

from __future__ import annotations

import contextlib
import gc
import io
import math
import os
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

# the suite's shared helpers (reference_fields.py, strategies.py) are imported by name from this directory; with
# ``--import-mode=importlib`` pytest does not put it on sys.path itself
sys.path.insert(0, str(Path(__file__).parent))

import session_bytecode  # noqa: E402  (a helper of this directory, on the path just above)

# (file, test name prefix) of the tests that take >= ~2 s each on the idle two-core machine, roughly longest first
# (a cold ``pytest -n 2 --durations=0`` of the suite, load 2-4; docs/suite_time.md).  Tests that reuse
# a result of a long one (tests/shared_results.py: computed once per worker process) follow it, so that both run
# early in the same worker instead of each computing it (the rest of their file may be stolen by the other worker).
LONG = (
    # First the compiled loops that several tests share (compiled once per kind in the fast tier, DEEP): their tests in
    # a row in the first worker, at the start, so that the loop is compiled once and reused in memory, and the other
    # worker, reaching a test that uses it later, loads it from numba's cache in the run's NAMBU_BCH_CACHE (two
    # workers that need it at the same time both compile it).  The Lotka-Volterra batch loop (5-9 s cold) ...
    ("test_numeric.py", "test_exponential_flows_agree_across_backends"),
    ("test_numeric_parallel.py", "test_an_overflow_in_any_thread_is_reported"),  # ... reused here
    ("test_hardening_numeric.py", "test_compiled_scan_agrees_with_numpy_guards"),  # the scan, ho3/32123's batch loop ...
    ("test_numeric.py", "test_"),  # ... reused by the file's batch tests, with ho/TVT's Kahan batch loop (3-4 s) ...
    ("test_numeric_parallel.py", "test_"),                                  # ... and here (both loops in threads)
    ("test_cache_safety.py", "test_"),                                      # 15-30 s each: numba recompiles in subprocesses
    ("test_docs.py", "test_api_reference_builds_without_warnings"),         # a Sphinx build in a subprocess
    ("test_bch_modular.py", "test_sparse_engine_equals_dense_engine"),      # 9 s at [12-12], cold: numba compile
    ("test_pickle.py", "test_results_come_back_from_loky_workers"),         # two spawned workers import and compute
    ("test_parallel.py", "test_loky_equals_serial_in_task_order"),          # ... and the same pool, right after
    ("test_cli.py", "test_every_subcommand_runs_as_a_subprocess"),          # 1-2 s each: a subprocess per subcommand
    ("test_packaging.py", "test_"),                                         # wheel and sdist built, installed, run
    ("test_fuzz_cli.py", "test_"),
    ("test_direct_route_fast.py", "test_rigid_body_symbolic_yoshida_family_over_base_field"),
    ("test_numeric_api_arguments.py", "test_default_x0_of_every_model_runs_a_long_orbit"),
    ("test_elimination.py", "test_solve_affine_matches_plain_domainmatrix"),  # 12 s at QQ<2^(1/3)>(a,b)
    ("test_notebooks.py", "test_notebook_executes"),                        # 3-8 s each, in a kernel process
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
    ("test_shadow.py", "test_rigid_body_non_symmetric_word_is_obstructed_at_h1"),  # the rigid body's 123 family ...
    ("test_existence.py", "test_rigid_body_lie_trotter_certified_numerically_with_drift"),  # ... reused here
    ("test_pickle.py", "test_result_round_trip[Existence"),                 # ... and here
    ("test_pickle.py", "test_more_results_round_trip[ShadowFamily none"),   # ... and here
    ("test_latex_compile.py", "test_api_blocks_compile_in_display_math"),   # ... and here
    ("test_design.py", "test_optimize_finds_yoshidas_sixth_order_solution"),
    ("test_any_system.py", "test_lie_poisson_bch_member_with_casimir_kept"),
    ("test_shadow.py", "test_n4_full_split_is_obstructed"),
    ("test_runge_kutta_numeric.py", "test_compiled_equals_interpreted_bit_for_bit"),  # cold: numba compiles the RK loops
    ("test_text_door.py", "test_text_reaches_eval_only_in_the_parser"),     # the package's ASTs (shared_results) ...
    ("test_flint_seam.py", "test_only_the_seam_imports_flint"),             # ... reused here
    ("test_flint_seam.py", "test_the_arithmetic_layer_has_no_import_cycle"),  # ... and here
    ("test_import_cycles.py", "test_package_has_no_import_cycle"),          # ... and here
    ("test_existence.py", "test_issue_example_has_a_smooth_pair_not_polynomial"),  # the example at h^2 ...
    ("test_existence.py", "test_bounded_work_refuses_an_elimination_above_the_cost_budget"),  # ... reused here
    ("test_existence.py", "test_issue_example_smooth_corrections_are_conserved"),  # ... and here
    ("test_existence.py", "test_section_integral_solves_the_homological_equation"),  # ... and here
)


#: The fast tier runs ``ceil(n / HYPOTHESIS_FAST_DIVISOR)`` of a hypothesis test's ``n`` examples; the deep tier all ``n``.
HYPOTHESIS_FAST_DIVISOR = 4


def _diagonal(values: int):
    """Keep one of ``values`` cases per row of a table whose ids end in ``-k`` (``k`` the column, 0 <= k < values):
    the column chosen by a checksum of the row's id, so every row is run once and every column about equally often."""
    def keep(pid: str) -> bool:
        row, _, col = pid.rpartition("-")
        return col == str(zlib.crc32(row.encode()) % values)
    return keep


#: The deep tier: (file, test name, cases kept in the fast tier).  A whole test is deep when the third field is
#: empty; otherwise the cases named there (parameter ids, or a predicate on the id) stay in the fast tier and the other
#: cases of the table are deep.  A test belongs here when it repeats a concern the fast tier already checks, at greater
#: depth or cost (docs/suite_time.md, "Two tiers"): another notebook, a build (Sphinx, wheel), another pdflatex run,
#: another cache-damage probe in subprocesses, an order of h^6 or more, another row of a large table, another process
#: start, another compile of a kind of compiled loop the fast tier compiles once (about 0.3 s or more cold each).
#: Nothing else is moved: the fast tier keeps a case of every table, every module and every subcommand.
DEEP = (
    # one notebook in the fast tier; a kernel process each, 5-12 s
    ("test_notebooks.py", "test_notebook_executes", ("01_hamiltonian_warmup",)),
    # the three probes that recompile numba's loops in subprocesses after damaging the warm cache (7-20 s each); the
    # fast tier keeps the verified read, the listing cache and test_hardening_numeric's kernel- and numba-cache probes
    ("test_cache_safety.py", "test_special_files_in_place_of_cache_files_neither_block_nor_are_read", ()),
    ("test_cache_safety.py", "test_pickles_planted_under_numba_cache_dir_are_never_loaded", ()),
    ("test_cache_safety.py", "test_private_numba_cache_unpickles_only_verified_files", ()),
    # builds: Sphinx (12 s), the wheel and sdist (twine, an installed wheel); the fast tier keeps the page index
    # check, the version and the citation
    ("test_docs.py", "test_api_reference_builds_without_warnings", ()),
    ("test_packaging.py", "test_wheel_and_sdist_pass_twine_check", ()),
    ("test_packaging.py", "test_wheel_holds_only_the_package", ()),
    ("test_packaging.py", "test_sdist_holds_the_sources_and_the_licence", ()),
    ("test_packaging.py", "test_installed_wheel_runs_the_readme_first_command", ()),
    # pdflatex: one compile per subcommand in the fast tier, the other outputs in the deep tier
    ("test_latex_compile.py", "test_cli_latex_compiles",
     ("shadow", "conserved", "exact --order 4", "bch", "fi", "models --format latex")),
    # another process start for what the fast tier checks once: the example suite with the plugin named explicitly
    # (the entry-point run stays), the dask cluster (loky stays)
    ("test_testing.py", "test_example_suite_with_explicit_plugin", ()),
    ("test_parallel.py", "test_dask_local_cluster_equals_serial", ()),
    # hostile text: every subcommand and every option once in the fast tier, all 105 pairs in the deep tier
    ("test_hardening_input.py", "test_hostile_text_every_subcommand_and_option",
     ("models--model", "bch--system", "fi--H", "shadow--G", "conserved--coords", "exact--param", "check--name",
      "plot--split", "models--format", "bch--integrator", "shadow--order", "shadow--route", "conserved--degree",
      "check--h", "plot--steps", "check--x0", "plot--every", "check--alpha", "plot--short-steps", "plot--dpi",
      "plot--fig-format")),
    # the numeric argument table: every (entry, argument) row with one of its 19 bad values in the fast tier
    ("test_numeric_api_arguments.py", "test_bad_argument_gives_one_nambu_error_line", _diagonal(19)),
    # the exact linear algebra over every field and backend: QQ for each backend and one algebraic field in the fast
    # tier, the parametric and algebraic-parametric fields (1-7 s each) in the deep tier
    ("test_elimination.py", "test_solve_affine_matches_plain_domainmatrix",
     ("flint-QQ", "modular-QQ", "sympy-only-QQ", "flint-QQ<2^(1/3)>")),
    ("test_elimination.py", "test_rank_nullspace_normal_form_match_plain",
     ("flint-QQ", "modular-QQ", "sympy-only-QQ", "flint-QQ(a,b)")),
    ("test_elimination.py", "test_rigid_body_shadows_match_plain_path",
     ("flint-values0-yoshida:12321-2", "modular-values0-yoshida:12321-2", "sympy-only-values0-yoshida:12321-2")),
    # the sparse BCH engine against the dense one: degrees <= 9 in the fast tier; degree 11-12 (a 15 s cold compile)
    ("test_bch_modular.py", "test_sparse_engine_equals_dense_engine",
     ("12321-9", "123-8", "21-8", "3:1/2,1:1,3:1/2-8", "1234321-6", "1:1/3,2:1/2,1:2/3,3:1,2:1/2-7",
      "1:999/7,2:1,1:-992/7-8")),
    # high orders (h^6 and more) and the large symbolic cases; each has a lower-order case in the fast tier
    ("test_direct_route_fast.py", "test_rigid_body_symbolic_yoshida_family_over_base_field", ()),
    ("test_design.py", "test_optimize_finds_yoshidas_sixth_order_solution", ()),
    ("test_exact_shadow.py", "test_alpha_family_reproduces_X_eff_to_h8", ("12321",)),
    ("test_direct_route_gauge.py", "test_psi_dim_equals_second_elimination",
     ("degrees-ho3-6_0", "free-columns-ho3-6_0", "degrees-lotka-volterra-6")),
    ("test_direct_route_flint.py", "test_solves_identical_with_and_without_flint", ("n3-params-123-2-True",)),
    ("test_shadow.py", "test_shadow_pair_reproduces_effective_field",
     ("ho3-12321-2", "ho3-13231-2", "ho3-31213-2", "ho3-21312-2", "ho3-23132-2", "ho3-32123-2", "ho-121-4", "ho-12-3",
      "lotka-volterra-12321-4", "lotka-volterra-123-2", "ho3-composite-121-4", "ho3-composite-12-2")),
    ("test_fi_route.py", "test_hull_members_have_the_brackets_field", ("ho3-12321-4", "lotka-volterra-12321-4")),
    ("test_fi_route.py", "test_h4_hull_equals_brute_force_enumeration", ("ho3-12321", "ho3-21312")),
    # tables: a sample of rows in the fast tier
    ("test_exact_solutions.py", "test_solutions_solve_the_equations",
     ("o-ho3-12321", "o-ho-121", "o-ho-12", "c-ho-121", "s-ho-121")),
    ("test_integrators.py", "test_condition1_every_composition",
     ("ho-121", "ho-212", "ho-12", "ho-21", "ho-forest-ruth", "ho3-12321", "ho3-13231", "ho3-31213", "ho3-21312",
      "ho3-23132", "ho3-32123", "ho3-123", "ho3-321", "ho3-composite-121", "ho3-composite-212", "ho3-composite-12",
      "lotka-volterra-123", "rigid-body-123")),
    ("test_exact_solutions.py", "test_shadow_solution_at_t_equal_h_is_the_map", ("ho3-12321", "ho-121")),
    ("test_integrators.py", "test_condition1_rigid_body_all_words", ("12321", "31213")),
    ("test_bseries.py", "test_bseries_equals_taylor_backward_analysis",
     ("euler-ho", "implicit-euler-rigid-body", "midpoint-lotka-volterra", "trapezoid-ho3", "rk4-ho", "kahan-ho3")),
    ("test_any_system.py", "test_generic_nambu_no_universal_shadow_pair_at_h2", ("12321",)),
    ("test_extended_ring.py", "test_ring_check_agrees_with_the_expression_check",
     ("pendulum-121-4", "exp-well-212-4", "henon-heiles-121-4")),
    ("test_design_methods.py", "test_complex_rows_of_check_methods",
     ("2:1/4-sqrt(3)*I/12,1:1/2-sqrt(3)*I/6,2:1/2,1:1/2+sqrt(3)*I/6,2:1/4+sqrt(3)*I/12-3-0.36-1.49",)),
    ("test_pickle.py", "test_more_results_round_trip",
     ("EffectiveField triple jump (cube root of 2)", "ShadowFamily ho h^4 fi", "ShadowFamily none")),
    # high orders and degrees beyond the fast tier's: gauss6, BCH degree 7-9 and 16 against the exact references
    ("test_bseries.py", "test_gauss_modified_field_starts_at_its_order", ("gauss4",)),
    ("test_bch_formal.py", "test_matrix_check_detects_a_wrong_high_degree_coefficient", ()),
    ("test_bch_formal.py", "test_against_free_associative_log",
     ("12-6", "1:1/3,2:1,3:1,1:2/3-6", "2:1/3,1:1/2,2:2/3,1:1/2-6")),
    ("test_bch_modular.py", "test_bernoulli_coefficients_of_ad_powers", ("13",)),
    # the engine's helper signatures after a cold compile (another compile of the engine the fast tier compiles once),
    # numba's import on first use and the served series' CLI in fresh processes (other process starts), and the
    # stored lines of the CLI's light models against every built model (builds all twelve; the fast tier keeps the
    # light path's byte-for-byte comparison with the full path)
    ("test_bch_modular.py", "test_the_solve_compiles_each_helper_for_one_signature", ()),
    ("test_bch_modular.py", "test_importing_the_compiled_modules_does_not_import_numba", ()),
    ("test_bch_cold.py", "test_the_cli_prints_a_served_series_without_sympy_or_numpy", ()),
    ("test_bch_cold.py", "test_the_cli_models_of_two_pieces_are_the_built_ones", ()),
    ("test_modular_rref.py", "test_n4_single_split_h4_same_with_modular_and_flint", ()),
    # sweeps against a reference at many points: the Lotka-Volterra exponential flows in both ranges (the fast tier
    # keeps test_exponential_flows_use_expm1 and _agree_across_backends), the expm1 pair against mpmath
    ("test_numeric.py", "test_exponential_flows_agree_bitwise_in_the_series_range", ()),
    ("test_numeric.py", "test_exponential_flows_mix_series_and_library_ranges", ()),
    ("test_numeric.py", "test_series_pair_is_accurate", ()),
    # the adversarial calls of paper_figures (drawing every figure, 4 s); test_hardening_numeric's paper_figures
    # tests and the no-code-execution check of the same callable stay in the fast tier
    ("test_fuzz_api.py", "test_public_callable_raises_only_the_family",
     lambda pid: pid != "nambu_bch.paper_figures"),
    # a long run (t = 10^3 from every model's default x0); the fast tier checks the defaults' size and use
    ("test_numeric_api_arguments.py", "test_default_x0_of_every_model_runs_a_long_orbit", ()),
    # Eqs. (1AX)-(2BY) for generic functions (jets); the fast tier checks them on the models (test_fi_route's h^2 hull)
    ("test_shadow.py", "test_eight_representations_for_generic_functions", ()),
    # threaded batches: the oscillators' kernels in the fast tier (ho3/32123's plain and ho/TVT's Kahan batch loop, the
    # ones test_numeric.py compiles); the exponential flows' (a 4-8 s compile of the Lotka-Volterra batch loops) deep
    ("test_numeric_parallel.py", "test_threads_give_the_one_thread_bits", ("ho3-32123-False", "ho-TVT-True")),
    # the generic T|V answer against the concrete systems: d = 1 and 2 in the fast tier, the d = 3 quartic (4-6 s)
    ("test_generic_separable.py", "test_substituted_equals_the_concrete_shadow_hamiltonian_d3", ()),
    # the command line as a subprocess (cli_run's "subprocess" case, 1.4-2.2 s each) is deep by the fixture's own
    # parameter mark (CLI_RUNNERS), for every test that asks for cli_run
    # the new method families: one case of each concern stays fast (ABA864's generalised order, the two routes on ho,
    # the compare rows and their CLI); the costlier repeats (2-5 s each, measured under load) are deep
    ("test_families_on_systems.py", "test_aba_methods_have_their_published_generalized_order", ("aba864-orders0",)),
    ("test_families_on_systems.py", "test_chin_4a_effective_field_two_routes_agree_exactly", ("ho", "henon-heiles")),
    ("test_families_on_systems.py", "test_work_precision_figure_with_the_new_families", ()),
    ("test_complex_routes.py", "test_effective_field_over_qq_i_two_routes", lambda pid: not pid.startswith("rigid-body")),
    ("test_complex_routes.py", "test_complex_triple_jump_has_order_four_on_a_system", ()),
    # the symbolic rigid body at h^10 (7 s): the orders h^6 and more are deep; its h^8 rows stay in the fast tier
    ("test_shadow_exact_data.py", "test_symbolic_rigid_body_h10_is_solved_within_the_budget", ()),
    # the table served in a fresh process (a process start; the in-process serving is fast-tier)
    ("test_bch_table.py", "test_a_fresh_process_serves_without_numba_or_the_effective_field_modules", ()),
    # the table's top degrees against the full engine (degree 22, ~24 s and ~430 MB): the fast tier checks them against
    # an independent word-coefficient computation on a sample of words (test_the_top_degrees_equal_an_independent_computation)
    ("test_bch_table.py", "test_the_top_degrees_equal_the_engine", ()),
    # the rigid body (over QQ(I1, I2, I3)) and the other 1.2-3 s rows of tables whose lighter rows stay in the fast tier
    # (the parametric field: test_elimination's QQ(a,b) row, test_direct_route_flint; the rigid body's numerics and
    # families: test_numeric, test_shadow, test_any_system's Lie-Poisson member)
    ("test_any_system.py", "test_new_system_numerics",
     ("pendulum", "exp-well", "rational", "henon-heiles", "toda", "ho3-pair")),
    ("test_any_system.py", "test_new_system_shadow_equals_X_eff_two_routes",
     ("pendulum", "exp-well", "rational", "henon-heiles", "fpu-beta", "toda", "ho3-pair")),
    ("test_any_system.py", "test_concrete_equals_generic_substituted_to_h4", ("pendulum-Tc0-Vc0", "exp-well-Tc1-Vc1")),
    ("test_field_backend.py", "test_three_backends_agree_with_plain_sympy", ("ho3", "lotka-volterra", "ho")),
    ("test_design.py", "test_designed_composition_has_order_four_numerically", ("ho3-None",)),
    ("test_bseries.py", "test_shadow_pair_field_equals_modified_field", ("ho3-midpoint", "lotka-volterra-midpoint")),
    ("test_bch_concrete.py", "test_fast_and_plain_representations_agree",
     ("ho3-12321", "lotka-volterra-123", "ho-forest-ruth")),
    # compiled code once per kind in the fast tier: ho3/32123's single-step and batch loops, ho/TVT's Kahan batch loop
    # (which test_hardening_numeric's probes and test_numeric_parallel's threads compile anyway), the Lotka-Volterra
    # batch loop (test_exponential_flows_agree_across_backends), the Runge-Kutta loop, the compiled scan and the sparse
    # BCH engine once each; the other systems' generated loops of this table (0.3-0.9 s of compile each, cold) are
    # deep.  Their generated source is still run on the interpreter by the fast tier (iterate's numpy backend and
    # backend="auto")
    ("test_numeric.py", "test_numba_and_numpy_agree_bitwise", ("False-ho3-32123", "True-ho3-32123")),
    # the kernel cache's damage probes recompile ho3/32123 in an empty cache each: the fast tier keeps garbage in place
    # of the source and an index naming a path outside the cache; the empty files and the unparsable index are deep
    ("test_hardening_numeric.py", "test_corrupt_cache_entries_are_regenerated", ("garbage source", "wrong index")),
    # process starts: one subprocess of `python -m nambu_bch` in the fast tier (every subcommand runs in process in
    # test_cli.py, and the console script in test_help_version_and_console_script); the same argv contract through the
    # console script is checked in process by test_fuzz_cli's edge values
    ("test_cli.py", "test_every_subcommand_runs_as_a_subprocess", ("models",)),
    ("test_fuzz_cli.py", "test_entry_point_subprocess", ()),
    # rows of tables (0.4-2.5 s each, cold) that repeat a kind a lighter row keeps in the fast tier: the paper's other
    # words, a second random instance, the h^4 row of an h^2 concern, the figures drawn again for a string check
    ("test_fuzz_api.py", "test_no_string_argument_is_run_as_code", lambda pid: pid != "nambu_bch.paper_figures"),
    ("test_exact_invariants.py", "test_table_rows", ("12321",)),
    ("test_bch_formal.py", "test_degree_9_exact_against_nilpotent_matrix_log",
     ("12321-1", "1:1/3,2:1/2,1:2/3,3:1,2:1/2-4")),
    ("test_shadow.py", "test_ho3_non_symmetric_words_are_obstructed_at_h1", ("123", "lie-trotter")),
    ("test_integrators.py", "test_time_reversal_symbolic", lambda pid: pid != "lotka-volterra-13231"),
    ("test_bch_concrete.py", "test_bch_route_equals_backward_error_analysis_to_h6",
     lambda pid: pid != "rigid-body-23132"),
    # a second compiled complex loop and its batch (two numba compiles, ~4 s cold): the fast tier keeps ho3's loop
    # against the reference bits
    ("test_complex_compiled.py", "test_compiled_rigid_body_and_batches", ()),
    # the h^2 hull against Eqs. (1AX)-(2BY) for the rigid body over QQ(I1, I2, I3) (2.7 s cold): the fast tier keeps the
    # ho3 (CL5-CL8) and Lotka-Volterra rows, and test_fi_route's rigid-body obstruction at h^2 keeps its hulls
    ("test_fi_route.py", "test_h2_hull_equals_affine_hull_of_eqs_1AX_to_2BY", ("ho3", "lotka-volterra")),
    # the FI span over QQ<2^(1/3)>(m, omega) (2.7 s cold): the fast tier keeps the exact families over QQ(params)
    ("test_fi_route.py", "test_fi_span_is_decided_exactly_over_an_algebraic_parameter_field", ()),
    # the paper's Figs. 3-4 are 32123's (10^4 steps, three solutions each): the fast tier keeps that word; 12321's
    # solutions stay in the fast tier through test_shadow_solution_at_t_equal_h_is_the_map's ho3-12321 row
    ("test_exact_solutions.py", "test_shadow_solution_tracks_the_integrator_figs_3_4", ("32123",)),
    # undefined functions H_i(x_i), G_j(x_j), BCH route against backward error analysis at h^2: the symmetric word in
    # the fast tier; the non-symmetric 123 (0.75 s of backward error analysis) deep: both routes of a non-symmetric
    # word stay in the fast tier on a model (test_bch_concrete's lotka-volterra-123 row, to h^4)
    ("test_bch_fast.py", "test_generic_separable_system_both_routes", ("12321",)),
    # a second degree or word of an obstruction whose first case stays fast
    # (test_shadow's rigid-body Phi^123 at degree 3 keeps the h^1 obstruction, test_ho3_123_obstruction_persists_at_
    # higher_degree the persistence at higher degree; the N = 4 Phi^1234321 at h^2 keeps the N = 4 full split, the
    # ho3 and rigid-body Phi^123 tests the non-symmetric words' failure at h^1)
    ("test_shadow.py", "test_rigid_body_non_symmetric_word_is_obstructed_at_h1_degree_5", ()),
    ("test_shadow.py", "test_n4_full_split_non_symmetric_word_is_obstructed_at_h1", ()),
    # the measured drift of a word without a shadow pair on a third system (the issue's, a kernel compile of its own):
    # test_existence's ho3 (exact averages) and rigid-body (numerical averages) Lie-Trotter tests keep _check_drift
    ("test_existence.py", "test_issue_example_non_symmetric_word_drifts", ()),
    # the docstring example of generic_nambu_h2 solves the generic h^2 system once more (1.2 s) in its own process
    # state: test_any_system's test_generic_nambu_no_universal_shadow_pair_at_h2[12321] asserts the same answer from
    # the shared result
    ("generic_nambu.py", "nambu_bch.shadow.generic_nambu.generic_nambu_h2", ()),
    # a set of four paper figures drawn again (1.4-2 s each, cold: matplotlib's text layout) for a concern a lighter
    # fast test keeps: the write failure through the CLI (test_paper_figures_all_or_nothing keeps the all-or-nothing
    # write, test_cli_edges the one-line output errors of main), the default-length figures at the default dpi
    # (test_paper_figures_returns_figures_with_parameters and test_cli.py's test_plot write the four PNGs)
    ("test_hardening_numeric.py", "test_cli_plot_file_error_one_line", ()),
    ("test_numeric_diagnostics.py", "test_paper_figures_are_written", ()),
    # the non-symmetric word 123 shown not time-reversible on a second system (its exponential flows composed and
    # reversed, 0.5-1.3 s): the fast tier keeps the ho3 row, and test_time_reversal_symbolic's lotka-volterra-12321
    # row composes and reverses the same exponential flows
    ("test_integrators.py", "test_no_time_reversal_for_123", ("ho3",)),
    # Auzinger's first table (CheckMethods, test_catalog_published): the three rows of 0.2-0.3 s CPU each whose kind a
    # lighter row keeps in the fast tier -- an order-6 real method (Y 8-6 keeps KL 10-6 and BM 11-6 PRK) and a complex
    # one (Emb 3/2 A c and the Milne 2/2 c rows keep A 3-3 c); every published row is still checked by the deep tier
    ("test_catalog_published.py", "test_ab_table_of_check_methods",
     lambda pid: pid not in ("KL 10-6", "BM 11-6 PRK", "A 3-3 c")),
    # the Runge-Kutta module's explicit and Kahan loops compiled against the interpreter (1.5-3 s each cold): the fast
    # tier keeps Newton's loop compiled bit for bit (test_compiled_equals_interpreted_bit_for_bit, gauss4), both
    # kinds interpreted against the reference (test_generated_step_matches_reference) and each entry point's callees
    ("test_runge_kutta_numeric.py", "test_explicit_and_kahan_loops_compiled_equal_interpreted_bit_for_bit", ()),
)

#: The two ways :func:`cli_run` runs the command line; the fast tier keeps ``in-process``: the ``subprocess`` case
#: carries the mark ``deep`` itself, so a new test asking for ``cli_run`` needs no entry in :data:`DEEP`.
CLI_RUNNERS = ("in-process", pytest.param("subprocess", marks=pytest.mark.deep))
REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(params=CLI_RUNNERS)
def cli_run(request, monkeypatch):
    """``run(*argv, cwd=...)``: ``nambu-bch ARGV`` in the directory ``cwd``, as a ``CompletedProcess``.

    Two cases of every test that asks for it: ``main(argv)`` in this process (stdout and stderr captured, the working
    directory changed for the call), and ``python -m nambu_bch ARGV`` in a subprocess (the package from this checkout).
    The same assertions run on both.  The subprocess case is deep (its parameter's mark): a process start adds only the
    interpreter start and the imports, which ``test_cli.py``'s subprocess of ``python -m nambu_bch`` checks in the fast
    tier (and one subprocess per subcommand in the deep tier).
    """
    def in_process(*args, cwd):
        from nambu_bch.cli import main

        argv = [str(a) for a in args]
        out, err = io.StringIO(), io.StringIO()
        with monkeypatch.context() as m:
            m.chdir(cwd)
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(argv)
        return subprocess.CompletedProcess(argv, code, out.getvalue(), err.getvalue())

    def in_subprocess(*args, cwd):
        env = {**os.environ, "PYTHONPATH": str(REPO)}
        return subprocess.run([sys.executable, "-m", "nambu_bch", *map(str, args)], cwd=cwd, env=env,
                              capture_output=True, text=True, timeout=600)

    return in_process if request.param == "in-process" else in_subprocess


#: Plugin distributions whose modules pytest marks for assertion rewriting (every module of a distribution with a
#: ``pytest11`` entry point).  None of them has an ``assert`` the suite relies on (the package has none at all), but
#: every pytest process re-parsed and rewrote ~150 of their modules as they were imported, ~0.7 s of CPU per process,
#: since ``PYTHONDONTWRITEBYTECODE`` keeps pytest from caching the result (docs/suite_time.md).  A module imported
#: before :func:`pytest_configure` (by a plugin's own imports) is rewritten regardless: hence the package's light
#: ``pytest11`` module, ``nambu_bch._pytest_plugin``.
NOT_REWRITTEN = ("nambu_bch", "hypothesis", "_hypothesis_pytestplugin", "_hypothesis_globals", "_hypothesis_ftz_detector",
                 "xdist", "platformdirs")


def pytest_configure(config):
    """Assertion rewriting for the tests only: unmark :data:`NOT_REWRITTEN`; and the session's bytecode
    (tests/session_bytecode.py) removed at its end where ``PYTHONDONTWRITEBYTECODE`` asks for none.

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
    if not hasattr(config, "workerinput") and sys.dont_write_bytecode:
        # the workers compile bytecode for the session (pytest_sessionstart); the checkout is left as it was found
        files = session_bytecode.initial_sources(config)
        before = session_bytecode.snapshot(files)
        config.add_cleanup(lambda: session_bytecode.remove_new(files, before))


def pytest_sessionstart(session):
    """An xdist worker compiles its share of the run's bytecode before collecting (tests/session_bytecode.py)."""
    workerinput = getattr(session.config, "workerinput", None)
    if workerinput and workerinput.get("workercount", 1) > 1:
        worker = int(str(workerinput.get("workerid", "gw0")).lstrip("gw") or 0)
        files = session_bytecode.initial_sources(session.config)
        session_bytecode.precompile(files, worker, workerinput["workercount"],
                                    session_bytecode.pytest_rewriter(session.config))


def pytest_sessionfinish(session):
    """joblib's reusable loky pool, if a test started one: its idle workers stopped now, without waiting for them to
    tear down their interpreters (``kill_workers``), instead of the process's exit joining them (1.5-2.5 s)."""
    reusable = sys.modules.get("joblib.externals.loky.reusable_executor")
    executor = getattr(reusable, "_executor", None)
    if executor is not None:
        executor.shutdown(wait=True, kill_workers=True)


def pytest_unconfigure(config):
    """An xdist worker's session is over and its process is about to end: the objects it made are moved out of the
    garbage collector's reach (:func:`gc.freeze`), so the interpreter's exit does not trace a heap of hundreds of MB
    once more (a worker's exit took 2.5-3.5 s, most of it that final collection).  Memory is returned to the system
    with the process; atexit handlers (``weakref.finalize``'s among them) still run.  Not in a single-process run,
    which may be a ``pytest.main`` inside a longer-lived program."""
    if hasattr(config, "workerinput"):
        gc.freeze()


def _deep_run(config) -> bool:
    """Whether this run's ``-m`` expression selects the deep tier (true for a test marked ``deep`` alone)."""
    expr = config.getoption("markexpr", "") or ""
    if not expr:
        return False
    try:
        from _pytest.mark.expression import Expression

        return bool(Expression.compile(expr).evaluate(lambda name, **kwargs: name == "deep" and not kwargs))
    except Exception:  # pytest's private parser changed: fall back to the words themselves
        return "deep" in expr.split() and "not" not in expr.split()


def _index_tiers():
    """:data:`DEEP` by (file, test name) (the first entry of a pair wins) and :data:`LONG` by file, in order: each
    item is then matched against its own file's few entries, not against every entry."""
    deep, long_ = {}, {}
    for f, n, keep in DEEP:
        deep.setdefault((f, n), keep)
    for i, (f, n) in enumerate(LONG):
        long_.setdefault(f, []).append((i, n))
    return deep, long_


def _in_deep_tier(file: str, name: str, deep_index: dict) -> bool:
    """Whether the test ``name`` of ``file`` is deep.  A DEEP entry names a test function (no ``[``: checked by
    tests/test_suite_tiers.py), so the entry of ``name`` is that of its function's name, the part before ``[``."""
    n, bracket, _ = name.partition("[")
    keep = deep_index.get((file, n))
    if keep is None:
        return False
    pid = name[len(n) + 1:-1] if bracket else ""
    return not (keep(pid) if callable(keep) else pid in keep)


def _scale_hypothesis(item, deep: bool) -> None:
    """A fast-tier hypothesis test draws ``ceil(n / HYPOTHESIS_FAST_DIVISOR)`` of its ``n`` examples."""
    test = getattr(item, "obj", None)
    test = getattr(test, "__func__", test)  # a method's function carries the settings
    current = getattr(test, "_hypothesis_internal_use_settings", None)
    if deep or current is None or not getattr(test, "is_hypothesis_test", False):
        return
    from hypothesis import settings

    full = _FULL_SETTINGS.setdefault(test, current)  # the parametrised cases of one test share its function
    fast = max(1, math.ceil(full.max_examples / HYPOTHESIS_FAST_DIVISOR))
    # the attribute @given reads its settings from when the test runs (hypothesis 6); absent, nothing changes
    test._hypothesis_internal_use_settings = settings(full, max_examples=fast)


_FULL_SETTINGS: dict = {}


def pytest_collection_modifyitems(session, config, items):
    deep = _deep_run(config)
    names = [(item.path.name, item.name) for item in items]
    # every collected (file, test name) before selection, for tests/test_suite_tiers.py's check of DEEP
    config.nambu_bch_collected = set(names)
    config.nambu_bch_deep = DEEP
    deep_index, long_index = _index_tiers()
    ranks = []
    for item, (f, name) in zip(items, names):
        if _in_deep_tier(f, name, deep_index):
            item.add_marker(pytest.mark.deep)
        elif deep and getattr(getattr(item, "obj", None), "is_hypothesis_test", False):
            item.add_marker(pytest.mark.deep)  # the deep tier runs the hypothesis tests again, at full counts
        _scale_hypothesis(item, deep)
        # the first LONG entry whose name prefix the test's name has, else after all of them
        ranks.append(next((i for i, n in long_index.get(f, ()) if name.startswith(n)), len(LONG)))

    order = sorted(range(len(items)), key=ranks.__getitem__)  # stable: the order among equal ranks is kept
    items[:] = [items[i] for i in order]
