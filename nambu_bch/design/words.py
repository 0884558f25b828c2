"""Coefficients of associative words in a product of exponentials, and the Lyndon defects.

For a composition ``Phi = exp(c_1 X_{k_1}) ... exp(c_s X_{k_s})`` (the package's
operator order, :mod:`nambu_bch.integrators.composition`) with the pieces as free
non-commuting generators, the coefficient of a word ``w = l_1 ... l_q`` in the
associative expansion of ``Phi`` is

    [w] Phi = sum over splittings w = B_1 B_2 ... B_s into consecutive blocks,
              block B_j empty or a power k_j^m,  of  prod_j c_j^m / m!,

computed by a dynamic programme over (factors, prefix length).  The exact flow
``exp(X_1 + ... + X_n)`` has ``[w] = 1/q!`` for every word of length ``q``.

If ``Phi = exp(X_1 + ... + X_n + E_q + O(q+1))`` with ``E_q`` the first non-zero
homogeneous part of ``log Phi - sum X_i`` (degree ``q``), then the degree-``q``
part of ``Phi - exp(sum X_i)`` is ``E_q``, a Lie polynomial; a Lie polynomial
vanishes iff its coefficients on the Lyndon words vanish (``P_w = w + larger
words``, Reutenauer, *Free Lie Algebras*, Thm. 5.1).  So the *Lyndon defects*

    d_w = q! [w] Phi - 1,      w a Lyndon word of length q,

vanish for all ``q <= p`` exactly when the composition has order ``p`` (this is
the formulation of SplittingOrderConditions.jl, H. Hofstaetter, and of Auzinger,
Hofstaetter, Ketcheson, Koch, BIT 57 (2017) 55, Sect. 2), and their 2-norm at
``q = p + 1`` is the local error measure LEM.

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. III.3-III.5;
Reutenauer, *Free Lie Algebras*, Thm. 5.1; Auzinger, Hofstaetter, Ketcheson,
Koch, *Practical splitting methods for the adaptive integration of nonlinear
evolution equations. Part I*, BIT Numer. Math. 57 (2017) 55-74.
"""

from __future__ import annotations

from math import factorial

from ..bch.lyndon import lyndon_words, witt_dimension

#: Largest number of (Lyndon word x factor x letter) operations one degree may cost.
MAX_WORK = 4_000_000


def word_coefficient(word, factors, one, zero, inv_factorial):
    """``[word] prod_j exp(c_j X_{k_j})`` for ``factors = [(k_j, c_j)]`` (any ring with ``+``, ``*``).

    ``inv_factorial(m)`` returns ``1/m!`` in the coefficient ring.

    >>> from fractions import Fraction
    >>> f = lambda m: Fraction(1, factorial(m))
    >>> word_coefficient((1, 2), [(1, Fraction(1)), (2, Fraction(1))], Fraction(1), Fraction(0), f)
    Fraction(1, 1)
    >>> word_coefficient((2, 1), [(1, Fraction(1)), (2, Fraction(1))], Fraction(1), Fraction(0), f)
    Fraction(0, 1)
    """
    word = tuple(word)
    return word_coefficients([word], factors, one, zero, inv_factorial)[word]


def word_coefficients(words, factors, one, zero, inv_factorial) -> dict:
    """``{w: [w] prod_j exp(c_j X_{k_j})}`` for several words, sharing the work of common prefixes.

    The dynamic programme of the module docstring, column by column: ``T[j][i]`` is the
    coefficient of the prefix ``w[:i]`` in the product of the first ``j`` factors,

        T[j][0] = 1,   T[0][i] = 0 (i > 0),
        T[j][i] = T[j-1][i] + sum_{m >= 1, w[i-m:i] = k_j^m} T[j-1][i-m] c_j^m / m!,

    and ``[w] = T[s][len(w)]``.  Column ``i`` depends on ``w[:i]`` only, so the words are
    visited in lexicographic order (a walk over their prefix tree) and the columns of a
    shared prefix are computed once; ``c_j^m / m!`` is formed once per factor and ``m``.
    Exact coefficient rings give the same values as the factor-by-factor programme.

    >>> from fractions import Fraction
    >>> f = lambda m: Fraction(1, factorial(m))
    >>> fac = [(1, Fraction(2)), (2, Fraction(3))]            # e^{2A} e^{3B}: [AB] = 6, [AAB] = 4 * 3 / 2
    >>> word_coefficients([(1, 2), (1, 1, 2), (2, 1)], fac, Fraction(1), Fraction(0), f)
    {(1, 1, 2): Fraction(6, 1), (1, 2): Fraction(6, 1), (2, 1): Fraction(0, 1)}
    """
    words = sorted({tuple(w) for w in words})
    top = max((len(w) for w in words), default=0)
    s = len(factors)
    letters = [k for k, _ in factors]
    scaled = []  # scaled[j][m] = c_j^m / m!
    for _, c in factors:
        row, power = [None], one
        for m in range(1, top + 1):
            power = power * c
            row.append(power * inv_factorial(m))
        scaled.append(row)
    out = {}
    path: tuple = ()
    columns = [[one] * (s + 1)]  # columns[i][j] = T[j][i] along the current path
    for w in words:
        common = 0
        while common < min(len(path), len(w)) and path[common] == w[common]:
            common += 1
        del columns[common + 1:]
        for i in range(common + 1, len(w) + 1):
            col = [zero] * (s + 1)
            for j in range(1, s + 1):
                k, acc = letters[j - 1], col[j - 1]
                m = 1
                while m <= i and w[i - m] == k:
                    prev = columns[i - m][j - 1]
                    if prev != zero:
                        acc = acc + prev * scaled[j - 1][m]
                    m += 1
                col[j] = acc
            columns.append(col)
        path = w
        out[w] = columns[len(w)][s]
    return out


def lyndon_defect_words(n_pieces: int, degree: int) -> list:
    """Lyndon words of length ``degree`` over the pieces ``1..n_pieces`` (``1 < 2 < ...``), lexicographic."""
    return [tuple(a + 1 for a in w) for w in lyndon_words(n_pieces, degree)]


def work(n_pieces: int, degree: int, n_factors: int) -> int:
    """Operation count of the defects of one degree: Witt dimension x factors x degree^2."""
    return witt_dimension(n_pieces, degree) * n_factors * degree * degree


def log_coefficients(factors, n_pieces: int, degree: int, one, zero, rational) -> dict:
    """``{w: [w] log Phi}`` over the Lyndon words ``w`` of length ``degree >= 2`` (minus ``1`` per letter at degree 1).

    ``[w] log(1 + Q) = sum_k (-1)^(k+1)/k sum_{w = u_1 ... u_k} prod_i [u_i] Phi`` over the
    splittings of ``w`` into ``k`` non-empty consecutive subwords; the coefficients of the
    subwords are computed once, all together (:func:`word_coefficients`; a word of length ``q`` has ``q(q+1)/2`` of them).  With linear-form
    coefficients the degree-``q`` part is homogeneous of degree ``q``, and it vanishes for
    ``q = 2..p`` exactly when the composition has order ``p``: these are the order conditions.
    ``rational(a, b)`` returns ``a/b`` in the coefficient ring.
    """
    inverse_factorials = {}

    def inv_factorial(m):
        if m not in inverse_factorials:
            inverse_factorials[m] = rational(1, factorial(m))
        return inverse_factorials[m]

    words = lyndon_defect_words(n_pieces, degree)
    coefficient = word_coefficients({w[j:i] for w in words for i in range(len(w) + 1) for j in range(i)},
                                    factors, one, zero, inv_factorial)
    out = {}
    for w in words:
        q = len(w)
        if q == 1:
            out[w] = coefficient[w] - one
            continue
        # A[i][k]: sum over splittings of w[:i] into k pieces
        A = [[zero] * (q + 1) for _ in range(q + 1)]
        A[0][0] = one
        for i in range(1, q + 1):
            for j in range(i):
                c = coefficient[w[j:i]]
                if c == zero:
                    continue
                for k in range(1, i + 1):
                    if A[j][k - 1] != zero:
                        A[i][k] = A[i][k] + A[j][k - 1] * c
        total = zero
        for k in range(1, q + 1):
            if A[q][k] != zero:
                total = total + A[q][k] * rational((-1) ** (k + 1), k)
        out[w] = total
    return out


def lyndon_defects(factors, n_pieces: int, degree: int, one, zero, inv_factorial) -> dict:
    """``{w: q! [w] Phi - 1}`` over the Lyndon words ``w`` of length ``q = degree`` (see module docstring)."""
    q_fact = factorial(degree)
    words = lyndon_defect_words(n_pieces, degree)
    coefficients = word_coefficients(words, factors, one, zero, inv_factorial)
    return {w: coefficients[w] * q_fact - one for w in words}
