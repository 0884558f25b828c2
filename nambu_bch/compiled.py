"""Whether compiled (numba) code may be used: one switch for the numeric kernels and the BCH engine.

numba is optional at run time: ``NAMBU_BCH_DISABLE_NUMBA=1`` (or numba missing) sends the numeric
kernels to their numpy fallback and the formal BCH series to the pure-Python dense engine; both
paths are tested.
"""

from __future__ import annotations

import importlib.util
import os
import sys


def numba_available() -> bool:
    """numba installed and not disabled by ``NAMBU_BCH_DISABLE_NUMBA=1`` (read at every call; numba is
    located, not imported: importing it costs ~0.3 s, paid only when compiled code first runs)."""
    if os.environ.get("NAMBU_BCH_DISABLE_NUMBA", "").strip().lower() in ("1", "true", "yes", "on"):
        return False
    if "numba" in sys.modules:
        return True
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False
