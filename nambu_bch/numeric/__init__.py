"""Numeric backend: compiled iteration of splitting integrators, diagnostics, the paper's figures (Sect. 5.5)."""

from .codegen import StepProgram, step_program
from .iterate import iterate, n_samples, sample_steps, sample_times
from .kernels import Kernel, cache_dir, kernel, numba_available
from .progress import Progress

__all__ = [
    "Kernel",
    "Progress",
    "StepProgram",
    "cache_dir",
    "iterate",
    "kernel",
    "n_samples",
    "numba_available",
    "sample_steps",
    "sample_times",
    "step_program",
]
