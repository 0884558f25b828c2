"""Shadow Hamiltonians evaluated along a given trajectory: values, deviations and the fitted drift.

A trajectory produced anywhere -- by :func:`~nambu_bch.numeric.iterate` or by another code, as an
array of states ``(n_samples, N)`` -- is measured against the shadow pair ``H_S``, ``G_S`` of the
package at a chosen truncation order (:func:`nambu_bch.shadow.shadow_hamiltonians`), and against
``H``, ``G`` and the other quantities of :data:`~nambu_bch.numeric.diagnostics.QUANTITY_NAMES`.
The symbolic work is done once: the expressions of :func:`~nambu_bch.numeric.diagnostics.quantities`
are lambdified once by :func:`~nambu_bch.numeric.diagnostics.numpy_function` (the evaluator of
:func:`~nambu_bch.numeric.check`) and applied to the whole array; no sympy runs per sample.

For a symmetric scheme of order 2 and the truncated pair of order ``k``, ``H_S(x_n) - H_S(x_0)``
is ``O(h^{k+2})`` over exponentially long times (Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, Sect. IX.8); the deviation and the straight-line drift (:func:`drift_rate`) are what
this module reports.

References
----------
Horikoshi, Sect. 5.5; Hairer, Lubich, Wanner, Sect. IX.8.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..bch.backward import check_order
from ..checks import finite_float, show
from ..errors import InvalidRunError, NumericalRangeError
from ..integrators.composition import composition as make_composition
from ..integrators.step import parameter_values
from .diagnostics import QUANTITY_NAMES, _json_float, _names, drift_rate, numpy_function, quantities
from .guards import finite_array
from .iterate import as_system
from ..values import ValueEquality

#: Quantities evaluated when ``which`` is not given (those a system and word do not have are left out).
DEFAULT_QUANTITIES = ("H", "G", "H_S", "G_S")


@dataclass(eq=False)
class ShadowTrajectory(ValueEquality):
    """``H``, ``G``, ``H_S``, ``G_S`` (and any other requested quantity) along one trajectory.

    Attributes
    ----------
    model, integrator : str
    h : float -- the step of the scheme whose shadow pair is evaluated
    order : int -- truncation order of ``H_S``, ``G_S``
    alpha : float -- value given to the family parameter(s)
    params : dict -- the parameter values
    t : numpy.ndarray -- the sample times, shape ``(n_samples,)``
    values : dict -- ``{name: Q(x_n)}``, float64 arrays of shape ``(n_samples,)``
    max_abs_error : dict -- ``max_n |Q(x_n) - Q(x_0)|`` per quantity
    drift : dict -- ``{name: DriftFit}``, a straight line through ``(t, Q(x_n) - Q(x_0))``
    skipped : dict -- requested quantities that were not evaluated, with the reason
    """

    model: str
    integrator: str
    h: float
    order: int
    alpha: float
    params: dict
    t: np.ndarray
    values: dict = field(default_factory=dict)
    max_abs_error: dict = field(default_factory=dict)
    drift: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)
    system: object = field(default=None, repr=False, compare=False)  # for the JSON head (coordinates, parameters)

    def _value(self) -> tuple:
        """The samples as data (``==``, ``hash``): arrays by dtype, shape and bytes, the system by its definition."""
        return (self.model, self.integrator, self.h, self.order, self.alpha, self.params, self.t, self.values,
                self.max_abs_error, self.drift, self.skipped, self.system)

    @property
    def n_samples(self) -> int:
        return int(self.t.size)

    def errors(self, name) -> np.ndarray:
        """``Q(x_n) - Q(x_0)`` of the quantity ``name``."""
        if name not in self.values:
            raise InvalidRunError(f"name must be one of the evaluated quantities {', '.join(self.values) or '(none)'}, "
                                  f"got {show(name)}")
        v = self.values[name]
        return v - v[0]

    def to_dict(self, values: bool = False) -> dict:
        """JSON-ready summary: the run's description, ``max_abs_error``, ``drift_rate`` and the fits in ``drift``;
        with ``values=True`` also ``t`` and ``values`` (lists of floats, one per sample)."""
        from ..render import result_head

        head = result_head(self.system, self.integrator) if self.system is not None else {}
        out = {
            **head,
            "model": self.model, "integrator": self.integrator, "h": float(self.h), "order": int(self.order),
            "alpha": float(self.alpha), "params": {k: float(v) for k, v in self.params.items()},
            "n_samples": self.n_samples, "t_span": float(self.t[-1] - self.t[0]),
            "max_abs_error": {k: _json_float(v) for k, v in self.max_abs_error.items()},
            "drift_rate": {k: _json_float(fit.rate) for k, fit in self.drift.items()},
            "drift": {k: {key: _json_float(v) for key, v in fit.to_dict().items()} for k, fit in self.drift.items()},
            **({"skipped": dict(self.skipped)} if self.skipped else {}),
        }
        if values:
            out["t"] = [float(v) for v in self.t]
            out["values"] = {k: [_json_float(x) for x in v] for k, v in self.values.items()}
        return out

    def __str__(self):
        lines = [f"{self.model} {self.integrator}: h = {self.h}, order {self.order}, {self.n_samples} samples "
                 f"over t = {float(self.t[0]):g} .. {float(self.t[-1]):g}"]
        lines += [f"  max |{k}(t) - {k}(0)| = {v:.3e}, drift rate {self.drift[k].rate:.3e} "
                  f"+- {self.drift[k].stderr:.1e}" for k, v in self.max_abs_error.items()]
        lines += [f"  {k}: not evaluated ({why})" for k, why in self.skipped.items()]
        return "\n".join(lines)


def shadow_along(system, word, trajectory, h, *, order=2, alpha=0.5, params=None, t=None,
                 which=None) -> ShadowTrajectory:
    """Evaluate the shadow pair of ``word`` at step ``h`` along ``trajectory`` and fit its drift.

    Parameters
    ----------
    system : System or model name; word : str or Composition -- the scheme that made the trajectory
    trajectory : array of shape ``(n_samples, N)`` -- states, one per row (float64; from
        :func:`~nambu_bch.numeric.iterate` or any other code), at least 3 of them
    h : float -- the step of the scheme (the shadow pair depends on it)
    order : int -- truncation order ``k`` of ``H_S``, ``G_S`` (0 to :data:`nambu_bch.checks.MAX_ORDER`)
    alpha : float -- the value of the family parameter(s)
    params : dict, optional -- parameter values (missing ones are 1, as for ``iterate``)
    t : array of shape ``(n_samples,)``, optional -- the sample times; None: ``h * arange(n_samples)``
        (a run sampled at every step; pass :func:`~nambu_bch.numeric.sample_times` for ``every > 1``)
    which : iterable of names, optional -- quantities to evaluate, some of
        :data:`~nambu_bch.numeric.diagnostics.QUANTITY_NAMES`; None: ``H``, ``G``, ``H_S``, ``G_S``
        where the system and word have them (names given explicitly but not defined are listed in
        ``skipped``)

    Returns
    -------
    ShadowTrajectory

    Raises
    ------
    InvalidRunError -- a trajectory or ``t`` of the wrong shape or type, times not strictly increasing
    NumericalRangeError -- non-finite states, times or ``alpha``, or a quantity that overflows along the trajectory
    InvalidOrderError -- ``order`` outside ``0..MAX_ORDER``

    Examples
    --------
    >>> from nambu_bch import iterate
    >>> x = iterate("ho3", "12321", 0.1, 400, [1.0, 1.0, 1.0])
    >>> r = shadow_along("ho3", "12321", x, 0.1, order=2)
    >>> sorted(r.max_abs_error), bool(r.max_abs_error["G_S"] < 1e-2 * r.max_abs_error["G"])
    (['G', 'G_S', 'H', 'H_S'], True)
    """
    system = as_system(system)
    comp = make_composition(word, len(system.splitting))
    name = word if isinstance(word, str) else str(comp)
    h, alpha, order = finite_float(h, "h"), finite_float(alpha, "alpha"), check_order(order)
    X = _states(trajectory, system.N)
    times = _times(t, h, X.shape[0])
    explicit = which is not None
    which = _names(which, QUANTITY_NAMES, "which") if explicit else DEFAULT_QUANTITIES
    skipped = {}
    exprs = quantities(system, word, h, params, order, alpha, which=which, skipped=skipped)
    if explicit:
        for q in which:
            if q not in exprs and q not in skipped:
                skipped[q] = f"not defined for {system.name} with {name} at order {order}"
    result = ShadowTrajectory(system.name, name, h, order, alpha,
                              {p.name: v for p, v in parameter_values(system, params).items()}, times,
                              skipped=skipped, system=system)
    with np.errstate(all="ignore"):
        for q, expr in exprs.items():
            result.values[q] = numpy_function(expr, system.coordinates)(X)
    bad = [q for q, v in result.values.items() if not np.all(np.isfinite(v))]
    if bad:
        raise NumericalRangeError(f"{', '.join(bad)} {'is' if len(bad) == 1 else 'are'} not finite along the "
                                  f"trajectory (float64 overflow in evaluating at h = {h:g}); rescale the states "
                                  "or the parameters")
    for q, v in result.values.items():
        dev = v - v[0]
        result.max_abs_error[q] = float(np.max(np.abs(dev)))
        result.drift[q] = drift_rate(times, v)
    return result


def _states(trajectory, N) -> np.ndarray:
    """``trajectory`` as a float64 array of shape ``(n_samples, N)`` with ``n_samples >= 3``, else one line."""
    X = finite_array(trajectory, "trajectory")
    if X.ndim != 2 or X.shape[1] != N or X.shape[0] < 3:
        raise InvalidRunError(f"trajectory must be an array of shape (n_samples, {N}) with n_samples >= 3 "
                              f"(one state per row), got shape {X.shape}")
    return X


def _times(t, h, n) -> np.ndarray:
    """The sample times: ``h * arange(n)``, or ``t`` checked to be ``n`` strictly increasing finite numbers."""
    if t is None:
        if h == 0:
            raise InvalidRunError("h = 0 gives every state the same time; pass t, the sample times")
        # |h|: along a backward run (h < 0) the rows still follow one another in time for the fit
        times = abs(h) * np.arange(n, dtype=np.float64)
        if not math.isfinite(times[-1]):
            raise NumericalRangeError(f"the last sample time |h| * (n_samples - 1) = {abs(h)!r} * {n - 1} is beyond "
                                      "the float64 range; pass t")
        return times
    times = finite_array(t, "t")
    if times.shape != (n,):
        raise InvalidRunError(f"t must be an array of shape ({n},), one time per state of the trajectory, "
                              f"got shape {times.shape}")
    if not np.all(np.diff(times) > 0):
        raise InvalidRunError("t must be strictly increasing, one time per state of the trajectory")
    return times
