"""Drift slopes of force-gradient compositions and processed kernels (:func:`gradient_check`).

Kept apart from :mod:`.force_gradient` (the runners, which :func:`~nambu_bch.numeric.iterate` hands such methods to)
because the check evaluates the shadow Hamiltonians through :mod:`.diagnostics`, which sits above ``iterate``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy

from ..checks import show
from ..errors import ResourceLimitError
from ..values import ValueEquality
from .force_gradient import (MAX_GRADIENT_STEPS, GradientStep, _values, is_processed_kernel, iterate_gradient,
                             iterate_processed)


@dataclass(frozen=True, eq=False)
class GradientCheck(ValueEquality):
    """The result of :func:`gradient_check`: per step size the largest drift of ``H`` and of the truncated shadow
    Hamiltonian ``H_S^[k]`` along the run, and the fitted slopes against ``h``."""

    system: object
    method: str
    processed: bool
    hs: tuple
    energy: tuple
    shadow: tuple
    shadow_order: object
    kernel_energy: tuple = ()

    def _value(self) -> tuple:
        return (self.system, self.method, self.processed, self.hs, self.energy, self.shadow, self.shadow_order,
                self.kernel_energy)

    @property
    def kernel_energy_slope(self) -> float:
        """For a processed kernel: the slope of the bare kernel's ``H`` drift (its own order, below the effective)."""
        return self._slope(self.hs, self.kernel_energy) if self.kernel_energy else float("nan")

    @staticmethod
    def _slope(hs, ys):
        good = [(h, y) for h, y in zip(hs, ys) if y is not None and y > 1e-13]
        if len(good) < 2:
            return float("nan")
        return float(np.polyfit(np.log([h for h, _ in good]), np.log([y for _, y in good]), 1)[0])

    @property
    def energy_slope(self) -> float:
        return self._slope(self.hs, self.energy)

    @property
    def shadow_slope(self) -> float:
        return self._slope(self.hs, self.shadow) if self.shadow_order is not None else float("nan")

    def to_dict(self) -> dict:
        return {"system": self.system.name, "integrator": self.method, "processed": self.processed,
                "h": list(self.hs), "max_H_drift": list(self.energy), "energy_slope": self.energy_slope,
                "shadow_order": self.shadow_order, "max_H_S_drift": list(self.shadow), "shadow_slope": self.shadow_slope,
                "kernel_max_H_drift": list(self.kernel_energy), "kernel_energy_slope": self.kernel_energy_slope}

    def __str__(self):
        lines = [f"{self.method} on {self.system.name}" + (" (processed: P K^n P^-1)" if self.processed else "")]
        head = f"{'h':>10} {'max|H - H(0)|':>15}"
        if self.shadow_order is not None:
            head += f" {'max|H_S^[' + str(self.shadow_order) + '] - H_S(0)|':>24}"
        if self.kernel_energy:
            head += f" {'kernel alone':>15}"
        lines.append(head)
        for i, h in enumerate(self.hs):
            row = f"{h:>10.4g} {self.energy[i]:>15.3e}"
            if self.shadow_order is not None:
                row += f" {self.shadow[i]:>24.3e}"
            if self.kernel_energy:
                row += f" {self.kernel_energy[i]:>15.3e}"
            lines.append(row)
        lines.append(f"slope of the H drift vs h: {self.energy_slope:.2f}")
        if self.kernel_energy:
            lines.append(f"slope of the kernel's own H drift vs h: {self.kernel_energy_slope:.2f}")
        if self.shadow_order is not None:
            lines.append(f"slope of the H_S^[{self.shadow_order}] drift vs h: {self.shadow_slope:.2f} "
                         f"(expected {self.shadow_order + 2} for a symmetric method)")
        return "\n".join(lines)


def gradient_check(system, method, h, steps, x0=None, params=None, halvings: int = 2) -> GradientCheck:
    """Run a force-gradient method (or a processed kernel) at ``h, h/2, ...`` over the same time ``steps h`` and
    measure the drift of ``H`` and, for a force-gradient composition of order ``p``, of ``H_S`` through ``h^p``
    (:func:`nambu_bch.design.gradient_system.gradient_shadow`): the slopes are ``p`` and ``p + 2``.  For a processed
    kernel the drift of ``H`` along the processed output has the effective order's slope, and the bare kernel's
    (``kernel_energy``) its own order's.
    """
    from ..checks import is_int
    from ..design.generalized import _gradient_spec, gradient_analysis
    from ..design.gradient_system import H as STEP, gradient_shadow
    from ..errors import InvalidRunError
    from .diagnostics import numpy_function

    from ..checks import finite_float
    from .guards import check_count

    if not is_int(halvings, 1, 4):
        raise InvalidRunError(f"halvings must be an integer in 1..4, got {halvings!r}")
    h = finite_float(h, "h")
    steps = check_count(steps, "steps", 1)
    if h == 0:
        raise InvalidRunError("h must be non-zero")
    if steps * 2**halvings > MAX_GRADIENT_STEPS:  # the finest run, refused before any work
        raise ResourceLimitError(f"steps = {show(steps)} with {halvings} halvings is more than the "
                                 f"{MAX_GRADIENT_STEPS:.0e} steps a force-gradient run accepts")
    step = GradientStep(system, method, params)
    S = step.system
    processed = is_processed_kernel(method)
    name = str(_gradient_spec(method))
    values = _values(S, params)
    coords = S.coordinates
    energy_f = numpy_function(S.H.subs(values), coords)
    shadow_f, k = None, None
    if not processed:
        k = gradient_analysis(method).order
        shadow = gradient_shadow(S, method, k)
        shadow_f = sympy.lambdify((*coords, STEP), shadow.truncated(k).subs(values), modules="numpy")
    hs, energy, drift, bare = [], [], [], []
    for i in range(halvings + 1):
        hi, ni = float(h) / 2**i, int(steps) * 2**i
        run = iterate_processed if processed else iterate_gradient
        x = run(S, method, hi, ni, x0, params)
        e = energy_f(x)
        hs.append(hi)
        energy.append(float(np.max(np.abs(e - e[0]))))
        if processed:
            k_run = energy_f(iterate_gradient(S, method, hi, ni, x0, params))
            bare.append(float(np.max(np.abs(k_run - k_run[0]))))
        if shadow_f is not None:
            s = np.broadcast_to(np.asarray(shadow_f(*x.T, hi), dtype=float), e.shape)
            drift.append(float(np.max(np.abs(s - s[0]))))
    return GradientCheck(S, name, processed, tuple(hs), tuple(energy),
                         tuple(drift) if shadow_f is not None else (None,) * len(hs), k, tuple(bare))
