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
    kind: str  # "full" or "single"

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
    return not any(sympy.sympify(expr).has(x) for x in coords)


def _moving(field: VectorField) -> tuple:
    return tuple(i for i, c in enumerate(field.components) if not field.algebra.is_zero(c))


def full_split(system) -> Splitting:
    """Split every Hamiltonian per coordinate; piece ``i`` moves ``x_i`` (Eqs. X1-X3)."""
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
