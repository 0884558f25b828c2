"""The coefficient field of an exact computation: ``QQ``, ``QQ(parameters)``, ``QQ(theta)``, ``QQ(theta)(parameters)``.

Every exact ring of the package (:class:`~nambu_bch.algebra.polynomial.PolynomialAlgebra`, the jet ring, the
backends' rings, the matrices of the elimination) has its coefficients in one of four fields:

* ``QQ`` -- the rationals (sympy's ``QQ``; python-flint's ``fmpq`` on the flint paths);
* ``QQ(p_1, .., p_k)`` -- rational functions in the parameters (masses, moments of inertia), each element a
  reduced fraction ``n / d`` with ``n, d`` in ``ZZ[p]`` coprime and ``lc(d) > 0`` (lexicographic order):
  sympy's ``FracField``, and flint's ``fmpz_mpoly`` pairs in :mod:`nambu_bch.algebra.frac_rref`;
* ``QQ(theta)`` -- an algebraic number field, ``theta`` a primitive element of the adjoined numbers
  (``QQ(i)`` for complex splitting coefficients, ``QQ(2^(1/3))`` for the triple jump), elements the
  polynomials of degree ``< [QQ(theta) : QQ]`` in ``theta`` (sympy's ``AlgebraicField``);
* ``QQ(theta)(p_1, .., p_k)`` -- rational functions over an algebraic number field.

In each, zero is structural: an element is zero exactly when its normal form is, so no simplification
decides anything.  :class:`CoefficientField` names which of the four a sympy domain is and owns what the
rest of the package asks of it: the ground field, the parameters, the adjoined numbers, whether the
elimination may clear denominators over ``ZZ``, and the flint context of the parameters when there is one.

References
----------
sympy ``polys.domains`` (``QQ``, ``FractionField``, ``AlgebraicField``); Cohen, *A Course in Computational
Algebraic Number Theory*, Sect. 4.2 (a number field as ``QQ[X] / (minimal polynomial)``).
"""

from __future__ import annotations

from functools import lru_cache

from ..errors import InvalidRunError
from . import _flint

__all__ = ["CoefficientField"]


class CoefficientField:
    """One of ``QQ``, ``QQ(params)``, ``QQ(theta)``, ``QQ(theta)(params)``, wrapping its sympy domain.

    Two fields are equal when their sympy domains are.

    >>> import sympy
    >>> from sympy.polys.domains import QQ
    >>> a = sympy.Symbol("a")
    >>> F = CoefficientField.of(QQ.algebraic_field(sympy.cbrt(2)).frac_field(a))
    >>> F.parameters, F.extension, F.is_algebraic, F.is_rational_functions
    ((a,), (2**(1/3),), True, False)
    >>> CoefficientField.of(QQ).is_rational, CoefficientField.of(QQ.frac_field(a)).is_rational_functions
    (True, True)
    """

    __slots__ = ("domain", "ground", "parameters", "extension")

    def __init__(self, domain):
        from sympy.polys.domains.domain import Domain

        if not isinstance(domain, Domain):
            raise InvalidRunError(f"a coefficient field wraps a sympy domain (QQ, QQ.frac_field(a), "
                                  f"QQ.algebraic_field(theta)), got {type(domain).__name__}")
        fraction = bool(getattr(domain, "is_FractionField", False))
        ground = domain.domain if fraction else domain
        if not (ground.is_QQ or ground.is_ZZ or ground.is_AlgebraicField):
            raise InvalidRunError(f"coefficient domain {domain} is not QQ, QQ(parameters), an algebraic number field "
                                  "QQ(theta) or QQ(theta)(parameters)")
        #: the sympy domain
        self.domain = domain
        #: ``QQ`` (or ``ZZ`` for a ring of integral polynomials) or ``QQ<theta>``: the field without parameters
        self.ground = ground
        #: the parameters, in the domain's (lexicographic) order
        self.parameters = tuple(domain.symbols) if fraction else ()
        #: the adjoined algebraic numbers as given (sympy expressions), ``()`` over ``QQ``
        self.extension = tuple(ground.orig_ext) if ground.is_AlgebraicField else ()

    @classmethod
    def of(cls, domain) -> "CoefficientField":
        """The field of a sympy domain (``QQ``, ``ZZ``, ``QQ.frac_field(..)``, ``QQ.algebraic_field(..)`` ...)."""
        return domain if isinstance(domain, cls) else cls(domain)

    @classmethod
    def recognise(cls, domain):
        """:meth:`of`, or ``None`` when ``domain`` is none of the four fields (sympy's ``EX``, a polynomial ring)."""
        if isinstance(domain, cls):
            return domain
        ground = domain.domain if getattr(domain, "is_FractionField", False) else domain
        if not (getattr(ground, "is_QQ", False) or getattr(ground, "is_ZZ", False)
                or getattr(ground, "is_AlgebraicField", False)):
            return None
        return cls(domain)

    def __eq__(self, other):
        return isinstance(other, CoefficientField) and self.domain == other.domain

    def __hash__(self):
        return hash(("CoefficientField", self.domain))

    def __repr__(self):
        return f"CoefficientField({self.domain})"

    # -- which field --------------------------------------------------------------------
    @property
    def is_rational(self) -> bool:
        """``QQ`` itself (no parameters, no extension)."""
        return self.domain.is_QQ

    @property
    def is_rational_functions(self) -> bool:
        """``QQ(params)``: rational functions over ``QQ`` (the fraction-pair elimination's field)."""
        return bool(self.parameters) and self.ground.is_QQ

    @property
    def is_algebraic(self) -> bool:
        """An algebraic number field adjoined (with or without parameters)."""
        return self.ground.is_AlgebraicField

    @property
    def is_number_field(self) -> bool:
        """``QQ`` or ``QQ(theta)`` without parameters: the elimination's entries are numbers (its cost has no
        polynomial gcds)."""
        return not self.parameters and (self.ground.is_QQ or self.ground.is_AlgebraicField)

    @property
    def lexicographic(self) -> bool:
        """The parameters' polynomials are ordered lexicographically (the order of the flint pairs' normal form)."""
        return not self.parameters or str(self.domain.field.ring.order) == "lex"

    # -- python-flint ------------------------------------------------------------------------
    def flint_context(self):
        """flint's ``fmpz_mpoly_ctx`` of ``ZZ[params]`` (lexicographic, the parameters in the field's order) for
        ``QQ(params)``, in which :mod:`nambu_bch.algebra.frac_rref` keeps its fraction pairs; ``None`` for the
        other fields (no flint counterpart).  The caller decides whether python-flint is used
        (:func:`nambu_bch.algebra._flint.available`)."""
        if not (self.is_rational_functions and self.lexicographic):
            return None
        return _flint.fmpz_mpoly_context(len(self.parameters))

    # -- elements --------------------------------------------------------------------------
    def convert(self, value):
        """An exact number (``int``, sympy ``Rational``, algebraic number in the extension) or a sympy expression in
        the parameters as an element of the domain."""
        if isinstance(value, int):
            return self.domain.convert(value)
        return self.domain.from_sympy(value)

    def to_sympy(self, element):
        """An element of the domain as a sympy expression (for printing)."""
        return self.domain.to_sympy(element)


def number_field(numbers) -> tuple:
    """``(K, elements)``: the smallest of ``ZZ``, ``QQ``, ``QQ(theta)`` holding the exact numbers, and them in it.

    sympy's ``construct_domain(numbers, extension=True)``: for algebraic numbers a primitive element ``theta`` of
    ``QQ(a_1, ..., a_k)`` and each ``a_i`` as a polynomial in ``theta`` (sympy's ``primitive_element``,
    ``to_number_field``), 10-100 ms for the triple jump's coefficients in ``QQ(2^(1/3))``.  The same few coefficient
    tuples (those of a composition) are asked for again by every order analysis, error constant and backward error
    analysis of that composition, so the answer is memoised per tuple (:func:`nambu_bch.clear_caches` empties it);
    ``elements`` is a new list each call.  Internal: the numbers are the package's own exact sympy numbers (a
    composition's coefficients), never user text.

    >>> import sympy
    >>> K, (a, b) = number_field([sympy.Rational(1, 2), sympy.cbrt(2) / 3])
    >>> K, K.to_sympy(b) == sympy.cbrt(2) / 3
    (QQ<2**(1/3)>, True)

    References
    ----------
    Cohen, *A Course in Computational Algebraic Number Theory*, Sect. 4.5 (a primitive element of a compositum).
    """
    numbers = tuple(numbers)
    try:
        hash(numbers)
    except TypeError:  # not sympy numbers: construct_domain decides, unmemoised
        return _construct(numbers)
    K, elements = _number_field(numbers)
    return K, list(elements)


def _construct(numbers: tuple) -> tuple:
    from sympy.polys.constructor import construct_domain

    return construct_domain(list(numbers), extension=True)


@lru_cache(maxsize=256)
def _number_field(numbers: tuple) -> tuple:
    K, elements = _construct(numbers)
    return K, tuple(elements)
