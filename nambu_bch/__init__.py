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
    ".bseries": ("modified_equation", "runge_kutta_shadow"),
    ".design": ("compare", "composition_order", "error_constant", "leading_error", "optimize_composition",
                "order_conditions"),
    ".bch": ("EffectiveField", "FormalBCH", "effective_field", "effective_field_bch", "expand_terms", "formal_bch"),
    ".exact": ("F", "ConservedQuantities", "ExactShadow", "F_series", "ModifiedSolution", "conserved_quantities",
               "exact_shadow_hamiltonians", "is_invariant", "modified_equations", "modified_solution"),
    ".integrators": ("PAPER_WORDS", "ButcherTableau", "Composition", "butcher_tableau", "composed_map", "composition",
                     "exact_flow", "step_function"),
    ".numeric": ("check", "iterate", "paper_figures", "sample_times", "shadow_along", "ShadowTrajectory"),
    ".shadow": ("LiouvilleSum", "LiouvilleTerm", "ShadowFamily", "direct_route", "fi_route", "representations",
                "shadow_hamiltonians"),
    ".parallel": ("sweep",),
    ".systems": ("Splitting", "System", "full_split", "model", "model_names", "separate", "single_split"),
}
_WHERE = {name: module for module, names in _LAZY.items() for name in names}


def __getattr__(name):
    if name == "__version__":
        globals()[name] = value = _version()
        return value
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'nambu_bch' has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE) | {"__version__"})


def clear_caches() -> None:
    """Empty every in-memory cache of the package (:func:`nambu_bch.caches.clear_caches`)."""
    from .caches import clear_caches as clear

    clear()


def _version() -> str:
    """The installed distribution's version: pyproject.toml's ``version`` is the one place it is written."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("nambu_bch")
    except PackageNotFoundError:  # a source tree on sys.path that was never installed
        return "0+unknown"


__all__ = sorted([*_WHERE, "NambuBCHError", "clear_caches", "errors"])
