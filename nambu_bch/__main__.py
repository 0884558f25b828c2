"""``python -m nambu_bch``: the ``nambu-bch`` command line (see :mod:`nambu_bch.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
