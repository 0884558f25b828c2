"""Splitting ``X_{H,G}`` into pieces whose flows are exact.

Full split (Eqs. HGs, X1-X3).  With every Hamiltonian separable,
``H^a = sum_j H^a_j(x_j)``, the Liouville field is a sum of terms
``X_{H^1_{j_1}, ..., H^{N-1}_{j_{N-1}}}`` over distinct indices; such a term
moves only the one coordinate ``i`` not among the ``j``'s, and its velocity
does not depend on ``x_i``.  Grouping the terms by ``i`` gives piece ``i``
(``X_1 = X_{H_2,G_3} + X_{H_3,G_2}`` etc. for N = 3), a *shear* whose exact
flow is ``x_i -> x_i + t X^i`` (Eqs. hX1g-hX3g).  For N = 2 this is
``X_H = X_T + X_V`` (Eq. XTXV): piece 1 = ``X_T`` moves ``x1 = q``.

Single split (the paper's footnote).  Only the first Hamiltonian is split,
``X_{H,G} = sum_i X_{H_i, G}``; piece ``i`` is ``X_{H_i,G}`` for the non-zero
``H_i`` in coordinate order.  Such a piece fixes ``x_i`` and is usually linear
in the coordinates it moves (Lotka-Volterra: exponentials).

References
----------
Horikoshi, Sect. 4.1, Eqs. (HGs), (X1)-(X3) and footnote 1; Modin (2010).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import permutations

import sympy

from ..algebra import VectorField, liouville_field
from ..checks import check_flag, check_type
from .separable import separate


@dataclass(frozen=True, eq=False)
class Piece:
    """One piece ``X_k`` of a splitting.

    Attributes
    ----------
    number : int
        1-based, the letter that names it in a word.
    terms : tuple of tuples of sympy expressions
        The Liouville terms whose sum is this piece: ``((A, C),)`` means ``X_{A,C}``.
    field : VectorField
    moving : tuple of int
        0-based indices of the coordinates this piece moves.
    """

    number: int
    terms: tuple
    field: VectorField
    moving: tuple

    def label(self) -> str:
        """LaTeX, e.g. ``X_{\\frac{x_2^2}{2m}, x_3}``."""
        if not self.terms:
            return "0"
        return " + ".join("X_{" + ", ".join(sympy.latex(f) for f in term) + "}" for term in self.terms)


@dataclass(frozen=True, eq=False)
class Splitting:
    """The pieces of a system's Liouville field, ``X = X_1 + ... + X_n``."""

    system: object
    pieces: tuple
    kind: str  # "full", "single" or (canonical) "fine"

    def __len__(self):
        return len(self.pieces)

    def __getitem__(self, number: int) -> Piece:
        """Piece by its 1-based number (the letter of a word)."""
        return self.pieces[number - 1]

    @property
    def fields(self) -> tuple:
        return tuple(p.field for p in self.pieces)

    def check_sum(self) -> bool:
        """``X_1 + ... + X_n == X_{H,G}`` (Eq. HGs)."""
        total = VectorField.zero(self.system.algebra)
        for f in self.fields:
            total = total + f
        return total == self.system.vector_field


def _is_constant(expr, coords) -> bool:
    return not any(sympy.sympify(expr, strict=True).has(x) for x in coords)


def _moving(field: VectorField) -> tuple:
    return tuple(i for i, c in enumerate(field.components) if not field.algebra.is_zero(c))


def full_split(system) -> Splitting:
    """Split every Hamiltonian per coordinate; piece ``i`` moves ``x_i`` (Eqs. X1-X3)."""
    from .system import System

    check_type(system, System, "system")
    coords = system.coordinates
    names = [system._ham_name(k, len(system.hamiltonians)) for k in range(len(system.hamiltonians))]
    parts = [separate(H, coords, name) for H, name in zip(system.hamiltonians, names)]
    pieces = []
    for i in range(system.N):
        others = [j for j in range(system.N) if j != i]
        terms = []
        for js in permutations(others, len(parts)):
            term = tuple(part[j] for part, j in zip(parts, js))
            if not any(_is_constant(f, coords) for f in term):
                terms.append(term)
        field = VectorField.zero(system.algebra)
        for term in terms:
            field = field + liouville_field(system.algebra, *term)
        pieces.append(Piece(i + 1, tuple(terms), field, _moving(field)))
    return Splitting(system, tuple(pieces), "full")


def single_split(system) -> Splitting:
    """Split only the first Hamiltonian: pieces ``X_{H_i, G}`` (the paper's footnote)."""
    from .system import System

    check_type(system, System, "system")
    coords = system.coordinates
    parts = separate(system.H, coords, "H")
    rest = system.hamiltonians[1:]
    pieces = []
    for Hi in parts:
        if _is_constant(Hi, coords):
            continue
        term = (Hi, *rest)
        field = liouville_field(system.algebra, *term)
        pieces.append(Piece(len(pieces) + 1, (term,), field, _moving(field)))
    return Splitting(system, tuple(pieces), "single")


def _components(terms, coords):
    """Group additive terms into classes of the transitive closure of "share a coordinate"."""
    groups: list = []  # [(set of coordinate indices, [terms])]
    for term in terms:
        used = {i for i, x in enumerate(coords) if term.has(x)}
        merged = [g for g in groups if g[0] & used]
        for g in merged:
            groups.remove(g)
            used |= g[0]
        groups.append((used, [t for g in merged for t in g[1]] + [term]))
    groups.sort(key=lambda g: min(g[0]))
    return [sympy.Add(*g[1]) for g in groups]


def canonical_split(system, fine: bool = False) -> Splitting:
    """Split ``H = T(p) + V(q)`` (canonical, ``N = 2d``): piece 1 = ``X_T`` moves the q's, piece 2 = ``X_V`` the p's.

    Both pieces are shears: ``q(t) = q + t dT/dp``, ``p(t) = p - t dV/dq``, for any
    functions ``T``, ``V`` (non-polynomial ones too), so ``121`` is position Verlet
    and ``212`` velocity Verlet (Hairer, Lubich, Wanner, *Geometric Numerical
    Integration*, Sect. I.3.1 and II.5).  With ``fine=True`` ``T`` and ``V`` are
    further split into parts on disjoint sets of coordinates (``T = p1^2/2 + p2^2/2``
    gives two pieces), T parts first.

    Raises
    ------
    NotSeparableError
        naming a term of ``H`` that mixes positions and momenta (no exact flow).

    Examples
    --------
    >>> from nambu_bch.systems import System
    >>> S = System("q1 q2 p1 p2", ["p1**2/2 + p2**2/2 + q1**2*q2"])
    >>> [p.field.to_sympy() for p in S.splitting.pieces]
    [(p1, p2, 0, 0), (0, 0, -2*q1*q2, -q1**2)]
    """
    from ..errors import NotSeparableError
    from .system import System

    check_type(system, System, "system")
    fine = check_flag(fine, "fine")
    coords = system.coordinates
    d = system.N // 2
    q, p = coords[:d], coords[d:]
    T, V = [], []
    for term in sympy.Add.make_args(sympy.expand(system.H)):
        in_q, in_p = term.has(*q), term.has(*p)
        if in_q and in_p:
            raise NotSeparableError(
                f"H = {system.H} is not separable into T(p) + V(q): the term {term} mixes positions "
                f"({', '.join(map(str, q))}) and momenta ({', '.join(map(str, p))}); accepted: a sum of terms each "
                "depending only on the momenta or only on the positions (their flows are exact shears)")
        if in_p:
            T.append(term)
        elif in_q:
            V.append(term)
    parts = (_components(T, coords) + _components(V, coords)) if fine else [sympy.Add(*T), sympy.Add(*V)]
    pieces = []
    for part in parts:
        if _is_constant(part, coords):
            continue
        field = liouville_field(system.algebra, part)
        pieces.append(Piece(len(pieces) + 1, ((part,),), field, _moving(field)))
    return Splitting(system, tuple(pieces), "fine" if fine else "full")


def _is_shear(field, moving) -> bool:
    xs = [field.algebra.coordinates[i] for i in moving]
    return not any(sympy.sympify(field.algebra.to_sympy(field.components[i]), strict=True).has(*xs) for i in moving)


def triplet_split(system, single: bool = False) -> Splitting:
    """Split ``X_{H,G}`` of Nambu's canonical triplets into exact shears.

    Every term ``A`` of ``H`` paired with every term ``B`` of ``G`` gives a field
    ``X_{A,B}`` (bilinearity of the triplet bracket); the non-zero ones are taken in
    order and merged greedily into the first piece whose union is still a shear (the
    velocities of the coordinates it moves do not depend on them), so two uncoupled
    ``(q, p, q^2)`` oscillators give the three pieces of ``ho3`` acting on both, and
    a coupling ``kappa x1 x4`` joins them.  ``single=True`` pairs each term of ``H``
    with the whole ``G``.  A field of a pair that is not a shear keeps a piece of
    its own and must have an exact (affine-linear) flow.

    Examples
    --------
    >>> from nambu_bch.systems import System
    >>> S = System("x1 x2 x3 x4 x5 x6", ["x2**2/2 + x3/2 + x5**2/2 + x6/2", "x3 - x1**2 + x6 - x4**2"])
    >>> [p.moving for p in S.splitting.pieces]
    [(0, 3), (1, 4), (2, 5)]
    """
    from ..errors import NoExactFlowError
    from ..integrators.flows import exact_flow
    from .system import System

    check_type(system, System, "system")
    single = check_flag(single, "single")
    coords = system.coordinates
    H_terms = list(sympy.Add.make_args(sympy.expand(system.H)))
    G_terms = [system.G] if single else list(sympy.Add.make_args(sympy.expand(system.G)))
    groups: list = []  # [terms, field, shear?]
    for A in H_terms:
        for B in G_terms:
            if _is_constant(A, coords) or _is_constant(B, coords):
                continue
            field = liouville_field(system.algebra, A, B)
            if field.is_zero():
                continue
            shear = _is_shear(field, _moving(field))
            for g in groups:
                if shear and g[2]:
                    union = g[1] + field
                    if _is_shear(union, _moving(union)):
                        g[0].append((A, B))
                        g[1] = union
                        break
            else:
                groups.append([[(A, B)], field, shear])
    groups.sort(key=lambda g: _moving(g[1]))  # piece numbers follow the coordinates moved (ho3: piece i moves x_i)
    pieces = tuple(Piece(k + 1, tuple(g[0]), g[1], _moving(g[1])) for k, g in enumerate(groups))
    for piece in pieces:
        if not _is_shear(piece.field, piece.moving):
            try:
                exact_flow(piece, coords)
            except NoExactFlowError as exc:
                raise NoExactFlowError(f"{system.name}: {exc}; accepted: pieces that are shears or affine-linear") from None
    return Splitting(system, pieces, "single" if single else "full")
