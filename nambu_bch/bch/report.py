"""``BCHReport``: the formal BCH series of a word on a system, optionally evaluated and expanded, as one result.

What ``nambu-bch bch`` prints (text, LaTeX, or exactly :meth:`BCHReport.to_dict` as JSON): the series
term by term in the Lyndon basis (Eq. BCH2), with ``field`` the effective field ``X_eff = Z_0 + h Z_1 + ...``
on the system, with ``terms`` its expansion into Liouville terms, vanishing brackets pruned (Eq. BCH4).

References
----------
Horikoshi, Eqs. (BCH1), (BCH2), (BCH4).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

# the effective field and the Liouville expansion (sympy) are imported by bch_report when asked for: the command
# line prints a series served from the BCH table through the functions below without sympy (nambu_bch.cli.bch)
from .formal import formal_bch


def word_line(name: str, factors) -> str:
    """``TVT: Phi_h = exp((1/2)*h*X1) exp(h*X2) exp((1/2)*h*X1)``: the word as a product of exponentials.

    ``factors`` are the ``(piece, coefficient)`` pairs in operator order (a sympy or ``Fraction`` coefficient)."""
    return f"{name}: Phi_h = " + " ".join(f"exp({'' if c == 1 else f'({c})*'}h*X{k})" for k, c in factors)


def _int_bracket_text(tree) -> str:
    """:func:`nambu_bch.render.bracket_text` of a tree whose leaves are piece numbers (no sympy needed)."""
    return f"[{_int_bracket_text(tree[0])},{_int_bracket_text(tree[1])}]" if type(tree) is tuple else f"X{tree}"


def _int_bracket_tree(tree):
    """:func:`nambu_bch.render.bracket_tree` of a tree whose leaves are piece numbers (no sympy needed)."""
    if type(tree) is tuple:
        return {"bracket": [_int_bracket_tree(tree[0]), _int_bracket_tree(tree[1])]}
    return tree


def series_lines(series) -> list:
    """``  h^k  coefficient  bracket`` per term of a :class:`~nambu_bch.bch.formal.FormalBCH`, lowest degree first.

    A rational series prints each coefficient as a ``Fraction`` (as the sympy ``Rational`` prints) and its
    brackets of piece numbers directly: no sympy object is built."""
    lines = []
    if series._domain is None:
        for d in range(1, series.max_degree + 1):
            den, items = series.scaled_terms(d)
            lines += [f"  h^{d - 1}  {Fraction(n, den)}  {_int_bracket_text(t)}" for n, t in items]
        return lines
    from ..render import bracket_text

    for d in range(1, series.max_degree + 1):
        lines += [f"  h^{d - 1}  {c}  {bracket_text(t)}" for c, t in series.terms(d)]
    return lines


def series_terms(series) -> list:
    """The ``terms`` of :meth:`BCHReport.to_dict`: per term its degree, power of ``h``, coefficient, bracket, tree."""
    if series._domain is None:  # the same strings as render's, without sympy
        out = []
        for d in range(1, series.max_degree + 1):
            den, items = series.scaled_terms(d)
            out += [{"degree": d, "power_of_h": d - 1, "coefficient": str(Fraction(n, den)),
                     "bracket": _int_bracket_text(t), "tree": _int_bracket_tree(t)} for n, t in items]
        return out
    from .. import render

    return [{"degree": d, "power_of_h": d - 1, "coefficient": render.expression(c), "bracket": render.bracket_text(t),
             "tree": render.bracket_tree(t)} for d in range(1, series.max_degree + 1) for c, t in series.terms(d)]


@dataclass(frozen=True)
class BCHReport:
    """The BCH series of ``composition`` through ``h^order`` on ``system``.

    Attributes
    ----------
    system : System
    composition : Composition
    order : int -- the highest power of ``h``
    series : FormalBCH -- through degree ``order + 1``
    field : EffectiveField or None -- ``X_eff`` on the system (when asked for)
    expanded : dict or None -- degree to ``[(coefficient, tree of Liouville terms)]`` (when asked for)
    """

    system: object
    composition: object
    order: int
    series: object
    field: object = None
    expanded: dict | None = None

    def to_dict(self) -> dict:
        """JSON-ready: the system part, the word's coefficients and pieces, the terms (and ``X_eff``,
        ``liouville_terms`` when computed); ``nambu-bch bch --format json`` prints exactly this dict."""
        from .. import render
        from .lyndon import tree_to_latex

        series, comp = self.series, self.composition
        terms = series_terms(series)
        out = render.result_head(self.system, comp.name, order=self.order, max_degree=series.max_degree,
                                 coefficients=[render.expression(c) for c in comp.coefficients],
                                 pieces=list(comp.pieces), terms=terms)
        if self.field is not None:
            out["X_eff"] = [[render.expression(c) for c in Z.to_sympy()] for Z in self.field.coefficients]
        if self.expanded is not None:
            out["liouville_terms"] = [
                {"degree": d, "coefficient": render.expression(c), "bracket": render.bracket_text(t),
                 "tree": render.bracket_tree(t), "latex": tree_to_latex(t)}
                for d, items in self.expanded.items() for c, t in items
            ]
        return out

    def to_text(self) -> str:
        """The word as a product of exponentials, then ``h^k  coefficient  bracket`` per term."""
        comp, series = self.composition, self.series
        lines = [word_line(comp.name, comp.factors()), series_heading(self.order), *series_lines(series)]
        if self.field is not None:
            for j, Z in enumerate(self.field.coefficients):
                comps = ", ".join(str(c) for c in Z.to_sympy())
                lines.append(f"Z_{j} = ({comps})")
        if self.expanded is not None:
            from ..render import bracket_text

            lines.append("Liouville terms (zero brackets pruned):")
            for d, items in self.expanded.items():
                for c, t in items:
                    lines.append(f"  h^{d - 1}  {c}  {bracket_text(t)}")
        return "\n".join(lines)

    def to_latex(self) -> list:
        """``aligned`` blocks: the word, the series (Eq. BCH2), ``X_eff`` and the Liouville terms when computed."""
        from ..printing import aligned, bracket_sum

        lhs, _, rhs = self.composition.to_latex().partition(" = ")
        blocks = [aligned([(lhs, "=", rhs.split(" "))]), self.series.to_latex()]
        if self.field is not None:
            blocks.append(self.field.to_latex())
        if self.expanded is not None:
            blocks += [bracket_sum(rf"X_{{\rm eff}}\big|_{{h^{{{d - 1}}}}}", [(c, t, d - 1) for c, t in items])
                       for d, items in self.expanded.items()]
        return blocks


def series_heading(order: int) -> str:
    """The line above the terms: ``X_eff through h^2 (formal BCH in the Lyndon basis):``."""
    return f"X_eff through h^{order} (formal BCH in the Lyndon basis):"


def bch_report(system, comp, order: int = 2, field: bool = False, terms: bool = False) -> BCHReport:
    """The formal BCH series of ``comp`` through ``h^order``, with ``X_eff`` on ``system`` and its Liouville terms.

    Parameters
    ----------
    system : System
    comp : Composition (checked against the system's splitting)
    order : int -- the highest power of ``h``
    field : bool -- also evaluate ``X_eff`` on the system
    terms : bool -- also expand into Liouville terms, zero brackets pruned (Eq. BCH4)

    Returns
    -------
    BCHReport
    """
    from .backward import effective_field
    from .expansion import expand_terms

    series = formal_bch(comp, order + 1)
    X = effective_field(system.splitting, comp, order) if field else None
    expanded = {d: expand_terms(series.terms(d), system.splitting) for d in series.degrees} if terms else None
    return BCHReport(system, comp, order, series, X, expanded)
