"""Exact results: invariants of the discrete map, the factor F(x), exact shadow Hamiltonians, exact solutions.

* :mod:`.factor` -- ``F(x)`` of Eq. (factor1) and its series (Eq. factor2);
* :mod:`.invariants` -- exact polynomial invariants ``H_c, G_c`` of a composed map (Table (table));
* :mod:`.exact_shadow` -- ``H_S^e = F^alpha H_c``, ``G_S^e = F^(1-alpha) G_c`` (Eqs. Xeff2, ESH12321, ESG12321);
* :mod:`.linear_core` -- the harmonic core ``y' = A y`` of oscillator-like fields;
* :mod:`.solutions` -- modified Nambu equations and their solutions ``x^o, x^c, x^s`` (Eqs. OHsol-SHsol).
"""

from .exact_shadow import ExactShadow, exact_shadow_hamiltonians
from .factor import F, F_series
from .invariants import ConservedQuantities, conserved_quantities, is_invariant
from .linear_core import LinearCore, linear_core
from .solutions import ModifiedSolution, modified_equations, modified_solution

__all__ = [
    "ConservedQuantities",
    "ExactShadow",
    "F",
    "F_series",
    "LinearCore",
    "ModifiedSolution",
    "conserved_quantities",
    "exact_shadow_hamiltonians",
    "is_invariant",
    "linear_core",
    "modified_equations",
    "modified_solution",
]
