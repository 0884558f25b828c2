"""nambu_bch: shadow Hamiltonians of splitting integrators in Nambu mechanics.

The public surface is re-exported here; see README.md for a tour and the architecture.
"""

from . import errors
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
from .bch import EffectiveField, FormalBCH, effective_field, effective_field_bch, expand_terms, formal_bch
from .errors import NambuBCHError
from .exact import (
    F,
    ConservedQuantities,
    ExactShadow,
    F_series,
    ModifiedSolution,
    conserved_quantities,
    exact_shadow_hamiltonians,
    is_invariant,
    modified_equations,
    modified_solution,
)
from .integrators import PAPER_WORDS, Composition, composed_map, composition, exact_flow, step_function
from .numeric import check, iterate, paper_figures, sample_times
from .shadow import (
    LiouvilleSum,
    LiouvilleTerm,
    ShadowFamily,
    direct_route,
    fi_route,
    representations,
    shadow_hamiltonians,
)
from .systems import Splitting, System, full_split, model, model_names, separate, single_split
from .design import (  # issue 15: choosing and designing the integrator
    compare,
    composition_order,
    error_constant,
    leading_error,
    optimize_composition,
    order_conditions,
)

__version__ = "0.1.0"

__all__ = [
    "PAPER_WORDS",
    "Composition",
    "ConservedQuantities",
    "EffectiveField",
    "ExactShadow",
    "F",
    "F_series",
    "FormalBCH",
    "LiouvilleSum",
    "LiouvilleTerm",
    "ModifiedSolution",
    "NambuBCHError",
    "PolynomialAlgebra",
    "ShadowFamily",
    "Splitting",
    "System",
    "VectorField",
    "check",
    "compare",
    "composed_map",
    "composition",
    "composition_order",
    "conserved_quantities",
    "direct_route",
    "effective_field",
    "effective_field_bch",
    "error_constant",
    "errors",
    "exact_flow",
    "exact_shadow_hamiltonians",
    "expand_terms",
    "fi_route",
    "formal_bch",
    "full_split",
    "is_invariant",
    "is_symplectic",
    "iterate",
    "leading_error",
    "lie_bracket",
    "liouville_field",
    "model",
    "model_names",
    "modified_equations",
    "modified_solution",
    "nambu_bracket",
    "optimize_composition",
    "order_conditions",
    "paper_figures",
    "poisson_bracket",
    "representations",
    "sample_times",
    "satisfies_nambu_condition",
    "separate",
    "shadow_hamiltonians",
    "single_split",
    "step_function",
]
