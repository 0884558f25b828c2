"""The package's own symbols: the step ``h`` and the family parameter ``alpha``.

Created once here and imported everywhere, so that every module (and every result a user compares)
speaks of the same ``h`` and ``alpha``.  Built-in coordinates and parameters belong to their systems
(:mod:`nambu_bch.systems.catalog`).

>>> from nambu_bch.symbols import STEP, ALPHA
>>> STEP, ALPHA
(h, alpha)
"""

import sympy

STEP = sympy.Symbol("h")
ALPHA = sympy.Symbol("alpha")
