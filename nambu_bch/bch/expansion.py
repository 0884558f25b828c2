"""Term-by-term expansion of a BCH series into brackets of Liouville terms (Eq. BCH3).

Each piece is a sum of Liouville terms, ``X_k = sum_t X_{t}`` with
``t = (H_a, G_b)`` (Eq. HGs, ``Piece.terms``); a bracket tree in the pieces is
multilinear, so it expands into the sum of the trees obtained by choosing one
term per leaf.  For the full split of a generic separable N = 3 system each
piece has two terms and each of the nine double commutators of Eq. (BCH2)
gives ``2^3`` trees: the 72 terms of Eq. (BCH3).

Pruning (``prune=True``) evaluates first the trees in the pieces on the
system's concrete fields and drops those that vanish *before* expanding them
(Eq. BCH4: five of the nine commutators of Eq. BCH2 vanish for ho3), then
drops expanded trees whose own value vanishes.  Evaluation is memoised with
zero subtrees pruned (:class:`~nambu_bch.bch.evaluation.BracketEvaluator`).

References
----------
Horikoshi, Eqs. (HGs), (BCH2), (BCH3), (BCH4).
"""

from __future__ import annotations

from itertools import product

from ..algebra import liouville_field
from ..algebra.backend import field_backend
from ..checks import check_flag, check_sequence, check_type, is_int, show
from ..errors import UnknownPieceError
from .evaluation import BracketEvaluator
from .lyndon import _terms, is_bracket, tree_leaves


def _expand_tree(tree, splitting):
    if is_bracket(tree):
        return [(a, b) for a, b in product(_expand_tree(tree[0], splitting), _expand_tree(tree[1], splitting))]
    return list(splitting[_leaf(tree, splitting)].terms)


def _leaf(leaf, splitting) -> int:
    """``leaf`` if it is a piece number of ``splitting``, else one line naming it."""
    if not is_int(leaf, 1, len(splitting)):
        raise UnknownPieceError(
            f"bracket tree leaf {show(leaf)} is not a piece of the splitting (pieces are 1..{len(splitting)})"
        )
    return leaf


def _evaluator(algebra, fields: dict) -> BracketEvaluator:
    backend = field_backend(algebra, fields)
    return BracketEvaluator(backend.fields, backend.bracket, backend.is_zero, to_field=backend.to_vector_field)


def piece_evaluator(splitting) -> BracketEvaluator:
    """A :class:`BracketEvaluator` whose leaves are the piece numbers of ``splitting``.

    Use ``.field(tree)`` for the :class:`~nambu_bch.algebra.VectorField` value (``.value`` is internal)."""
    return _evaluator(splitting.system.algebra, {p.number: p.field for p in splitting.pieces})


def term_evaluator(splitting) -> BracketEvaluator:
    """A :class:`BracketEvaluator` whose leaves are the Liouville terms ``(H_a, G_b, ...)`` of ``splitting``."""
    algebra = splitting.system.algebra
    terms = {t for p in splitting.pieces for t in p.terms}
    return _evaluator(algebra, {t: liouville_field(algebra, *t) for t in terms})


def expand_terms(terms, splitting, prune: bool = True, evaluators=None) -> list:
    """Replace every piece by its Liouville terms: ``[(coefficient, tree_of_terms), ...]``.

    Parameters
    ----------
    terms : iterable of ``(coefficient, tree)``
        Trees in the piece numbers, e.g. ``FormalBCH.terms(3)`` or the paper's
        nine-term Eq. (BCH2).
    splitting : Splitting
        Supplies ``Piece.terms`` (and, when pruning, the concrete fields).
    prune : bool
        Drop trees whose concrete value is zero, before and after expansion.
    evaluators : (BracketEvaluator, BracketEvaluator), optional
        Reuse memoised evaluators for pieces and terms across calls.

    Returns
    -------
    list of ``(coefficient, tree)`` whose leaves are Liouville terms, tuples of
    Hamiltonian pieces exactly as in ``Piece.terms``; input order is kept.

    Examples
    --------
    >>> from nambu_bch import model
    >>> from nambu_bch.bch import formal_bch
    >>> S = model("ho3").splitting
    >>> len(expand_terms(formal_bch("12321", 3).terms(3), S, prune=False)), len(expand_terms(formal_bch("12321", 3).terms(3), S))
    (8, 4)
    """
    from ..systems.splitting import Splitting

    check_type(splitting, Splitting, "splitting")
    prune = check_flag(prune, "prune")
    if evaluators is not None:
        for e in check_sequence(evaluators, "evaluators", "BracketEvaluators", length=2):
            check_type(e, BracketEvaluator, "each of evaluators")
    terms = list(_terms(terms, 2))
    for _, tree in terms:  # every leaf a piece, before a tree is evaluated
        for leaf in tree_leaves(tree):
            _leaf(leaf, splitting)
    pieces_eval, terms_eval = evaluators or (piece_evaluator(splitting), term_evaluator(splitting)) if prune else (None, None)
    out = []
    for c, tree in terms:
        if prune and pieces_eval.is_zero(tree):
            continue
        for expanded in _expand_tree(tree, splitting):
            if prune and terms_eval.is_zero(expanded):
                continue
            out.append((c, expanded))
    return out
