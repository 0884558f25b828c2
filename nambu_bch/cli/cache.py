"""A cache of deterministic CLI output (``nambu-bch models``) so that listing the models does not import sympy.

The output of ``models`` for the built-in catalogue depends only on the package's
source; it is stored under ``$NAMBU_BCH_CACHE/cli`` (else ``~/.cache/nambu_bch/cli``)
keyed by a SHA-256 of the request and of every ``.py`` file of the package, so any
edit of the package invalidates it.  An unwritable or corrupt cache is ignored
(the output is then computed, as without a cache).  Nothing but text the package
itself produced is stored or read back.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent.parent  # the nambu_bch package


def _key(request) -> str:
    digest = hashlib.sha256(repr(tuple(request)).encode())
    for path in sorted(_PACKAGE.rglob("*.py")):
        digest.update(str(path.relative_to(_PACKAGE)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _directory() -> Path:
    root = os.environ.get("NAMBU_BCH_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "nambu_bch")
    return Path(root) / "cli"


def cached_text(request, compute) -> str:
    """``compute()`` (a str), read from the cache when the same ``request`` was answered by the same source."""
    try:
        path = _directory() / (_key(request) + ".txt")
    except OSError:  # the package's files cannot be read for the key: no cache
        return compute()
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        pass
    text = compute()
    try:
        from ..atomic import write_atomic

        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, text)
    except OSError:
        pass
    return text
