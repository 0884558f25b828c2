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
    """A literature composition with decimal coefficients: ``error_bound`` is its largest order-condition defect;
    ``structure`` the problem class its published order needs (``""`` any splitting, ``"rkn"``)."""

    error_bound: float = 0.0
    structure: str = ""


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


def with_error_bound(comp: Composition, parts: int, structure: str = "") -> CatalogComposition:
    """``comp`` as a :class:`CatalogComposition` whose ``error_bound`` is its largest absolute Lyndon defect of
    length ``<= comp.order`` for ``parts`` pieces, computed exactly; with ``structure="rkn"`` the largest residual
    modulo the RKN ideal (:func:`nambu_bch.design.structure.structured_bound`), where the published order holds."""
    from ..design.conditions import _Exact  # the Lyndon defects live with the order conditions

    field = _Exact(comp)
    # Below degree 4 the RKN quotient is the free Lie algebra, and a symmetric method has E_4 = 0 exactly: there the
    # defects of the general order conditions measure only the rounding of the decimals, and count in the bound.
    general = comp.order if structure != "rkn" else min(comp.order, 4 if comp.symmetric else 3)
    bound = max(abs(float(field.K.to_sympy(v))) for q in range(1, general + 1) for v in field.defects(parts, q).values())
    if structure == "rkn":
        from ..design.structure import structured_bound

        bound = max(bound, structured_bound(comp, comp.order, structure))
    return CatalogComposition(comp.pieces, comp.coefficients, comp.name,
                              comp.order, comp.citation + f"; decimals as exact rationals, order conditions to {bound:.1e}",
                              bound, structure)


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


def _number(text: str, exact: bool):
    """A table entry: a published decimal as the rational it denotes, or an exact formula read by the package's
    whitelist parser (numbers, + - * / ** and sqrt)."""
    if not exact:
        return sympy.Rational(text)
    from ..parsing import parse_expression

    return parse_expression(text, {}, what="table coefficient")


def _ab(table) -> Composition:
    """The palindromic two-part method ``X(x_1) Y(y_1) X(x_2) ... Y(y_1) X(x_1)`` of an ``"ab"`` table, ``X`` the
    piece ``table.first``; the piece with the middle factor gets ``1 - 2 sum``, the other a middle pair ``1/2 - sum``."""
    x_outer, y_outer = ([_number(v, table.exact) for v in row] for row in table.values)
    x_middle = len(x_outer) == len(y_outer) + 1

    def full(outer, middle):
        if middle:
            return outer + [sympy.expand(1 - 2 * sum(outer))] + outer[::-1]
        half = outer + [sympy.expand(sympy.Rational(1, 2) - sum(outer))]
        return half + half[::-1]

    x, y = full(x_outer, x_middle), full(y_outer, not x_middle)
    other = 3 - table.first
    pieces, coeffs = [], []
    for i, xi in enumerate(x):
        pieces.append(table.first)
        coeffs.append(xi)
        if i < len(y):
            pieces.append(other)
            coeffs.append(y[i])
    return Composition(tuple(pieces), tuple(coeffs), table.name, table.order, table.reference)


@lru_cache(maxsize=64)
def _build(kind: str, word, n_pieces):
    table = TABLES[kind]
    if table.kind == "ab":
        if table.exact:
            return _ab(table)
        comp = with_error_bound(_ab(table), 2, table.structure)
        if table.generalized:  # the published accuracy is that of the generalised order, not only the classical one
            from ..design.structure import generalized_bound

            bound = max(comp.error_bound, generalized_bound(comp, table.generalized))
            comp = CatalogComposition(comp.pieces, comp.coefficients, comp.name, comp.order,
                                      comp.citation.replace(f"{comp.error_bound:.1e}", f"{bound:.1e}"), bound, comp.structure)
        return comp
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
