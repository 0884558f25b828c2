"""The system's own error of a word: the leading term of X_eff - X_{H,G}, of H_S - H, and its size.

For a composition of formal order ``p`` the modified field is
``X_eff = X_{H,G} + h^j Z_j + O(h^(j+1))`` with ``j >= p`` the first power whose
coefficient ``Z_j`` is non-zero *on this system* (brackets can vanish, so a system can
see a higher order than the formal one).  ``Z_j`` comes from the backward error analysis
(:func:`~nambu_bch.bch.effective_field`), the shadow correction ``H_S - H = h^j (...)``
from the direct route (:func:`~nambu_bch.shadow.shadow_hamiltonians`) when a shadow
pair exists.  The size on a region is

    size = max_{x in sample} ||Z_j(x)||_2,

over a seeded uniform sample of a box (parameters at their values, default 1): a number
with the units of a velocity per ``h^j`` that one can compare between words of the same
``j`` (the local error of one step is about ``h^(j+1) size``).

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. IX.1 (modified equations);
Horikoshi, Eqs. (eL1), (eL2), (L2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy

from ..bch import effective_field
from ..checks import is_int, show
from ..errors import InvalidOrderError, InvalidRunError
from ..integrators.composition import composition_for
from ..integrators.step import parameter_values
from ..numeric.iterate import as_system
from ..parsing import as_expression
from .conditions import error_analysis
from ..symbols import STEP

#: Highest power of ``h`` searched for the leading term.
MAX_POWER = 8
#: Most sample points of :func:`field_size` (one float64 evaluation of the field each).
MAX_SAMPLES = 10**7


@dataclass(frozen=True)
class LeadingError:
    """The leading error of ``word`` on ``system`` (see module docstring).

    Attributes
    ----------
    system, word : str
    formal_order : int           -- order ``p`` of the composition (any system)
    power : int                  -- ``j``: ``X_eff - X_{H,G} = h^j Z_j + O(h^(j+1))``
    field : tuple of sympy Expr  -- components of ``Z_j``
    hamiltonian : sympy Expr or None -- ``[h^j] (H_S - H)`` (with the family's free parameters), None if no shadow pair
    size : float                 -- ``max ||Z_j||_2`` over the sample
    box : tuple of (lo, hi)      -- the region, per coordinate
    samples : int
    """

    system: str
    word: str
    formal_order: int
    power: int
    field: tuple
    hamiltonian: object
    size: float
    box: tuple
    samples: int

    def to_dict(self) -> dict:
        return {"system": self.system, "word": self.word, "formal_order": self.formal_order, "power": self.power,
                "field": [str(c) for c in self.field],
                "hamiltonian": None if self.hamiltonian is None else str(self.hamiltonian),
                "size": self.size, "box": [list(b) for b in self.box], "samples": self.samples}

    def to_latex(self) -> str:
        comps = r",\ ".join(sympy.latex(c) for c in self.field)
        out = rf"X_{{\rm eff}} - X_{{H,G}} = h^{{{self.power}}}\left({comps}\right) + O(h^{{{self.power + 1}}})"
        if self.hamiltonian is not None:
            out += rf",\quad H_S - H = h^{{{self.power}}}\left({sympy.latex(self.hamiltonian)}\right) + \dots"
        return out

    def _repr_latex_(self):
        return f"${self.to_latex()}$"


def _box(system, box):
    n = len(system.coordinates)
    if box is None:
        return tuple((-1.0, 1.0) for _ in range(n))
    try:
        out = tuple((float(lo), float(hi)) for lo, hi in box)
    except (TypeError, ValueError):
        raise InvalidRunError(f"box must be {n} pairs (lo, hi), one per coordinate, got {box!r}") from None
    if len(out) != n or not all(np.isfinite(lo) and np.isfinite(hi) and lo <= hi for lo, hi in out):
        raise InvalidRunError(f"box must be {n} finite pairs (lo, hi) with lo <= hi, one per coordinate, got {box!r}")
    return out


def field_size(components, system, box=None, samples: int = 2000, params=None, seed: int = 0) -> float:
    """``max ||F(x)||_2`` of a polynomial field over a seeded uniform sample of ``box`` (default ``[-1, 1]^N``); the
    Hermitian norm ``sqrt(sum |F_i|^2)`` when the field has complex coefficients."""
    system = as_system(system)
    box = _box(system, box)
    if not is_int(samples, 1, MAX_SAMPLES):
        raise InvalidRunError(f"samples must be an integer in 1..{MAX_SAMPLES:.0e}, got {show(samples)}")
    if not is_int(seed, 0, 2**32 - 1, numpy=True):
        raise InvalidRunError(f"seed must be an integer in 0..2^32-1, got {show(seed)}")
    if isinstance(components, (str, bytes)) or not hasattr(components, "__iter__"):
        raise InvalidRunError(f"components must be a list of {system.N} sympy expressions (a field), got {show(components)}")
    values = parameter_values(system, params)
    exprs = [as_expression(c, system.symbols(), "component").subs(values) for c in components]
    f = sympy.lambdify(system.coordinates, exprs, modules="numpy")
    rng = np.random.RandomState(seed)
    pts = [rng.uniform(lo, hi, samples) for lo, hi in box]
    # complex-coefficient methods have complex error fields: the size is the Hermitian norm sqrt(sum |F_i|^2)
    cols = [np.broadcast_to(np.asarray(v, dtype=complex), (samples,)) for v in f(*pts)]
    return float(np.sqrt(sum(c.real**2 + c.imag**2 for c in cols)).max())


def leading_error(system, word, box=None, samples: int = 2000, params=None, seed: int = 0,
                  hamiltonian: bool = True) -> LeadingError:
    """The leading term of ``X_eff - X_{H,G}`` (and of ``H_S - H``) of ``word`` on ``system``, and its size.

    Parameters
    ----------
    system : System or model name
    word : word, alias or Composition
    box : sequence of (lo, hi) per coordinate, default ``[-1, 1]^N``
    samples : int -- points of the seeded uniform sample
    params : dict -- parameter values for the size (default 1)
    hamiltonian : bool -- also compute ``[h^j](H_S - H)`` by the direct route

    Examples
    --------
    >>> E = leading_error("ho", "121")
    >>> E.power, E.field                      # Eq. (SHPV1): -omega^2 x2/(12 m), -m omega^4 x1/6
    (2, (-omega**2*x2/(12*m), -m*omega**4*x1/6))
    >>> round(E.size, 6) <= round((1/144 + 1/36) ** 0.5, 6)
    True
    """
    system = as_system(system)
    if not isinstance(hamiltonian, bool):
        raise InvalidRunError(f"hamiltonian must be True or False, got {show(hamiltonian)}")
    comp = composition_for(word, system.splitting)
    parts = len(set(comp.pieces))
    p = error_analysis(comp, max(comp.pieces)).order if parts == max(comp.pieces) else 1
    for j in range(max(p, 1), MAX_POWER + 1):
        X = effective_field(system.splitting, comp, order=j)
        if not X[j].is_zero():
            break
    else:
        raise InvalidOrderError(
            f"X_eff of {comp.name!r} on {system.name} equals X_H,G through h^{MAX_POWER}; no leading error term below that"
        )
    field = tuple(sympy.factor_terms(c) for c in X[j].to_sympy())
    ham = None
    if hamiltonian:
        from ..shadow import shadow_hamiltonians

        fam = shadow_hamiltonians(system, comp, order=j)
        if fam.exists:
            ham = sympy.factor_terms(sympy.expand(fam.H_S - system.H).coeff(STEP, j))
    size = field_size(field, system, box, samples, params, seed)
    return LeadingError(system.name, comp.name, p, j, field, ham, size, _box(system, box), samples)
