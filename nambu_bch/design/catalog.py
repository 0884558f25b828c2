"""Composition methods from the literature, with citations, resolved by name like the built-in aliases.

The coefficient tables live in :mod:`nambu_bch.integrators.tables` (frozen, each with its reference) and are built by
:mod:`nambu_bch.integrators.methods`; this module only reads them for design.

Names (``WORD`` a symmetric base word such as ``121`` or ``12321``; without ``:WORD``
the base is the Strang word ``12..n..21`` of the splitting, so ``n_pieces`` is needed):

==================  =====  ======  ============================================================
name                order  stages  coefficients
==================  =====  ======  ============================================================
``suzuki:WORD``     4      5       exact, ``g = 1/(4 - 4^(1/3))``: (g, g, 1 - 4g, g, g)
``kahan-li:WORD``   6      9       26-digit decimals (published), error bound stated
``yoshida6:WORD``   6      7       15-digit decimals (Yoshida's solution A), error bound stated
``blanes-moan``     4      6       AB method S6 (pieces 1 = A, 2 = B), 15-digit decimals
``emb-43-ak-s``     4      5       Auzinger-Koch symmetric AB method, 18-digit decimals
``milne-22-c-i``    2      2       complex AB method, exact Gaussian rationals
``ak-114``          4      11      symmetric ABC method (pieces 1, 2, 3), 18-digit decimals
==================  =====  ======  ============================================================

The last three stand for the 29 methods of SplittingOrderConditions.jl's CheckMethods tables (real, complex, two
and three parts) taken from Auzinger, Hofstaetter & Koch's tables; ``docs/integrators.md`` lists them all with the
published orders, stages and error constants that ``tests/test_catalog_published.py`` reproduces.

Exactness: decimals are read as exact rationals with a stated ``error_bound``
(:mod:`nambu_bch.integrators.methods`).

References
----------
Suzuki, Phys. Lett. A 146 (1990) 319 (5-jump, "fractal" decomposition; built in integrators.composition);
Kahan & Li, Math. Comp. 66 (1997) 1089, and Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, Sect. V.3.2, Eq. (3.11) (p6 s9 coefficients); Yoshida, Phys. Lett. A 150
(1990) 262, Table 1, solution A; Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313,
Table 2 (S6); Auzinger, Hofstaetter & Koch, "Coefficients of various splitting methods",
www.asc.tuwien.ac.at/~winfried/splitting, and Auzinger, Hofstaetter, Ketcheson & Koch, BIT Numer. Math. 57 (2017) 55
(the CheckMethods methods).  Published error constants (LEM), e.g. Y 8-6 and KL 10-6 (16.17 / 90.86, 1.84 / 10.70):
SplittingOrderConditions.jl, ``examples/CheckMethods.ipynb``.
"""

from __future__ import annotations

from ..integrators.methods import NAMES, CatalogComposition, lookup, methods, with_error_bound

__all__ = ["NAMES", "CatalogComposition", "lookup", "methods", "with_error_bound"]
