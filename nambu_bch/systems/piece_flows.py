"""Exact flows of the pieces of a splitting.

A piece ``X`` moves the coordinates ``M`` (those with a non-zero component)
and fixes the rest, so along its flow the velocity of ``x_M`` can only depend
on ``x_M`` and on constants of the motion.  Two cases are solved exactly:

* **shear** -- ``X^i`` for ``i`` in ``M`` does not depend on ``x_M``:
  ``x_i(t) = x_i + t X^i`` (Eqs. XT, VT, hX1g-hX3g, hX1e-hX3e);
* **affine-linear** -- ``dx_M/dt = A x_M + b`` with ``A, b`` free of ``x_M``:
  ``(x_M(t), 1) = exp(t [[A, b], [0, 0]]) (x_M, 1)``.  Diagonal ``A`` gives the
  exponentials of the Lotka-Volterra pieces, nilpotent ``A`` the polynomial
  flows of the ``(q^2, p^2, qp)`` oscillator, imaginary eigenvalues the rotations
  of the Lie-Poisson rigid body (written with real ``cos``, ``sin``).

Anything else raises :class:`~nambu_bch.errors.NoExactFlowError` naming the piece.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy

from ..errors import NoExactFlowError

#: The symbol of the sub-flow's time in :attr:`ExactFlow.expressions`.
TIME = sympy.Symbol("t")


@dataclass(frozen=True, eq=False)
class ExactFlow:
    """``x -> phi_t(x)`` of one piece, as sympy expressions in the coordinates and ``t``.

    Attributes
    ----------
    expressions : tuple of sympy expressions, one per coordinate
    kind : ``"shear"``, ``"nilpotent"``, ``"linear"`` or ``"rotation"`` (real ``cos``/``sin`` of the fixed coordinates)
    polynomial : bool -- the flow is polynomial in the coordinates and ``t``
    """

    expressions: tuple
    kind: str
    polynomial: bool

    def at(self, t) -> tuple:
        """The flow for time ``t`` (e.g. ``c*h``)."""
        return tuple(e.subs(TIME, t) for e in self.expressions)


@lru_cache(maxsize=256)
def piece_flow(piece, coordinates: tuple) -> ExactFlow:
    """The exact flow of ``piece`` (a :class:`~nambu_bch.systems.Piece`) in ``coordinates`` (a tuple of symbols, one
    per coordinate of its algebra; :func:`nambu_bch.integrators.flows.exact_flow` checks both), else
    :class:`~nambu_bch.errors.NoExactFlowError` naming the piece."""
    comps = piece.field.to_sympy()
    moving = list(piece.moving)
    xs = [coordinates[i] for i in moving]
    out = list(coordinates)
    if not moving:
        return ExactFlow(tuple(out), "shear", True)
    if not any(comps[i].has(*xs) for i in moving):
        for i in moving:
            out[i] = coordinates[i] + TIME * comps[i]
        return ExactFlow(tuple(out), "shear", all(comps[i].is_polynomial(*coordinates) for i in moving))
    # affine-linear: comps[i] = sum_j A_ij x_j + b_i with A, b free of the moving coordinates
    A = sympy.zeros(len(moving) + 1)
    for r, i in enumerate(moving):
        expr = sympy.expand(comps[i])
        for c, x in enumerate(xs):
            A[r, c] = expr.coeff(x, 1)
        A[r, -1] = sympy.expand(expr - sum(A[r, c] * x for c, x in enumerate(xs)))
        if any(A[r, c].has(*xs) for c in range(len(moving) + 1)):
            raise NoExactFlowError(
                f"piece {piece.number} ({piece.label()}) has velocity {comps[i]} for {coordinates[i]}, which is neither "
                "free of nor linear in the coordinates it moves; its flow has no closed form here (accepted: shears, "
                "affine-linear pieces; try another split)"
            )
    rotation = _plane_rotation(A, xs, coordinates)
    if rotation is not None:
        for i, value in zip(moving, rotation):
            out[i] = value
        return ExactFlow(tuple(out), "rotation", False)
    nilpotent = (A**(len(moving) + 1)).is_zero_matrix
    if nilpotent:
        E = sympy.eye(len(moving) + 1)
        term = sympy.eye(len(moving) + 1)
        for k in range(1, len(moving) + 1):
            term = term * A * TIME / k
            E += term
    else:
        try:
            E = (A * TIME).exp()
        except Exception as exc:  # sympy raises assorted errors for matrices it cannot exponentiate
            raise NoExactFlowError(f"piece {piece.number} ({piece.label()}): exp(t A) has no closed form ({exc})") from None
    state = sympy.Matrix([*xs, 1])
    new = E * state
    kind = "nilpotent" if nilpotent else "linear"
    for r, i in enumerate(moving):
        value = sympy.expand(sympy.simplify(new[r]))
        if value.has(sympy.I):
            value = _real_form(value, piece)
            kind = "rotation"
        out[i] = value
    polynomial = all(e.is_polynomial(*coordinates, TIME) for e in out)
    return ExactFlow(tuple(out), kind, polynomial)


def _plane_rotation(A, xs, coordinates):
    """The flow ``(x_a cos(w t) - x_b sin(w t), x_a sin(w t) + x_b cos(w t))`` of ``dx_a/dt = -w x_b``,
    ``dx_b/dt = w x_a`` when ``A = [[0, -w, 0], [w, 0, 0], [0, 0, 0]]`` with ``w`` a monomial in a fixed coordinate
    (and parameters): the Lie-Poisson rigid body's pieces ``X_{x_i^2/(2 I_i), C}``, ``w = +-x_i/I_i``.  Else ``None``.

    ``exp(t A)`` in closed form: sympy's matrix exponential goes through a Jordan form in ``exp(+-i w t)`` and
    ``simplify``, ~0.5 s per piece, for the expressions :func:`_real_form` then writes in exactly this shape.
    """
    if len(xs) != 2 or any(A[r, c] != 0 for r, c in ((0, 0), (1, 1), (0, 2), (1, 2))):
        return None
    w = A[1, 0]
    if not (w.is_Mul or w.is_Symbol) or not w.has(*coordinates) or w.has(sympy.I) or sympy.expand(A[0, 1] + w) != 0:
        return None
    a, b = xs
    c, s = sympy.cos(TIME * w), sympy.sin(TIME * w)
    return sympy.expand(a * c - b * s), sympy.expand(a * s + b * c)


def _real_form(value, piece):
    """``exp(+-i w t)`` combinations of a real flow as ``cos(w t)``, ``sin(w t)`` (rotations, e.g. rigid-body pieces).

    A real matrix ``A`` with imaginary eigenvalues ``+-i w`` gives ``exp(t A)`` in
    complex exponentials; rewriting them by Euler's formula and expanding cancels
    every ``i`` (the flow is real), which is checked: the numeric kernels then see
    only real ``cos`` and ``sin`` (McLachlan 1993, the rigid-body rotations).
    """
    real = sympy.expand(value.rewrite(sympy.cos))
    if real.has(sympy.I):
        real = sympy.expand(sympy.simplify(real))
    if real.has(sympy.I):
        raise NoExactFlowError(
            f"piece {piece.number} ({piece.label()}): its exact flow {value} could not be written without complex numbers")
    return real
