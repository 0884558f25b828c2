"""Shadow Hamiltonians of Poisson splittings by the BCH series on Hamiltonians, for any smooth functions.

When every piece of a splitting is a Hamiltonian field of *one* Poisson bracket,
``X_k = X_{H_k}`` with ``X_F f = P(f, F)``, the map ``F -> X_F`` turns brackets of
functions into commutators of fields: ``[X_A, X_B] = X_{P(B, A)}`` (Eq. CL1; the
Jacobi identity of ``P``).  The formal BCH series of a composition (Eqs. BCH1,
BCH2, any degree), evaluated on the functions ``H_k`` with ``[A, B] -> P(B, A)``,
is then a shadow Hamiltonian:

    H_S = sum_j h^j sum_w c_w P_w(H_1, ..., H_n),    X_{H_S} = X_eff  (order by order).

No ansatz and no linear solve are needed, so ``H_k`` may be any functions
(``cos q``, ``exp(q1 - q2)``, ``1/(1 + q^2)``, or undefined ``T(p)``, ``V(q)``: the
*generic answer* of the paper's Sect. 4 procedure, a polynomial in the derivatives
of ``T`` and ``V``).  The brackets that qualify:

* canonical systems (``N = 2d``, one Hamiltonian, pieces ``T(p)``, ``V(q)``):
  ``P`` = the canonical Poisson bracket (Eq. Poisson);
* Nambu systems split in the first Hamiltonian only (``split="single"``, the
  Lie-Poisson rigid body, Lotka-Volterra): ``P(f, g) = {f, g, H_2, ..., H_{N-1}}``
  is a Poisson bracket (a Nambu bracket with ``N - 2`` fixed slots; Takhtajan 1994,
  Sect. 2), so the pieces ``X_{H_k, G}`` are Hamiltonian for it and ``G_S = G``.

Every result is re-checked: ``X_{H_S}`` against ``X_eff`` from backward error
analysis (:func:`~nambu_bch.bch.backward.effective_field`, no Lie algebra) through
``h^order``, before it is returned.

References
----------
Horikoshi, Sect. 4 (general procedure), Eqs. (CL1), (BCH1), (BCH2), (SHPV1);
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, 2nd ed., Sect. IX.4
(modified equations of splitting methods from the BCH formula) and Sect. III.4.2
(the symmetric BCH formula); Yoshida, Celest. Mech. 56 (1993) 27, Sect. 3.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy

from ..algebra import liouville_field, nambu_bracket, poisson_bracket
from ..algebra.zero import is_zero
from ..bch.backward import check_order, effective_field
from ..bch.evaluation import BracketEvaluator
from ..bch.formal import formal_bch
from ..bch.lyndon import witt_dimension
from ..errors import NambuBCHError, NoExactResultError, ResourceLimitError
from ..integrators.composition import composition_for

H_STEP = sympy.Symbol("h")

#: Largest accepted work estimate of a BCH request on non-polynomial pieces (:func:`bch_work`).  Measured on
#: ``sin(sin(...(x1)))`` nests under position Verlet through the CLI (docs/hardening.md, round two), the time
#: was about 7 s + W / 60 s on a shared machine (W = 82: 9 s, 608: 20 s, 2609: 55 s, 2776: 58 s, 7630: > 120 s),
#: so 4000 is about a minute; W grows 3x-10x per order or nesting level, so the limit is not a fine line.  In the
#: extended exact ring (algebra/extended.py) the same requests are 10x-30x faster, but W also measures the size of
#: the printed answer (8 MB for W = 7633), which the ring does not shrink, so the limit stays.
MAX_BCH_WORK = 4000


def derivative_terms(expr, coordinates, k: int, memo=None) -> int:
    """An estimate, without differentiating, of the number of terms of a ``k``-th derivative of ``expr``.

    Read from the tree: a sum adds its parts' counts; a product takes one factor's derivative per
    way of sharing the ``k`` derivatives among its factors (Leibniz); a function of an argument ``g``
    (``sin(g)``, ``exp(g)``, a non-integer power) has one term per integer partition ``k = k_1 + ...``
    with the product of ``g``'s ``k_i``-th derivatives (Faa di Bruno; terms with the same block sizes
    combine).  A factor free of the coordinates has a single term and no derivative.  Capped at
    ``10**12``.

    >>> x = sympy.Symbol("x1")
    >>> [derivative_terms(sympy.sin(sympy.sin(x)), [x], k) for k in (1, 2, 3, 4)]   # partitions of k
    [1, 2, 3, 5]
    """
    memo = {} if memo is None else memo
    coordinates = tuple(coordinates)
    return _terms(expr, coordinates, k, memo)


_CAP_TERMS = 10**12


def _partitions(k, largest=None):
    """The integer partitions of ``k`` (tuples, parts non-increasing)."""
    largest = k if largest is None else largest
    if k == 0:
        yield ()
        return
    for part in range(min(k, largest), 0, -1):
        for rest in _partitions(k - part, part):
            yield (part, *rest)


def _terms(e, coords, k, memo):
    key = (e, k, coords)
    found = memo.get(key)
    if found is not None:
        return found
    if k == 0:
        count = 1
    elif not e.has(*coords):
        count = 0
    elif e.is_Symbol:
        count = 1 if k == 1 else 0
    elif e.is_Add:
        count = sum(_terms(a, coords, k, memo) for a in e.args)
    elif e.is_Mul:
        # distribute the k derivatives over the factors: the ways of writing k as an ordered sum
        counts = [1] + [0] * k  # counts[j]: terms of a j-th derivative of the factors seen so far
        for a in e.args:
            new = [0] * (k + 1)
            for j in range(k + 1):
                if counts[j]:
                    for i in range(k - j + 1):
                        new[j + i] = min(_CAP_TERMS, new[j + i] + counts[j] * _terms(a, coords, i, memo))
            counts = new
        count = counts[k]
    elif e.is_Pow and e.exp.is_Integer and e.exp > 0 and not e.base.is_number:
        # a polynomial power of g: its derivatives are polynomials in g's derivatives (Faa di Bruno, degree-bounded)
        count = sum(math_prod(_terms(e.base, coords, part, memo) for part in parts)
                    for parts in _partitions(k) if len(parts) <= int(e.exp))
    else:
        # f(g_1, ...): Faa di Bruno in each argument that moves (a Pow b**g counts its base and exponent)
        moving = [a for a in e.args if a.has(*coords)]
        count = 0
        for g in moving:
            count += sum(math_prod(_terms(g, coords, part, memo) for part in parts) for parts in _partitions(k))
    count = min(_CAP_TERMS, count)
    memo[key] = count
    return count


def math_prod(values):
    out = 1
    for v in values:
        out = min(_CAP_TERMS, out * v)
    return out


def bch_work(system, pieces, hams, order: int) -> tuple:
    """``(work, worst piece)``: the size of a BCH request on non-polynomial Hamiltonians, from its input alone.

    ``work = sum_j witt_dimension(pieces, j) * sum_H sum_x derivative_terms(H, x, j)`` over the bracket
    lengths ``j = 1 .. order + 1``: a bracket of ``j`` letters differentiates the pieces up to ``j`` times,
    and there are at most ``witt_dimension(pieces, j)`` of them.  Polynomial Hamiltonians are left out (their
    derivatives only shrink); so the estimate is 0 for polynomial systems.
    """
    coords = system.coordinates
    memo: dict = {}
    work, worst = 0, (0, None)
    for H in hams:
        expr = sympy.sympify(H, strict=True)
        if expr.is_polynomial(*coords):
            continue
        size = 0
        for j in range(1, order + 2):
            terms = sum(derivative_terms(expr, [x], j, memo) for x in coords)
            size = min(_CAP_TERMS, size + witt_dimension(pieces, j) * terms)
        work = min(_CAP_TERMS, work + size)
        worst = max(worst, (size, expr), key=lambda pair: pair[0])
    return work, worst[1]


def check_work(system, pieces: int, hams, order: int) -> int:
    """Refuse, before any work, a BCH request on non-polynomial pieces estimated above :data:`MAX_BCH_WORK`.

    Returns
    -------
    int -- the estimate :func:`bch_work`

    Raises
    ------
    ResourceLimitError
        naming the order, the largest piece, the estimate and the limit.
    """
    work, worst = bch_work(system, pieces, hams, order)
    if work > MAX_BCH_WORK:
        shown = work if work < _CAP_TERMS else "> 10^12"
        piece = str(worst)
        piece = piece if len(piece) <= 60 else piece[:57] + "..."
        raise ResourceLimitError(
            f"{system.name}: the shadow Hamiltonian through h^{order} differentiates {piece} up to {order + 1} times "
            f"in every bracket of the BCH series: about {shown} terms (at most {MAX_BCH_WORK} are accepted, about a "
            "minute; estimated before any work): lower the order or the nesting of functions")
    return work


def poisson_structure(system):
    """``(piece Hamiltonians, fixed Hamiltonians)`` when every piece is ``X_{H_k, fixed...}``, else ``None``.

    Examples
    --------
    >>> from nambu_bch import model
    >>> poisson_structure(model("pendulum"))
    ((x2**2/2, -cos(x1)), ())
    >>> poisson_structure(model("ho3")) is None      # the full split: pieces are sums of X_{A,C}
    True
    """
    splitting = system.splitting
    if system.bracket == "canonical":
        hams = []
        for piece in splitting.pieces:
            if len(piece.terms) != 1 or len(piece.terms[0]) != 1:
                return None
            hams.append(piece.terms[0][0])
        return tuple(hams), ()
    if system.bracket in ("nambu", "lie-poisson") and splitting.kind == "single":
        rest = tuple(system.hamiltonians[1:])
        hams = []
        for piece in splitting.pieces:
            if len(piece.terms) != 1 or tuple(piece.terms[0][1:]) != rest:
                return None
            hams.append(piece.terms[0][0])
        return tuple(hams), rest
    return None


def _extended_ring(system, hams):
    """The extended exact ring of non-polynomial ``hams`` (``None`` for polynomials or atoms the ring refuses)."""
    from ..algebra.extended import extended_ring

    alg = system.algebra
    if all(alg.is_polynomial(alg.convert(H)) for H in hams):
        return None
    return extended_ring(system.coordinates, system.parameters, hams)


def _ring_bracket(ring, fixed):
    """``P(f, g)`` on elements of the extended ring: canonical, or Nambu with the ``fixed`` Hamiltonians' slots."""
    n = ring.n
    if not fixed:
        d = n // 2

        def P(f, g):
            df = [ring.diff(f, i) for i in range(n)]
            dg = [ring.diff(g, i) for i in range(n)]
            total = ring.zero
            for k in range(d):
                total = total + df[k] * dg[k + d] - df[k + d] * dg[k]
            return total
        return P
    fixed_grads = [[ring.diff(G, i) for i in range(n)] for G in fixed]

    def P(f, g):
        return _det([[ring.diff(f, i) for i in range(n)], [ring.diff(g, i) for i in range(n)], *fixed_grads], ring.zero)
    return P


def _bracket(system, fixed):
    alg = system.algebra

    if not fixed:
        def P(f, g):
            return poisson_bracket(alg, f, g) if alg.n > 2 else nambu_bracket(alg, f, g)
    else:
        def P(f, g):
            return nambu_bracket(alg, f, g, *fixed)
    return P


@dataclass
class PoissonShadow:
    """``H_S`` of a Poisson splitting through ``h^order`` (``fixed`` = the unsplit Hamiltonians, kept).

    Attributes
    ----------
    system, composition, order
    series : dict ``j -> expr`` -- the coefficient of ``h^j`` (``series[0] = H``)
    fixed : tuple -- ``(G,)`` for a single-split Nambu system, ``()`` for canonical
    verified_orders : int -- ``X_{H_S}`` equals the backward-error ``X_eff`` through this power
    effective : EffectiveField or None -- the backward-error field of the check when it ran in sympy expressions
        (``None`` when it ran in the extended exact ring, whose field is not converted back)
    """

    system: object
    composition: object
    order: int
    series: dict
    fixed: tuple = ()
    verified_orders: int = -1
    brackets: int = 0
    effective: object = None
    notes: list = field(default_factory=list)

    @property
    def H_S(self):
        return sympy.Add(*(H_STEP**j * c for j, c in sorted(self.series.items())))

    @property
    def shadows(self) -> tuple:
        return (self.H_S, *self.fixed)


def bch_shadow(system, word, order: int = 2, verify: bool = True) -> PoissonShadow:
    """``H_S`` of ``word`` on a Poisson splitting from the BCH series on the pieces' Hamiltonians.

    Parameters
    ----------
    system : System whose pieces are Hamiltonian for one Poisson bracket (:func:`poisson_structure`)
    word : composition spec
    order : int -- highest power of ``h``
    verify : bool -- re-check ``X_{H_S, fixed} = X_eff + O(h^{order+1})`` against backward error analysis

    Returns
    -------
    PoissonShadow

    Raises
    ------
    NambuBCHError
        when the pieces are not Hamiltonian for one bracket (use the direct route).

    Examples
    --------
    >>> from nambu_bch import model
    >>> R = bch_shadow(model("pendulum"), "121", order=2)       # position Verlet
    >>> R.series[2]
    -x2**2*cos(x1)/24 + sin(x1)**2/12
    """
    order = check_order(order)
    structure = poisson_structure(system)
    if structure is None:
        raise NambuBCHError(
            f"{system.name}: the pieces of the {system.splitting.kind} splitting are not Hamiltonian fields of one Poisson "
            "bracket (accepted: canonical T|V splits, or Nambu systems with split='single'); use the direct route")
    hams, fixed = structure
    comp = composition_for(word, system.splitting)
    check_work(system, len(hams), (*hams, *fixed), order)
    alg = system.algebra
    ring = _extended_ring(system, (*hams, *fixed))
    frac = None if ring is not None else _FractionBackend.make(system, (*hams, *fixed))
    if ring is not None:  # exp, sin/cos, square roots, quotients: exact polynomial arithmetic in the extended ring
        P, to_sympy = _ring_bracket(ring, [ring.convert(G) for G in fixed]), ring.to_sympy
        leaves = {k + 1: ring.convert(Hk) for k, Hk in enumerate(hams)}
        zero_test = lambda v: not v  # noqa: E731
    elif frac is not None:  # rational Hamiltonians the ring refuses: exact sparse fractions
        P, to_sympy = frac.bracket, frac.to_sympy
        leaves = {k + 1: frac.convert(Hk) for k, Hk in enumerate(hams)}
        zero_test = lambda v: not v  # noqa: E731
    else:
        P, to_sympy = _bracket(system, fixed), alg.to_sympy
        leaves = {k + 1: alg.convert(Hk) for k, Hk in enumerate(hams)}
        zero_test = lambda v: alg.is_zero(v) if alg.is_polynomial(v) else is_zero(v)  # noqa: E731
    # [X_A, X_B] = X_{P(B, A)} (Eq. CL1 with X_F f = P(f, F))
    evaluator = BracketEvaluator(leaves, bracket=lambda A, B: P(B, A), is_zero=zero_test)
    series = formal_bch(comp, order + 1)
    out = {}
    for j in range(order + 1):
        if ring is not None:  # sum in the ring, one conversion per order
            total = ring.zero
            for c, tree in series.terms(j + 1):
                value = evaluator.value(tree)
                if value is not None:
                    total = total + value * ring.scalar(c)
            # expanded, exponentials combined: what _tidy makes of it, except that rational functions are factored
            out[j] = _tidy(to_sympy(total)) if ring.rational else to_sympy(total)
            continue
        total = sympy.Integer(0)
        for c, tree in series.terms(j + 1):
            value = evaluator.value(tree)
            if value is not None:
                total += sympy.sympify(c, strict=True) * to_sympy(value)
        out[j] = _tidy(total)
    result = PoissonShadow(system, comp, order, out, tuple(fixed), brackets=evaluator.brackets_computed)
    if verify:
        check_against_backward(result)
    return result


class _FractionBackend:
    """Rational functions of the coordinates (and parameters) as sparse fractions over QQ.

    Brackets of rational Hamiltonians (``-1/(1 + q^2)``) in sympy trees need ``cancel``
    after every step; in sympy's ``FracField`` they are exact and fast.
    """

    def __init__(self, system, field, gens):
        self.system = system
        self.field = field
        self.gens = gens[: system.N]
        fixed = poisson_structure(system)[1]
        self.fixed_grads = [[f.diff(x) for x in self.gens] for f in (self.convert(F) for F in fixed)]

    @classmethod
    def make(cls, system, exprs):
        symbols = (*system.coordinates, *system.parameters)
        if all(sympy.sympify(e, strict=True).is_polynomial(*system.coordinates) for e in exprs):
            return None  # the polynomial ring is faster still
        if not all(sympy.sympify(e, strict=True).is_rational_function(*symbols) for e in exprs):
            return None
        from sympy.polys.domains import QQ
        from sympy.polys.fields import field

        K, *gens = field(list(symbols), QQ)
        return cls(system, K, gens)

    def convert(self, expr):
        return self.field.from_expr(sympy.sympify(expr, strict=True))

    def to_sympy(self, value):
        return value.as_expr()

    def bracket(self, f, g):
        xs = self.gens
        if not self.fixed_grads:
            d = len(xs) // 2
            if len(xs) == 2:
                d = 1
            return sum((f.diff(xs[k]) * g.diff(xs[k + d]) - f.diff(xs[k + d]) * g.diff(xs[k]) for k in range(d)),
                       self.field.zero)
        rows = [[f.diff(x) for x in xs], [g.diff(x) for x in xs], *self.fixed_grads]
        return _det(rows, self.field.zero)

    def equal(self, a, b) -> bool:
        return self.convert(a) == self.convert(b)


def _det(rows, zero):
    from itertools import permutations

    from ..algebra.brackets import permutation_sign

    total = zero
    for perm in permutations(range(len(rows))):
        term = None
        for r, c in enumerate(perm):
            entry = rows[r][c]
            if not entry:
                term = None
                break
            term = entry if term is None else term * entry
        if term is not None:
            total = total + term if permutation_sign(perm) > 0 else total - term
    return total


def _tidy(expr):
    """A readable exact form: polynomials expanded, rational functions factored, exponentials combined."""
    expr = sympy.expand(expr)
    symbols = sorted(expr.free_symbols, key=str)
    if expr.is_polynomial(*symbols):
        return expr
    if expr.is_rational_function(*symbols):
        return sympy.factor(sympy.cancel(expr))
    if expr.has(sympy.exp):
        return sympy.expand(sympy.powsimp(expr, combine="exp"))
    return expr


def check_against_backward(result: PoissonShadow) -> None:
    """Raise :class:`NoExactResultError` unless ``X_{H_S, fixed}`` equals the backward-error ``X_eff`` through ``h^order``.

    When every atom of the system and of ``H_S`` has a place in the extended exact ring
    (:mod:`nambu_bch.algebra.extended`: exp, sin, cos, square roots, denominators), both sides are computed
    and compared there (zero = the normal form is zero; no ``simplify``).  Otherwise (undefined functions,
    algebraic coefficients of the composition) the comparison runs in sympy expressions.
    """
    if not _check_in_extended_ring(result):
        _check_in_expressions(result)
    result.verified_orders = result.order


def _differs(result, j, i):
    system = result.system
    return NoExactResultError(
        f"{system.name}, {result.composition.name}: X_(H_S) differs from the backward-error X_eff at h^{j} "
        f"in d{system.coordinates[i]}/dt; not returned")


def _check_in_extended_ring(result: PoissonShadow) -> bool:
    """The check of :func:`check_against_backward` in the extended exact ring; ``False`` when the ring refuses
    the system's atoms (the caller then checks in sympy expressions)."""
    from ..algebra.extended import ExtendedBackend, extended_ring
    from ..bch.backward import _backward_graded

    system, order, comp = result.system, result.order, result.composition
    if comp.extension:
        return False
    alg = system.algebra
    pieces = {p.number: [alg.to_sympy(c) for c in p.field.components] for p in system.splitting.pieces}
    series = [sympy.sympify(result.series[j], strict=True) for j in range(order + 1)]
    exprs = [*system.hamiltonians, *result.fixed, *series, *(c for comps in pieces.values() for c in comps)]
    ring = extended_ring(system.coordinates, system.parameters, exprs)
    if ring is None:
        return False
    try:
        backend = ExtendedBackend(ring, pieces)
        fixed = [ring.convert(G) for G in result.fixed]
        hams = [ring.convert(Hj) for Hj in series]
    except NoExactResultError:
        return False
    Z = _backward_graded(backend, comp, order)
    n = ring.n
    fixed_grads = [[ring.diff(G, i) for i in range(n)] for G in fixed]
    for j in range(order + 1):
        grad = [ring.diff(hams[j], i) for i in range(n)]
        if fixed_grads:  # X^i = {x_i, H, G, ...}: the Jacobian determinant with e_i as the first row
            comps = [_det([[ring.one if k == i else ring.zero for k in range(n)], grad, *fixed_grads], ring.zero)
                     for i in range(n)]
        else:  # canonical, X_F = (dF/dp, -dF/dq) (N = 2: (x1, x2) = (q, p))
            d = n // 2
            comps = grad[d:] + [-g for g in grad[:d]]
        for i, (a, b) in enumerate(zip(comps, Z[j])):
            if a - b:
                raise _differs(result, j, i)
    return True


def _check_in_expressions(result: PoissonShadow) -> None:
    system, order = result.system, result.order
    X = effective_field(system.splitting, result.composition, order)
    result.effective = X
    alg = system.algebra
    for j in range(order + 1):
        Hj = result.series[j]
        if result.fixed or alg.is_polynomial(alg.convert(Hj)):
            comps = liouville_field(alg, Hj, *result.fixed).to_sympy()
        else:  # canonical, X_F = (dF/dp, -dF/dq): differentiate without expanding rational functions
            d = alg.n // 2
            comps = [sympy.diff(Hj, x) for x in alg.coordinates[d:]] + [-sympy.diff(Hj, x) for x in alg.coordinates[:d]]
        expected = X[j].to_sympy()
        frac = _FractionBackend.make(system, (*comps, *expected))
        for i, (a, b) in enumerate(zip(comps, expected)):
            same = frac.equal(a, b) if frac is not None else is_zero(a - b)
            if not same:
                raise _differs(result, j, i)


# ----------------------------------------------------------------------------------------------
# the generic answer: undefined T(p), V(q)
# ----------------------------------------------------------------------------------------------
T_FUN, V_FUN = sympy.Function("T"), sympy.Function("V")
Q, P_ = sympy.symbols("x1 x2")


def generic_system():
    """``H = T(p) + V(q)`` on ``(x1, x2) = (q, p)`` with undefined functions ``T``, ``V``.

    >>> generic_system().H
    T(x2) + V(x1)
    """
    from ..systems import System

    return System("x1 x2", [T_FUN(P_) + V_FUN(Q)], (), name="generic-TV",
                  description="H = T(p) + V(q), T and V undefined", citation="Horikoshi, Sect. 4")


def generic_shadow(word="121", order: int = 2) -> PoissonShadow:
    """The generic shadow Hamiltonian of ``word`` for ``H = T(p) + V(q)``: a polynomial in derivatives of T, V.

    For position Verlet (``121``: half steps of T, piece 1) the h^2 term is
    ``T''(p) V'(q)^2 / 12 - V''(q) T'(p)^2 / 24``: the symmetric BCH formula
    ``log(e^{A/2} e^B e^{A/2}) = A + B - [A,[A,B]]/24 - [B,[A,B]]/12 + ...``
    (HLW Sect. III.4.2) with ``[X_A, X_B] = X_{{B,A}}``; for the harmonic oscillator it is Eq. (SHPV1).

    Examples
    --------
    >>> R = generic_shadow("121", 2)
    >>> R.series[2]
    -Derivative(T(x2), x2)**2*Derivative(V(x1), (x1, 2))/24 + Derivative(T(x2), (x2, 2))*Derivative(V(x1), x1)**2/12
    """
    return bch_shadow(generic_system(), word, order, verify=True)


def substitute(expr, T=None, V=None):
    """``expr`` (in undefined ``T(x2)``, ``V(x1)`` and their derivatives) with concrete ``T(p)``, ``V(q)``.

    >>> substitute(generic_shadow("121", 2).series[2], T=P_**2/2, V=-sympy.cos(Q))
    -x2**2*cos(x1)/24 + sin(x1)**2/12
    """
    if T is not None:
        expr = expr.replace(T_FUN, sympy.Lambda(P_, T))
    if V is not None:
        expr = expr.replace(V_FUN, sympy.Lambda(Q, V))
    return sympy.expand(expr.doit())
