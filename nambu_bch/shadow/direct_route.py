"""The direct route: shadow Hamiltonians by an exact linear solve, order by order.

Write ``H_S^a = H^a + sum_{j>=1} h^j dH^a_j`` for the ``N - 1`` Hamiltonians
(``H, G`` for N = 3; ``H`` alone for N = 2, where ``X_{H_S}`` is Eq. L1).  By
multilinearity of ``X_{H^1..H^{N-1}}``, the ``h^j`` part of ``X_{H_S^1..}`` is

    sum_a X_{H^1, .., dH^a_j, .., H^{N-1}}  +  (cross terms of lower orders),

the cross terms being the products with two or more corrections, e.g.
``X_{dH_1, dG_1}`` at ``h^2`` or ``X_{dH_2, dG_2}`` at ``h^4``.  Matching the
effective field ``X_eff = sum_j h^j Z_j`` (Eq. L2) gives at each order the
*linear* equation

    L(dH_j, dG_j) := X_{dH_j, G} + X_{H, dG_j} = Z_j - (cross terms)      (*)

for polynomial corrections of degree ``<= D`` (the ansatz degree, chosen from
the degrees of the right-hand side and of the Hamiltonians, or given).  The
unknowns are the monomial coefficients; (*) is solved exactly with
``DomainMatrix`` over ``QQ(parameters)`` (:mod:`nambu_bch.algebra.elimination`).

The complete solution space at order ``j`` is a particular solution plus the
kernel of ``L`` -- the *gauge*: it contains ``(d psi/dG, -d psi/dH)`` for every
``psi(H, G)`` (and constants), plus whatever else the system allows; it is
computed, not assumed, and compared with the ``psi`` directions.

The alpha-family (the package's parametrisation, Eq. Xeff3 generalised).  Two
canonical members are the normal forms of the solution modulo the kernel
(the one rule of :mod:`nambu_bch.algebra.ansatz`, shared with the FI route):

* ``alpha = 0``: the corrections of ``H`` cleared first (constants first, then
  the monomials of ``H`` itself, lexicographic with ``x_N`` highest, then the
  other monomials), then those of ``G`` -- the shadow pair with "everything in
  ``G_S``";
* ``alpha = 1``: the same with the roles of the slots exchanged (last
  Hamiltonian cleared first).

The family is ``(1 - alpha) * member_0 + alpha * member_1`` at every order
(affine combinations of solutions are solutions), with the lower-order family
fed into the cross terms, so higher orders are solved over ``QQ(params)[alpha]``
(right-hand sides split by powers of ``alpha``).  For ``ho3`` and ``12321`` this
is exactly Eqs. (SH12321c), (SG12321c); ``alpha = 0, 1`` give Eqs. (SH12321b),
(SG12321b) and (SH12321a), (SG12321a).  For N = 2 the kernel is the constants
and the solution is unique (Eq. SHPV, SHPV1).

When (*) has no solution the result carries a certificate: a left null
vector ``y`` of ``L`` (``y L = 0``) with ``y (RHS) != 0`` -- a functional on
vector fields (a combination of monomial coefficients of the components) that
vanishes on every ``X_{dH,G} + X_{H,dG}`` of the ansatz but not on the
right-hand side.

References
----------
Horikoshi, Eqs. (L1), (L2), (SHPV), (SHPV1), (BCH5), (SH12321a)-(SG12321c),
(Xeff3); Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.3
(modified Hamiltonians order by order).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from itertools import product

import sympy
from sympy.polys.rings import PolyElement

from ..algebra import VectorField, liouville_field
from ..algebra.ansatz import Ansatz, Rows
from ..algebra import elimination, frac_rref
from ..algebra.elimination import SparseMatrix, elimination_cost, rank, signed_sums
from ..algebra._flint import exponents
from ..algebra.flint_ring import FlintRing, polynomial_ring
from ..bch.backward import check_order
from ..bch.collector import no_full_collection
from ..checks import check_flag, show
from ..bch.concrete import effective_field_by_cost
from ..errors import InvalidOrderError, NambuBCHError, ResourceLimitError
from ..integrators.composition import composition_for

H_STEP = sympy.Symbol("h")
ALPHA = sympy.Symbol("alpha")


@dataclass
class OrderSolution:
    """The solution of Eq. (*) at one power ``h^order``.

    Attributes
    ----------
    order : int
    status : ``"solved"``, ``"vanishes"`` (zero right-hand side, e.g. odd orders of a
        symmetric word), ``"obstructed"`` or ``"refused"`` (more than ``max_unknowns`` unknowns, or an elimination above
        :data:`SOLVE_COST`)
    degree : int or None -- the ansatz degree used
    corrections : tuple of sympy expressions -- the family's ``dH^a_order`` (in ``alpha``)
    members : (tuple, tuple) -- the ``alpha = 0`` and ``alpha = 1`` members
    gauge : list of tuples -- a basis of the kernel (one correction per slot), one vector per free column
    kernel_dim, psi_dim : int -- dimension of the kernel, and of the part spanned by
        ``(d psi/dG, -d psi/dH)`` for monomials ``psi = H^p G^q`` (N = 3; ``None`` otherwise)
    certificate : dict ``{(component, monomial): coefficient}`` or None
    obstruction_value : sympy expression -- the certificate applied to the right-hand side
    rhs : VectorField or None -- the right-hand side of Eq. (*)

    Notes
    -----
    A solved order converts ``corrections`` and ``members`` to sympy on first access (``convert``, a callable
    returning both; the same expressions, cached), and ``gauge`` likewise (``convert_gauge``, from the exact
    kernel vectors): the route itself works on the ring elements, and a caller that only reads ``H_S, G_S``
    never pays for the per-order sympy forms.
    """

    order: int
    status: str
    degree: int | None = None
    corrections: tuple = ()
    members: tuple = ()
    gauge: list = field(default_factory=list)
    kernel_dim: int = 0
    psi_dim: int | None = None
    certificate: dict | None = None
    obstruction_value: object = None
    rhs: object = None
    convert: object = field(default=None, repr=False, compare=False)
    convert_gauge: object = field(default=None, repr=False, compare=False)

    def _converted(self, name):
        value = self.__dict__.get("_" + name)
        if name == "gauge":
            if value is None and self.convert_gauge is not None:
                value = self.__dict__["_gauge"] = self.convert_gauge()
                self.convert_gauge = None
            return value
        if value is None and self.convert is not None:
            self.__dict__["_corrections"], self.__dict__["_members"] = self.convert()
            self.convert = None
            value = self.__dict__["_" + name]
        return value

    @property
    def extra_gauge_dim(self):
        """Kernel directions not of the form ``(psi_G, -psi_H)`` (system-specific gauge)."""
        return None if self.psi_dim is None else self.kernel_dim - self.psi_dim


def _lazy(name):
    """A property of :class:`OrderSolution` whose value may be converted on first access (``convert``)."""

    def get(self):
        return self._converted(name)

    def put(self, value):
        self.__dict__["_" + name] = value

    return property(get, put, doc=f"``{name}`` as sympy expressions (converted on first access)")


# after @dataclass: the generated __init__ assigns through the properties (defaults () stay the fields' own)
OrderSolution.corrections = _lazy("corrections")
OrderSolution.members = _lazy("members")
OrderSolution.gauge = _lazy("gauge")


@dataclass
class DirectResult:
    """All orders of the direct route for one system and composition."""

    system: object
    composition: object
    order: int
    orders: list
    hamiltonians: tuple  # ring elements of the Hamiltonians
    algebra: object
    effective: object
    corrections: dict  # (slot, order) -> ring element in alpha

    @property
    def exists(self) -> bool:
        return all(o.status in ("solved", "vanishes") for o in self.orders)

    @property
    def failed_order(self):
        return next((o.order for o in self.orders if o.status not in ("solved", "vanishes")), None)

    def has_symbol(self, symbol) -> bool:
        """Whether ``symbol`` occurs in ``shadow()``, read off the exact data (no sympy sum is built).

        The shadows are ``H^a + sum_j h^j dH^a_j`` with distinct powers of ``h`` per order, so nothing cancels: the
        symbol occurs when it occurs in a Hamiltonian or in a correction -- as a generator of the ring (an exponent),
        as a parameter of the coefficient field, or in a sympy correction of a non-polynomial result.
        """
        if any(sympy.sympify(Ha, strict=True).has(symbol) for Ha in self.system.hamiltonians):
            return True
        for c in self.corrections.values():
            if not self.algebra.is_polynomial(c):
                if sympy.sympify(c, strict=True).has(symbol):
                    return True
                continue
            symbols = c.ring.symbols
            if symbol in symbols and any(m[symbols.index(symbol)] for m in c.keys()):
                return True
            if symbol in getattr(c.ring.domain, "symbols", ()) and self.algebra.to_sympy(c).has(symbol):
                return True
        return False

    def shadow(self, upto=None) -> tuple:
        """``(H_S, G_S, ...)`` as sympy expressions in ``h`` and ``alpha`` through ``h^upto``."""
        with no_full_collection():  # thousands of new terms and keys, no cycles among them
            return self._shadow(self.order if upto is None else upto)

    def _shadow(self, upto) -> tuple:
        out, memo = [], {}  # the sort keys of the terms, shared by the shadows
        for a, Ha in enumerate(self.hamiltonians):
            # term by term: the same expression as sympy.expand of the sum (PolynomialAlgebra.expanded_terms),
            # without expand's walk over the rational-function coefficients, and sorted by a key (the distinct
            # powers of h and monomials never combine) instead of sympy's comparison function
            parts = [(Ha, ())] + [(self.corrections[(a, j)], (H_STEP**j,)) for j in range(1, upto + 1)
                                  if self.corrections.get((a, j))]
            if all(self.algebra.is_polynomial(p) for p, _ in parts):
                out.append(self.algebra.expanded_sum(parts, memo))
            else:  # non-polynomial pieces (the BCH series of _non_polynomial): sympy expands the sum, but not
                # the powers of sums (a denominator (q1**2 + q2**2)**4 stays one factor instead of nine terms)
                out.append(sympy.expand(sympy.Add(*[sympy.Mul(self.algebra.to_sympy(p), *f) for p, f in parts]),
                                        multinomial=False))
        return tuple(out)


#: Most unknowns (slots x monomials of degree <= D) of one order's linear solve; refused above, up front.
MAX_UNKNOWNS = 4000
#: Bounded work (``max_unknowns`` given): an order whose elimination is estimated above this many operations
#: (:func:`~nambu_bch.algebra.elimination.elimination_cost`, from the block structure of the built matrix) is
#: refused up front.  The N = 4 single split at h^6 (1485 unknowns) is 2.1e8: 1.1 s multi-modular, 0.5 s flint; the
#: rigid body with symbolic I at h^10 (910 unknowns over QQ(I1, I2, I3)) is 3.5e9, and its whole direct route took
#: 7.3 s CPU (load 4.4) where the refusal's fallback, the existence decision by orbit averages in sympy expressions,
#: took about 116 s: the budget admits it.  At h^12 (estimate 8.9e9) the exact solve with its sympy sums took
#: 11.3 s CPU (load 10; ``benchmarks/bench_shadow.py --targets``, row d) where the fallback took about 210 s
#: (docs/performance.md): admitted too.
SOLVE_COST = 10**10


def _check_ansatz_size(slots, n, degree):
    """Refuse, before any work, an ansatz of ``slots * binomial(D + n, n)`` unknowns above :data:`MAX_UNKNOWNS`."""
    unknowns = Ansatz.size(n, degree, slots) if degree < 10**4 else math.inf
    if unknowns > MAX_UNKNOWNS:
        shown = unknowns if unknowns != math.inf else "> 10^12"
        raise ResourceLimitError(
            f"an ansatz of degree {degree} in {n} coordinates has {shown} unknowns; at most {MAX_UNKNOWNS} are accepted "
            "(lower the degree or the order)"
        )


def operator_columns(alg, hams, ansatz, rows, memo=None, field=None) -> list:
    """The columns of ``L`` in Eq. (*): ``X_{H^1, .., x^mu, .., H^{N-1}}`` (``x^mu`` in slot ``a``) per ansatz column.

    Parameters
    ----------
    alg : PolynomialAlgebra -- the ring of ``hams`` (extra constant generators allowed)
    hams : sequence of ring elements -- the Hamiltonians ``H^1 .. H^{N-1}``
    ansatz : Ansatz -- the unknown corrections (its slots are the Hamiltonians')
    rows : Rows -- interns ``(component, exponent tuple[:n])``
    memo : dict, optional -- ``(slot, mu) -> components``, shared by the orders of one solve
    field : callable, optional -- ``slots -> VectorField``, the Liouville field of the slots (default
        :func:`~nambu_bch.algebra.brackets.liouville_field` on ``alg``; the direct route passes its fraction-free one)

    Returns
    -------
    list of sparse row vectors ``{row: coefficient}``, one per ansatz column.
    """
    pad = (0,) * (len(alg.gens) - alg.n)
    out = []
    for a, e in ansatz.columns:
        comps = None if memo is None else memo.get((a, e))
        if comps is None:
            slots = list(hams)
            slots[a] = alg.ring.from_dict({e + pad: alg.domain.one})
            comps = (liouville_field(alg, *slots) if field is None else field(slots)).components
            if memo is not None:
                memo[(a, e)] = comps
        out.append(rows.field(comps, alg.n))
    return out


def _lift(alg, value):
    """A ring element of the effective field's algebra as an element of ``alg`` (which has the extra ``alpha``)."""
    if not hasattr(value, "ring"):
        raise NambuBCHError(f"the direct route needs a polynomial effective field, got the component {value}")
    pad = (0,) * (len(alg.gens) - len(value.ring.gens))
    return alg.ring.from_dict({m + pad: alg.domain.convert(c) for m, c in value.items()})


def _flint_on() -> bool:
    """The elimination's fast paths are on and python-flint is available (``NAMBU_BCH_DISABLE_FLINT`` unset)."""
    return elimination.FAST_PATHS and elimination.flint_available()


def _divided(numerators: dict, denominator, domain, ctx=False, pairs: bool = False) -> dict:
    """``{key: n / denominator}`` in ``domain = QQ(params)``, zero quotients left out.

    ``numerators``: ``{key: {exponent tuple: rational}}`` (polynomials in the parameters), ``denominator``
    a non-zero polynomial of the field's ring (or, with ``ctx``, an ``fmpz_mpoly`` of ``ctx``).  Each quotient
    is a reduced fraction, cancelled by flint's gcd when python-flint is available
    (:mod:`nambu_bch.algebra.frac_rref`, the same normal form), else by sympy's field.  ``ctx``: the flint
    context of ``domain`` or ``None`` (sympy's field), when the caller has chosen already
    (:meth:`_Solver._flint_context`).  ``pairs`` (with a flint ``ctx``): the quotients as normalised flint pairs,
    not converted to the field.
    """
    if ctx is False:
        ctx = frac_rref.context(domain) if _flint_on() else None
    field = domain.field
    out = {}
    if ctx is None:
        for k, n in numerators.items():
            v = field.new(field.ring.from_dict(n), denominator)
            if v:
                out[k] = v
        return out
    # a flint polynomial of ctx (the fraction-free fields' own lcm) is already the integer form P / 1
    D = frac_rref.integer_poly(denominator, ctx) if isinstance(denominator, PolyElement) else (denominator, 1)
    for k, n in numerators.items():
        pair = frac_rref.quotient_terms(n, D, ctx)
        if pair is not None:
            out[k] = pair if pairs else frac_rref.to_field(pair, domain)
    return out


def _lcm(a, b):
    """The lcm of two flint ``fmpz_mpoly`` with positive leading coefficients, its own leading coefficient positive
    (flint's gcd has a positive leading coefficient, and exact quotients of such polynomials keep the sign)."""
    g = a.gcd(b)
    return a * b if g.is_one() else a * (b / g)


def _total_degree(p, n):
    return max((sum(m[:n]) for m in p.keys()), default=-1)


def needed_degree(gdeg, rhs_deg: int) -> tuple:
    """``(D, reach)``: the default ansatz degree of an order whose field has degree ``rhs_deg``.

    ``gdeg[a]`` is the degree of the gradient of ``H^a``; a correction of degree ``D`` in slot ``a`` gives a
    field of degree ``<= D - 1 + reach_a`` (``reach_a`` the sum of the other slots' gradient degrees), so ``D``
    is the least degree reaching ``rhs_deg`` in every slot, and ``reach`` the largest ``reach_a``.
    """
    sums = [sum(g for b, g in enumerate(gdeg) if b != a) for a in range(len(gdeg))]
    return max(1, max(rhs_deg + 1 - s for s in sums)), max(sums)


def _sympy_forms(alg, fam, mem_polys) -> tuple:
    """The sympy forms of a solved order's family and members (:attr:`OrderSolution.corrections`, ``members``)."""
    memo: dict = {}  # the members and the family share most coefficients: each converted once
    return (tuple(alg.to_sympy(f, memo) for f in fam),
            tuple(tuple(alg.to_sympy(p, memo) for p in polys) for polys in mem_polys))


def _gauge_forms(ansatz, kernel, coordinates, domain) -> list:
    """The sympy forms of a solved order's kernel basis (:attr:`OrderSolution.gauge`), one tuple per vector."""
    return [ansatz.expressions(v, coordinates, domain) for v in kernel]


class _Solver:
    def __init__(self, system, comp, order, degree, max_unknowns=None, effective=None):
        self.max_unknowns = max_unknowns
        self.system = system
        self.comp = comp
        self.order = order
        self.degree = degree
        splitting = system.splitting
        if effective is None:
            effective = effective_field_by_cost(splitting, comp, order)  # backward route for algebraic coefficients
        self.effective = effective
        alg0 = self.effective[0].algebra
        self.alg = alg = alg0.with_constants(ALPHA)
        self.n = alg.n
        self.alpha_index = len(alg.gens) - 1
        hams = []
        for Hk in system.hamiltonians:
            p = alg.convert(Hk)
            if not alg.is_polynomial(p):
                raise NambuBCHError(f"the direct route needs polynomial Hamiltonians, got {Hk}")
            hams.append(p)
        self.hams = tuple(hams)
        self.slots = len(hams)
        self.gdeg = [_total_degree(p, self.n) - 1 for p in hams]
        self._columns: dict = {}
        self._plain = None  # the polynomial ring of the fraction-free fields (_fields_cleared)
        self._ctx = False  # the flint context of the coefficient field, or None (_flint_context), chosen once
        self._cleared: dict = {}  # id of a Hamiltonian -> (its cleared polynomial, its denominator)
        self._jacobian_rank2 = None  # H, G algebraically independent (_psi_dim), found once per solve
        self._cofactors: dict = {}  # slot -> the fields with x_j in that slot (_monomial_field), once per solve
        N1, n = len(hams), self.n
        # the determinant form of Eq. (gLiouville) (liouville_field's general case), over a field without parameters:
        # over QQ(params) the sums of shifted cofactors would add fractions, slower than the fraction-free fields
        self._laplace = (N1 == n - 1 and not (N1 == 1 and n % 2 == 0 and n > 2) and not (N1 == 2 and n % 3 == 0 and n > 3)
                         and not self._cleared_ok())

    # -- fields ------------------------------------------------------------------
    def _cleared_ok(self):
        domain = self.alg.domain
        return getattr(domain, "is_FractionField", False) and domain.domain.is_QQ

    def _field(self, slots):
        """``X_{slots}`` (Eq. gLiouville); over ``QQ(params)`` fraction-free (:meth:`_fields_cleared`)."""
        fast = self._monomial_field(slots)
        return fast if fast is not None else self._general_field(slots)

    def _monomial_field(self, slots):
        """``X_{H^1, .., x^mu, .., H^{N-1}}`` (a monomial of degree >= 2 in one slot) by Laplace expansion, or None.

        The Liouville field is a determinant whose row of slot ``a`` is ``grad x^mu = sum_j mu_j x^(mu - e_j) e_j``;
        a determinant is linear in each row over the polynomial ring, so

            X_{.., x^mu, ..} = sum_j mu_j x^(mu - e_j) X_{.., x_j, ..}     (x_j in slot a),

        and the ``n`` fields ``X_{.., x_j, ..}`` of a slot (the cofactors) are computed once per solve: a column of
        the operator is then a sum of shifted copies of them -- the same ring element, without a determinant of
        polynomials per column.  Only the determinant form of Eq. (gLiouville) (``N - 1`` slots; not the
        canonical or triplet brackets) over a coefficient field without parameters is expanded; other slots and
        fields go the general way (None).
        """
        alg, n = self.alg, self.n
        if not self._laplace:
            return None
        others = [b for b, p in enumerate(slots) if p is not self.hams[b]]
        if len(others) != 1 or len(slots[others[0]]) != 1:
            return None
        a = others[0]
        ((mu, c),) = slots[a].items()
        if c != alg.domain.one or any(mu[n:]) or sum(mu) < 2:
            return None
        cofactors = self._cofactors.get(a)
        if cofactors is None:
            cofactors = []
            for j in range(n):
                unit = list(slots)
                unit[a] = alg.gens[j]
                cofactors.append(self._general_field(unit).components)
            self._cofactors[a] = cofactors
        sums = [{} for _ in range(n)]
        zero = alg.domain.zero
        for j in range(n):
            if not mu[j]:
                continue
            shift = tuple(e - (k == j) for k, e in enumerate(mu))
            for i, comp in enumerate(cofactors[j]):
                out = sums[i]
                for m, v in comp.items():
                    key = tuple(x + y for x, y in zip(m, shift))
                    out[key] = out.get(key, zero) + mu[j] * v
        return VectorField(alg, [alg.ring.from_dict({m: v for m, v in out.items() if v}) for out in sums])

    def _general_field(self, slots):
        if self._cleared_ok():
            return self._fields_cleared([slots])
        return liouville_field(self.alg, *slots)

    def _fields_cleared(self, assignments, as_pairs: bool = False):
        """``sum_k X_{slots_k}`` over ``QQ(params)`` without fraction arithmetic: the same field, exactly.

        ``X_{P_1 .. P_{N-1}}`` is multilinear in its slots over the constants, so with ``P_a = Q_a / D_a``
        (``D_a`` the lcm of the coefficient denominators, a polynomial in the parameters, ``Q_a`` a
        polynomial in the coordinates, ``alpha`` and the parameters) ``X_{P} = X_{Q} / (D_1 .. D_{N-1})``.
        ``X_Q`` is computed in ``QQ[coordinates, alpha, params]`` (products without gcds; the parameters
        are never differentiated) -- on flint's ``fmpq_mpoly`` when python-flint is available
        (:class:`~nambu_bch.algebra.flint_ring.FlintRing`), else on sympy's ring; the fields of all
        ``assignments`` are summed there over the lcm ``T`` of their denominators, and each coefficient of
        the sum is divided by ``T`` once (one cancellation per coefficient instead of one per product term
        and per sum: :func:`_divided`).  Field elements are reduced fractions either way, so the result is
        the same ring element.  ``as_pairs`` (python-flint on): the components as ``{monomial: flint pair}``
        dicts instead (:meth:`_subtracted` takes them).
        """
        alg = self.alg
        field = alg.domain.field
        width = len(alg.gens)
        pad = (0,) * width
        plain = self._plain_ring()
        make = plain.from_terms
        # the denominators in flint's ZZ[params] when the plain ring is flint's (no sympy lcm or product), else in
        # sympy's QQ[params]: any non-zero multiple of the lcm serves, since each quotient is reduced afterwards
        ctx = self._flint_context() if isinstance(plain, FlintRing) else None
        one = field.ring.one if ctx is None else ctx.constant(1)
        parts = []
        for slots in assignments:
            cleared, total = [], one
            for p in slots:
                hit = self._cleared.get(id(p)) if any(p is q for q in self.hams) else None
                if hit is None:
                    hit = self._clear(p, make) if ctx is None else self._clear_flint(p, make, ctx)
                    if any(p is q for q in self.hams):  # the Hamiltonians: cleared once per solve
                        self._cleared[id(p)] = hit
                cleared.append(hit[0])
                if hit[1] != one:
                    total = total * hit[1]
            parts.append((liouville_field(plain, *cleared).components, total))
        T = parts[0][1]
        for _, total in parts[1:]:
            if total != T:
                T = T.lcm(total) if ctx is None else _lcm(T, total)
        sums = None
        for comps, total in parts:
            if total == T:
                scale = None
            elif ctx is None:
                scale = {pad + m: c for m, c in T.exquo(total).items()}
            else:
                quotient = T / total  # exact: T is a multiple of total
                scale = {pad + m: c for m, c in zip(exponents(quotient), quotient.coeffs())}
            if scale is not None:
                factor = make(scale)
                comps = [c * factor for c in comps]
            sums = list(comps) if sums is None else [a + b for a, b in zip(sums, comps)]
        components = []
        for comp in sums:
            groups: dict = {}
            for m, q in plain.terms(comp).items():
                groups.setdefault(m[:width], {})[m[width:]] = q
            if as_pairs:
                components.append(_divided(groups, T, alg.domain, ctx, pairs=True))
                continue
            components.append(alg.ring.from_dict(_divided(groups, T, alg.domain, self._flint_context()))
                              if groups else alg.zero)
        return components if as_pairs else VectorField(alg, components)

    @staticmethod
    def _clear_flint(p, make, ctx):
        """:meth:`_clear` with ``D`` in flint's ``ZZ[params]`` (``ctx``): the coefficients as normalised fraction pairs
        (:func:`~nambu_bch.algebra.frac_rref.from_field`, shared with the eliminations' conversions), ``D`` the lcm of
        their denominators and ``Q = sum_m x^m n_m (D / d_m)``, every product and exact division in C."""
        pairs = [(m, frac_rref.from_field(c, ctx)) for m, c in p.items()]
        D = ctx.constant(1)
        for _, (_, d) in pairs:
            if d != D:
                D = _lcm(D, d)
        terms: dict = {}
        for m, (n, d) in pairs:
            num = n if d == D else n * (D / d)
            for e, q in zip(exponents(num), num.coeffs()):
                terms[m + e] = q
        return make(terms), D

    @staticmethod
    def _clear(p, make):
        """``(Q, D)`` with ``p = Q / D``: ``D`` the lcm of the coefficients' denominators (a polynomial in the
        parameters), ``Q`` a polynomial in the coordinates, constants and parameters (``make``: the plain ring's)."""
        if all(c.denom.is_one for c in p.values()):  # no parameter in a denominator (an ansatz monomial): Q = p
            return make({m + e: q for m, c in p.items() for e, q in c.numer.items()}), p.ring.domain.field.ring.one
        D = p.ring.domain.field.ring.one
        for c in p.values():
            D = D.lcm(c.denom)
        terms: dict = {}
        for m, c in p.items():
            num = c.numer * D.exquo(c.denom)
            for e, q in num.items():
                terms[m + e] = q
        return make(terms), D

    def _flint_context(self):
        """The flint context of ``QQ(params)`` when python-flint is on, else ``None`` (chosen once per solve)."""
        if self._ctx is False:
            self._ctx = frac_rref.context(self.alg.domain) if _flint_on() else None
        return self._ctx

    def _plain_ring(self):
        """``QQ[coordinates, constants, parameters]`` of :meth:`_fields_cleared`: flint's when available, else sympy's."""
        if self._plain is None:
            alg = self.alg
            self._plain = polynomial_ring(alg.coordinates, alg.constants + alg.parameters, _flint_on())
        return self._plain

    def _cross(self, j, corrections, as_pairs: bool = False):
        """``sum`` over assignments of lower orders to two or more slots (the cross terms at ``h^j``); ``as_pairs``:
        the components as ``{monomial: flint pair}`` when the fraction-free fields run on flint (else a field)."""
        assignments = []
        for orders in product(range(j), repeat=self.slots):
            if sum(orders) != j or sum(1 for o in orders if o) < 2:
                continue
            slots = []
            for a, o in enumerate(orders):
                if o == 0:
                    slots.append(self.hams[a])
                else:
                    c = corrections.get((a, o))
                    if not c:
                        break
                    slots.append(c)
            else:
                assignments.append(slots)
        if not assignments:
            return None
        if self._cleared_ok():
            return self._fields_cleared(assignments, as_pairs and isinstance(self._plain_ring(), FlintRing)
                                        and self._flint_context() is not None)
        total = None
        for slots in assignments:
            X = liouville_field(self.alg, *slots)
            total = X if total is None else total + X
        return total

    def _subtracted(self, c, x):
        """``c - x`` for a ring element ``c`` over ``QQ(params)`` and ``x = {monomial: flint pair}``, the differences
        on flint pairs (:func:`~nambu_bch.algebra.frac_rref.sub`: gcds in C, not sympy's field) and converted once,
        recorded in the scope's conversions so that the elimination reads them back without converting.

        The same ring element as sympy's ``c - x`` with its terms in the order sympy's subtraction leaves them
        (``c``'s, a cancelled one removed, then ``x``'s new ones): field elements have one normal form, and the
        order, which interns the rows of the elimination, is kept so that nothing downstream can tell.
        """
        if not x:
            return c
        ctx, domain = self._flint_context(), self.alg.domain
        out = dict(c.items())
        for m, v in x.items():
            old = out.get(m)
            if old is None:
                out[m] = frac_rref.to_field((-v[0], v[1]), domain)
                continue
            d = frac_rref.sub(frac_rref.from_field(old, ctx), v)
            if d[0].is_zero():
                del out[m]
            else:
                out[m] = frac_rref.to_field(d, domain)
        return self.alg.ring.from_dict(out) if out else self.alg.zero

    def _needed_degree(self, rhs_deg):
        return needed_degree(self.gdeg, rhs_deg)

    # -- one order -----------------------------------------------------------------
    def solve_order(self, j, corrections) -> OrderSolution:
        alg = self.alg
        Z = self.effective[j]
        comps = [_lift(alg, c) for c in Z.components]
        cross = self._cross(j, corrections, as_pairs=True)
        if isinstance(cross, VectorField):
            comps = [c - x for c, x in zip(comps, cross.components)]
        elif cross is not None:
            comps = [self._subtracted(c, x) for c, x in zip(comps, cross)]
        rhs = VectorField(alg, comps)
        if all(not c for c in comps):
            return OrderSolution(j, "vanishes", corrections=(sympy.Integer(0),) * self.slots, rhs=rhs)
        rhs_deg = max(_total_degree(c, self.n) for c in comps)
        needed, reach = self._needed_degree(rhs_deg)
        D = self.degree if self.degree is not None else needed
        if D - 1 + reach < rhs_deg:
            raise InvalidOrderError(
                f"ansatz degree {D} cannot match the h^{j} field of degree {rhs_deg} "
                f"(corrections need degree >= {needed}); pass degree >= {needed} or None"
            )
        if self.max_unknowns is not None and Ansatz.size(self.n, D, self.slots) > self.max_unknowns:
            # bounded work: the exact solve is refused up front, the order stays undecided
            return OrderSolution(j, "refused", degree=D, rhs=rhs)
        _check_ansatz_size(self.slots, self.n, D)
        ansatz = Ansatz(self.n, D, self.slots)
        rows = Rows()
        col_vectors = operator_columns(alg, self.hams, ansatz, rows, self._columns, self._field)
        if self.max_unknowns is not None and elimination_cost(col_vectors, len(rows), alg.domain) > SOLVE_COST:
            return OrderSolution(j, "refused", degree=D, rhs=rhs)  # bounded work: the elimination would be too long
        by_power: dict = {}
        for i, comp in enumerate(comps):
            for m, c in comp.items():
                k = m[self.alpha_index]
                by_power.setdefault(k, {})
                r = rows((i, m[: self.n]))
                by_power[k][r] = by_power[k].get(r, alg.domain.zero) + c
        powers = sorted(by_power)
        domain = alg.domain
        rhs_list = [by_power[k] for k in powers]
        prio0, prio1 = ansatz.priorities(self.hams)

        # the canonical members straight from the elimination (one rule: algebra/ansatz.py)
        sol = Ansatz.solve_canonical(col_vectors, rhs_list, len(rows), domain, prio0)
        member0, kernel = sol.particular, sol.kernel
        if not sol.consistent:
            inverse = rows.keys()
            cert = {}
            for r, v in sol.certificate.items():
                i, mono = inverse[r]
                cert[(alg.coordinates[i], ansatz.monomial(mono, alg.coordinates))] = domain.to_sympy(v)
            value = sum(
                (domain.to_sympy(sum((v * by_power[k].get(r, domain.zero) for r, v in sol.certificate.items()), domain.zero)) * ALPHA**k
                 for k in powers),
                sympy.Integer(0),
            )
            return OrderSolution(j, "obstructed", degree=D, certificate=cert, obstruction_value=sympy.factor(value),
                                 kernel_dim=len(sol.kernel), rhs=rhs)
        if self.slots == 1:
            member1 = member0
        elif domain.is_QQ or self._flint_context() is not None:
            # the other member as the normal form of this one modulo the kernel: no second elimination
            member1 = Ansatz.member(sol, prio1, domain)
        else:  # over QQ<theta>(params) the reduction would run on sympy's field: a second elimination instead
            member1 = Ansatz.solve_canonical(col_vectors, rhs_list, len(rows), domain, prio1, certificate=False).particular
        members = [member0, member1]
        # family = (1 - alpha) member0 + alpha member1, each member a polynomial in alpha
        fam = [alg.zero for _ in range(self.slots)]
        mem_polys = []
        pad = (0,) * (len(alg.gens) - self.n - 1)
        for member in members:
            polys = [alg.zero for _ in range(self.slots)]
            for k, vec in zip(powers, member):
                polys = [p + q for p, q in zip(polys, ansatz.polynomials(vec, alg.ring, pad + (k,)))]
            mem_polys.append(polys)
        # (1 - alpha) m0 + alpha m1 written as m0 + alpha (m1 - m0): a shift of monomials instead of products
        # of coefficients, each of which would cancel a fraction (slow over QQ<2^(1/3)>(parameters))
        alpha = tuple(int(i == self.alpha_index) for i in range(len(alg.gens)))
        for a in range(self.slots):
            fam[a] = self._family(mem_polys[0][a], mem_polys[1][a], alpha)
        for a in range(self.slots):
            corrections[(a, j)] = fam[a]
        psi_dim = self._psi_dim(ansatz, D, sol.pivots) if self.slots == 2 else None

        # on first access (OrderSolution); a partial of a module function, so that an unconverted solution pickles
        convert = functools.partial(_sympy_forms, alg, tuple(fam), tuple(map(tuple, mem_polys)))
        gauge = functools.partial(_gauge_forms, ansatz, tuple(kernel), alg.coordinates, domain)
        return OrderSolution(j, "solved", degree=D, corrections=None, members=None, gauge=None,
                             kernel_dim=len(kernel), psi_dim=psi_dim, rhs=rhs, convert=convert, convert_gauge=gauge)

    def _family(self, m0, m1, alpha):
        """``m0 + alpha (m1 - m0)``; over ``QQ<theta>(params)`` coefficient by coefficient over ``QQ(params)``
        (:func:`~nambu_bch.algebra.elimination.signed_sums`: no gcds over the number field)."""
        sums: dict = {}
        for m, c in m0.items():
            sums.setdefault(m, []).append((1, c))
            sums.setdefault(tuple(i + j for i, j in zip(m, alpha)), []).append((-1, c))
        for m, c in m1.items():
            sums.setdefault(tuple(i + j for i, j in zip(m, alpha)), []).append((1, c))
        coeffs = signed_sums(sums, self.alg.domain)
        if coeffs is None:
            ctx = self._flint_context() if self._cleared_ok() else None
            if ctx is not None:
                return self._family_flint(m0, m1, alpha, ctx)
            return m0 + (m1 - m0).mul_monom(alpha)
        return self.alg.ring.from_dict(coeffs) if coeffs else self.alg.zero

    def _family_flint(self, m0, m1, alpha, ctx):
        """``m0 + alpha (m1 - m0)`` over ``QQ(params)`` with the coefficient differences on flint pairs
        (:mod:`~nambu_bch.algebra.frac_rref`: gcds in C instead of sympy's per-operation cancellation).

        The same ring element as sympy's ``m0 + (m1 - m0).mul_monom(alpha)``, its terms inserted in the order
        sympy's arithmetic leaves them (``m1``'s, then ``m0``'s new ones; then ``m0``'s, then the shifted new
        ones): field elements have one normal form, and the order is kept so that nothing downstream can tell."""
        domain = self.alg.domain
        memo: dict = {}

        def pair(c):
            hit = memo.get(id(c))
            if hit is None:
                hit = memo[id(c)] = frac_rref.from_field(c, ctx)
            return hit

        diff: dict = {}  # m1 - m0, pairs
        for m, c in m1.items():
            diff[m] = pair(c)
        for m, c in m0.items():
            b = pair(c)
            a = diff.get(m)
            v = frac_rref.sub(a, b) if a is not None else (-b[0], b[1])
            if v[0].is_zero():
                diff.pop(m, None)
            else:
                diff[m] = v
        out: dict = {m: pair(c) for m, c in m0.items()}
        for m, v in diff.items():
            key = tuple(i + j for i, j in zip(m, alpha))
            a = out.get(key)
            if a is None:
                out[key] = v
                continue
            w = frac_rref.sub(a, (-v[0], v[1]))
            if w[0].is_zero():
                del out[key]
            else:
                out[key] = w
        if not out:
            return self.alg.zero
        # unchanged coefficients of m0 stay the very elements (no round trip)
        unchanged = {m: c for m, c in m0.items() if out.get(m) is memo.get(id(c))}
        return self.alg.ring.from_dict({m: unchanged[m] if m in unchanged else frac_rref.to_field(v, domain)
                                        for m, v in out.items()})

    def _independent(self):
        """``H, G`` are algebraically independent (a 2 x 2 minor of their Jacobian in the coordinates is non-zero)."""
        if self._jacobian_rank2 is None:
            alg = self.alg
            grads = [[alg.diff(P, i) for i in range(self.n)] for P in self.hams]
            self._jacobian_rank2 = any(grads[0][i] * grads[1][k] != grads[0][k] * grads[1][i]
                                       for i in range(self.n) for k in range(i + 1, self.n))
        return self._jacobian_rank2

    def _psi_dim(self, ansatz, D, pivots):
        """Dimension of ``span{(psi_G, -psi_H) : psi = H^p G^q}`` within the ansatz, without a second elimination.

        Every such pair lies in ``ker L`` (``X_{f(H,G), G} = f_H X_{H,G}``: the bracket is a derivation in each
        slot and alternating), and is a column vector of the ansatz exactly when each of its two components
        ``q H^p G^(q-1)`` and ``-p H^(p-1) G^q`` (a zero one aside) has total degree ``<= D`` in the coordinates
        and no constant generator (``alpha``) -- read off the degrees, since the coordinate degree and the
        constant degree of a product add up over a polynomial ring (an integral domain).

        Counting is the rank.  When the Jacobian of ``(H, G)`` in the coordinates has rank 2, ``H`` and ``G``
        are algebraically independent over the coefficient field (the Jacobian criterion in characteristic 0:
        Jacobi 1841; e.g. Ehrenborg and Rota, Eur. J. Combin. 14 (1993), 157-181, Thm. 3.2).  A relation
        ``sum c_pq (q H^p G^(q-1), -p H^(p-1) G^q) = 0`` is ``(Psi_g(H, G), -Psi_h(H, G)) = 0`` for the
        polynomial ``Psi(h, g) = sum c_pq h^p g^q``; independence makes ``Psi_g`` and ``Psi_h`` zero as
        polynomials, so ``Psi`` is a constant and every ``c_pq`` with ``(p, q) != (0, 0)`` vanishes.  The
        fitting pairs are therefore linearly independent, and their number is the rank the former second pass
        computed (an elimination of those vectors).

        Otherwise (a degenerate pair, ``X_{H,G} = 0``) the pairs are not independent; they still lie in the
        kernel, whose basis from the elimination is the identity on its free columns (one vector per free
        column, zero on the other free columns), so a kernel vector is the combination of the basis with its
        own values on the free columns as coefficients: the rank of the pairs is the rank of their restriction
        to the free columns (those outside the elimination's pivots), a matrix of ``len(kernel)`` columns.
        """
        alg, n = self.alg, self.n
        Hp, Gp = self.hams
        dh, dg = (_total_degree(P, n) for P in (Hp, Gp))
        plain = [not any(any(m[n:]) for m in P.keys()) for P in (Hp, Gp)]  # no constant generator

        def fits(k, l):  # H^k G^l (k, l >= 0) is a combination of ansatz monomials
            return dh * k + dg * l <= D and (k == 0 or plain[0]) and (l == 0 or plain[1])

        pairs = [(p, q) for p in range(D + 2) for q in range(D + 2)
                 if p + q and (q == 0 or fits(p, q - 1)) and (p == 0 or fits(p - 1, q))]
        if self._independent() or not pairs:
            return len(pairs)
        pivots = set(pivots)
        place = {c: k for k, c in enumerate(c for c in range(len(ansatz)) if c not in pivots)}  # the free columns
        index, vecs = ansatz.index, []
        for p, q in pairs:
            dG = q * Hp**p * Gp ** (q - 1) if q else alg.zero  # d psi / dG
            dH = p * Hp ** (p - 1) * Gp**q if p else alg.zero  # d psi / dH
            vec = {}
            for a, poly in enumerate((dG, -dH)):
                for m, c in poly.items():
                    k = place.get(index[(a, m[:n])])
                    if k is not None:
                        vec[k] = c
            if vec:
                vecs.append(vec)
        return rank(SparseMatrix.from_rows(vecs, len(place), alg.domain)) if vecs else 0


def direct_route(system, word, order: int = 2, degree=None, max_unknowns=None, progress=None,
                 effective=None) -> DirectResult:
    """Solve ``X_{H_S,G_S} = X_eff + O(h^{order+1})`` order by order (Eq. L2; Eq. L1 for N = 2).

    Parameters
    ----------
    system : System
    word : composition spec (``"12321"``, ``"lie-trotter"``, ``Composition`` ...)
    order : int -- highest power of ``h`` kept
    degree : int, optional -- ansatz degree of the corrections (default: from the field)
    max_unknowns : int, optional -- refuse (status ``"refused"``) an order whose ansatz has more unknowns, or
        whose elimination is estimated above :data:`SOLVE_COST`; None: neither limit (only :data:`MAX_UNKNOWNS`)
    progress : bool or None -- a progress bar over the orders (tqdm); None: on a terminal or in
        Jupyter once the run has lasted a second (:func:`nambu_bch.progress.stages`)
    effective : optional -- a given modified field instead of the composition's (indexable by the power of
        ``h`` through ``order``, polynomial ``VectorField``s on the system's algebra, e.g. a Runge--Kutta
        method's :class:`~nambu_bch.bseries.modified.ModifiedEquation`); ``word`` is then only its label
        (an object with a ``name``)

    Returns
    -------
    DirectResult -- stops at the first obstructed or refused order.

    Examples
    --------
    >>> from nambu_bch import model
    >>> R = direct_route(model("ho"), "121", order=2)        # Eq. (SHPV1)
    >>> sympy.expand(R.shadow()[0] - model("ho").H)
    h**2*m*omega**4*x1**2/12 - h**2*omega**2*x2**2/(24*m)
    """
    from ..systems.spec import as_system

    system = as_system(system)
    order = check_order(order)
    check_flag(progress, "progress", none=True)
    if degree is not None:
        if isinstance(degree, bool) or not isinstance(degree, int) or degree < 1:
            raise InvalidOrderError(f"degree must be a positive integer (the ansatz degree) or None, got {degree!r}")
        _check_ansatz_size(len(system.hamiltonians), system.N, degree)
    comp = composition_for(word, system.splitting) if effective is None else word
    if effective is not None:
        _check_effective(effective, system, order)
    if not all(system.algebra.is_polynomial(system.algebra.convert(Hk)) for Hk in system.hamiltonians):
        if effective is not None:
            raise NambuBCHError("the direct route on a given field needs polynomial Hamiltonians")
        return _non_polynomial(system, comp, order)
    if max_unknowns is not None and (isinstance(max_unknowns, bool) or not isinstance(max_unknowns, int) or max_unknowns < 1):
        raise InvalidOrderError(f"max_unknowns must be a positive integer or None, got {max_unknowns!r}")
    corrections: dict = {}
    orders = []
    from ..progress import stages

    # each coefficient crosses to flint once for all orders' eliminations; the solve builds tens of thousands of
    # acyclic ring elements, each of which would count towards a full collection walking sympy's caches
    with frac_rref.shared_conversions(), no_full_collection():
        solver = _Solver(system, comp, order, degree, max_unknowns, effective)
        for j in stages(range(1, order + 1), f"shadow {getattr(comp, 'name', comp)} on {system.name}: orders",
                        enabled=progress):
            sol = solver.solve_order(j, corrections)
            orders.append(sol)
            if sol.status in ("obstructed", "refused"):
                break
    if orders and orders[-1].status == "refused" and effective is None:  # order 0 solves nothing: H_S = H, G_S = G
        from .generic import poisson_structure

        if poisson_structure(system) is not None:
            # the ansatz is too large, but the pieces are Hamiltonian for one Poisson bracket: the BCH
            # series on their Hamiltonians is the shadow Hamiltonian (verified against backward error analysis)
            return _non_polynomial(system, comp, order)
    return DirectResult(system, comp, order, orders, solver.hams, solver.alg, solver.effective, corrections)


def _check_effective(effective, system, order) -> None:
    """A given modified field: its coefficients ``h^0 .. h^order`` are vector fields on the system's coordinates."""
    try:
        fields = [effective[j] for j in range(order + 1)]
    except (TypeError, IndexError, KeyError):
        raise NambuBCHError(f"effective must hold the field's coefficients of h^0 .. h^{order}, got {show(effective)}") from None
    if not all(isinstance(Z, VectorField) and Z.algebra.coordinates == system.coordinates for Z in fields):
        raise NambuBCHError(f"effective must hold vector fields on {system.name}'s coordinates, got {show(effective)}")


def _non_polynomial(system, comp, order) -> DirectResult:
    """Non-polynomial Hamiltonians: the BCH series on the pieces' Hamiltonians (substitution into the generic answer).

    A polynomial ansatz cannot hold ``cos q`` or ``exp q``; when the pieces are Hamiltonian
    for one Poisson bracket (canonical ``T|V`` splits, ``split="single"`` Nambu systems),
    :func:`~nambu_bch.shadow.generic.bch_shadow` gives ``H_S`` for any smooth functions,
    re-checked against backward error analysis before it is used.  The solution is
    unique up to constants (connected phase space, canonical) or up to the Casimir
    gauge (``G_S = G`` is the member returned).
    """
    from .generic import bch_shadow, poisson_structure

    if poisson_structure(system) is None:
        bad = next(Hk for Hk in system.hamiltonians if not system.algebra.is_polynomial(system.algebra.convert(Hk)))
        raise NambuBCHError(
            f"the direct route needs polynomial Hamiltonians unless every piece is Hamiltonian for one Poisson bracket "
            f"(canonical T(p) + V(q), or split='single'); got {bad} with the {system.splitting.kind} split")
    R = bch_shadow(system, comp, order, verify=True)
    slots = len(system.hamiltonians)
    corrections, orders = {}, []
    for j in range(1, order + 1):
        c = R.series.get(j, sympy.Integer(0))
        if c == 0:
            orders.append(OrderSolution(j, "vanishes", corrections=(sympy.Integer(0),) * slots))
            continue
        corrections[(0, j)] = c
        orders.append(OrderSolution(j, "solved", corrections=(c,) + (sympy.Integer(0),) * (slots - 1)))
    return DirectResult(system, comp, order, orders, tuple(system.hamiltonians), system.algebra, R.effective, corrections)
