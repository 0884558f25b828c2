"""Private directories for the on-disk caches: where they are, whether they may be trusted, and how they are read.

A cache directory is trusted only if it is a real directory (not a symbolic link) owned by the
effective user and writable by nobody else, and no directory above it can be changed by another
user (each is owned by root or by us and is not writable by group or others, unless it is sticky
like ``/tmp``); otherwise another local user could plant a file the package would then read (a
kernel it runs, a pickle numba loads, a listing it prints) or swap the directory for one of theirs.
Every cache file is read by :func:`read_private`: a regular file we own, opened so that nothing can
block or be substituted, and bounded in size.  Used by the kernel cache
(:mod:`nambu_bch.numeric.kernels`), numba's machine-code cache (:mod:`nambu_bch.compiled`) and the
``models`` listing cache (:mod:`nambu_bch.cli.cache`); they write through
:func:`nambu_bch.atomic.write_atomic`.  Imports nothing heavy, so the command line's fast paths can use it.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

_WRITABLE_BY_OTHERS = stat.S_IWGRP | stat.S_IWOTH


def cache_root() -> Path:
    """``$NAMBU_BCH_CACHE``, else ``~/.cache/nambu_bch``."""
    return Path(os.environ.get("NAMBU_BCH_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "nambu_bch"))


def euid():
    """The effective user id (None where the platform has none)."""
    return os.geteuid() if hasattr(os, "geteuid") else None


def _foreign_owner(uid) -> bool:
    return euid() is not None and uid not in (0, euid())


def unsafe_ancestor(path):
    """None if no directory above ``path`` can be changed by another user; else the reason.

    Checked along the path as given and along its resolved path (so a symbolic link above the cache
    is followed, and the link itself must sit in a safe directory): every ancestor must be owned by
    root or by the effective user and must not be writable by group or others unless it has the
    sticky bit (``/tmp``: others cannot rename or remove what is ours there).
    """
    absolute = os.path.abspath(path)
    seen = set()
    for candidate in (absolute, os.path.realpath(absolute)):
        for ancestor in Path(candidate).parents:
            if ancestor in seen:
                continue
            seen.add(ancestor)
            try:
                st = os.lstat(ancestor)
            except OSError as exc:
                return f"{ancestor} is not accessible ({exc.strerror})"
            if _foreign_owner(st.st_uid):
                return f"{ancestor} (above {path}) is owned by uid {st.st_uid}, not by root or this user ({euid()})"
            if stat.S_ISLNK(st.st_mode):  # its target lies on the resolved path, checked there
                continue
            if not stat.S_ISDIR(st.st_mode):
                return f"{ancestor} (above {path}) is not a directory"
            if st.st_mode & _WRITABLE_BY_OTHERS and not st.st_mode & stat.S_ISVTX:
                return (f"{ancestor} (above {path}) is writable by group or others without the sticky bit "
                        f"(mode {stat.S_IMODE(st.st_mode):o})")
    return None


def _unsafe_stat(path, st, check_owner: bool, kind: str, check_mode: bool = True):
    """The reason why ``st`` (of ``path``) is not a private ``kind``, or None."""
    if stat.S_ISLNK(st.st_mode):
        return f"{path} is a symbolic link"
    if not (stat.S_ISDIR(st.st_mode) if kind == "directory" else stat.S_ISREG(st.st_mode)):
        return f"{path} is not a {kind}" + ("" if kind == "directory" else " (a FIFO, socket, device or directory)")
    if check_owner and euid() is not None and st.st_uid != euid():
        return f"{path} is owned by uid {st.st_uid}, not by this user ({euid()})"
    if check_mode and st.st_mode & _WRITABLE_BY_OTHERS:
        return f"{path} is writable by group or others (mode {stat.S_IMODE(st.st_mode):o})"
    return None


def untrusted(path: Path, check_owner: bool = True, kind: str = "directory"):
    """None if ``path`` is a ``kind`` (``"directory"`` or ``"file"``) we own that nobody else may write; else the reason.

    A directory must also have only safe directories above it (:func:`unsafe_ancestor`).
    """
    try:
        st = os.lstat(path)
    except OSError as exc:
        return f"{path} is not accessible ({exc.strerror})"
    reason = _unsafe_stat(path, st, check_owner, kind)
    if reason is None and kind == "directory":
        reason = unsafe_ancestor(path)
    return reason


def read_private(path, limit: int, owned: bool = True) -> bytes:
    """The bytes of the regular file ``path``, ours and writable by nobody else, at most ``limit`` bytes.

    The one way a cache file is read.  ``lstat`` first (a symbolic link, FIFO, socket, device or
    directory is refused before it is opened, so opening cannot block or have a device's side
    effects), then ``open`` with ``O_NOFOLLOW | O_NONBLOCK`` and ``fstat`` of the opened descriptor,
    which must be the very file checked (same device and inode), so nothing can be substituted
    in between.  The directory is the caller's to check (:func:`untrusted`).  ``owned=False``
    drops the owner and mode checks (the package's own source files, installed by someone else).

    Raises
    ------
    OSError
        Absent, not a private regular file, or larger than ``limit``.
    """
    before = os.lstat(path)
    reason = _unsafe_stat(path, before, owned, "file", owned)
    if reason:
        raise OSError(reason)
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(path, flags)
    with os.fdopen(fd, "rb") as handle:
        st = os.fstat(fd)
        reason = _unsafe_stat(path, st, owned, "file", owned)
        if reason is None and (st.st_dev, st.st_ino) != (before.st_dev, before.st_ino):
            reason = f"{path} was replaced while it was opened"
        if reason is None and st.st_size > limit:
            reason = f"{path} is larger than {limit} bytes"
        if reason:
            raise OSError(reason)
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise OSError(f"{path} is larger than {limit} bytes")
    return data


def _prepare(base: Path, parts, fresh: bool = False):
    """``base/parts[0]/.../parts[-1]`` with every level created (mode 0700) and checked; ``(path, None)`` or ``(None, reason)``.

    ``fresh``: ``base`` was just made by ``mkdtemp`` (ours by construction), so ownership is not re-checked.
    """
    level = base
    levels = [base]
    for part in parts:
        level = level / part
        levels.append(level)
    for level in levels:
        try:
            level.mkdir(mode=0o700, parents=True, exist_ok=True)
        except OSError as exc:
            return None, f"cannot create {level} ({exc.strerror})"
        reason = untrusted(level, check_owner=not fresh)
        if reason:
            return None, reason
    try:  # a fresh name (O_EXCL): nothing planted under a guessable name can be opened
        fd, probe = tempfile.mkstemp(prefix=".probe-", dir=levels[-1])
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        return None, f"{levels[-1]} is not writable ({exc.strerror})"
    return levels[-1], None


def private_directory(*parts: str, notes: dict | None = None, fresh: bool = True):
    """``<cache root>/<parts...>``, every level private; else the same under ``$TMPDIR/nambu_bch-<uid>``.

    When neither is private: a fresh ``mkdtemp`` directory (``fresh=True``), else None (the caller
    then keeps nothing on disk).  Why the cache root was not used is recorded in ``notes``
    (``{str(cache root): reason}``).
    """
    root = cache_root()
    path, reason = _prepare(root, parts)
    if path is not None:
        return path
    if notes is not None:
        notes[str(root)] = reason
    uid = euid() if euid() is not None else "user"
    path, reason2 = _prepare(Path(tempfile.gettempdir()) / f"nambu_bch-{uid}", parts)
    if path is not None:
        return path
    if notes is not None:
        notes[str(root)] = f"{reason}; {reason2}"
    if not fresh:
        return None
    path, reason3 = _prepare(Path(tempfile.mkdtemp(prefix="nambu_bch-")), parts, fresh=True)
    if path is None:  # pragma: no cover - a fresh mkdtemp directory is always ours
        raise OSError(f"no private cache directory: {reason}; {reason2}; {reason3}")
    return path
