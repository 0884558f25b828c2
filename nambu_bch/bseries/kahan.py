"""Kahan's method on a quadratic vector field as an exact birational map; the Euler top's closed forms.

On a quadratic field ``f`` Kahan's method ``(x' - x)/h = Q(x, x') + B (x + x')/2 + c`` (the polarised field)
is the linearly implicit map (its Rosenbrock form, Celledoni--McLachlan--Owren--Quispel 2013)::

    x' = x + h (I - h/2 f'(x))^{-1} f(x) = P(x) / Delta(x),   Delta = det(I - h/2 f'(x)),
    P = Delta x + h adj(I - h/2 f'(x)) f(x)

(Cramer's rule), a rational map with polynomial numerators.  Every identity about it is checked here with the
denominators cleared, as an identity of polynomials in ``x``, the parameters and ``h``: equality of sparse
polynomials is a normal form, so nothing is decided by simplification.

* ``F`` is an integral ``N/D`` of the map iff ``N(x') D(x) = N(x) D(x')``, i.e. with homogenisation
  ``N^(P, Delta) D Delta^{deg D} = N D^(P, Delta) Delta^{deg N}`` (:meth:`KahanMap.keeps_ratio`);
* the map keeps the measure ``dx / phi(x)`` iff ``det DPhi(x) = phi(x') / phi(x)``.  With
  ``DPhi_ij = (Delta d_j P_i - P_i d_j Delta) / Delta^2 =: Q_ij / Delta^2`` this reads
  ``det Q * phi * Delta^{deg phi} = phi^(P, Delta) * Delta^{2n}`` (:meth:`KahanMap.keeps_measure`).

For the Euler top ``x1' = a1 x2 x3, x2' = a2 x3 x1, x3' = a3 x1 x2`` (Kahan; Hirota--Kimura) the map keeps the
three ratios ``(a_j x_i^2 - a_i x_j^2) / (1 - h^2/4 a_i a_j x_k^2)`` ((i j k) cyclic; any two are independent)
and the measure ``dx / (D_1 D_2)`` with ``D_k = 1 - h^2/4 a_i a_j x_k^2``: :func:`euler_top_closed_forms`.

The closed forms are checked against the map itself (exactly, in the test suite), not against a printed page. The
integrals are the Hirota--Kimura ones; the measure was found here (an ansatz of products of the ``D_k``, then
checked exactly). Celledoni--McLachlan--Owren--Quispel prove invariant measures for Kahan maps of Hamiltonian fields
with a *constant* Poisson structure, which the Euler top's Lie--Poisson bracket is not; Celledoni et al. (2019)
compute measures of Kahan maps by discrete Darboux polynomials.

References
----------
E. Celledoni, R. I. McLachlan, B. Owren, G. R. W. Quispel, *Geometric properties of Kahan's method*,
J. Phys. A 46 (2013) 025201 (the Runge--Kutta and Rosenbrock forms, invariant measures and modified integrals);
E. Celledoni, C. Evripidou, D. I. McLaren, B. Owren, G. R. W. Quispel, B. K. Tapley, *Detecting and determining
preserved measures and integrals of birational maps* (arXiv:1902.04685);
R. Hirota, K. Kimura, *Discretization of the Euler top*, J. Phys. Soc. Japan 69 (2000) 627;
M. Petrera, Y. B. Suris, *On the Hamiltonian structure of Hirota--Kimura discretization of the Euler top*
(arXiv:0707.4382), where the integrals of the discrete Euler top are written as such ratios.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from ..algebra import PolynomialAlgebra, VectorField
from ..checks import show
from ..errors import InvalidCompositionError, NambuBCHError

H = sympy.Symbol("h")
#: Largest dimension accepted: the determinant is expanded by minors (n! products).
MAX_KAHAN_DIMENSION = 6


def _degree_in_coordinates(p, n: int) -> int:
    return max((sum(m[:n]) for m in p.keys()), default=0)


def _det(M, zero):
    """Determinant by expansion along the first row (exact ring arithmetic; n <= MAX_KAHAN_DIMENSION)."""
    n = len(M)
    if n == 1:
        return M[0][0]
    total = zero
    for j in range(n):
        if M[0][j]:
            minor = [row[:j] + row[j + 1:] for row in M[1:]]
            term = M[0][j] * _det(minor, zero)
            total = total + term if j % 2 == 0 else total - term
    return total


def _adjugate(M, zero, one):
    n = len(M)
    if n == 1:
        return [[one]]
    out = [[zero] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            minor = [row[:j] + row[j + 1:] for k, row in enumerate(M) if k != i]
            c = _det(minor, zero)
            out[j][i] = c if (i + j) % 2 == 0 else -c
    return out


@dataclass(frozen=True, eq=False)
class KahanMap:
    """Kahan's map ``x -> x' = P(x)/Delta(x)`` of a quadratic field, exactly (polynomials in ``x``, parameters, ``h``).

    Attributes
    ----------
    algebra : PolynomialAlgebra -- with the constant ``h``
    field : VectorField -- ``f``
    numerators : tuple -- ``P_1 .. P_n``
    denominator : ``Delta = det(I - h/2 f'(x))``
    """

    algebra: PolynomialAlgebra
    field: VectorField
    numerators: tuple
    denominator: object

    def pullback(self, p):
        """``(p^(P, Delta), deg p)``: ``p(x') = p^(P, Delta) / Delta^{deg p}`` with ``deg`` the degree in ``x``."""
        alg = self.algebra
        n = alg.n
        p = alg.convert(p)
        if not alg.is_polynomial(p):
            raise NambuBCHError(f"a polynomial in {alg.coordinates} and h is needed here, got {p}")
        d = _degree_in_coordinates(p, n)
        gens = alg.ring.gens
        total = alg.zero
        powers: dict = {}

        def power(base, k, key):
            value = powers.get(key)
            if value is None:
                value = base ** k
                powers[key] = value
            return value

        for m, c in p.items():
            term = alg.ring.from_dict({(0,) * len(m): c})
            for i in range(len(m)):
                if i < n:
                    term = term * power(self.numerators[i], m[i], (i, m[i]))
                elif m[i]:
                    term = term * gens[i] ** m[i]
            total = total + term * power(self.denominator, d - sum(m[:n]), ("D", d - sum(m[:n])))
        return total, d

    def keeps_ratio(self, numerator, denominator) -> bool:
        """Whether ``N/D`` is an integral of the map: ``N(x') D(x) = N(x) D(x')`` with denominators cleared."""
        alg = self.algebra
        N, D = alg.convert(numerator), alg.convert(denominator)
        Np, dn = self.pullback(N)
        Dp, dd = self.pullback(D)
        return Np * D * self.denominator ** dd == N * Dp * self.denominator ** dn

    def jacobian_determinant(self) -> tuple:
        """``(det Q, Delta^{2n})`` with ``det DPhi = det Q / Delta^{2n}``, ``Q_ij = Delta d_j P_i - P_i d_j Delta``."""
        alg = self.algebra
        n, Dl = alg.n, self.denominator
        dD = [alg.diff(Dl, j) for j in range(n)]
        Q = [[Dl * alg.diff(P, j) - P * dD[j] for j in range(n)] for P in self.numerators]
        return _det(Q, alg.zero), Dl ** (2 * n)

    def keeps_measure(self, phi) -> bool:
        """Whether the map keeps ``dx / phi(x)``: ``det DPhi(x) phi(x) = phi(x')`` with denominators cleared."""
        alg = self.algebra
        phi = alg.convert(phi)
        detQ, den = self.jacobian_determinant()
        image, d = self.pullback(phi)
        return detQ * phi * self.denominator ** d == image * den

    def __call__(self, point: dict) -> tuple:
        """The image of a point given as ``{symbol: exact number}`` for the coordinates, parameters and ``h``."""
        alg = self.algebra
        symbols = (*alg.coordinates, *alg.parameters, *alg.constants)
        if not isinstance(point, dict) or any(s not in point for s in symbols):
            raise NambuBCHError(f"a point must give exact numbers for {', '.join(map(str, symbols))}, got {show(point)}")
        try:
            values = {s: sympy.sympify(point[s], strict=True) for s in symbols}
        except sympy.SympifyError:
            raise NambuBCHError(f"a point must give exact numbers (int, Fraction, sympy Rational), got {show(point)}") from None
        if not all(v.is_number for v in values.values()):
            raise NambuBCHError(f"a point must give exact numbers, got {show(point)}")

        def at(p):
            return alg.to_sympy(p).subs(values, simultaneous=True)

        Dl = at(self.denominator)
        if Dl == 0:
            raise NambuBCHError(f"Kahan's map is not defined at {show(point)}: det(I - h/2 f'(x)) = 0 there")
        return tuple(at(P) / Dl for P in self.numerators)


def kahan_map(field: VectorField) -> KahanMap:
    """Kahan's map of the quadratic field ``field`` as ``x' = P/Delta`` (``h`` adjoined to the algebra if absent).

    ``x' = x + h (I - h/2 f'(x))^{-1} f(x)`` (Celledoni--McLachlan--Owren--Quispel 2013), by Cramer's rule:
    ``Delta = det(I - h/2 f'(x))``, ``P = Delta x + h adj(I - h/2 f'(x)) f(x)``.
    """
    if not isinstance(field, VectorField):
        raise NambuBCHError(f"kahan_map needs a VectorField, got {type(field).__name__}")
    alg = field.algebra
    if not all(alg.is_polynomial(c) for c in field.components):
        raise NambuBCHError(f"Kahan's method needs a polynomial field, got {field.to_sympy()}")
    if H not in alg.constants:  # h becomes the last generator: the exponents gain a trailing 0
        alg = alg.with_constants(H)
        field = VectorField(alg, [alg.ring.from_dict({m + (0,): v for m, v in c.items()}) for c in field.components])
    n = alg.n
    if n > MAX_KAHAN_DIMENSION:
        raise NambuBCHError(f"kahan_map expands determinants by minors; at most {MAX_KAHAN_DIMENSION} coordinates, "
                            f"got {n}")
    degree = max((_degree_in_coordinates(c, n) for c in field.components), default=0)
    if degree > 2:
        raise InvalidCompositionError(f"Kahan's method is defined here for quadratic vector fields; the field has "
                                      f"degree {degree}")
    h = alg.ring.gens[n + alg.constants.index(H)]
    half = alg.domain.convert(sympy.Rational(1, 2))
    M = [[(alg.ring.one if i == j else alg.zero) - half * h * alg.diff(field.components[i], j) for j in range(n)]
         for i in range(n)]
    Dl = _det(M, alg.zero)
    adj = _adjugate(M, alg.zero, alg.ring.one)
    x = alg.ring.gens[:n]
    P = tuple(Dl * x[i] + h * sum((adj[i][j] * field.components[j] for j in range(n)), alg.zero) for i in range(n))
    return KahanMap(alg, field, P, Dl)


@dataclass(frozen=True, eq=False)
class EulerTopClosedForms:
    """The Euler top's Kahan map and its closed-form invariants (generic coefficients ``a1, a2, a3``).

    Attributes
    ----------
    map : KahanMap -- on ``QQ[x1, x2, x3, a1, a2, a3, h]`` (the ``a_i`` are constants of the algebra)
    integrals : tuple of ``(N_k, D_k)``, ``k = 1, 2, 3`` -- ``N_k = a_j x_i^2 - a_i x_j^2``,
        ``D_k = 1 - h^2/4 a_i a_j x_k^2`` with ``(k i j)`` cyclic (``integrals[0]`` has ``x1`` in its denominator)
    density : ``phi = D_1 D_2`` -- the map keeps ``dx / phi``
    alphas : the symbols ``a1, a2, a3``
    """

    map: KahanMap
    integrals: tuple
    density: object
    alphas: tuple

    def specialise(self, values: dict) -> dict:
        """The closed forms as sympy expressions with ``a_i`` (and others) substituted: ``{"I1".., "phi"}``."""
        alg = self.map.algebra
        out = {f"I{k + 1}": alg.to_sympy(N).subs(values) / alg.to_sympy(D).subs(values)
               for k, (N, D) in enumerate(self.integrals)}
        out["phi"] = alg.to_sympy(self.density).subs(values)
        return out


def euler_top_closed_forms() -> EulerTopClosedForms:
    """Kahan's map of the Euler top ``x_i' = a_i x_j x_k`` with its integrals and invariant measure, exactly.

    The map keeps ``I_k = (a_j x_i^2 - a_i x_j^2) / (1 - h^2/4 a_i a_j x_k^2)`` ((k i j) cyclic: ``I_k`` has
    ``x_k`` in its denominator; the Hirota--Kimura integrals) and the measure ``dx1 dx2 dx3 / (D_1 D_2)``,
    ``D_k = 1 - h^2/4 a_i a_j x_k^2`` (found here; since ``D_1 / D_3`` is a function of the integrals, ``D_2 D_3``
    and ``D_3 D_1`` serve as well).  Each statement is checked exactly by :meth:`KahanMap.keeps_ratio` and
    :meth:`KahanMap.keeps_measure` in the tests.
    """
    x = sympy.symbols("x1 x2 x3")
    a = sympy.symbols("a1 a2 a3")
    alg = PolynomialAlgebra(x, (), (*a, H))
    f = VectorField(alg, [alg.convert(a[0] * x[1] * x[2]), alg.convert(a[1] * x[2] * x[0]),
                          alg.convert(a[2] * x[0] * x[1])])
    K = kahan_map(f)
    integrals = []
    for k, i, j in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        N = alg.convert(a[j] * x[i] ** 2 - a[i] * x[j] ** 2)
        D = alg.convert(1 - H ** 2 / 4 * a[i] * a[j] * x[k] ** 2)
        integrals.append((N, D))
    (_, D1), (_, D2), _ = integrals
    return EulerTopClosedForms(K, tuple(integrals), D1 * D2, a)


def euler_top_coefficients(system) -> tuple:
    """``(a1, a2, a3)`` with ``f = (a1 x2 x3, a2 x3 x1, a3 x1 x2)`` for a system of that form (sympy, exact).

    For the package's ``rigid-body``: ``a1 = (I3 - I2)/(I2 I3)`` and cyclic.
    """
    from ..systems.spec import as_system

    system = as_system(system)
    if system.N != 3:
        raise NambuBCHError(f"an Euler top has three coordinates; {system.name} has {system.N}")
    x = system.coordinates
    f = system.vector_field.to_sympy()
    out = []
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
        a = sympy.cancel(f[i] / (x[j] * x[k]))
        if a.free_symbols & set(x):
            raise NambuBCHError(f"{system.name} is not an Euler top x_i' = a_i x_j x_k: component {i + 1} is {f[i]}")
        out.append(a)
    return tuple(out)


def euler_top_density(system):
    """Kahan's invariant density ``phi = D_1 D_2`` of an Euler-top system, in its coordinates, parameters and ``h``.

    The map keeps ``dx / phi`` (:func:`euler_top_closed_forms`); this is the ``rho`` of the density bracket
    (:func:`nambu_bch.shadow.density_bracket.density_shadow`).
    """
    from ..systems.spec import as_system

    system = as_system(system)
    a = euler_top_coefficients(system)
    E = euler_top_closed_forms()
    values = dict(zip(E.alphas, a))
    values.update(zip(E.map.algebra.coordinates, system.coordinates))
    return sympy.expand(E.map.algebra.to_sympy(E.density).subs(values, simultaneous=True))
