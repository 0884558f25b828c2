"""nambu_bch: shadow Hamiltonians of splitting integrators in Nambu mechanics.

The public surface is re-exported here; see README.md for a tour and the architecture.
"""

from . import _startup  # noqa: F401  (first: Ctrl-C during the command line's imports is one line, exit 130)
from . import errors
from .errors import NambuBCHError

# The public names are imported on first use (PEP 562), so that ``nambu-bch --help`` and argument
# errors answer without importing sympy, numpy and numba; ``from nambu_bch import X`` works as before.
_LAZY = {
    ".algebra": ("PolynomialAlgebra", "VectorField", "is_symplectic", "lie_bracket", "liouville_field", "nambu_bracket",
                 "poisson_bracket", "satisfies_nambu_condition"),
    ".bch": ("EffectiveField", "FormalBCH", "effective_field", "effective_field_bch", "expand_terms", "formal_bch"),
    ".exact": ("F", "ConservedQuantities", "ExactShadow", "F_series", "ModifiedSolution", "conserved_quantities",
               "exact_shadow_hamiltonians", "is_invariant", "modified_equations", "modified_solution"),
    ".integrators": ("PAPER_WORDS", "Composition", "composed_map", "composition", "exact_flow", "step_function"),
    ".numeric": ("check", "iterate", "paper_figures", "sample_times"),
    ".shadow": ("LiouvilleSum", "LiouvilleTerm", "ShadowFamily", "direct_route", "fi_route", "representations",
                "shadow_hamiltonians"),
    ".systems": ("Splitting", "System", "full_split", "model", "model_names", "separate", "single_split"),
}
_WHERE = {name: module for module, names in _LAZY.items() for name in names}


def __getattr__(name):
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'nambu_bch' has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


__version__ = "0.1.0"

__all__ = [
    "PAPER_WORDS",
    "Composition",
    "ConservedQuantities",
    "EffectiveField",
    "ExactShadow",
    "F",
    "F_series",
    "FormalBCH",
    "LiouvilleSum",
    "LiouvilleTerm",
    "ModifiedSolution",
    "NambuBCHError",
    "PolynomialAlgebra",
    "ShadowFamily",
    "Splitting",
    "System",
    "VectorField",
    "check",
    "composed_map",
    "composition",
    "conserved_quantities",
    "direct_route",
    "effective_field",
    "effective_field_bch",
    "errors",
    "exact_flow",
    "exact_shadow_hamiltonians",
    "expand_terms",
    "fi_route",
    "formal_bch",
    "full_split",
    "is_invariant",
    "is_symplectic",
    "iterate",
    "lie_bracket",
    "liouville_field",
    "model",
    "model_names",
    "modified_equations",
    "modified_solution",
    "nambu_bracket",
    "paper_figures",
    "poisson_bracket",
    "representations",
    "sample_times",
    "satisfies_nambu_condition",
    "separate",
    "shadow_hamiltonians",
    "single_split",
    "step_function",
]
