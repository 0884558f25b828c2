"""The FI route: shadow Hamiltonians from the representations of the BCH commutators (Sect. 4.2, 5.2).

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
condition is linear and is solved exactly (:mod:`nambu_bch.shadow.linear`).
The result is the whole solution family (particular + kernel), its two
canonical members and their alpha-family (same rule as the direct route, see
:mod:`nambu_bch.shadow.direct_route`), and :meth:`FIResult.check_member` to
test a given choice, e.g. the paper's Eqs. (CL5a)-(CL8a) with (SH12321a).

References
----------
Horikoshi, Eqs. (BCH2)-(BCH5), (CL5)-(CL8b), (SH12321a)-(SG12321c), (Xeff3).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import product

import sympy

from ..bch import expand_terms, formal_bch
from ..bch.lyndon import is_bracket
from ..errors import InvalidOrderError, NambuBCHError
from ..integrators.composition import composition_for
from .direct_route import ALPHA, H_STEP, _monomials
from .fundamental_identity import representations, single_representations
from .linear import kernel_rref, normal_form, solve_affine
from .liouville_terms import LiouvilleSum


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
class FIResult:
    """The FI-route solution family for one system, composition and power of ``h``.

    Attributes
    ----------
    power : int -- the power of ``h`` solved (2 for symmetric words, 1 otherwise)
    commutators : list of FICommutator
    exists : bool
    members : (FIMember, FIMember) -- the ``alpha = 0`` and ``alpha = 1`` members
    corrections : tuple -- the alpha-family ``(dH, dG)`` (sympy, in ``alpha``)
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
    _ctx: dict = field(default_factory=dict, repr=False)

    @property
    def free_parameter_count(self) -> int:
        """Dimension of the whole solution family (weights and corrections)."""
        return len(self.kernel)

    def shadow(self) -> tuple:
        """``(H_S, G_S)`` of the alpha-family through ``h^power``."""
        return tuple(
            sympy.expand(Hk + H_STEP**self.power * c) for Hk, c in zip(self.system.hamiltonians, self.corrections)
        )

    def combination(self, weights) -> LiouvilleSum:
        """``sum_t c_t sum_r w_{t,r} R_{t,r}``; ``weights[t]`` maps a label (or rep index) to its weight."""
        total = LiouvilleSum.zero(self._ctx["algebra"], self._ctx["atoms"])
        for t, comm in enumerate(self.commutators):
            w = weights[t]
            items = w.items() if isinstance(w, dict) else enumerate(w)
            for key, value in items:
                rep = self._rep(comm, key)
                total = total + rep.formal.scale(comm.coefficient * sympy.sympify(value))
            if sympy.simplify(sum(sympy.sympify(v) for _, v in (w.items() if isinstance(w, dict) else enumerate(w))) - 1) != 0:
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

    def kernel_corrections(self) -> list:
        """The ``(dH, dG, ...)`` part of every homogeneous solution (weights dropped), as sympy expressions."""
        alg, nw, ccols = self._ctx["algebra"], self._ctx["nw"], self._ctx["ccols"]
        out = []
        for vec in self.kernel:
            corr = [sympy.Integer(0)] * len(self.system.hamiltonians)
            for col, v in vec.items():
                if col >= nw:
                    a, e = ccols[col - nw]
                    corr[a] += alg.domain.to_sympy(v) * sympy.Mul(*(x**p for x, p in zip(alg.coordinates, e)))
            out.append(tuple(corr))
        return out

    def to_text(self) -> str:
        lines = [f"FI route, {self.composition.name}, h^{self.power}:"]
        for t, comm in enumerate(self.commutators):
            lines.append(f"  ({comm.coefficient}) {comm.label()}")
            for r, rep in enumerate(comm.representations):
                w0 = self.members[0].weights[t][r] if self.members else "-"
                w1 = self.members[1].weights[t][r] if self.members else "-"
                lines.append(f"     {'/'.join(rep.labels)}: {rep}   weights (alpha=0, 1): {w0}, {w1}")
        return "\n".join(lines)


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


def _target_term(ctx, a, correction) -> LiouvilleSum:
    """``X_{H^1, .., correction, .., H^{N-1}}`` with every Hamiltonian slot a sum of its atoms."""
    alg, atoms, per_slot = ctx["algebra"], ctx["atoms"], ctx["per_slot"]
    total = LiouvilleSum.zero(alg, atoms)
    choices = [per_slot[b] if b != a else [correction] for b in range(len(per_slot))]
    for slots in product(*choices):
        total = total + LiouvilleSum.from_slots(alg, slots, atoms=atoms)
    return total


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
    order : int -- 2 for symmetric words (1 for other words); odd orders of a symmetric word vanish
    degree : int, optional -- ansatz degree of ``dH, dG`` (default: the largest monomial degree met)
    terms : list of ``(coefficient, tree)``, optional -- the commutators to represent, with leaves
        Liouville terms (e.g. the paper's Eq. BCH4); default: the formal BCH series, expanded and pruned.

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
    """
    from ..systems.system import as_system

    system = as_system(system)
    splitting = system.splitting
    comp = composition_for(word, splitting)
    power = 2 if comp.symmetric else 1
    if order != power and terms is None:
        raise InvalidOrderError(
            f"the FI route solves the lowest correction, h^{power} for {'symmetric' if comp.symmetric else 'non-symmetric'} "
            f"word {comp.name!r}; got order={order!r} -- use route='direct' for other orders"
        )
    alg = system.algebra
    atoms, per_slot = _atoms(system)
    ctx = {"algebra": alg, "atoms": atoms, "per_slot": per_slot}
    if terms is None:
        terms = expand_terms(formal_bch(comp, power + 1).terms(power + 1), splitting, prune=True)
    entries = []
    for coef, tree in terms:
        if power == 2:
            entries.append(_as_double(sympy.sympify(coef), tree))
        else:
            entries.append((sympy.sympify(coef), tuple(tree)))
    entries = _merge(entries)
    commutators = []
    ring_of: dict = {}

    def to_ring(term):  # convert each Hamiltonian piece once; brackets then stay in the ring
        return tuple(ring_of.setdefault(f, alg.convert(f)) for f in term)

    for coef, leaves in entries:
        rleaves = tuple(to_ring(t) for t in leaves)
        reps = representations(alg, *rleaves) if len(leaves) == 3 else single_representations(alg, *rleaves)
        distinct: list = []
        for label, rep_terms in reps.items():
            formal = LiouvilleSum.zero(alg, atoms)
            for t in rep_terms:
                formal = formal + LiouvilleSum.from_slots(alg, t.slots, t.coefficient, atoms=atoms)
            for d in distinct:
                if d.formal == formal:
                    d.labels += (label,)
                    break
            else:
                shown = tuple(t for t in rep_terms if not LiouvilleSum.from_slots(alg, t.slots, t.coefficient, atoms=atoms).is_zero())
                distinct.append(FIRepresentation((label,), shown, formal))
        commutators.append(FICommutator(coef, leaves, distinct))
    hams = system.hamiltonians
    slots = len(hams)
    if degree is None:
        degree = max((sum(v) for c in commutators for r in c.representations for key in r.formal.terms
                      for kind, v in key if kind == 0), default=1)
        degree = max(degree, 1)
    elif isinstance(degree, bool) or not isinstance(degree, int) or degree < 1:
        raise InvalidOrderError(f"degree must be a positive integer (the ansatz degree) or None, got {degree!r}")
    monos = _monomials(alg.n, degree)
    # columns: weights (t, r), then corrections (a, monomial)
    wcols = [(t, r) for t, c in enumerate(commutators) for r in range(len(c.representations))]
    ccols = [(a, e) for a in range(slots) for e in monos]
    keys: dict = {}

    def row(key):
        if key not in keys:
            keys[key] = len(keys)
        return keys[key]

    columns = []
    for t, r in wcols:
        comm = commutators[t]
        scaled = comm.representations[r].formal.scale(comm.coefficient)
        vec = {row(("k", k)): v for k, v in scaled.terms.items()}
        vec[row(("w", t))] = alg.domain.one
        columns.append(vec)
    for a, e in ccols:
        formal = _target_term(ctx, a, sympy.Mul(*(x**p for x, p in zip(alg.coordinates, e))))
        columns.append({row(("k", k)): -v for k, v in formal.terms.items()})
    rhs = {row(("w", t)): alg.domain.one for t in range(len(commutators))}
    sol = solve_affine(columns, [rhs], len(keys), alg.domain)
    result = FIResult(system, comp, power, commutators, sol.consistent, degree, _ctx=ctx)
    if not sol.consistent:
        inverse = {v: k for k, v in keys.items()}
        result.certificate = {str(inverse[r]): alg.domain.to_sympy(v) for r, v in sol.certificate.items()}
        return result
    nw = len(wcols)
    ctx.update(nw=nw, ccols=ccols)
    index = {c: nw + k for k, c in enumerate(ccols)}
    zero = (0,) * alg.n

    def priority(slot_order):
        out = [index[(a, zero)] for a in range(slots)]
        for a in slot_order:
            own = sorted({m[: alg.n] for m in alg.convert(hams[a]).keys()}, key=lambda e: tuple(reversed(e)), reverse=True)
            out += [index[(a, e)] for e in own if (a, e) in index and index[(a, e)] not in out]
            out += [index[c] for c in ccols if c[0] == a and index[c] not in out]
        return out + list(range(nw))

    members = []
    for prio in (priority(range(slots)), priority(reversed(range(slots)))):
        vec = normal_form(sol.particular[0], sol.kernel, prio, alg.domain)
        weights = [[sympy.Integer(0)] * len(c.representations) for c in commutators]
        corr = [sympy.Integer(0)] * slots
        for col, v in vec.items():
            v = alg.domain.to_sympy(v)
            if col < nw:
                t, r = wcols[col]
                weights[t][r] = v
            else:
                a, e = ccols[col - nw]
                corr[a] += v * sympy.Mul(*(x**p for x, p in zip(alg.coordinates, e)))
        members.append(FIMember(weights, tuple(corr)))
    result.members = tuple(members)
    result.corrections = tuple(sympy.expand((1 - ALPHA) * c0 + ALPHA * c1)
                               for c0, c1 in zip(members[0].corrections, members[1].corrections))
    result.kernel = kernel_rref(sol.kernel, priority(range(slots)), alg.domain)
    return result
