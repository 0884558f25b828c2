"""BCH engine: formal series in a free Lie algebra and concrete effective fields."""

# The names are imported on first use (PEP 562): ``from nambu_bch.bch import formal_bch`` loads the formal
# series alone, not the effective-field machinery of .backward and .concrete (a fresh process saves their imports).
_LAZY = {
    ".backward": ("EffectiveField", "check_order", "effective_field"),
    ".concrete": ("clear_cache", "effective_field_bch"),
    ".evaluation": ("BracketEvaluator",),
    ".expansion": ("expand_terms",),
    ".formal": ("FormalBCH", "estimate_size", "formal_bch"),
    ".lyndon": ("is_bracket", "lie_to_associative", "lyndon_words", "standard_bracketing", "terms_to_latex",
                "tree_degree", "tree_to_associative", "tree_to_latex", "witt_dimension"),
}
_WHERE = {name: module for module, names in _LAZY.items() for name in names}
_SUBMODULES = ("backward", "concrete", "evaluation", "expansion", "formal", "light", "lyndon", "modular", "report",
               "table")


def __getattr__(name):
    from importlib import import_module

    module = _WHERE.get(name)
    if module is not None:
        value = getattr(import_module(module, __name__), name)
    elif name in _SUBMODULES:
        value = import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module 'nambu_bch.bch' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


__all__ = sorted(_WHERE)
