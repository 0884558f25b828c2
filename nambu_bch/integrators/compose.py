"""The composed map ``Phi_h`` of a splitting and a composition, exactly in ``h``.

The sub-flows act on the state in word order (see
:mod:`nambu_bch.integrators.composition`): ``x -> phi^{k_s}_{c_s h}( ... phi^{k_1}_{c_1 h}(x))``.
Polynomial sub-flows are composed in the sparse ring (fast, exact); others by
sympy substitution.
"""

from __future__ import annotations

from functools import lru_cache

import sympy

from ..parsing import as_expression
from ..symbols import STEP
from .composition import composition_for
from .flows import TIME, exact_flow



def composed_map(splitting, comp, h=STEP) -> tuple:
    """``Phi_h(x)`` as sympy expressions in the coordinates, parameters and ``h``.

    Examples
    --------
    >>> from nambu_bch import model
    >>> composed_map(model("ho").splitting, "121")[1]     # position Verlet, momentum
    -h**2*omega**2*x2/2 - h*m*omega**2*x1 + x2
    """
    comp = composition_for(comp, splitting)
    h = as_expression(h, splitting.system.symbols(), "h")
    return _composed_map(splitting, comp, h)


@lru_cache(maxsize=128)
def _composed_map(splitting, comp, h) -> tuple:
    """The map of :func:`composed_map` per (splitting, composition, step): an immutable tuple, composed once.

    The invariant search, :func:`~nambu_bch.exact.is_invariant` and the testing helpers ask for the same map of
    the same word; composing it again costs the same substitutions each time."""
    system = splitting.system
    coords = system.coordinates
    flows = [(exact_flow(splitting[k], coords), c) for k, c in comp.factors()]
    # the ring route takes the step as a generator: a symbol (h = -h or 0.1 compose by substitution)
    if isinstance(h, sympy.Symbol) and all(f.polynomial for f, _ in flows):
        composed = _compose_in_ring(system, flows, comp, h)
        if composed is not None:
            return composed
    state = list(coords)
    for flow, c in flows:
        step = flow.at(c * h)
        state = [sympy.expand(e.subs(dict(zip(coords, state)), simultaneous=True)) for e in step]
    return tuple(state)


def _compose_in_ring(system, flows, comp, h):
    algebra = system.algebra.with_constants(h, TIME, extension=comp.extension)
    t = algebra.gens[algebra.n + algebra.constants.index(TIME)]
    hh = algebra.gens[algebra.n + algebra.constants.index(h)]
    state = list(algebra.gens[: algebra.n])
    for flow, c in flows:
        step = [algebra.convert(e) for e in flow.expressions]
        if not all(algebra.is_polynomial(e) for e in step):  # a constant such as m = exp(2) is not in the ring
            return None
        step = [e.compose(t, hh * algebra.convert(c)) for e in step]
        substitution = list(zip(algebra.gens[: algebra.n], state))
        state = [e.compose(substitution) for e in step]
    return tuple(algebra.to_sympy(e) for e in state)
