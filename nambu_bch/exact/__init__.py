"""Exact results: invariants of the discrete map, the factor F(x), exact shadow Hamiltonians, exact solutions."""

from .factor import F, F_series
from .invariants import ConservedQuantities, conserved_quantities, is_invariant

__all__ = ["ConservedQuantities", "F", "F_series", "conserved_quantities", "is_invariant"]
