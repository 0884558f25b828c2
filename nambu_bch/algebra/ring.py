"""The declared ring protocol of the exact arithmetic: a commutative ring with derivations and a normal form.

Every exact ring of the package is a commutative ring ``R`` over a coefficient field ``K``
(:class:`~nambu_bch.algebra.fields.CoefficientField`) with ``n`` derivations ``D_0, .., D_{n-1}``:

* ``D_i`` is ``K``-linear and satisfies the Leibniz rule ``D_i(a b) = D_i(a) b + a D_i(b)``;
* the ``D_i`` commute pairwise and ``D_i(x_j) = delta_ij`` on the first ``n`` generators (the coordinates);
* every element has one canonical normal form, so ``a = 0`` is decided structurally (no simplification).

The implementations:

* :class:`~nambu_bch.algebra.polynomial.PolynomialAlgebra` -- ``K[x_1..x_n, c_1..c_k]`` (sympy's sparse
  polynomials, ``K = QQ(params)`` or an algebraic extension), ``D_i = d/dx_i``, the constants ``c`` never
  differentiated;
* :class:`~nambu_bch.shadow.jets.JetAlgebra` -- ``QQ[x, F_alpha]``, the jets ``F_alpha = d^alpha F`` of
  undetermined functions, ``D_i`` the total derivative ``d/dx_i + sum_alpha F_{alpha + e_i} d/dF_alpha``;
* :class:`~nambu_bch.algebra.flint_ring.FlintRing` -- ``QQ[x, c, params]`` on flint's ``fmpq_mpoly``;
* :class:`~nambu_bch.algebra.extended.ExtendedRing` -- ``B[C, u] / (S^2 + C^2 - 1, u^2 - P)`` localised at
  the denominators, for Hamiltonians with ``exp``, ``sin``, ``cos``, square roots and denominators; ``D_i`` by the
  chain rule through the generators; the normal form is the remainder modulo a Groebner basis (the
  relations' leading terms are coprime).

The interface (:class:`ExactRing`): ``n``; ``gens`` (the ring's generators, the ``n`` coordinates first);
``zero``; ``diff(a, i) = D_i(a)``; ``convert(e)`` (a sympy expression or number as an element, or, for the rings
that also carry general expressions, the expression itself when it is not in the ring); ``common(*values)``
(the values in one representation); ``is_zero(a)``; ``is_polynomial(a)`` (``a`` is an element of the ring, not a
general sympy expression).  A class declares the protocol with :func:`declare`; :func:`check_ring` is the one
check of an ``algebra`` argument.

References
----------
Kolchin, *Differential Algebra and Algebraic Groups* (1973), ch. I (differential rings); Cox, Little, O'Shea,
*Ideals, Varieties, and Algorithms*, Sect. 2.6 (normal forms modulo a Groebner basis); Horikoshi, Eqs. (NB),
(gLiouville) (the brackets and Liouville fields built on these rings).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from ..checks import show
from ..errors import InvalidRunError

__all__ = ["ExactRing", "check_ring", "declare", "declared_rings"]


@runtime_checkable
class ExactRing(Protocol):
    """A commutative ring with ``n`` commuting derivations and a canonical normal form (module docstring)."""

    #: the number of coordinates (derivations ``D_0 .. D_{n-1}``)
    n: int
    #: the generators, the ``n`` coordinates first
    gens: tuple
    #: the zero element
    zero: object

    def diff(self, value, index: int):
        """``D_index(value)``."""

    def convert(self, value):
        """A sympy expression or exact number as an element of the ring."""

    def common(self, *values) -> tuple:
        """The values in one representation (all ring elements when possible)."""

    def is_zero(self, value) -> bool:
        """``value == 0``, decided on the normal form."""

    def is_polynomial(self, value) -> bool:
        """``value`` is an element of the ring (not a general sympy expression)."""


# the declared implementations, as tuples so that isinstance stays a nominal (fast) test: a structural test
# against the Protocol looks up every attribute and costs tens of microseconds per call
_CHECK = {"rings": (), "field_rings": ()}


def declare(vector_fields: bool = True):
    """Class decorator: the class implements :class:`ExactRing`; with ``vector_fields`` a
    :class:`~nambu_bch.algebra.vector_field.VectorField` and the field backends may live on it (the rings whose
    fields are the package's :class:`VectorField`; the extended rings have their own backend)."""

    def mark(cls):
        ExactRing.register(cls)
        _CHECK["rings"] += (cls,)
        if vector_fields:
            _CHECK["field_rings"] += (cls,)
        return cls

    return mark


def declared_rings(vector_fields: bool = False) -> tuple:
    """The classes declared with :func:`declare` so far (those carrying vector fields only, with ``vector_fields``)."""
    return _CHECK["field_rings" if vector_fields else "rings"]


def check_ring(value, what: str, vector_fields: bool = True):
    """``value`` if it is an instance of a declared exact ring (one carrying vector fields, with ``vector_fields``),
    else one line naming ``what`` and the accepted rings."""
    if not isinstance(value, declared_rings(vector_fields)):
        kinds = "a PolynomialAlgebra or FlintRing" if vector_fields else \
            "a PolynomialAlgebra, FlintRing or ExtendedRing"
        raise InvalidRunError(f"{what} must be an exact ring ({kinds}), got {show(value)}")
    return value
