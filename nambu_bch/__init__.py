"""nambu_bch: shadow Hamiltonians of splitting integrators in Nambu mechanics.

The public surface is re-exported here; see README.md for a tour and the architecture.
"""

from . import _startup  # noqa: F401  (first: Ctrl-C during the command line's imports is one line, exit 130)
from . import errors
from .errors import NambuBCHError

# The public names are imported on first use (PEP 562), so that ``nambu-bch --help`` and argument
# errors answer without importing sympy, numpy and numba; ``from nambu_bch import X`` works as before.
# ``__all__`` is the curated set a session needs: systems, the shadow Hamiltonians, the exact results, the
# effective field and formal series, numerics, design, the result types and the errors.
_LAZY = {
    ".bch": ("EffectiveField", "FormalBCH", "effective_field", "formal_bch"),
    ".bseries": ("ModifiedEquation", "modified_equation", "runge_kutta_shadow"),
    ".design": ("compare", "composition_order", "error_constant", "leading_error", "optimize_composition",
                "order_conditions"),
    ".exact": ("ConservedQuantities", "ExactShadow", "ModifiedSolution", "conserved_quantities",
               "exact_shadow_hamiltonians", "modified_solution"),
    ".integrators": ("PAPER_WORDS", "Composition", "composition"),
    ".numeric": ("ShadowTrajectory", "check", "iterate", "paper_figures", "shadow_along"),
    ".parallel": ("sweep",),
    ".shadow": ("ShadowFamily", "shadow_hamiltonians"),
    ".systems": ("System", "model", "model_names"),
}
_WHERE = {name: module for module, names in _LAZY.items() for name in names}

# Route-level and building-block names of the earlier, wider top level: their home is the subpackage
# (``nambu_bch.shadow.direct_route``, ...); they still resolve here so that existing code keeps working, but are
# not in ``__all__`` or ``dir()``.
_MOVED = {
    ".algebra": ("PolynomialAlgebra", "VectorField", "is_symplectic", "lie_bracket", "liouville_field", "nambu_bracket",
                 "poisson_bracket", "satisfies_nambu_condition"),
    ".bch": ("effective_field_bch", "expand_terms"),
    ".exact": ("F", "F_series", "is_invariant", "modified_equations"),
    ".integrators": ("ButcherTableau", "butcher_tableau", "composed_map", "exact_flow", "step_function"),
    ".numeric": ("sample_times",),
    ".shadow": ("LiouvilleSum", "LiouvilleTerm", "direct_route", "fi_route", "representations"),
    ".systems": ("Splitting", "full_split", "separate", "single_split"),
}
_MOVED_WHERE = {name: module for module, names in _MOVED.items() for name in names}


def __getattr__(name):
    if name == "__version__":
        globals()[name] = value = _version()
        return value
    module = _WHERE.get(name)
    moved = module is None
    if moved:
        module = _MOVED_WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'nambu_bch' has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(module, __name__), name)
    if not moved:  # a moved name is not cached here, so that it stays out of dir()
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
