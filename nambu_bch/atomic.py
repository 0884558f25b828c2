"""File output that never leaves a half-written file and never replaces what it should write through.

:func:`write_output` is what ``--output`` uses:

* a **regular file** (new or existing) is written atomically: a temporary file in
  the same directory, flushed and ``fsync``-ed, then ``os.replace``; an existing
  file keeps its permission bits (a new one gets ``0o666 & ~umask``, as ``open``
  would give it);
* a **symbolic link** is followed: the file it points to is replaced atomically
  (the link itself stays a link); a dangling link, or a chain that loops, is refused;
* a **special file** -- character device (``/dev/stdout``, ``/dev/null``,
  ``/dev/full``, a terminal), FIFO or socket -- is written through as a stream,
  never replaced by a regular file;
* a directory is refused.

Errors (``ENOSPC`` on ``/dev/full``, ``EACCES``, ``EPIPE`` ...) are raised as
:class:`~nambu_bch.errors.OutputError` with a one-line message naming the path.
"""

from __future__ import annotations

import os
import stat
import tempfile

from .errors import OutputError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_atomic(path, data, mode: int | None = None) -> None:
    """Write ``data`` (str or bytes) to the regular file ``path`` via a temporary file and ``os.replace``.

    An existing file is replaced only once the new content is complete and flushed,
    so an interruption leaves either the old file or the new one, never a mixture.
    ``mode`` (permission bits) defaults to that of the existing file, else
    ``0o666 & ~umask``.  Raises ``OSError``; see :func:`write_output` for the checked entry.
    """
    path = os.fspath(path)
    if mode is None:
        try:
            mode = stat.S_IMODE(os.stat(path).st_mode)
        except FileNotFoundError:
            mode = 0o666 & ~_umask()
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-" + os.path.basename(path) + "-", dir=directory)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data.encode("utf-8") if isinstance(data, str) else data)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _write_stream(path, data: bytes) -> None:
    """Write through a device, FIFO or socket (no truncation, no replacement)."""
    fd = os.open(path, os.O_WRONLY | getattr(os, "O_CLOEXEC", 0))
    try:
        view = memoryview(data)
        while view:
            written = os.write(fd, view)
            view = view[written:]
    finally:
        os.close(fd)


def output_target(path) -> tuple:
    """``(kind, resolved path)`` for ``path``: kind ``"regular"`` (new or existing file) or ``"stream"``.

    Symbolic links are followed to their final target; a dangling or looping link
    and a directory raise :class:`~nambu_bch.errors.OutputError`.
    """
    shown = os.fspath(path)
    if not isinstance(shown, str) or not shown or "\x00" in shown:
        raise OutputError(f"--output {shown!r}: not a usable file name")
    try:
        info = os.stat(shown)  # follows links
    except FileNotFoundError:
        if os.path.islink(shown):
            raise OutputError(f"--output {shown!r}: a symbolic link to a missing file ({os.readlink(shown)!r}); refused") from None
        return "regular", shown
    except OSError as exc:  # ELOOP, EACCES, ENOTDIR ...
        raise OutputError(f"--output {shown!r}: cannot use this path ({exc.strerror or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise OutputError(f"--output {shown!r}: is a directory; give a file name")
    if stat.S_ISREG(info.st_mode):
        return "regular", os.path.realpath(shown)
    return "stream", shown


def write_output(path, data) -> None:
    """Write ``data`` (str or bytes) to ``path`` as :mod:`this module <nambu_bch.atomic>` describes.

    Raises
    ------
    OutputError
        One line naming the path and the reason (``No space left on device`` ...).

    Examples
    --------
    >>> import os, tempfile
    >>> d = tempfile.mkdtemp(); p = os.path.join(d, "out.txt")
    >>> write_output(p, "one"); os.chmod(p, 0o600); write_output(p, "two")
    >>> open(p).read(), oct(os.stat(p).st_mode & 0o777)
    ('two', '0o600')
    >>> write_output(os.devnull, "discarded")          # a device is written through, not replaced
    >>> os.path.exists(os.devnull) and not os.path.isfile(os.devnull)
    True
    """
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    kind, target = output_target(path)
    shown = os.fspath(path)
    try:
        if kind == "stream":
            _write_stream(target, payload)
        else:
            write_atomic(target, payload)
    except OSError as exc:
        raise OutputError(f"--output {shown!r}: cannot write ({exc.strerror or exc})") from None
