"""Progress bars of numeric runs: :mod:`nambu_bch.progress` (tqdm), re-exported under its historical name.

The implementation lives at the package's top level so that symbolic code (the
order-by-order direct route) can use it without importing the numeric stack.
"""

from ..progress import Progress, progress_wanted, stages

__all__ = ["Progress", "progress_wanted", "stages"]
