"""Vector fields as first-order differential operators X = X^i d/dx_i.

Convention (the paper's, Eqs. CL1 and CL2): the Lie bracket of two fields is
their commutator *as operators*, ``[X, Y] f = X(Y f) - Y(X f)``, so that
``[X, Y]^i = X(Y^i) - Y(X^i)`` and, for Hamiltonian fields,
``[X_A, X_B] = X_{{B,A}}`` (Eq. CL1).

Components are exact ring elements when the field is polynomial
(see :mod:`nambu_bch.algebra.polynomial`) and general sympy expressions
otherwise; the operations are the same for both.
"""

from __future__ import annotations

import sympy

from ..checks import check_type, show
from ..errors import NambuBCHError
from .ring import ExactRing, check_ring


class VectorField:
    """A vector field on the coordinates of ``algebra``.

    Parameters
    ----------
    algebra : PolynomialAlgebra or FlintRing
    components : sequence
        ``X^i``, one per coordinate, as sympy expressions or ring elements.

    Examples
    --------
    >>> import sympy
    >>> x1, x2 = sympy.symbols("x1 x2")
    >>> from nambu_bch.algebra import PolynomialAlgebra
    >>> A = PolynomialAlgebra([x1, x2])
    >>> X = VectorField(A, [x2, 0]); Y = VectorField(A, [0, -x1])
    >>> X.bracket(Y).to_sympy()
    (x1, -x2)
    """

    __slots__ = ("algebra", "components")

    def __init__(self, algebra: ExactRing, components):
        check_ring(algebra, "algebra")
        if isinstance(components, (str, bytes, dict)) or not hasattr(components, "__iter__"):
            raise NambuBCHError(f"the components of a vector field are a sequence of expressions, got {show(components)}")
        components = tuple(components)
        if len(components) != algebra.n:
            raise NambuBCHError(
                f"a vector field on {algebra.n} coordinates needs {algebra.n} components, got {len(components)}"
            )
        self.algebra = algebra
        self.components = algebra.common(*(algebra.convert(c) for c in components))

    def __reduce__(self):
        """Pickle as the algebra and the components (ring elements pickle as exponent tuples and exact coefficients)."""
        return _vector_field_from, (self.algebra, self.components)

    @classmethod
    def zero(cls, algebra: ExactRing) -> "VectorField":
        return cls(algebra, [algebra.zero] * algebra.n)

    # -- action ---------------------------------------------------------------------
    def apply(self, f):
        """``X f = sum_i X^i df/dx_i`` (``f`` a sympy expression or ring element).

        The arithmetic is the algebra's field backend (:mod:`nambu_bch.algebra.backend`):
        exact polynomials when ``f`` and the components are ring elements, expanded sympy otherwise.
        """
        A = self.algebra
        f, *components = A.common(A.convert(f), *self.components)
        backend = A.ring_backend if A.is_polynomial(f) else A.expression_backend
        return backend.apply(backend.field(components), f)

    __call__ = apply

    def bracket(self, other: "VectorField") -> "VectorField":
        """The commutator ``[self, other]`` as differential operators (Eq. CL1), on the algebra's field backend."""
        other = self._aligned(other)
        A = self.algebra
        parts = A.common(*self.components, *other.components)
        backend = A.ring_backend if A.is_polynomial(parts[0]) else A.expression_backend
        X, Y = backend.field(parts[: A.n]), backend.field(parts[A.n:])
        return VectorField(A, backend.values(backend.bracket(X, Y)))

    def divergence(self):
        """``div X = sum_i dX^i/dx_i`` (zero for every Liouville field)."""
        A = self.algebra
        total = A.zero if all(A.is_polynomial(c) for c in self.components) else sympy.Integer(0)
        for i, c in enumerate(self.components):
            total = total + A.diff(c, i)
        return total

    # -- linear structure -------------------------------------------------------------
    def _aligned(self, other) -> "VectorField":
        """``other`` expressed in this field's algebra (rings differ e.g. by a 2**(1/3) extension)."""
        if not isinstance(other, VectorField) or other.algebra.coordinates != self.algebra.coordinates:
            raise NambuBCHError("vector fields on different coordinates cannot be combined")
        if other.algebra.ring == self.algebra.ring:
            return other
        return VectorField(self.algebra, other.to_sympy())

    def __add__(self, other):
        other = self._aligned(other)
        pairs = (self.algebra.common(a, b) for a, b in zip(self.components, other.components))
        return VectorField(self.algebra, [a + b for a, b in pairs])

    def __neg__(self):
        return VectorField(self.algebra, [-c for c in self.components])

    def __sub__(self, other):
        return self + (-other)

    def scale(self, factor) -> "VectorField":
        """``factor * X`` for a constant factor (number, parameter or ring constant)."""
        A = self.algebra
        factor = A.convert(factor)
        return VectorField(self.algebra, [a * b for a, b in (A.common(factor, c) for c in self.components)])

    __rmul__ = scale
    __mul__ = scale

    # -- tests and output ---------------------------------------------------------------
    def is_zero(self) -> bool:
        return all(self.algebra.is_zero(c) for c in self.components)

    def __eq__(self, other):
        if not isinstance(other, VectorField) or other.algebra.coordinates != self.algebra.coordinates:
            return NotImplemented
        return (self - other).is_zero()

    # equality is semantic (the difference simplifies to zero), so no hash can agree with it
    __hash__ = None

    def to_sympy(self) -> tuple:
        return tuple(self.algebra.to_sympy(c) for c in self.components)

    def to_latex(self) -> str:
        parts = []
        for x, c in zip(self.algebra.coordinates, self.to_sympy()):
            if c != 0:
                parts.append(rf"\left({sympy.latex(sympy.factor(c))}\right)\frac{{\partial}}{{\partial {sympy.latex(x)}}}")
        return " + ".join(parts) if parts else "0"

    def _repr_latex_(self):
        return f"${self.to_latex()}$"

    def __repr__(self):
        return f"VectorField({self.to_sympy()})"


def _vector_field_from(algebra, components) -> VectorField:
    """The field :meth:`VectorField.__reduce__` described (components already in the algebra's representation)."""
    X = object.__new__(VectorField)
    X.algebra, X.components = algebra, tuple(components)
    return X


def lie_bracket(X: VectorField, Y: VectorField) -> VectorField:
    """``[X, Y] = XY - YX`` as differential operators (Eq. CL1 convention)."""
    check_type(X, VectorField, "X")
    check_type(Y, VectorField, "Y")
    return X.bracket(Y)
