"""The package's one integer check and one float conversion for arguments (no numpy or sympy imported).

``is_int``: ``True`` is not an integer here, ``3.0`` neither.  ``finite_float``: any real number to a
finite float64, or one line naming the argument.

>>> is_int(3, 1, 10), is_int(True), is_int(3.0), is_int(0, 1), is_int(11, None, 10)
(True, False, False, False, False)
"""

from __future__ import annotations

import math
import numbers
import sys

from .errors import InvalidRunError, NumericalRangeError, one_line

#: The accepted truncation orders ``k`` (``h^0 .. h^k``) of every symbolic route and of ``--order``: one range
#: for the API and the command line.  Order 0 is the exact answer ``H_S = H, G_S = G`` (no correction is kept).
#: The top is a work bound, not a mathematical one: the number of BCH words grows like ``n^k / k`` for n pieces,
#: and at ``k = 12`` the ho3 expansion already takes tens of seconds and hundreds of MB.
MAX_ORDER = 12


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


def check_flag(value, what, none=False):
    """``value`` as a bool: ``True``/``False`` (numpy's too), or ``None`` where ``none`` allows it (automatic)."""
    if value is None and none:
        return None
    if not (isinstance(value, bool) or (type(value).__module__ == "numpy" and type(value).__name__ in ("bool_", "bool"))):
        raise InvalidRunError(f"{what} must be True or False{' or None' if none else ''}, got {show(value)}")
    return bool(value)


def check_int(value, what, low=None, high=None) -> int:
    """``value`` as an int if :func:`is_int` accepts it (numpy integers too), else one line naming ``what``."""
    if not is_int(value, low, high, numpy=True):
        if low is not None and high is not None:
            accepted = f"an integer from {low} to {high}"
        elif low is not None:
            accepted = f"an integer >= {low}"
        else:
            accepted = "an integer" if high is None else f"an integer <= {high}"
        raise InvalidRunError(f"{what} must be {accepted}, got {show(value)}")
    return int(value)


def check_type(value, kind, what):
    """``value`` if it is an instance of ``kind`` (a class or a tuple of classes), else one line naming ``what``.

    For the arguments that must be one of the package's objects (a splitting, a vector field, a
    composition): a wrong object is refused at the entry instead of failing deep inside.
    """
    if not isinstance(value, kind):
        names = " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))
        raise InvalidRunError(f"{what} must be a {names}, got {show(value)}")
    return value


def check_sequence(value, what, of="items", length=None) -> tuple:
    """``value`` as a tuple if it is a sequence (a list, tuple, array, ...; not a string, bytes, a mapping or a set),
    else one line naming ``what``; with ``length``, also that it has that many items.

    The one check of "a sequence of ..." arguments (coordinates, slots, components, terms): a string
    would otherwise be iterated character by character and a number fail deep inside.
    """
    if isinstance(value, (str, bytes, bytearray, dict, set, frozenset)) or not hasattr(value, "__iter__") \
            or getattr(value, "ndim", 1) != 1:
        raise InvalidRunError(f"{what} must be a sequence of {of}, got {show(value)}")
    out = tuple(value)
    if length is not None and len(out) != length:
        raise InvalidRunError(f"{what} must be a sequence of {length} {of}, got {len(out)}: {show(value)}")
    return out


def show(value) -> str:
    """``repr(value)`` on one line, shortened to one readable piece (a 400-digit integer is not echoed whole)."""
    text = repr(value)
    if "\n" in text:  # an array's or a matrix's repr: one line (a string's repr has no line break)
        text = one_line(text, len(text))
    return text if len(text) <= 60 else f"{text[:30]}...{text[-12:]} ({len(text)} characters)"


def finite_float(value, what) -> float:
    """``value`` as a finite float64, else one line naming ``what`` (the one conversion of user numbers).

    Accepts a real number of any kind: ``int``, ``float``, numpy scalars, exact sympy numbers
    (what the expression parser returns for ``--h 1/10``), ``mpmath.mpf``, and a string in
    Python's float syntax (``"0.1"``).  An exact value beyond
    the float64 range (``10**400``, ``exp(exp(10))``) is refused (:class:`NumericalRangeError`)
    instead of becoming ``inf`` or raising ``OverflowError``, and so is a non-zero value that
    rounds to 0 (``exp(-10**4)``); NaN and infinities likewise.  Anything else (symbols,
    complex numbers, arrays, other strings) is :class:`InvalidRunError`.

    >>> finite_float(1, "h"), finite_float("0.5", "h")
    (1.0, 0.5)
    >>> finite_float(10**400, "t_end")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    nambu_bch.errors.NumericalRangeError: t_end = 1000...000 (401 characters) is not finite in float64 ...
    """
    if value is None or isinstance(value, (bool, bytes, complex)) or getattr(value, "shape", ()) != ():
        raise InvalidRunError(f"{what} must be a real number, got {show(value)}")
    try:
        out = float(value)
    except OverflowError:
        out = math.inf
    except (TypeError, ValueError):
        raise InvalidRunError(f"{what} must be a real number, got {show(value)}") from None
    if math.isnan(out):
        raise NumericalRangeError(f"{what} = {show(value)} is not finite (not a number); give a finite real number")
    if math.isinf(out):
        raise NumericalRangeError(f"{what} = {show(value)} is not finite in float64 (|x| <= "
                                  f"{sys.float_info.max:.3g}); give a finite real number")
    if out == 0.0 and not _is_zero(value):
        raise NumericalRangeError(f"{what} = {show(value)} is non-zero but rounds to 0 in float64 (|x| >= "
                                  "5e-324 needed); give a larger number or 0")
    return out


def _is_zero(value) -> bool:
    try:
        if isinstance(value, str):
            import decimal

            return decimal.Decimal(value.strip()) == 0
        return bool(value == 0)
    except (TypeError, ValueError, ArithmeticError):  # pragma: no cover - exotic number types
        return False
