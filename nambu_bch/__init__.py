"""nambu_bch: shadow Hamiltonians of splitting integrators in Nambu mechanics.

The public surface is re-exported here; see README.md for a tour.
"""

from .algebra import (
    PolynomialAlgebra,
    VectorField,
    is_symplectic,
    lie_bracket,
    liouville_field,
    nambu_bracket,
    poisson_bracket,
    satisfies_nambu_condition,
)
from .errors import NambuBCHError
from .integrators import PAPER_WORDS, Composition, composed_map, composition, exact_flow, step_function
from .systems import Splitting, System, full_split, model, model_names, separate, single_split

__version__ = "0.1.0"

__all__ = [
    "PAPER_WORDS",
    "Composition",
    "NambuBCHError",
    "PolynomialAlgebra",
    "Splitting",
    "System",
    "VectorField",
    "composed_map",
    "composition",
    "exact_flow",
    "full_split",
    "is_symplectic",
    "lie_bracket",
    "liouville_field",
    "model",
    "model_names",
    "nambu_bracket",
    "poisson_bracket",
    "satisfies_nambu_condition",
    "separate",
    "single_split",
    "step_function",
]
