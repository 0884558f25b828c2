"""Brackets, Liouville fields, Lie brackets and structure conditions."""

from .brackets import liouville_field, nambu_bracket, poisson_bracket
from .polynomial import PolynomialAlgebra
from .structure import is_symplectic, jacobian, satisfies_nambu_condition
from .vector_field import VectorField, lie_bracket

__all__ = [
    "PolynomialAlgebra",
    "VectorField",
    "is_symplectic",
    "jacobian",
    "lie_bracket",
    "liouville_field",
    "nambu_bracket",
    "poisson_bracket",
    "satisfies_nambu_condition",
]
