"""Running force-gradient compositions and processed kernels on a canonical system ``H = T(p) + V(q)``.

The step is built from exact data (:func:`nambu_bch.design.gradient_system.gradient_structure`): the drift
``q <- q + t dT/dp`` and the kick of the modified potential ``b V + c h^2 G``, ``G = {V, {T, V}}``,
``p <- p - h (b dV/dq + c h^2 dG/dq)``.  The derivatives are exact sympy expressions with the parameters substituted,
each checked by :func:`~nambu_bch.numeric.codegen.check_kernel_expression` (only the state and whitelisted functions)
before numpy code is generated from them, as for every kernel of the package.  The loop runs in numpy (one step per
Python iteration, a batch of states at once); :data:`MAX_GRADIENT_STEPS` bounds a run up front.

Processed kernels.  A kernel ``K`` of effective order ``p`` with processor log ``Z = sum_q h^q Z_q``
(:func:`nambu_bch.design.gradient_system.processor_field`) is run as ``x_n = P_(-Z)(K^n(P_Z(x_0)))``, where
``P_Z(x) = (exp(Z) x)(x)`` is the Lie series truncated at ``h^p``: the kernel runs on its own and the processor is
applied once on entry and once at each output (Blanes, Casas & Ros 1999; the standard use of processing).  The
ordering follows ``exp(ad_Z) log K = log(exp(Z) K exp(-Z))`` in the pull-back convention of
:mod:`nambu_bch.bch.backward` (the leftmost operator is the first map).

Cost, as :func:`nambu_bch.design.compare` counts it: a drift or a plain kick is one sub-flow evaluation; a
force-gradient kick is two (the force ``grad V`` and the gradient of ``G``, a Hessian-vector product for
``T = |p|^2/2``); a processor application counts two evaluations, twice per run.

References
----------
Chin, Phys. Lett. A 226 (1997) 344; Omelyan, Mryglod & Folk, Comput. Phys. Commun. 151 (2003) 272;
Blanes, Casas & Ros, SIAM J. Sci. Comput. 21 (1999) 711.
"""

from __future__ import annotations

import numpy as np
import sympy

from ..errors import ResourceLimitError

#: Most trajectory-steps of one numpy-loop run (a few seconds).
MAX_GRADIENT_STEPS = 2_000_000
#: Evaluations a force-gradient kick counts (the force and the gradient of G).
GRADIENT_KICK_COST = 2
#: Evaluations one application of a processor counts.
PROCESSOR_COST = 2


def _compiled(exprs, symbols, where):
    from .codegen import check_kernel_expression

    allowed = set(symbols)
    for e in exprs:
        check_kernel_expression(sympy.sympify(e, strict=True), allowed, where)
    return sympy.lambdify(symbols, list(exprs), modules="numpy")


def _values(system, params):
    from ..integrators.step import parameter_values

    return {p: sympy.nsimplify(v, rational=True) if isinstance(v, float) else v
            for p, v in parameter_values(system, params).items()}


class GradientStep:
    """``step(x, h)``: one step of a force-gradient composition on a canonical system (module docstring)."""

    def __init__(self, system, spec, params=None):
        from ..design.generalized import _gradient_spec
        from ..design.gradient_system import gradient_structure

        S = gradient_structure(system)
        self.structure, self.system = S, S.system
        self.composition = _gradient_spec(spec)
        if self.composition.is_complex:
            from ..errors import InvalidCompositionError

            raise InvalidCompositionError(f"a force-gradient run needs real coefficients; {self.composition} has "
                                          f"complex ones")
        values = _values(S.system, params)
        q, p = S.positions, S.momenta
        d = len(q)
        where = f"the force-gradient step on {S.system.name}"
        self._dT = _compiled([sympy.diff(S.T, x).subs(values) for x in p], p, where)
        self._dV = _compiled([sympy.diff(S.V, x).subs(values) for x in q], q, where)
        self._dG = _compiled([sympy.diff(S.G, x).subs(values) for x in q], q, where)
        self.d = d
        self.factors = [(k, float(b), float(c)) for k, b, c in self.composition.factors]

    def __call__(self, x, h):
        x = np.array(x, dtype=float)
        d = self.d
        q, p = x[:d], x[d:]
        for k, b, c in self.factors:
            if k == 1:
                q = q + (b * h) * _stack(self._dT(*p), q)
            else:
                force = b * _stack(self._dV(*q), p)
                if c:
                    force = force + (c * h * h) * _stack(self._dG(*q), p)
                p = p - h * force
        return np.concatenate([q, p])

    def cost(self) -> tuple:
        """``(per_step, extra)``: evaluations per step after merging equal neighbours (also across steps)."""
        runs = []
        for k, _, c in self.factors:
            weight = GRADIENT_KICK_COST if c else 1
            if runs and runs[-1][0] == k and not c and not runs[-1][2]:
                continue
            runs.append((k, weight, c))
        if len(runs) > 1 and runs[0][0] == runs[-1][0] and not runs[0][2] and not runs[-1][2]:
            return sum(w for _, w, _ in runs[:-1]), runs[-1][1]
        return sum(w for _, w, _ in runs), 0


def _stack(values, like):
    return np.array([np.broadcast_to(np.asarray(v, dtype=float), np.shape(like[0])) for v in values])


class Processor:
    """``x -> (exp(s Z) x)(x)``, the Lie series truncated at ``h^order`` (``s = +1`` or ``-1``), from exact data."""

    def __init__(self, system, pieces, order, params=None):
        from ..design.gradient_system import H

        values = _values(system, params)
        coords = system.coordinates
        self.maps = {}
        for sign in (1, -1):
            Z = [sympy.Integer(0)] * len(coords)
            for q, field in pieces:
                for i, c in enumerate(field):
                    Z[i] += sign * H**q * c
            # the Lie series exp(Z) x_i = x_i + Z x_i + Z(Z x_i)/2 + ..., kept through h^order
            out = []
            for x in coords:
                total, term = x, x
                for k in range(1, order + 1):
                    term = sympy.expand(sum(Zi * sympy.diff(term, y) for Zi, y in zip(Z, coords)) / k)
                    term = sum(term.coeff(H, j) * H**j for j in range(order + 1))
                    if term == 0:
                        break
                    total += term
                out.append(sympy.expand(total).subs(values))
            self.maps[sign] = _compiled(out, (*coords, H), f"the processor on {system.name}")

    def __call__(self, x, h, sign=1):
        x = np.asarray(x, dtype=float)
        return _stack(self.maps[sign](*x, h), x[0:1])


def _run(step, x, h, steps, every, after=None):
    from .samples import n_samples, sample_steps

    marks = set(int(s) for s in sample_steps(steps, every))
    out = np.empty((n_samples(steps, every), *np.shape(x)))
    j = 0
    for n in range(steps + 1):
        if n:
            x = step(x, h)
        if n in marks:
            out[j] = x if after is None else after(x)
            j += 1
    return out


def _inputs(system, h, steps, every, x0, params):
    from .guards import check_inputs, initial_state

    x0, _ = initial_state(system, x0)
    h, steps, every, X, _ = check_inputs(system, h, steps, every, x0, params)
    batch = 1 if X.ndim == 1 else X.shape[1]
    if steps * batch > MAX_GRADIENT_STEPS:
        raise ResourceLimitError(f"steps = {steps} x {batch} states is more than the {MAX_GRADIENT_STEPS:.0e} "
                                 f"trajectory-steps a force-gradient run accepts (numpy loop); take a larger h")
    return h, steps, every, X


def iterate_gradient(system, spec, h, steps, x0=None, params=None, every=1) -> np.ndarray:
    """Iterate a force-gradient composition on a canonical ``T(p) + V(q)`` system (module docstring).

    Same arguments, shapes and samples as :func:`nambu_bch.numeric.iterate` (float64, numpy loop).

    Examples
    --------
    >>> x = iterate_gradient("ho", "chin-4a", 0.1, 10, [1.0, 0.0])
    >>> x.shape
    (11, 2)
    """
    step = GradientStep(system, spec, params)
    h, steps, every, X = _inputs(step.system, h, steps, every, x0, params)
    with np.errstate(all="ignore"):  # non-finite states are refused by _check
        return _check(_run(step, X, h, steps, every), step.system)


def iterate_processed(system, kernel, h, steps, x0=None, params=None, every=1, max_degree: int = 7) -> np.ndarray:
    """Iterate the processed method ``P K P^(-1)``: the kernel ``K`` runs, the processor enters and leaves once per
    output (module docstring); the samples are those of the processed method, of the kernel's effective order.

    Examples
    --------
    >>> x = iterate_processed("ho", "takahashi-imada", 0.1, 10, [1.0, 0.0])
    >>> x.shape
    (11, 2)
    """
    from ..design.gradient_system import processor_field

    step = GradientStep(system, kernel, params)
    h, steps, every, X = _inputs(step.system, h, steps, every, x0, params)
    order, pieces = processor_field(step.system, kernel, max_degree)
    P = Processor(step.system, pieces, order, params)
    with np.errstate(all="ignore"):  # non-finite states are refused by _check
        y0 = P(X, h, +1)
        return _check(_run(step, y0, h, steps, every, after=lambda y: P(y, h, -1)), step.system)


def _check(samples, system):
    """The samples, or one line if the run left float64 (overflow, a singular force)."""
    from ..errors import NumericalRangeError

    if not np.isfinite(samples).all():
        raise NumericalRangeError(f"the force-gradient run on {system.name} left float64 (non-finite state); "
                                  f"take a smaller h or another x0")
    return samples


def is_gradient_method(word) -> bool:
    """Whether ``word`` names or is a force-gradient composition or kernel (not a plain composition)."""
    from ..design.generalized import GRADIENT_METHODS, GradientComposition

    if isinstance(word, GradientComposition):
        return True
    return isinstance(word, str) and word.strip().lower() in GRADIENT_METHODS


def is_processed_kernel(word) -> bool:
    """Whether ``word`` is a catalogue kernel meant to run processed (``takahashi-imada``)."""
    from ..design.generalized import PROCESSED_KERNELS

    return isinstance(word, str) and word.strip().lower() in PROCESSED_KERNELS
