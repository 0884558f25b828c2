"""FI representations of nested commutators of any depth: their affine hull, built recursively.

A BCH term at ``h^j`` is a bracket tree of depth ``j`` whose leaves are Liouville
terms ``X_{A,C}`` (Eq. BCH3).  Every commutator ``[X_L, X_R]`` of two Liouville
terms has the two representations of Eqs. (CL2a)/(CL2b)

    a(L, R) = sum_j X_{R_1, .., {R_j, L_1..L_{N-1}}, .., R_{N-1}},
    b(L, R) = - sum_j X_{L_1, .., {L_j, R_1..R_{N-1}}, .., L_{N-1}},

so a tree ``[T_1, T_2]`` whose subtrees are represented by formal sums
``r_1 = sum_t c_t X_t`` and ``r_2 = sum_u c'_u X_u`` is represented by
``sum_{t,u} c_t c'_u w_{tu}(t, u)`` with one choice ``w_{tu}`` in ``{a, b}`` per
pair of terms (Eqs. 1AX-2BY are the ``2^3`` choices for ``[a,[b,c]]``; a
right-nested depth-4 bracket has ``1 + 2 + 4 + 8 = 15`` choice points).  Rather
than enumerate the ``2^15`` labelled representations, we build the *affine
hull* ``Aff(T) = p_T + span(D_T)`` of all of them recursively.  ``a`` and ``b``
are bilinear in the formal sums, so with ``S_i`` the union of the supports of
the members of ``Aff(T_i)``:

    p_[T1,T2] = a(p_1, p_2),
    D_[T1,T2] = { a(d, p_2), a(p_1, e), a(d, e) : d in D_1, e in D_2 }
                  u { (b - a)(t, u) : t in S_1, u in S_2 },

(``a(r_1, r_2) - a(p_1, p_2) = a(d, p_2) + a(p_1, e) + a(d, e)`` for
``r_i = p_i + d``, ``e``; a flip of one pair changes a member by
``c_t c'_u (b - a)(t, u)``), reduced to a basis at every level (exact echelon
form), each kept direction with the label of the choices that give it.

The formal sums of this recursion ("raw" sums) are taken modulo multilinearity
and antisymmetry only, with slots expanded into monomials except the Hamiltonian
pieces (atoms), which stay whole as in the paper's bookkeeping; the vanishing
rule is *not* applied inside the recursion (a term ``X_{P,Q}`` that vanishes as
a field still has non-vanishing FI images), only at the end
(:meth:`RawOps.reduce`, :class:`~nambu_bch.shadow.liouville_terms.LiouvilleSum`).
Choices are made per pair of *monomial* Liouville terms of the raw sums; for
systems whose pieces are monomials (ho3, the rigid body, Lotka-Volterra) this
is the paper's per-term choice, equal terms merged.

References
----------
Horikoshi, Eqs. (BCH3), (CL2), (CL2a), (CL2b), (1AX)-(2BY), (CL5)-(CL8);
Takhtajan, Commun. Math. Phys. 160 (1994) 295 (the fundamental identity).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy

from ..algebra.brackets import permutation_sign
from ..algebra.elimination import Echelon  # noqa: F401  (used here; imported from here by tests)
from ..bch.lyndon import is_bracket
from ..errors import NambuBCHError
from .fundamental_identity import _bracket
from .liouville_terms import LiouvilleSum, _atom_id, _ATOMS, _context

#: Refuse a bracket whose hull needs more candidate directions than this (bounded work).
MAX_PAIRS = 200_000


def _canonical(entries):
    """``(sign, sorted entries)`` by antisymmetry; ``(0, None)`` for a repeated entry."""
    if len(set(entries)) < len(entries):
        return 0, None
    order = sorted(range(len(entries)), key=lambda i: entries[i])
    return permutation_sign(order), tuple(entries[i] for i in order)


def _content_order(key):
    """A sort key of a raw term by content (atoms by their expression, not by registration order)."""
    return tuple((kind, v) if kind == 0 else (kind, str(_ATOMS[v])) for kind, v in key)


class RawOps:
    """Raw formal sums (multilinearity and antisymmetry only) and the two FI maps on them, memoised.

    Entries are ``(0, exponents)`` for a monomial and ``(1, atom id)`` for a
    Hamiltonian piece kept whole (the entries of
    :class:`~nambu_bch.shadow.liouville_terms.LiouvilleSum`); a raw sum is a
    dict ``{sorted entries: coefficient}`` with coefficients in the algebra's domain.
    """

    def __init__(self, algebra, atoms):
        self.algebra, self.atoms = algebra, tuple(atoms)
        self.n = algebra.n
        self.domain = algebra.domain
        self.context = _context(algebra, self.atoms)
        self._poly: dict = {}
        self._ways: dict = {}
        self._leaves: dict = {}
        self._coefficients: dict = {}
        self._exprs: dict = {}
        self.hulls: dict = {}  # tree -> NestedHull, for callers that share hulls between words
        self._ring_atoms = {algebra.convert(a): _atom_id(sympy.sympify(a, strict=True)) for a in self.atoms}

    def poly(self, entry):
        if entry not in self._poly:
            kind, v = entry
            alg = self.algebra
            if kind == 1:
                self._poly[entry] = alg.convert(_ATOMS[v])
            else:
                self._poly[entry] = alg.ring.from_dict({tuple(v) + (0,) * (len(alg.ring.gens) - self.n): self.domain.one})
        return self._poly[entry]

    def poly_of(self, expr):
        """A slot function (sympy or ring element) as a ring element, memoised."""
        if expr not in self._exprs:
            self._exprs[expr] = self.algebra.convert(expr)
        return self._exprs[expr]

    def monomials(self, p):
        """``[(entry, coefficient)]`` of a ring element (monomial entries)."""
        out = []
        for mon, c in p.items():
            if any(mon[self.n:]):
                raise NambuBCHError(f"formal Liouville sums need slots free of {self.algebra.constants}, got {p}")
            out.append(((0, tuple(mon[: self.n])), c))
        return out

    def from_slots(self, slots, coefficient=None) -> dict:
        """``coefficient * X_{slots}`` expanded: slots equal to an atom stay whole, others into monomials."""
        alg = self.algebra
        expanded = []
        for s in slots:
            p = alg.convert(s)
            if not alg.is_polynomial(p):
                raise NambuBCHError(f"formal Liouville sums need polynomial slots, got {s}")
            if p in self._ring_atoms:
                expanded.append([((1, self._ring_atoms[p]), self.domain.one)])
            else:
                expanded.append(self.monomials(p))
        return self.from_expanded(expanded, coefficient)

    def coefficient(self, c):
        """A number or sympy constant as an element of the coefficient domain (memoised)."""
        if c not in self._coefficients:
            self._coefficients[c] = self.domain.from_sympy(sympy.sympify(c, strict=True))
        return self._coefficients[c]

    def from_expanded(self, expanded, coefficient=None) -> dict:
        """``coefficient * X_{s_1..}`` for slots given as ``[(entry, coefficient), ...]`` each (multilinear expansion)."""
        out: dict = {}
        coeff = self.domain.one if coefficient is None else coefficient

        def walk(i, entries, c):
            if i == len(expanded):
                sign, key = _canonical(entries)
                if sign:
                    out[key] = out.get(key, self.domain.zero) + sign * c
                return
            for e, ce in expanded[i]:
                walk(i + 1, entries + (e,), c * ce)

        walk(0, (), coeff)
        return {k: v for k, v in out.items() if v}

    def leaf(self, term) -> dict:
        if term not in self._leaves:
            self._leaves[term] = self.from_slots(term)
        return self._leaves[term]

    def way(self, left, right, way: str) -> dict:
        """``[X_left, X_right]`` for unit raw terms by Eq. (CL2a) (``"a"``) or (CL2b) (``"b"``)."""
        key = (left, right, way)
        if key in self._ways:
            return self._ways[key]
        base, other, sign = (right, left, 1) if way == "a" else (left, right, -1)
        others = [self.poly(e) for e in other]
        out: dict = {}
        for j in range(len(base)):
            br = _bracket(self.algebra, self.poly(base[j]), *others)
            for e, c in self.monomials(br):
                s, k = _canonical(base[:j] + (e,) + base[j + 1:])
                if s:
                    out[k] = out.get(k, self.domain.zero) + s * sign * c
        out = {k: v for k, v in out.items() if v}
        self._ways[key] = out
        return out

    def apply(self, P: dict, Q: dict, way: str = "a") -> dict:
        """The bilinear extension of :meth:`way` to raw sums."""
        out: dict = {}
        for k1, c1 in P.items():
            for k2, c2 in Q.items():
                c = c1 * c2
                for k, v in self.way(k1, k2, way).items():
                    out[k] = out.get(k, self.domain.zero) + c * v
        return {k: v for k, v in out.items() if v}

    def flip(self, t, u) -> dict:
        """``(b - a)(t, u)``: the change of a representation when the pair ``(t, u)`` is switched to Eq. (CL2b)."""
        out = dict(self.way(t, u, "b"))
        for k, v in self.way(t, u, "a").items():
            out[k] = out.get(k, self.domain.zero) - v
        return {k: v for k, v in out.items() if v}

    def slot(self, entry) -> sympy.Expr:
        """The function of an entry: the atom, or the monomial ``x^a``."""
        kind, v = entry
        if kind == 1:
            return _ATOMS[v]
        return sympy.Mul(*(x**e for x, e in zip(self.algebra.coordinates, v)))

    def items(self, raw: dict, coefficient=None) -> list:
        """``[(sympy coefficient, (slot functions...)), ...]`` of a raw sum, in key order."""
        to = self.domain.to_sympy
        c0 = sympy.Integer(1) if coefficient is None else sympy.sympify(coefficient, strict=True)
        out = []
        for k in sorted(raw, key=lambda key: sorted(_content_order(key))):
            order = sorted(range(len(k)), key=lambda i: _content_order((k[i],)))  # slots by content, sign kept
            out.append((permutation_sign(order) * c0 * to(raw[k]), tuple(self.slot(k[i]) for i in order)))
        return out

    def to_text(self, raw: dict, coefficient=None) -> str:
        parts = [f"({c})*X_{{{', '.join(map(str, slots))}}}" for c, slots in self.items(raw, coefficient)]
        return " + ".join(parts) if parts else "0"

    def to_latex(self, raw: dict, coefficient=None) -> str:
        parts = [rf"\left({sympy.latex(c)}\right) X_{{{', '.join(sympy.latex(x) for x in slots)}}}"
                 for c, slots in self.items(raw, coefficient)]
        return " + ".join(parts) if parts else "0"

    def reduce(self, raw: dict, coefficient=None) -> LiouvilleSum:
        """The raw sum as a :class:`LiouvilleSum` (vanishing rule applied)."""
        terms: dict = {}
        c0 = self.domain.one if coefficient is None else coefficient
        for entries, c in raw.items():
            sign, key = self.context.key(entries)
            if sign:
                terms[key] = terms.get(key, self.domain.zero) + sign * c * c0
        return LiouvilleSum._trusted(self.algebra, terms, self.atoms)  # canonical keys from the context


@dataclass
class NestedHull:
    """The affine hull ``base + span(directions)`` of the FI representations of one bracket tree.

    ``directions`` are ``(label, raw sum)``; a label records the choices: ``L<x>``/``R<x>``
    (the left/right subtree moved along its direction ``x``), ``L<x>R<y>`` (both), and
    ``b<i>.<j>`` (the pair of the ``i``-th term of the left subtree's terms and the ``j``-th of
    the right one's, in their sorted supports, switched from Eq. CL2a to Eq. CL2b); the
    base is Eq. (CL2a) at every pair.
    """

    tree: object
    base: dict
    directions: list = field(default_factory=list)
    support: tuple = ()

    @property
    def dimension(self) -> int:
        return len(self.directions)


def nested_hull(ops: RawOps, tree, memo: dict | None = None) -> NestedHull:
    """The affine hull of all FI representations of ``tree`` (leaves: Liouville terms), recursively.

    Parameters
    ----------
    ops : RawOps
    tree : a Liouville term (tuple of slots) or a pair ``(left, right)`` of trees
    memo : dict, optional -- hulls of subtrees already built (shared between the BCH terms)

    Returns
    -------
    NestedHull

    Examples
    --------
    >>> from nambu_bch import model
    >>> S = model("ho3"); AC, BD = S.splitting[1].terms[0], S.splitting[2].terms[0]
    >>> ops = RawOps(S.algebra, (AC[0], BD[0], AC[1], BD[1]))
    >>> H = nested_hull(ops, (AC, (AC, BD)))    # Eq. (CL5): the eight forms 1AX..2BY span a line
    >>> H.dimension, [label for label, _ in H.directions]
    (1, ['b0.0'])
    """
    memo = {} if memo is None else memo
    if tree in memo:
        return memo[tree]
    if not is_bracket(tree):
        raw = ops.leaf(tuple(tree))
        out = NestedHull(tree, raw, [], tuple(sorted(raw, key=_content_order)))
        memo[tree] = out
        return out
    H1, H2 = nested_hull(ops, tree[0], memo), nested_hull(ops, tree[1], memo)
    work = len(H1.support) * len(H2.support) + (len(H1.directions) + 1) * (len(H2.directions) + 1)
    if work > MAX_PAIRS:
        raise NambuBCHError(f"the FI hull of a bracket of depth {_depth(tree)} needs {work} candidate directions "
                            f"(more than {MAX_PAIRS}); use route='direct'")
    base = ops.apply(H1.base, H2.base)
    ech = Echelon(ops.domain)
    dirs = []

    def offer(label, vec):
        if vec and ech.insert(vec):
            dirs.append((label, vec))

    for i, t in enumerate(H1.support):
        for j, u in enumerate(H2.support):
            offer(f"b{i}.{j}", ops.flip(t, u))
    for lab, d in H1.directions:
        offer(f"L<{lab}>", ops.apply(d, H2.base))
    for lab, e in H2.directions:
        offer(f"R<{lab}>", ops.apply(H1.base, e))
    for lab, d in H1.directions:
        for lab2, e in H2.directions:
            offer(f"L<{lab}>R<{lab2}>", ops.apply(d, e))
    support = set(base)
    for _, d in dirs:
        support.update(d)
    out = NestedHull(tree, base, dirs, tuple(sorted(support, key=_content_order)))
    memo[tree] = out
    return out


def _depth(tree) -> int:
    return 1 + max(_depth(tree[0]), _depth(tree[1])) if is_bracket(tree) else 0
