"""The polynomial ansatz of the exact linear solves: unknowns, column and row interning, the canonical members.

Three searches reduce to a linear system over ``K = QQ(parameters)`` whose
unknowns are the coefficients of polynomials (:mod:`nambu_bch.algebra.elimination`
eliminates it):

* the direct route, ``X_{dH_j,G} + X_{H,dG_j} = Z_j - (cross terms)`` order by order
  (Horikoshi Sect. 4.2, Eqs. L2, BCH5; :mod:`nambu_bch.shadow.direct_route`);
* the FI route, the same target against the affine hulls of the fundamental-identity
  representations (Sect. 4.2, 5.2; :mod:`nambu_bch.shadow.fi_route`);
* the invariant search, ``I(Phi_h(x)) = I(x)`` (Sect. 5.3, Table (table);
  :mod:`nambu_bch.exact.invariants`).

An :class:`Ansatz` is the list of unknowns

    dH^a = sum_{mu in M} c_{a,mu} x^mu,    a = 0 .. slots - 1,    M = {mu : lowest <= |mu| <= degree},

one *column* per pair ``(a, mu)``, slot-major, the monomials ``M`` in one of two
fixed orders:

* ``"lex"`` (the shadow routes): lexicographic with ``x_N`` the most significant
  exponent, descending (``x3^2, x2 x3, x1 x3, x3, x2^2, ...``, the constant last);
* ``"graded"`` (the invariant search): ascending total degree, within a degree
  lexicographic with ``x_1`` the most significant exponent, descending.

The rows of a system (the coordinates of an equation: component and monomial of a
vector field, a formal Liouville term, a monomial of an image) are interned by
:class:`Rows`, in order of first appearance.

The canonical members (one rule).  The solutions of one order form an affine
space ``p + ker L``; the kernel is the gauge (``(d psi/dG, -d psi/dH)`` for every
``psi(H, G)``, and whatever else the system allows), so a member is fixed by a
rule.  The package's rule is the normal form of ``p`` modulo ``ker L`` for a
column priority (:func:`~nambu_bch.algebra.elimination.normal_form`: the unique
solution vanishing on the greedily first priority columns the kernel can clear),
with the priority (:meth:`Ansatz.priority`)

1. the constant of every slot,
2. slot by slot, in ``slot_order``: the monomials of that slot's Hamiltonian
   ``H^a`` (in the ansatz order), then the slot's other monomials,
3. the unknowns outside the ansatz (the FI route's weights) last.

The ``alpha = 0`` member takes ``slot_order = 0, 1, ..`` (the corrections of ``H``
cleared first: "everything in ``G_S``"), the ``alpha = 1`` member the reverse, and
the family is ``(1 - alpha) member_0 + alpha member_1`` (Eq. Xeff3 generalised;
for ``ho3`` and ``12321`` Eqs. SH12321a-SH12321c).  :meth:`Ansatz.solve_canonical`
gets the same member in one elimination (the columns in reverse priority, so the
free columns, set to zero, are the cleared ones); :meth:`Ansatz.canonical` reduces a
given solution.  The invariant search has no affine family (its solutions are a
vector space of invariants): it uses the monomials and the rows only, and picks
the invariant tending to ``H`` by its own target rule (Eqs. CQPV, CQ12321H, Table
(table); :mod:`nambu_bch.exact.invariants`), which keeps the paper's ``H_c, G_c``
with ``X_eff = F(omega h) X_{H_c,G_c}`` (Eq. Xeff2).

References
----------
Horikoshi, Sect. 4.2 (Eq. L2), Sect. 5.2 (Eq. BCH5), Sect. 5.3 (Eqs. Xeff2, Xeff3,
SH12321a-SH12321c, Table (table)); Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, Sect. IX.3 (modified Hamiltonians order by order).

Examples
--------
>>> A = Ansatz(n=2, degree=2, slots=2)
>>> A.monomials
((0, 2), (1, 1), (0, 1), (2, 0), (1, 0), (0, 0))
>>> A.columns[6], A.index[(1, (0, 0))], len(A)
((1, (0, 2)), 11, 12)
>>> A.priority([[(2, 0)], [(0, 2)]], (0, 1))        # constants, then H^0's x1^2, the rest of slot 0, then slot 1
[5, 11, 3, 0, 1, 2, 4, 6, 7, 8, 9, 10]
>>> Ansatz(n=3, degree=2, lowest=1, order="graded").monomials[3:]
((2, 0, 0), (1, 1, 0), (1, 0, 1), (0, 2, 0), (0, 1, 1), (0, 0, 2))
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property
from itertools import combinations_with_replacement

import sympy

from ..checks import is_int
from ..errors import NambuBCHError, ResourceLimitError
from . import elimination, frac_rref
from .elimination import SparseMatrix, normal_form, solve_affine

#: The monomial orders of :class:`Ansatz`.
ORDERS = ("lex", "graded")
#: Most columns an :class:`Ansatz` builds (callers refuse far smaller ansatze with their own limits).
MAX_COLUMNS = 1_000_000


def _lex_key(e):
    return tuple(-k for k in reversed(e))


def _graded_key(e):
    return sum(e), tuple(-k for k in e)


@dataclass(frozen=True)
class Ansatz:
    """Unknown polynomials ``sum_mu c_{a,mu} x^mu`` in ``slots`` slots, ``lowest <= |mu| <= degree``.

    Parameters
    ----------
    n : int -- number of coordinates
    degree : int -- highest total degree
    slots : int -- number of unknown polynomials (``N - 1`` Hamiltonian corrections, 1 for an invariant)
    lowest : int -- lowest total degree (0; the invariant search leaves the constants out: 1)
    order : ``"lex"`` or ``"graded"`` -- the monomial order (module docstring)

    Attributes
    ----------
    monomials : tuple of exponent tuples, in the ansatz order
    columns : tuple of ``(slot, exponent tuple)``, slot-major
    index : dict ``(slot, exponent tuple) -> column``

    Raises
    ------
    NambuBCHError on a non-integer or negative size, an unknown order; ResourceLimitError above
    :data:`MAX_COLUMNS` columns (refused before any monomial is built).
    """

    n: int
    degree: int
    slots: int = 1
    lowest: int = 0
    order: str = "lex"

    def __post_init__(self):
        for name, value, low in (("n", self.n, 1), ("degree", self.degree, 0), ("slots", self.slots, 1),
                                 ("lowest", self.lowest, 0)):
            if not is_int(value, low):
                raise NambuBCHError(f"Ansatz {name} must be an integer >= {low}, got {value!r}")
        if self.lowest > self.degree:
            raise NambuBCHError(f"Ansatz lowest degree {self.lowest} exceeds its degree {self.degree}")
        if self.order not in ORDERS:
            raise NambuBCHError(f"Ansatz order must be one of {ORDERS}, got {self.order!r}")
        size = self.size(self.n, self.degree, self.slots, self.lowest)
        if size > MAX_COLUMNS:
            raise ResourceLimitError(f"an ansatz of degree {self.degree} in {self.n} coordinates with {self.slots} "
                                     f"slots has {size} unknowns; at most {MAX_COLUMNS} are built")

    @staticmethod
    def size(n: int, degree: int, slots: int = 1, lowest: int = 0) -> int:
        """The number of columns, ``slots * (C(degree + n, n) - C(lowest - 1 + n, n))``, without building them.

        >>> Ansatz.size(3, 2, slots=2), Ansatz.size(3, 2, lowest=1)
        (20, 9)
        """
        below = math.comb(lowest - 1 + n, n) if lowest > 0 else 0
        return slots * (math.comb(degree + n, n) - below)

    # -- columns -----------------------------------------------------------------------
    def key(self, e):
        """The sort key of an exponent tuple in this ansatz's order (ascending keys = the ansatz order)."""
        return _lex_key(e) if self.order == "lex" else _graded_key(e)

    def sort(self, exponents) -> list:
        """Distinct exponent tuples (only the first ``n`` entries kept) in the ansatz order."""
        return sorted({tuple(e[: self.n]) for e in exponents}, key=self.key)

    @cached_property
    def monomials(self) -> tuple:
        found = [tuple(combo.count(i) for i in range(self.n))
                 for d in range(self.lowest, self.degree + 1)
                 for combo in combinations_with_replacement(range(self.n), d)]
        return tuple(sorted(found, key=self.key))

    @cached_property
    def columns(self) -> tuple:
        return tuple((a, e) for a in range(self.slots) for e in self.monomials)

    @cached_property
    def index(self) -> dict:
        return {c: k for k, c in enumerate(self.columns)}

    def __len__(self) -> int:
        return len(self.columns)

    def monomial(self, e, coordinates) -> sympy.Expr:
        """``x^e`` as a sympy expression in ``coordinates``."""
        return sympy.Mul(*(x**k for x, k in zip(coordinates, e)))

    # -- solutions as polynomials ---------------------------------------------------------
    def expressions(self, vector: dict, coordinates, domain, offset: int = 0) -> tuple:
        """``(dH^0, dH^1, ..)`` as sympy expressions from a sparse solution ``{column: value}``.

        Columns below ``offset`` (unknowns outside the ansatz) are ignored; column ``offset + k`` is
        ``columns[k]``.
        """
        terms: list = [[] for _ in range(self.slots)]
        for col, v in vector.items():
            if col >= offset:
                a, e = self.columns[col - offset]
                terms[a].append(domain.to_sympy(v) * self.monomial(e, coordinates))
        return tuple(sympy.Add(*t) for t in terms)  # one Add per slot (a running += re-sorts the sum at every term)

    def polynomials(self, vector: dict, ring, tail=(), offset: int = 0) -> list:
        """``[dH^0, dH^1, ..]`` as elements of ``ring`` (its first ``n`` generators the coordinates; the exponents
        of the further generators are ``tail``, e.g. a power of ``alpha``)."""
        terms = [{} for _ in range(self.slots)]
        for col, v in vector.items():
            if col >= offset:
                a, e = self.columns[col - offset]
                terms[a][tuple(e) + tuple(tail)] = v
        return [ring.from_dict(t) if t else ring.zero for t in terms]

    # -- the canonical members --------------------------------------------------------------
    def slot_orders(self) -> tuple:
        """The slot orders of the ``alpha = 0`` and ``alpha = 1`` members: ``(0, 1, ..)`` and its reverse."""
        return tuple(range(self.slots)), tuple(reversed(range(self.slots)))

    def priority(self, own, slot_order, offset: int = 0, rest=()) -> list:
        """Columns, most important to clear first (module docstring, rule 1-3).

        Parameters
        ----------
        own : sequence, one per slot, of the Hamiltonian's monomials (ring elements or exponent tuples;
            only the first ``n`` exponents count)
        slot_order : sequence of slots
        offset : int -- the ansatz columns are ``offset + k`` in the caller's system
        rest : columns outside the ansatz, appended last (the FI route's weights)
        """
        index = self.index
        zero = (0,) * self.n
        out = [index[(a, zero)] for a in range(self.slots) if (a, zero) in index]
        seen = set(out)
        for a in slot_order:
            mine = [index[(a, e)] for e in self.sort(own[a]) if (a, e) in index]
            for c in mine + [index[(a, e)] for e in self.monomials]:
                if c not in seen:
                    seen.add(c)
                    out.append(c)
        return [offset + c for c in out] + list(rest)

    def priorities(self, own, offset: int = 0, rest=()) -> tuple:
        """The priorities of the ``alpha = 0`` and ``alpha = 1`` members."""
        return tuple(self.priority(own, order, offset, rest) for order in self.slot_orders())

    @staticmethod
    def canonical(vectors, kernel, priority, domain) -> list:
        """The normal forms of solutions ``vectors`` modulo ``span(kernel)`` for ``priority`` (the canonical member)."""
        return [normal_form(v, kernel, priority, domain) for v in vectors]

    @staticmethod
    def member(solution, priority, domain) -> list:
        """The canonical member for ``priority`` from a consistent solution of the same system: the particular
        solutions ``solve_canonical(.., priority).particular`` would give, without a second elimination.

        A canonical member is the normal form of any solution modulo the kernel (module docstring), so the
        particular solutions of one :meth:`solve_canonical` call and its kernel give the member of every other
        priority by reduction against the kernel's echelon form (a few dozen vectors instead of the whole
        system; over ``QQ(params)`` on python-flint's fraction pairs, :func:`~nambu_bch.algebra.frac_rref.normal_forms`).
        The entries of each vector are in :meth:`solve_canonical`'s order (descending position in ``priority``).

        Parameters
        ----------
        solution : AffineSolution -- consistent, its column indices the caller's (a :meth:`solve_canonical` result)
        priority : list -- every column once, most important to clear first
        domain : the coefficient field

        Returns
        -------
        list of dict -- one vector per right-hand side
        """
        if not solution.consistent:
            raise NambuBCHError("an inconsistent system has no canonical member")
        ctx = frac_rref.context(domain) if elimination.FAST_PATHS and elimination.flint_available() else None
        if ctx is not None:
            return frac_rref.normal_forms(solution.particular, solution.kernel, priority, domain, ctx)
        position = {c: i for i, c in enumerate(priority)}
        return [dict(sorted(v.items(), key=lambda cv: -position[cv[0]]))
                for v in Ansatz.canonical(solution.particular, solution.kernel, priority, domain)]

    @staticmethod
    def solve_canonical(columns, rhs, nrows: int, domain, priority, certificate: bool = True):
        """:func:`~nambu_bch.algebra.elimination.solve_affine` whose particular solutions are the canonical member.

        The columns are eliminated in reverse ``priority`` (every column must appear in it), so the
        free columns, set to zero, are the greedily first priority columns the kernel can clear: the
        particular solutions equal :meth:`canonical` of any solution.  Column indices in the result
        (particular, kernel, pivots) are the caller's; certificate rows are unchanged.
        """
        order = list(reversed(priority))
        if sorted(order) != list(range(len(columns))):
            raise NambuBCHError(f"the priority must list each of the {len(columns)} columns once")
        res = solve_affine(SparseMatrix.from_columns([columns[c] for c in order], nrows, domain), rhs, certificate=certificate)

        def back(vec):
            return {order[c]: v for c, v in vec.items()}

        return replace(res, particular=None if res.particular is None else [back(p) for p in res.particular],
                       kernel=[back(k) for k in res.kernel], pivots=tuple(order[p] for p in res.pivots))


class Rows:
    """Row interning of a linear system: equation keys ``-> 0, 1, 2, ..`` in order of first appearance.

    >>> R = Rows()
    >>> R(("w", 0)), R(("k", "x")), R(("w", 0)), len(R), R.keys()
    (0, 1, 0, 2, [('w', 0), ('k', 'x')])
    >>> R.vector({"y": 3, "x": 1}, sign=-1)
    {2: -3, 3: -1}
    """

    __slots__ = ("index",)

    def __init__(self):
        self.index: dict = {}

    def __len__(self) -> int:
        return len(self.index)

    def __call__(self, key) -> int:
        """The row of ``key`` (a new row on first sight)."""
        index = self.index
        if key not in index:
            index[key] = len(index)
        return index[key]

    def vector(self, items, sign: int = 1) -> dict:
        """``{row(key): sign * value}`` of a mapping (or pairs) ``key -> value``."""
        pairs = items.items() if hasattr(items, "items") else items
        return {self(k): (v if sign == 1 else sign * v) for k, v in pairs}

    def field(self, components, n: int) -> dict:
        """The rows of a vector field: key ``(component, exponent tuple[:n])`` for every term of every component."""
        return {self((i, m[:n])): c for i, comp in enumerate(components) for m, c in comp.items()}

    def keys(self) -> list:
        """The keys by row (the inverse map)."""
        return list(self.index)
