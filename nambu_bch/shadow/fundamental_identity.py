"""The fundamental identity: commutators of Liouville fields as sums of Liouville terms (Eqs. CL2a-2BY).

For ``N = 3`` the fundamental identity
``{{f,E,F},C,D} = {{f,C,D},E,F} + {f,{E,C,D},F} + {f,E,{F,C,D}}`` turns the
commutator ``[X_{C,D}, X_{E,F}] f = {{f,E,F},C,D} - {{f,C,D},E,F}`` (Eq. CL2)
into a sum of Liouville terms in two ways, depending on the term it is used for:

* way ``a`` (Eq. CL2a): ``[X_{C,D}, X_{E,F}] = X_{{E,C,D},F} + X_{E,{F,C,D}}``,
* way ``b`` (Eq. CL2b): ``[X_{C,D}, X_{E,F}] = -X_{{C,E,F},D} - X_{C,{D,E,F}}``.

For general ``N`` (slots ``L = (L_1..L_{N-1})``, ``R = (R_1..R_{N-1})``) way
``a`` replaces each slot ``R_j`` by ``{R_j, L_1..L_{N-1}}`` in turn and sums;
way ``b`` does the same to ``L`` with ``R`` and a minus sign.  For ``N = 2``
both ways give Eq. (CL1), ``[X_A, X_B] = X_{{B,A}}`` (the Jacobi identity).

A double commutator ``[X_{A,B}, [X_{C,D}, X_{E,F}]]`` needs three uses: one
for the inner commutator (``1`` = way a, ``2`` = way b) and one for each of
the two resulting commutators with ``X_{A,B}`` (``A``/``B`` for the first,
``X``/``Y`` for the second, each ``a``/``b``): the ``2^3 = 8``
representations of Eqs. (1AX)-(2BY), labelled as in the paper.  For general
``N`` there are ``2 * 2^(N-1)`` labels ``"1" + "ab..."``.

References
----------
Horikoshi, Eqs. (CL1), (CL2), (CL2a), (CL2b), (CL3), (CL4), (1AX)-(2BY);
Takhtajan, Commun. Math. Phys. 160 (1994) 295 (the fundamental identity).
"""

from __future__ import annotations

from itertools import product

import sympy
from sympy.polys.rings import PolyElement

from ..algebra import PolynomialAlgebra, nambu_bracket
from ..checks import check_sequence, check_type, show
from ..errors import NambuBCHError
from ..parsing import as_expression
from .liouville_terms import LiouvilleTerm

#: The paper's labels of the eight representations of a double commutator (N = 3), Eqs. (1AX)-(2BY).
FI_LABELS = ("1AX", "1AY", "1BX", "1BY", "2AX", "2AY", "2BX", "2BY")


_MEMO: dict = {}


def _bracket(algebra, *fs):
    # ring elements stay ring elements (fast nesting) and are memoised: the eight representations
    # share most inner brackets; anything else is a sympy expression, computed afresh
    if all(isinstance(f, PolyElement) for f in fs):
        key = (algebra.ring, fs)
        if key not in _MEMO:
            if len(_MEMO) > 100000:
                _MEMO.clear()
            _MEMO[key] = nambu_bracket(algebra, *fs)
        return _MEMO[key]
    return nambu_bracket(algebra, *fs)


def _commutator(left, right, way: str, bracket) -> list:
    """``[X_left, X_right]`` as ``[(sign, slots), ...]`` by the fundamental identity used ``way`` (Eqs. CL2a, CL2b).

    ``bracket(f, g1, ..., g_{N-1})`` computes the Nambu bracket ``{f, g1, ...}``: the
    algebra's bracket for :func:`commutator_terms`, the paper's notation ``"{E,C,D}"``
    for :func:`formal_form` (one implementation of the identity for both).
    """
    if way == "a":
        base, other, sign = right, left, 1
    elif way == "b":
        base, other, sign = left, right, -1
    else:
        raise NambuBCHError(f"way must be 'a' (Eq. CL2a) or 'b' (Eq. CL2b), got {show(way)}")
    out = []
    for j in range(len(base)):
        slots = list(base)
        slots[j] = bracket(base[j], *other)
        out.append((sign, tuple(slots)))
    return out


def _double(a, b, c, label: str, bracket) -> list:
    """``[X_a, [X_b, X_c]]`` as ``[(sign, slots), ...]`` in representation ``label`` (Eqs. 1AX-2BY)."""
    inner, outer = _ways(label, len(a))
    out = []
    for (s1, slots), way in zip(_commutator(b, c, inner, bracket), outer):
        out.extend((s1 * s2, t) for s2, t in _commutator(a, slots, way, bracket))
    return out


def _slots(algebra, *fields) -> list:
    """The slot tuples of Liouville fields on ``algebra``, each ``N - 1`` functions, else one line naming the argument."""
    check_type(algebra, PolynomialAlgebra, "algebra")
    return [check_sequence(slots, what, "functions", length=algebra.n - 1) for what, slots in fields]


def commutator_terms(algebra, left, right, way: str, coefficient=1) -> list:
    """``coefficient * [X_left, X_right]`` as Liouville terms by the fundamental identity used ``way`` (``"a"``/``"b"``).

    Parameters
    ----------
    algebra : PolynomialAlgebra   (general sympy expressions are accepted in the slots)
    left, right : tuples of ``N - 1`` functions (the slots of the two fields)
    way : ``"a"`` (Eq. CL2a) or ``"b"`` (Eq. CL2b)

    Returns
    -------
    list of LiouvilleTerm

    Examples
    --------
    >>> import sympy
    >>> from nambu_bch.algebra import PolynomialAlgebra
    >>> x = sympy.symbols("x1:4"); alg = PolynomialAlgebra(x)
    >>> [str(t) for t in commutator_terms(alg, (x[1], x[2]), (x[0]**2, x[2]), "a")]
    ['X_{2*x1, x3}', 'X_{x1**2, 0}']
    """
    left, right = _slots(algebra, ("left", left), ("right", right))
    c = as_expression(coefficient, algebra.symbol_table, "coefficient")
    pairs = _commutator(left, right, way, lambda *fs: _bracket(algebra, *fs))
    return [LiouvilleTerm(slots, sign * c) for sign, slots in pairs]


def labels(n_slots: int) -> tuple:
    """The representation labels of a double commutator with ``n_slots`` slots per field (``FI_LABELS`` for 2)."""
    if n_slots == 2:
        return FI_LABELS
    return tuple(inner + "".join(rest) for inner in "12" for rest in product("ab", repeat=n_slots))


def _ways(label: str, n_slots: int):
    inner = {"1": "a", "2": "b"}[label[0]]
    if n_slots == 2 and label in FI_LABELS:
        outer = ("a" if label[1] == "A" else "b", "a" if label[2] == "X" else "b")
    else:
        outer = tuple(label[1:])
    return inner, outer


def double_commutator_terms(algebra, a, b, c, label: str, coefficient=1) -> list:
    """``coefficient * [X_a, [X_b, X_c]]`` as Liouville terms, representation ``label`` (e.g. ``"1AX"``, Eq. 1AX).

    Examples
    --------
    >>> from nambu_bch import model
    >>> S = model("ho3"); alg = S.algebra
    >>> AC, BD = S.splitting[1].terms[0], S.splitting[2].terms[0]
    >>> [str(t) for t in double_commutator_terms(alg, AC, AC, BD, "1AX") if not t.vanishes(alg.coordinates)]   # Eq. (CL5)
    ['X_{m*omega**2*x3/2, -2*x2**2/m**2}']
    """
    a, b, c = _slots(algebra, ("a", a), ("b", b), ("c", c))
    if not isinstance(label, str) or label not in labels(len(a)):
        raise NambuBCHError(f"label must be one of {', '.join(labels(len(a)))}, got {show(label)}")
    c_ = as_expression(coefficient, algebra.symbol_table, "coefficient")
    pairs = _double(a, b, c, label, lambda *fs: _bracket(algebra, *fs))
    return [LiouvilleTerm(slots, sign * c_) for sign, slots in pairs]


def representations(algebra, a, b, c, coefficient=1) -> dict:
    """All ``label -> [LiouvilleTerm, ...]`` representations of ``coefficient * [X_a, [X_b, X_c]]``."""
    a, b, c = _slots(algebra, ("a", a), ("b", b), ("c", c))  # before the 2^(N-1) labels are listed
    return {lab: double_commutator_terms(algebra, a, b, c, lab, coefficient) for lab in labels(len(a))}


def single_representations(algebra, b, c, coefficient=1) -> dict:
    """``{"a": Eq. CL2a terms, "b": Eq. CL2b terms}`` of ``coefficient * [X_b, X_c]``."""
    return {way: commutator_terms(algebra, b, c, way, coefficient) for way in "ab"}


def formal_form(label: str) -> list:
    """``[(sign, (slot1, slot2)), ...]`` of ``[X_{A,B}, [X_{C,D}, X_{E,F}]]`` in representation ``label`` (Eqs. 1AX-2BY).

    The same identity as :func:`double_commutator_terms`, with symbolic functions
    ``A..F`` and slots written in the paper's bracket notation: ``label[0]``: ``1``
    uses the fundamental identity on the first term of Eq. (CL2) (Eq. CL2a), ``2``
    on the second (Eq. CL2b); ``label[1]`` (``A``/``B``) and ``label[2]``
    (``X``/``Y``) make the same choice for Eqs. (CL3) and (CL4).

    >>> [(s, ",".join(t)) for s, t in formal_form("1AX")]     # Eq. (1AX)
    [(1, '{{E,C,D},A,B},F'), (1, '{E,C,D},{F,A,B}'), (1, '{E,A,B},{F,C,D}'), (1, 'E,{{F,C,D},A,B}')]
    """
    if label not in FI_LABELS:
        raise ValueError(f"FI label must be one of 1AX..2BY, got {label!r}")
    return _double(("A", "B"), ("C", "D"), ("E", "F"), label, lambda *fs: "{" + ",".join(fs) + "}")


def bch_double_commutators(system, comp) -> list:
    """``[(coefficient, (a, b, c), {label: [LiouvilleTerm, ...]})]`` for each non-zero ``h^2`` double commutator.

    The degree-3 part of the formal BCH series of ``comp`` (Eq. BCH2) is expanded
    into Liouville terms on the system's splitting with vanishing brackets pruned
    (Eqs. BCH3, BCH4); each ``[[a, b], c]`` is rewritten ``-[c, [a, b]]``, and each
    ``[X_a, [X_b, X_c]]`` is represented in the eight ways of Eqs. (1AX)-(2BY),
    vanishing Liouville terms dropped (as in Eqs. CL5-CL8).

    >>> from nambu_bch import model, composition
    >>> [(c, lab) for c, _, forms in bch_double_commutators(model("ho3"), composition("12321"))
    ...  for lab, terms in forms.items() if lab == "1AX"][:1]
    [(-1/24, '1AX')]
    """
    from ..bch import expand_terms, formal_bch
    from ..bch.lyndon import is_bracket

    out = []
    for c, tree in expand_terms(formal_bch(comp, 3).terms(3), system.splitting):
        if is_bracket(tree[1]):
            a, (b, d) = tree[0], tree[1]
        else:  # [[a, b], d] = -[d, [a, b]]
            (a, b), d, c = tree[0], tree[1], -c
            a, b, d = d, a, b
        reps = {}
        for label in labels(len(a)):
            terms = double_commutator_terms(system.algebra, a, b, d, label, c)
            reps[label] = [t for t in terms if not t.vanishes(system.coordinates)]
        out.append((c, (a, b, d), reps))
    return out
