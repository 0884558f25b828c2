"""``ShadowFamily``: the result of a shadow-Hamiltonian computation, with text / LaTeX / JSON output.

A family is ``H_S(h, alpha), G_S(h, alpha)`` with ``X_{H_S,G_S} = X_eff + O(h^{order+1})``
(Eq. L2; ``X_{H_S}``, Eq. L1, for N = 2), the free parameter(s) of the
parametrisation (``alpha`` of Eq. Xeff3), the remaining gauge directions per
order, and -- when no shadow pair exists -- the failed order, the ansatz
degree tried and a certificate of the obstruction.

References
----------
Horikoshi, Eqs. (L1), (L2), (SH12321c), (SG12321c), (Xeff3).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass, field

import sympy

from ..algebra.ansatz import Ansatz
from ..algebra.canonical import coordinate_coefficients
from ..parsing import as_expression
from ..printing import (Printable, aligned, by_monomials, h_coefficients, laid_out, latex_text, series_text,
                        series_tokens)
from ..symbols import ALPHA, STEP
from ..values import ValueEquality


def existence_fields(decision, failed_order) -> dict:
    """The fields ``exists, existence, drift, evidence`` of a family whose polynomial ansatz failed at ``h^failed_order``.

    Parameters
    ----------
    decision : :class:`~nambu_bch.shadow.existence.Existence` or None -- the decision by orbit
        averages (:func:`~nambu_bch.shadow.existence.decide`); None: existence in smooth
        functions was not decided (``existence=False``)
    failed_order : int or None -- the first power of ``h`` the polynomial ansatz did not solve

    Returns
    -------
    dict -- keyword arguments of :class:`ShadowFamily` (a pure function: nothing is computed or changed)

    References
    ----------
    The three outcomes (pair / certified non-existence / undecided); Horikoshi, Eq. (L2).

    >>> existence_fields(None, 3)["evidence"]["outcome"]
    'undecided'
    """
    if decision is None:
        return {"exists": None, "existence": None, "drift": None,
                "evidence": {"outcome": "undecided", "order": failed_order, "method": None,
                             "reason": "no polynomial pair; existence in smooth functions not decided (existence=False)"}}
    return {"exists": decision.exists, "existence": decision, "drift": decision.drift_dict(), "evidence": decision.evidence()}


def _vanishing_note(composition, order: int) -> str:
    why = " (odd order of a symmetric word)" if composition.symmetric and order % 2 else ""
    return f"h^{order}: the correction vanishes{why}"


def _operator(n_hams: int) -> str:
    if n_hams == 1:
        return "X_{dH}"
    if n_hams == 2:
        return "X_{dH,G} + X_{H,dG}"
    return "sum_a X_{H_1..dH_a..H_" + str(n_hams) + "}"


def _obstruction_text(sol, n_hams: int = 2) -> str:
    """One line: the direct route's left-null functional ``l`` at the failed order and ``l(RHS) != 0``."""
    terms = sorted(sol.certificate.items(), key=lambda kv: (str(kv[0][0]), sympy.default_sort_key(kv[0][1])))
    shown = " + ".join(f"({c})*[{mono}]Y^{x}" for (x, mono), c in terms[:6])
    more = f" + ... ({len(terms)} terms)" if len(terms) > 6 else ""
    return (
        f"at h^{sol.order} no polynomial corrections of degree <= {sol.degree} solve "
        f"{_operator(n_hams)} = Z_{sol.order} - (cross terms): the functional l(Y) = {shown}{more} "
        f"vanishes on every such field but l(RHS) = {sol.obstruction_value}"
    )


class Corrections(Mapping):
    """``order -> (dH_j, dG_j, ..)`` of a direct-route family, read-only, each order's sympy forms converted on first
    access (:class:`~nambu_bch.shadow.direct_route.OrderSolution`); equal to the dict of the same items.

    >>> from nambu_bch import model, shadow_hamiltonians
    >>> F = shadow_hamiltonians(model("ho"), "TVT")
    >>> list(F.corrections), F.corrections == {2: F.details.orders[1].corrections}
    ([2], True)
    """

    def __init__(self, solutions: dict):
        self._solutions = dict(solutions)

    def __getitem__(self, order):
        return self._solutions[order].corrections

    def __iter__(self):
        return iter(self._solutions)

    def __len__(self):
        return len(self._solutions)

    def __repr__(self):
        return repr(dict(self.items()))


class Gauge(Corrections):
    """``order -> [directions]`` of a direct-route family: the kernel basis of each solved order, read-only, converted to
    sympy on first access (:attr:`~nambu_bch.shadow.direct_route.OrderSolution.gauge`); equal to the dict of the same
    items."""

    def __getitem__(self, order):
        return self._solutions[order].gauge


def _free_parameters(exists, shadows) -> list:
    """``["alpha"]`` when an existing family's shadows depend on ``alpha`` (Eq. Xeff3), else ``[]``."""
    return ["alpha"] if exists and any(S.has(ALPHA) for S in shadows) else []


def _direct_shadows(result) -> tuple:
    """The shadows of a direct-route result as sympy expressions (a module function: a pending family pickles)."""
    return result.shadow()


def _exact_layout(result, slot: int, hamiltonian, coordinates, with_base: bool):
    """``[(k, c_k)]`` of the shadow ``H^slot + sum_k h^k dH_k`` (:func:`~nambu_bch.printing.h_coefficients` with base
    ``0`` when ``with_base``, else the Hamiltonian) from the direct route's exact per-order corrections.

    Each correction is laid out on its own from its ring element: the coefficient of each coordinate monomial
    factored by python-flint into the expression ``sympy.factor`` gives
    (:func:`~nambu_bch.algebra.canonical.coordinate_coefficients`); without that path, each correction's expanded
    sympy form (``PolynomialAlgebra.expanded_terms``, the terms ``sympy.expand`` gives) is laid out by
    :func:`~nambu_bch.printing.laid_out`.  Either way the shadow's whole sum is neither expanded nor regrouped by
    powers of ``h``.  None when a piece is not a polynomial or the system's Hamiltonian is not the ring's own
    expanded form (the caller then lays out the sum).
    """
    alg = result.algebra
    Ha = result.hamiltonians[slot]
    parts = {k: result.corrections[(slot, k)] for k in range(1, result.order + 1) if result.corrections.get((slot, k))}
    if not all(alg.is_polynomial(p) for p in (Ha, *parts.values())):
        return None
    memo: dict = {}  # the sort keys of the terms, shared by the orders
    base = alg.expanded_sum([(Ha, ())], memo)
    if base != sympy.expand(hamiltonian):
        return None
    pieces = {0: Ha, **parts} if with_base else parts
    if tuple(alg.ring.symbols[: alg.n]) == tuple(coordinates):
        rows = {k: coordinate_coefficients(p, alg.n) for k, p in pieces.items()}
        if all(r is not None for r in rows.values()):
            return [(k, by_monomials(rows[k], coordinates)) for k in sorted(rows) if rows[k]]
    by_power = {k: alg.expanded_sum([(p, ())], memo) for k, p in parts.items()}
    if with_base:
        by_power[0] = base
    return laid_out(by_power, coordinates)


def _exact_series(result, slot: int, hamiltonian):
    """``{k: c_k}`` of :meth:`ShadowFamily.series` (``c_0`` the Hamiltonian, ``c_k`` the correction of ``h^k``, each
    expanded) from the exact corrections, or None.

    ``series`` expands each laid-out ``c_k`` (:func:`_exact_layout`: monomials times factored coefficients).  When
    every coefficient's denominator is a monomial in the parameters (or a number), that expansion multiplies out
    the numerators into distinct products of rational numbers and integer powers of symbols, the canonical form of
    the Laurent polynomial -- which is the correction's own expanded form (``PolynomialAlgebra.expanded_terms``
    splits a monomial denominator into powers the same way), so it is taken from there without expanding.  A
    sum in a denominator is kept whole by ``expand`` in factored form and expanded otherwise: None then (the
    caller expands the layout).
    """
    alg = result.algebra
    Ha = result.hamiltonians[slot]
    pieces = {0: Ha, **{k: result.corrections[(slot, k)] for k in range(1, result.order + 1)
                        if result.corrections.get((slot, k))}}
    if not all(alg.is_polynomial(p) for p in pieces.values()):
        return None
    domain = alg.domain
    if getattr(domain, "is_FractionField", False):
        if not domain.domain.is_QQ or any(len(c.denom) != 1 for p in pieces.values() for c in p.values()):
            return None
    elif not domain.is_QQ:
        return None
    memo: dict = {}
    out = {k: alg.expanded_sum([(p, ())], memo) for k, p in sorted(pieces.items())}
    if out[0] != sympy.expand(hamiltonian):
        return None
    return out


@dataclass(frozen=True, eq=False)
class ShadowFamily(Printable, ValueEquality):
    """Shadow Hamiltonians of a composition on a system, as a family.

    A family is immutable; it is built by :meth:`from_direct`, :meth:`from_fi` or :meth:`unperturbed`.

    Attributes
    ----------
    system, composition
    order : int -- highest power of ``h`` kept
    route : ``"direct"`` or ``"fi"``
    exists : True / False / None -- a pair exists / non-existence is certified / undecided
    polynomial : bool or None -- the pair found is polynomial (False: no polynomial pair up to the degree tried)
    drift : dict or None -- predicted secular drift ``dH'/dt`` per Hamiltonian of a certified non-existence
    evidence : dict or None -- the existence decision as data (:meth:`~nambu_bch.shadow.existence.Existence.evidence`)
    existence : the :class:`~nambu_bch.shadow.existence.Existence` decision, or None
    shadows : tuple -- all shadow Hamiltonians ``(H_S, G_S, ...)`` (sympy, in ``h`` and ``alpha``), or ``()``; a
        direct-route family keeps the exact corrections (``details``) and builds these sums on first access
    free_parameters : list of str -- e.g. ``["alpha"]``
    gauge : dict ``order -> [directions]`` -- kernel bases (one correction per Hamiltonian; direct route: a read-only
        :class:`Gauge`, converted to sympy on first access)
    corrections : mapping ``order -> tuple`` -- the family's ``dH_j, dG_j`` (direct route: a read-only
        :class:`Corrections`, converted to sympy on first access)
    degree : dict ``order -> int`` -- ansatz degrees used
    notes : list of str -- e.g. vanishing odd orders
    failed_order, certificate, obstruction -- set when ``exists`` is false
    details : the route's own result (``DirectResult`` or ``FIResult``)
    fi_span : list of dict or None -- FI route: per solved order, how much of the family the FI
        representations reach (:class:`~nambu_bch.shadow.fi_route.FISpan`; ``reached`` false: the
        family's members needed the direct route's kernel, the reason is also in ``notes``); None for the direct route
    """

    system: object
    composition: object
    order: int
    route: str
    exists: object
    shadows: tuple = ()
    free_parameters: list = field(default_factory=list)
    gauge: dict = field(default_factory=dict)
    corrections: dict = field(default_factory=dict)
    degree: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    failed_order: int | None = None
    certificate: dict | None = None
    obstruction: str | None = None
    details: object = None
    polynomial: bool | None = None
    drift: dict | None = None
    evidence: dict | None = None
    existence: object = None
    fi_span: list | None = None

    # -- named constructors ------------------------------------------------------------
    @classmethod
    def from_direct(cls, system, composition, order: int, result, decision=None, *, max_unknowns=None) -> "ShadowFamily":
        """The family of a direct-route result (:func:`~nambu_bch.shadow.direct_route.direct_route`).

        Parameters
        ----------
        system, composition, order -- as given to the route
        result : DirectResult
        decision : Existence or None -- the existence decision when the polynomial ansatz failed
            (:func:`existence_fields`; None: undecided); ignored when a polynomial pair was found
        max_unknowns : int or None -- the bound the route used (named in the obstruction of a refused order)
        """
        notes, solved, degree = [], {}, {}
        for o in result.orders:
            if o.status == "vanishes":
                notes.append(_vanishing_note(composition, o.order))
            elif o.status == "solved":
                solved[o.order] = o
                degree[o.order] = o.degree
            else:
                degree[o.order] = o.degree
        corrections, gauge = Corrections(solved), Gauge(solved)
        common = dict(gauge=gauge, corrections=corrections, degree=degree, notes=notes, details=result)
        if result.exists:
            # the exact corrections stay the data; the sympy sums are built on first access (``shadows``)
            return cls(system, composition, order, "direct", True, shadows=functools.partial(_direct_shadows, result),
                       polynomial=True, free_parameters=["alpha"] if result.has_symbol(ALPHA) else [], **common)
        bad = result.orders[-1]
        if bad.status == "obstructed":
            certificate, obstruction = bad.certificate, _obstruction_text(bad, len(system.hamiltonians))
        else:
            certificate = None
            if max_unknowns is None or Ansatz.size(len(system.coordinates), bad.degree, len(system.hamiltonians)) > max_unknowns:
                what = f"has more than max_unknowns={max_unknowns} unknowns"
            else:  # within max_unknowns, above the elimination cost budget (direct_route.SOLVE_COST)
                what = "needs an elimination above the bounded-work budget"
            obstruction = (f"at h^{bad.order} the polynomial ansatz of degree <= {bad.degree} {what}: "
                           "the exact solve was refused up front")
        return cls(system, composition, order, "direct", failed_order=bad.order, polynomial=False, certificate=certificate,
                   obstruction=obstruction, **existence_fields(decision, bad.order), **common)

    @classmethod
    def from_fi(cls, system, composition, order: int, result, decision=None, *, direct=None) -> "ShadowFamily":
        """The family of an FI-route result (:func:`~nambu_bch.shadow.fi_route.fi_route`).

        When the FI ansatz fails, the FI ansatz is no certificate: a polynomial pair of the
        ``direct`` route (a DirectResult, if given) gives the shadows; otherwise ``decision``
        (:func:`existence_fields`; None: undecided) gives the existence outcome.
        """
        power = result.power
        notes, gauge, corrections, degree = [], {}, {}, {power: result.degree}
        failed_order = certificate = obstruction = None
        if result.certificate is not None:
            failed_order, certificate = power, result.certificate
            obstruction = (f"at h^{power} no affine combination of the FI representations equals "
                           f"X_{{H,dG}} + X_{{dH,G}} with corrections of degree <= {result.degree}")
        else:
            corrections[power] = result.corrections
            gauge[power] = result.kernel_corrections()
            for o in result.orders:
                if o.status == "vanishes":
                    notes.append(_vanishing_note(composition, o.order))
                    continue
                degree[o.order] = o.degree
                if o.status == "solved":
                    corrections[o.order] = o.corrections
                    gauge[o.order] = list(o.kernel)
                else:
                    failed_order, certificate = o.order, o.certificate
                    obstruction = (f"at h^{o.order} no affine combination of the FI representations equals "
                                   f"X_{{H,dG}} + X_{{dH,G}} + (cross terms) with corrections of degree <= {o.degree}")
        spans = result.spans()
        notes += [span.reason() for span in spans if not span.reached]
        if result.exists:
            outcome = dict(exists=True, polynomial=True, shadows=result.shadow())
        elif direct is not None and direct.exists:
            outcome = dict(exists=True, polynomial=True, shadows=direct.shadow())
            notes.append("the FI ansatz failed; the shadows are the direct route's polynomial pair")
        else:
            outcome = dict(polynomial=False, **existence_fields(decision, failed_order))
        return cls(system, composition, order, "fi", gauge=gauge, corrections=corrections, degree=degree, notes=notes,
                   failed_order=failed_order, certificate=certificate, obstruction=obstruction, details=result,
                   free_parameters=_free_parameters(outcome["exists"], outcome.get("shadows", ())),
                   fi_span=[span.to_dict() for span in spans], **outcome)

    @classmethod
    def unperturbed(cls, system, composition, order: int, route: str = "fi") -> "ShadowFamily":
        """A symmetric word below its first correction (``order < 2``): the shadows are the Hamiltonians."""
        shadows = tuple(sympy.expand(Hk) for Hk in system.hamiltonians)
        polynomial = all(system.algebra.is_polynomial(system.algebra.convert(Hk)) for Hk in system.hamiltonians)
        return cls(system, composition, order, route, True, shadows=shadows, free_parameters=_free_parameters(True, shadows),
                   notes=["h^1: the correction vanishes (symmetric word)"], polynomial=polynomial,
                   fi_span=[] if route == "fi" else None)

    #: derived data kept after the first output and not pickled (the copy derives them again from the exact data)
    _TRANSIENT = ("_value_cache", "_layouts")

    def _n_shadows(self) -> int:
        """How many shadow Hamiltonians the family has, without building a pending family's sympy sums."""
        value = self.__dict__.get("_shadows", ())
        return len(self.system.hamiltonians) if callable(value) else len(value)

    def _layout(self, slot: int, with_base: bool = False):
        """``[(k, c_k)]`` of the shadow ``slot`` by powers of ``h`` (:func:`~nambu_bch.printing.h_coefficients`, base
        ``0`` when ``with_base``, else the Hamiltonian), each ``c_k`` by monomials with factored coefficients; computed
        once and shared by the text, LaTeX and JSON outputs.  A direct-route family lays out its exact per-order
        corrections (:func:`_exact_layout`) instead of expanding and regrouping the sympy sum."""
        layouts = self.__dict__.setdefault("_layouts", {})
        key = (slot, with_base)
        if key not in layouts:
            coords, hamiltonian = self.system.coordinates, self.system.hamiltonians[slot]
            value = None
            if self.route == "direct" and self.exists and self.details is not None:
                value = _exact_layout(self.details, slot, hamiltonian, coords, with_base)
            if value is None:
                value = h_coefficients(self.shadows[slot], 0 if with_base else hamiltonian, coords)
            layouts[key] = value
        return layouts[key]

    def _printed(self, slot: int):
        """``(expression, layout)`` arguments of ``series_text``/``series_tokens`` for shadow ``slot``: the layout when
        the shadow is polynomial in ``h`` (the expression is then not needed), else the sympy sum for their fallback."""
        layout = self._layout(slot)
        return (self.shadows[slot], None) if layout is None else (None, layout)

    def _value(self) -> tuple:
        """The exact data that determine the family (``==``, ``hash``): a direct-route family's ring elements
        ``(slot, order) -> dH`` and per-order status, never its sympy sums; an FI-route family's expressions."""
        details = self.details
        if self.route == "direct" and details is not None:
            exact = (sorted(details.corrections.items(), key=lambda kv: kv[0]),
                     [(o.order, o.status, o.degree, o.kernel_dim, o.psi_dim, o.obstruction_value) for o in details.orders])
        else:
            exact = (self.shadows, dict(self.corrections), dict(self.gauge))
        return (self.system, self.composition, self.order, self.route, self.exists, self.polynomial, self.failed_order,
                self.degree, self.notes, self.free_parameters, exact, self.certificate, self.obstruction, self.existence,
                self.fi_span)

    def _outcome_headline(self) -> str:
        """The existence outcome of a family without a polynomial pair (pair / certified non-existence / undecided)."""
        return {True: "shadow Hamiltonians exist in smooth functions but are not polynomial",
                False: "no shadow Hamiltonians (certified)", None: "existence undecided"}[self.exists]

    def _outcome_text(self) -> str:
        """One line for a family without a polynomial pair: the outcome, its reason, the polynomial obstruction."""
        ev = self.evidence or {}
        return f"{self._outcome_headline()}: {ev.get('reason', '')}; no polynomial pair: {self.obstruction}"

    @property
    def H_S(self):
        """The first shadow Hamiltonian (``None`` if none exists)."""
        return self.shadows[0] if self.shadows else None

    @property
    def G_S(self):
        """The second shadow Hamiltonian (``None`` for N = 2 or if none exists)."""
        return self.shadows[1] if len(self.shadows) > 1 else None

    def member(self, **values) -> tuple:
        """The shadow Hamiltonians at given parameter values, e.g. ``member(alpha=1)`` (Eq. SH12321a)."""
        subs = {sympy.Symbol(k): as_expression(v, self.system.symbols(), f"member({k}=...)") for k, v in values.items()}
        return tuple(sympy.expand(S.subs(subs)) for S in self.shadows)

    # -- output ------------------------------------------------------------------
    def _names(self):
        """LaTeX and text names of the Hamiltonians: ``H``, ``G`` (N = 3) or ``H_{1} .. H_{k}``."""
        k = len(self.system.hamiltonians)
        if k <= 2:
            return [("H", "H"), ("G", "G")][:k]
        return [(f"H_{{{a + 1}}}", f"H{a + 1}") for a in range(k)]

    def to_latex(self) -> str:
        r"""``H_S &= H + h^2(...) + O(h^4)`` per Hamiltonian, then ``H &= ...``, as one ``aligned`` block.

        The remainder skips odd powers for symmetric words (Eqs. SH12321c, SG12321c); an
        obstructed family shows the failed order, the ansatz degree and the certificate.
        Belongs in display math with amsmath (docs/latex.md).

        >>> from nambu_bch import model, shadow_hamiltonians
        >>> print(shadow_hamiltonians(model("ho"), "TVT").to_latex())          # Eq. (SHPV1)
        \begin{aligned}
        H_{S} &= H + h^{2}\Bigl(\frac{m \omega^{4} x_{1}^{2}}{12} - \frac{\omega^{2} x_{2}^{2}}{24 m}\Bigr) + O(h^{4}), \\
        H &= \frac{m \omega^{2} x_{1}^{2}}{2} + \frac{x_{2}^{2}}{2 m}
        \end{aligned}
        """
        if not self._n_shadows():
            rows = self._obstruction_rows()
            if self.evidence is not None:
                rows.insert(0, ("", "", [latex_text(self._outcome_headline())]))
            return aligned(rows)
        power = self.composition.remainder_power(self.order)
        coords = self.system.coordinates
        rows = []
        for slot, ((name, _), base) in enumerate(zip(self._names(), self.system.hamiltonians)):
            expr, layout = self._printed(slot)
            rows.append((f"{name}_{{S}}", "=", series_tokens(name, expr, base, coords, power, coefficients=layout)))
        for (name, _), base in zip(self._names(), self.system.hamiltonians):
            rows.append((name, "=", series_tokens("0", base, 0, coords)))
        for row in rows[:-1]:
            row[2][-1] += ","
        return aligned(rows)

    def _obstruction_rows(self):
        """The obstruction as ``aligned`` rows: headline, then the certificate functional (direct route)."""
        order, degree = self.failed_order, self.degree.get(self.failed_order)
        head = [r"\text{no polynomial shadow Hamiltonians of }" + latex_text(self.composition.name),
                r"\text{on }" + latex_text(self.system.name),
                r"\text{at order }" + sympy.latex(STEP**order)
                + (rf"\text{{ with corrections of degree }} \le {degree}" if degree is not None else "") + ":"]
        rows = [("", "", head)]
        cert = self.certificate or {}
        if cert and all(isinstance(k, tuple) for k in cert):
            terms = sorted(cert.items(), key=lambda kv: (str(kv[0][0]), sympy.default_sort_key(kv[0][1])))
            tokens = []
            for i, ((x, mono), c) in enumerate(terms):
                piece = rf"\left[{sympy.latex(mono)}\right] Y^{{{sympy.latex(x)}}}"
                c = sympy.factor(c)
                tok = piece if c == 1 else (rf"- {piece}" if c == -1 else rf"\left({sympy.latex(c)}\right) {piece}")
                tokens.append(tok if i == 0 or tok.startswith("- ") else "+ " + tok)
            rows.append((r"\ell(Y)", "=", tokens))
            value = getattr(self._failed_solution(), "obstruction_value", None)
            rows.append(("", "", [r"\text{vanishes on every admissible correction field, but}"]))
            if value is not None:
                rows.append((r"\ell(\text{right-hand side})", "=", [sympy.latex(value) + r" \neq 0"]))
        elif cert:
            rows.append(("", "", [r"\text{no affine combination of the FI representations}",
                                  r"\text{solves the equation (certificate in the JSON output)}"]))
        return rows

    def _failed_solution(self):
        orders = getattr(self.details, "orders", None)
        return orders[-1] if orders else None

    def to_text(self) -> str:
        """``H_S = H + h**2*(...) + O(h^4)`` per Hamiltonian, the definitions, free parameters and notes.

        >>> from nambu_bch import model, shadow_hamiltonians
        >>> print(shadow_hamiltonians(model("ho"), "TVT"))                      # Eq. (SHPV1)
        H_S = H + h**2*(m*omega**4*x1**2/12 - omega**2*x2**2/(24*m)) + O(h^4)
        H = m*omega**2*x1**2/2 + x2**2/(2*m)
        h^1: the correction vanishes (odd order of a symmetric word)
        """
        if not self._n_shadows():
            if self.evidence is None:
                return f"no polynomial shadow Hamiltonians for {self.composition.name} on {self.system.name}: {self.obstruction}"
            return f"{self.composition.name} on {self.system.name}: {self._outcome_text()}"
        power = self.composition.remainder_power(self.order)
        coords = self.system.coordinates
        lines = []
        for slot, ((_, name), base) in enumerate(zip(self._names(), self.system.hamiltonians)):
            expr, layout = self._printed(slot)
            lines.append(f"{name}_S = " + series_text(name, expr, base, coords, power, coefficients=layout))
        lines.append(", ".join(f"{name} = {base}" for (_, name), base in zip(self._names(), self.system.hamiltonians)))
        if self.free_parameters:
            lines.append("free parameters: " + ", ".join(self.free_parameters))
        lines += self.notes
        return "\n".join(lines)

    def series(self) -> dict:
        """``{"H_S": {k: c_k}, "G_S": {...}}``: the coefficient of ``h^k`` of each shadow Hamiltonian (k = 0 is H)."""
        out = {}
        for slot, (_, name) in enumerate(self._names()[:self._n_shadows()]):
            exact = None
            if self.route == "direct" and self.exists and self.details is not None:
                exact = _exact_series(self.details, slot, self.system.hamiltonians[slot])
            if exact is not None:  # the expanded layout, read off the exact corrections
                out[f"{name}_S"] = {k: c for k, c in exact.items() if c != 0}
                continue
            coefficients = self._layout(slot, with_base=True) or []
            out[f"{name}_S"] = {k: sympy.expand(c) for k, c in coefficients}
        return out

    def to_dict(self) -> dict:
        """JSON-ready dict (docs/json.md): expressions as strings ``sympy.sympify`` reads back.

        The system's part (model, coordinates, parameters, Hamiltonians) comes first
        (:func:`nambu_bch.render.result_head`); ``nambu-bch shadow --format json`` prints exactly this dict.
        """
        from ..render import result_head

        out = result_head(self.system, self.composition.name, order=self.order, route=self.route)
        out.update({
            "exists": self.exists,
            "H_S": None if self.H_S is None else str(self.H_S),
            "G_S": None if self.G_S is None else str(self.G_S),
            "free_parameters": list(self.free_parameters),
        })
        if len(self.shadows) > 2:
            out["shadows"] = [str(S) for S in self.shadows]
        out["polynomial"] = self.polynomial
        if self.failed_order is not None:
            out["drift"] = self.drift
            out["evidence"] = self.evidence
            out["obstruction"] = self.obstruction
            out["failed_order"] = self.failed_order
            out["degree"] = self.degree.get(self.failed_order)
        if self.notes:
            out["notes"] = list(self.notes)
        out["series"] = {name: {str(k): str(c) for k, c in coefficients.items()} for name, coefficients in self.series().items()}
        names = [name for _, name in self._names()]
        out["gauge"] = {str(k): [dict(zip((f"d{n}" for n in names), map(str, direction))) for direction in directions
                                 if any(sympy.sympify(c, strict=True) != 0 for c in direction)]  # weight-only FI directions dropped
                        for k, directions in sorted(self.gauge.items())}
        out["certificate"] = self._certificate_data()
        out["fi_span"] = self.fi_span
        return out

    def _certificate_data(self):
        """The obstruction certificate as data (``None`` when the family exists).

        Direct route: the functional ``l(Y) = sum c [monomial] Y^x`` (one term per component
        ``x`` and monomial) with ``value = l(right-hand side) != 0``; FI route: the weight of
        each representation row.
        """
        if self.exists or not self.certificate:
            return None
        cert = self.certificate
        if all(isinstance(key, tuple) for key in cert):
            terms = sorted(cert.items(), key=lambda kv: (str(kv[0][0]), sympy.default_sort_key(kv[0][1])))
            value = getattr(self._failed_solution(), "obstruction_value", None)
            return {"kind": "left-null-functional", "order": self.failed_order, "degree": self.degree.get(self.failed_order),
                    "terms": [{"component": str(x), "monomial": str(mono), "coefficient": str(c)} for (x, mono), c in terms],
                    "value": None if value is None else str(value)}
        return {"kind": "fi-rows", "order": self.failed_order, "degree": self.degree.get(self.failed_order),
                "terms": [{"row": str(key), "coefficient": str(c)} for key, c in cert.items()], "value": None}

    def __repr__(self):
        state = ("exists" if self.shadows else f"exists (smooth, not polynomial at h^{self.failed_order})") if self.exists \
            else f"obstructed at h^{self.failed_order}" if self.exists is False else f"undecided at h^{self.failed_order}"
        return (f"ShadowFamily({self.system.name!r}, {self.composition.name!r}, order={self.order}, route={self.route!r}, "
                f"{state}, free_parameters={self.free_parameters})")


def _get_shadows(self):
    value = self.__dict__.get("_shadows", ())
    if callable(value):  # pending: built from the route's exact data, once
        value = self.__dict__["_shadows"] = tuple(value())
    return value


def _put_shadows(self, value):
    self.__dict__["_shadows"] = value  # the frozen dataclass's __init__ assigns through object.__setattr__


# after @dataclass: the generated __init__ assigns through the property (the default () stays the field's own);
# equality, hashing, repr and pickling read the property, so a pending family equals its built copy
ShadowFamily.shadows = property(_get_shadows, _put_shadows,
                                doc="The shadow Hamiltonians ``(H_S, G_S, ...)`` as sympy expressions (built on first access).")
