"""The factor F(x) that turns the conserved quantities into exact shadow Hamiltonians.

For the harmonic oscillator the position/velocity Verlet map is a rotation by
the angle ``theta = 2 asin(x/2)`` (``x = omega h``) in suitably scaled
coordinates, and its effective field is the conserved quantities' field
stretched by the factor (Eqs. factor1, factor2)

    F(x) = 2 asin(x/2) / (x sqrt(1 - x^2/4))
         = sum_{n>=0} (n!)^2 / (2n+1)! x^(2n) = 1 + x^2/6 + x^4/30 + ...,

defined for ``|x| < 2`` (the stability interval of the integrator); ``F`` is
even and ``F(0) = 1``.

Numerics.  ``F`` is evaluated as ``4 asin(x/2) / (x sqrt((2-x)(2+x)))``: near
``|x| = 2`` the factor ``2 - |x|`` is exact (Sterbenz), so the blow-up
``F ~ pi / (2 sqrt(2 - |x|))`` keeps full relative accuracy, while
``1 - x^2/4`` would lose every digit of ``2 - |x|``.  For ``|x| < 1/4`` the
Maclaurin series (ratio of successive terms below ``x^2/4``) is summed by
Horner's rule, which also stays exact for subnormal ``x``.

References
----------
Horikoshi, Eqs. (factor1), (factor2), (Xeff1), (Xeff2); Hardy & Okunbor (1999);
Kobayashi (2021).
"""

from __future__ import annotations

import math
from fractions import Fraction
from numbers import Real

import mpmath
import numpy as np
import sympy

from ..checks import finite_float, is_int, show
from ..errors import NambuBCHError, NumericalRangeError, UnstableStepError
from ..parsing import as_expression

#: Below this |x| the series is used (its 13 terms reach 2^-60 relative accuracy).
_SERIES_CUTOFF = 0.25
_SERIES_TERMS = 14


#: Highest order of :func:`F_series`: 200 terms, coefficients of about 120 digits (a request, not a limit of F).
MAX_SERIES_ORDER = 400


def _coefficient(n: int) -> Fraction:
    """``(n!)^2 / (2n+1)!``, the coefficient of ``x^(2n)`` in F."""
    return Fraction(math.factorial(n) ** 2, math.factorial(2 * n + 1))


_COEFFS = tuple(float(_coefficient(n)) for n in range(_SERIES_TERMS))


def F_series(x, order: int):
    """The Maclaurin polynomial of F through ``x**order`` (Eq. factor2).

    ``sum_{2n <= order} (n!)^2/(2n+1)! x^(2n)``; ``x`` may be a sympy expression
    (e.g. ``omega*h``) or a number.

    Parameters
    ----------
    x : sympy expression, number, or text in ``x``, ``omega``, ``h`` (read by the safe parser)
    order : int, highest power of ``x`` kept (>= 0)

    Returns
    -------
    The truncated series, a sympy expression for sympy ``x``.

    Examples
    --------
    >>> x = sympy.Symbol("x")
    >>> F_series(x, 4)
    x**4/30 + x**2/6 + 1
    >>> F_series(x, 8).coeff(x, 8) == sympy.factorial(4)**2 / sympy.factorial(9)
    True
    """
    if not is_int(order, 0, MAX_SERIES_ORDER):
        from ..errors import InvalidOrderError

        raise InvalidOrderError(f"order of F_series must be an integer in 0..{MAX_SERIES_ORDER}, got {show(order)}")
    if isinstance(x, (sympy.Basic, str)):
        x = as_expression(x, sympy.symbols("x omega h"), "x of F_series")
        return sympy.Add(*[sympy.Rational(c.numerator, c.denominator) * x ** (2 * n)
                           for n, c in ((n, _coefficient(n)) for n in range(order // 2 + 1))])
    if isinstance(x, np.ndarray):
        from ..numeric.guards import finite_array

        x = finite_array(x, "x")
    elif not isinstance(x, mpmath.mpf):
        x = finite_float(x, "x")
    total = 0
    for n in range(order // 2, -1, -1):
        c = _coefficient(n)
        total = total * x * x + (mpmath.mpf(c.numerator) / c.denominator if isinstance(x, mpmath.mpf) else float(c))
    return total


def _unstable(value) -> UnstableStepError:
    return UnstableStepError(
        f"F(x) needs |x| = |omega h| < 2 (the stability interval of the integrator), got x = {value!r}"
    )


def _F_float_array(x: np.ndarray) -> np.ndarray:
    """F on a float64 array (already checked finite and |x| < 2)."""
    ax = np.abs(x)
    out = np.empty_like(ax)
    small = ax < _SERIES_CUTOFF
    if small.any():
        x2 = ax[small] ** 2
        acc = np.full_like(x2, _COEFFS[-1])
        for c in reversed(_COEFFS[:-1]):
            acc = acc * x2 + c
        out[small] = acc
    big = ~small
    if big.any():
        a = ax[big]
        out[big] = 4.0 * np.arcsin(0.5 * a) / (a * np.sqrt((2.0 - a) * (2.0 + a)))
    return out


def _F_mpmath(x):
    if not mpmath.isfinite(x):
        raise NumericalRangeError(f"F(x) needs a finite x, got {x!r}")
    if abs(x) >= 2:
        raise _unstable(x)
    if x == 0:
        return mpmath.mpf(1)
    a = abs(x)
    return 4 * mpmath.asin(a / 2) / (a * mpmath.sqrt((2 - a) * (2 + a)))


def _F_sympy(x):
    if x.is_number:
        if x.has(sympy.nan, sympy.zoo, sympy.oo, -sympy.oo) or not x.is_real:
            raise NumericalRangeError(f"F(x) needs a finite real x, got {x}")
        if x.is_zero:
            return sympy.Integer(1)
        if sympy.Abs(x) >= 2:
            raise _unstable(x)
    return 2 * sympy.asin(x / 2) / (x * sympy.sqrt(1 - x**2 / 4))


def F(x):
    """The factor ``F(x) = 2 asin(x/2) / (x sqrt(1 - x^2/4))`` of Eq. (factor1).

    Sympy in, sympy out (the exact closed form; ``F(0) = 1``); a float, numpy
    scalar or array in, the same kind out (float64, vectorised, within a few
    ulps over ``0 <= |x| < 2``); an ``mpmath.mpf`` in, an ``mpf`` at the
    working precision out.

    Parameters
    ----------
    x : sympy expression, float, int, numpy array or mpmath mpf

    Returns
    -------
    F(x) of the same kind.

    Raises
    ------
    UnstableStepError  if a numeric ``|x| >= 2`` (the integrator is unstable there).
    NumericalRangeError  if ``x`` is NaN or infinite.

    References
    ----------
    Horikoshi, Eqs. (factor1), (factor2).

    Examples
    --------
    >>> F(sympy.Symbol("x"))
    2*asin(x/2)/(x*sqrt(1 - x**2/4))
    >>> F(0.0), F(sympy.Integer(0))
    (1.0, 1)
    >>> round(F(1.0), 12) == round(2*math.pi/(3*math.sqrt(3)), 12)
    True
    """
    if isinstance(x, sympy.Basic):
        return _F_sympy(x)
    if isinstance(x, mpmath.mpf):
        return _F_mpmath(x)
    if isinstance(x, (bool, complex)) or isinstance(x, mpmath.mpc):
        raise NambuBCHError(f"F(x) takes a real x (sympy, float, numpy array or mpmath mpf), got {x!r}")
    if isinstance(x, Real) and not isinstance(x, np.generic):
        try:
            value = float(x)
        except OverflowError:  # an int beyond the float range
            raise NumericalRangeError(f"F(x) needs a finite x, got a {type(x).__name__} beyond the float range") from None
        if not math.isfinite(value):
            raise NumericalRangeError(f"F(x) needs a finite x, got {x!r}")
        if abs(value) >= 2:
            raise _unstable(x)
        return float(_F_float_array(np.array([value]))[0])
    try:
        arr = np.asarray(x)
    except Exception as exc:  # noqa: BLE001 - anything numpy cannot read is bad input
        raise NambuBCHError(f"F(x) takes a real x (sympy, float, numpy array or mpmath mpf), got {x!r}") from exc
    if arr.dtype.kind not in "biuf":
        raise NambuBCHError(f"F(x) takes real numbers, got an array of dtype {arr.dtype}")
    arr = arr.astype(np.float64)
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)].ravel()[0]
        raise NumericalRangeError(f"F(x) needs finite x, got {bad!r} in the input")
    unstable = np.abs(arr) >= 2
    if unstable.any():
        raise _unstable(float(arr[unstable].ravel()[0]))
    out = _F_float_array(arr.ravel()).reshape(arr.shape)
    if isinstance(x, np.generic) or arr.ndim == 0:
        return np.float64(out.reshape(()))
    return out
