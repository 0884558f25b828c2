"""A cache of deterministic CLI output (``nambu-bch models``) so that listing the models does not import sympy.

The output of ``models`` for the built-in catalogue depends only on the package's
source; it is stored under ``$NAMBU_BCH_CACHE/cli`` (else ``~/.cache/nambu_bch/cli``)
keyed by a SHA-256 of the request and of every ``.py`` file of the package, so any
edit of the package invalidates it.  Each entry is one line ``nambu_bch listing sha256=<digest>``
followed by the text, written atomically (mode 0600); it is printed only if the digest matches
the text and the text holds no control character but newlines, so a truncated, damaged or planted
entry (terminal escapes) is computed again and rewritten, never printed.  An unwritable cache is
ignored (the output is then computed, as without a cache), and so is one whose directory or file
is not private (owned by this user, writable by nobody else, read as a regular file only:
:mod:`nambu_bch.private_dirs`), so another local user cannot plant the text it prints.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from ..private_dirs import cache_root, read_private, untrusted

_PACKAGE = Path(__file__).resolve().parent.parent  # the nambu_bch package
#: First bytes of an entry; the SHA-256 of the text follows, then a newline and the text.
_HEADER = "nambu_bch listing sha256="
#: Largest entry read back (the listings are below 20 kB).
MAX_ENTRY = 2**20


def _key(request) -> str:
    digest = hashlib.sha256(repr(tuple(request)).encode())
    for path in sorted(_PACKAGE.rglob("*.py")):
        digest.update(str(path.relative_to(_PACKAGE)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _directory():
    """``$NAMBU_BCH_CACHE/cli`` when it and its parent are private (:mod:`nambu_bch.private_dirs`), else None."""
    root = cache_root()
    path = root / "cli"
    try:
        root.mkdir(mode=0o700, parents=True, exist_ok=True)
        path.mkdir(mode=0o700, exist_ok=True)
    except OSError:
        return None
    return path if untrusted(root) is None and untrusted(path) is None else None


def cached_text(request, compute) -> str:
    """``compute()`` (a str), read from the cache when the same ``request`` was answered by the same source."""
    directory = _directory()
    if directory is None:  # no private cache directory: compute, as without a cache
        return compute()
    try:
        path = directory / (_key(request) + ".txt")
    except OSError:  # the package's files cannot be read for the key: no cache
        return compute()
    text = _read_entry(path)
    if text is not None:
        return text
    text = compute()
    try:
        from ..atomic import write_atomic

        write_atomic(path, f"{_HEADER}{hashlib.sha256(text.encode()).hexdigest()}\n{text}", mode=0o600)
    except OSError:
        pass
    return text


def _read_entry(path):
    """The text of the entry ``path`` if it is intact (digest) and printable, else None (then it is computed)."""
    try:
        data = read_private(path, MAX_ENTRY).decode("utf-8")
    except (OSError, UnicodeDecodeError):  # absent, not a private regular file, too large, not UTF-8
        return None
    head, newline, text = data.partition("\n")
    if not newline or head != _HEADER + hashlib.sha256(text.encode()).hexdigest():
        return None
    if not all(line.isprintable() for line in text.split("\n")):  # escapes, CR, bidi marks: never printed
        return None
    return text
