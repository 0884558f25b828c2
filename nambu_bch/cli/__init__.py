"""The ``nambu-bch`` command line as a package; see :mod:`nambu_bch.cli._main` for the synopsis and exit codes.

The console script is ``nambu_bch.cli:main``; ``python -m nambu_bch`` runs the same.
"""

from ._main import SUBCOMMANDS, build_parser, main
from ._options import UsageError

__all__ = ["SUBCOMMANDS", "UsageError", "build_parser", "main"]
