"""The FI route: shadow Hamiltonians from the representations of the BCH commutators (Sect. 4.2, 5.2), any order.

Take the lowest non-vanishing correction of ``X_eff`` as a sum of commutators of
Liouville terms (the formal BCH series, expanded and pruned: Eq. BCH4 for
``12321``): double commutators ``c_t [X_a, [X_b, X_c]]`` at ``h^2`` for a
symmetric word, single commutators ``c_t [X_b, X_c]`` at ``h`` otherwise.
Each commutator has the representations of Eqs. (1AX)-(2BY) (resp. CL2a,
CL2b); several labels may give the same formal sum (Eq. CL5: ``1AX`` and ``1BX``
give ``X_{B, -2x_2^2/m^2}``), so the distinct ones are kept with the labels
that give them.  An affine combination of the representations of each
commutator (weights summing to one, e.g. ``3, -2`` in Eq. CL5a) is again a
valid representation; we ask for which weights the total equals

    X_{H, dG} + X_{dH, G}        (Eq. BCH5; X_{dH} for N = 2)

as a formal sum of Liouville terms modulo multilinearity, antisymmetry and the
vanishing rule (:class:`~nambu_bch.shadow.liouville_terms.LiouvilleSum`).  The
unknowns are the weights and the monomial coefficients of ``dH, dG``; the
condition is linear and is solved exactly (:mod:`nambu_bch.algebra.elimination`).
The result is the whole solution family (particular + kernel), its two
canonical members and their alpha-family (the direct route's rule, one
implementation: :mod:`nambu_bch.algebra.ansatz`), and :meth:`FIResult.check_member` to
test a given choice, e.g. the paper's Eqs. (CL5a)-(CL8a) with (SH12321a).

Higher orders (``order`` up to ``MAX_FI_ORDER = 6``).  At ``h^j`` the
BCH brackets have depth ``j`` (Lyndon basis, not all right-nested); the FI
representations of each are kept as their affine hull, built recursively
(:mod:`nambu_bch.shadow.fi_nested`: base = Eq. CL2a at every pair, labelled
directions), and the condition

    sum_t c_t (p_t + sum_k w_tk d_tk) = X_{H,dG_j} + X_{dH_j,G} + sum_{i+k=j} X_{dH_i,dG_k}

is linear in the weights and ``dH_j, dG_j``, the lower orders' alpha-family fed
into the cross terms (right-hand sides split by powers of alpha).  Each
:class:`FIOrder` reports its family, members, the corrections reached through
FI representations (``fi_dim``) and the direct route's kernel at the same
degree (``direct_dim``): every FI solution is a direct one, and ``whole`` says
whether the FI span is all of it (docs/fi_route.md: for ho3 it is a proper part).

The family returned at every order is the FI particular solution plus the direct route's
kernel at the direct route's default degree, with the direct route's canonical members, so
both routes give the same alpha-family; :class:`FISpan` says whether the FI solutions alone
held it (for Lotka-Volterra at ``h^4`` they do not: the alpha direction needs ``X_{H,H} = 0``).

References
----------
Horikoshi, Eqs. (BCH2)-(BCH5), (CL5)-(CL8b), (SH12321a)-(SG12321c), (Xeff3).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from itertools import product

import sympy

from ..algebra.ansatz import Ansatz, Rows
from ..algebra.elimination import Echelon, SparseMatrix, kernel_rref, normal_form, rank, solve_affine
from ..algebra.zero import is_zero
from ..bch import expand_terms, formal_bch
from ..bch.expansion import piece_evaluator, term_evaluator
from ..bch.lyndon import _terms, is_bracket, tree_degree, tree_leaves
from ..checks import is_int, show
from ..errors import InvalidOrderError, NambuBCHError
from ..integrators.composition import composition_for
from ..parsing import as_expression
from ..symbols import ALPHA, STEP
from ..systems.spec import as_system
from ..values import system_key
from .direct_route import needed_degree, operator_columns
from .fi_nested import RawOps, nested_hull
from .fundamental_identity import representations, single_representations
from .liouville_terms import LiouvilleSum

#: Highest power of ``h`` the FI route solves (the hulls of degree-9 brackets are not bounded cheaply).
MAX_FI_ORDER = 6


@dataclass
class FIRepresentation:
    """One distinct representation of a commutator: the labels giving it, its non-vanishing terms, its formal sum."""

    labels: tuple
    terms: tuple  # LiouvilleTerm, the non-vanishing ones
    formal: LiouvilleSum

    def to_latex(self) -> str:
        return " + ".join(t.to_latex() for t in self.terms) if self.terms else "0"

    def __str__(self):
        return " + ".join(str(t) for t in self.terms) if self.terms else "0"


@dataclass
class FICommutator:
    """``coefficient * [X_a, [X_b, X_c]]`` (or ``[X_b, X_c]``) with its distinct representations."""

    coefficient: object
    leaves: tuple  # (a, b, c) or (b, c), Liouville terms (tuples of Hamiltonian pieces)
    representations: list

    def label(self) -> str:
        def X(t):
            return "X_{" + ", ".join(str(s) for s in t) + "}"

        if len(self.leaves) == 3:
            a, b, c = self.leaves
            return f"[{X(a)}, [{X(b)}, {X(c)}]]"
        b, c = self.leaves
        return f"[{X(b)}, {X(c)}]"


@dataclass
class FIMember:
    """A member of the FI family: weights per commutator (aligned with its representations) and corrections."""

    weights: list
    corrections: tuple


@dataclass
class FINested:
    """``coefficient * tree`` (a BCH bracket of Liouville terms, any depth) with the affine hull of its FI forms.

    The representations of ``tree`` are ``base + sum_k w_k d_k`` (any weights), ``hull.directions``
    the ``(label, d_k)``; :mod:`~nambu_bch.shadow.fi_nested` explains the labels.
    """

    coefficient: object
    tree: object
    hull: object  # fi_nested.NestedHull
    ops: object = field(default=None, repr=False, compare=False)  # fi_nested.RawOps, for output (a cache, not data)

    def label(self, latex: bool = False) -> str:
        show_slot = sympy.latex if latex else str

        def show(t):
            if is_bracket(t):
                return f"[{show(t[0])}, {show(t[1])}]"
            return "X_{" + ", ".join(show_slot(s) for s in t) + "}"

        return show(self.tree)

    def to_dict(self, limit=None) -> dict:
        """JSON-able: coefficient, bracket (nested lists of slots), base and directions as ``[{coefficient, slots}]``."""
        from ..render import expression

        def tree(t):
            return [tree(t[0]), tree(t[1])] if is_bracket(t) else [expression(s) for s in t]

        def terms(raw, c=None):
            return [{"coefficient": expression(k), "slots": [expression(x) for x in slots]}
                    for k, slots in self.ops.items(raw, c)]

        dirs = self.hull.directions[:limit] if limit is not None else self.hull.directions
        return {
            "coefficient": expression(self.coefficient),
            "bracket": tree(self.tree),
            "dimension": self.hull.dimension,
            "base": terms(self.hull.base, self.coefficient),
            "directions": [{"label": lab, "terms": terms(d, self.coefficient)} for lab, d in dirs],
        }

    def to_text(self, limit=None) -> str:
        lines = [f"({self.coefficient}) {self.label()}   (affine hull of dimension {self.hull.dimension})",
                 f"  base (Eq. CL2a at every pair): {self.ops.to_text(self.hull.base, self.coefficient)}"]
        dirs = self.hull.directions if limit is None else self.hull.directions[:limit]
        lines += [f"  + w * [{lab}]: {self.ops.to_text(d, self.coefficient)}" for lab, d in dirs]
        if len(dirs) < self.hull.dimension:
            lines.append(f"  ... {self.hull.dimension - len(dirs)} more directions (raise --limit)")
        return "\n".join(lines)

    def to_latex(self, limit=None) -> str:
        rows = [rf"\left({sympy.latex(self.coefficient)}\right) {self.label(latex=True)}",
                rf"\quad \overset{{\rm a}}{{=}} {self.ops.to_latex(self.hull.base, self.coefficient)}"]
        dirs = self.hull.directions if limit is None else self.hull.directions[:limit]
        rows += [rf"\quad + w \cdot [\text{{{lab}}}]: {self.ops.to_latex(d, self.coefficient)}" for lab, d in dirs]
        return " \\\\\n".join(rows)


@dataclass
class FIOrder:
    """The FI route at one power ``h^j`` above the lowest: ``sum_t c_t Aff(T_t)`` against the target with cross terms.

    Attributes
    ----------
    order : int
    status : ``"solved"``, ``"vanishes"`` or ``"obstructed"``
    degree : int or None -- ansatz degree of the corrections
    commutators : list of FINested -- the BCH brackets at ``h^j`` with their hulls
    directions : list of ``(commutator index, label)`` -- the independent directions kept (one weight each)
    corrections : tuple -- the alpha-family ``(dH_j, dG_j, ...)`` (the direct route's: :class:`FISpan`)
    members : (tuple, tuple) -- the ``alpha = 0`` and ``alpha = 1`` members
    kernel : list of tuples -- a basis of the corrections of the homogeneous FI solutions
    fi_dim : int -- dimension of that space (corrections reached through FI representations)
    direct_dim : int -- dimension of the direct route's kernel at the same ansatz degree (computed on first use)
    certificate : dict or None
    span : FISpan or None -- whether the FI solutions alone held the family (set when solved)
    family : the exact alpha-family (:class:`AlphaFamily`) of a solved order

    Notes
    -----
    A solved order keeps its family and kernel as exact ring elements (``family``); ``corrections``, ``members``
    and ``kernel`` are their sympy forms, built on first access (the higher orders are fed the exact data), compared
    and pickled through the exact data.
    """

    order: int
    status: str
    degree: int | None = None
    commutators: list = field(default_factory=list)
    directions: list = field(default_factory=list)
    corrections: tuple = ()
    members: tuple = ()
    kernel: list = field(default_factory=list)
    fi_dim: int = 0
    certificate: dict | None = None
    span: FISpan | None = None
    family: AlphaFamily | None = field(default=None, repr=False)
    _kernel_exact: tuple | None = field(default=None, repr=False)  # per kernel basis vector, its ring element per slot
    _direct: tuple = field(default=(), repr=False)
    _direct_dim: int | None = field(default=None, repr=False)

    def _build(self, name):
        """The sympy form of ``name`` from the exact data (members and family together: the family needs both)."""
        if name == "kernel":
            return [self.family.forms_of(polys) for polys in self._kernel_exact]
        self.__dict__["_corrections"], self.__dict__["_members"] = self.family.forms()
        return self.__dict__["_" + name]

    def _value(self) -> tuple:
        forms = (self.family, self._kernel_exact) if self.family is not None else (self.corrections, self.members,
                                                                                    self.kernel)
        return (self.order, self.status, self.degree, self.commutators, self.directions, self.fi_dim, self.certificate,
                self.span, forms)

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self is other or self._value() == other._value()

    def __getstate__(self):
        return _exact_state(self, ("corrections", "members", "kernel"))

    @property
    def direct_dim(self) -> int | None:
        if self._direct_dim is None and self._direct:
            self._direct_dim = _direct_kernel_dim(*self._direct)
        return self._direct_dim

    @property
    def whole(self) -> bool:
        """Is the FI solution set the whole solution space of the direct route at this order and degree?"""
        return self.status == "solved" and self.fi_dim == self.direct_dim


@dataclass
class FIResult:
    """The FI-route solution family for one system, composition and power of ``h``.

    Attributes
    ----------
    power : int -- the power of ``h`` solved (2 for symmetric words, 1 otherwise)
    commutators : list of FICommutator
    exists : bool
    members : (FIMember, FIMember) -- the ``alpha = 0`` and ``alpha = 1`` FI solutions (weights and corrections)
    corrections : tuple -- the alpha-family ``(dH, dG)`` (sympy, in ``alpha``): the FI particular solution
        plus the direct route's kernel, canonical members by the direct route's rule (``span`` says
        whether the FI members already were them)
    kernel : list -- basis of the homogeneous solutions (weights, corrections)
    degree : int -- ansatz degree of the corrections
    certificate : dict or None
    """

    system: object
    composition: object
    power: int
    commutators: list
    exists: bool
    degree: int
    members: tuple = ()
    corrections: tuple = ()
    kernel: list = field(default_factory=list)
    certificate: dict | None = None
    orders: list = field(default_factory=list)  # FIOrder, the powers above ``power``
    failed_order: int | None = None
    span: FISpan | None = None  # the lowest order's; FIOrder.span for the others
    family: AlphaFamily | None = field(default=None, repr=False)  # the exact form of ``corrections``
    _ctx: dict = field(default_factory=dict, repr=False)

    def _build(self, name):
        return self.family.forms()[0]

    def _value(self) -> tuple:
        forms = self.family if self.family is not None else self.corrections
        # not _ctx: the algebra, atoms and caches derived from the system and composition
        return (system_key(self.system), self.composition, self.power, self.commutators, self.exists, self.degree,
                self.members, forms, self.kernel, self.certificate, self.orders, self.failed_order, self.span)

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self is other or self._value() == other._value()

    def __getstate__(self):
        return _exact_state(self, ("corrections",))

    @property
    def free_parameter_count(self) -> int:
        """Dimension of the whole solution family (weights and corrections)."""
        return len(self.kernel)

    def shadow(self) -> tuple:
        """``(H_S, G_S)`` of the alpha-family through the highest power solved."""
        out = []
        for a, Hk in enumerate(self.system.hamiltonians):
            total = Hk + STEP**self.power * self.corrections[a]
            for o in self.orders:
                if o.status == "solved":
                    total += STEP**o.order * o.corrections[a]
            out.append(sympy.expand(total))
        return tuple(out)

    def combination(self, weights) -> LiouvilleSum:
        """``sum_t c_t sum_r w_{t,r} R_{t,r}``; ``weights[t]`` maps a label (or rep index) to its weight."""
        total = LiouvilleSum.zero(self._ctx["algebra"], self._ctx["atoms"])
        for t, comm in enumerate(self.commutators):
            w = weights[t]
            items = w.items() if isinstance(w, dict) else enumerate(w)
            for key, value in items:
                rep = self._rep(comm, key)
                total = total + rep.formal.scale(comm.coefficient * sympy.sympify(value, strict=True))
            if not is_zero(sum(sympy.sympify(v, strict=True) for _, v in (w.items() if isinstance(w, dict) else enumerate(w))) - 1):
                raise NambuBCHError(f"the weights of commutator {t} ({comm.label()}) must sum to 1, got {w}")
        return total

    @staticmethod
    def _rep(comm, key):
        if isinstance(key, int):
            return comm.representations[key]
        for rep in comm.representations:
            if key in rep.labels:
                return rep
        raise NambuBCHError(f"unknown representation label {key!r} for {comm.label()}; known: "
                            f"{[lab for r in comm.representations for lab in r.labels]}")

    def target(self, corrections) -> LiouvilleSum:
        """The formal ``sum_a X_{H^1, .., dH^a, .., H^{N-1}}`` (Eq. BCH5 right-hand side minus ``X_{H,G}``)."""
        total = LiouvilleSum.zero(self._ctx["algebra"], self._ctx["atoms"])
        for a, c in enumerate(corrections):
            total = total + _target_term(self._ctx, a, c)
        return total

    def check_member(self, weights, corrections) -> bool:
        """Do these representation weights give ``X_{H,dG} + X_{dH,G}`` with these corrections (formally)?"""
        return self.combination(weights) == self.target(corrections)

    def spans(self) -> list:
        """The :class:`FISpan` of every solved order, lowest first."""
        return [x for x in (self.span, *(o.span for o in self.orders)) if x is not None]

    def kernel_corrections(self) -> list:
        """The ``(dH, dG, ...)`` part of every homogeneous solution (weights dropped), as sympy expressions."""
        alg, nw, ansatz = self._ctx["algebra"], self._ctx["nw"], self._ctx["ansatz"]
        return [ansatz.expressions(vec, alg.coordinates, alg.domain, offset=nw) for vec in self.kernel]

    def to_text(self) -> str:
        lines = [f"FI route, {self.composition.name}, h^{self.power}:"]
        for t, comm in enumerate(self.commutators):
            lines.append(f"  ({comm.coefficient}) {comm.label()}")
            for r, rep in enumerate(comm.representations):
                w0 = self.members[0].weights[t][r] if self.members else "-"
                w1 = self.members[1].weights[t][r] if self.members else "-"
                lines.append(f"     {'/'.join(rep.labels)}: {rep}   weights (alpha=0, 1): {w0}, {w1}")
        for o in self.orders:
            lines.append(f"FI route, {self.composition.name}, h^{o.order}: {o.status}"
                         + (f", {len(o.commutators)} brackets, {len(o.directions)} independent FI directions, "
                            f"FI family dimension {o.fi_dim} of the direct route's {o.direct_dim}"
                            if o.status == "solved" else ""))
        return "\n".join(lines)


def _lazy(name):
    """A property whose sympy value is built from the exact data on first access (``None`` stored: not built yet)."""

    def get(self):
        value = self.__dict__.get("_" + name)
        if value is None:
            value = self.__dict__["_" + name] = self._build(name)
        return value

    def put(self, value):
        self.__dict__["_" + name] = value

    return property(get, put, doc=f"``{name}`` as sympy expressions (built from the exact data on first access)")


def _exact_state(obj, names) -> dict:
    """The pickle of an FI result: its exact data, without the sympy forms built from them (rebuilt on access)."""
    state = dict(obj.__dict__)
    if state.get("family") is not None:
        for name in names:
            state["_" + name] = None
    return state


# after @dataclass: the generated __init__ assigns through the properties (the defaults stay the fields' own)
FIOrder.corrections = _lazy("corrections")
FIOrder.members = _lazy("members")
FIOrder.kernel = _lazy("kernel")
FIResult.corrections = _lazy("corrections")


@dataclass(frozen=True)
class AlphaFamily:
    """One order's alpha-family as exact data: ``(1 - alpha) m_0 + alpha m_1`` from its two canonical members.

    The sympy forms (:meth:`forms`) are those the FI route printed before it kept exact data: each member
    expanded from its monomial terms, the family ``sympy.expand((1 - alpha) m_0 + alpha m_1)``.

    Attributes
    ----------
    algebra
        The algebra of the solve (its ring holds the polynomials).
    members
        ``(m_0, m_1)``; a member is one tuple per slot of pairs ``(k, dH_k)``: ``dH_k`` the coefficient of
        ``alpha^k`` (a ring element, polynomial in the coordinates).
    """

    algebra: object
    members: tuple

    def forms_of(self, polys) -> tuple:
        """One sympy sum per slot of ring elements (``x^e`` times the coefficient, as :meth:`Ansatz.expressions`)."""
        to, coords = self.algebra.domain.to_sympy, self.algebra.coordinates
        return tuple(sympy.Add(*(to(v) * sympy.Mul(*(x**k for x, k in zip(coords, m))) for m, v in p.items()))
                     for p in polys)

    def member_forms(self) -> tuple:
        """The two members as sympy expressions in the coordinates and ``alpha`` (expanded)."""
        out = []
        for member in self.members:
            corr = []
            for parts in member:
                c = sympy.Integer(0)
                for k, p in parts:
                    c = c + ALPHA**k * self.forms_of((p,))[0]
                corr.append(sympy.expand(c))
            out.append(tuple(corr))
        return tuple(out)

    def forms(self) -> tuple:
        """``(family, members)`` as sympy expressions."""
        members = self.member_forms()
        return _family(members), members

    def alpha_parts(self) -> list:
        """Per slot ``{k: ring element}``: the coefficient of ``alpha^k`` of the family (non-zero ones, highest ``k``
        first), exactly -- what the higher orders' cross terms take."""
        out = []
        for m0, m1 in zip(*self.members):
            parts: dict = {}
            for sign, shift, member in ((1, 0, m0), (-1, 1, m0), (1, 1, m1)):
                for k, p in member:
                    term = p if sign == 1 else -p
                    parts[k + shift] = parts[k + shift] + term if k + shift in parts else term
            out.append({k: parts[k] for k in sorted(parts, reverse=True) if parts[k]})
        return out


def _same_member(m, f) -> bool:
    """Are two members (as :class:`AlphaFamily` holds them) the same polynomials?  Decided by the difference: over
    ``QQ<theta>(params)`` a coefficient's fraction is not reduced, so equal values may differ as pairs."""
    for parts_m, parts_f in zip(m, f):
        diff: dict = {}
        for sign, parts in ((1, parts_m), (-1, parts_f)):
            for k, p in parts:
                term = p if sign == 1 else -p
                diff[k] = diff[k] + term if k in diff else term
        if any(diff.values()):
            return False
    return True


def _exact_member(alg, ansatz, powers, vecs, offset=0) -> tuple:
    """A member (one tuple per slot of ``(k, dH_k)``) from its sparse solution vectors, one per power ``k``."""
    tail = (0,) * (len(alg.gens) - alg.n)
    polys = [ansatz.polynomials(vec, alg.ring, tail, offset) for vec in vecs]
    return tuple(tuple((k, p[a]) for k, p in zip(powers, polys)) for a in range(ansatz.slots))


_RAW_OPS: dict = {}
_FORMS: dict = {}


def clear_cache() -> None:
    """Forget the memoised FI maps, hulls, labelled forms, formal columns, bracket evaluators and gauge kernels."""
    _RAW_OPS.clear()
    _FORMS.clear()
    _MONOMIAL_COLUMNS.clear()
    _EVALUATORS.clear()
    _OPERATOR.clear()


def _raw_ops(alg, atoms) -> RawOps:
    """One :class:`RawOps` (memoised FI maps and brackets) per algebra and atom list, shared by all words."""
    key = (alg.ring, alg.coordinates, atoms)
    if key not in _RAW_OPS or len(_RAW_OPS[key]._ways) + len(_RAW_OPS[key].hulls) > 200_000:
        if len(_RAW_OPS) > 32:
            _RAW_OPS.clear()
        _RAW_OPS[key] = RawOps(alg, atoms)
    return _RAW_OPS[key]


def _distinct_forms(ops, leaves) -> list:
    """``[(labels, shown terms, formal sum)]``: the distinct labelled forms (Eqs. 1AX-2BY or CL2a/b) of ``leaves``, memoised."""
    key = (ops.algebra.ring, ops.algebra.coordinates, ops.atoms, leaves)
    if key in _FORMS:
        return _FORMS[key]
    alg = ops.algebra
    rleaves = tuple(tuple(ops.poly_of(f) for f in t) for t in leaves)
    reps = representations(alg, *rleaves) if len(leaves) == 3 else single_representations(alg, *rleaves)
    distinct: list = []
    for label, rep_terms in reps.items():
        parts = [ops.reduce(ops.from_slots(t.slots, ops.coefficient(t.coefficient))) for t in rep_terms]
        formal = sum(parts, LiouvilleSum.zero(alg, ops.atoms))
        for d in distinct:
            if d[2] == formal:
                d[0] += (label,)
                break
        else:
            distinct.append([(label,), tuple(t for t, part in zip(rep_terms, parts) if not part.is_zero()), formal])
    if len(_FORMS) > 20000:
        _FORMS.clear()
    _FORMS[key] = [tuple(d) for d in distinct]
    return _FORMS[key]


def _atoms(system):
    """The Hamiltonian pieces of the splitting (kept whole in formal sums) and, per slot, those summing to ``H^a``."""
    per_slot = [[] for _ in system.hamiltonians]
    for piece in system.splitting.pieces:
        for term in piece.terms:
            for a, f in enumerate(term):
                if f not in per_slot[a]:
                    per_slot[a].append(f)
    for a, Ha in enumerate(system.hamiltonians):
        rest = sympy.expand(Ha - sum(per_slot[a], sympy.Integer(0)))
        if rest.free_symbols & set(system.coordinates):
            return (), [[Hb] for Hb in system.hamiltonians]  # pieces do not rebuild H: plain monomial bookkeeping
    atoms = tuple(dict.fromkeys(f for slot in per_slot for f in slot))
    return atoms, per_slot


_MONOMIAL_COLUMNS: dict = {}


def _monomial_column(ctx, a, e) -> LiouvilleSum:
    """:func:`_target_term` of the monomial ``x^e`` in slot ``a``, memoised (shared by all orders and words)."""
    alg = ctx["algebra"]
    key = (alg.ring, alg.coordinates, ctx["atoms"], tuple(map(tuple, ctx["per_slot"])), a, e)
    if key not in _MONOMIAL_COLUMNS:
        if len(_MONOMIAL_COLUMNS) > 20000:
            _MONOMIAL_COLUMNS.clear()
        _MONOMIAL_COLUMNS[key] = _target_term(ctx, a, sympy.Mul(*(x**p for x, p in zip(alg.coordinates, e))))
    return _MONOMIAL_COLUMNS[key]


def _target_term(ctx, a, correction) -> LiouvilleSum:
    """``X_{H^1, .., correction, .., H^{N-1}}`` with every Hamiltonian slot a sum of its atoms."""
    alg, atoms, per_slot = ctx["algebra"], ctx["atoms"], ctx["per_slot"]
    total = LiouvilleSum.zero(alg, atoms)
    choices = [per_slot[b] if b != a else [correction] for b in range(len(per_slot))]
    for slots in product(*choices):
        total = total + LiouvilleSum.from_slots(alg, slots, atoms=atoms)
    return total


def _check_term_tree(tree, slots, power) -> None:
    """A user's tree of ``terms=``: a bracket of depth ``power`` whose leaves are Liouville terms (``slots`` expressions)."""
    def leaf_ok(leaf):
        return type(leaf) is tuple and len(leaf) == slots and all(isinstance(f, sympy.Expr) for f in leaf)

    leaves = tree_leaves(tree)
    if not is_bracket(tree) or tree_degree(tree) != power + 1 or not all(leaf_ok(leaf) for leaf in leaves):
        raise NambuBCHError(f"each tree of terms must be a bracket of {power + 1} Liouville terms (tuples of {slots} "
                            f"sympy expressions, as in Piece.terms), got {show(tree)}")


def _as_double(coef, tree):
    """``(coefficient, (a, b, c))`` with the tree brought to ``[a, [b, c]]`` form by antisymmetry."""
    left, right = tree
    if not is_bracket(left) and is_bracket(right) and not any(is_bracket(x) for x in right):
        return coef, (left, right[0], right[1])
    if is_bracket(left) and not is_bracket(right) and not any(is_bracket(x) for x in left):
        return -coef, (right, left[0], left[1])
    raise NambuBCHError(f"the FI route handles double commutators [a,[b,c]], got the tree {tree!r}")


def _merge(entries):
    """Merge equal commutators, and ``[a,[c,b]]`` into ``[a,[b,c]]`` with the opposite sign."""
    out: dict = {}
    order = []
    for coef, leaves in entries:
        key, sign = leaves, 1
        if len(leaves) == 3 and (leaves[0], leaves[2], leaves[1]) in out:
            key, sign = (leaves[0], leaves[2], leaves[1]), -1
        elif len(leaves) == 2 and (leaves[1], leaves[0]) in out:
            key, sign = (leaves[1], leaves[0]), -1
        if key not in out:
            out[key] = 0
            order.append(key)
        out[key] += sign * coef
    return [(out[k], k) for k in order if out[k] != 0]


def fi_route(system, word, order: int = 2, degree=None, terms=None) -> FIResult:
    """Search the affine combinations of FI representations giving ``X_{H,dG} + X_{dH,G}`` (Eq. BCH5).

    Parameters
    ----------
    system : System
    word : composition spec
    order : int -- highest power of ``h``: from the lowest correction (2 for symmetric words, 1 otherwise)
        to ``MAX_FI_ORDER``; the powers above the lowest are in ``FIResult.orders``
    degree : int, optional -- ansatz degree of ``dH, dG`` at every order (default: per order, the largest
        monomial degree met in the formal sums)
    terms : list of ``(coefficient, tree)``, optional -- the lowest-order commutators to represent, with
        leaves Liouville terms (e.g. the paper's Eq. BCH4); default: the formal BCH series, expanded and
        pruned.  Only with ``order`` the lowest power.

    Returns
    -------
    FIResult

    Examples
    --------
    >>> from nambu_bch import model
    >>> R = fi_route(model("ho3"), "12321")
    >>> [len(c.representations) for c in R.commutators]          # Eqs. (CL5)-(CL8): two each
    [2, 2, 2, 2]
    >>> R.commutators[0].representations[0].labels                # Eq. (CL5), first alternative
    ('1AX', '1BX')
    >>> R4 = fi_route(model("ho3"), "12321", 4)                   # h^4: six brackets of depth 4
    >>> [(o.order, o.status) for o in R4.orders], (R4.orders[1].fi_dim, R4.orders[1].direct_dim)
    ([(3, 'vanishes'), (4, 'solved')], (3, 5))

    References
    ----------
    Horikoshi, Eqs. (BCH2)-(BCH5), (CL2a), (CL2b), (1AX)-(2BY), (CL5)-(CL8), (SH12321c), (Xeff3).
    """
    system = as_system(system)
    comp, power = _checked_request(system, word, order, terms)
    # the commutators' coefficients lie in the composition's field (QQ(i), QQ(2^(1/3)), ...): solve over it
    alg = system.algebra.with_constants(extension=comp.extension)
    atoms, per_slot = _atoms(system)
    ctx = {"algebra": alg, "atoms": atoms, "per_slot": per_slot}
    commutators = _commutators(system, comp, power, terms, atoms)
    user_degree = degree is not None
    degree = _ansatz_degree(commutators, degree)
    hams = system.hamiltonians
    ansatz = Ansatz(alg.n, degree, len(hams))
    wcols, rows, columns, rhs = _weight_system(ctx, commutators, ansatz)
    sol = solve_affine(SparseMatrix.from_columns(columns, len(rows), alg.domain), [rhs])
    result = FIResult(system, comp, power, commutators, sol.consistent, degree, _ctx=ctx)
    if not sol.consistent:
        inverse = rows.keys()
        result.certificate = {str(inverse[r]): alg.domain.to_sympy(v) for r, v in sol.certificate.items()}
        return result
    nw = len(wcols)
    ctx.update(nw=nw, ansatz=ansatz)
    # the canonical members (one rule: algebra/ansatz.py), the weights cleared last
    prios = ansatz.priorities([alg.convert(Hk).keys() for Hk in hams], offset=nw, rest=range(nw))
    members, vecs = _canonical_members(alg, commutators, wcols, ansatz, sol, prios)
    result.members = tuple(members)
    result.kernel = kernel_rref(sol.kernel, prios[0], alg.domain)
    fi_dim = rank(SparseMatrix.from_rows([{c: v for c, v in vec.items() if c >= nw} for vec in result.kernel],
                                         nw + len(ansatz), alg.domain))
    fi_members = [_exact_member(alg, ansatz, [0], [vec], nw) for vec in vecs]
    result.family, result.span = _whole_family(alg, hams, ansatz, nw, sol.particular, [0],
                                               degree if user_degree else None, fi_members, fi_dim, power)
    result.corrections = None  # built from result.family on first access
    if order > power:
        _higher_orders(result, order, degree if user_degree else None)
    return result


def _checked_request(system, word, order, terms) -> tuple:
    """``(composition, lowest power)`` of a request, the order and ``terms`` checked against that power."""
    comp = composition_for(word, system.splitting)
    power = 2 if comp.symmetric else 1
    if not is_int(order, power, MAX_FI_ORDER):
        raise InvalidOrderError(
            f"the FI route solves h^{power}..h^{MAX_FI_ORDER} for {'symmetric' if comp.symmetric else 'non-symmetric'} "
            f"word {comp.name!r}; got order={order!r} -- use route='direct' for other orders"
        )
    if terms is not None and order != power:
        raise InvalidOrderError(f"terms= gives the h^{power} brackets only; got order={order!r}")
    return comp, power


def _commutators(system, comp, power, terms, atoms) -> list:
    """The lowest-order commutators (the formal BCH series expanded and pruned, or the given ``terms``), merged,
    each with its distinct FI representations (Eqs. (1AX)-(2BY), (CL5)-(CL8))."""
    splitting = system.splitting
    if terms is None:
        terms = expand_terms(formal_bch(comp, power + 1).terms(power + 1), splitting, prune=True,
                             evaluators=_evaluators(splitting))
    entries = []
    for coef, tree in _terms(terms, 2):
        coef = as_expression(coef, None, "a coefficient of terms")
        _check_term_tree(tree, len(system.hamiltonians), power)
        if power == 2:
            entries.append(_as_double(coef, tree))
        else:
            entries.append((coef, tuple(tree)))
    entries = _merge(entries)
    commutators = []
    ops = _raw_ops(system.algebra, atoms)
    for coef, leaves in entries:
        distinct = [FIRepresentation(labels, shown, formal) for labels, shown, formal in _distinct_forms(ops, leaves)]
        commutators.append(FICommutator(coef, leaves, distinct))
    return commutators


def _ansatz_degree(commutators, degree) -> int:
    """``degree`` checked, or by default the largest monomial degree met in the representations (at least 1)."""
    if degree is None:
        degree = max((sum(v) for c in commutators for r in c.representations for key in r.formal.terms
                      for kind, v in key if kind == 0), default=1)
        return max(degree, 1)
    if not is_int(degree, 1):
        raise InvalidOrderError(f"degree must be a positive integer (the ansatz degree) or None, got {degree!r}")
    return degree


def _weight_system(ctx, commutators, ansatz) -> tuple:
    """The affine system of Eq. (BCH5): columns the weights ``(t, r)`` of each representation, then the ansatz's
    corrections ``(a, monomial)``; rows the formal Liouville keys and one "weights sum to 1" row per commutator.
    Returns ``(weight columns, rows, columns, right-hand side)``."""
    alg = ctx["algebra"]
    wcols = [(t, r) for t, c in enumerate(commutators) for r in range(len(c.representations))]
    rows = Rows()
    columns = []
    for t, r in wcols:
        comm = commutators[t]
        scaled = comm.representations[r].formal.scale(comm.coefficient)
        vec = {rows(("k", k)): v for k, v in scaled.terms.items()}
        vec[rows(("w", t))] = alg.domain.one
        columns.append(vec)
    for a, e in ansatz.columns:
        formal = _monomial_column(ctx, a, e)
        columns.append({rows(("k", k)): -v for k, v in formal.terms.items()})
    rhs = {rows(("w", t)): alg.domain.one for t in range(len(commutators))}
    return wcols, rows, columns, rhs


def _canonical_members(alg, commutators, wcols, ansatz, sol, prios) -> list:
    """One :class:`FIMember` per priority order: the canonical solution's weights and corrections; and the
    canonical solution vectors."""
    nw = len(wcols)
    members, vecs = [], []
    for prio in prios:
        vec, = Ansatz.canonical(sol.particular, sol.kernel, prio, alg.domain)
        weights = [[sympy.Integer(0)] * len(c.representations) for c in commutators]
        for col, v in vec.items():
            if col < nw:
                t, r = wcols[col]
                weights[t][r] = alg.domain.to_sympy(v)
        members.append(FIMember(weights, ansatz.expressions(vec, alg.coordinates, alg.domain, offset=nw)))
        vecs.append(vec)
    return members, vecs


# -- higher orders -----------------------------------------------------------------------------------


def _alpha_parts(alg, expr) -> dict:
    """``{k: ring element}``: the coefficient of ``alpha^k`` of a correction (sympy), in the algebra's ring."""
    expr = sympy.expand(expr)
    if expr == 0:
        return {}
    if not expr.has(ALPHA):
        return {0: alg.convert(expr)}
    return {m[0]: alg.convert(c) for m, c in sympy.Poly(expr, ALPHA).terms() if c != 0}


def _cross_terms(ops, per_slot, j, corrections, slots) -> dict:
    """``{k: LiouvilleSum}``: the alpha^k part of the products of lower-order corrections at ``h^j`` (formal).

    ``corrections[(a, o)]`` is ``{k: ring element}`` (alpha^k parts of the slot-``a`` correction at ``h^o``).
    """
    raw: dict = {}
    for orders in product(range(j), repeat=slots):
        if sum(orders) != j or sum(1 for o in orders if o) < 2:
            continue
        choices = []
        for a, o in enumerate(orders):
            if o == 0:  # a Hamiltonian slot: the sum of its atoms
                atoms = [ops.from_slots((f,)) for f in per_slot[a]]
                choices.append([(0, [(k[0], c) for A in atoms for k, c in A.items()])])
            else:
                choices.append([(k, ops.monomials(p)) for k, p in corrections.get((a, o), {}).items()])
        for pick in product(*choices):
            k = sum(p for p, _ in pick)
            part = raw.setdefault(k, {})
            for key, v in ops.from_expanded([e for _, e in pick]).items():
                part[key] = part.get(key, ops.domain.zero) + v
    out = {k: ops.reduce(v) for k, v in raw.items()}
    return {k: v for k, v in out.items() if not v.is_zero()}


def _max_degree(sums) -> int:
    return max((sum(v) for f in sums for key in f.terms for kind, v in key if kind == 0), default=1)


def _direct_kernel_dim(alg, hams, ansatz) -> int:
    """``dim ker (dH, dG) -> X_{dH,G} + X_{H,dG}`` on the polynomials of ``ansatz`` (the direct route's gauge)."""
    rows = Rows()
    vecs = operator_columns(alg, [alg.convert(Hk) for Hk in hams], ansatz, rows)
    return len(vecs) - rank(SparseMatrix.from_rows(vecs, len(rows), alg.domain))


@dataclass(frozen=True)
class FISpan:
    """How much of one order's family the FI representations reach.

    The FI route solves the formal equation, whose solutions are field solutions; its family is then
    the FI particular solution plus the whole kernel of ``(dH, dG) -> X_{dH,G} + X_{H,dG}`` at the
    direct route's ansatz degree, with the direct route's canonical members, so both routes return
    the same alpha-family.  This record says whether the FI solutions alone held that family.

    Attributes
    ----------
    order : int -- the power of ``h``
    degree : int -- ansatz degree of the family (the direct route's default, or the degree given)
    fi_dim : int -- dimension of the corrections reached through FI representations (at the FI degree)
    gauge_dim : int -- dimension of the whole kernel at ``degree``
    reached : bool -- both canonical members are FI solutions (the FI family is the whole family)
    """

    order: int
    degree: int
    fi_dim: int
    gauge_dim: int
    reached: bool

    def reason(self) -> str | None:
        """Why the family needed directions the FI representations miss (None when it did not)."""
        if self.reached:
            return None
        return (f"h^{self.order}: the FI representations reach {self.fi_dim} of the {self.gauge_dim} gauge directions "
                f"(degree {self.degree}) and not the alpha-family's; its members are completed by the direct route's "
                "kernel (formal FI sums keep the Hamiltonian pieces whole, so they miss field identities such as "
                "X_{H,H} = 0)")

    def to_dict(self) -> dict:
        return {"order": self.order, "degree": self.degree, "fi_dim": self.fi_dim, "gauge_dim": self.gauge_dim,
                "reached": self.reached, "reason": self.reason()}


def _whole_family(alg, hams, ansatz, nw, particulars, powers, degree, fi_members, fi_dim, order):
    """The canonical members of (FI particular solution) + (the direct route's kernel), and their :class:`FISpan`.

    Parameters
    ----------
    alg : the system's algebra; hams : its Hamiltonians (sympy)
    ansatz : Ansatz -- the FI solve's corrections, columns ``nw + k``
    particulars : list of sparse vectors -- one FI particular solution per power of alpha in ``powers``
    degree : int or None -- the ansatz degree asked for (None: the direct route's default, at least the FI one)
    fi_members : the FI route's own two members (exact, as :class:`AlphaFamily` holds them), to tell whether
        they were already the family's
    fi_dim, order : for the :class:`FISpan`

    Returns
    -------
    (family, span) -- the :class:`AlphaFamily` and the span record
    """
    domain = alg.domain
    rings = [alg.convert(Hk) for Hk in hams]
    vecs = [{c - nw: v for c, v in vec.items() if c >= nw} for vec in particulars]
    rows, cols, _ = _operator(alg, hams, rings, ansatz.degree, kernel=False)
    if degree is None:  # the degree of the field the particular solution makes, and the direct route's rule
        field: dict = {}
        for vec in vecs:
            for c, v in vec.items():
                for r, w in cols[c].items():
                    field[r] = field.get(r, domain.zero) + v * w
        keys = rows.keys()
        rhs_deg = max((sum(keys[r][1]) for r, v in field.items() if v), default=0)
        gdeg = [max((sum(m[: alg.n]) for m in p.keys()), default=0) - 1 for p in rings]
        degree = max(ansatz.degree, needed_degree(gdeg, rhs_deg)[0])
    big = ansatz if degree == ansatz.degree else Ansatz(alg.n, degree, ansatz.slots)
    if big is not ansatz:
        vecs = [{big.index[ansatz.columns[c]]: v for c, v in vec.items()} for vec in vecs]
    kernel = _operator(alg, hams, rings, degree)[2]
    members = tuple(_exact_member(alg, big, powers, [normal_form(vec, kernel, prio, domain) for vec in vecs])
                    for prio in big.priorities([p.keys() for p in rings]))
    reached = all(_same_member(m, f) for m, f in zip(members, fi_members))
    return AlphaFamily(alg, members), FISpan(order, degree, fi_dim, len(kernel), reached)


_OPERATOR: dict = {}


def _operator(alg, hams, rings, degree, kernel=True) -> tuple:
    """``(rows, columns, kernel)`` of ``(dH, dG) -> X_{dH,G} + X_{H,dG}`` on the ansatz of ``degree``, memoised
    (shared by all words and orders of a system; ``kernel`` None until first asked for)."""
    key = (alg.ring, alg.coordinates, tuple(hams), degree)
    entry = _OPERATOR.get(key)
    if entry is None:
        if len(_OPERATOR) > 256:
            _OPERATOR.clear()
        rows = Rows()
        entry = _OPERATOR[key] = [rows, operator_columns(alg, rings, Ansatz(alg.n, degree, len(rings)), rows), None]
    if kernel and entry[2] is None:
        entry[2] = solve_affine(SparseMatrix.from_columns(entry[1], len(entry[0]), alg.domain), []).kernel
    return tuple(entry)


def _family(members) -> tuple:
    """``(1 - alpha) m_0 + alpha m_1``, expanded, per slot."""
    return tuple(sympy.expand((1 - ALPHA) * c0 + ALPHA * c1) for c0, c1 in zip(*members))


def _higher_orders(result, order, degree) -> None:
    """Solve ``h^{power+1} .. h^order`` by the recursive hulls (fi_nested), the lower family fed into the cross terms."""
    system, comp, ctx = result.system, result.composition, result._ctx
    alg, atoms = ctx["algebra"], ctx["atoms"]
    if not result.exists:
        return
    corrections = {(a, result.power): parts for a, parts in enumerate(result.family.alpha_parts())}
    ops = _raw_ops(alg, atoms)
    memo = ops.hulls  # hulls of subtrees, shared by all words of the splitting
    series = formal_bch(comp, order + 1)
    for j in range(result.power + 1, order + 1):
        o = _solve_order(system, ctx, ops, memo, series, j, corrections, degree)
        if o.status == "obstructed":
            # the certificate is the first left null vector in row order, and the cross terms' rows are numbered in
            # the order of the lower orders' terms; the route has always taken that order from their sympy forms
            # (an exact ring element built from an expression): the terminal, obstructed order is solved again with
            # that order, so that its certificate stays the one the route has always printed (only an obstructed
            # order pays for the second solve)
            o = _solve_order(system, ctx, ops, memo, series, j, _sympy_ordered(alg, result), degree)
        result.orders.append(o)
        if o.status == "obstructed":
            result.exists = False
            result.failed_order = j
            return
        parts = o.family.alpha_parts() if o.status == "solved" else [{} for _ in o.corrections]
        for a, p in enumerate(parts):
            corrections[(a, j)] = p
    ctx["ops"] = ops


def _sympy_ordered(alg, result) -> dict:
    """The lower orders' alpha parts of ``result`` (as the cross terms take them) from their sympy forms."""
    out = {(a, result.power): _alpha_parts(alg, c) for a, c in enumerate(result.corrections)}
    for o in result.orders:
        out.update({(a, o.order): _alpha_parts(alg, c) for a, c in enumerate(o.corrections)})
    return out


_EVALUATORS = weakref.WeakKeyDictionary()


def _evaluators(splitting):
    """The memoised piece and term evaluators of a splitting (pruning of vanishing brackets), shared by all words."""
    if splitting not in _EVALUATORS:
        _EVALUATORS[splitting] = (piece_evaluator(splitting), term_evaluator(splitting))
    return _EVALUATORS[splitting]


def _merged_trees(system, series, j) -> list:
    """``[(coefficient, tree)]``: the BCH brackets at ``h^j`` in Liouville terms, vanishing ones pruned, equal ones merged."""
    merged: dict = {}
    for coef, tree in expand_terms(series.terms(j + 1), system.splitting, prune=True,
                                   evaluators=_evaluators(system.splitting)):
        merged[tree] = merged.get(tree, 0) + sympy.sympify(coef, strict=True)
    return [(c, tree) for tree, c in merged.items() if c != 0]


def _brackets(system, series, j, ops, memo, limit=None) -> list:
    """The BCH brackets at ``h^j`` with their hulls (the first ``limit`` of them if given)."""
    trees = _merged_trees(system, series, j)
    return [FINested(c, tree, nested_hull(ops, tree, memo), ops) for c, tree in trees[:limit]]


@dataclass(frozen=True)
class FIForms:
    """The eight fundamental-identity forms of ``[X_{A,B},[X_{C,D},X_{E,F}]]`` (Eqs. 1AX-2BY) and, for a system,
    each ``h^2`` double commutator of the BCH series in them (Eqs. CL5-CL8): what ``nambu-bch fi`` prints.

    Attributes
    ----------
    system : System
    composition : Composition
    representations : list or None -- :func:`~nambu_bch.shadow.fundamental_identity.bch_double_commutators`
        of the system, or None for the forms alone
    """

    system: object
    composition: object
    representations: list | None = None

    def to_dict(self) -> dict:
        """JSON-ready: ``forms`` (label, text, LaTeX); with a system its part first and ``representations``;
        ``nambu-bch fi --format json`` prints exactly this dict."""
        from .. import render
        from .fundamental_identity import FI_LABELS

        out = {"forms": [{"label": lab, "text": render.fi_form_text(lab), "latex": render.fi_form_latex(lab)}
                         for lab in FI_LABELS]}
        if self.representations is None:
            return out
        out = {**render.result_head(self.system, self.composition.name), **out}
        out["representations"] = [
            {
                "coefficient": render.expression(c),
                "commutator": [[render.expression(s) for s in t] for t in abd],
                "forms": {lab: [{"coefficient": render.expression(t.coefficient),
                                 "slots": [render.expression(s) for s in t.expressions]} for t in terms]
                          for lab, terms in forms.items()},
            }
            for c, abd, forms in self.representations
        ]
        return out

    def to_text(self) -> str:
        from .. import render
        from .fundamental_identity import FI_LABELS

        lines = [f"{lab}: {render.fi_form_text(lab)}" for lab in FI_LABELS]
        for c, abd, forms in self.representations or ():
            a, b, d = ("X_{" + ", ".join(str(s) for s in t) + "}" for t in abd)
            lines.append(f"{c} [{a}, [{b}, {d}]] (h^2 term of {self.composition.name} on {self.system.name}):")
            lines += [f"  {lab}: " + (" + ".join(str(t) for t in terms) or "0") for lab, terms in forms.items()]
        return "\n".join(lines)

    def to_latex(self) -> list:
        from .. import render

        title = f"{self.composition.name} on {self.system.name}"
        return [render.fi_forms_latex()] + [render.fi_representations_latex(title, c, abd, forms)
                                            for c, abd, forms in self.representations or ()]


def fi_forms(system, word) -> FIForms:
    """The eight FI forms and each ``h^2`` double commutator of ``word`` on ``system`` in them (Eqs. CL5-CL8).

    >>> from nambu_bch import model
    >>> F = fi_forms(model("ho3"), "12321")
    >>> len(F.to_dict()["forms"]), F.to_dict()["representations"][0]["coefficient"]
    (8, '-1/24')
    """
    from .fundamental_identity import bch_double_commutators

    comp = composition_for(word, system.splitting)
    return FIForms(system, comp, bch_double_commutators(system, comp))


class FIBrackets(list):
    """The brackets of ``X_eff`` at one power of ``h`` with their FI hulls: a list of :class:`FINested`.

    Attributes
    ----------
    system : System
    composition : Composition
    order : int -- the power of ``h``
    total : int -- the number of brackets at ``h^order`` (the list holds the first ``limit`` of them)
    limit : int or None -- at most this many brackets, and this many directions per bracket, are shown
    """

    def __init__(self, items, system, composition, order: int, total: int, limit=None):
        super().__init__(items)
        self.system, self.composition, self.order, self.total, self.limit = system, composition, order, total, limit

    def _more(self):
        return f"... {self.total - len(self)} more brackets (raise --limit)" if len(self) < self.total else None

    def to_dict(self) -> dict:
        """JSON-ready: the system part, ``order``, ``total`` and ``brackets`` (:meth:`FINested.to_dict`);
        ``nambu-bch fi --order K --format json`` prints exactly this dict."""
        from ..render import result_head

        return {**result_head(self.system, self.composition.name, order=self.order), "total": self.total,
                "brackets": [b.to_dict(self.limit) for b in self]}

    def to_text(self) -> str:
        head = f"h^{self.order} brackets of {self.composition.name} on {self.system.name}: {self.total}"
        more = self._more()
        return "\n".join([head, *(b.to_text(self.limit) for b in self), *([more] if more else [])])

    def to_latex(self) -> str:
        from ..printing import latex_text

        title = latex_text(f"{self.composition.name} on {self.system.name}, {self.total} brackets at") + f" h^{{{self.order}}}"
        more = self._more()
        return " \\\\\n".join([title, *(b.to_latex(self.limit) for b in self), *([latex_text(more)] if more else [])])


def fi_brackets(system, word, order: int, limit=None) -> FIBrackets:
    """The brackets of ``X_eff`` at ``h^order``, each with the affine hull of its FI representations.

    Parameters
    ----------
    system : System
    word : composition spec
    order : int -- the power of ``h`` (1..MAX_FI_ORDER)
    limit : int, optional -- build the hulls of the first ``limit`` brackets only
        (:func:`count_brackets` gives the total; the rigid body has 22 272 brackets at ``h^6``)

    Returns
    -------
    FIBrackets -- a list of FINested, empty when the order vanishes (odd orders of a symmetric word), with
    ``total`` and ``to_dict`` / ``to_text`` / ``to_latex``

    Examples
    --------
    >>> from nambu_bch import model
    >>> B = fi_brackets(model("ho3"), "12321", 4)        # the six degree-5 brackets of Eq. (BCH3) that survive
    >>> len(B), [b.hull.dimension for b in B]
    (6, [1, 1, 2, 2, 1, 1])
    """
    system = as_system(system)
    comp = _bracket_composition(system, word, order)
    if limit is not None and not is_int(limit, 1):
        raise NambuBCHError(f"limit must be a positive integer or None, got {show(limit)}")
    atoms, _ = _atoms(system)
    trees = _merged_trees(system, formal_bch(comp, order + 1), order)
    ops = RawOps(system.algebra, atoms)
    memo: dict = {}
    items = [FINested(c, tree, nested_hull(ops, tree, memo), ops) for c, tree in trees[:limit]]
    return FIBrackets(items, system, comp, order, len(trees), limit)


def count_brackets(system, word, order: int) -> int:
    """The number of brackets :func:`fi_brackets` lists at ``h^order`` (no hulls built).

    >>> from nambu_bch import model
    >>> count_brackets(model("ho3"), "12321", 4), count_brackets(model("ho3"), "12321", 5)
    (6, 0)
    """
    system = as_system(system)
    comp = _bracket_composition(system, word, order)
    return len(_merged_trees(system, formal_bch(comp, order + 1), order))


def bracket_bound(system, word, order: int) -> int:
    """An upper bound of :func:`count_brackets` from the piece-level BCH trees alone (no Liouville-term bracket built).

    Each tree of the BCH series at ``h^order`` in the pieces that does not vanish on the pieces' fields (the first
    pruning of :func:`~nambu_bch.bch.expand_terms`, Eq. BCH4) expands into ``prod_leaf n_leaf`` trees of Liouville
    terms, ``n_k`` the number of terms of piece ``k`` (Eq. BCH3: ``2^3`` per double commutator of the generic N = 3
    system).  The sum of these products bounds the count; it equals it unless an expanded tree vanishes on its own
    or two coincide (pieces sharing a term).  The piece-level trees are few (174 for the rigid body at ``h^6``, of
    22 272 expanded ones), so this decides the size of a listing before the costly term-level evaluation.

    >>> from nambu_bch import model
    >>> bracket_bound(model("ho3"), "12321", 4), bracket_bound(model("rigid-body"), "12321", 6)
    (6, 22272)
    """
    system = as_system(system)
    comp = _bracket_composition(system, word, order)
    splitting = system.splitting
    pieces_eval, _ = _evaluators(splitting)
    total = 0
    for _, tree in formal_bch(comp, order + 1).terms(order + 1):
        if not pieces_eval.is_zero(tree):
            count = 1
            for leaf in tree_leaves(tree):
                count *= len(splitting[leaf].terms)
            total += count
    return total


def _bracket_composition(system, word, order):
    comp = composition_for(word, system.splitting)
    if not is_int(order, 1, MAX_FI_ORDER):
        raise InvalidOrderError(f"order must be an integer between 1 and {MAX_FI_ORDER} for the FI brackets, got {show(order)}")
    return comp


def _solve_order(system, ctx, ops, memo, series, j, corrections, degree) -> FIOrder:
    """One power ``h^j``: ``sum_t c_t (p_t + sum_k w_tk d_tk) = X_{H,dG_j} + X_{dH_j,G} + cross``, linear.

    ``corrections[(a, o)]`` holds the lower orders' alpha-family (``{k: ring element}``); the right-hand
    side is split by powers of alpha (so the solution is polynomial in alpha), the two members are
    the normal forms of :func:`fi_route`, and the family is ``(1 - alpha) member_0 + alpha member_1``.
    """
    alg, atoms = ctx["algebra"], ctx["atoms"]
    domain = alg.domain
    hams = system.hamiltonians
    slots = len(hams)
    user_degree = degree
    commutators = _brackets(system, series, j, ops, memo)
    base = LiouvilleSum.zero(alg, atoms)
    ech = Echelon(domain)
    directions, dvecs = [], []
    for t, comm in enumerate(commutators):
        c = domain.from_sympy(comm.coefficient)
        base = base + ops.reduce(comm.hull.base, c)
        for label, d in comm.hull.directions:
            vec = ops.reduce(d, c)
            if not vec.is_zero() and ech.insert(dict(vec.terms)):
                directions.append((t, label))
                dvecs.append(vec)
    cross = _cross_terms(ops, ctx["per_slot"], j, corrections, slots)
    rhs_sums = dict(cross)
    rhs_sums[0] = rhs_sums[0] - base if 0 in rhs_sums else -base
    rhs_sums = {k: v for k, v in rhs_sums.items() if not v.is_zero()}
    if not rhs_sums and not dvecs:
        return FIOrder(j, "vanishes", corrections=(sympy.Integer(0),) * slots, commutators=commutators)
    if degree is None:
        degree = max(_max_degree([base, *dvecs, *rhs_sums.values()]), 1)
    ansatz = Ansatz(alg.n, degree, slots)
    rows = Rows()
    columns = [rows.vector(v.terms) for v in dvecs]
    for a, e in ansatz.columns:
        columns.append(rows.vector(_monomial_column(ctx, a, e).terms, -1))
    powers = sorted(rhs_sums)
    rhs = [rows.vector(rhs_sums[k].terms) for k in powers]
    nw = len(dvecs)
    sol = solve_affine(SparseMatrix.from_columns(columns, len(rows), domain), rhs)
    out = FIOrder(j, "solved", degree, commutators, directions)
    if not sol.consistent:
        inverse = rows.keys()
        out.status = "obstructed"
        out.certificate = {str(inverse[r]): domain.to_sympy(v) for r, v in sol.certificate.items()}
        return out
    # the canonical members (one rule: algebra/ansatz.py), the FI directions' weights cleared last
    prios = ansatz.priorities([alg.convert(Hk).keys() for Hk in hams], offset=nw, rest=range(nw))
    members = [_exact_member(alg, ansatz, powers, Ansatz.canonical(sol.particular, sol.kernel, prio, domain), nw)
               for prio in prios]
    projected = [{col: v for col, v in vec.items() if col >= nw} for vec in sol.kernel]
    projected = [p for p in projected if p]
    basis = kernel_rref(projected, prios[0][: len(ansatz)], domain) if projected else []
    tail = (0,) * (len(alg.gens) - alg.n)
    out._kernel_exact = tuple(tuple(ansatz.polynomials(vec, alg.ring, tail, nw)) for vec in basis)
    out.fi_dim = len(basis)
    out._direct = (alg, hams, ansatz)
    out.family, out.span = _whole_family(alg, hams, ansatz, nw, sol.particular, powers, user_degree, members,
                                         out.fi_dim, j)
    if out.span.degree == degree:  # the kernel at the FI degree was just computed
        out._direct_dim = out.span.gauge_dim
    out.corrections = out.members = out.kernel = None  # built from the exact data on first access
    return out
