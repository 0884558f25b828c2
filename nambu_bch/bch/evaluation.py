"""Bracket trees evaluated on concrete vector fields, memoised, with zero subtrees pruned.

A tree ``[T_1, T_2]`` is evaluated as the commutator of the values of its two
subtrees (``[X, Y] = XY - YX`` as operators, Eq. CL1).  Every subtree is
evaluated at most once per evaluator (the standard bracketings of Lyndon words
share their factors, so a whole BCH series costs one bracket per Lyndon word),
and a subtree whose value is zero makes every tree containing it zero without
further work: only what the request needs is computed.

References
----------
Horikoshi, Eqs. (CL1), (BCH2)-(BCH4) (commutators that vanish for ho3 are dropped).
"""

from __future__ import annotations

from ..errors import UnknownPieceError
from .lyndon import is_bracket


class BracketEvaluator:
    """Memoised values of bracket trees whose leaves name concrete vector fields.

    Parameters
    ----------
    leaf_value : dict or callable
        Leaf -> :class:`~nambu_bch.algebra.VectorField` (piece number -> piece field,
        Liouville term -> its field).
    bracket : callable, optional
        ``bracket(X, Y)``; default ``X.bracket(Y)``.
    is_zero : callable, optional
        ``is_zero(X)``; default ``X.is_zero()``.
    to_field : callable, optional
        Internal value -> :class:`~nambu_bch.algebra.VectorField` (for fast backends);
        default: values are fields already.

    Examples
    --------
    >>> from nambu_bch import model
    >>> S = model("ho3").splitting
    >>> E = BracketEvaluator({p.number: p.field for p in S.pieces})
    >>> E.is_zero((1, (1, 3))), E.is_zero((1, (1, 2)))     # Eq. (BCH4)
    (True, False)
    >>> E.field((1, (1, 2))).to_sympy()
    (2*omega**2*x2/m, 0, 0)
    """

    def __init__(self, leaf_value, bracket=None, is_zero=None, to_field=None):
        self._leaf = leaf_value
        self._bracket = bracket or (lambda X, Y: X.bracket(Y))
        self._is_zero = is_zero or (lambda X: X.is_zero())
        self._to_field = to_field
        self._cache: dict = {}
        self._by_id: dict = {}
        self.brackets_computed = 0

    def leaf(self, leaf):
        if callable(self._leaf) and not isinstance(self._leaf, dict):
            return self._leaf(leaf)
        try:
            return self._leaf[leaf]
        except KeyError:
            raise UnknownPieceError(
                f"bracket tree leaf {leaf!r} is not a generator here; known generators: {sorted(self._leaf, key=str)}"
            ) from None

    def value(self, tree):
        """The field of ``tree``, or ``None`` when it is zero."""
        # BCH trees are shared objects (cached standard bracketings): look them up by identity
        # first, which avoids re-hashing a nested tuple on every call
        hit = self._by_id.get(id(tree))
        if hit is not None and hit[0] is tree:
            return hit[1]
        try:
            result = self._cache[tree]
            self._by_id[id(tree)] = (tree, result)
            return result
        except KeyError:
            pass
        if is_bracket(tree):
            left = self.value(tree[0])
            right = self.value(tree[1]) if left is not None else None
            if left is None or right is None or tree[0] == tree[1]:
                result = None
            else:
                result = self._bracket(left, right)
                self.brackets_computed += 1
                if self._is_zero(result):
                    result = None
        else:
            result = self.leaf(tree)
            if result is not None and self._is_zero(result):
                result = None
        self._cache[tree] = result
        self._by_id[id(tree)] = (tree, result)
        return result

    def field(self, tree, zero=None):
        """The value of ``tree`` as a :class:`~nambu_bch.algebra.VectorField` (``zero`` when it vanishes)."""
        value = self.value(tree)
        if value is None:
            return zero
        return self._to_field(value) if self._to_field else value

    def is_zero(self, tree) -> bool:
        """``True`` when the concrete value of ``tree`` vanishes."""
        return self.value(tree) is None
