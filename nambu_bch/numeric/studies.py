"""Speed-versus-accuracy studies: truncation order, arithmetic, step size (for benchmarks and notebooks).

Three questions a user of the package asks before a long run, each answered by
measurement (``benchmarks/bench_precision.py`` prints them; a notebook plots them):

* :func:`truncation_study` -- for BCH truncation orders ``k = 2, 4, 6, 8``: the
  cost of deriving the shadow Hamiltonians and the size of their residual
  oscillation and drift over a long run (``O(h^{k+2})`` for a symmetric scheme);
* :func:`precision_study` -- float64, float64 + Kahan, mpmath: cost per step and
  the round-off drift of the exact invariants ``H_c``, ``G_c`` (which the exact
  map conserves, so whatever they do is round-off); the mpmath run is shorter
  and its drift is extrapolated linearly (``rate * T``), which the result says;
* :func:`h_scan` -- errors of ``H, G, H_c, G_c`` for steps up to and beyond the
  stability limit ``omega h -> 2`` (Hairer, Lubich, Wanner, Sect. I.5), with the
  unstable steps reported as such (:class:`~nambu_bch.errors.UnstableStepError`).

Each returns a dataclass with ``to_dict()`` (JSON-ready) and ``rows()`` (a list of
dicts, one per line of a printed table).

References
----------
Horikoshi, Sect. 5.5; Higham, *Accuracy and Stability of Numerical Algorithms*, Sect. 4.3.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..bch.backward import check_order
from ..checks import finite_float, show
from ..errors import InvalidRunError, NambuBCHError, NumericalRangeError, UnstableStepError
from ..integrators.step import parameter_values
from .diagnostics import QUANTITY_NAMES, _names, drift_rate, errors_along, quantities
from .guards import check_count, check_work, finite_array, initial_state
from .iterate import as_system, iterate
from .samples import sample_times
from .kernels import kernel, resolve_backend


def _best_time(fn, repeats):
    best = float("inf")
    result = None
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def _finite(v):
    v = float(v)
    return v if math.isfinite(v) else None


# -- h scan ---------------------------------------------------------------------------------------------------


@dataclass
class HScan:
    """Errors over a range of steps.  ``max_abs_error[name][j]`` is NaN where ``hs[j]`` is unstable."""

    system: str
    word: str
    hs: np.ndarray
    steps: int
    stable: np.ndarray
    max_abs_error: dict
    omega: float | None = None
    messages: list = field(default_factory=list)

    @property
    def omega_h(self):
        return None if self.omega is None else self.omega * self.hs

    @property
    def stability_limit(self) -> float:
        """The largest stable ``h`` of the scan (NaN if none)."""
        ok = self.hs[self.stable]
        return float(ok.max()) if ok.size else float("nan")

    def rows(self) -> list:
        out = []
        for j, h in enumerate(self.hs):
            row = {"h": float(h), "stable": bool(self.stable[j])}
            if self.omega is not None:
                row["omega_h"] = float(self.omega * h)
            row.update({k: _finite(v[j]) for k, v in self.max_abs_error.items()})
            out.append(row)
        return out

    def to_dict(self) -> dict:
        return {"system": self.system, "word": self.word, "steps": self.steps, "omega": self.omega,
                "stability_limit": _finite(self.stability_limit), "rows": self.rows()}


def h_scan(system="ho3", word="32123", hs=None, steps=10_000, x0=None, params=None,
           names=("H", "G", "H_c", "G_c"), backend="auto") -> HScan:
    """``max_n |Q(x_n) - Q(x_0)|`` for each step in ``hs``, up to and past the stability limit.

    Parameters
    ----------
    system, word : the scheme (default: the paper's ``32123`` on ``ho3``)
    hs : steps; default ``omega h`` from 1e-3 to 1.999 geometrically, then 2.0 and 2.1
    steps : int -- steps per run
    x0 : initial state (default: the model's documented x0, else all ones); params : dict
    names : quantities to measure (see :func:`~nambu_bch.numeric.diagnostics.quantities`)

    Returns
    -------
    HScan

    Examples
    --------
    >>> scan = h_scan("ho", "TVT", hs=[0.5, 1.5, 1.99, 2.0, 2.5], steps=200)
    >>> scan.stable.tolist(), scan.stability_limit
    ([True, True, True, False, False], 1.99)
    """
    system = as_system(system)
    values = {p.name: v for p, v in parameter_values(system, params).items()}
    omega = values.get("omega")
    if hs is None:
        scale = omega or 1.0
        hs = np.concatenate([np.geomspace(1e-3, 1.9, 14), [1.99, 1.999, 2.0, 2.1]]) / scale
    hs = finite_array(hs, "hs").reshape(-1)
    steps = check_count(steps, "steps", 0)
    check_work(steps * max(hs.size, 1), None)  # the scan's runs together, before the first
    names = _names(names, QUANTITY_NAMES, "names")
    x0, _ = initial_state(system, x0)
    errs = {}
    stable = np.zeros(hs.size, dtype=bool)
    messages = []
    for j, h in enumerate(hs):
        try:
            samples = iterate(system, word, float(h), steps, x0, params, 1, backend=backend)
        except (UnstableStepError, NumericalRangeError) as exc:
            messages.append(f"h = {h:g}: {type(exc).__name__}: {exc}")
            continue
        stable[j] = True
        exprs = quantities(system, word, float(h), params, which=names)
        for name, series in errors_along(samples, exprs, system.coordinates).items():
            errs.setdefault(name, np.full(hs.size, np.nan))[j] = float(np.max(np.abs(series)))
    return HScan(system.name, str(word), hs, int(steps), stable, errs, omega, messages)


# -- truncation order --------------------------------------------------------------------------------------------


@dataclass
class TruncationStudy:
    """Per order ``k``: derivation time, ``max |Q(t) - Q(0)|`` and drift rate of ``H_S``, ``G_S``."""

    system: str
    word: str
    h: float
    steps: int
    orders: list
    derive_seconds: list
    max_abs_error: dict
    drift_rate: dict
    sources: list

    @property
    def source(self) -> str:
        """Where the shadow Hamiltonians came from (one line; per order in :meth:`rows`)."""
        return "; ".join(sorted(set(self.sources)))

    def rows(self) -> list:
        out = []
        for j, k in enumerate(self.orders):
            row = {"order": k, "derive_seconds": _finite(self.derive_seconds[j]), "source": self.sources[j]}
            for name in self.max_abs_error:
                row[f"max|d{name}|"] = _finite(self.max_abs_error[name][j])
                row[f"drift({name})"] = _finite(self.drift_rate[name][j])
            out.append(row)
        return out

    def to_dict(self) -> dict:
        return {"system": self.system, "word": self.word, "h": self.h, "steps": self.steps,
                "source": self.source, "rows": self.rows()}


def truncation_study(system="ho3", word="32123", orders=(2, 4, 6, 8), h=0.1, steps=1_000_000, x0=None,
                     params=None, alpha=0.5, every=100, backend="auto") -> TruncationStudy:
    """Cost and residual drift of the truncated shadow Hamiltonians for each order ``k``.

    The shadow Hamiltonians come from :func:`nambu_bch.shadow.shadow_hamiltonians` (the BCH
    route, timed on its first call in this process; ``source`` ``"bch"``); where that is not
    available or finds none, from the series of the exact ones
    (:meth:`nambu_bch.exact.ExactShadow.series`, ``source`` ``"exact-series"``).  One run of
    ``steps`` steps (sampled every ``every``) serves all orders.

    Returns
    -------
    TruncationStudy
    """
    import sympy

    from ..symbols import ALPHA, STEP

    system = as_system(system)
    try:
        orders = [check_order(k) for k in orders]
    except TypeError:
        raise InvalidRunError(f"orders must be a list of truncation orders such as (2, 4, 6), got {show(orders)}") from None
    h, alpha = finite_float(h, "h"), finite_float(alpha, "alpha")
    x0, _ = initial_state(system, x0)
    samples = iterate(system, word, h, steps, x0, params, every, backend=backend)
    t = sample_times(h, steps, every)
    values = parameter_values(system, params)
    subs = {**{p: sympy.Float(v, 60) for p, v in values.items()}, STEP: sympy.Float(float(h), 60),
            ALPHA: sympy.Float(float(alpha), 60)}
    derive, errs, drifts, sources = [], {}, {}, []
    for k in orders:
        start = time.perf_counter()
        exprs, source = None, "bch"
        try:
            from ..shadow import shadow_hamiltonians

            fam = shadow_hamiltonians(system, word, order=k)
            if fam.exists:
                free = {sympy.Symbol(str(s)): sympy.Float(float(alpha), 60) for s in fam.free_parameters}
                exprs = {"H_S": fam.H_S, "G_S": fam.G_S}
                exprs = {n: sympy.sympify(e, strict=True).xreplace(free) for n, e in exprs.items() if e is not None}
        except NambuBCHError:
            exprs = None
        if exprs is None:  # BCH route unavailable (or no shadow Hamiltonian): the exact family's series
            from ..exact import exact_shadow_hamiltonians

            source = "exact-series"
            H_S, G_S = exact_shadow_hamiltonians(system, word).series(k)
            exprs = {n: e for n, e in (("H_S", H_S), ("G_S", G_S)) if e is not None}
        derive.append(time.perf_counter() - start)
        sources.append(source)
        exprs = {n: e.xreplace(subs) for n, e in exprs.items()}
        for name, series in errors_along(samples, exprs, system.coordinates).items():
            errs.setdefault(name, []).append(float(np.max(np.abs(series))))
            drifts.setdefault(name, []).append(drift_rate(t, series).rate)
    return TruncationStudy(system.name, str(word), float(h), int(steps), list(orders), derive, errs, drifts, sources)


# -- arithmetic ----------------------------------------------------------------------------------------------------


@dataclass
class PrecisionStudy:
    """Per arithmetic: seconds per step, ``max |Q(t) - Q(0)|``, drift rate and drift over ``steps``."""

    system: str
    word: str
    h: float
    steps: int
    rows_: list

    def rows(self) -> list:
        return list(self.rows_)

    def to_dict(self) -> dict:
        return {"system": self.system, "word": self.word, "h": self.h, "steps": self.steps, "rows": self.rows()}


def precision_study(system="ho3", word="32123", h=0.1, steps=10_000_000, x0=None, params=None, every=1000,
                    mp_steps=20_000, dps=30, names=("H_c", "G_c"), repeats=3, backend="auto",
                    timing_steps=2_000_000) -> PrecisionStudy:
    """Cost per step and round-off drift of the exact invariants for float64, float64 + Kahan and mpmath.

    The cost per step of the two float64 arithmetics is timed on their own runs of
    ``timing_steps`` steps sampled only at the end (both compiled before timing, alternated,
    best of ``repeats``), so that a short study still measures the loop rather than the
    call overhead; the drift comes from the ``steps``-step runs sampled every ``every``.
    The float64 runs take ``steps`` steps;
    the mpmath run takes ``mp_steps`` steps and its drift over ``steps`` is *extrapolated*
    linearly (``extrapolated: True`` in its row).  Each row also gives the state error
    ``max_i |x_i - x_i^mp|`` after ``mp_steps`` steps against the mpmath run (same map, so pure
    round-off).

    Returns
    -------
    PrecisionStudy -- rows with ``arithmetic``, ``seconds_per_step``, ``steps_run``,
    ``extrapolated``, ``state_error_at_mp_steps`` and per quantity ``max|dQ|``, ``rate(Q)``, ``drift(Q)``.
    """
    system = as_system(system)
    x0, _ = initial_state(system, x0)
    h = finite_float(h, "h")
    steps, mp_steps = check_count(steps, "steps", 1), check_count(mp_steps, "mp_steps", 1)
    repeats, timing_steps = check_count(repeats, "repeats", 1), check_count(timing_steps, "timing_steps", 1)
    names = _names(names, QUANTITY_NAMES, "names")
    # every run of the study, from the request: float64 (two arithmetics, timed repeatedly) and mpmath
    check_work(2 * (steps + mp_steps + repeats * timing_steps), x0)
    check_work(mp_steps + min(mp_steps, 2000), x0, mpmath=True)
    be = resolve_backend(backend)
    kern = kernel(system, word)
    if be == "numba":
        kern.compile(kahan=False)
        kern.compile(kahan=True)
    exprs = quantities(system, word, h, params, which=names)
    T = h * steps
    mp_every = max(1, mp_steps // 1000)
    mp_samples = iterate(system, word, h, mp_steps, x0, params, mp_every, dps=dps)
    mp_final = np.array([float(v) for v in mp_samples[-1]])
    rows = []
    timing = {False: float("inf"), True: float("inf")}
    nt = max(1, int(timing_steps))
    for kahan in (False, True):  # warm: compile / load both loops before any timing
        iterate(system, word, h, 10, x0, params, 10, kahan=kahan, backend=be, check_stable=False)
    for _ in range(max(1, repeats)):  # alternate, so a busy machine slows both alike
        for kahan in (False, True):
            seconds, _ = _best_time(lambda k=kahan: iterate(system, word, h, nt, x0, params, nt, kahan=k, backend=be), 1)
            timing[kahan] = min(timing[kahan], seconds)
    for label, kahan in (("float64", False), ("float64+kahan", True)):
        samples = iterate(system, word, h, steps, x0, params, every, kahan=kahan, backend=be)
        short = iterate(system, word, h, mp_steps, x0, params, mp_steps, kahan=kahan, backend=be)[-1]
        row = {"arithmetic": label, "seconds_per_step": timing[kahan] / nt, "timing_steps": nt, "steps_run": steps,
               "extrapolated": False, "state_error_at_mp_steps": float(np.max(np.abs(short - mp_final)))}
        t = sample_times(h, steps, every)
        for name, series in errors_along(samples, exprs, system.coordinates).items():
            fit = drift_rate(t, series)
            row.update({f"max|d{name}|": float(np.max(np.abs(series))), f"rate({name})": fit.rate,
                        f"drift({name})": fit.rate * T})
        rows.append(row)
    seconds, _ = _best_time(lambda: iterate(system, word, h, min(mp_steps, 2000), x0, params, 2000, dps=dps), 1)
    row = {"arithmetic": f"mpmath dps={dps}", "seconds_per_step": seconds / min(mp_steps, 2000),
           "timing_steps": min(mp_steps, 2000), "steps_run": mp_steps, "extrapolated": True, "state_error_at_mp_steps": 0.0}
    t = sample_times(h, mp_steps, mp_every)
    for name, series in errors_along(mp_samples, exprs, system.coordinates, dps=dps).items():
        fit = drift_rate(t, series)
        row.update({f"max|d{name}|": float(np.max(np.abs(series))), f"rate({name})": fit.rate,
                    f"drift({name})": fit.rate * T})
    rows.append(row)
    return PrecisionStudy(system.name, str(word), float(h), int(steps), rows)


__all__ = ["HScan", "PrecisionStudy", "TruncationStudy", "h_scan", "precision_study", "truncation_study",
           "QUANTITY_NAMES"]
