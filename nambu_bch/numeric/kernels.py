"""Compiled kernels: the generated step loop, compiled once with numba and cached on disk.

:func:`kernel` turns a ``(system, word)`` into a :class:`Kernel`: the
:class:`~nambu_bch.numeric.codegen.StepProgram` is printed as a Python module
(:func:`~nambu_bch.numeric.codegen.python_source`), written to the cache
directory under a hash of its source, imported, and its loop functions are
compiled with ``numba.njit(cache=True)`` on first use -- so a second process
loads the machine code from disk instead of compiling again.

Cache directory: ``$NAMBU_BCH_CACHE`` if set, else ``~/.cache/nambu_bch``
(a temporary directory if neither is writable); kernels live in
``<cache>/kernels``.  Deleting it is always safe.

Backends:

* ``"numba"`` -- the generated loops compiled by numba (no fast-math, so IEEE
  operations in source order, bit-identical to the fallback);
* ``"numpy"`` -- the same generated source run by the interpreter: a scalar
  Python loop for one trajectory, numpy arrays (chunks of the batch kept in
  cache) for batches;
* ``"auto"`` -- numba unless it is missing or ``NAMBU_BCH_DISABLE_NUMBA=1``.

The parameters and the step enter only through the constants ``K`` (one
float64 array per run), so one compiled kernel serves every ``h`` and every
parameter value.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import tempfile
import time
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..errors import InvalidRunError
from ..integrators.composition import composition as make_composition
from ..integrators.step import parameter_values
from .codegen import python_source, source_hash, step_program

BACKENDS = ("auto", "numba", "numpy")
#: States per chunk of a batch: the chunk's arrays stay in L1/L2 while all steps run.
NUMBA_CHUNK = 256
NUMPY_CHUNK = 16384


_CACHE_DIRS: dict = {}


def cache_dir() -> Path:
    """The kernel cache directory (``$NAMBU_BCH_CACHE/kernels`` or ``~/.cache/nambu_bch/kernels``)."""
    root = os.environ.get("NAMBU_BCH_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "nambu_bch")
    known = _CACHE_DIRS.get(root)
    if known is not None and known.is_dir():
        return known
    _CACHE_DIRS[root] = path = _usable_dir(Path(root) / "kernels")
    return path


def _usable_dir(path: Path) -> Path:
    """``path`` created and writable, else a per-user directory under the system temp dir."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / f".probe-{os.getpid()}"
        probe.write_text("")
        probe.unlink()
    except OSError:
        path = Path(tempfile.gettempdir()) / f"nambu_bch-{os.getuid() if hasattr(os, 'getuid') else 'user'}" / "kernels"
        path.mkdir(parents=True, exist_ok=True)
    return path


def numba_available() -> bool:
    """numba importable and not disabled by ``NAMBU_BCH_DISABLE_NUMBA=1`` (read at every call)."""
    if os.environ.get("NAMBU_BCH_DISABLE_NUMBA", "").strip().lower() in ("1", "true", "yes", "on"):
        return False
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def resolve_backend(backend: str = "auto") -> str:
    """``"numba"`` or ``"numpy"`` for a requested backend name."""
    if backend not in BACKENDS:
        raise InvalidRunError(f"backend {backend!r} is not one of {', '.join(BACKENDS)}")
    if backend == "auto":
        return "numba" if numba_available() else "numpy"
    if backend == "numba" and not numba_available():
        raise InvalidRunError("backend 'numba' was requested but numba is not installed or NAMBU_BCH_DISABLE_NUMBA=1; "
                              "use backend='numpy' or 'auto'")
    return backend


def _write_once(path: Path, text: str):
    """Create ``path`` with ``text`` atomically unless it exists (keeps its mtime, which numba's cache checks)."""
    if path.exists():
        return
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".py")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    try:
        os.link(tmp, path)
    except FileExistsError:
        pass
    except OSError:  # no hard links on this file system
        if not path.exists():
            os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


class Kernel:
    """The compiled step loops of one ``(system, word)``.

    Attributes
    ----------
    program : :class:`~nambu_bch.numeric.codegen.StepProgram`
    source : str -- the generated module
    path : pathlib.Path -- where it is cached
    module : the imported module (pure-Python functions, the numpy fallback)
    compile_seconds : dict -- wall time of each numba compilation or cache load, by function name
    """

    def __init__(self, system, comp):
        self.system = system
        self.composition = comp
        self.program = step_program(system, comp)
        self.source = python_source(self.program)
        key = source_hash(self.source)
        self.path = cache_dir() / f"nambu_bch_kernel_{key}.py"
        _write_once(self.path, self.source)
        name = f"nambu_bch_kernel_{key}"
        spec = importlib.util.spec_from_file_location(name, self.path)
        module = importlib.util.module_from_spec(spec)
        sys.modules.setdefault(name, module)
        spec.loader.exec_module(module)
        self.module = module
        self._constants = {}
        self._jitted = {}
        self.compile_seconds = {}

    def __repr__(self):
        return f"Kernel({self.program.system_name!r}, {self.program.word!r}, {self.path.name})"

    # -- constants ----------------------------------------------------------------------------------
    def constants(self, h, params=None) -> np.ndarray:
        """``K = [k_0(h, params), ...]`` as float64 (computed once per run, in Python)."""
        values = parameter_values(self.system, params)
        f = self._constants.get("math")
        if f is None:
            f = self._constants["math"] = self.program.constant_function("math")
        K = [float(v) for v in f(float(h), *(values[p] for p in self.program.parameters))]
        return np.array(K, dtype=np.float64)

    # -- functions ----------------------------------------------------------------------------------
    def function(self, name: str, backend: str = "numba"):
        """The loop ``name`` (``run``, ``run_kahan``, ``run_batch``, ``run_batch_kahan``) for ``backend``."""
        if backend == "numpy":
            if name.startswith("run_batch"):
                name = name.replace("run_batch", "run_numpy")
            return getattr(self.module, name)
        fn = self._jitted.get(name)
        if fn is None:
            import numba

            fn = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")(getattr(self.module, name))
            self._jitted[name] = fn
        return fn

    def compile(self, kahan: bool = False, batch: bool = False) -> float:
        """Compile (or load from the disk cache) one loop now; the wall time in seconds."""
        name = ("run_batch" if batch else "run") + ("_kahan" if kahan else "")
        if name in self.compile_seconds:
            return self.compile_seconds[name]
        fn = self.function(name, "numba")
        N = self.program.N
        K = np.zeros(max(1, len(self.program.constants)))
        start = time.perf_counter()
        if batch:
            X = np.zeros((N, 1))
            out = np.zeros((2, N, 1))
            args = (X, np.zeros((N, 1))) if kahan else (X,)
            fn(*args, K, 1, 1, out, NUMBA_CHUNK)
        else:
            x = np.zeros(N)
            out = np.zeros((2, N))
            args = (x, np.zeros(N)) if kahan else (x,)
            fn(*args, K, 1, 1, out)
        self.compile_seconds[name] = time.perf_counter() - start
        return self.compile_seconds[name]

    # -- running ------------------------------------------------------------------------------------
    def run(self, x, K, steps, every, out, *, kahan=False, comp=None, backend="numba") -> int:
        """Advance one state ``x`` (shape (N,), float64, in place); ``out[0]`` holds the start, ``out[1:]`` is filled.

        Returns the number of steps done (less than ``steps`` only if a sample became non-finite).
        """
        name = "run_kahan" if kahan else "run"
        if backend == "numba":
            self.compile(kahan=kahan)
            fn = self.function(name)
            args = (x, comp) if kahan else (x,)
            return int(fn(*args, K, int(steps), int(every), out))
        fn = getattr(self.module, name)
        xs = [float(v) for v in x]
        cs = [float(v) for v in comp] if kahan else None
        args = (xs, cs) if kahan else (xs,)
        n = fn(*args, [float(k) for k in K], int(steps), int(every), out)
        x[:] = xs
        if kahan:
            comp[:] = cs
        return int(n)

    def run_batch(self, X, K, steps, every, out, *, kahan=False, comp=None, backend="numba", chunk=None) -> int:
        """Advance states ``X`` (shape (N, batch), float64, in place); ``out`` of shape (n, N, batch)."""
        name = "run_batch_kahan" if kahan else "run_batch"
        args = (X, comp) if kahan else (X,)
        if backend == "numba":
            self.compile(kahan=kahan, batch=True)
            return int(self.function(name)(*args, K, int(steps), int(every), out, int(chunk or NUMBA_CHUNK)))
        fn = self.function(name, "numpy")
        return int(fn(*args, [float(k) for k in K], int(steps), int(every), out, int(chunk or NUMPY_CHUNK)))


def kernel(system, word) -> Kernel:
    """The :class:`Kernel` of ``word`` on ``system`` (memoised in the process, cached on disk across processes).

    Examples
    --------
    >>> from nambu_bch import model
    >>> k = kernel(model("ho"), "121")
    >>> k.program.updates[1].increments
    ((1, k1*s0),)
    >>> [float(v) for v in k.constants(0.1)]
    [0.05, -0.1]
    """
    directory = str(cache_dir())
    if isinstance(word, str):  # resolving a word can be slow (triple jumps: exact algebraic coefficients)
        return _kernel_for_word(system, word, directory)
    comp = make_composition(word, len(system.splitting)).check(system.splitting)
    return _kernel(system, comp, directory)


@lru_cache(maxsize=64)
def _kernel_for_word(system, word, directory):
    comp = make_composition(word, len(system.splitting)).check(system.splitting)
    return _kernel(system, comp, directory)


@lru_cache(maxsize=64)
def _kernel(system, comp, directory):
    return Kernel(system, comp)
