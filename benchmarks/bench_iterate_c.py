"""Helper of bench_iterate.py: the C reference loop, generated from the same step program (built -O3 -march=native by the benchmark).

The C source comes from :func:`nambu_bch.numeric.codegen.c_source` (sympy's C99 printer on the
hoisted increments), so it performs the same floating-point operations in the same order as the
numba kernel; the benchmark checks that both give bit-identical states.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import tempfile
import time

import numpy as np

from nambu_bch.numeric.codegen import c_source

DOUBLE_P = ctypes.POINTER(ctypes.c_double)


def c_compiler():
    """Path of a C compiler (``$CC``, gcc, cc, clang) or None."""
    for name in (os.environ.get("CC"), "gcc", "cc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


class CReference:
    """The compiled C loops of one step program (``run`` and ``run_batch``)."""

    def __init__(self, program, flags=("-O2",), compiler=None):
        self.compiler = compiler or c_compiler()
        if self.compiler is None:
            raise RuntimeError("no C compiler found (set CC)")
        self.flags = tuple(flags)
        self.dir = tempfile.mkdtemp(prefix="nambu_bch_cref_")
        src = os.path.join(self.dir, "step.c")
        lib = os.path.join(self.dir, "step.so")
        with open(src, "w") as fh:
            fh.write(c_source(program))
        start = time.perf_counter()
        subprocess.run([self.compiler, *self.flags, "-std=c99", "-shared", "-fPIC", "-o", lib, src, "-lm"],
                       check=True, capture_output=True)
        self.compile_seconds = time.perf_counter() - start
        self.lib = ctypes.CDLL(lib)
        self.lib.run.argtypes = [DOUBLE_P, DOUBLE_P, ctypes.c_long]
        self.lib.run.restype = ctypes.c_long
        self.lib.run_batch.argtypes = [DOUBLE_P, DOUBLE_P, ctypes.c_long, ctypes.c_long, ctypes.c_long]
        self.lib.run_batch.restype = None

    def run(self, x, K, steps):
        """Advance ``x`` (float64, shape (N,)) in place by ``steps`` steps."""
        self.lib.run(x.ctypes.data_as(DOUBLE_P), K.ctypes.data_as(DOUBLE_P), int(steps))

    def run_batch(self, X, K, steps, chunk=256):
        """Advance ``X`` (float64, C-contiguous, shape (N, B)) in place."""
        assert X.flags.c_contiguous and X.dtype == np.float64
        self.lib.run_batch(X.ctypes.data_as(DOUBLE_P), K.ctypes.data_as(DOUBLE_P), int(steps), X.shape[1], int(chunk))

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)
