"""Atomic file output: a reader never sees a half-written file."""

from __future__ import annotations

import os
import tempfile


def write_atomic(path, data) -> None:
    """Write ``data`` (str or bytes) to ``path`` via a temporary file in the same directory and ``os.replace``.

    An existing file is replaced only once the new content is complete and flushed,
    so an interruption leaves either the old file or the new one, never a mixture.
    """
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-" + os.path.basename(path) + "-", dir=directory)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data.encode("utf-8") if isinstance(data, str) else data)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
