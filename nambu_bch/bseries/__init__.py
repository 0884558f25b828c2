"""B-series: rooted trees, the modified equation of a Runge--Kutta method, its shadow Hamiltonians; Kahan's map."""

from .kahan import (EulerTopClosedForms, KahanMap, euler_top_closed_forms, euler_top_coefficients, euler_top_density,
                    kahan_map)
from .modified import ModifiedEquation, modified_equation, modified_equation_by_taylor, runge_kutta_shadow
from .rooted_trees import density, elementary_weight, graft, modified_coefficients, order, symmetry, trees

__all__ = [
    "EulerTopClosedForms",
    "KahanMap",
    "ModifiedEquation",
    "density",
    "elementary_weight",
    "euler_top_closed_forms",
    "euler_top_coefficients",
    "euler_top_density",
    "graft",
    "kahan_map",
    "modified_coefficients",
    "modified_equation",
    "modified_equation_by_taylor",
    "order",
    "runge_kutta_shadow",
    "symmetry",
    "trees",
]
