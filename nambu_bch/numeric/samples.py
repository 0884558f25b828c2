"""The sample grid of a run: how many samples, at which steps and times (no imports beyond numpy).

A run of ``steps`` steps keeping every ``every``-th state samples the steps
``0, every, 2 every, ...`` and always the last step; :mod:`.iterate`,
:mod:`.precision` and :mod:`.figures` share this one definition.
"""

from __future__ import annotations

import numpy as np


def n_samples(steps: int, every: int) -> int:
    """Number of samples of a run: ``ceil(steps / every) + 1``.

    >>> n_samples(10, 5), n_samples(10, 3), n_samples(0, 4)
    (3, 5, 1)
    """
    return -(-int(steps) // int(every)) + 1


def sample_steps(steps: int, every: int = 1) -> np.ndarray:
    """The step number of every sample: ``0, every, 2 every, ...``, ending at ``steps``.

    >>> sample_steps(10, 3).tolist()
    [0, 3, 6, 9, 10]
    """
    grid = np.arange(0, int(steps) + 1, int(every), dtype=np.int64)
    if grid[-1] != steps:
        grid = np.append(grid, np.int64(steps))
    return grid


def sample_times(h, steps: int, every: int = 1) -> np.ndarray:
    """Times ``t = n h`` of the samples (float64)."""
    return float(h) * sample_steps(steps, every).astype(np.float64)
