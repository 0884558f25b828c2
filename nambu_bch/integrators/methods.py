"""Compositions from the published decimal tables of :mod:`.tables` (``kahan-li:WORD``, ``yoshida6:WORD``, ``blanes-moan``).

Exactness.  Decimal coefficients are taken as the exact rationals they denote; the last (middle) coefficient of each
piece is the complement to one, so the scheme is exactly consistent.  Such a composition is a
:class:`CatalogComposition` with ``error_bound``: the largest absolute Lyndon defect of length ``<= order`` of those
rationals, computed exactly at construction.  :func:`~nambu_bch.design.error_analysis` treats defects below that bound
as zero when it determines the order; symbolic routes (``effective_field``, shadow Hamiltonians) analyse the rationals
as they are, so their ``X_eff`` carries terms of the size of ``error_bound`` below ``h^order``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy

from ..errors import InvalidCompositionError
from .composition import Composition
from .composition import composition as make_composition
from .tables import DECIMAL, SUZUKI, TABLES

#: The names of the decimal tables, resolved by :func:`lookup`.
NAMES = DECIMAL


@dataclass(frozen=True)
class CatalogComposition(Composition):
    """A literature composition with decimal coefficients: ``error_bound`` is its largest order-condition defect."""

    error_bound: float = 0.0


def _palindrome(outer):
    """``(g_1, ..., g_k, g_mid, g_k, ..., g_1)`` with ``g_mid = 1 - 2 sum g_i``, exact rationals."""
    g = [sympy.Rational(x) for x in outer]
    return g + [1 - 2 * sum(g)] + g[::-1]


def _stages(base: Composition, gammas, name, order, citation, cls=Composition, **extra):
    factors = []
    for g in gammas:
        for k, c in base.factors():
            if factors and factors[-1][0] == k:
                factors[-1] = (k, sympy.expand(factors[-1][1] + g * c))
            else:
                factors.append((k, sympy.expand(g * c)))
    return cls(tuple(k for k, _ in factors), tuple(c for _, c in factors), name, order, citation, **extra)


def with_error_bound(comp: Composition, parts: int) -> CatalogComposition:
    """``comp`` as a :class:`CatalogComposition` whose ``error_bound`` is its largest absolute Lyndon defect of
    length ``<= comp.order`` for ``parts`` pieces, computed exactly."""
    from ..design.conditions import _Exact  # the Lyndon defects live with the order conditions

    field = _Exact(comp)
    bound = max(abs(float(field.K.to_sympy(v))) for q in range(1, comp.order + 1)
                for v in field.defects(parts, q).values())
    return CatalogComposition(comp.pieces, comp.coefficients, comp.name,
                              comp.order, comp.citation + f"; decimals as exact rationals, order conditions to {bound:.1e}",
                              bound)


def _base(word: str | None, n_pieces, name):
    if word is None:
        if not n_pieces:
            raise InvalidCompositionError(f"{name!r} needs the number of pieces of the splitting (or use '{name}:WORD')")
        word = "".join(str(k) for k in range(1, n_pieces + 1))
        word = word + word[-2::-1]
    base = make_composition(word)
    if not base.symmetric or base.order != 2:
        raise InvalidCompositionError(f"{name!r} composes a symmetric second-order base word such as '121' or '12321', got {word!r}")
    return base


def _ab(table) -> Composition:
    """The palindromic two-part method ``A(a_1) B(b_1) ... B(b_1) A(a_1)`` of an ``"ab"`` table."""
    a_outer, b_outer = ([sympy.Rational(x) for x in row] for row in table.values)
    a = a_outer + [1 - 2 * sum(a_outer)] + a_outer[::-1]
    b = b_outer + [sympy.Rational(1, 2) - sum(b_outer)]
    b = b + b[::-1]
    pieces, coeffs = [], []
    for i, ai in enumerate(a):
        pieces.append(1)
        coeffs.append(ai)
        if i < len(b):
            pieces.append(2)
            coeffs.append(b[i])
    return Composition(tuple(pieces), tuple(coeffs), table.name, table.order, table.reference)


@lru_cache(maxsize=64)
def _build(kind: str, word, n_pieces):
    table = TABLES[kind]
    if table.kind == "ab":
        return with_error_bound(_ab(table), 2)
    base = _base(word, n_pieces, kind)
    comp = _stages(base, _palindrome(table.values), f"{kind}:{base.name}", table.order, table.reference)
    return with_error_bound(comp, base.n_pieces)


def lookup(text: str, n_pieces=None):
    """The catalog composition named ``text`` (``name`` or ``name:WORD``), or ``None`` if it is not a catalog name."""
    low = text.strip().lower()
    kind, sep, word = low.partition(":")
    if kind not in NAMES:
        return None
    if not TABLES[kind].takes_word:
        if sep:
            raise InvalidCompositionError(f"{kind!r} is a method for two pieces (1 = A, 2 = B) and takes no base word")
        return _build(kind, None, None)
    return _build(kind, word or None, None if sep else n_pieces)


def methods() -> dict:
    """``{name: (order, stages, citation)}`` of the literature methods (Suzuki's five-jump and the decimal tables)."""
    return {t.name: (t.order, t.stages, t.reference) for t in (SUZUKI, *(TABLES[name] for name in NAMES))}
