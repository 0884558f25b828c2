"""Compositions as data, exact sub-flows, the composed map and a numeric step."""

from .compose import composed_map
from .composition import PAPER_WORDS, Composition, composition, composition_for, strang_word
from .flows import ExactFlow, exact_flow
from .runge_kutta import TABLEAUX, ButcherTableau, butcher_tableau
from .step import parameter_values, step_function, subflow_functions

__all__ = [
    "PAPER_WORDS",
    "TABLEAUX",
    "ButcherTableau",
    "Composition",
    "butcher_tableau",
    "ExactFlow",
    "composed_map",
    "composition",
    "composition_for",
    "exact_flow",
    "parameter_values",
    "step_function",
    "strang_word",
    "subflow_functions",
]
