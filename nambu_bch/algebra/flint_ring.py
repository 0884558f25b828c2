"""A polynomial ring ``QQ[x_1..x_n, c_1..c_k]`` on python-flint's ``fmpq_mpoly``, for the brackets' arithmetic.

:func:`~nambu_bch.algebra.brackets.liouville_field` and the Nambu/Poisson brackets use
only a small part of :class:`~nambu_bch.algebra.polynomial.PolynomialAlgebra`: the number
``n`` of coordinates, the generators, ``ring.one``, ``zero``, ``diff``, ``convert``,
``common``, ``is_zero``, ``is_polynomial``.  :class:`FlintRing` offers exactly that on flint
polynomials (products in C), so a Liouville field of polynomials with rational coefficients
-- the fraction-free cross terms of the direct route, where the parameters are further
generators that are never differentiated -- is computed without sympy's Python-level
polynomial products.  Exact: the same polynomials as over sympy's ring (tested).

References
----------
Horikoshi, Eq. (gLiouville); FLINT ``fmpq_mpoly``.
"""

from __future__ import annotations

from types import SimpleNamespace

from . import _flint
from ._flint import exponents
from .polynomial import PolynomialAlgebra
from .ring import declare


@declare()
class FlintRing:
    """``QQ[names]`` on flint ``fmpq_mpoly`` (lexicographic, generators in the order of ``names``), the first ``n``
    generators the coordinates.

    >>> R = FlintRing(("x", "y", "a"), 2)
    >>> x, y, a = R.gens
    >>> from nambu_bch.algebra.brackets import liouville_field
    >>> liouville_field(R, a * x**2 / 2).components == (R.zero, -a * x)      # X_H = (dH/dy, -dH/dx)
    True
    """

    def __init__(self, names, n: int):
        self.names = tuple(names)
        self.ctx = _flint.fmpq_mpoly_context(len(self.names))  # generators v0, v1, .. in the order of ``names``
        self.n = n
        self.gens = tuple(self.ctx.gens())
        self.zero = self.ctx.from_dict({})
        self.ring = SimpleNamespace(one=self.ctx.from_dict({(0,) * len(self.gens): 1}))

    def __reduce__(self):
        """Pickle as the generator names and the number of coordinates (a flint context is process-local)."""
        return FlintRing, (self.names, self.n)

    def __eq__(self, other):
        return isinstance(other, FlintRing) and (self.names, self.n) == (other.names, other.n)

    def __hash__(self):
        return hash((self.names, self.n))

    def from_terms(self, terms: dict):
        """The polynomial ``sum c x^e`` of ``{exponent tuple: rational}`` (sympy ``QQ`` elements or flint ``fmpq``)."""
        fmpq, native = _flint.fmpq, _flint.module().fmpq  # flint's own rationals pass without a call
        return self.ctx.from_dict({e: c if isinstance(c, native) else fmpq(c) for e, c in terms.items()})

    @staticmethod
    def terms(p) -> dict:
        """``{exponent tuple: fmpq}`` of a polynomial (no zero coefficients)."""
        return dict(zip(exponents(p), p.coeffs()))

    # -- the interface of the brackets ------------------------------------------------
    def diff(self, value, index: int):
        return value.derivative(index)

    def convert(self, value):
        return value

    def common(self, *values):
        return values

    @staticmethod
    def is_zero(value) -> bool:
        return value.is_zero()

    @staticmethod
    def is_polynomial(value) -> bool:
        return True


def polynomial_ring(coordinates, constants, flint: bool):
    """``QQ[coordinates, constants]`` with the coordinates as the ring protocol's derivation variables: a
    :class:`FlintRing` when ``flint`` (python-flint chosen by the caller, :func:`nambu_bch.algebra._flint.available`),
    else a :class:`~nambu_bch.algebra.polynomial.PolynomialAlgebra` over ``QQ`` -- the same polynomials, exponent
    tuples in the same order (coordinates, then constants), with ``from_terms``/``terms`` on both."""
    if flint:
        return FlintRing([str(s) for s in (*coordinates, *constants)], len(coordinates))
    return PolynomialAlgebra(coordinates, (), constants)
