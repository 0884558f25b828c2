"""B-series: rooted trees, the modified equation of a Runge--Kutta method, its shadow Hamiltonians."""

from .modified import ModifiedEquation, modified_equation, modified_equation_by_taylor, runge_kutta_shadow
from .rooted_trees import density, elementary_weight, graft, modified_coefficients, order, symmetry, trees

__all__ = [
    "ModifiedEquation",
    "density",
    "elementary_weight",
    "graft",
    "modified_coefficients",
    "modified_equation",
    "modified_equation_by_taylor",
    "order",
    "runge_kutta_shadow",
    "symmetry",
    "trees",
]
