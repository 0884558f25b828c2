"""Numeric backend: compiled iteration of splitting integrators, diagnostics, the paper's figures (Sect. 5.5).

``iterate`` runs a scheme (numba kernels generated once from the exact sub-flows, numpy and
mpmath fallbacks, optional Kahan summation); ``check`` measures every error the package
predicts; ``paper_figures`` redraws Figs. 1-4; ``shadow_along``
evaluates the shadow pair along any trajectory, ``iterate_complex`` runs compositions with complex coefficients in
complex128, ``numerical_shadow`` the Skeel-Hardy shadow Hamiltonian from a canonical trajectory alone;
``hybrid_monte_carlo`` samples exp(-H) or the shadow exp(-H_S) with the schemes, canonical or Nambu; the studies
answer speed-versus-accuracy questions.
"""

from ..progress import Progress
from .codegen import StepProgram, step_program
from .complex_iterate import iterate_complex
from .diagnostics import (CheckResult, DriftFit, OrderFit, RunningStats, check, drift_rate, fit_order, observed_order,
                          quantities)
from .figures import FigureSet, paper_figures
from .force_gradient import iterate_gradient, iterate_processed
from .gradient_check import GradientCheck, gradient_check
from .hmc import Estimate, MonteCarloRun, hybrid_monte_carlo
from .iterate import iterate, iterate_chunks
from .kernels import Kernel, cache_dir, kernel, numba_available
from .runge_kutta import rk_iterate, rk_step_function
from .samples import n_samples, sample_steps, sample_times
from .skeel_hardy import NumericalShadow, numerical_shadow
from .trajectory import ShadowTrajectory, shadow_along
from .studies import HScan, PrecisionStudy, TruncationStudy, h_scan, precision_study, truncation_study

__all__ = [
    "CheckResult",
    "DriftFit",
    "Estimate",
    "FigureSet",
    "GradientCheck",
    "HScan",
    "Kernel",
    "MonteCarloRun",
    "NumericalShadow",
    "OrderFit",
    "PrecisionStudy",
    "Progress",
    "RunningStats",
    "ShadowTrajectory",
    "StepProgram",
    "TruncationStudy",
    "cache_dir",
    "check",
    "drift_rate",
    "fit_order",
    "gradient_check",
    "h_scan",
    "hybrid_monte_carlo",
    "iterate",
    "iterate_chunks",
    "iterate_complex",
    "iterate_gradient",
    "iterate_processed",
    "kernel",
    "n_samples",
    "numba_available",
    "numerical_shadow",
    "observed_order",
    "paper_figures",
    "precision_study",
    "quantities",
    "rk_iterate",
    "rk_step_function",
    "sample_steps",
    "sample_times",
    "shadow_along",
    "step_program",
    "truncation_study",
]
