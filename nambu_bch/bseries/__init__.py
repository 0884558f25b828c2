"""B-series: rooted trees, the modified equation of a Runge--Kutta method, its shadow Hamiltonians; Kahan's map;
P-series (coloured trees) of partitioned pairs."""

from .kahan import (EulerTopClosedForms, KahanMap, euler_top_closed_forms, euler_top_coefficients, euler_top_density,
                    kahan_map)
from .modified import ModifiedEquation, modified_equation, modified_equation_by_taylor, runge_kutta_shadow
from .p_series import ColouredTrees, p_series_modified_equation
from .rooted_trees import density, elementary_weight, graft, modified_coefficients, order, symmetry, trees

__all__ = [
    "ColouredTrees",
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
    "p_series_modified_equation",
    "runge_kutta_shadow",
    "symmetry",
    "trees",
]
