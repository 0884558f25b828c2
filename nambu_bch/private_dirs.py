"""Private directories for the on-disk caches: where they are, and whether they may be trusted.

A cache directory is trusted only if it is a real directory (not a symbolic link) owned by the
effective user and writable by nobody else; otherwise another local user could plant a file the
package would then read (a kernel it runs, a listing it prints).  Used by the kernel cache
(:mod:`nambu_bch.numeric.kernels`) and the ``models`` listing cache (:mod:`nambu_bch.cli.cache`).
Imports nothing heavy, so the command line's fast paths can use it.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path


def cache_root() -> Path:
    """``$NAMBU_BCH_CACHE``, else ``~/.cache/nambu_bch``."""
    return Path(os.environ.get("NAMBU_BCH_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "nambu_bch"))


def euid():
    """The effective user id (None where the platform has none)."""
    return os.geteuid() if hasattr(os, "geteuid") else None


def untrusted(path: Path, check_owner: bool = True, kind: str = "directory"):
    """None if ``path`` is a ``kind`` (``"directory"`` or ``"file"``) we own that nobody else may write; else the reason."""
    try:
        st = os.lstat(path)
    except OSError as exc:
        return f"{path} is not accessible ({exc.strerror})"
    if stat.S_ISLNK(st.st_mode):
        return f"{path} is a symbolic link"
    if not (stat.S_ISDIR(st.st_mode) if kind == "directory" else stat.S_ISREG(st.st_mode)):
        return f"{path} is not a {kind}"
    if check_owner and euid() is not None and st.st_uid != euid():
        return f"{path} is owned by uid {st.st_uid}, not by this user ({euid()})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"{path} is writable by group or others (mode {stat.S_IMODE(st.st_mode):o})"
    return None
