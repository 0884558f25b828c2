"""Choosing and designing the integrator: error constants, order conditions, optimal compositions, comparisons.

* :func:`error_constant`, :func:`error_analysis`, :func:`composition_order` -- the local error
  measure LEM and the order of a composition, exactly (:mod:`.conditions`, :mod:`.words`);
* :func:`template`, :func:`order_conditions` -- polynomial order conditions of templates;
* :func:`optimize_composition` -- the template solution with the smallest error constant (:mod:`.optimize`);
* :func:`leading_error` -- the system's own leading error term and its size (:mod:`.system_error`);
* :func:`compare` -- work-precision comparison on a system (:mod:`.compare`); :func:`runge_kutta_error_constant`
  -- the principal error norm of a tableau or partitioned pair, exactly;
* :mod:`.catalog` -- literature methods (Suzuki, Kahan-Li, Yoshida 6, Blanes-Moan, McLachlan, SRKN, PEFRL,
  SABA/SBAB) by name;
* :mod:`.structure` -- order and error constants on the RKN quotient (``structure="rkn"``) and the generalised
  order of near-integrable splittings ``A + eps B``;
* :mod:`.generalized` -- force-gradient factors and processed kernels (effective order);
* :mod:`.gradient_system` -- force-gradient compositions on a canonical system: X_eff (two routes), shadow
  Hamiltonians.
"""

from .catalog import CatalogComposition, methods
from .compare import Comparison, compare, cost, runge_kutta_error_constant
from .conditions import (
    ErrorConstant,
    OrderConditions,
    Template,
    composition_order,
    error_analysis,
    error_constant,
    order_conditions,
    template,
)
from .gradient_system import GradientField, GradientShadow, gradient_effective_field, gradient_shadow
from .optimize import DesignedComposition, NoSolutionError, optimize_composition
from .system_error import LeadingError, field_size, leading_error

__all__ = [
    "CatalogComposition",
    "Comparison",
    "DesignedComposition",
    "ErrorConstant",
    "GradientField",
    "GradientShadow",
    "LeadingError",
    "NoSolutionError",
    "OrderConditions",
    "Template",
    "compare",
    "composition_order",
    "cost",
    "error_analysis",
    "error_constant",
    "field_size",
    "gradient_effective_field",
    "gradient_shadow",
    "leading_error",
    "methods",
    "optimize_composition",
    "order_conditions",
    "runge_kutta_error_constant",
    "template",
]
