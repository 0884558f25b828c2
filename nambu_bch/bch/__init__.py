"""BCH engine: formal series in a free Lie algebra and concrete effective fields."""

from .backward import EffectiveField, check_order, effective_field

__all__ = ["EffectiveField", "check_order", "effective_field"]
