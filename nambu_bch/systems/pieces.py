"""The pieces of a splitting and the builders of the four splits (:mod:`.splitting` has the mathematics).

:class:`Piece` and :class:`Splitting`, and ``build_*_split``: the splits of a system without the type check of
the public :func:`~nambu_bch.systems.splitting.full_split` etc., so that :class:`~nambu_bch.systems.System`'s
default ``splitting`` can use them from below.  A triplet piece that is not a shear is verified to have an exact
flow here (:func:`~nambu_bch.systems.piece_flows.piece_flow`).

References
----------
Horikoshi, Sect. 4.1, Eqs. (HGs), (X1)-(X3) and footnote 1; Modin (2010).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import permutations

import sympy

from ..algebra import VectorField, liouville_field
from ..checks import check_flag
from .piece_flows import piece_flow
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


def build_full_split(system) -> Splitting:
    """Piece ``i`` moves ``x_i``: every Hamiltonian split per coordinate (:func:`~nambu_bch.systems.splitting.full_split`)."""
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


def build_single_split(system) -> Splitting:
    """Pieces ``X_{H_i, G}`` (:func:`~nambu_bch.systems.splitting.single_split`)."""
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


def build_canonical_split(system, fine: bool = False) -> Splitting:
    """Pieces ``X_T``, ``X_V`` (and their parts with ``fine``) of a canonical system (:func:`~nambu_bch.systems.splitting.canonical_split`)."""
    from ..errors import NotSeparableError

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


def build_triplet_split(system, single: bool = False) -> Splitting:
    """Exact shears of Nambu's canonical triplets (:func:`~nambu_bch.systems.splitting.triplet_split`)."""
    from ..errors import NoExactFlowError

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
                piece_flow(piece, tuple(coords))
            except NoExactFlowError as exc:
                raise NoExactFlowError(f"{system.name}: {exc}; accepted: pieces that are shears or affine-linear") from None
    return Splitting(system, pieces, "single" if single else "full")
