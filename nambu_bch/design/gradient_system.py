"""Force-gradient compositions and processed kernels on a canonical system ``H = T(p) + V(q)``: X_eff and H_S.

Structure.  For a canonical system split into the drift ``T(p)`` (piece 1) and the kick ``V(q)`` (piece 2), with ``T``
a quadratic form in the momenta with constant coefficients, the Poisson bracket ``G = {V, {T, V}}`` depends on the
positions only (``-|grad V|^2`` for ``T = |p|^2/2``, ``-grad V . M^(-1) grad V`` for ``T = p . M^(-1) p / 2``).  In
the package's convention ``X_H f = {f, H}`` the Lie operators satisfy ``[X_F, X_G] = -X_{{F,G}}``, so the double
bracket ``W = [X_2, [X_1, X_2]]`` of the pieces is ``X_G``, and it commutes with ``X_2`` (both move ``p`` by a function
of ``q``).  A force-gradient factor ``(2, b, c)`` = ``exp(b h X_2 + c h^3 W)`` is then the exact time-``h`` flow of the
potential ``b V + c h^2 G``: a kick, ``p <- p - h grad(b V + c h^2 G)``.  :func:`gradient_structure` checks all of this
exactly (and refuses in one line where it fails: non-canonical brackets, Nambu systems, non-separable splittings, a
kinetic part that is not a constant quadratic form).

Two routes to ``X_eff`` (:func:`gradient_effective_field`), which must agree exactly:

* ``"formal"``: ``log Phi`` as a word series in ``X_1, X_2`` (:mod:`.generalized`, the gradient term substituted as
  its bracket), its degree-``q`` part written on the Lyndon brackets ``P_u`` (``P_u = u + larger words``, a
  unitriangular system) and the brackets evaluated on the system's fields: ``Z_(q-1) = sum_u alpha_u P_u(X_1, X_2)``;
* ``"backward"``: backward error analysis of the map itself (Hairer, Lubich, Wanner, Sect. IX.1), the pull-back of
  each factor expanded as ``exp(b h X_2) exp(c h^3 W)`` (they commute), never touching a free Lie algebra.

Shadow Hamiltonians (:func:`gradient_shadow`).  Every factor is a Hamiltonian flow, so the method is symplectic and
``X_eff`` is Hamiltonian at every order: ``H_S = sum_j h^j H_j`` with ``H_j`` the Lie polynomial of ``Z_j`` read with
``X_1 -> T``, ``X_2 -> V`` and ``[a, b] -> -{a, b}``.  Each ``X_{H_j} = Z_j`` is checked exactly against the backward
route.

Processed methods (:func:`processor_field`).  The processor ``P`` of a kernel of effective order ``p`` is given by its
log ``Z = sum_q h^q Z_q`` (:func:`~nambu_bch.design.generalized.effective_order`); on a system ``Z_q`` is a concrete
field, and ``P K^n P^(-1)`` with ``P^* = exp(Z)`` applied as the truncated Lie series is how
:mod:`nambu_bch.numeric.force_gradient` runs it.

References
----------
Chin, Phys. Lett. A 226 (1997) 344; Omelyan, Mryglod & Folk, Comput. Phys. Commun. 151 (2003) 272 (force-gradient
algorithms); Takahashi & Imada, J. Phys. Soc. Jpn. 53 (1984) 3765; Blanes, Casas & Ros, SIAM J. Sci. Comput. 21
(1999) 711; Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sects. IX.1, IX.3.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from ..errors import InvalidCompositionError, InvalidSystemError
from ..values import ValueEquality
from .generalized import MAX_SERIES_DEGREE, _bracket_basis, _gradient_spec, _log_of
from .words import lyndon_defect_words

H = sympy.Symbol("h")
#: Highest power of ``h`` in ``X_eff`` here (the series degree is one more).
MAX_GRADIENT_ORDER = MAX_SERIES_DEGREE - 1


@dataclass(frozen=True, eq=False)
class GradientStructure:
    """The pieces of a canonical ``T(p) + V(q)`` system and the force-gradient potential ``G = {V, {T, V}}``.

    Attributes: ``system``, ``T``, ``V``, ``G`` (sympy, ``G`` depends on the positions only), ``positions``,
    ``momenta`` (symbols), ``fields`` (``{1: X_T, 2: X_V, 3: W = X_G}`` on the system's algebra).
    """

    system: object
    T: object
    V: object
    G: object
    positions: tuple
    momenta: tuple
    fields: dict


def poisson(f, g, positions, momenta):
    """The canonical bracket ``{f, g} = sum_i (df/dq_i dg/dp_i - df/dp_i dg/dq_i)`` (so ``X_H f = {f, H}``)."""
    return sympy.expand(sum(sympy.diff(f, q) * sympy.diff(g, p) - sympy.diff(f, p) * sympy.diff(g, q)
                            for q, p in zip(positions, momenta)))


def gradient_structure(system) -> GradientStructure:
    """Check that force-gradient factors are kicks on ``system`` and return its :class:`GradientStructure`.

    Refuses (:class:`~nambu_bch.errors.InvalidSystemError`, one line) a system that is not canonical, not split into
    ``T(p)`` and ``V(q)``, or whose ``T`` is not a quadratic form in the momenta with constant coefficients.
    """
    from ..algebra import liouville_field
    from ..bch.expansion import piece_evaluator
    from ..systems.spec import as_system

    system = as_system(system)
    if system.bracket != "canonical":
        raise InvalidSystemError(
            f"force-gradient methods need a canonical system H = T(p) + V(q); {system.name} has the {system.bracket} "
            f"bracket, where [X_2,[X_1,X_2]] is not a kick (use a splitting method)")
    splitting = system.splitting
    d = system.N // 2
    positions, momenta = system.coordinates[:d], system.coordinates[d:]
    if len(splitting) != 2 or any(len(p.terms) != 1 or len(p.terms[0]) != 1 for p in splitting.pieces):
        raise InvalidSystemError(f"force-gradient methods need the split H = T(p) + V(q); {system.name} is split into "
                                 f"{len(splitting)} pieces ({system.split})")
    T, V = splitting[1].terms[0][0], splitting[2].terms[0][0]
    if T.free_symbols & set(positions) or V.free_symbols & set(momenta):
        raise InvalidSystemError(f"force-gradient methods need piece 1 = T(p) and piece 2 = V(q); {system.name} has "
                                 f"pieces {T} and {V}")
    scaled = sympy.expand(T.subs({p: 2 * p for p in momenta}, simultaneous=True) - 4 * T)
    hessian_constant = all(sympy.diff(T, a, b).free_symbols.isdisjoint(system.coordinates) for a in momenta for b in momenta)
    if scaled != 0 or not hessian_constant:
        raise InvalidSystemError(f"force-gradient methods need a kinetic energy quadratic in the momenta with constant "
                                 f"coefficients; {system.name} has T = {T}")
    G = poisson(V, poisson(T, V, positions, momenta), positions, momenta)
    E = piece_evaluator(splitting)
    W = E.field((2, (1, 2)))
    if W != liouville_field(system.algebra, G):  # the identity the kicks rest on, checked on this system exactly
        raise InvalidSystemError(f"[X_2,[X_1,X_2]] is not the field of {{V,{{T,V}}}} on {system.name}")
    return GradientStructure(system, T, V, G, positions, momenta, {1: splitting[1].field, 2: splitting[2].field, 3: W})


def check_real_exact(comp, what: str) -> None:
    """Refuse, in one line, a composition these routes cannot take: published decimals (``X_eff`` would carry their
    rounding) or complex coefficients (the kicks are real flows)."""
    if comp.error_bound:
        raise InvalidCompositionError(f"{what} needs exact coefficients; {str(comp)!r} has published decimals")
    if comp.is_complex:
        raise InvalidCompositionError(f"{what} needs real coefficients; {str(comp)!r} has complex ones")


def _check_order(order):
    from ..checks import is_int
    from ..errors import InvalidOrderError

    if not is_int(order, 0, MAX_GRADIENT_ORDER):
        raise InvalidOrderError(f"order must be an integer in 0..{MAX_GRADIENT_ORDER}, got {order!r}")
    return order


def lie_coordinates(K, S, series: dict, q: int) -> list:
    """``[(u, alpha_u)]``: the degree-``q`` part of a Lie series on the Lyndon brackets ``P_u`` (exact sympy numbers).

    ``[w] series = sum_u alpha_u [w] P_u`` over the Lyndon words ``w`` of length ``q``; the matrix is unitriangular
    (``P_u = u + larger words``, Reutenauer, Thm. 5.1), so the solve is exact back-substitution.
    """
    words = lyndon_defect_words(2, q)
    basis = _bracket_basis(S, q)
    M = sympy.Matrix([[K.to_sympy(P.get(w, K.zero)) for P in basis] for w in words])
    v = sympy.Matrix([K.to_sympy(series.get(w, K.zero)) for w in words])
    alpha = M.LUsolve(v)
    return [(u, sympy.expand(a)) for u, a in zip(words, alpha)]


def _tree(u):
    from ..bch.lyndon import standard_bracketing

    return standard_bracketing(u) if len(u) > 1 else u[0]


def _value(E, u, n):
    """The components of the Lyndon bracket ``P_u`` on the pieces (zeros where the evaluator prunes it)."""
    field = E.field(_tree(u))
    return (sympy.Integer(0),) * n if field is None else field.to_sympy()


@dataclass(frozen=True, eq=False)
class GradientField(ValueEquality):
    """``X_eff = sum_j h^j Z_j`` of a force-gradient composition on a system, by one route.

    ``coefficients``: the ``Z_j`` as tuples of exact sympy expressions (components in the coordinates' order);
    ``lie``: per ``j`` the Lyndon coordinates ``[(u, alpha_u)]`` of ``Z_j`` (formal route only).  ``==`` compares
    the field (system, composition, order, ``Z_j``), so the two routes' results are equal exactly when they agree.
    """

    system: object
    composition: object
    order: int
    route: str
    coefficients: tuple
    lie: tuple = ()

    def __getitem__(self, j):
        return self.coefficients[j]

    def _value(self) -> tuple:
        """The exact data (``==``, ``hash``): the field itself, whichever route computed it."""
        return self.system, self.composition, self.order, self.coefficients

    def to_dict(self) -> dict:
        return {"system": self.system.name, "composition": str(self.composition), "route": self.route,
                "order": self.order, "Z": [[str(c) for c in Z] for Z in self.coefficients]}

    def __str__(self):
        lines = [f"X_eff of {self.composition} on {self.system.name} ({self.route} route), through h^{self.order}"]
        lines += [f"Z_{j} = ({', '.join(str(c) for c in Z)})" for j, Z in enumerate(self.coefficients) if any(Z)]
        return "\n".join(lines)


def gradient_effective_field(system, spec, order: int = 4, route: str = "formal") -> GradientField:
    """``X_eff`` of a force-gradient composition (or plain two-part composition) on ``system`` through ``h^order``.

    Parameters
    ----------
    system : a canonical ``T(p) + V(q)`` system (:func:`gradient_structure`)
    spec : ``"chin-4a"``, ``"takahashi-imada"``, a :class:`~nambu_bch.design.generalized.GradientComposition` or its
        factor list, or a two-part composition
    order : highest power of ``h`` (at most :data:`MAX_GRADIENT_ORDER`)
    route : ``"formal"`` (word series, Lyndon brackets evaluated on the fields) or ``"backward"`` (the map's own
        backward error analysis); both are exact and agree (module docstring)

    Examples
    --------
    >>> X = gradient_effective_field("ho", "chin-4a", order=4)
    >>> X[4] == gradient_effective_field("ho", "chin-4a", order=4, route="backward")[4]
    True
    """
    S = gradient_structure(system)
    comp = _gradient_spec(spec)
    check_real_exact(comp, "X_eff on a system")
    order = _check_order(order)
    if route == "formal":
        return _formal(S, comp, order)
    if route == "backward":
        return _backward(S, comp, order)
    raise InvalidCompositionError(f"route must be 'formal' or 'backward', got {route!r}")


def _formal(S, comp, order):
    from ..bch.expansion import piece_evaluator

    K, series, log = _log_of(comp, order + 1)
    E = piece_evaluator(S.system.splitting)
    zero = (sympy.Integer(0),) * S.system.N
    coefficients, lie = [], []
    for q in range(1, order + 2):
        coords = lie_coordinates(K, series, log, q)
        total = [sympy.Integer(0)] * S.system.N
        for u, a in coords:
            if a != 0:
                for i, c in enumerate(_value(E, u, S.system.N)):
                    total[i] += a * c
        coefficients.append(tuple(sympy.expand(c) for c in total) if any(total) else zero)
        lie.append(tuple((u, a) for u, a in coords if a != 0))
    return GradientField(S.system, comp, order, "formal", tuple(coefficients), tuple(lie))


def _backward(S, comp, order):
    from ..algebra import VectorField
    from ..algebra.backend import field_backend
    from ..bch.backward import modified_field_of_map

    algebra = S.system.algebra.with_constants(H)
    fields = {k: VectorField(algebra, f.to_sympy()) for k, f in S.fields.items()}
    backend = field_backend(algebra, fields, laurent=True)
    top = order + 1
    zero = backend.zero

    def pull(field, c, power, series):
        """``exp(c h^power X) applied to a series in h``: ``[h^(m + power k)] += c^k / k! X^k f_m``."""
        out = list(series)
        for m, f in enumerate(series):
            term, scale, k = f, backend.rational(sympy.Integer(1)), 0
            while m + power * (k + 1) <= top:
                k += 1
                term = backend.apply(field, term)
                scale = scale * c * backend.rational(sympy.Rational(1, k))
                if backend.is_zero_function(term):
                    break
                out[m + power * k] = out[m + power * k] + term * scale
        return out

    pulled = []
    for x in backend.coordinates:
        series = [x] + [zero] * top
        for k, b, c in reversed(comp.factors):  # the innermost operator acts first (Phi^* = exp(..1) ... exp(..s))
            if k == 2 and c != 0:
                series = pull(backend.fields[3], backend.constants([c])[0], 3, series)
            if b != 0:
                series = pull(backend.fields[k], backend.constants([b])[0], 1, series)
        pulled.append(series)
    Z = modified_field_of_map(backend, pulled, order)
    coefficients = tuple(tuple(sympy.expand(c) for c in z.to_sympy()) for z in Z)
    return GradientField(S.system, comp, order, "backward", coefficients)


@dataclass(frozen=True, eq=False)
class GradientShadow(ValueEquality):
    """``H_S = sum_j h^j H_j`` of a force-gradient composition on a canonical system (exact sympy ``terms``)."""

    system: object
    composition: object
    order: int
    terms: tuple

    def _value(self) -> tuple:
        return self.system, self.composition, self.order, self.terms

    @property
    def hamiltonian(self):
        return sympy.expand(sum(H**j * t for j, t in enumerate(self.terms)))

    def truncated(self, k: int):
        """``sum_{j <= k} h^j H_j``."""
        return sympy.expand(sum(H**j * t for j, t in enumerate(self.terms[:k + 1])))

    def to_dict(self) -> dict:
        return {"system": self.system.name, "composition": str(self.composition), "order": self.order,
                "H": [str(t) for t in self.terms]}

    def __str__(self):
        lines = [f"H_S of {self.composition} on {self.system.name}, through h^{self.order}"]
        lines += [f"H_{j} = {t}" for j, t in enumerate(self.terms) if t != 0]
        return "\n".join(lines)


def gradient_shadow(system, spec, order: int = 4) -> GradientShadow:
    """The shadow Hamiltonian of a force-gradient composition on ``system`` through ``h^order``, exactly.

    ``H_j`` is the Lie polynomial of ``Z_j`` (formal route) read with ``X_1 -> T``, ``X_2 -> V`` and
    ``[a, b] -> -{a, b}``; every ``X_{H_j}`` is checked to equal the backward route's ``Z_j``.

    Examples
    --------
    >>> gradient_shadow("ho", "chin-4a", order=2).terms[2]
    0
    """
    from ..algebra import liouville_field

    S = gradient_structure(system)
    formal = gradient_effective_field(S.system, spec, order, "formal")
    backward = gradient_effective_field(S.system, spec, order, "backward")
    memo: dict = {}

    def ham(tree):
        if tree in memo:
            return memo[tree]
        if not isinstance(tree, tuple):
            value = S.T if tree == 1 else S.V
        else:
            value = -poisson(ham(tree[0]), ham(tree[1]), S.positions, S.momenta)
        memo[tree] = value
        return value

    terms = []
    for j, coords in enumerate(formal.lie):
        Hj = sympy.expand(sum(a * ham(_tree(u)) for u, a in coords))
        field = liouville_field(S.system.algebra, Hj).to_sympy() if Hj != 0 else (0,) * S.system.N
        if any(sympy.expand(a - b) != 0 for a, b in zip(field, backward.coefficients[j])):
            raise InvalidCompositionError(f"H_{j} of {formal.composition} on {S.system.name} does not generate Z_{j}")
        terms.append(Hj)
    return GradientShadow(S.system, formal.composition, order, tuple(terms))


def processor_field(system, kernel, max_degree: int = 7):
    """``(effective order p, [(q, Z_q)])``: the processor's log ``Z = sum_q h^q Z_q`` of ``kernel`` on ``system``,
    each ``Z_q`` a tuple of exact sympy components (:func:`~nambu_bch.design.generalized.effective_order`)."""
    from ..bch.expansion import piece_evaluator
    from .generalized import effective_order

    S = gradient_structure(system)
    e = effective_order(kernel, max_degree=max_degree)
    E = piece_evaluator(S.system.splitting)
    out = []
    for q, coords in sorted(e.processor.items()):
        words = lyndon_defect_words(2, q)
        total = [sympy.Integer(0)] * S.system.N
        for u, a in zip(words, coords):
            if a != 0:
                for i, c in enumerate(_value(E, u, S.system.N)):
                    total[i] += a * c
        if any(total):
            out.append((q, tuple(sympy.expand(c) for c in total)))
    return e.order, out
