"""The free Lie algebra: Lyndon words, their standard bracketing, bracket trees.

Basis.  Over an ordered alphabet ``a_0 < a_1 < ...`` a *Lyndon word* is a
non-empty word strictly smaller (lexicographically) than each of its proper
suffixes.  Its *standard factorisation* is ``w = u v`` with ``v`` the longest
proper suffix of ``w`` that is itself Lyndon (then ``u`` is Lyndon too), and
its *standard bracketing* is ``P_a = a`` for a letter and
``P_w = [P_u, P_v]``.  The ``P_w`` over all Lyndon words form a basis of the
free Lie algebra (Chen-Fox-Lyndon), and expanded in the free associative
algebra ``P_w = w + sum_{v > w} alpha_v v`` (all ``v`` rearrangements of
``w``; Reutenauer, Thm. 5.1), which makes coordinates in this basis a
triangular solve.  The number of Lyndon words of length ``d`` over ``g``
letters is Witt's formula ``(1/d) sum_{e | d} mu(e) g^(d/e)``.

Trees.  A bracket tree is a leaf or a 2-tuple ``(left, right)`` meaning the
commutator ``[left, right] = left right - right left``.  A leaf is an
``int`` (a piece / generator number), or a tuple of sympy expressions (a
Liouville term ``X_{A,B}`` as in ``Piece.terms``); :func:`is_bracket` tells
the two tuple kinds apart by their entries.

References
----------
Reutenauer, *Free Lie Algebras* (1993), Sect. 5.1 and Thm. 5.1 (Lyndon basis),
Cor. 4.14 (Witt's formula); Duval, J. Algorithms 4 (1983) 363 (generation);
Horikoshi, Eq. (BCH2) (nested commutators written as trees).
"""

from __future__ import annotations

import sys
from functools import lru_cache

# numpy and sympy are imported where they are used: the trees of a series served from the table need neither
from ..checks import check_int, check_sequence, is_int, show
from ..errors import InvalidRunError, ResourceLimitError, UnknownPieceError


def is_bracket(tree) -> bool:
    """``True`` for a bracket node ``(left, right)``, ``False`` for a leaf.

    >>> import sympy
    >>> is_bracket((1, (2, 3))), is_bracket(1), is_bracket((sympy.Symbol("A"), sympy.Symbol("C")))
    (True, False, False)
    """
    basic = _sympy_basic()
    return type(tree) is tuple and len(tree) == 2 and not isinstance(tree[0], basic) and not isinstance(tree[1], basic)


def _sympy_basic():
    """sympy's ``Basic`` if sympy is imported, else ``()``: a Liouville term's entries exist only once it is."""
    sympy = sys.modules.get("sympy")
    return () if sympy is None else sympy.Basic


def tree_degree(tree) -> int:
    """Number of leaves of a bracket tree (its degree in the free Lie algebra).

    >>> tree_degree((1, (1, 2)))
    3
    """
    if is_bracket(tree):
        return tree_degree(tree[0]) + tree_degree(tree[1])
    return 1


def tree_leaves(tree) -> tuple:
    """The leaves of a tree, left to right.

    >>> tree_leaves(((1, 2), (1, 3)))
    (1, 2, 1, 3)
    """
    basic = _sympy_basic()
    return _leaves(tree, basic) if basic else _pair_leaves(tree)


def _leaves(tree, basic) -> tuple:
    """:func:`tree_leaves`, a tuple with an entry of type ``basic`` (sympy's) being a leaf (:func:`is_bracket`)."""
    if type(tree) is tuple and len(tree) == 2 and not isinstance(tree[0], basic) and not isinstance(tree[1], basic):
        return _leaves(tree[0], basic) + _leaves(tree[1], basic)
    return (tree,)


def _pair_leaves(tree) -> tuple:
    """:func:`tree_leaves` without sympy: every pair is a bracket (faster than :func:`_leaves`, the cost
    of writing a series served without sympy)."""
    return _pair_leaves(tree[0]) + _pair_leaves(tree[1]) if type(tree) is tuple and len(tree) == 2 else (tree,)


#: Largest number of bits of ``n_letters ** degree`` that :func:`witt_dimension` computes (the degree is a BCH
#: degree, at most a few dozen in any series the package can build).
MAX_WITT_BITS = 10**5
#: Highest degree of a tree that :func:`tree_to_associative` expands (the BCH routes stop at degree 13).
MAX_TREE_DEGREE = 16


def witt_dimension(n_letters: int, degree: int) -> int:
    """Number of Lyndon words of length ``degree`` over ``n_letters`` letters (Witt's formula).

    ``dim L_d = (1/d) sum_{e | d} mu(e) g^(d/e)``: the dimension of the degree-``d``
    part of the free Lie algebra on ``g`` generators (Reutenauer, Cor. 4.14).

    >>> [witt_dimension(3, d) for d in range(1, 10)]
    [3, 3, 8, 18, 48, 116, 312, 810, 2184]
    """
    n_letters, degree = check_int(n_letters, "n_letters", 0), check_int(degree, "degree")
    if degree < 1:
        return 0
    if degree * max(1, n_letters.bit_length()) > MAX_WITT_BITS:  # before the trial division and the powers
        raise ResourceLimitError(f"witt_dimension({show(n_letters)}, {show(degree)}) has about "
                                 f"{show(degree * n_letters.bit_length())} bits; at most {MAX_WITT_BITS} are computed")
    return _witt_dimension(n_letters, degree)


@lru_cache(maxsize=4096)
def _witt_dimension(n_letters: int, degree: int) -> int:
    total = sum(mobius(e) * n_letters ** (degree // e) for e in divisors(degree))
    return int(total) // degree


def divisors(n: int) -> list:
    """The positive divisors of ``n >= 1``, increasing (trial division; ``n`` is a degree, small).

    >>> divisors(12)
    [1, 2, 3, 4, 6, 12]
    """
    return [e for e in range(1, n + 1) if n % e == 0]


def mobius(n: int) -> int:
    """The Möbius function: ``(-1)^k`` for ``n`` a product of ``k`` distinct primes, else 0 (``mobius(1) = 1``).

    >>> [mobius(n) for n in range(1, 11)]
    [1, -1, -1, 0, -1, 1, -1, 0, 0, 1]
    """
    sign, p = 1, 2
    while p * p <= n:
        if n % p == 0:
            n //= p
            if n % p == 0:
                return 0
            sign = -sign
        p += 1
    return -sign if n > 1 else sign


def lyndon_words(n_letters: int, degree: int) -> list:
    """All Lyndon words of length ``degree`` over letters ``0..n_letters-1``, in lexicographic order.

    Duval's algorithm generates every Lyndon word of length ``<= degree`` in order.

    >>> lyndon_words(2, 3)
    [(0, 0, 1), (0, 1, 1)]
    """
    return list(_lyndon_words(check_int(n_letters, "n_letters"), check_int(degree, "degree")))


@lru_cache(maxsize=None)
def _lyndon_words(n_letters: int, degree: int) -> tuple:
    if n_letters < 1 or degree < 1:
        return ()
    out = []
    w = [-1]
    while w:
        w[-1] += 1
        if len(w) == degree:
            out.append(tuple(w))
        m = len(w)
        while len(w) < degree:
            w.append(w[len(w) - m])
        while w and w[-1] == n_letters - 1:
            w.pop()
    return tuple(out)


def is_lyndon(word) -> bool:
    """``word`` is strictly smaller than all its proper suffixes.

    >>> is_lyndon((0, 1)), is_lyndon((1, 0)), is_lyndon((0, 0))
    (True, False, False)
    """
    word = tuple(word)
    return bool(word) and all(word < word[i:] for i in range(1, len(word)))


@lru_cache(maxsize=None)
def standard_factorization(word: tuple) -> tuple:
    """``(u, v)`` with ``v`` the longest proper Lyndon suffix of the Lyndon word ``word``.

    >>> standard_factorization((0, 0, 1, 0, 1))
    ((0, 0, 1), (0, 1))
    """
    for i in range(1, len(word)):
        if is_lyndon(word[i:]):
            return word[:i], word[i:]
    raise InvalidRunError(f"{word!r} is a letter or not a Lyndon word; standard factorisation needs a Lyndon word of length >= 2")


def standard_bracketing(word, letters=None):
    """The bracket tree ``P_w`` of a Lyndon word; leaves are ``letters[a]`` (default: the letters).

    >>> standard_bracketing((0, 0, 1), letters=(1, 2))
    (1, (1, 2))
    """
    word = tuple(_sequence(word, "word"))
    if letters is not None:
        letters = check_sequence(letters, "letters", "leaves")
    top = None if letters is None else len(letters) - 1
    if not word or not all(is_int(a, 0, top, numpy=True) for a in word):
        raise InvalidRunError(f"word must be a non-empty Lyndon word of letters 0..{'g-1' if top is None else top} "
                              f"(integers), got {show(word)}")
    return _bracketing(word, letters)


def _bracketing(word, letters):
    if len(word) == 1:
        return word[0] if letters is None else letters[word[0]]
    u, v = standard_factorization(word)
    return (_bracketing(u, letters), _bracketing(v, letters))


@lru_cache(maxsize=None)
def lyndon_expansion(word: tuple, n_letters: int) -> tuple:
    """``P_w`` in the free associative algebra as ``(indices, coefficients)`` numpy int64 arrays.

    A word ``a_1 .. a_d`` has index ``sum a_i g^(d-i)`` (base-``g`` digits), so that
    lexicographic order of equal-length words is numeric order of indices.
    """
    import numpy as np

    g = n_letters
    if len(word) == 1:
        return np.array([word[0]], dtype=np.int64), np.array([1], dtype=np.int64)
    u, v = standard_factorization(word)
    iu, cu = lyndon_expansion(u, g)
    iv, cv = lyndon_expansion(v, g)
    su, sv = g ** len(u), g ** len(v)
    idx = np.concatenate([(iu[:, None] * sv + iv[None, :]).ravel(), (iv[:, None] * su + iu[None, :]).ravel()])
    coef = np.concatenate([(cu[:, None] * cv[None, :]).ravel(), -(cv[:, None] * cu[None, :]).ravel()])
    keys, inverse = np.unique(idx, return_inverse=True)
    summed = np.zeros(len(keys), dtype=np.int64)
    np.add.at(summed, inverse, coef)
    keep = summed != 0
    return keys[keep], summed[keep]


def word_index(word, n_letters: int) -> int:
    """Base-``g`` index of a word (see :func:`lyndon_expansion`)."""
    index = 0
    for a in word:
        index = index * n_letters + a
    return index


def tree_to_associative(tree) -> dict:
    """A bracket tree expanded in the free associative algebra: ``{word: integer}``.

    Words are tuples of leaves; ``[x, y] = xy - yx``.

    >>> sorted(tree_to_associative((1, 2)).items())
    [((1, 2), 1), ((2, 1), -1)]
    """
    degree = tree_degree(tree)
    if degree > MAX_TREE_DEGREE:  # the expansion has up to 2^(degree - 1) words
        raise ResourceLimitError(f"a bracket tree of degree {degree} expands into up to 2^{degree - 1} words; "
                                 f"at most degree {MAX_TREE_DEGREE} is expanded")
    for leaf in tree_leaves(tree):
        try:
            hash(leaf)
        except TypeError:
            raise InvalidRunError(f"the leaves of a bracket tree must be hashable (numbers, symbols, tuples), "
                                  f"got {show(leaf)}") from None
    return _associative(tree)


def _associative(tree) -> dict:
    if not is_bracket(tree):
        return {(tree,): 1}
    left, right = _associative(tree[0]), _associative(tree[1])
    out: dict = {}
    for a, ca in left.items():
        for b, cb in right.items():
            out[a + b] = out.get(a + b, 0) + ca * cb
            out[b + a] = out.get(b + a, 0) - ca * cb
    return {w: c for w, c in out.items() if c != 0}


def _sequence(value, what):
    """``value`` if it can be iterated as a sequence (a string too), else one line naming ``what``."""
    if not hasattr(value, "__iter__") or isinstance(value, dict):
        raise InvalidRunError(f"{what} must be a sequence, got {show(value)}")
    return value


def _terms(terms, lengths):
    """The ``(coefficient, tree[, factor])`` items of ``terms``, each checked to be a tuple of an accepted length."""
    lengths = lengths if isinstance(lengths, tuple) else (lengths,)
    form = " or ".join({2: "(coefficient, tree)", 3: "(coefficient, tree, factor)"}[n] for n in lengths)
    for item in _sequence(terms, "terms"):
        if not isinstance(item, (tuple, list)) or len(item) not in lengths:
            raise InvalidRunError(f"each term must be a {form} tuple, got {show(item)}")
        yield item


def lie_to_associative(terms) -> dict:
    """``sum c * tree`` over ``(c, tree)`` pairs, in the free associative algebra: ``{word: c}``.

    Two Lie polynomials are equal iff these dicts are equal (the free Lie algebra
    embeds in the free associative algebra, Reutenauer Thm. 0.5); this is how the
    paper's nine-term Eq. (BCH2), which is not written in a basis, is compared
    with the Lyndon-basis series.

    >>> lie_to_associative([(1, (1, (2, 3))), (1, (2, (3, 1))), (1, (3, (1, 2)))])    # Jacobi
    {}
    """
    out: dict = {}
    for c, tree in _terms(terms, 2):
        for w, k in tree_to_associative(tree).items():
            out[w] = out.get(w, 0) + c * k
    return {w: c for w, c in out.items() if c != 0}


def tree_to_latex(tree, names=None) -> str:
    """LaTeX of a bracket tree, ``[X_{1},[X_{1},X_{2}]]``; ``names`` maps leaves to LaTeX.

    ``names`` is a dict or a callable; the default writes ``X_{k}`` for an integer
    leaf ``k`` and ``X_{A,B}`` for a Liouville term ``(A, B)``.

    >>> tree_to_latex((1, (1, 2)))
    '[X_{1},[X_{1},X_{2}]]'
    """
    if names is not None and not (callable(names) or isinstance(names, dict)):
        raise InvalidRunError(f"names must be a dict or a callable, got {show(names)}")
    if is_bracket(tree):
        return f"[{tree_to_latex(tree[0], names)},{tree_to_latex(tree[1], names)}]"
    if names is not None:
        if callable(names):
            return names(tree)
        try:
            known = tree in names
        except TypeError:  # an unhashable leaf cannot be a key of names
            known = False
        if not known:
            raise UnknownPieceError(f"no LaTeX name for generator {show(tree)}; names given for "
                                    f"{show(sorted(names, key=str))}")
        return names[tree]
    if isinstance(tree, tuple):
        import sympy

        return "X_{" + ",".join(sympy.latex(e) for e in tree) + "}"
    return f"X_{{{tree}}}"


def terms_to_latex(terms, names=None) -> str:
    r"""A linear combination of bracket trees as LaTeX, term by term.

    Parameters
    ----------
    terms : iterable of ``(coefficient, tree)`` or ``(coefficient, tree, factor)``
        ``factor`` (e.g. ``h**2``) multiplies the coefficient when printed.
    names : dict or callable, optional
        As in :func:`tree_to_latex`.

    Examples
    --------
    Eq. (BCH1) in the paper's form:

    >>> import sympy
    >>> terms_to_latex([(1, 1), (1, 2), (sympy.Rational(-1, 24), (1, (1, 2))), (sympy.Rational(1, 12), (2, (2, 1)))],
    ...                {1: "X_T", 2: "X_V"})
    'X_T + X_V - \\frac{1}{24} [X_T,[X_T,X_V]] + \\frac{1}{12} [X_V,[X_V,X_T]]'
    """
    import sympy

    parts = []
    for item in _terms(terms, (2, 3)):
        c, tree, factor = item if len(item) == 3 else (*item, sympy.Integer(1))
        c = sympy.sympify(c, strict=True)
        body = tree_to_latex(tree, names)
        if c.is_Rational:
            magnitude = abs(c) * factor
            text = "" if magnitude == 1 else sympy.latex(magnitude) + " "
            parts.append(f"{'-' if c < 0 else '+'} {text}{body}")
        else:
            extra = "" if factor == 1 else " " + sympy.latex(factor)
            parts.append(rf"+ \left({sympy.latex(c)}\right){extra} {body}")
    text = " ".join(parts)
    if text.startswith("+ "):
        text = text[2:]
    elif text.startswith("- "):
        text = "-" + text[2:]
    return text or "0"
