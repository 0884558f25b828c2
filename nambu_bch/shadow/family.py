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

from dataclasses import dataclass, field

import sympy

H_STEP = sympy.Symbol("h")


def _corrections(shadow, base, coordinates):
    """``shadow - base`` by powers of ``h``: ``[(k, expr)]``, each coefficient of a monomial factored.

    Factoring per monomial keeps rational functions of the parameters readable
    (``(I2 - I3)/(I2 I3)`` rather than one long common denominator) and gives the
    paper's layout, e.g. ``h^2 (alpha omega^2/(12 m) x2^2 + alpha m omega^4/12 x1^2)``.
    """
    groups = sympy.collect(sympy.expand(shadow - base), H_STEP, evaluate=False)
    out = []
    for key, part in groups.items():
        power = 0 if key == 1 else sympy.degree(key, H_STEP)
        if part.is_polynomial(*coordinates):
            poly = sympy.Poly(part, *coordinates)
            terms = [sympy.factor(c) * sympy.Mul(*(x**e for x, e in zip(coordinates, m))) for m, c in poly.terms()]
        else:  # cos, exp, rational: the terms as they are (shadow/generic.py)
            terms = list(sympy.Add.make_args(part))
        out.append((power, sympy.Add(*terms, evaluate=False)))
    return sorted(out, key=lambda item: item[0])


def _render(name, base_name, shadow, base, coordinates, tail, latex):
    show = sympy.latex if latex else str
    parts = [base_name]
    for power, expr in _corrections(shadow, base, coordinates):
        step = show(H_STEP**power) if power else ""
        if latex:
            parts.append(rf"{step}\left({show(expr)}\right)")
        else:
            parts.append(f"{step}*({show(expr)})" if step else f"({show(expr)})")
    return f"{name} = " + " + ".join(parts) + tail


@dataclass
class ShadowFamily:
    """Shadow Hamiltonians of a composition on a system, as a family.

    Attributes
    ----------
    system, composition
    order : int -- highest power of ``h`` kept
    route : ``"direct"`` or ``"fi"``
    exists : bool
    shadows : tuple -- all shadow Hamiltonians ``(H_S, G_S, ...)`` (sympy, in ``h`` and ``alpha``), or ``()``
    free_parameters : list of str -- e.g. ``["alpha"]``
    gauge : dict ``order -> [directions]`` -- kernel bases (one correction per Hamiltonian)
    corrections : dict ``order -> tuple`` -- the family's ``dH_j, dG_j``
    degree : dict ``order -> int`` -- ansatz degrees used
    notes : list of str -- e.g. vanishing odd orders
    failed_order, certificate, obstruction -- set when ``exists`` is false
    details : the route's own result (``DirectResult`` or ``FIResult``)
    """

    system: object
    composition: object
    order: int
    route: str
    exists: bool
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
        subs = {sympy.Symbol(k): sympy.sympify(v) for k, v in values.items()}
        return tuple(sympy.expand(S.subs(subs)) for S in self.shadows)

    # -- output ------------------------------------------------------------------
    def _names(self):
        k = len(self.system.hamiltonians)
        if k == 1:
            return ["H"]
        if k == 2:
            return ["H", "G"]
        return [f"H_{{{a + 1}}}" for a in range(k)]

    def _lines(self, latex: bool) -> list:
        """``H_S = H + h^2(...) + O(h^k)`` per Hamiltonian, then the definitions ``H = ...``."""
        power = self.composition.remainder_power(self.order)
        tail = rf" + O(h^{{{power}}})" if latex else f" + O(h^{power})"
        coords = self.system.coordinates
        names = self._names()
        lines = []
        for name, S, base in zip(names, self.shadows, self.system.hamiltonians):
            shadow_name = rf"{name}_{{S}}" if latex else f"{name}_S".replace("{", "").replace("}", "")
            base_name = name if latex else name.replace("{", "").replace("}", "")
            lines.append(_render(shadow_name, base_name, S, base, coords, tail, latex))
        show = sympy.latex if latex else str
        definitions = [f"{n if latex else n.replace('{', '').replace('}', '')} = {show(b)}" for n, b in zip(names, self.system.hamiltonians)]
        lines.append((r",\quad " if latex else ", ").join(definitions))
        return lines

    def to_latex(self) -> str:
        """``H_S = H + h^2(...) + O(h^4)`` (and ``G_S``; the remainder skips odd powers of symmetric words), or the obstruction."""
        if not self.exists:
            return rf"\text{{no polynomial shadow Hamiltonians: {self.obstruction}}}"
        return ",\\\\\n".join(self._lines(latex=True))

    def _repr_latex_(self):
        return "$$" + self.to_latex().replace(",\\\\\n", r",\quad ") + "$$"

    def to_dict(self) -> dict:
        """JSON-ready dict (DESIGN.md): expressions as strings ``sympy.sympify`` reads back."""
        sys_ = self.system
        out = {
            "model": sys_.name,
            "integrator": self.composition.name,
            "order": self.order,
            "coordinates": [str(x) for x in sys_.coordinates],
            "H": str(sys_.H),
            "G": None if sys_.G is None else str(sys_.G),
            "bracket": getattr(sys_, "bracket", None),
            "exists": self.exists,
            "H_S": None if self.H_S is None else str(self.H_S),
            "G_S": None if self.G_S is None else str(self.G_S),
            "free_parameters": list(self.free_parameters),
            "route": self.route,
        }
        if len(self.shadows) > 2:
            out["shadows"] = [str(S) for S in self.shadows]
        if not self.exists:
            out["obstruction"] = self.obstruction
            out["failed_order"] = self.failed_order
            out["degree"] = self.degree.get(self.failed_order)
        if self.notes:
            out["notes"] = list(self.notes)
        return out

    def to_text(self) -> str:
        if not self.exists:
            return f"no polynomial shadow Hamiltonians for {self.composition.name} on {self.system.name}: {self.obstruction}"
        lines = self._lines(latex=False)
        if self.free_parameters:
            lines.append("free parameters: " + ", ".join(self.free_parameters))
        lines += self.notes
        return "\n".join(lines)

    def __repr__(self):
        state = "exists" if self.exists else f"obstructed at h^{self.failed_order}"
        return (f"ShadowFamily({self.system.name!r}, {self.composition.name!r}, order={self.order}, route={self.route!r}, "
                f"{state}, free_parameters={self.free_parameters})")
