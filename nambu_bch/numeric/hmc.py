r"""Hybrid Monte Carlo with the package's splitting schemes: exp(-H) or the shadow exp(-H_S), canonical or Nambu.

**The sampler.**  The target density is ``pi(x) ~ exp(-E(x))`` on the coordinates of a system, with
``E = H`` (hybrid Monte Carlo, Duane, Kennedy, Pendleton, Roweth 1987) or ``E = H_S``, the shadow Hamiltonian
of the scheme truncated at order ``k`` (shadow hybrid Monte Carlo, Izaguirre and Hampton 2004).  One iteration,
vectorised over independent chains:

1. **Refresh.**  The ``refresh`` coordinates ``c`` enter ``H`` as ``k_c c^2 / 2`` and nowhere else (checked
   exactly), so under ``exp(-H)`` they are independent Gaussians ``N(0, 1/k_c)`` given the others: they are
   drawn anew.  For ``E = H_S`` the draw is an independence Metropolis proposal for ``exp(-H_S)`` and is
   accepted with ``min(1, exp(-(D(x') - D(x))))``, ``D = H_S - H`` (Izaguirre and Hampton, Sect. 3).
2. **Trajectory.**  ``L = steps`` steps of the scheme ``Phi_h``, the proposal ``y = R Phi_h^L(x)`` with the
   linear involution ``R`` that negates the ``flip`` coordinates, accepted with
   ``min(1, exp(E(x) - E(y)))``; then ``R`` is applied again (it preserves ``pi``), so an accepted state is
   ``Phi_h^L(x)`` and a rejected one ``R x``.  A proposal that leaves float64 (inf or nan) is rejected and
   counted in ``diverged``.

**Why it is exact** (detailed balance for ``pi``): the proposal map ``F = R Phi_h^L`` is an involution that
preserves volume, which makes the Metropolis step reversible for ``pi`` (Tierney 1998; Neal, *MCMC using
Hamiltonian dynamics*, 2011, Sect. 3.2), provided

* every sub-flow preserves volume: the fields of the pieces are divergence free (``div X_i = 0``, checked
  exactly; true for canonical and Nambu pieces, Eq. (NB) and Liouville's theorem);
* ``R Phi_h R = Phi_h^{-1}``: each piece field is ``R``-reversible, ``X_i(R x) = -R X_i(x)`` (checked exactly
  for every piece), so ``R phi_t R = phi_{-t}`` for each sub-flow, and the word is palindromic, so the
  composition satisfies ``Phi_{-h} = Phi_h^{-1}``;
* ``E(R x) = E(x)`` (checked exactly, for ``H`` and for the family member ``H_S`` used).

For a canonical system ``R`` flips the momenta.  A Nambu system has no momentum to flip in general; this module
finds out whether the coordinates given in ``flip`` reverse every piece and refuses, naming the piece, when they
do not.  Lundstrum's generalized HMC (Phys. Rev. D 111 (2025), arXiv:2409.18958; PoS LATTICE2024 044) is of this
kind: a triplet ``(q, p, r)`` per degree of freedom, ``H = V(q) + p^2/2 + r^2/2`` for the target and a second
Hamiltonian ``G`` carrying further forces into the molecular dynamics; with ``G = r + W(q)`` the three pieces
of the paper's splitting are shears (``q' = p``; ``p' = -V'(q) + r W'(q)``; ``r' = -p W'(q)``) and the flip
of ``p`` alone reverses each of them (the flip of ``r`` does not).

**Weights.**  Samples of ``exp(-H_S)`` estimate expectations under ``exp(-H)`` with the weights
``w = exp(H_S - H)`` (kept as logarithms): ``<f> = sum w f / sum w`` (:meth:`MonteCarloRun.expectation`).  A
truncated ``H_S`` of a non-quadratic system is in general not bounded below (for example, ``-h^2 q^6/24`` in
the velocity-Verlet ``H_S`` of ``V = q^4/4``); chains started in the bulk do not reach that region in practice,
and :attr:`MonteCarloRun.diverged` counts the proposals that escaped.

References
----------
S. Duane, A. D. Kennedy, B. J. Pendleton, D. Roweth, Phys. Lett. B 195 (1987) 216.
J. A. Izaguirre, S. S. Hampton, J. Comput. Phys. 200 (2004) 581.
R. M. Neal, *MCMC using Hamiltonian dynamics*, Handbook of Markov Chain Monte Carlo (2011), Ch. 5.
E. Lundstrum, *Generalized HMC using Nambu mechanics for lattice QCD*, arXiv:2409.18958.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import sympy

from ..algebra.zero import is_zero
from ..checks import check_int, check_sequence, finite_float, show
from ..errors import InvalidCompositionError, InvalidRunError, NumericalRangeError, ResourceLimitError
from ..integrators.composition import composition as make_composition
from ..integrators.step import parameter_values
from ..symbols import STEP
from ..values import ValueEquality
from .diagnostics import numpy_function
from .guards import MAX_RUN_STEPS, finite_array, initial_state
from .iterate import as_system
from .kernels import kernel, resolve_backend

#: Most kept values (iterations x coordinates x chains) one run stores: 2*10^7 float64 are 160 MB.
MAX_KEPT_VALUES = 2 * 10**7
#: Trajectory-steps from which ``backend="auto"`` compiles the scheme's loop instead of running numpy.
COMPILE_WORK = 10**7
TARGETS = ("H", "H_S")


class Estimate(NamedTuple):
    """An expectation and its standard error (the spread of the estimate over groups of chains)."""

    value: float
    error: float


@dataclass(eq=False)
class MonteCarloRun(ValueEquality):
    """The chains of :func:`hybrid_monte_carlo` after burn-in, their acceptance and their weights.

    Attributes
    ----------
    model, integrator, target : str -- the system, the scheme and ``"H"`` or ``"H_S"``
    h : float; steps : int -- the step and the steps per trajectory
    order : int or None; alpha : float or None -- the truncation and family value of ``H_S`` (``target="H_S"``)
    refresh, flip : tuple of str -- the coordinates drawn anew and those negated by the involution ``R``
    acceptance : float -- the fraction of trajectories accepted (kept iterations)
    refresh_acceptance : float -- the fraction of refresh proposals accepted (1 for ``target="H"``)
    diverged : int -- proposals that left float64 (rejected), over all iterations
    samples : numpy.ndarray -- shape ``(iterations, N, chains)``, the states after each kept iteration
    log_weights : numpy.ndarray -- shape ``(iterations, chains)``, ``H_S - H`` at the samples (zeros for ``"H"``)
    """

    model: str
    integrator: str
    target: str
    h: float
    steps: int
    order: int | None
    alpha: float | None
    params: dict
    refresh: tuple
    flip: tuple
    seed: int | None
    acceptance: float
    refresh_acceptance: float
    diverged: int
    samples: np.ndarray
    log_weights: np.ndarray
    coordinates: tuple = field(default=(), repr=False)

    def _value(self) -> tuple:
        return (self.model, self.integrator, self.target, self.h, self.steps, self.order, self.alpha, self.params,
                self.refresh, self.flip, self.seed, self.acceptance, self.refresh_acceptance, self.diverged,
                self.samples, self.log_weights, self.coordinates)

    @property
    def chains(self) -> int:
        return int(self.samples.shape[2])

    @property
    def iterations(self) -> int:
        return int(self.samples.shape[0])

    def weights(self) -> np.ndarray:
        """``exp(H_S - H)`` at the samples, scaled so that the largest is 1 (shape ``(iterations, chains)``)."""
        return np.exp(self.log_weights - self.log_weights.max())

    @property
    def effective_sample_fraction(self) -> float:
        """``(sum w)^2 / (n sum w^2)``: 1 for equal weights, smaller as the weights spread."""
        w = self.weights()
        return float(w.sum() ** 2 / (w * w).sum() / w.size)

    def expectation(self, f, groups=None) -> Estimate:
        """The weighted mean of ``f`` over the samples, and its standard error from ``groups`` groups of chains
        (None: 20, or one per chain when there are fewer).

        ``f`` maps an array of states of shape ``(N, ...)`` (one row per coordinate) to values of shape ``(...)``,
        e.g. ``lambda x: x[0]**2``.
        """
        groups = min(20, self.chains) if groups is None else check_int(groups, "groups", 2, self.chains)
        values = np.asarray(f(np.moveaxis(self.samples, 1, 0)), dtype=np.float64)
        if values.shape != self.log_weights.shape:
            raise InvalidRunError(f"f must map states of shape (N, iterations, chains) to shape "
                                  f"{self.log_weights.shape}, got {values.shape}")
        w = self.weights()
        with np.errstate(all="ignore"):
            parts = [float((wg * vg).sum() / wg.sum())
                     for wg, vg in zip(np.array_split(w, groups, axis=1), np.array_split(values, groups, axis=1))]
            out = Estimate(float((w * values).sum() / w.sum()), float(np.std(parts) / math.sqrt(groups)))
        if not (math.isfinite(out.value) and math.isfinite(out.error)):
            raise NumericalRangeError("the expectation or its error is not finite in float64 (f is too large at the "
                                      "samples); rescale f")
        return out

    def to_dict(self, samples: bool = False) -> dict:
        """JSON-ready summary (the samples and weights only with ``samples=True``)."""
        out = {"kind": "hybrid_monte_carlo", "model": self.model, "integrator": self.integrator,
               "target": self.target, "h": self.h, "steps": self.steps, "order": self.order, "alpha": self.alpha,
               "params": dict(self.params), "refresh": list(self.refresh), "flip": list(self.flip),
               "seed": self.seed, "chains": self.chains, "iterations": self.iterations,
               "acceptance": self.acceptance, "refresh_acceptance": self.refresh_acceptance,
               "diverged": self.diverged, "effective_sample_fraction": self.effective_sample_fraction}
        if samples:
            out["samples"] = self.samples.tolist()
            out["log_weights"] = self.log_weights.tolist()
        return out

    def __str__(self):
        shadow = f" (order {self.order}, alpha = {self.alpha:g})" if self.target == "H_S" else ""
        return (f"hybrid Monte Carlo on {self.model} with {self.integrator}, h = {self.h:g}, {self.steps} steps per "
                f"trajectory, target exp(-{self.target}){shadow}: {self.chains} chains x {self.iterations} iterations\n"
                f"  acceptance {self.acceptance:.4f}, refresh acceptance {self.refresh_acceptance:.4f}, "
                f"diverged {self.diverged}, effective sample fraction {self.effective_sample_fraction:.4f}")


def hybrid_monte_carlo(system, word, h, steps, *, refresh=None, flip=None, target="H", order=4, alpha=0.5,
                       chains=1000, iterations=50, burn=10, x0=None, params=None, seed=None,
                       backend="auto") -> MonteCarloRun:
    """Sample ``exp(-H)`` (or the shadow ``exp(-H_S)``, reweighted) with trajectories of a splitting scheme.

    Parameters
    ----------
    system : System or model name; word : str or Composition -- a palindromic scheme of the system's pieces
    h : float > 0; steps : int >= 1 -- the step and the number of steps of one trajectory
    refresh : sequence of coordinate names -- drawn anew each iteration; ``H`` must be ``k c^2/2`` in each
        (``k > 0``) plus terms free of it.  None: the momenta of a canonical system (required otherwise)
    flip : sequence of coordinate names -- the involution ``R`` negates them; None: the ``refresh`` coordinates
    target : ``"H"`` or ``"H_S"`` -- the density sampled; ``"H_S"``: the shadow Hamiltonian truncated at ``order``
        with the family parameter(s) at ``alpha``, reweighted to ``exp(-H)``
    chains, iterations, burn : int -- independent chains, kept iterations, iterations discarded first
    x0 : array of shape (N,) or (N, chains), optional -- start states (None: the model's default state)
    params : dict, optional -- parameter values (missing ones are 1); seed : int, optional -- for numpy's generator
    backend : ``"auto"``, ``"numba"`` or ``"numpy"`` -- as for :func:`~nambu_bch.numeric.iterate`

    Returns
    -------
    MonteCarloRun

    Raises
    ------
    InvalidCompositionError -- a word that is not palindromic, or whose pieces ``flip`` does not reverse or
        that do not preserve volume
    InvalidRunError -- bad names, counts, ``target``, ``x0``, or an ``H`` (``H_S``) that is not Gaussian in the
        ``refresh`` coordinates or not invariant under ``R``
    ResourceLimitError -- more trajectory-steps than one run accepts, or more kept values than
        :data:`MAX_KEPT_VALUES`, refused before any work

    Examples
    --------
    >>> run = hybrid_monte_carlo("ho", "212", 0.5, 2, chains=1000, iterations=30, seed=1)
    >>> run.samples.shape, run.acceptance > 0.9
    ((30, 2, 1000), True)
    >>> round(run.expectation(lambda x: x[0]**2).value, 1)          # <q^2> = 1 under exp(-H), m = omega = 1
    1.0
    """
    system = as_system(system)
    comp = make_composition(word, len(system.splitting))
    if not comp.symmetric:
        raise InvalidCompositionError(f"hybrid Monte Carlo needs a palindromic (time-symmetric) scheme, so that "
                                      f"Phi_-h = Phi_h^-1; got {show(str(comp))}")
    h = finite_float(h, "h")
    if not h > 0:
        raise InvalidRunError(f"h must be positive, got {show(h)}")
    steps = check_int(steps, "steps", 1)
    chains, iterations = check_int(chains, "chains", 2), check_int(iterations, "iterations", 1)
    burn = check_int(burn, "burn", 0)
    if seed is not None:
        seed = check_int(seed, "seed", 0)
    if not (isinstance(target, str) and target in TARGETS):
        raise InvalidRunError(f"target must be one of {', '.join(TARGETS)}, got {show(target)}")
    coords = [str(c) for c in system.coordinates]
    refresh = _default_refresh(system) if refresh is None else _names(refresh, coords, "refresh")
    flip = refresh if flip is None else _names(flip, coords, "flip")
    if not isinstance(backend, str):
        raise InvalidRunError(f"backend must be 'auto', 'numba' or 'numpy', got {show(backend)}")
    be = resolve_backend(backend)
    if iterations * system.N * chains > MAX_KEPT_VALUES:  # from the request, before any array is made
        raise ResourceLimitError(f"{iterations} iterations x {system.N} coordinates x {chains} chains is more than the "
                                 f"{MAX_KEPT_VALUES:.0e} values one run keeps; take fewer chains or iterations")
    if (iterations + burn) * steps * chains > MAX_RUN_STEPS:
        raise ResourceLimitError(f"{iterations + burn} iterations x {steps} steps x {chains} chains is more than the "
                                 f"{MAX_RUN_STEPS:.0e} trajectory-steps one run accepts; take fewer of them")
    x0, _ = initial_state(system, x0)
    X = _start(x0, system.N, chains)

    signs = np.array([-1.0 if c in flip else 1.0 for c in coords])
    _check_pieces(system, comp, signs)
    values = parameter_values(system, params)
    exact_params = {p: sympy.nsimplify(v, rational=True) for p, v in values.items()}
    scale = _gaussian_scales(system.H, system.coordinates, refresh, coords, exact_params)
    _check_invariant(system.H, system.coordinates, signs, "H")
    # the values the run evaluates with: the parameters, h and alpha as their exact binary values (as check does)
    given = {**{p: sympy.Float(v, 60) for p, v in values.items()}, STEP: sympy.Float(h, 60)}
    exprs = {"H": sympy.sympify(system.H, strict=True).xreplace(given)}
    if target == "H_S":
        order, alpha = check_int(order, "order", 2), finite_float(alpha, "alpha")
        H_S, free = _shadow_family(system, comp, order)  # derived once: checked exactly, then evaluated
        exact_alpha = sympy.nsimplify(alpha, rational=True)
        _check_invariant(H_S.xreplace({s: exact_alpha for s in free}).xreplace(exact_params), system.coordinates, signs,
                         "H_S")
        exprs["H_S"] = H_S.xreplace({s: sympy.Float(alpha, 60) for s in free}).xreplace(given)
    else:
        order = alpha = None
    for name, expr in exprs.items():
        if expr.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo):
            raise InvalidRunError(f"{name} is singular at these parameter values; give others")
    energy = {n: numpy_function(e, system.coordinates) for n, e in exprs.items()}

    kern = kernel(system, comp)
    K = kern.constants(h, params)
    if backend == "auto" and be == "numba" and not kern.ready(kern.loop_name(False, True)) \
            and (iterations + burn) * steps * chains < COMPILE_WORK:
        be = "numpy"
    rng = np.random.default_rng(seed)
    idx = [coords.index(c) for c in refresh]
    E = energy[target]
    gap = (lambda S: energy["H_S"](S) - energy["H"](S)) if target == "H_S" else None
    samples = np.empty((iterations, system.N, chains))
    log_w = np.zeros((iterations, chains))
    accepted = refreshed = diverged = 0
    out = np.empty((2, system.N, chains))
    with np.errstate(all="ignore"):
        for it in range(burn + iterations):
            new = X.copy()
            new[idx] = rng.standard_normal((len(idx), chains)) * scale[:, None]
            if gap is None:
                ok = np.ones(chains, dtype=bool)
            else:
                ok = rng.random(chains) < np.exp(np.minimum(0.0, gap(X.T) - gap(new.T)))
            X = np.where(ok, new, X)
            Y = X.copy()
            kern.run_batch(Y, K, steps, steps, out, backend=be)
            finite = np.isfinite(Y).all(axis=0)
            E0, E1 = E(X.T), E(np.where(finite, Y, X).T)
            take = finite & np.isfinite(E1) & (rng.random(chains) < np.exp(np.minimum(0.0, E0 - E1)))
            X = np.where(take, Y, X * signs[:, None])
            diverged += int((~finite).sum())
            if it >= burn:
                k = it - burn
                samples[k] = X
                if gap is not None:
                    log_w[k] = gap(X.T)
                accepted += int(take.sum())
                refreshed += int(ok.sum())
    if not np.isfinite(log_w).all():
        raise NumericalRangeError("H_S - H is not finite at a sample: the chains left the range where the "
                                  "truncated shadow Hamiltonian can be evaluated; take a smaller h")
    total = iterations * chains
    return MonteCarloRun(system.name, str(comp) if not isinstance(word, str) else word, target, h, steps, order, alpha,
                         {p.name: v for p, v in values.items()}, tuple(refresh), tuple(flip), seed,
                         accepted / total, refreshed / total, diverged, samples, log_w, tuple(coords))


def _names(value, coords, what) -> tuple:
    items = check_sequence(value, what, of="coordinate names")
    bad = [v for v in items if not isinstance(v, str) or v not in coords]
    if bad:
        raise InvalidRunError(f"{what} names coordinates of the system ({', '.join(coords)}); got {show(bad[0])}")
    if len(set(items)) != len(items):
        raise InvalidRunError(f"{what} names a coordinate twice: {show(list(items))}")
    if not items:
        raise InvalidRunError(f"{what} needs at least one coordinate of {', '.join(coords)}")
    return tuple(items)


def _default_refresh(system) -> tuple:
    if system.bracket != "canonical":
        raise InvalidRunError(f"{system.name} has the {system.bracket} bracket: say which coordinates to draw anew "
                              f"(refresh=...) and which to negate (flip=...); only canonical systems have momenta")
    return tuple(str(c) for c in system.coordinates[system.N // 2:])


def _start(x0, N, chains) -> np.ndarray:
    X = finite_array(x0, "x0")
    if X.ndim == 1:
        X = np.repeat(X[:, None], chains, axis=1)
    if X.shape != (N, chains):
        raise InvalidRunError(f"x0 must have shape ({N},) or ({N}, {chains}) (chains = {chains}), got {X.shape}")
    return np.ascontiguousarray(X)


def _check_pieces(system, comp, signs) -> None:
    """Every piece of the word preserves volume and is reversed by ``R = diag(signs)``, exactly."""
    coords = system.coordinates
    flipped = {c: -c for c, s in zip(coords, signs) if s < 0}
    for piece in system.splitting.pieces:
        if piece.number not in comp.pieces:
            continue
        X = [sympy.sympify(c, strict=True) for c in piece.field.to_sympy()]
        if not is_zero(sum(sympy.diff(x, c) for x, c in zip(X, coords))):
            raise InvalidCompositionError(f"piece {piece.number} of {system.name} does not preserve volume "
                                          f"(its field has a non-zero divergence)")
        for x, c, s in zip(X, coords, signs):
            if not is_zero(x.xreplace(flipped) + s * x):
                flips = ", ".join(str(c) for c, t in zip(coords, signs) if t < 0)
                raise InvalidCompositionError(
                    f"negating {flips} does not reverse piece {piece.number} of {system.name} (its {c}-component "
                    f"{x} fails X(R x) = -R X(x)), so the scheme is not reversible under that flip; flip other coordinates")


def _check_invariant(expr, coords, signs, name) -> None:
    flipped = {c: -c for c, s in zip(coords, signs) if s < 0}
    if not is_zero(expr.xreplace(flipped) - expr):
        flips = ", ".join(str(c) for c, s in zip(coords, signs) if s < 0)
        raise InvalidRunError(f"{name} is not invariant under negating {flips}, so the flip does not preserve "
                              f"exp(-{name}); flip other coordinates")


def _gaussian_scales(H, coordinates, refresh, coords, exact_params) -> np.ndarray:
    """``1/sqrt(k_c)`` for each refreshed ``c``, where ``H = k_c c^2/2 + (terms free of c)`` exactly."""
    out = []
    for name in refresh:
        c = coordinates[coords.index(name)]
        k = sympy.diff(H, c, 2)
        if k.free_symbols & set(coordinates) or not is_zero(sympy.diff(H, c) - k * c):
            raise InvalidRunError(f"H is not k {name}^2/2 plus terms free of {name}, so {name} cannot be drawn "
                                  f"from exp(-H) as a Gaussian; refresh only such coordinates")
        value = float(k.xreplace(exact_params))
        if not (math.isfinite(value) and value > 0):
            raise InvalidRunError(f"the coefficient k of {name}^2/2 in H is {value:g} at these parameters; "
                                  f"a Gaussian refresh needs k > 0")
        out.append(1.0 / math.sqrt(value))
    return np.array(out)


def _shadow_family(system, comp, order):
    """``(H_S, family parameters)``: the exact shadow Hamiltonian of order ``order``, refused where there is none."""
    from ..shadow.api import shadow_hamiltonians

    family = shadow_hamiltonians(system, comp, order=order)
    if not family.exists or family.H_S is None:
        raise InvalidRunError(f"{system.name} with {comp} has no shadow pair at order {order}, so exp(-H_S) "
                              f"cannot be sampled; use target='H'")
    return sympy.sympify(family.H_S, strict=True), [sympy.Symbol(str(s)) for s in family.free_parameters]
