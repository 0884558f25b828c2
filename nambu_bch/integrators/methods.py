"""Compositions from the published decimal tables of :mod:`.tables` (``kahan-li:WORD``, ``yoshida6:WORD``, ``blanes-moan``,
and the methods of Auzinger, Hofstaetter & Koch's tables that SplittingOrderConditions.jl's CheckMethods rates, such
as ``emb-43-ak-s``, the complex ``milne-22-c-i`` and the three-part ``ak-114``).

Exactness.  Decimal coefficients are taken as the exact rationals they denote; the last (middle) coefficient of each
piece is the complement to one, so the scheme is exactly consistent.  Such a composition is a
:class:`CatalogComposition` with ``error_bound``: the largest absolute Lyndon defect of length ``<= order`` of those
rationals, computed exactly at construction.  :func:`~nambu_bch.design.error_analysis` treats defects below that bound
as zero when it determines the order; symbolic routes (``effective_field``, shadow Hamiltonians) analyse the rationals
as they are, so their ``X_eff`` carries terms of the size of ``error_bound`` below ``h^order``.

The builders live in :mod:`.composition`, beside the parser that resolves these names; this module is where the
names are documented and imported from.
"""

from .composition import NAMES, CatalogComposition, lookup, methods, with_error_bound

__all__ = ["NAMES", "CatalogComposition", "lookup", "methods", "with_error_bound"]
