"""Exact results: invariants of the discrete map, the factor F(x), exact shadow Hamiltonians, exact solutions."""

from .factor import F, F_series
from .exact_shadow import ExactShadow, exact_shadow_hamiltonians
from .invariants import ConservedQuantities, conserved_quantities, is_invariant
from .solutions import ModifiedSolution, modified_equations, modified_solution

__all__ = ["ConservedQuantities", "ExactShadow", "F", "F_series", "ModifiedSolution", "conserved_quantities", "exact_shadow_hamiltonians", "is_invariant", "modified_equations", "modified_solution"]
