"""The public surface, pinned: the names each package re-exports (``__all__``) and the cache registry.

A change of the public API (a name added, renamed or dropped) must be deliberate:
it fails here until the table below is updated with it.  Each listed name must also resolve, and ``nambu_bch.clear_caches``
must know every ``functools.lru_cache`` and module-level cache dictionary of the
package, checked by scanning every module.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
import weakref

import pytest

import nambu_bch
from nambu_bch.caches import CACHES

SURFACE = {
    "nambu_bch": (
        "Composition", "ConservedQuantities", "EffectiveField", "ExactShadow", "FormalBCH", "ModifiedEquation",
        "ModifiedSolution", "NambuBCHError", "PAPER_WORDS", "ShadowFamily", "ShadowTrajectory", "System", "check",
        "clear_caches", "compare", "composition", "composition_order", "conserved_quantities", "effective_field",
        "error_constant", "errors", "exact_shadow_hamiltonians", "formal_bch", "iterate", "leading_error", "model",
        "model_names", "modified_equation", "modified_solution", "optimize_composition", "order_conditions",
        "paper_figures", "runge_kutta_shadow", "shadow_along", "shadow_hamiltonians", "sweep",
    ),
    "nambu_bch.algebra": (
        "CoefficientField", "ExactRing", "ExpressionBackend", "FieldBackend", "PolynomialAlgebra", "PolynomialBackend",
        "VectorField",
        "field_backend", "is_symplectic", "jacobian", "lie_bracket", "liouville_field",
        "nambu_bracket", "poisson_bracket", "satisfies_nambu_condition",
    ),
    "nambu_bch.bch": (
        "BracketEvaluator", "EffectiveField", "FormalBCH", "check_order", "clear_cache", "effective_field",
        "effective_field_bch", "estimate_size", "expand_terms", "formal_bch", "is_bracket", "lie_to_associative",
        "lyndon_words", "standard_bracketing", "terms_to_latex", "tree_degree", "tree_to_associative",
        "tree_to_latex", "witt_dimension",
    ),
    "nambu_bch.bseries": (
        "ColouredTrees", "EulerTopClosedForms", "KahanMap", "ModifiedEquation", "density", "elementary_weight",
        "euler_top_closed_forms", "euler_top_coefficients", "euler_top_density", "graft", "kahan_map",
        "modified_coefficients", "modified_equation", "modified_equation_by_taylor", "order",
        "p_series_modified_equation", "runge_kutta_shadow", "symmetry", "trees",
    ),
    "nambu_bch.cli": (
        "SUBCOMMANDS", "UsageError", "build_parser", "main",
    ),
    "nambu_bch.design": (
        "CatalogComposition", "Comparison", "DesignedComposition", "ErrorConstant", "GradientField", "GradientShadow",
        "LeadingError", "NoSolutionError", "OrderConditions", "Template", "compare", "composition_order", "cost",
        "error_analysis", "error_constant", "field_size", "gradient_effective_field", "gradient_shadow",
        "leading_error", "methods", "optimize_composition", "order_conditions", "runge_kutta_error_constant", "template",
    ),
    "nambu_bch.exact": (
        "ConservedQuantities", "ExactShadow", "F", "F_series", "LinearCore", "ModifiedSolution",
        "conserved_quantities", "exact_shadow_hamiltonians", "is_invariant", "linear_core", "modified_equations",
        "modified_solution",
    ),
    "nambu_bch.integrators": (
        "ButcherTableau", "Composition", "ExactFlow", "PAPER_WORDS", "TABLEAUX", "butcher_tableau", "composed_map",
        "composition", "composition_for", "exact_flow",
        "parameter_values", "step_function", "strang_word", "subflow_functions",
    ),
    "nambu_bch.numeric": (
        "CheckResult", "DriftFit", "Estimate", "FigureSet", "GradientCheck", "HScan", "Kernel", "MonteCarloRun",
        "NumericalShadow", "OrderFit", "PrecisionStudy", "Progress", "RunningStats", "ShadowTrajectory", "StepProgram",
        "TruncationStudy", "cache_dir", "check", "drift_rate", "fit_order", "gradient_check", "h_scan",
        "hybrid_monte_carlo", "iterate", "iterate_chunks", "iterate_complex", "iterate_gradient", "iterate_processed",
        "kernel", "n_samples", "numba_available",
        "numerical_shadow", "observed_order",
        "paper_figures", "precision_study", "quantities", "rk_iterate", "rk_step_function", "sample_steps",
        "sample_times", "shadow_along", "step_program", "truncation_study",
    ),
    "nambu_bch.shadow": (
        "Contraction", "ContractionSum", "DensityBrackets", "DirectResult", "Existence", "FICommutator", "FINested", "FIOrder",
        "FIRepresentation", "FIResult", "FI_LABELS", "JetAlgebra", "LiouvilleSum", "LiouvilleTerm", "OrderSolution",
        "SeparableShadow", "ShadowFamily", "commutator_terms", "count_brackets", "decide", "density_brackets", "density_shadow",
        "direct_route", "double_commutator_terms", "fi_brackets", "fi_route", "representations", "separable_shadow",
        "shadow_hamiltonians",
    ),
    "nambu_bch.systems": (
        "BRACKETS", "Piece", "Splitting", "System", "canonical_split", "full_split", "infer_bracket", "is_separable",
        "model", "model_names", "separate", "single_split", "triplet_split",
    ),
}


@pytest.mark.parametrize("module", sorted(SURFACE))
def test_all_is_pinned(module):
    mod = importlib.import_module(module)
    assert tuple(sorted(mod.__all__)) == SURFACE[module]
    assert len(set(mod.__all__)) == len(mod.__all__)


@pytest.mark.parametrize("module", sorted(SURFACE))
def test_every_public_name_resolves(module):
    mod = importlib.import_module(module)
    missing = [name for name in mod.__all__ if not hasattr(mod, name)]
    assert missing == []


def test_top_level_names_are_the_subpackages_objects():
    """``nambu_bch.X`` is the object of the subpackage that defines it (one concept, one place)."""
    for name in nambu_bch.__all__:
        if name in ("errors", "NambuBCHError", "clear_caches"):
            continue
        value = getattr(nambu_bch, name)
        home = importlib.import_module(nambu_bch._WHERE[name], "nambu_bch")
        assert getattr(home, name) is value, name


#: names of the earlier, wider top level, now at home in their subpackage only; still resolved at the top level
MOVED = (
    "ButcherTableau", "F", "F_series", "LiouvilleSum", "LiouvilleTerm", "PolynomialAlgebra", "Splitting", "VectorField",
    "butcher_tableau", "composed_map", "direct_route", "effective_field_bch", "exact_flow", "expand_terms", "fi_route",
    "full_split", "is_invariant", "is_symplectic", "lie_bracket", "liouville_field", "modified_equations",
    "nambu_bracket", "poisson_bracket", "representations", "sample_times", "satisfies_nambu_condition", "separate",
    "single_split", "step_function",
)


@pytest.mark.parametrize("name", MOVED)
def test_moved_names_still_resolve_at_the_top_level(name):
    """``nambu_bch.direct_route`` etc. keep working (the subpackage's object), outside ``__all__`` and ``dir()``."""
    value = getattr(nambu_bch, name)
    assert getattr(importlib.import_module(nambu_bch._MOVED_WHERE[name], "nambu_bch"), name) is value
    assert name not in nambu_bch.__all__ and name not in dir(nambu_bch)
    namespace = {}
    exec(f"from nambu_bch import {name}", namespace)  # the import statement of existing code
    assert namespace[name] is value


def test_unknown_top_level_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'shadow_hamiltonian'"):
        nambu_bch.shadow_hamiltonian  # noqa: B018


def _all_modules():
    for info in pkgutil.walk_packages(nambu_bch.__path__, "nambu_bch."):
        if not info.name.endswith("__main__"):
            yield importlib.import_module(info.name)


def _module_caches():
    """``(module, attribute)`` of every lru_cache function and every module-level cache dictionary."""
    found = set()
    for mod in _all_modules():
        for attr, obj in vars(mod).items():
            if hasattr(obj, "cache_clear") and getattr(obj, "__module__", None) == mod.__name__:
                found.add((mod.__name__, attr))
            elif isinstance(obj, weakref.WeakKeyDictionary) or (
                    isinstance(obj, dict) and attr.startswith("_") and attr.isupper() and not obj):
                # empty module-level dicts named like constants are filled at run time: caches
                found.add((mod.__name__, attr))
    return found


# run-time dictionaries that are not caches: interning tables whose entries live sums refer to
NOT_CACHES = {("nambu_bch.shadow.liouville_terms", "_ATOM_IDS")}
# caches emptied by a module's clear_cache() listed in CACHES
VIA_CLEAR_CACHE = {
    ("nambu_bch.bch.concrete", "_EVALUATORS"), ("nambu_bch.bch.formal", "_PATTERN_CACHE"),
    ("nambu_bch.bch.table", "_TREES"), ("nambu_bch.bch.table", "_WORDS"), ("nambu_bch.bch.table", "_NUMERATORS"),
    ("nambu_bch.numeric.precision", "_MPMATH"), ("nambu_bch.shadow.fi_route", "_RAW_OPS"),
    ("nambu_bch.shadow.fi_route", "_FORMS"), ("nambu_bch.shadow.fi_route", "_MONOMIAL_COLUMNS"),
    ("nambu_bch.shadow.fi_route", "_EVALUATORS"), ("nambu_bch.shadow.fi_route", "_OPERATOR"),
    ("nambu_bch.shadow.liouville_terms", "_CONTEXTS"),
    ("nambu_bch.shadow.liouville_terms", "canonical_key"), ("nambu_bch.shadow.liouville_terms", "_dependent"),
}


def test_clear_caches_knows_every_cache():
    listed = set(CACHES)
    missing = _module_caches() - listed - NOT_CACHES - VIA_CLEAR_CACHE
    assert missing == set()
    for module, attr in CACHES:  # every entry names something that exists
        assert hasattr(importlib.import_module(module), attr), (module, attr)


def test_clear_caches_empties_them():
    """After work that fills the caches, ``nambu_bch.clear_caches()`` leaves every one empty; results are unchanged."""
    from nambu_bch import composition, formal_bch, model, shadow_hamiltonians

    before = shadow_hamiltonians(model("ho3"), "12321", order=2)
    formal_bch(composition("12321"), 4)
    sizes = {}
    for module, attr in CACHES:
        obj = getattr(sys.modules[module], attr, None) if module in sys.modules else None
        if hasattr(obj, "cache_info"):
            sizes[(module, attr)] = obj.cache_info().currsize
    assert any(sizes.values())  # the computation above did fill some
    nambu_bch.clear_caches()
    for module, attr in CACHES:
        if module not in sys.modules:
            continue
        obj = getattr(sys.modules[module], attr)
        if hasattr(obj, "cache_info"):
            assert obj.cache_info().currsize == 0, (module, attr)
        elif not callable(obj):
            assert len(obj) == 0, (module, attr)
    for module, attr in VIA_CLEAR_CACHE:
        obj = getattr(sys.modules[module], attr)
        assert (obj.cache_info().currsize if hasattr(obj, "cache_info") else len(obj)) == 0, (module, attr)
    after = shadow_hamiltonians(model("ho3"), "12321", order=2)  # Eqs. SH12321c, SG12321c, recomputed
    assert after.H_S == before.H_S and after.G_S == before.G_S
