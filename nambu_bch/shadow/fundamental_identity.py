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

from ..algebra import nambu_bracket
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
    left, right = tuple(left), tuple(right)
    if way == "a":
        base, other, sign = right, left, 1
    elif way == "b":
        base, other, sign = left, right, -1
    else:
        raise ValueError(f"way must be 'a' (Eq. CL2a) or 'b' (Eq. CL2b), got {way!r}")
    out = []
    for j in range(len(base)):
        slots = list(base)
        slots[j] = _bracket(algebra, base[j], *other)
        out.append(LiouvilleTerm(tuple(slots), sign * sympy.sympify(coefficient)))
    return out


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
    n_slots = len(a)
    inner, outer = _ways(label, n_slots)
    out = []
    for term, way in zip(commutator_terms(algebra, b, c, inner, coefficient), outer):
        out.extend(commutator_terms(algebra, a, term.slots, way, term.coefficient))
    return out


def representations(algebra, a, b, c, coefficient=1) -> dict:
    """All ``label -> [LiouvilleTerm, ...]`` representations of ``coefficient * [X_a, [X_b, X_c]]``."""
    return {lab: double_commutator_terms(algebra, a, b, c, lab, coefficient) for lab in labels(len(a))}


def single_representations(algebra, b, c, coefficient=1) -> dict:
    """``{"a": Eq. CL2a terms, "b": Eq. CL2b terms}`` of ``coefficient * [X_b, X_c]``."""
    return {way: commutator_terms(algebra, b, c, way, coefficient) for way in "ab"}
