"""A kernel's single-trajectory loop as a C shared library: compiled runs of a fresh process without numba.

Importing numba costs about half a second of CPU and loading a cached kernel through it about as much
again (docs/numerics.md, "The first compiled run of a process"), which a short-lived process pays for
its first compiled run even when the machine code is cached.  So when a kernel's ``run`` loop is
compiled by numba, and a C compiler is on the ``PATH``, the same loop is also built as a shared library
(:func:`~nambu_bch.numeric.codegen.c_run_source`: the same statements, built with
``-ffp-contract=off``, so the samples are numba's bits) and cached next to the kernel's source.
``iterate(backend="auto")`` runs one trajectory (float64, no Kahan summation, no ``fma``) through it
whenever it is cached and verifies -- in a later process, numba is then not imported at all.
``NAMBU_BCH_DISABLE_CLIB=1`` turns both the build and the use off.

What is cached, and how it is trusted (the rules of :mod:`~nambu_bch.numeric.kernels`):

* ``nambu_bch_clib_<key>.so`` -- the library, ``key`` the kernel's :func:`~nambu_bch.numeric.kernels.input_key`
  (the digest of the exact inputs and of the generator's code), written atomically (mode 0600);
* ``nambu_bch_clib_<key>.json`` -- the SHA-256 of the library's bytes and of the C source it was built from.

Loading reads the library through :func:`nambu_bch.private_dirs.read_private` (a private regular file
of the private cache directory, size bounded), checks its SHA-256 against the record, and hands
``dlopen`` exactly the verified bytes: they are copied into an anonymous memory file
(``os.memfd_create``) that is opened as ``/proc/self/fd/N``, so nothing can be substituted between the
check and the load.  Anything that fails -- no record, a mismatch, no ``memfd_create`` (not Linux), a
library that does not load -- leaves the run to numba, as before.  The C source, like every generated
source, holds no user text (state ``s_i``, constants ``k_j`` and numeric literals).
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import shutil
import subprocess
import tempfile

from ..atomic import write_atomic
from ..private_dirs import read_private
from .codegen import TEMPLATE_VERSION, c_run_source

#: Compilers tried, in order (found on the ``PATH``; a library is built only when one is present).
COMPILERS = ("cc", "gcc", "clang")
#: Build flags: no contraction of ``a*b + c`` (numba's default bits), no machine-specific instructions (a
#: cache directory shared by machines of different CPUs must not hold a library one of them cannot run).
FLAGS = ("-O2", "-ffp-contract=off", "-fno-fast-math", "-shared", "-fPIC")
#: Largest library read back (a loop is a few kB of machine code).
MAX_LIBRARY = 4 * 2**20
#: Seconds a build may take before it is abandoned (the run then stays on numba).
BUILD_TIMEOUT = 60
_DOUBLE_P = ctypes.POINTER(ctypes.c_double)
#: The memory files of the libraries loaded in this process (one per kernel; never closed, see :func:`load`).
_OPEN: list = []


def disabled() -> bool:
    """``NAMBU_BCH_DISABLE_CLIB=1``: no library is built or loaded (runs stay on numba), read at every call."""
    return os.environ.get("NAMBU_BCH_DISABLE_CLIB", "").strip().lower() in ("1", "true", "yes", "on")


def compiler():
    """The path of the first of :data:`COMPILERS` on the ``PATH``, or None (also when :func:`disabled`)."""
    if disabled():
        return None
    for name in COMPILERS:
        path = shutil.which(name)
        if path:
            return path
    return None


def paths(kern) -> tuple:
    """``(library, record)``: where the kernel's library and its record live in the kernel cache."""
    stem = kern.directory / f"nambu_bch_clib_{kern.key}"
    return stem.with_suffix(".so"), stem.with_suffix(".json")


def build(kern) -> bool:
    """Build the kernel's library from its step program and cache it with its record; whether it was built.

    The C source comes from the kernel's validated :class:`~nambu_bch.numeric.codegen.StepProgram`
    (exact data; :func:`~nambu_bch.numeric.codegen.c_run_source`), the compiler runs without a shell on
    files of a private temporary directory inside the kernel cache.
    """
    cc = compiler()
    if cc is None:
        return False
    source = c_run_source(kern.program).encode("ascii")
    library, record = paths(kern)
    try:
        with tempfile.TemporaryDirectory(prefix="nambu_bch_clib_", dir=kern.directory) as tmp:
            src, out = os.path.join(tmp, "run.c"), os.path.join(tmp, "run.so")
            with open(src, "wb") as fh:
                fh.write(source)
            done = subprocess.run([cc, *FLAGS, "-o", out, src, "-lm"], capture_output=True, timeout=BUILD_TIMEOUT,
                                  check=False)
            if done.returncode != 0:
                return False
            with open(out, "rb") as fh:
                data = fh.read(MAX_LIBRARY + 1)
        if len(data) > MAX_LIBRARY:
            return False
        meta = {"template": TEMPLATE_VERSION, "sha256": hashlib.sha256(data).hexdigest(),
                "source_sha256": hashlib.sha256(source).hexdigest()}
        write_atomic(library, data, mode=0o600)
        write_atomic(record, json.dumps(meta, sort_keys=True).encode("utf-8"), mode=0o600)
    except (OSError, subprocess.SubprocessError):
        return False
    return True


def load(kern):
    """The cached library's ``run`` as a ctypes function, or None (absent, not verified, or not loadable)."""
    if disabled():
        return None
    library, record = paths(kern)
    try:
        meta = json.loads(read_private(record, 4096).decode("utf-8"))
        if not isinstance(meta, dict) or meta.get("template") != TEMPLATE_VERSION:
            return None
        data = read_private(library, MAX_LIBRARY)
        if not isinstance(meta.get("sha256"), str) or hashlib.sha256(data).hexdigest() != meta["sha256"]:
            return None
        fd = os.memfd_create("nambu_bch_clib", getattr(os, "MFD_CLOEXEC", 0))
    except (OSError, ValueError, AttributeError):  # absent, corrupt, modified, or no memfd_create
        return None
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        lib = ctypes.CDLL(f"/proc/self/fd/{fd}")
    except OSError:
        os.close(fd)
        return None
    # the descriptor stays open with the library: dlopen knows a library by its path, and a path
    # /proc/self/fd/N reused after a close would hand back the library loaded first under it
    _OPEN.append(fd)
    fn = lib.run
    fn.argtypes = [_DOUBLE_P, _DOUBLE_P, ctypes.c_long, ctypes.c_long, _DOUBLE_P]
    fn.restype = ctypes.c_long
    fn.library = lib  # keeps the library loaded as long as the function is used
    return fn


def run(fn, x, K, steps, every, out) -> int:
    """Call a loaded library's ``run``: ``x`` (N,) and ``K`` float64, ``out`` (n, N) C-contiguous float64."""
    return int(fn(x.ctypes.data_as(_DOUBLE_P), K.ctypes.data_as(_DOUBLE_P), int(steps), int(every),
                  out.ctypes.data_as(_DOUBLE_P)))
