"""Concrete ``X_eff(h)`` of a composition: the formal BCH series evaluated on the pieces' fields.

``X_eff = sum_j h^j Z_j`` with ``Z_j = sum_{w} c_w P_w(X_1, ..., X_n)`` over the
Lyndon words ``w`` of length ``j + 1`` (:func:`~nambu_bch.bch.formal.formal_bch`),
each bracket ``P_w`` evaluated once on the concrete fields (memoised, zero
subtrees pruned).  This is the second, independent route to the object that
:func:`~nambu_bch.bch.backward.effective_field` computes by backward error
analysis; both return an :class:`~nambu_bch.bch.backward.EffectiveField`.

References
----------
Horikoshi, Eqs. (eL1), (BCH1), (eL2), (BCH2); Hairer, Lubich, Wanner,
*Geometric Numerical Integration*, Sect. IX.4 (modified equations of splitting
methods via BCH).
"""

from __future__ import annotations

import weakref

from sympy.polys.domains import QQ

from ..algebra import VectorField
from ..algebra.backend import field_backend
from ..integrators.composition import composition_for
from .backward import H, EffectiveField, check_order, effective_field
from .evaluation import BracketEvaluator
from .formal import clear_cache as clear_formal_cache
from .formal import formal_bch


def effective_field_bch(splitting, comp, order: int = 2, fast: bool = True) -> EffectiveField:
    """``X_eff`` of ``comp`` on ``splitting`` through ``h**order`` from the formal BCH series.

    Parameters
    ----------
    splitting : Splitting
    comp : Composition or word (``"12321"``, ``"lie-trotter"``, ...)
    order : int
        Highest power of ``h`` kept (``Z_0 .. Z_order``; the series is needed to degree ``order + 1``).
    fast : bool
        Evaluate brackets in Laurent polynomials in the parameters over QQ when the
        fields allow it (:func:`nambu_bch.algebra.backend.field_backend`); ``False``
        uses the system's ring over ``QQ(parameters)``.  Non-polynomial fields run
        in expanded sympy expressions either way.

    Returns
    -------
    EffectiveField
        Same type, algebra and values as :func:`~nambu_bch.bch.backward.effective_field`.

    Examples
    --------
    >>> from nambu_bch import model
    >>> X = effective_field_bch(model("ho").splitting, "121", order=2)
    >>> X[2].to_sympy()    # Eq. (SHPV1)
    (-omega**2*x2/(12*m), -m*omega**4*x1/6)
    """
    order = check_order(order)
    comp = composition_for(comp, splitting)
    algebra = splitting.system.algebra.with_constants(H, extension=comp.extension)
    series = formal_bch(comp, order + 1)
    backend, evaluator = _evaluator(splitting, algebra, comp.extension, fast)
    Z = []
    for j in range(order + 1):
        if series.domain == QQ or series.domain == backend.domain:
            den, pairs = series.scaled_terms(j + 1)
            values = [(c, evaluator.value(tree)) for c, tree in pairs]
            Z.append(backend.scaled_combine(den, [(c, X) for c, X in values if X is not None]))
            continue
        values = [(c, evaluator.value(tree)) for c, tree in series.terms(j + 1)]
        Z.append(backend.combine([(c, X) for c, X in values if X is not None]))
    return EffectiveField(tuple(Z), order, comp, splitting)


def effective_field_by_cost(splitting, comp, order: int = 2) -> EffectiveField:
    """``X_eff`` through ``h**order`` by the cheaper of the two exact routes (the same field either way).

    Algebraic coefficients (``yoshida:*``, ``2^(1/3)``) go to backward error analysis
    (:func:`~nambu_bch.bch.backward.effective_field`): the formal series would run in the
    dense engine with field elements of ``QQ(2^(1/3))`` on all ``g^d`` words and evaluate
    thousands of brackets with algebraic coefficients (ho3 ``yoshida:12321`` to
    ``h^8`` over 100 s by BCH, 0.45 s backward).  Rational compositions take backward error analysis
    too when it needs fewer Lie derivatives than the BCH route has Lyndon brackets (:func:`_backward_cheaper`:
    five-stage words in three pieces from ``h^4`` on); short series in two pieces keep the BCH route
    (:func:`effective_field_bch`), whose Lyndon brackets are shared across compositions.

    Examples
    --------
    >>> from nambu_bch import model
    >>> S = model("ho").splitting
    >>> effective_field_by_cost(S, "yoshida:121", 2)[2] == effective_field_bch(S, "yoshida:121", 2)[2]
    True
    """
    comp = composition_for(comp, splitting)
    if comp.extension or _backward_cheaper(comp, order):
        return effective_field(splitting, comp, order)
    return effective_field_bch(splitting, comp, order)


def _backward_cheaper(comp, order: int) -> bool:
    """Backward error analysis needs fewer Lie derivatives than the BCH route has brackets to evaluate.

    Per coordinate, backward error analysis applies a field to a function about ``s t (t + 1) / 2`` times
    for the ``s`` exact sub-flows (Lie series to ``h^t``, ``t = order + 1``) and ``t^3 / 6`` times for
    the modified field; the BCH route evaluates one bracket, about two such applications per coordinate,
    per Lyndon word of length ``2 .. t`` in the ``g`` distinct pieces, ``sum_d dim L_d(g)`` (Witt's formula),
    which grows like ``g^t / t``.  Short series in two pieces stay on the BCH route (FPU at ``h^6``: 0.07 s
    against 0.19 s backward); three or more pieces at high order go backward (ho3, 12321, ``h^12``: 4.9 s
    and 300 MB by BCH, 0.02 s backward; the N = 4 single split, 1234321, ``h^8``: 33 s and 1.5 GB by BCH,
    1.2 s and 80 MB backward; measured under load 10, docs/performance.md).
    """
    from .lyndon import witt_dimension

    top, letters = order + 1, len(set(comp.pieces))
    brackets = sum(witt_dimension(letters, d) for d in range(2, top + 1))
    return len(comp.pieces) * top * (top + 1) / 2 + top**3 / 6 < 2 * brackets


# Bracket values are shared by every composition on a splitting (the Lyndon trees of the six paper
# words are the same trees with other coefficients), so evaluators live as long as the splitting.
_EVALUATORS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _evaluator(splitting, algebra, extension, fast):
    """``(backend, BracketEvaluator)`` for ``splitting``, cached per extension and mode."""
    per_splitting = _EVALUATORS.setdefault(splitting, {})
    key = (tuple(extension), bool(fast))
    if key not in per_splitting:
        pieces = {p.number: p.field for p in splitting.pieces}
        if extension:
            pieces = {k: VectorField(algebra, X.to_sympy()) for k, X in pieces.items()}
        backend = field_backend(algebra, pieces, laurent=fast)
        per_splitting[key] = (backend, BracketEvaluator(backend.fields, backend.bracket, backend.is_zero))
    return per_splitting[key]


def clear_cache() -> None:
    """Forget memoised bracket values and associative logs (benchmarks call this between timed runs)."""
    _EVALUATORS.clear()
    clear_formal_cache()

