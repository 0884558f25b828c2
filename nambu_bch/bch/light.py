"""A composition's word read without sympy: pieces and exact :class:`fractions.Fraction` coefficients.

:func:`formal_bch` serves the two-generator series (``12``, ``21``, ``121``, ``212``) from the shipped table
(:mod:`nambu_bch.bch.table`), which needs only the pieces and rational coefficients of the word.  Reading the
word with :func:`~nambu_bch.integrators.composition.composition` imports sympy (the coefficients of a
:class:`~nambu_bch.integrators.composition.Composition` are sympy numbers), which costs a fresh process more time
and memory than the whole series to degree 18.  :func:`parse_word` reads the plain forms of that grammar with
the same rules and the same result (pieces, coefficients, name, symmetry), and answers ``None`` for anything else
-- named methods, symbolic or decimal coefficients, and every input the full parser refuses -- so that the caller
goes the full parser's way, which gives the one-line errors.  The :class:`Word` builds its ``Composition`` only
when asked (the full parser, from the same text).

The forms read here:

* a digit word of pieces 1-9 (``"12"``, ``"12321"``): a palindrome of odd length is the symmetric second-order
  scheme (half steps except the middle letter), any other word a plain product of full steps;
* the Verlet aliases (``TVT``, ``PV``, ``position-verlet``, ``VTV``, ``VV``, ``velocity-verlet``; two pieces);
* ``lie-trotter`` and ``strang`` over ``n_pieces`` pieces;
* ``"piece:coefficient,..."`` with integer or ``p/q`` coefficients (``"1:1/2,2:1,1:1/2"``).

``tests/test_bch_cold.py`` checks each form against the full parser.

References
----------
Horikoshi, Eqs. (PV1), (12321) (the symmetric words); Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, Sect. II.4 (compositions).
"""

from __future__ import annotations

import re
from fractions import Fraction

# The grammar's limits and aliases, as nambu_bch.integrators.composition has them (tests/test_bch_cold.py
# checks that the two agree): that module imports sympy, so they are not imported from it.
MAX_FACTORS = 200
MAX_TEXT = 400
MAX_PIECES = 9
ALIASES = {"tvt": "121", "pv": "121", "position-verlet": "121", "vtv": "212", "vv": "212", "velocity-verlet": "212"}
#: a coefficient read here: an integer or p/q without leading zeros, as Python's parser (and so the package's
#: whitelist parser) reads them; at most 30 digits each (anything longer goes the full parser's way)
_NUMBER = re.compile(r"-?(?:0|[1-9][0-9]{0,29})(?:/[1-9][0-9]{0,29})?")
_PIECE = re.compile(r"[0-9]{1,3}")
_ONE, _HALF = Fraction(1), Fraction(1, 2)
#: the characters the full parser accepts in a composition's text (letters and digits besides)
_PUNCTUATION = " :,/.+-*()^_"


class Word:
    """A composition with rational coefficients, read without sympy.

    Attributes
    ----------
    spec : str -- the text it was read from
    n_pieces : int or None -- the number of pieces it was read for
    pieces : tuple of int
    coefficients : tuple of Fraction
    name : str -- the name the full parser gives it
    """

    # a plain immutable class: importing dataclasses (inspect, ast, dis, ...) would cost a fresh process more than
    # reading the series from the table
    __slots__ = ("spec", "n_pieces", "pieces", "coefficients", "name")

    def __init__(self, spec, n_pieces, pieces, coefficients, name):
        put = object.__setattr__
        put(self, "spec", spec)
        put(self, "n_pieces", n_pieces)
        put(self, "pieces", pieces)
        put(self, "coefficients", coefficients)
        put(self, "name", name)

    def __setattr__(self, name, value):
        raise AttributeError(f"cannot assign to field {name!r}: a Word is immutable")

    def __delattr__(self, name):
        raise AttributeError(f"cannot delete field {name!r}: a Word is immutable")

    def _fields(self) -> tuple:
        return tuple(getattr(self, key) for key in self.__slots__)

    def __eq__(self, other):
        return self._fields() == other._fields() if type(other) is type(self) else NotImplemented

    def __hash__(self):
        return hash(self._fields())

    def __repr__(self):
        return "Word(" + ", ".join(f"{key}={getattr(self, key)!r}" for key in self.__slots__) + ")"

    def __reduce__(self):
        return Word, self._fields()

    @property
    def symmetric(self) -> bool:
        """Palindromic pieces and coefficients (:attr:`Composition.symmetric`)."""
        return self.pieces == self.pieces[::-1] and self.coefficients == self.coefficients[::-1]

    def remainder_power(self, order: int) -> int:
        """:meth:`Composition.remainder_power`: ``order + 2`` for a symmetric word after an even order, else
        ``order + 1``."""
        return order + 2 if self.symmetric and order % 2 == 0 else order + 1

    def composition(self):
        """The :class:`~nambu_bch.integrators.composition.Composition` of :attr:`spec` (imports sympy)."""
        from ..integrators.composition import composition

        return composition(self.spec, self.n_pieces)


def parse_word(spec, n_pieces=None):
    """The :class:`Word` of ``spec`` if it is one of the plain forms (module docstring) and valid, else ``None``.

    ``None`` also for every input the full parser refuses: the caller then calls it, and it says why.

    >>> w = parse_word("121")
    >>> w.pieces, [str(c) for c in w.coefficients], w.symmetric
    ((1, 2, 1), ['1/2', '1', '1/2'], True)
    >>> parse_word("yoshida") is None, parse_word("1:sqrt(2),2:1") is None
    (True, True)
    """
    if not isinstance(spec, str) or len(spec) > MAX_TEXT:
        return None
    if n_pieces is not None and (type(n_pieces) is not int or not 1 <= n_pieces <= MAX_FACTORS):
        return None
    text = spec.strip()
    if text.isdigit() and text.isascii():  # a digit word (the usual request): no character to check one by one
        return None if "0" in text else _checked(spec, n_pieces, *_digits(text), text)
    if not all(ch.isascii() and (ch.isalnum() or ch in _PUNCTUATION) for ch in text):
        return None
    low = text.lower()
    if low in ALIASES:
        if n_pieces is not None and n_pieces != 2:
            return None
        return _checked(spec, n_pieces, *_digits(ALIASES[low]), text)
    if low in ("lie-trotter", "strang"):
        if not n_pieces or n_pieces > MAX_PIECES:
            return None
        word = "".join(str(k) for k in range(1, n_pieces + 1))
        if low == "strang":
            word += word[-2::-1]
        return _checked(spec, n_pieces, *_digits(word), word)
    if ":" in text:
        return _pairs(spec, n_pieces, text)
    return None


def _digits(word: str):
    """Pieces and coefficients of a digit word: a palindrome of odd length halves every step but the middle one."""
    pieces = tuple(map(int, word))
    if len(word) % 2 == 1 and len(word) > 1 and word == word[::-1]:
        coefficients = [_HALF] * len(word)
        coefficients[len(word) // 2] = _ONE
        return pieces, tuple(coefficients)
    return pieces, (_ONE,) * len(word)


def _pairs(spec, n_pieces, text):
    """``"piece:coefficient,..."``, every coefficient an integer or ``p/q``."""
    pieces, coefficients, names = [], [], []
    for item in text.split(","):
        k, _, c = item.partition(":")
        k, c = k.strip(), c.strip()
        if not _PIECE.fullmatch(k) or not _NUMBER.fullmatch(c):
            return None
        pieces.append(int(k))
        coefficients.append(Fraction(c))
        names.append(f"{int(k)}:{c}")
    return _checked(spec, n_pieces, tuple(pieces), tuple(coefficients), ",".join(names))


def _checked(spec, n_pieces, pieces, coefficients, name):
    """The :class:`Word`, or ``None`` where :class:`Composition` would refuse it (a piece out of range, too many
    factors, a piece whose coefficients do not sum to one)."""
    if not pieces or len(pieces) > MAX_FACTORS or not all(1 <= k <= MAX_FACTORS for k in pieces):
        return None
    totals: dict = {}
    for k, c in zip(pieces, coefficients):
        totals[k] = totals[k] + c if k in totals else c
    if any(t != 1 for t in totals.values()):
        return None
    return Word(spec, n_pieces, pieces, coefficients, name)
