"""Shadow Hamiltonians: Liouville-term algebra, the fundamental identity, the FI and direct routes, ``ShadowFamily``."""

from .api import shadow_hamiltonians
from .density_bracket import DensityBrackets, density_brackets, density_shadow
from .direct_route import DirectResult, OrderSolution, direct_route
from .existence import Existence, decide
from .family import ShadowFamily
from .fi_route import FICommutator, FINested, FIOrder, FIRepresentation, FIResult, count_brackets, fi_brackets, fi_route
from .fundamental_identity import FI_LABELS, commutator_terms, double_commutator_terms, representations
from .generic_separable import Contraction, ContractionSum, SeparableShadow, separable_shadow
from .jets import JetAlgebra
from .liouville_terms import LiouvilleSum, LiouvilleTerm

__all__ = [
    "Contraction",
    "ContractionSum",
    "DensityBrackets",
    "FI_LABELS",
    "DirectResult",
    "Existence",
    "FICommutator",
    "FINested",
    "FIOrder",
    "FIRepresentation",
    "FIResult",
    "JetAlgebra",
    "LiouvilleSum",
    "LiouvilleTerm",
    "OrderSolution",
    "SeparableShadow",
    "ShadowFamily",
    "commutator_terms",
    "count_brackets",
    "decide",
    "density_brackets",
    "density_shadow",
    "direct_route",
    "double_commutator_terms",
    "fi_brackets",
    "fi_route",
    "representations",
    "separable_shadow",
    "shadow_hamiltonians",
]
