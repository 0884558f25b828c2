"""The sample grid of a run: how many samples, at which steps and times.

A run of ``steps`` steps keeping every ``every``-th state samples the steps
``0, every, 2 every, ...`` and always the last step; :mod:`.iterate`,
:mod:`.precision` and :mod:`.figures` share this one definition.  The arguments
are checked like a run's (:mod:`.guards`): ``steps`` an integer ``>= 0``,
``every`` an integer ``>= 1``, ``h`` a finite real number, and the grid no
larger than a run's sample array may be (:data:`MAX_SAMPLE_BYTES`).
"""

from __future__ import annotations

import numpy as np

from ..checks import show
from ..errors import NumericalRangeError, ResourceLimitError
from .guards import MAX_SAMPLE_BYTES, check_count, finite_float  # noqa: F401  (MAX_SAMPLE_BYTES: read here by iterate)


def _grid(steps, every):
    return check_count(steps, "steps", 0), check_count(every, "every", 1)


def n_samples(steps: int, every: int) -> int:
    """Number of samples of a run: ``ceil(steps / every) + 1``.

    >>> n_samples(10, 5), n_samples(10, 3), n_samples(0, 4)
    (3, 5, 1)
    """
    steps, every = _grid(steps, every)
    return -(-steps // every) + 1


def sample_steps(steps: int, every: int = 1) -> np.ndarray:
    """The step number of every sample: ``0, every, 2 every, ...``, ending at ``steps``.

    >>> sample_steps(10, 3).tolist()
    [0, 3, 6, 9, 10]
    """
    steps, every = _grid(steps, every)
    count = -(-steps // every) + 1
    if count * 8 > MAX_SAMPLE_BYTES:
        raise ResourceLimitError(f"steps = {show(steps)} sampled every {show(every)} give more samples than fit in "
                                 f"{MAX_SAMPLE_BYTES / 2**30:.0f} GiB; sample less often (larger every)")
    grid = np.arange(0, steps + 1, every, dtype=np.int64)
    if grid[-1] != steps:
        grid = np.append(grid, np.int64(steps))
    return grid


def sample_times(h, steps: int, every: int = 1) -> np.ndarray:
    """Times ``t = n h`` of the samples (float64).

    >>> sample_times(0.5, 4, 3).tolist()
    [0.0, 1.5, 2.0]
    """
    h = finite_float(h, "h")
    grid = sample_steps(steps, every)
    if not np.isfinite(h * float(grid[-1])):
        raise NumericalRangeError(f"the last sample time h * steps = {h!r} * {int(grid[-1])} is beyond the float64 range")
    return h * grid.astype(np.float64)
