"""The exact flows of the pieces of a splitting: :func:`exact_flow`, the checked entry of the routes.

The flows themselves (shears and affine-linear pieces, Eqs. XT, VT, hX1g-hX3g, hX1e-hX3e) are solved by
:func:`nambu_bch.systems.piece_flows.piece_flow`, below the splittings that verify each piece has one; see that
module for the mathematics.
"""

from __future__ import annotations

from ..checks import check_type, show
from ..errors import InvalidRunError
from ..parsing import as_symbols
from ..systems.piece_flows import TIME, ExactFlow, piece_flow
from ..systems.pieces import Piece

__all__ = ["TIME", "ExactFlow", "exact_flow"]


def exact_flow(piece, coordinates) -> ExactFlow:
    """The exact flow of ``piece`` (a :class:`~nambu_bch.systems.Piece`)."""
    check_type(piece, Piece, "piece")
    coordinates = as_symbols(coordinates, "coordinates")
    if len(coordinates) != piece.field.algebra.n:
        raise InvalidRunError(f"piece {piece.number} moves {piece.field.algebra.n} coordinates, got {show(coordinates)}")
    return piece_flow(piece, coordinates)
