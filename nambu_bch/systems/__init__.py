"""Systems, separable decomposition, splittings and the catalog of models."""

from .catalog import model, model_names
from .separable import is_separable, separate
from .splitting import Piece, Splitting, full_split, single_split
from .system import System

__all__ = ["Piece", "Splitting", "System", "full_split", "is_separable", "model", "model_names", "separate", "single_split"]
