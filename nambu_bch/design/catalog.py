"""Composition methods from the literature, with citations, resolved by name like the built-in aliases.

Names (``WORD`` a symmetric base word such as ``121`` or ``12321``; without ``:WORD``
the base is the Strang word ``12..n..21`` of the splitting, so ``n_pieces`` is needed):

==================  =====  ======  ============================================================
name                order  stages  coefficients
==================  =====  ======  ============================================================
``suzuki:WORD``     4      5       exact, ``g = 1/(4 - 4^(1/3))``: (g, g, 1 - 4g, g, g)
``kahan-li:WORD``   6      9       26-digit decimals (published), error bound stated
``yoshida6:WORD``   6      7       15-digit decimals (Yoshida's solution A), error bound stated
``blanes-moan``     4      6       AB method S6 (pieces 1 = A, 2 = B), 15-digit decimals
==================  =====  ======  ============================================================

Exactness.  Decimal coefficients are taken as the exact rationals they denote; the last
(middle) coefficient of each piece is the complement to one, so the scheme is exactly
consistent.  Such a composition is a :class:`CatalogComposition` with ``error_bound``: the
largest absolute Lyndon defect of length ``<= order`` of those rationals, computed exactly
at construction.  :func:`~nambu_bch.design.error_analysis` treats defects below that bound
as zero when it determines the order; symbolic routes (``effective_field``, shadow
Hamiltonians) analyse the rationals as they are, so their ``X_eff`` carries terms of the
size of ``error_bound`` below ``h^order``.

References
----------
Suzuki, Phys. Lett. A 146 (1990) 319 (5-jump, "fractal" decomposition; built in integrators.composition);
Kahan & Li, Math. Comp. 66 (1997) 1089, and Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, Sect. V.3.2, Eq. (3.11) (p6 s9 coefficients); Yoshida, Phys. Lett. A 150
(1990) 262, Table 1, solution A; Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313,
Table 2 (S6).  Published error constants of Y 8-6 and KL 10-6 (16.17 / 90.86, 1.84 / 10.70):
SplittingOrderConditions.jl, ``examples/CheckMethods.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy

from ..errors import InvalidCompositionError
from ..integrators.composition import Composition
from ..integrators.composition import composition as make_composition

_SUZUKI = "Suzuki, Phys. Lett. A 146 (1990) 319"  # built by integrators.composition (the five-jump)
_KAHAN_LI = "Kahan & Li, Math. Comp. 66 (1997) 1089; Hairer, Lubich, Wanner, GNI, Sect. V.3.2, Eq. (3.11)"
_YOSHIDA6 = "Yoshida, Phys. Lett. A 150 (1990) 262, Table 1, solution A"
_BLANES_MOAN = "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 2 (S6)"

#: gamma_1 .. gamma_5 of the Kahan-Li p6 s9 composition (gamma_5 the middle one), as published.
KAHAN_LI = ("0.39216144400731413927925056", "0.33259913678935943859974864", "-0.70624617255763935980996482",
            "0.08221359629355080023149045")
#: w_3, w_2, w_1 of Yoshida's sixth-order solution A (outermost first); w_0 = 1 - 2(w_1 + w_2 + w_3).
YOSHIDA6 = ("0.784513610477560", "0.235573213359357", "-1.17767998417887")
#: a_1, a_2, a_3 and b_1, b_2 of Blanes-Moan S6; a_4 = 1 - 2(a_1 + a_2 + a_3), b_3 = 1/2 - b_1 - b_2.
BLANES_MOAN = (("0.0792036964311957", "0.353172906049774", "-0.0420650803577195"),
               ("0.209515106613362", "-0.143851773179818"))


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


def _with_bound(comp: Composition, parts: int) -> CatalogComposition:
    from .conditions import _Exact

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


@lru_cache(maxsize=64)
def _build(kind: str, word, n_pieces):
    if kind == "blanes-moan":
        (a1, a2, a3), (b1, b2) = ([sympy.Rational(x) for x in row] for row in BLANES_MOAN)
        a = [a1, a2, a3, 1 - 2 * (a1 + a2 + a3), a3, a2, a1]
        b = [b1, b2, sympy.Rational(1, 2) - b1 - b2]
        b = b + b[::-1]
        pieces, coeffs = [], []
        for i in range(7):
            pieces.append(1)
            coeffs.append(a[i])
            if i < 6:
                pieces.append(2)
                coeffs.append(b[i])
        return _with_bound(Composition(tuple(pieces), tuple(coeffs), "blanes-moan", 4, _BLANES_MOAN), 2)
    base = _base(word, n_pieces, kind)
    label = f"{kind}:{base.name}"
    if kind == "kahan-li":
        return _with_bound(_stages(base, _palindrome(KAHAN_LI), label, 6, _KAHAN_LI), base.n_pieces)
    if kind == "yoshida6":
        return _with_bound(_stages(base, _palindrome(YOSHIDA6), label, 6, _YOSHIDA6), base.n_pieces)
    raise AssertionError(kind)


NAMES = ("kahan-li", "yoshida6", "blanes-moan")  # also listed in integrators/composition.py (_CATALOG); suzuki lives there


def lookup(text: str, n_pieces=None):
    """The catalog composition named ``text`` (``name`` or ``name:WORD``), or ``None`` if it is not a catalog name."""
    low = text.strip().lower()
    kind, sep, word = low.partition(":")
    if kind not in NAMES:
        return None
    if kind == "blanes-moan":
        if sep:
            raise InvalidCompositionError("'blanes-moan' is a method for two pieces (1 = A, 2 = B) and takes no base word")
        return _build(kind, None, None)
    return _build(kind, word or None, None if sep else n_pieces)


def methods() -> dict:
    """``{name: (order, stages, citation)}`` of the catalog."""
    return {"suzuki": (4, 5, _SUZUKI), "kahan-li": (6, 9, _KAHAN_LI), "yoshida6": (6, 7, _YOSHIDA6),
            "blanes-moan": (4, 6, _BLANES_MOAN)}
