"""The modified equation of a Runge--Kutta method on a polynomial system, exactly, and its shadow question.

For ``y' = f(y)`` and a Runge--Kutta method (:mod:`nambu_bch.integrators.runge_kutta`) the
numerical map is the B-series ``B(Phi, y)``; its modified field (backward error analysis,
Hairer--Lubich--Wanner Sects. IX.1 and IX.9) is::

    f~ = f + h f_2 + h^2 f_3 + ...,   f_{j+1} = sum_{|t| = j+1} b(t)/sigma(t) F(t),

with ``b`` from :func:`~nambu_bch.bseries.rooted_trees.modified_coefficients` and the elementary
differentials ``F(t)`` (HLW Sect. III.1: ``F(•) = f``, ``F([t_1..t_m]) = f^(m)(F(t_1), .., F(t_m))``)
computed on the package's exact polynomial ring.  :func:`modified_equation_by_taylor` is the
independent route: the stages are solved as power series in ``h`` by fixed-point iteration, and
the map's series goes through the same backward error analysis as a composition
(:func:`~nambu_bch.bch.backward.modified_field_of_map`).

:func:`runge_kutta_shadow` asks the direct route (:func:`~nambu_bch.shadow.direct_route.direct_route`)
whether ``f~ = X_{H_S, G_S}`` order by order.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from ..algebra import VectorField
from ..bch.backward import FieldSeries, check_order, modified_field_of_map
from ..values import ValueEquality
from ..errors import InvalidCompositionError, NambuBCHError
from ..integrators.runge_kutta import butcher_tableau
from . import rooted_trees as T

H = sympy.Symbol("h")
#: Highest order accepted (bounded work): h^8 needs the 286 trees of 9 vertices; each further order multiplies
#: the trees by about 2.7, and the elementary differentials' work more.
MAX_RK_ORDER = 8


@dataclass(frozen=True, eq=False)
class ModifiedEquation(FieldSeries, ValueEquality):
    """``f~ = sum_{j=0}^{order} h^j Z_j`` of a Runge--Kutta method on a system (``Z_0 = f``).

    Attributes
    ----------
    coefficients : tuple of VectorField, ``Z_0 .. Z_order``
    order : int
    method : the method's tableau (:class:`nambu_bch.integrators.runge_kutta.ButcherTableau`)
    system : System
    tree_coefficients : dict ``{tree: b(tree)}`` (HLW's normalisation, ``b(•) = 1``), trees up to ``order + 1`` vertices
        (empty for a partitioned pair, whose field comes from the Taylor route)
    """

    coefficients: tuple
    order: int
    method: object
    system: object
    tree_coefficients: dict

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the ``Z_j`` as ring elements, the tableau, the system, the ``b(tree)``."""
        return self.coefficients, self.order, self.method, self.system, self.tree_coefficients


    def to_text(self) -> str:
        """``f~ = Z_0 + h*Z_1 + ... + O(h^(order+1))``, one line per non-zero ``Z_j``."""
        used = [j for j, Z in enumerate(self.coefficients) if not Z.is_zero()]
        head = " + ".join(("" if j == 0 else "h*" if j == 1 else f"h**{j}*") + f"Z_{j}" for j in used) or "0"
        lines = [f"Z_{j} = ({', '.join(str(c) for c in self.coefficients[j].to_sympy())})" for j in used]
        return "\n".join([f"modified field of {self.method.name}: f~ = {head} + O(h^{self.order + 1})", *lines])

    def __repr__(self):
        return f"ModifiedEquation({self.method.name!r}, order={self.order}, system={self.system.name!r})"


def _polynomial_field(system, tableau):
    """The system's field ``f`` as ring elements, checked against what the tableau can represent."""
    f = system.vector_field
    if not all(f.algebra.is_polynomial(c) for c in f.components):
        raise NambuBCHError(f"the modified equation of a Runge-Kutta method needs a polynomial vector field; "
                            f"{system.name} has {f.to_sympy()}")
    if tableau.quadratic_only:
        n = f.algebra.n
        degree = max((sum(m[:n]) for c in f.components for m in c.keys()), default=0)
        if degree > 2:
            raise InvalidCompositionError(
                f"{tableau.name!r} is a Runge-Kutta method only on quadratic vector fields; the field of {system.name} "
                f"has degree {degree}")
    return f


def elementary_differentials(field: VectorField, upto: int) -> dict:
    """``{t: F(t)}`` (tuples of ring elements) for every tree with at most ``upto`` vertices (HLW Sect. III.1).

    ``f^(m)(v_1, .., v_m)^k = sum_{i_1..i_m} d^m f^k / dx_{i_1}..dx_{i_m} v_1^{i_1} .. v_m^{i_m}``: the
    derivatives act on ``f`` only, each partial derivative computed once.
    """
    ordered = [t for m in range(1, upto + 1) for t in T.trees(m)]
    return differentials(field.algebra, {None: field.components}, ordered, lambda t: (None, t))


def differentials(algebra, parts: dict, ordered, split) -> dict:
    """``{t: F(t)}`` for the trees ``ordered`` (children before parents): ``F(t) = f_c^(m)(F(t_1), .., F(t_m))`` with
    ``(c, (t_1, .., t_m)) = split(t)`` and ``f_c = parts[c]`` (the components of one field).

    One field (``parts = {None: f}``) gives the elementary differentials of B-series; one field per colour those of
    P-series (HLW Sect. III.2), each partial derivative of each ``f_c`` computed once.
    """
    n, zero = algebra.n, algebra.zero
    partial: dict = {}

    def derivative(c, k, index):
        key = (c, k, index)
        value = partial.get(key)
        if value is None:
            value = parts[c][k] if not index else algebra.diff(derivative(c, k, index[:-1]), index[-1])
            partial[key] = value
        return value

    def contract(c, k, vectors, index):
        if not vectors:
            return derivative(c, k, tuple(sorted(index)))
        total = zero
        for i in range(n):
            if vectors[0][i]:
                inner = contract(c, k, vectors[1:], index + (i,))
                if inner:
                    total = total + vectors[0][i] * inner
        return total

    out: dict = {}
    for t in ordered:
        c, children = split(t)
        vectors = [out[child] for child in children]
        out[t] = tuple(contract(c, k, vectors, ()) if parts[c][k] else zero for k in range(n))
    return out


def modified_equation(system, method, order: int = 2) -> ModifiedEquation:
    """The modified field ``f~ = f + h f_2 + ...`` of a Runge--Kutta method through ``h**order``, exactly (B-series).

    Parameters
    ----------
    system : System or model name (a polynomial vector field)
    method : name of :data:`~nambu_bch.integrators.runge_kutta.TABLEAUX` (``"midpoint"``, ``"gauss4"``,
        ``"kahan"`` ...) or a :class:`~nambu_bch.integrators.runge_kutta.ButcherTableau`; or a partitioned pair
        (:data:`~nambu_bch.integrators.runge_kutta.PARTITIONED`, ``"lobatto-iiia-iiib-3"``) on a canonical system,
        expanded by the Taylor route (:func:`modified_equation_by_taylor`; ``tree_coefficients`` is then empty; the
        P-series route, :func:`~nambu_bch.bseries.p_series.p_series_modified_equation`, gives the same field with the
        bi-coloured trees' coefficients)
    order : int -- the highest power of ``h`` kept, at most :data:`MAX_RK_ORDER`

    Examples
    --------
    >>> from nambu_bch import model
    >>> M = modified_equation(model("ho"), "midpoint", 2)
    >>> M[2].to_sympy()      # 1/12 f'f'f (f'' = 0): HLW IX.1
    (-omega**2*x2/(12*m), m*omega**4*x1/12)
    """
    from ..systems.spec import as_system

    system = as_system(system)
    pair = _partitioned(method)
    if pair is not None:  # the Taylor route: faster here than the P-series (the same exact field, tested)
        order = check_order(order, MAX_RK_ORDER)
        return ModifiedEquation(tuple(modified_equation_by_taylor(system, pair, order)), order, pair, system, {})
    tableau = butcher_tableau(method)
    order = check_order(order, MAX_RK_ORDER)
    f = _polynomial_field(system, tableau)
    alg = f.algebra
    b = T.modified_coefficients(T.rk_coefficients(tableau, order + 1), order + 1)
    F = elementary_differentials(f, order + 1)
    coefficients = series_fields(alg, b, F, T.trees, T.symmetry, order, tableau.name, "B-series")
    return ModifiedEquation(tuple(coefficients), order, tableau, system, b)


def series_fields(alg, b, F, trees, symmetry, order, name, kind) -> list:
    """``[f_1, ..., f_(order+1)]``: ``f_j = sum_{|t| = j} b(t) / sigma(t) F(t)``, the modified field's coefficient of
    ``h^(j-1)`` from the series coefficients ``b`` and the elementary differentials ``F`` (B- or P-series, HLW IX.1,
    IX.10); rational coefficients only."""
    coefficients = []
    for j in range(order + 1):
        comps = [alg.zero] * alg.n
        for t in trees(j + 1):
            value = b.get(t, 0)
            if value == 0:
                continue
            if not value.is_rational:
                raise NambuBCHError(f"the modified equation of {name!r} has the irrational coefficient {value} "
                                    f"(tree {t}); only rational {kind} coefficients are supported")
            scale = alg.domain.convert(value / symmetry(t))
            comps = [c + scale * e for c, e in zip(comps, F[t])]
        coefficients.append(VectorField(alg, comps))
    return coefficients


def modified_equation_by_taylor(system, method, order: int = 2) -> tuple:
    """``Z_0 .. Z_order`` by expanding the Runge--Kutta step in ``h`` and backward error analysis of the map.

    The independent check of :func:`modified_equation`: the stages ``Y_i = y + h sum_j a_ij f(Y_j)`` are
    solved as polynomials in ``h`` truncated after ``h^(order+1)`` by ``order + 1`` fixed-point sweeps
    (each gains one power of ``h``), the step ``y + h sum_i b_i f(Y_i)`` is read off, and
    :func:`~nambu_bch.bch.backward.modified_field_of_map` gives the field (HLW Sect. IX.1).
    Radicals of the tableau (Gauss methods) are adjoined to the coefficient field for the expansion.
    A partitioned pair (:data:`~nambu_bch.integrators.runge_kutta.PARTITIONED`) integrates the ``q`` components
    with its first tableau and the ``p`` components with its second (HLW Sect. II.2), on a canonical system.
    """
    from ..systems.spec import as_system

    system = as_system(system)
    order = check_order(order, MAX_RK_ORDER)
    pair = _partitioned(method)
    if pair is not None:
        d = _canonical_half(system, pair)
        f = _polynomial_field(system, pair.q)
        per_coordinate = [pair.q] * d + [pair.p] * d
    else:
        tableau = butcher_tableau(method)
        f = _polynomial_field(system, tableau)
        per_coordinate = [tableau] * f.algebra.n
    return _taylor_route(f, per_coordinate, order)


def _partitioned(method):
    """The partitioned pair ``method`` names, or None when it names (or is) a plain tableau."""
    from ..integrators.runge_kutta import PARTITIONED, PartitionedTableau, partitioned_tableau

    if isinstance(method, PartitionedTableau) or (isinstance(method, str) and method in PARTITIONED):
        return partitioned_tableau(method)
    return None


def _canonical_half(system, pair) -> int:
    """``d`` for a canonical system on ``2d`` coordinates (``q`` the first ``d``); refuses any other system."""
    if system.bracket != "canonical":
        raise InvalidCompositionError(
            f"{pair.name!r} is a partitioned method for canonical systems (q' = dH/dp, p' = -dH/dq); {system.name} "
            f"has the {system.bracket} bracket")
    return system.N // 2


def _taylor_route(f, per_coordinate, order):
    """The Taylor expansion of the step with the tableau ``per_coordinate[k]`` for component ``k``, then backward
    error analysis (all tableaux with the same number of stages)."""
    base = f.algebra
    top = order + 1
    numbers = [x for t in set(per_coordinate) for row in t.A for x in row] + [x for t in set(per_coordinate)
                                                                              for x in t.b]
    radicals = sorted({p for x in numbers for p in x.atoms(sympy.Pow) if not p.exp.is_integer}, key=str)
    alg = base.with_constants(extension=radicals) if radicals else base
    n = alg.n
    h_index = n + alg.constants.index(H)
    gens = alg.ring.gens
    fields = [alg.convert(base.to_sympy(c)) if radicals else c for c in f.components]
    hgen = gens[h_index]

    def cut(p):
        return alg.ring.from_dict({m: c for m, c in p.items() if m[h_index] <= top}) if p else p

    A = [[[alg.domain.from_sympy(a) for a in row] for row in t.A] for t in per_coordinate]
    B = [[alg.domain.from_sympy(x) for x in t.b] for t in per_coordinate]
    s = per_coordinate[0].stages
    coords = list(gens[:n])
    Y = [list(coords) for _ in range(s)]
    for _ in range(top):
        K = [_compose_cut(fields, Yi, h_index, top, alg.ring) for Yi in Y]
        Y = [[cut(coords[k] + hgen * sum((A[k][i][j] * K[j][k] for j in range(s)), alg.zero)) for k in range(n)]
             for i in range(s)]
    K = [_compose_cut(fields, Yi, h_index, top, alg.ring) for Yi in Y]
    step = [cut(coords[k] + hgen * sum((B[k][i] * K[i][k] for i in range(s)), alg.zero)) for k in range(n)]
    pulled = []
    for p in step:
        series = [{} for _ in range(top + 1)]
        for m, c in p.items():
            series[m[h_index]][m[:h_index] + (0,) + m[h_index + 1:]] = c
        if radicals:  # the coefficients are rational again: back to the system's ring
            pulled.append([base.convert(alg.to_sympy(alg.ring.from_dict(t))) if t else base.zero for t in series])
        else:
            pulled.append([alg.ring.from_dict(t) if t else alg.zero for t in series])
    return modified_field_of_map(base.ring_backend, pulled, order)


def _compose_cut(fields, values, h_index, top, ring) -> list:
    """``[f(values) mod h^(top+1) for f in fields]``: the first ``len(values)`` generators replaced by ``values``.

    The same polynomials as ``f.compose(...)`` truncated after ``h^top`` (the powers of ``h`` are non-negative, so
    a product's terms below the cut come from its factors' terms below the cut), but each power ``values[k]**e``
    is formed once for all the fields and monomials, and every product skips the pairs of terms above the cut:
    ``compose`` rebuilds every power for every monomial at full length, which over ``QQ(sqrt(3))`` (Gauss4) was
    most of the Taylor route's time.
    """
    n = len(values)
    zero = ring.domain.zero

    def mul_cut(a, b):
        out: dict = {}
        for ma, ca in a.items():
            room = top - ma[h_index]
            for mb, cb in b.items():
                if mb[h_index] <= room:
                    m = tuple(x + y for x, y in zip(ma, mb))
                    out[m] = out.get(m, zero) + ca * cb
        return ring.from_dict({m: c for m, c in out.items() if c})

    powers = [[ring.one] for _ in range(n)]

    def power(k, e):
        while len(powers[k]) <= e:
            powers[k].append(mul_cut(powers[k][-1], values[k]))
        return powers[k][e]

    result = []
    for f in fields:
        total = ring.zero
        for monom, coeff in f.items():
            if monom[h_index] > top:
                continue
            term = ring.from_dict({(0,) * n + tuple(monom[n:]): coeff})
            for k in range(n):
                if monom[k]:
                    term = mul_cut(term, power(k, monom[k]))
            total += term
        result.append(total)
    return result


def runge_kutta_shadow(system, method, order: int = 2, degree=None, max_unknowns=None):
    """Whether the modified field of a Runge--Kutta method is ``X_{H_S, G_S}`` order by order (the direct route).

    Returns the :class:`~nambu_bch.shadow.direct_route.DirectResult` of
    :func:`~nambu_bch.shadow.direct_route.direct_route` run on :func:`modified_equation`: ``.exists``,
    ``.shadow()`` (``H_S, G_S`` in ``h`` and ``alpha``), and per order the solution or the certificate
    of obstruction (``.orders[j - 1].certificate``).
    """
    from ..shadow.direct_route import direct_route
    from ..systems.spec import as_system

    system = as_system(system)
    M = modified_equation(system, method, order)
    return direct_route(system, M.method, M.order, degree=degree, max_unknowns=max_unknowns, progress=False,
                        effective=M)
