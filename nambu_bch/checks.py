"""The package's one integer check for arguments (``True`` is not an integer here, ``3.0`` neither).

>>> is_int(3, 1, 10), is_int(True), is_int(3.0), is_int(0, 1), is_int(11, None, 10)
(True, False, False, False, False)
"""

from __future__ import annotations

import numbers


def is_int(value, low=None, high=None, numpy: bool = False) -> bool:
    """``value`` is an ``int`` (with ``numpy=True`` also a numpy integer), not a ``bool``, and ``low <= value <= high``.

    Parameters
    ----------
    value : anything
    low, high : int or None -- inclusive bounds, ``None`` for none
    numpy : also accept ``numpy.integer`` values (run lengths and orders coming from arrays)
    """
    if isinstance(value, bool):
        return False
    if not isinstance(value, int):
        if not (numpy and isinstance(value, numbers.Integral) and type(value).__module__ == "numpy"):
            return False
    return (low is None or value >= low) and (high is None or value <= high)
