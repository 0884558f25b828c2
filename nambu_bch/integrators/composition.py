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
  (velocity Verlet, ``212``) -- two-piece splittings only; ``lie-trotter``
  (``12...n``), ``strang`` (``12..n..21``); ``forest-ruth`` / ``yoshida``
  (Yoshida's triple jump of the splitting's Strang word), ``yoshida:WORD`` /
  ``triple-jump:WORD`` (triple jump of a symmetric WORD), ``suzuki`` /
  ``suzuki:WORD`` (Suzuki's fractal five-jump) -- all fourth order.  The aliases
  expand over the pieces of the splitting they are used with (``n_pieces``).
* an explicit list of ``(piece, coefficient)`` pairs, ``"1:1/2,2:1,1:1/2"``.

Consistency, checked in one place (:meth:`Composition.check`, reached by every
route through :func:`composition_for`): every piece ``1..n`` of the splitting
occurs, and each piece's coefficients sum to one.  A word that leaves a piece
out (``121`` on a three-piece splitting) is not an integrator of the system's
flow and is refused, naming the missing pieces.

References
----------
Horikoshi, Eqs. (PV1), (12321), (ST2); Yoshida, Phys. Lett. A 150 (1990) 262,
Eq. (5.19) (triple jump); Forest & Ruth, Physica D 43 (1990) 105;
Suzuki, Phys. Lett. A 146 (1990) 319, Eq. (3.14) (five-jump);
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. II.4.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import sympy
from sympy.polys.domains import QQ

from ..algebra.zero import is_zero
from ..checks import check_int, is_int, show
from ..errors import InconsistentCoefficientsError, InvalidCompositionError, UnknownPieceError, did_you_mean
from .tables import DECIMAL, SUZUKI, TABLES, TRIPLE_JUMP

#: Names of the published decimal tables (:mod:`.tables`), built by :func:`lookup` (``name`` or ``name:WORD``).
_CATALOG = DECIMAL
_ALIASES = {"tvt": "121", "pv": "121", "position-verlet": "121", "vtv": "212", "vv": "212", "velocity-verlet": "212"}
_JUMPS = ("forest-ruth", "yoshida", "triple-jump", "suzuki")
#: Most factors a composition may have (bounded work downstream: BCH, kernels).
MAX_FACTORS = 200
#: Most characters of a composition given as text.
MAX_TEXT = 400
#: Most pieces a splitting may have for the digit-word aliases (pieces are the digits 1-9).
MAX_PIECES = 9


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
        for what, value in (("pieces", self.pieces), ("coefficients", self.coefficients)):
            if not isinstance(value, (tuple, list)):
                raise InvalidCompositionError(f"the {what} of a composition are a tuple, got {show(value)}")
        if not self.pieces:
            raise InvalidCompositionError("a composition needs at least one factor, got none")
        if len(self.pieces) != len(self.coefficients):
            raise InvalidCompositionError(
                f"{len(self.pieces)} pieces but {len(self.coefficients)} coefficients in composition {self.name!r}"
            )
        if len(self.pieces) > MAX_FACTORS:
            raise InvalidCompositionError(
                f"composition {_shown(self.name)} has {len(self.pieces)} factors; at most {MAX_FACTORS} are accepted"
            )
        for k in self.pieces:
            if not is_int(k, 1, MAX_FACTORS):
                raise UnknownPieceError(
                    f"piece numbers are integers 1..{MAX_FACTORS}, got {k!r} in composition {_shown(self.name)}"
                )
        coeffs = tuple(_exact(c, self.name) for c in self.coefficients)
        object.__setattr__(self, "coefficients", coeffs)
        bad = sums_not_one(zip(self.pieces, coeffs))
        if bad:
            detail = ", ".join(f"piece {k}: {s}" for k, s in sorted(bad.items()))
            raise InconsistentCoefficientsError(
                f"the coefficients of composition {self.name!r} must sum to 1 for every piece; got {detail}"
            )

    @property
    def symmetric(self) -> bool:
        """Palindromic pieces and coefficients: ``Phi_{-h} o Phi_h = id``."""
        return self.pieces == self.pieces[::-1] and all(
            is_zero(a - b) for a, b in zip(self.coefficients, self.coefficients[::-1])
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
        # complex coefficients a + b*I: the field QQ(i, ...) -- I is no power, so it is added by name
        return tuple(sorted(atoms, key=str)) + ((sympy.I,) if self.is_complex else ())

    @property
    def is_complex(self) -> bool:
        """Some coefficient is not real (``1/4 + I/4``): the exact routes then work over ``QQ(i)`` (:attr:`extension`
        holds ``I``), the numerics in complex128 (:mod:`nambu_bch.numeric.complex_iterate`)."""
        return any(c.has(sympy.I) and not c.is_real for c in self.coefficients)

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
        """``self`` if it is an integrator of ``splitting``'s flow; the one consistency check of the package.

        A composition approximates ``exp(h (X_1 + ... + X_n))`` only if every piece
        ``1..n`` of the splitting occurs and each piece's coefficients sum to one
        (the latter is checked on construction).  Raises
        :class:`UnknownPieceError` for a piece the splitting does not have, and
        :class:`InconsistentCoefficientsError` naming the pieces the word leaves out.

        >>> from nambu_bch import model
        >>> composition("121").check(model("ho3").splitting)
        Traceback (most recent call last):
        ...
        nambu_bch.errors.InconsistentCoefficientsError: composition '121' never applies piece(s) [3] of the splitting of ho3 (pieces 1..3); every piece must occur with total coefficient 1, e.g. the Strang word 12321
        """
        from ..systems.splitting import Splitting

        if not isinstance(splitting, Splitting):
            raise InvalidCompositionError(
                f"a composition is checked against a Splitting (e.g. model('ho3').splitting), got {type(splitting).__name__}"
            )
        n = len(splitting)
        name = getattr(splitting.system, "name", "the system")
        extra = sorted({k for k in self.pieces if k > n})
        if extra:
            raise UnknownPieceError(
                f"composition {_shown(self.name)} uses piece(s) {extra}, but the splitting of {name} has pieces 1..{n}"
            )
        missing = sorted(set(range(1, n + 1)) - set(self.pieces))
        if missing:
            raise InconsistentCoefficientsError(
                f"composition {_shown(self.name)} never applies piece(s) {missing} of the splitting of {name} "
                f"(pieces 1..{n}); every piece must occur with total coefficient 1, e.g. the Strang word {strang_word(n)}"
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


def _shown(text, limit: int = 60) -> str:
    text = str(text)
    return repr(text if len(text) <= limit else text[: limit - 3] + "...")


def strang_word(n: int) -> str:
    """The Strang word ``12..n..21`` of an ``n``-piece splitting (``"1"`` for one piece).

    >>> strang_word(3), strang_word(2), strang_word(1)
    ('12321', '121', '1')
    """
    check_int(n, "the number of pieces of a Strang word", 1, MAX_PIECES)  # pieces are digits
    word = "".join(str(k) for k in range(1, n + 1))
    return word + word[-2::-1]


def three_parts(spec) -> Composition:
    """A two-part composition applied to three parts ``X_1 + X_2 + X_3``: CheckMethods' ABC rule.

    The method's piece 1 stays piece 1 (A), its piece 2 becomes piece 3 (C), and a new middle piece 2 (B) follows
    every factor so that its running time catches up with the factor just applied: after a factor of A (C) the
    coefficients of B applied so far sum to the coefficients of A (C) applied so far.  So
    ``A(a_1) B(b_1) A(a_2) ...`` becomes ``A(a_1) B(a_1) C(b_1) B(b_1 - a_1) A(a_2) B(a_1 + a_2 - b_1) ...``,
    factors with coefficient zero dropped and adjacent factors of one piece merged: Lie-Trotter ``12`` becomes
    ``123``, Strang ``121`` becomes ``12321``, and a palindromic method stays palindromic.  The order is that of
    the two-part method for the methods of the CheckMethods table.

    Parameters
    ----------
    spec : a composition (or its spec) that uses exactly the pieces 1 and 2

    References
    ----------
    SplittingOrderConditions.jl (Auzinger, Herfort, Hofstaetter, Koch), ``src/SplittingOrderConditions.jl``,
    ``get_ABC_coeffs``, used for the ABC column of ``examples/CheckMethods.ipynb``.

    >>> three_parts("121").pieces, three_parts("12").pieces
    ((1, 2, 3, 2, 1), (1, 2, 3))
    """
    comp = composition(spec, 2)
    if set(comp.pieces) != {1, 2}:
        raise InvalidCompositionError(
            f"the three-part rule applies to a composition of the two pieces 1 and 2, got {_shown(comp.name)} "
            f"with pieces {sorted(set(comp.pieces))}"
        )
    pieces, coeffs = [], []

    def emit(k, c):
        if is_zero(c):
            return
        if pieces and pieces[-1] == k:
            coeffs[-1] = sympy.expand(coeffs[-1] + c)
            if is_zero(coeffs[-1]):
                pieces.pop()
                coeffs.pop()
        else:
            pieces.append(k)
            coeffs.append(c)

    ran = {1: sympy.Integer(0), 2: sympy.Integer(0)}
    middle = sympy.Integer(0)
    for k, c in comp.factors():
        emit(1 if k == 1 else 3, c)
        ran[k] = sympy.expand(ran[k] + c)
        emit(2, sympy.expand(ran[k] - middle))
        middle = ran[k]
    return Composition(tuple(pieces), tuple(coeffs), f"three-parts:{comp.name}", comp.order,
                       f"{comp.citation}; applied to three parts by CheckMethods' ABC rule (SplittingOrderConditions.jl)")


def composition_for(spec, target) -> Composition:
    """The composition ``spec`` for a splitting (or a system's splitting), checked: the one entry of every route.

    Aliases expand over the splitting's own pieces (``strang``, ``forest-ruth``,
    ``suzuki``); the result passes :meth:`Composition.check` (every piece used, each
    with total coefficient one) or an :class:`~nambu_bch.errors.InvalidCompositionError`
    is raised naming what is wrong.

    >>> from nambu_bch import model
    >>> composition_for("forest-ruth", model("ho3")).pieces
    (1, 2, 3, 2, 1, 2, 3, 2, 1, 2, 3, 2, 1)
    """
    from ..systems.splitting import Splitting
    from ..systems.system import System

    splitting = target.splitting if isinstance(target, System) else target
    if not isinstance(splitting, Splitting):
        raise InvalidCompositionError(
            f"a composition is used with a System or a Splitting (e.g. model('ho3')), got {type(target).__name__}"
        )
    return composition(spec, len(splitting)).check(splitting)


def sums_not_one(pairs) -> dict:
    """``{piece: sum}`` of the pieces whose exact coefficients in ``pairs`` (piece, coefficient) do not sum to 1
    (zero decided by :func:`~nambu_bch.algebra.zero.is_zero`); empty when every piece's do."""
    totals: dict = {}
    for k, c in pairs:
        totals[k] = totals.get(k, 0) + c
    sums = {k: sympy.nsimplify(t) for k, t in totals.items()}
    return {k: t for k, t in sums.items() if not is_zero(t - 1)}


def _exact(c, name):
    if c is None or isinstance(c, (bool, bytes, dict, list, tuple, set)):
        raise InvalidCompositionError(
            f"coefficient {c!r} of composition {_shown(name)} is not a number; give exact numbers such as '1/2' or sympy.Rational(1, 2)"
        )
    if isinstance(c, float):
        raise InvalidCompositionError(
            f"coefficient {c!r} of composition {name!r} is a float; give exact numbers such as '1/2' or sympy.Rational(1, 2)"
        )
    if isinstance(c, Fraction):
        c = sympy.Rational(c.numerator, c.denominator)
    if isinstance(c, str):
        from ..parsing import parse_expression

        # the imaginary unit is the one name of coefficient text: exact complex coefficients, e.g. 1/4+I/4
        c = parse_expression(c, {"I": sympy.I}, what=f"coefficient of composition {name!r}")
    try:
        c = sympy.sympify(c, strict=True)
    except (sympy.SympifyError, TypeError, ValueError):
        raise InvalidCompositionError(f"coefficient {c!r} of composition {_shown(name)} is not an exact number") from None
    if not isinstance(c, sympy.Expr) or not c.is_number or c.has(sympy.Float) or not c.is_finite:
        raise InvalidCompositionError(f"coefficient {c} of composition {name!r} must be an exact real number")
    if not c.is_real:
        real, imag = c.as_real_imag()
        if real.has(sympy.re, sympy.im) or imag.has(sympy.re, sympy.im) or imag.is_zero is not False:
            raise InvalidCompositionError(
                f"coefficient {c} of composition {name!r} must be an exact real number or a complex one a + b*I "
                "with exact real a, b"
            )
        c = sympy.expand(real + sympy.I * imag)
    return c


def _strang(word: str) -> Composition:
    mid = len(word) // 2
    coeffs = [sympy.Rational(1, 2)] * len(word)
    coeffs[mid] = sympy.Integer(1)
    return Composition(tuple(int(ch) for ch in word), tuple(coeffs), word, 2, "Horikoshi, Eqs. (PV1), (12321), (ST2)")


def _jump_base(base: Composition, what: str) -> int:
    """``p = order + 1`` of a symmetric base with rational coefficients, else one line saying why not."""
    if not base.symmetric or base.order % 2:
        raise InvalidCompositionError(f"the {what} needs a symmetric base scheme of even order, got {base.name!r}")
    if not all(c.is_Rational for c in base.coefficients):
        raise InvalidCompositionError(
            f"the {what} of {_shown(base.name)} is refused: its base already has irrational coefficients "
            "(nested jumps, order >= 6, are not supported); give a word with rational coefficients such as 12321"
        )
    return base.order + 1


def _jump(base: Composition, gammas, root, name: str, citation: str) -> Composition:
    """``Phi_{g_1 h} ... Phi_{g_m h}`` of ``base``, adjacent sub-flows of one piece merged, coefficients in QQ(root).

    ``gammas(theta)`` gives the ``g_i`` as elements of ``QQ(root)`` from its generator ``theta = root``:
    the arithmetic stays in the number field (one normal form per number, ``a + b r + c r^2 ...``); converting
    sympy expressions such as ``1/(2 - 2^(1/3))`` into the field would compute minimal polynomials each time.
    """
    field = QQ.algebraic_field(root)
    pieces, coeffs = [], []
    for g in gammas(field.from_sympy(root), field):
        for k, c in base.factors():
            term = g * field.convert(QQ.from_sympy(c), QQ)
            if pieces and pieces[-1] == k:  # merge adjacent sub-flows of one piece
                coeffs[-1] = coeffs[-1] + term
            else:
                pieces.append(k)
                coeffs.append(term)
    return Composition(tuple(pieces), tuple(field.to_sympy(c) for c in coeffs), name, base.order + 2, citation)


def _triple_jump(base: Composition) -> Composition:
    """Yoshida's triple jump ``Phi_{g1 h} Phi_{g0 h} Phi_{g1 h}``, order + 2 for symmetric ``base``.

    ``g1 = 1/(2 - 2^(1/p))``, ``g0 = -2^(1/p)/(2 - 2^(1/p))``, ``p = order + 1``
    (Yoshida 1990, Eq. 5.19).
    """
    p = _jump_base(base, "triple jump")

    def gammas(theta, field):
        g1 = field.one / (field.convert(2) - theta)
        return g1, -theta * g1, g1

    return _jump(base, gammas, sympy.Integer(2) ** sympy.Rational(1, p), f"triple-jump:{base.name}", TRIPLE_JUMP.reference)


def _five_jump(base: Composition) -> Composition:
    """Suzuki's fractal five-jump ``Phi_{g h} Phi_{g h} Phi_{(1-4g) h} Phi_{g h} Phi_{g h}``, order + 2.

    ``g = 1/(4 - 4^(1/p))``, ``p = order + 1`` (Suzuki, Phys. Lett. A 146 (1990) 319,
    Eq. 3.14): for a second-order base ``g1 = g2 = g4 = g5 = 1/(4 - 4^(1/3))`` and
    ``g3 = 1 - 4 g1``.  The coefficients lie in ``QQ(2^(2/p))``.
    """
    p = _jump_base(base, "five-jump")

    def gammas(theta, field):
        g = field.one / (field.convert(4) - theta)
        return g, g, field.one - field.convert(4) * g, g, g

    return _jump(base, gammas, sympy.Integer(4) ** sympy.Rational(1, p), f"suzuki:{base.name}", SUZUKI.reference)


def composition(spec, n_pieces: int | None = None) -> Composition:
    """A :class:`Composition` from a word, alias, ``"k:c,..."`` list or ``[(k, c), ...]``.

    Parameters
    ----------
    spec : str, Composition, or sequence of (piece, coefficient)
    n_pieces : int, optional
        Number of pieces of the splitting the composition is for: the aliases
        ``lie-trotter``, ``strang``, ``forest-ruth``, ``yoshida`` and ``suzuki`` expand
        over pieces ``1..n_pieces`` (without it ``forest-ruth``/``yoshida``/``suzuki``
        mean two pieces, ``121``), and ``TVT``/``VTV`` need ``n_pieces`` 2.
        Use :func:`composition_for` to also check the result against a splitting.

    Examples
    --------
    >>> composition("12321").coefficients
    (1/2, 1/2, 1, 1/2, 1/2)
    >>> composition("TVT").pieces
    (1, 2, 1)
    >>> composition("123").order, composition("123").symmetric
    (1, False)
    """
    if n_pieces is not None:
        if not is_int(n_pieces, 1, MAX_FACTORS):
            raise InvalidCompositionError(f"n_pieces must be a positive integer (the number of pieces), got {n_pieces!r}")
    if isinstance(spec, str):
        if len(spec) > MAX_TEXT:
            raise InvalidCompositionError(f"composition {_shown(spec)} is {len(spec)} characters long; at most {MAX_TEXT} are accepted")
        # compositions are immutable and radical coefficients are slow to normalise: build each once
        return _composition_from_text(spec, n_pieces)
    return _build(spec, n_pieces)


@lru_cache(maxsize=512)
def _composition_from_text(spec: str, n_pieces):
    return _build(spec, n_pieces)


def _build(spec, n_pieces):
    """The composition of ``spec``: a registered name (:data:`_FORMS`) or the generic forms of :func:`_generic`."""
    if isinstance(spec, Composition):
        return spec
    if isinstance(spec, (list, tuple)):
        return _from_pairs(spec)
    text = _checked_text(spec)
    head, sep, _ = text.lower().partition(":")
    form = _FORMS.get(head)
    if form is not None and (form.with_word if sep else form.alone):
        return form.build(text, n_pieces)
    return _generic(text)


def _from_pairs(spec) -> Composition:
    """An explicit ``[(piece, coefficient), ...]``."""
    if len(spec) > MAX_FACTORS:
        raise InvalidCompositionError(f"an explicit composition has at most {MAX_FACTORS} factors, got {len(spec)}")
    try:
        pairs = [(k, c) for k, c in spec]
    except (TypeError, ValueError):
        raise InvalidCompositionError(f"an explicit composition is a list of (piece, coefficient) pairs, got {_shown(spec)}") from None
    for k, _ in pairs:  # no silent coercion: 1.5, True or "1" is not a piece number
        if isinstance(k, bool) or not isinstance(k, (int, sympy.Integer)):
            raise UnknownPieceError(
                f"piece {k!r} of composition {_shown(spec)} is not an integer; pieces are numbered 1, 2, ..."
            )
    pieces = tuple(int(k) for k, _ in pairs)
    coeffs = tuple(c for _, c in pairs)
    return _with_order(Composition(pieces, coeffs, ",".join(f"{k}:{c}" for k, c in pairs)))


def _checked_text(spec) -> str:
    """``spec`` stripped, if it is non-empty text of the accepted characters."""
    if not isinstance(spec, str) or not spec.strip():
        raise InvalidCompositionError(f"a composition is a word such as '12321', an alias or 'k:c,...' list, got {_shown(spec)}")
    text = spec.strip()
    bad = sorted(set(ch for ch in text if not (ch.isascii() and (ch.isalnum() or ch in _TEXT_PUNCTUATION))))
    if bad:
        raise InvalidCompositionError(
            f"composition {_shown(text)} contains {''.join(bad)!r}; accepted are letters, digits, spaces and {_TEXT_PUNCTUATION.strip()}"
        )
    return text


def _alias(text, n_pieces) -> Composition:
    """``TVT``, ``VV``, ...: the Verlet words of a two-piece splitting."""
    low = text.lower()
    if n_pieces is not None and n_pieces != 2:
        raise InvalidCompositionError(
            f"{text!r} is {_ALIASES[low]} and exists only for two-piece splittings; this splitting has {n_pieces} "
            f"pieces (use the Strang word {strang_word(n_pieces)} or 'strang')"
        )
    comp = _strang(_ALIASES[low])
    return Composition(comp.pieces, comp.coefficients, text, 2, comp.citation)


def _over_pieces(text, n_pieces) -> Composition:
    """``lie-trotter`` (``12..n``) and ``strang`` (``12..n..21``) over the splitting's pieces."""
    if not n_pieces:
        raise InvalidCompositionError(f"{text!r} needs the number of pieces of the splitting")
    _digit_pieces(text, n_pieces)
    word = "".join(str(k) for k in range(1, n_pieces + 1))
    return composition(word if text.lower() == "lie-trotter" else strang_word(n_pieces))


def _jump_form(text, n_pieces) -> Composition:
    """``forest-ruth``, ``yoshida[:WORD]``, ``triple-jump[:WORD]``, ``suzuki[:WORD]``."""
    head, _, base = text.lower().partition(":")
    if not base:  # over the splitting's own Strang word (two pieces, 121, when unknown)
        base = strang_word(_digit_pieces(text, n_pieces) if n_pieces else 2)
    else:
        base = text.split(":", 1)[1].strip()
        if base.lower().startswith(tuple(j + ":" for j in _JUMPS[1:])) or base.lower() in _JUMPS:
            raise InvalidCompositionError(
                f"composition {_shown(text)}: nested jumps (order >= 6) are not supported; "
                "give one jump of a symmetric second-order word, e.g. yoshida:12321"
            )
    inner = composition(base, n_pieces)
    return _five_jump(inner) if head == "suzuki" else _triple_jump(inner)


def _table_method(text, n_pieces) -> Composition:
    """A method of the published decimal tables (:mod:`.tables`, built by :func:`lookup` below)."""
    return lookup(text, n_pieces)


def _generic(text) -> Composition:
    """The forms without a name: ``'piece:coefficient,...'`` and digit words; else the one-line refusal."""
    head = text.lower().partition(":")[0].strip()
    if ":" in text and not head.isdigit():
        raise InvalidCompositionError(_named_form_message(text, head))
    if ":" in text:
        pairs = []
        for item in text.split(","):
            k, sep, c = item.partition(":")
            if not sep or not k.strip().isdigit() or not c.strip():
                raise InvalidCompositionError(f"composition item {_shown(item)} of {_shown(text)} is not of the form 'piece:coefficient'")
            pairs.append((int(k), c.strip()))
        return composition(pairs)
    from .runge_kutta import PARTITIONED, TABLEAUX

    # a Runge-Kutta method is no word over the pieces: say where it is available
    if text.lower() in PARTITIONED:
        raise InvalidCompositionError(
            f"{text!r} is a partitioned Runge-Kutta pair, not a composition of the pieces; shadow_hamiltonians, "
            "check, iterate and compare accept it on canonical systems; the composition routes (BCH, FI, exact) do not")
    if text.lower() in TABLEAUX:
        raise InvalidCompositionError(
            f"{text!r} is a Runge-Kutta method, not a composition of the pieces; shadow_hamiltonians, check, iterate "
            "and compare accept it; the composition routes (BCH, FI, exact) do not")
    if not text.isdigit() or "0" in text:
        raise InvalidCompositionError(
            f"unknown composition {text!r}{did_you_mean(text, _NAMES) if not text.isdigit() else ''}; "
            "use a word of piece digits 1-9 such as '12321', "
            f"an alias ({', '.join(sorted(_ALIASES))}, lie-trotter, strang, forest-ruth, yoshida, yoshida:WORD, "
            "triple-jump:WORD, suzuki[:WORD], kahan-li[:WORD], yoshida6[:WORD], blanes-moan) "
            "or an explicit list 'piece:coefficient,...'"
        )
    if len(text) % 2 == 1 and text == text[::-1] and len(text) > 1:
        return _strang(text)
    return Composition(tuple(int(ch) for ch in text), (sympy.Integer(1),) * len(text), text, 1, "plain product (Lie-Trotter)")


@dataclass(frozen=True)
class _Form:
    """How a name is written: alone (``NAME``) and/or with a base word (``NAME:WORD``), and what builds it."""

    alone: bool
    with_word: bool
    build: object


_TEXT_PUNCTUATION = " :,/.+-*()^_"
#: The registry of names: the token before ``:`` (lower case) -> its form.  A name written in a form it does not
#: take (``strang:12321``) falls through to :func:`_generic`, which says so.
_FORMS = {
    **{alias: _Form(True, False, _alias) for alias in _ALIASES},
    "lie-trotter": _Form(True, False, _over_pieces),
    "strang": _Form(True, False, _over_pieces),
    **{jump: _Form(True, jump != "forest-ruth", _jump_form) for jump in _JUMPS},
    **{name: _Form(True, True, _table_method) for name in _CATALOG},
}
#: Names that take a base word after a colon (``yoshida:12321``) and names that stand alone.
_WITH_WORD = (*_JUMPS[1:], *(c for c in _CATALOG if TABLES[c].takes_word))
_NAMES = (*_ALIASES, "lie-trotter", "strang", *_JUMPS, *_CATALOG)


def _named_form_message(text: str, head: str) -> str:
    """The answer to ``NAME:REST`` where NAME takes no base word (``strang:12321``) or is no method at all."""
    forms = ", ".join(f"{name}:WORD" for name in _WITH_WORD)
    if head in _NAMES:
        return (
            f"composition {_shown(text)}: {head!r} takes no base word (it expands over the splitting's own pieces); "
            f"write {head!r} alone or a word such as '12321' itself; the forms with a word are {forms}"
        )
    return (
        f"composition {_shown(text)}: {_shown(head)} is not a method{did_you_mean(head, _NAMES)}; the forms with a "
        f"word are {forms} (e.g. yoshida:12321), an explicit list is 'piece:coefficient,...' such as '1:1/2,2:1,1:1/2'"
    )


def _digit_pieces(text, n_pieces):
    if n_pieces > MAX_PIECES:
        raise InvalidCompositionError(
            f"{text!r} is a word over pieces 1..{MAX_PIECES}; this splitting has {n_pieces} pieces "
            "(give an explicit 'piece:coefficient,...' list)"
        )
    return n_pieces


def _with_order(comp: Composition) -> Composition:
    order = 2 if comp.symmetric else 1
    return Composition(comp.pieces, comp.coefficients, comp.name, order, comp.citation or "explicit coefficients")


#: The paper's six symmetric second-order words for the N = 3 oscillator (Sect. 5.1).
PAPER_WORDS = ("12321", "13231", "31213", "21312", "23132", "32123")


# ---------------------------------------------------------------------------------------------
# The published decimal tables of :mod:`.tables` as compositions (documented in :mod:`.methods`, which names them).
# They are built here, beside the parser that resolves their names, so that parser and builder need no import cycle.

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
    modulo the RKN ideal (:func:`nambu_bch.design.defects.structured_bound`), where the published order holds."""
    # Deferred for the import order only: ``nambu_bch.design``'s package __init__ imports the order conditions,
    # which import this module; design.defects itself imports no composition parser (no module cycle).
    from ..design.defects import _Exact, structured_bound

    field = _Exact(comp)
    # Below degree 4 the RKN quotient is the free Lie algebra, and a symmetric method has E_4 = 0 exactly: there the
    # defects of the general order conditions measure only the rounding of the decimals, and count in the bound.
    general = comp.order if structure != "rkn" else min(comp.order, 4 if comp.symmetric else 3)
    bound = max(abs(complex(field.K.to_sympy(v))) for q in range(1, general + 1) for v in field.defects(parts, q).values())
    if structure == "rkn":
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
    base = composition(word)
    if not base.symmetric or base.order != 2:
        raise InvalidCompositionError(f"{name!r} composes a symmetric second-order base word such as '121' or '12321', got {word!r}")
    return base


#: A published complex decimal ``re+im*I`` of a table.
_COMPLEX_DECIMAL = re.compile(r"([+-]?[0-9.]+)([+-][0-9.]+)\*I")


def _number(text: str, exact: bool):
    """A table entry: a published decimal (or complex decimal ``re+im*I``) as the exact number it denotes, or an exact
    formula read by the package's whitelist parser (numbers, + - * / **, sqrt, cbrt and the imaginary unit I)."""
    if not exact:
        pair = _COMPLEX_DECIMAL.fullmatch(text)
        return sympy.Rational(pair[1]) + sympy.I * sympy.Rational(pair[2]) if pair else sympy.Rational(text)
    from ..parsing import parse_expression

    return parse_expression(text, {"I": sympy.I}, what="table coefficient")


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


def _word(table) -> Composition:
    """The composition of a ``"word"`` table: its factors as listed (mirrored when symmetric); for decimals the
    innermost factor of each piece is rebuilt from the others, ``1 - sum`` (symmetric: ``1 - 2 sum`` for the middle
    factor, ``1/2 - sum`` for another piece's innermost one), so that the scheme is exactly consistent."""
    pieces = [int(k) for k in table.word]
    values = [_number(v, table.exact) for v in table.values]
    if not table.exact:
        for k in set(pieces):
            inner = max(i for i, p in enumerate(pieces) if p == k)
            rest = sum(v for i, (p, v) in enumerate(zip(pieces, values)) if p == k and i != inner)
            if not table.symmetric:
                values[inner] = 1 - rest
            else:
                values[inner] = 1 - 2 * rest if inner == len(pieces) - 1 else sympy.Rational(1, 2) - rest
    values = [sympy.expand(v) for v in values]
    if table.symmetric:
        pieces, values = pieces + pieces[-2::-1], values + values[-2::-1]
    return Composition(tuple(pieces), tuple(values), table.name, table.order, table.reference)


@lru_cache(maxsize=64)
def _catalog_build(kind: str, word, n_pieces):
    table = TABLES[kind]
    if table.kind == "word":
        comp = _word(table)
        return comp if table.exact else with_error_bound(comp, comp.n_pieces, table.structure)
    if table.kind == "ab":
        if table.exact:
            return _ab(table)
        comp = with_error_bound(_ab(table), 2, table.structure)
        if table.generalized:  # the published accuracy is that of the generalised order, not only the classical one
            from ..design.defects import generalized_bound

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
            raise InvalidCompositionError(f"{kind!r} is a method of fixed pieces (1 = A, 2 = B, ...) and takes no base word")
        return _catalog_build(kind, None, None)
    return _catalog_build(kind, word or None, None if sep else n_pieces)


def methods() -> dict:
    """``{name: (order, stages, citation)}`` of the literature methods (Suzuki's five-jump and the decimal tables)."""
    return {t.name: (t.order, t.stages, t.reference) for t in (SUZUKI, *(TABLES[name] for name in NAMES))}
