"""BCH engine: formal series in a free Lie algebra and concrete effective fields."""

from .backward import EffectiveField, check_order, effective_field
from .concrete import clear_cache, effective_field_bch
from .evaluation import BracketEvaluator
from .expansion import expand_terms
from .formal import FormalBCH, estimate_size, formal_bch
from .lyndon import (
    is_bracket,
    lie_to_associative,
    lyndon_words,
    standard_bracketing,
    terms_to_latex,
    tree_degree,
    tree_to_associative,
    tree_to_latex,
    witt_dimension,
)

__all__ = [
    "BracketEvaluator",
    "EffectiveField",
    "FormalBCH",
    "check_order",
    "clear_cache",
    "effective_field",
    "effective_field_bch",
    "estimate_size",
    "expand_terms",
    "formal_bch",
    "is_bracket",
    "lie_to_associative",
    "lyndon_words",
    "standard_bracketing",
    "terms_to_latex",
    "tree_degree",
    "tree_to_associative",
    "tree_to_latex",
    "witt_dimension",
]
