"""Diagnostics along a run: errors of H, G, H_c, G_c, H_S; x^o, x^c, x^s - x; order and drift fits.

The numerical proof of the symbolic results (Sect. 5.5 of the paper):

* the original Hamiltonians ``H``, ``G`` oscillate with ``O(h^2)`` amplitude;
* the exact conserved quantities ``H_c``, ``G_c`` (Table (table)) stay at round-off;
* the truncated BCH shadow Hamiltonians of order ``k`` oscillate with
  ``O(h^{k+2})`` amplitude for a symmetric scheme (:func:`nambu_bch.shadow.shadow_hamiltonians`);
* the exact shadow Hamiltonians ``F^alpha H_c``, ``F^(1-alpha) G_c`` stay at round-off;
* ``x^o - x`` beats (Fig. 3), ``x^c - x`` beats (Fig. 4, solid), ``x^s - x`` stays at
  round-off (Fig. 4, dashed): Eqs. (OHsol), (CQsol), (SHsol).

:func:`check` runs all of these and returns a :class:`CheckResult` whose
``to_dict()`` is what ``nambu-bch check`` prints.  :func:`observed_order`
fits ``log(error) = p log(h) + c``; :func:`drift_rate` fits a straight line
``Q(t) - Q(0) = r t + c`` (a secular drift has ``r != 0`` beyond its error).

Every quantity is a sympy expression lambdified *once* (numpy) and evaluated
on the whole sample array.  Quantities that a system and word do not have
(no polynomial invariant, no closed-form solution, no shadow Hamiltonian at
this order) are left out, never guessed.

References
----------
Horikoshi, Sect. 5.5, Figs. 1-4, Eqs. (OHsol), (CQsol), (SHsol), Table (table).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import sympy

from ..bch.backward import check_order
from ..checks import finite_float, show
from ..errors import InvalidRunError, NambuBCHError, NumericalRangeError
from ..integrators.composition import composition as make_composition
from ..integrators.step import parameter_values
from .guards import MAX_RUN_STEPS, check_count, finite_array, initial_state
from .iterate import as_system, iterate
from .samples import sample_steps, sample_times
from ..symbols import ALPHA, STEP


#: The quantities :func:`quantities` can provide, in display order.
QUANTITY_NAMES = ("H", "G", "H_c", "G_c", "H_S", "G_S", "H_S_exact", "G_S_exact")


# -- the quantities ---------------------------------------------------------------------------------------


def quantities(system, word, h, params=None, order=2, alpha=0.5, which=QUANTITY_NAMES, skipped=None) -> dict:
    """``{name: sympy expression in the coordinates}`` with ``h``, the parameters and ``alpha`` substituted.

    ``H``, ``G`` (the system), ``H_c``, ``G_c`` (:func:`nambu_bch.exact.conserved_quantities`),
    ``H_S``, ``G_S`` (truncated BCH shadow Hamiltonians of ``order``, family parameters set to
    ``alpha``), ``H_S_exact``, ``G_S_exact`` (:func:`nambu_bch.exact.exact_shadow_hamiltonians`).
    Names a system or word does not have are absent, and so are those that are singular at
    these parameter values (e.g. ``H_c`` of the rigid body has ``I1 - I2`` in a denominator,
    so at ``I1 = I2`` it is not defined): ``skipped`` (a dict, if given) receives
    ``{name: reason}`` for them.

    Examples
    --------
    >>> from nambu_bch import model
    >>> q = quantities(model("ho3"), "32123", 0.1, which=("H", "H_c"))
    >>> sorted(q), sorted(map(str, q["H_c"].free_symbols))
    (['H', 'H_c'], ['x1', 'x2', 'x3'])
    """
    system = as_system(system)
    h, alpha, order = finite_float(h, "h"), finite_float(alpha, "alpha"), check_order(order)
    which = _names(which, QUANTITY_NAMES, "which")
    values = parameter_values(system, params)
    # exact binary values (60 digits), so mpmath evaluations see the same h as the run
    subs = {**{p: sympy.Float(v, 60) for p, v in values.items()}, STEP: sympy.Float(h, 60),
            ALPHA: sympy.Float(alpha, 60)}
    out = {}

    def put(name, expr):
        if name in which and expr is not None:
            value = sympy.sympify(expr, strict=True).xreplace(subs)
            if value.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo):
                if skipped is not None:
                    given = ", ".join(f"{p} = {v:g}" for p, v in values.items())
                    skipped[name] = f"singular at {given}" if given else "singular"
                return
            out[name] = value

    put("H", system.H)
    put("G", system.G)
    if {"H_c", "G_c"} & set(which):
        cq = _try(lambda: _exact().conserved_quantities(system, word))
        if cq is not None:
            put("H_c", cq.H_c)
            put("G_c", cq.G_c)
    if {"H_S", "G_S"} & set(which):
        fam = _try(lambda: _shadow(system, word, order))
        if fam is not None and fam.exists:
            free = list(fam.free_parameters)
            extra = {sympy.Symbol(str(s)) if not isinstance(s, sympy.Symbol) else s: sympy.Float(float(alpha), 60) for s in free}
            put("H_S", None if fam.H_S is None else sympy.sympify(fam.H_S, strict=True).xreplace(extra))
            put("G_S", None if fam.G_S is None else sympy.sympify(fam.G_S, strict=True).xreplace(extra))
    if {"H_S_exact", "G_S_exact"} & set(which):
        es = _try(lambda: _exact().exact_shadow_hamiltonians(system, word))
        if es is not None:
            put("H_S_exact", es.H_S)
            put("G_S_exact", es.G_S)
    return out


def _names(names, accepted, what) -> tuple:
    """``names`` (one name or an iterable of them) as a tuple, each one of ``accepted``; else one line."""
    if isinstance(names, str):
        names = (names,)
    try:
        names = tuple(names)
    except TypeError:
        names = None
    if names is None or not all(isinstance(n, str) and n in accepted for n in names):
        raise InvalidRunError(f"{what} must name some of {', '.join(accepted)}, got {names!r}")
    return names


def _exact():
    from .. import exact

    return exact


def _shadow(system, word, order):
    from ..shadow import shadow_hamiltonians

    return shadow_hamiltonians(system, word, order=order)


def _try(fn):
    """The result, or None when the package says the result does not exist (a :class:`NambuBCHError`).

    ``NotImplementedError`` is sympy's answer for an equation its solvers cannot handle
    (an exact solution of a sub-flow the package does not know): the quantity is then
    left out, as a non-existent one.  Anything else is a bug and propagates.
    """
    try:
        return fn()
    except (NambuBCHError, NotImplementedError):
        return None


def evaluate(expr, coordinates, samples, dps=None) -> np.ndarray:
    """``expr`` on every sample (rows of ``samples``, shape (n, N) or (n, N, batch)); float64 out.

    With ``dps`` (object samples from an mpmath run) the evaluation is done in mpmath.
    """
    if dps is None:
        return numpy_function(expr, coordinates)(samples)
    import mpmath

    fn = sympy.lambdify(coordinates, expr, modules="mpmath")
    with mpmath.workdps(dps):
        flat = samples.reshape(samples.shape[0], samples.shape[1], -1)
        res = np.empty((flat.shape[0], flat.shape[2]), dtype=object)
        for n in range(flat.shape[0]):
            for b in range(flat.shape[2]):
                res[n, b] = fn(*flat[n, :, b])
        return res.reshape((samples.shape[0],) + samples.shape[2:])


def numpy_function(expr, coordinates):
    """``f(samples) -> float64 array``: ``expr`` lambdified once (numpy) and evaluated on sample rows."""
    fn = sympy.lambdify(coordinates, expr, modules="numpy")
    n = len(coordinates)

    def f(samples):
        cols = [np.asarray(samples[:, i], dtype=np.float64) for i in range(n)]
        return np.broadcast_to(np.asarray(fn(*cols), dtype=np.float64), cols[0].shape).copy()

    return f


def errors_along(samples, exprs: dict, coordinates, dps=None) -> dict:
    """``{name: Q(x_n) - Q(x_0)}`` for each expression (float64 arrays; differences taken before rounding)."""
    out = {}
    for name, expr in exprs.items():
        v = evaluate(expr, coordinates, samples, dps)
        if dps is None:
            out[name] = v - v[0]
        else:
            import mpmath

            with mpmath.workdps(dps):
                out[name] = np.array([float(a - v[0]) for a in v.ravel()]).reshape(v.shape)
    return out


def solution_differences(system, word, h, steps, every, x0, samples, params=None, kinds="ocs") -> dict:
    """``{"x3_o": x3^o(t_n) - x3_n, ...}`` for every coordinate and kind with a closed-form solution.

    Eqs. (OHsol), (CQsol), (SHsol); Figs. 3 and 4 plot ``x3_o``, ``x3_c``, ``x3_s``.
    """
    system = as_system(system)
    t = sample_times(h, steps, every)
    out = {}
    for kind in kinds:
        sol = _try(lambda k=kind: _exact().modified_solution(system, word, k).numeric(params=params, h=float(h)))
        if sol is None:
            continue
        ref = sol(t, np.asarray(x0, dtype=float))
        for i, c in enumerate(system.coordinates):
            out[f"{c}_{kind}"] = ref[i] - samples[:, i]
    return out


# -- check --------------------------------------------------------------------------------------------------


@dataclass
class CheckResult:
    """The errors of one run (``nambu-bch check``).

    Attributes
    ----------
    model, integrator : str
    h : float
    steps, every : int
    x0 : list of float
    params : dict
    order : int -- truncation order of ``H_S``, ``G_S``
    alpha : float -- value given to the family parameter(s)
    max_abs_error : dict -- ``max_n |Q(x_n) - Q(x_0)|`` per quantity, ``max_n |x_i^k(t_n) - x_{i,n}|``
        per ``x{i}_{k}`` (k = o, c, s)
    drift_rate : dict -- slope of a straight-line fit of ``Q(t) - Q(0)`` (per unit time)
    seconds : float -- wall time of the run and its diagnostics
    skipped : dict -- quantities left out because they are singular at these parameters, with the reason
    """

    model: str
    integrator: str
    h: float
    steps: int
    every: int
    x0: list
    params: dict
    order: int
    alpha: float
    max_abs_error: dict = field(default_factory=dict)
    drift_rate: dict = field(default_factory=dict)
    seconds: float = 0.0
    skipped: dict = field(default_factory=dict)
    system: object = field(default=None, repr=False, compare=False)  # for the JSON head (coordinates, parameters)
    #: how the run computed: float64, or complex128 for complex coefficients (:mod:`.complex_iterate`)
    arithmetic: str = "float64"

    def to_dict(self) -> dict:
        """JSON-ready: ``{"model", "integrator", "h", "steps", ..., "max_abs_error": {...}, "drift_rate": {...}}``,
        after the system's part (:func:`nambu_bch.render.result_head`) when the system is known;
        ``nambu-bch check --format json`` prints exactly this dict."""
        from ..render import result_head

        head = result_head(self.system, self.integrator) if self.system is not None else {}
        return {
            **head,
            "model": self.model, "integrator": self.integrator, "h": float(self.h), "steps": int(self.steps),
            "every": int(self.every), "x0": [float(v) for v in self.x0],
            "params": {k: float(v) for k, v in self.params.items()}, "order": int(self.order),
            "alpha": float(self.alpha),
            "max_abs_error": {k: _json_float(v) for k, v in self.max_abs_error.items()},
            "drift_rate": {k: _json_float(v) for k, v in self.drift_rate.items()},
            **({"skipped": dict(self.skipped)} if self.skipped else {}),
            **({"arithmetic": self.arithmetic} if self.arithmetic != "float64" else {}),
        }

    def __str__(self):
        complex_run = f" ({self.arithmetic}; |Q(t) - Q(0)| of complex Q)" if self.arithmetic != "float64" else ""
        lines = [f"{self.model} {self.integrator}: h = {self.h}, {self.steps} steps{complex_run}"]
        lines += [f"  max |{_label(k)}| = {v:.3e}" for k, v in self.max_abs_error.items()]
        lines += [f"  {k}: not evaluated ({why})" for k, why in self.skipped.items()]
        return "\n".join(lines)


def _label(key):
    """``H`` -> ``H(t) - H(0)``; ``x1_o`` -> ``x1^o - x1`` (the closed-form solution minus the run)."""
    coord, _, kind = key.rpartition("_")
    if kind in ("o", "c", "s") and coord and not coord.startswith(("H", "G")):
        return f"{coord}^{kind} - {coord}"
    return f"{key}(t) - {key}(0)"


def _json_float(v):
    v = float(v)
    return v if math.isfinite(v) else None


class RunningStats:
    """Streaming ``max |y|`` and least-squares slope of ``y`` against ``t``, fed block by block.

    Blocks are merged with the pairwise update of Chan, Golub and LeVeque (*Algorithms for
    computing the sample variance*, Am. Stat. 37 (1983), Eq. 2.1 generalised to the
    co-moment): the means and the centred sums ``Stt = sum (t - tbar)^2``,
    ``Sty = sum (t - tbar)(y - ybar)`` of two blocks combine exactly, so the slope
    ``Sty / Stt`` equals :func:`drift_rate` of the whole series to rounding, while only one
    block is ever held.

    Examples
    --------
    >>> t = np.arange(10.0); y = 2 * t + np.sin(t)
    >>> acc = RunningStats(); acc.add(t[:4], y[:4]); acc.add(t[4:], y[4:])
    >>> bool(abs(acc.rate - drift_rate(t, y).rate) < 1e-12), acc.count, bool(acc.max_abs == abs(y).max())
    (True, 10, True)
    """

    def __init__(self):
        self.count = 0
        self.max_abs = 0.0
        self.mean_t = self.mean_y = self.stt = self.sty = 0.0
        self.finite = True

    def add(self, t, y):
        t = np.asarray(t, dtype=np.float64).ravel()
        y = np.asarray(y, dtype=np.float64).ravel()
        if not y.size:
            return
        if not np.all(np.isfinite(y)):
            self.finite = False
            return
        self.max_abs = max(self.max_abs, float(np.max(np.abs(y))))
        nb = y.size
        mt, my = float(t.mean()), float(y.mean())
        dt = t - mt
        stt, sty = float(dt @ dt), float(dt @ (y - my))
        na, n = self.count, self.count + nb
        delta_t, delta_y = mt - self.mean_t, my - self.mean_y
        self.stt += stt + delta_t * delta_t * na * nb / n
        self.sty += sty + delta_t * delta_y * na * nb / n
        self.mean_t += delta_t * nb / n
        self.mean_y += delta_y * nb / n
        self.count = n

    @property
    def rate(self) -> float:
        """The least-squares slope (0 with fewer than 3 points or one distinct time)."""
        return self.sty / self.stt if self.count > 2 and self.stt > 0 else 0.0


def check(system, word, h, steps, x0=None, params=None, *, order=2, alpha=0.5, every=1, kahan=False,
          backend="auto", include=None, chunk_samples=None) -> CheckResult:
    """Run ``word`` on ``system`` and measure every error the package can predict.

    The run is streamed (:func:`~nambu_bch.numeric.iterate.iterate_chunks`): each block of
    samples is evaluated and folded into running maxima and drift fits (:class:`RunningStats`),
    so memory stays bounded whatever ``steps / every`` is.

    Parameters
    ----------
    system : System or model name; word : str or Composition
    h : float; steps : int
    x0 : array of shape (N,); None: the model's documented default (:data:`nambu_bch.systems.catalog.DEFAULT_X0`)
    params : dict, optional
    order : int -- truncation order ``k`` of the BCH shadow Hamiltonians ``H_S``, ``G_S``, 0 to
        :data:`nambu_bch.checks.MAX_ORDER` (0: ``H_S = H``, ``G_S = G``)
    alpha : float -- the value of the family parameter(s) of ``H_S``, ``G_S`` and the exact ones
    every : int -- sample (and measure) every ``every`` steps
    kahan, backend : as for :func:`~nambu_bch.numeric.iterate`
    include : iterable of names, optional -- restrict to these quantities (default: all of
        :data:`QUANTITY_NAMES`) -- and solution kinds ``"o"``, ``"c"``, ``"s"``
    chunk_samples : int, optional -- samples per streamed block (tuning and tests)

    A composition with complex coefficients runs in complex128 instead
    (:func:`complex_check`: ``H``, ``G``, ``H_S``, ``G_S``, errors as moduli).

    Returns
    -------
    CheckResult -- ``.to_dict()["max_abs_error"]`` has ``H, G, H_c, G_c, H_S, G_S``,
        ``H_S_exact, G_S_exact`` and ``x1_o .. xN_s`` where they are defined; ``skipped`` names the quantities
        that are singular at the given parameters.

    Raises
    ------
    InvalidOrderError
        ``order`` outside ``0..MAX_ORDER``.
    ResourceLimitError
        More steps than a run accepts (:func:`~nambu_bch.numeric.guards.check_work`).
    NumericalRangeError
        A non-finite ``alpha``, or a quantity that is not finite along the run
        (float64 overflow in evaluating it, e.g. ``x0 = (1e154, 1e154, 1)``).

    References
    ----------
    Horikoshi, Sect. 5.5, Figs. 1-4.

    Examples
    --------
    >>> r = check("ho3", "32123", 0.1, 2000, [1.0, 1.0, 1.0], include=("H", "H_c", "s"))
    >>> sorted(r.max_abs_error)
    ['H', 'H_c', 'x1_s', 'x2_s', 'x3_s']
    >>> r.max_abs_error["H_c"] < 1e-13 < 1e-4 < r.max_abs_error["H"], r.max_abs_error["x3_s"] < 1e-10
    (True, True)
    """
    import time

    from .iterate import CHUNK_SAMPLES, iterate_chunks

    start = time.perf_counter()
    system = as_system(system)
    from ..integrators.runge_kutta import runge_kutta_method

    comp = runge_kutta_method(word) or make_composition(word, len(system.splitting))  # a Runge-Kutta method runs too
    name = word if isinstance(word, str) else str(comp)
    if getattr(comp, "is_complex", False):  # a complex map: complex128 on its own path
        if kahan:
            raise InvalidRunError(f"kahan=True applies to float64 runs; {name!r} has complex coefficients and runs in "
                                  "complex128")
        return complex_check(system, word, h, steps, x0, params, order=order, alpha=alpha, every=every, include=include,
                             backend=backend)
    alpha = finite_float(alpha, "alpha")
    order = check_order(order)
    given, (x0, _) = x0, initial_state(system, x0)  # the run resolves None itself, and names it as the default
    try:
        ndim = np.ndim(x0)
    except (TypeError, ValueError):  # ragged: iterate_chunks names it
        ndim = 1
    if ndim != 1:
        raise InvalidRunError(f"check takes one initial state of shape ({system.N},), got shape {np.shape(x0)}")
    everything = QUANTITY_NAMES + tuple("ocs")
    include = _names(include, everything, "include") if include is not None else everything
    chunk_samples = CHUNK_SAMPLES if chunk_samples is None else check_count(chunk_samples, "chunk_samples", 2)
    blocks = iterate_chunks(system, word, h, steps, given, params, every, kahan=kahan, backend=backend,
                            chunk_samples=chunk_samples)
    first_numbers, first = next(blocks)  # validates the run before any symbolic work
    skipped = {}
    exprs = quantities(system, word, h, params, order, alpha, which=[q for q in include if q in QUANTITY_NAMES],
                       skipped=skipped)
    fns = {q: numpy_function(e, system.coordinates) for q, e in exprs.items()}
    x0f = np.asarray(x0, dtype=np.float64)
    sols = {}
    for kind in (k for k in "ocs" if k in include):
        sol = _try(lambda k=kind: _exact().modified_solution(system, word, k).numeric(params=params, h=float(h)))
        if sol is not None:
            sols[kind] = sol
    stats = {q: RunningStats() for q in fns}
    stats.update({f"{c}_{k}": RunningStats() for k in sols for c in system.coordinates})
    hf = float(h)
    with np.errstate(all="ignore"):
        start_values = {q: fn(first)[0] for q, fn in fns.items()}
        for numbers, block in _chain([(first_numbers, first)], blocks):
            t = hf * numbers.astype(np.float64)
            for q, fn in fns.items():
                stats[q].add(t, fn(block) - start_values[q])
            for kind, sol in sols.items():
                ref = sol(t, x0f)
                for i, c in enumerate(system.coordinates):
                    stats[f"{c}_{kind}"].add(t, ref[i] - block[:, i])
    bad = [q for q, acc in stats.items() if not acc.finite]
    if bad:
        raise NumericalRangeError(
            f"{', '.join(bad)} {'is' if len(bad) == 1 else 'are'} not finite along the run of {name} on {system.name} "
            f"from x0 = {x0f.tolist()} (float64 overflow in evaluating {'it' if len(bad) == 1 else 'them'}"
            f"{f', alpha = {alpha:g}' if any(q.endswith(('_S', '_S_exact')) for q in bad) else ''}); "
            "rescale the initial state or the parameters"
        )
    result = CheckResult(system.name, name, float(h), int(steps), int(every), [float(v) for v in x0],
                         {p.name: v for p, v in parameter_values(system, params).items()}, int(order), float(alpha),
                         system=system)
    for key, acc in stats.items():
        result.max_abs_error[key] = acc.max_abs
    for q in fns:
        result.drift_rate[q] = stats[q].rate
    result.skipped = skipped
    result.seconds = time.perf_counter() - start
    return result


def _chain(*iterables):
    for it in iterables:
        yield from it


# -- fits ---------------------------------------------------------------------------------------------------


@dataclass
class DriftFit:
    """``Q(t) - Q(0) ~ rate * t + intercept``; ``stderr`` is the standard error of ``rate``."""

    rate: float
    stderr: float
    intercept: float
    span: float

    @property
    def drift(self) -> float:
        """``rate * span``: the secular change over the fitted time span."""
        return self.rate * self.span

    def to_dict(self) -> dict:
        return {"rate": self.rate, "stderr": self.stderr, "intercept": self.intercept, "span": self.span,
                "drift": self.drift}


def drift_rate(t, values) -> DriftFit:
    """Least-squares straight line through ``(t, values - values[0])``: the secular drift rate.

    Examples
    --------
    >>> t = np.linspace(0, 10, 101)
    >>> fit = drift_rate(t, 3e-12 * t + 1e-3 * np.sin(40 * t))
    >>> abs(fit.rate - 3e-12) < 2e-5, fit.span
    (True, 10.0)
    """
    t = finite_array(t, "t").ravel()
    y = finite_array(values, "values").ravel()
    if t.shape != y.shape or t.size < 3:
        raise InvalidRunError(f"drift_rate needs matching t and values with at least 3 points, got {t.shape} and {y.shape}")
    y = y - y[0]
    tm = t.mean()
    dt = t - tm
    sxx = float(dt @ dt)
    if sxx == 0:
        raise InvalidRunError("drift_rate needs at least two distinct times")
    rate = float(dt @ (y - y.mean())) / sxx
    intercept = float(y.mean() - rate * tm)
    resid = y - (rate * t + intercept)
    stderr = math.sqrt(float(resid @ resid) / max(t.size - 2, 1) / sxx)
    return DriftFit(rate, stderr, intercept, float(t[-1] - t[0]))


@dataclass
class OrderFit:
    """``error ~ C h^order`` fitted on ``log error = order log h + log C``."""

    order: float
    intercept: float
    hs: np.ndarray
    errors: np.ndarray
    quantity: str

    def to_dict(self) -> dict:
        return {"order": self.order, "intercept": self.intercept, "hs": [float(v) for v in self.hs],
                "errors": [float(v) for v in self.errors], "quantity": self.quantity}


def fit_order(hs, errors, quantity="error") -> OrderFit:
    """Slope of ``log(errors)`` against ``log(hs)`` (least squares).

    >>> round(fit_order([0.1, 0.05, 0.025], [2e-2, 5e-3, 1.25e-3]).order, 6)
    2.0
    """
    hs = finite_array(hs, "hs")
    errors = finite_array(errors, "errors")
    if (hs.ndim != 1 or np.unique(hs).size < 2 or np.any(hs <= 0) or np.any(errors <= 0)
            or hs.shape != errors.shape):
        raise InvalidRunError(f"an order fit needs >= 2 distinct positive steps and as many positive errors, got "
                              f"hs = {show(hs.tolist())}, errors = {show(errors.tolist())}")
    slope, intercept = np.polyfit(np.log(hs), np.log(errors), 1)
    return OrderFit(float(slope), float(intercept), hs, errors, quantity)


def observed_order(system, word, hs, T, x0=None, params=None, quantity="x", backend="auto") -> OrderFit:
    """The observed order of convergence of ``word`` by a log-log fit over the steps ``hs``.

    ``quantity="x"``: the global error ``max_i |x_i(T) - x_i^ref(T)|`` against the exact
    solution ``x^o`` (Eq. OHsol) when the system has one, else against a run of
    the same scheme with step ``min(hs)/64`` (whose error is ``64^p`` times smaller).
    ``quantity="H"`` (or ``"G"``, ...): ``max_{t <= T} |Q(x(t)) - Q(x(0))|``.
    Each ``h`` is adjusted to ``T / round(T / h)`` so the runs end exactly at ``T``.

    Examples
    --------
    >>> fit = observed_order("ho3", "32123", [0.1, 0.05, 0.025], 5.0, [1.0, 1.0, 1.0])
    >>> round(fit.order, 1)
    2.0
    """
    system = as_system(system)
    x0, _ = initial_state(system, x0)
    T = finite_float(T, "T")
    hs = finite_array(hs, "hs")
    if hs.ndim != 1 or hs.size < 2 or not np.all(hs > 0) or not T > 0:
        raise InvalidRunError(f"observed_order needs T > 0 and at least two positive steps hs, got T = {T!r}, hs = {show(hs)}")
    if not isinstance(quantity, str) or quantity not in ("x",) + QUANTITY_NAMES:
        raise InvalidRunError(f"quantity must be 'x' or one of {', '.join(QUANTITY_NAMES)}, got {show(quantity)}")
    steps_list = [max(1, round(T / h)) if T / h < MAX_RUN_STEPS else MAX_RUN_STEPS + 1 for h in hs]
    hs_eff = np.array([T / n for n in steps_list])
    errors = []
    if quantity == "x":
        sol = _try(lambda: _exact().modified_solution(system, word, "o").numeric(params=params, h=float(hs_eff[0])))
        if sol is not None:
            ref = sol(np.array([T]), x0)[:, 0]
        else:
            n_ref = steps_list[int(np.argmin(hs_eff))] * 64
            ref = iterate(system, word, T / n_ref, n_ref, x0, params, n_ref, backend=backend)[-1]
        for h, n in zip(hs_eff, steps_list):
            final = iterate(system, word, h, n, x0, params, n, backend=backend)[-1]
            errors.append(float(np.max(np.abs(final - ref))))
    else:
        for h, n in zip(hs_eff, steps_list):
            exprs = quantities(system, word, h, params, which=(quantity,))
            if quantity not in exprs:
                raise InvalidRunError(f"quantity {quantity!r} is not defined for {system.name} with {word!r}; "
                                      f"use 'x' or one of {', '.join(QUANTITY_NAMES)}")
            samples = iterate(system, word, h, n, x0, params, 1, backend=backend)
            errors.append(float(np.max(np.abs(errors_along(samples, exprs, system.coordinates)[quantity]))))
    return fit_order(hs_eff, errors, quantity)


def complex_check(system, word, h, steps, x0=None, params=None, *, order=2, alpha=0.5, every=1, project=False,
                  include=None, backend="auto"):
    """:func:`nambu_bch.numeric.check` for a composition with complex coefficients: errors of ``H``, ``G`` and the
    complex shadow pair ``H_S, G_S`` along :func:`iterate_complex`.

    ``include`` takes the names :func:`~nambu_bch.numeric.check` takes; of them ``H``, ``G``, ``H_S``, ``G_S`` are
    evaluated.  Each quantity ``Q`` (complex in general: ``H_S`` has imaginary coefficients) is evaluated in complex128 on
    every sample; ``max_abs_error[Q] = max_n |Q(x_n) - Q(x_0)|`` (the modulus) and ``drift_rate[Q]`` is the
    least-squares slope of ``|Q(x_n) - Q(x_0)|`` against ``t_n``.  With ``project=True`` (the real run
    ``Re Phi_h``) ``Q`` is replaced by its real part ``Re Q`` (the states are real; the imaginary terms of
    ``H_S`` describe the complex map, which the projection discards).  The conserved quantities and exact solutions of
    :mod:`nambu_bch.exact` are real constructions and are not evaluated.  ``backend``: of the run
    (:func:`~nambu_bch.numeric.complex_iterate.iterate_complex`).

    Returns
    -------
    CheckResult -- with ``arithmetic`` ``"complex128"`` or ``"complex128, real part after every step"``.
    """
    import time

    from ..integrators.composition import composition_for
    from .complex_iterate import iterate_complex

    start = time.perf_counter()
    system = as_system(system)
    alpha, order = finite_float(alpha, "alpha"), check_order(order)
    # the names check() accepts; of them the complex run evaluates H, G, H_S, G_S (the rest are real constructions)
    everything = QUANTITY_NAMES + tuple("ocs")
    include = _names(include, everything, "include") if include is not None else everything
    include = [q for q in include if q in ("H", "G", "H_S", "G_S")]
    samples = iterate_complex(system, word, h, steps, x0, params, every, project=project, backend=backend)
    skipped = {}
    exprs = quantities(system, word, h, params, order, alpha, which=include, skipped=skipped)
    t = float(h) * sample_steps(steps, every).astype(np.float64)
    comp = composition_for(word, system.splitting)
    result = CheckResult(system.name, word if isinstance(word, str) else comp.name, float(h), int(steps), int(every),
                         [float(v) for v in samples[0].real],
                         {p.name: v for p, v in parameter_values(system, params).items()}, int(order), float(alpha),
                         system=system,
                         arithmetic="complex128, real part after every step" if project else "complex128")
    with np.errstate(all="ignore"):
        for name, expr in exprs.items():
            fn = sympy.lambdify(system.coordinates, expr, modules="numpy")
            cols = [np.asarray(samples[:, i], dtype=np.complex128) for i in range(system.N)]
            values = np.broadcast_to(np.asarray(fn(*cols), dtype=np.complex128), cols[0].shape)
            if project:  # a real run: the real part of Q (H_S's imaginary terms belong to the complex map)
                values = values.real
            err = np.abs(values - values[0])
            if not np.isfinite(err).all():
                raise NumericalRangeError(f"{name} is not finite along the complex run of {comp.name} on {system.name}; "
                                          "rescale the initial state or the parameters")
            acc = RunningStats()
            acc.add(t, err)
            result.max_abs_error[name] = acc.max_abs
            result.drift_rate[name] = acc.rate
    result.skipped = skipped
    result.seconds = time.perf_counter() - start
    return result
