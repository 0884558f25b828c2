"""Exact polynomials, brackets, Liouville fields, vector fields and their backends, structure conditions."""

from .backend import ExpressionBackend, FieldBackend, PolynomialBackend, field_backend
from .brackets import liouville_field, nambu_bracket, poisson_bracket
from .fields import CoefficientField
from .polynomial import PolynomialAlgebra
from .ring import ExactRing
from .structure import is_symplectic, jacobian, satisfies_nambu_condition
from .vector_field import VectorField, lie_bracket

__all__ = [
    "CoefficientField",
    "ExactRing",
    "ExpressionBackend",
    "FieldBackend",
    "PolynomialAlgebra",
    "PolynomialBackend",
    "VectorField",
    "field_backend",
    "is_symplectic",
    "jacobian",
    "lie_bracket",
    "liouville_field",
    "nambu_bracket",
    "poisson_bracket",
    "satisfies_nambu_condition",
]
