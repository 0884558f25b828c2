"""Systems, separable decomposition, splittings and the catalog of models."""

from .catalog import model, model_names
from .separable import is_separable, separate
from .splitting import Piece, Splitting, canonical_split, full_split, single_split, triplet_split
from .system import BRACKETS, System, infer_bracket

__all__ = ["BRACKETS", "Piece", "Splitting", "System", "canonical_split", "full_split", "infer_bracket", "is_separable", "model", "model_names", "separate",
           "single_split", "triplet_split"]
