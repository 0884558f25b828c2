"""Helper of bench_iterate.py: the C reference loop, generated from the same step program.

The C source comes from :func:`nambu_bch.numeric.codegen.c_source` (sympy's C99 printer on the
hoisted increments), so it performs the same floating-point operations in the same order as the
numba kernel.  The benchmark builds it twice: gcc's default optimised build ``-O3 -march=native``
(GNU C, where gcc contracts ``a*b + c`` into fused multiply-adds: :data:`DEFAULT_FLAGS`), and the
bit-reproducible build with contraction off (:data:`EXACT_FLAGS`), which must equal the default
numba kernel bit for bit.  No ``-std=c99``: ISO C mode turns contraction off too.
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
#: gcc's default optimised build for this machine (contraction allowed: gcc's default is -ffp-contract=fast).
DEFAULT_FLAGS = ("-O3", "-march=native")
#: The same build with every operation rounded on its own, as written: the numba kernels' bits.
EXACT_FLAGS = ("-O3", "-march=native", "-ffp-contract=off")


def c_compiler():
    """Path of a C compiler (``$CC``, gcc, cc, clang) or None."""
    for name in (os.environ.get("CC"), "gcc", "cc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


class CReference:
    """The compiled C loops of one step program (``run`` and ``run_batch``)."""

    def __init__(self, program, flags=DEFAULT_FLAGS, compiler=None):
        self.compiler = compiler or c_compiler()
        if self.compiler is None:
            raise RuntimeError("no C compiler found (set CC)")
        self.flags = tuple(flags)
        self.dir = tempfile.mkdtemp(prefix="nambu_bch_cref_")
        src = os.path.join(self.dir, "step.c")
        lib = os.path.join(self.dir, "step.so")
        with open(src, "w") as fh:
            fh.write(getattr(self, "_text", None) or c_source(program))
        start = time.perf_counter()
        subprocess.run([self.compiler, *self.flags, "-shared", "-fPIC", "-o", lib, src, "-lm"],
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


def lotka_volterra_one_exp_source(factors) -> str:
    """A hand-written C loop for the cyclic Lotka-Volterra splitting with ONE ``exp`` per sub-flow.

    Piece ``k`` (``X_{x_k, G}``, ``G = x1 x2 x3``) moves the two other coordinates:
    ``x_{k+1} <- x_{k+1} / E``, ``x_{k+2} <- x_{k+2} E`` with ``E = exp(c h x_k)`` (indices
    cyclic) -- the reference "C with one exp per piece".  It multiplies by the
    exponential instead of adding ``x expm1(u)``, so it rounds differently from the generated
    kernels (the benchmark compares the states to ~1e-12, not bit for bit).
    ``factors`` are ``(piece, coefficient)``; ``K[j] = c_j h`` is passed at run time.
    """
    body = []
    for j, (k, _) in enumerate(factors):
        a, b, c = (k - 1) % 3, k % 3, (k + 1) % 3
        body.append(f"{{ const double E = exp(K[{j}] * s{a}); s{b} = s{b} / E; s{c} = s{c} * E; }}")
    return f"""#include <math.h>
long run(double *restrict x, const double *restrict K, long steps) {{
    double s0 = x[0], s1 = x[1], s2 = x[2];
    for (long n = 0; n < steps; ++n) {{
        {chr(10).join('        ' + line for line in body).strip()}
    }}
    x[0] = s0; x[1] = s1; x[2] = s2;
    return steps;
}}
void run_batch(double *restrict X, const double *restrict K, long steps, long B, long chunk) {{ }}
"""


class CSource(CReference):
    """A C translation unit given as text (same ``run`` signature as :class:`CReference`)."""

    def __init__(self, source, flags=DEFAULT_FLAGS, compiler=None):
        class _Program:  # CReference prints c_source(program); give it the text instead
            pass

        self._text = source
        super().__init__(_Program(), flags, compiler)
