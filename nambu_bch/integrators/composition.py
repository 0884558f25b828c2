"""Compositions of sub-flows as pure data: a word over the pieces plus exact coefficients.

Operator order (the one convention of the package)
--------------------------------------------------
A composition with pieces ``(k_1, ..., k_s)`` and coefficients
``(c_1, ..., c_s)`` is the operator product (Lie series, acting on functions)

    Phi_h = exp(c_1 h X_{k_1}) exp(c_2 h X_{k_2}) ... exp(c_s h X_{k_s}),

exactly as the paper writes Phi^{12321} (Eq. 12321, Eq. eL2).  Because
``exp(t X) f = f o phi_t`` (``phi_t`` the flow of ``X``), the operator product
``exp(sX) exp(tY)`` sends ``f`` to ``f o psi_t o phi_s``: the sub-flows act on a
*state* in the order of the word, **left to right** -- ``X_{k_1}`` first.  So
the word ``"12"`` (Lie-Trotter) moves the state by piece 1 and then by piece 2,
and its effective field is ``BCH(hX_1, hX_2) = h(X_1 + X_2) + h^2/2 [X_1, X_2] + ...``
with ``[X, Y] = XY - YX`` as operators.  ``tests/test_integrators.py`` checks
this on that word.

Words
-----
* a palindromic digit word of odd length (``"12321"``, ``"121"``): the
  symmetric second-order scheme of the paper, half steps except the middle
  letter (Eqs. PV1, 12321);
* any other digit word (``"123"``, ``"12"``): a plain product of full steps;
* aliases: ``TVT`` / ``PV`` (position Verlet, ``121``), ``VTV`` / ``VV``
  (velocity Verlet, ``212``), ``lie-trotter`` (``12...n``), ``strang``
  (``12..n..21``), ``yoshida:WORD`` / ``triple-jump:WORD`` and
  ``forest-ruth`` (the fourth-order triple jump of a symmetric word);
* an explicit list of ``(piece, coefficient)`` pairs, ``"1:1/2,2:1,1:1/2"``.

Every piece's coefficients must sum to one (consistency).

References
----------
Horikoshi, Eqs. (PV1), (12321), (ST2); Yoshida, Phys. Lett. A 150 (1990) 262,
Eq. (5.19) (triple jump); Forest & Ruth, Physica D 43 (1990) 105;
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. II.4.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import sympy
from sympy.polys.domains import QQ

from ..errors import InconsistentCoefficientsError, InvalidCompositionError, UnknownPieceError

#: Names resolved by :mod:`nambu_bch.design.catalog` (literature methods, ``name`` or ``name:WORD``).
_CATALOG = ("suzuki", "kahan-li", "yoshida6", "blanes-moan")
_ALIASES = {"tvt": "121", "pv": "121", "position-verlet": "121", "vtv": "212", "vv": "212", "velocity-verlet": "212"}


@dataclass(frozen=True)
class Composition:
    """``Phi_h = prod_j exp(c_j h X_{k_j})`` in operator order (sub-flows act left to right).

    Attributes
    ----------
    pieces : tuple of int          -- 1-based piece numbers ``k_j``
    coefficients : tuple of sympy numbers -- exact ``c_j``
    name : str                      -- the word or spec it was made from
    order : int                     -- classical order of the scheme
    citation : str
    """

    pieces: tuple
    coefficients: tuple
    name: str = ""
    order: int = 1
    citation: str = ""

    def __post_init__(self):
        if not self.pieces:
            raise InvalidCompositionError("a composition needs at least one factor, got none")
        if len(self.pieces) != len(self.coefficients):
            raise InvalidCompositionError(
                f"{len(self.pieces)} pieces but {len(self.coefficients)} coefficients in composition {self.name!r}"
            )
        for k in self.pieces:
            if not isinstance(k, int) or k < 1:
                raise UnknownPieceError(f"piece numbers are positive integers, got {k!r} in composition {self.name!r}")
        coeffs = tuple(_exact(c, self.name) for c in self.coefficients)
        object.__setattr__(self, "coefficients", coeffs)
        sums = {k: sympy.nsimplify(sum(c for p, c in zip(self.pieces, coeffs) if p == k)) for k in set(self.pieces)}
        bad = {k: s for k, s in sums.items() if sympy.simplify(s - 1) != 0}
        if bad:
            detail = ", ".join(f"piece {k}: {s}" for k, s in sorted(bad.items()))
            raise InconsistentCoefficientsError(
                f"the coefficients of composition {self.name!r} must sum to 1 for every piece; got {detail}"
            )

    @property
    def symmetric(self) -> bool:
        """Palindromic pieces and coefficients: ``Phi_{-h} o Phi_h = id``."""
        return self.pieces == self.pieces[::-1] and all(
            sympy.simplify(a - b) == 0 for a, b in zip(self.coefficients, self.coefficients[::-1])
        )

    @property
    def n_pieces(self) -> int:
        """The largest piece number used (the splitting must have at least this many)."""
        return max(self.pieces)

    @property
    def extension(self) -> tuple:
        """Algebraic numbers (e.g. ``2**(1/3)``) the coefficients need beyond QQ."""
        atoms = set()
        for c in self.coefficients:
            if not c.is_Rational:
                atoms |= {sympy.root(a.base, a.exp.q) for a in c.atoms(sympy.Pow) if a.exp.is_Rational and not a.exp.is_Integer}
        return tuple(sorted(atoms, key=str))

    def remainder_power(self, order: int) -> int:
        """The first power of ``h`` after ``h**order`` that ``X_eff`` can contain.

        ``order + 1`` in general; symmetric schemes have only even powers in ``X_eff``
        (Hairer, Lubich, Wanner, Thm. IX.3.2), so their remainder after an even order is
        ``O(h**(order + 2))``.

        >>> composition("12321").remainder_power(2), composition("123").remainder_power(2)
        (4, 3)
        """
        return order + 2 if self.symmetric and order % 2 == 0 else order + 1

    def factors(self):
        """``[(piece, coefficient), ...]`` in operator order."""
        return list(zip(self.pieces, self.coefficients))

    def check(self, splitting) -> "Composition":
        """Raise :class:`UnknownPieceError` if a piece is not in ``splitting``."""
        n = len(splitting)
        missing = sorted({k for k in self.pieces if k > n})
        if missing:
            raise UnknownPieceError(
                f"composition {self.name!r} uses piece(s) {missing}, but the splitting of "
                f"{getattr(splitting.system, 'name', 'the system')} has pieces 1..{n}"
            )
        return self

    def adjoint(self) -> "Composition":
        """``Phi*_h = Phi_{-h}^{-1}``: the reversed product."""
        return Composition(self.pieces[::-1], self.coefficients[::-1], f"adjoint({self.name})", self.order, self.citation)

    def to_latex(self) -> str:
        def exponent(c):
            if c == 1:
                return "h"
            text = sympy.latex(c)
            return rf"\left({text}\right)h" if c.is_Add else rf"{text}\,h"

        return r"\Phi_h = " + " ".join(rf"e^{{{exponent(c)} X_{{{k}}}}}" for k, c in self.factors())

    def __str__(self):
        return self.name or ",".join(f"{k}:{c}" for k, c in self.factors())


def _exact(c, name):
    if isinstance(c, float):
        raise InvalidCompositionError(
            f"coefficient {c!r} of composition {name!r} is a float; give exact numbers such as '1/2' or sympy.Rational(1, 2)"
        )
    if isinstance(c, Fraction):
        c = sympy.Rational(c.numerator, c.denominator)
    if isinstance(c, str):
        from ..parsing import parse_expression

        c = parse_expression(c, [], what=f"coefficient of composition {name!r}")
    c = sympy.sympify(c)
    if not c.is_number or c.has(sympy.Float) or not c.is_real:
        raise InvalidCompositionError(f"coefficient {c} of composition {name!r} must be an exact real number")
    return c


def _strang(word: str) -> Composition:
    mid = len(word) // 2
    coeffs = [sympy.Rational(1, 2)] * len(word)
    coeffs[mid] = sympy.Integer(1)
    return Composition(tuple(int(ch) for ch in word), tuple(coeffs), word, 2, "Horikoshi, Eqs. (PV1), (12321), (ST2)")


def _triple_jump(base: Composition) -> Composition:
    """Yoshida's triple jump ``Phi_{g1 h} Phi_{g0 h} Phi_{g1 h}``, order + 2 for symmetric ``base``."""
    if not base.symmetric or base.order % 2:
        raise InvalidCompositionError(f"the triple jump needs a symmetric base scheme of even order, got {base.name!r}")
    p = base.order + 1
    root = sympy.Integer(2) ** sympy.Rational(1, p)
    g1 = 1 / (2 - root)
    g0 = -root / (2 - root)
    field = QQ.algebraic_field(root)

    def canonical(c):  # a + b 2^(1/p) + ... : one normal form per number
        return field.to_sympy(field.from_sympy(sympy.expand(c)))

    pieces, coeffs = [], []
    for g in (g1, g0, g1):
        for k, c in base.factors():
            if pieces and pieces[-1] == k:  # merge adjacent sub-flows of one piece
                coeffs[-1] = canonical(coeffs[-1] + g * c)
            else:
                pieces.append(k)
                coeffs.append(canonical(g * c))
    return Composition(
        tuple(pieces), tuple(coeffs), f"triple-jump:{base.name}", base.order + 2,
        "Yoshida, Phys. Lett. A 150 (1990) 262; Forest & Ruth, Physica D 43 (1990) 105",
    )


def composition(spec, n_pieces: int | None = None) -> Composition:
    """A :class:`Composition` from a word, alias, ``"k:c,..."`` list or ``[(k, c), ...]``.

    Parameters
    ----------
    spec : str, Composition, or sequence of (piece, coefficient)
    n_pieces : int, optional
        Number of pieces of the splitting (needed by ``lie-trotter`` and ``strang``).

    Examples
    --------
    >>> composition("12321").coefficients
    (1/2, 1/2, 1, 1/2, 1/2)
    >>> composition("TVT").pieces
    (1, 2, 1)
    >>> composition("123").order, composition("123").symmetric
    (1, False)
    """
    if isinstance(spec, str):
        # compositions are immutable and radical coefficients are slow to normalise: build each once
        return _composition_from_text(spec, n_pieces)
    return _build(spec, n_pieces)


@lru_cache(maxsize=512)
def _composition_from_text(spec: str, n_pieces):
    return _build(spec, n_pieces)


def _build(spec, n_pieces):
    if isinstance(spec, Composition):
        return spec
    if isinstance(spec, (list, tuple)):
        try:
            pieces = tuple(int(k) for k, _ in spec)
            coeffs = tuple(c for _, c in spec)
        except (TypeError, ValueError):
            raise InvalidCompositionError(f"an explicit composition is a list of (piece, coefficient) pairs, got {spec!r}") from None
        return _with_order(Composition(pieces, coeffs, ",".join(f"{k}:{c}" for k, c in spec)))
    if not isinstance(spec, str) or not spec.strip():
        raise InvalidCompositionError(f"a composition is a word such as '12321', an alias or 'k:c,...' list, got {spec!r}")
    text = spec.strip()
    low = text.lower()
    if low in _ALIASES:
        comp = _strang(_ALIASES[low])
        return Composition(comp.pieces, comp.coefficients, text, 2, comp.citation)
    if low in ("lie-trotter", "strang"):
        if not n_pieces:
            raise InvalidCompositionError(f"{text!r} needs the number of pieces of the splitting")
        word = "".join(str(k) for k in range(1, n_pieces + 1))
        return composition(word if low == "lie-trotter" else word + word[-2::-1])
    if low == "forest-ruth":
        return _triple_jump(composition("121"))
    if low.startswith(("yoshida:", "triple-jump:")):
        return _triple_jump(composition(text.split(":", 1)[1], n_pieces))
    if low.partition(":")[0] in _CATALOG:
        from ..design.catalog import lookup  # literature methods with citations (issue 15)

        return lookup(text, n_pieces)
    if ":" in text:
        pairs = []
        for item in text.split(","):
            k, sep, c = item.partition(":")
            if not sep or not k.strip().isdigit():
                raise InvalidCompositionError(f"composition item {item!r} of {text!r} is not of the form 'piece:coefficient'")
            pairs.append((int(k), c.strip()))
        return composition(pairs)
    if not text.isdigit() or "0" in text:
        raise InvalidCompositionError(
            f"unknown composition {text!r}; use a word of piece digits 1-9 such as '12321', "
            f"an alias ({', '.join(sorted(_ALIASES))}, lie-trotter, strang, forest-ruth, yoshida:WORD, "
            "suzuki[:WORD], kahan-li[:WORD], yoshida6[:WORD], blanes-moan) "
            "or an explicit list 'piece:coefficient,...'"
        )
    if len(text) % 2 == 1 and text == text[::-1] and len(text) > 1:
        return _strang(text)
    return Composition(tuple(int(ch) for ch in text), (sympy.Integer(1),) * len(text), text, 1, "plain product (Lie-Trotter)")


def _with_order(comp: Composition) -> Composition:
    order = 2 if comp.symmetric else 1
    return Composition(comp.pieces, comp.coefficients, comp.name, order, comp.citation or "explicit coefficients")


#: The paper's six symmetric second-order words for the N = 3 oscillator (Sect. 5.1).
PAPER_WORDS = ("12321", "13231", "31213", "21312", "23132", "32123")
