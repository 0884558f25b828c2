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

The pieces and the builders are in :mod:`.pieces` (below :class:`~nambu_bch.systems.System`, whose default
``splitting`` they make); the functions here are the checked entry points of the API.
"""

from __future__ import annotations

from ..checks import check_type
from .pieces import (Piece, Splitting, build_canonical_split, build_full_split, build_single_split,
                     build_triplet_split)
from .system import System

__all__ = ["Piece", "Splitting", "canonical_split", "full_split", "single_split", "triplet_split"]


def full_split(system) -> Splitting:
    """Split every Hamiltonian per coordinate; piece ``i`` moves ``x_i`` (Eqs. X1-X3)."""
    return build_full_split(check_type(system, System, "system"))


def single_split(system) -> Splitting:
    """Split only the first Hamiltonian: pieces ``X_{H_i, G}`` (the paper's footnote)."""
    return build_single_split(check_type(system, System, "system"))


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
    return build_canonical_split(check_type(system, System, "system"), fine)


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
    return build_triplet_split(check_type(system, System, "system"), single)
