"""Compositions as data, exact sub-flows, the composed map and a numeric step."""

from .compose import composed_map
from .composition import PAPER_WORDS, Composition, composition
from .flows import ExactFlow, exact_flow
from .step import parameter_values, step_function, subflow_functions

__all__ = [
    "PAPER_WORDS",
    "Composition",
    "ExactFlow",
    "composed_map",
    "composition",
    "exact_flow",
    "parameter_values",
    "step_function",
    "subflow_functions",
]
