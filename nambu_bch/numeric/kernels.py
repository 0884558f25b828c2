"""Compiled kernels: the generated step loop, compiled once with numba and cached on disk.

:func:`kernel` turns a ``(system, word)`` into a :class:`Kernel`: the
:class:`~nambu_bch.numeric.codegen.StepProgram` is printed as a Python module
(:func:`~nambu_bch.numeric.codegen.python_source`), written to the cache
directory under a hash of its source, imported, and its loop functions are
compiled with numba on first use, their machine code kept in the same private
cache (:func:`nambu_bch.compiled.enable_private_cache`) -- so a second process
loads the machine code from disk instead of compiling again.

Cache directory: ``$NAMBU_BCH_CACHE`` if set, else ``~/.cache/nambu_bch``;
kernels live in ``<cache>/kernels``.  Deleting it is always safe.

What is cached, and how it is trusted (docs/hardening.md):

* ``nambu_bch_index_<key>.json`` -- ``key`` is :func:`input_key`, a digest of the
  exact inputs (fields of the pieces, exact coefficients, the generator's own code);
  the index records the module name, the SHA-256 of its source and the small
  metadata a run needs (number of constants, the linear coordinates of the
  stability check), so a cached kernel runs without sympy;
* ``nambu_bch_kernel_<hash>.py`` -- the generated source; before it is executed
  its bytes are checked against the recorded SHA-256 (a modified, truncated or
  garbage file is regenerated), and the verified bytes themselves are compiled,
  so the file is never read twice;
* ``__pycache__/*.nbi, *.nbc`` -- numba's machine code, kept here whatever
  ``$NUMBA_CACHE_DIR`` says, each file carrying a SHA-256 of its content that is
  checked before numba unpickles it (:func:`nambu_bch.compiled.enable_private_cache`);
  an entry that fails the check, or that numba cannot load, is compiled again;
* ``nambu_bch_clib_<key>.so`` / ``.json`` -- the single-trajectory loop as a C shared library and its record,
  built when numba compiles a freshly generated ``run`` and a C compiler is present, verified before it is
  loaded (:mod:`~nambu_bch.numeric.clib`).

Every cache file is read through :func:`nambu_bch.private_dirs.read_private` (a
private regular file: never a symlink, FIFO or device, size bounded) and written
through :func:`nambu_bch.atomic.write_atomic`.

Every directory of the cache must be a real directory owned by the effective
user and not writable by group or others (:func:`cache_dir`), otherwise a
private fallback is used, so another local user cannot plant a kernel.  The
generated source contains no user text at all (:mod:`~nambu_bch.numeric.codegen`).

Backends:

* ``"numba"`` -- the generated loops compiled by numba (no fast-math, so IEEE
  operations in source order, bit-identical to the fallback); with ``fma=True`` a
  second compiled copy of each loop may fuse ``a*b + c`` (:data:`CONTRACT`, its
  machine code cached apart: :func:`nambu_bch.compiled.cache_variant`);
* ``"numpy"`` -- the same generated source run by the interpreter: a scalar
  Python loop for one trajectory, numpy arrays (chunks of the batch kept in
  cache) for batches;
* ``"auto"`` -- numba unless it is missing or ``NAMBU_BCH_DISABLE_NUMBA=1``.

The parameters and the step enter only through the constants ``K`` (one
float64 array per run), so one compiled kernel serves every ``h`` and every
parameter value.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import sys
import time
import types
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..compiled import cache_variant, dispatcher, enable_private_cache, fused_multiply_add
from ..compiled import numba_available  # noqa: F401  (re-exported: nambu_bch.numeric.numba_available)
from ..errors import InvalidRunError, NumericalRangeError
from ..atomic import write_atomic
from ..private_dirs import cache_root, private_directory, read_private, untrusted
from ..integrators.composition import composition_for
from ..integrators.step import parameter_values
from .codegen import (COPY_FUNCTION, FMA_FUNCTION, PAIR_FUNCTION, SCAN_FUNCTION, SELECT_FUNCTION, TEMPLATE_VERSION,
                      python_source, source_hash, step_program)

from .guards import BACKENDS, linear_part  # the accepted names live with the other checks of a run's inputs
#: numba's fast-math flags of a run with ``fma=True``: contraction of ``a*b + c`` into one fused
#: multiply-add only -- no reassociation, no finite-math or signed-zero assumptions.
CONTRACT = frozenset({"contract"})
#: States per chunk of a batch: the chunk's arrays stay in L1/L2 while all steps run.
NUMBA_CHUNK = 256
NUMPY_CHUNK = 16384


_CACHE_DIRS: dict = {}
#: Why the cache is not where it was asked to be (empty when it is): ``{requested root: reason}``.
CACHE_NOTES: dict = {}


def cache_dir() -> Path:
    """The kernel cache directory (``$NAMBU_BCH_CACHE/kernels`` or ``~/.cache/nambu_bch/kernels``).

    Every directory of the cache (the root, ``kernels``, numba's ``kernels/__pycache__``) must be a
    real directory (not a symlink) owned by the effective user and not writable by group or
    others, with no directory above it that another user can change
    (:func:`nambu_bch.private_dirs.untrusted`); one that is not is refused and a private fallback is
    used instead: the per-user ``$TMPDIR/nambu_bch-<uid>`` if it passes the same checks, else a fresh
    ``mkdtemp`` directory (mode 0700).  The reason is kept in :data:`CACHE_NOTES`.
    """
    root = str(cache_root())
    known = _CACHE_DIRS.get(root)
    if known is not None and untrusted(known) is None:
        return known
    _CACHE_DIRS[root] = path = _usable_dir()
    return path


def _usable_dir() -> Path:
    """``<cache root>/kernels`` (with ``kernels/__pycache__``) if private, else the per-user temp dir if private,
    else a fresh private temp dir (:func:`nambu_bch.private_dirs.private_directory`); the reason in :data:`CACHE_NOTES`."""
    try:
        return private_directory("kernels", "__pycache__", notes=CACHE_NOTES).parent
    except OSError as exc:  # pragma: no cover - a fresh mkdtemp directory is always ours
        raise InvalidRunError(f"no safe kernel cache directory: {exc}") from None


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


#: Largest cache file read back (a kernel module is a few kB; anything bigger is not ours).
MAX_CACHE_FILE = 4 * 2**20
_MODULE_NAME = re.compile(r"nambu_bch_kernel_[0-9a-f]{20}")
_INDEX_FIELDS = {"template": str, "module": str, "sha256": str, "N": int, "n_constants": int,
                 "n_parameters": int, "linear": list}
_FUNCTIONS = ("constants", "run", "run_fma", "run_kahan", "run_batch", "run_batch_kahan", "run_numpy",
              "run_numpy_kahan")


def input_key(system, comp) -> str:
    """The digest of everything a kernel is generated from (exact inputs, not names).

    The coordinates, parameters, each piece's vector field and moving coordinates (``srepr``),
    the composition's pieces and exact coefficients, the template version and a digest of the
    generator's own code (:func:`_generator_digest`).  Equal keys
    mean equal generated source, so a cached source can be used without sympy.
    """
    import sympy

    parts = [TEMPLATE_VERSION, _generator_digest(), sympy.srepr(tuple(system.coordinates)),
             sympy.srepr(tuple(system.parameters))]
    for piece in system.splitting:
        parts.append(sympy.srepr(tuple(piece.field.to_sympy())) + repr(tuple(piece.moving)))
    parts.append(repr([(int(k), sympy.srepr(c)) for k, c in comp.factors()]))
    return hashlib.sha256("\x1f".join(parts).encode()).hexdigest()[:32]


@lru_cache(maxsize=1)
def _generator_digest() -> str:
    """A digest of the code that turns exact inputs into source (codegen and the exact flows), so an
    upgraded package never reuses a source generated by an older one."""
    from ..integrators import flows
    from ..systems import piece_flows
    from . import codegen

    h = hashlib.sha256()
    for module in (codegen, flows, piece_flows):
        try:
            h.update(Path(module.__file__).read_bytes())
        except OSError:  # no source on disk (frozen): the template version alone
            h.update(TEMPLATE_VERSION.encode())
    return h.hexdigest()[:16]


def _read_small(path: Path) -> bytes:
    """The bytes of a private regular file (no symlink, FIFO or device), at most :data:`MAX_CACHE_FILE`; OSError otherwise."""
    return read_private(path, MAX_CACHE_FILE)


def _write_file(path: Path, data: bytes):
    """Make ``path`` hold ``data``: kept untouched if it already does (numba's cache checks its mtime),
    else replaced atomically (:func:`nambu_bch.atomic.write_atomic`, mode 0600)."""
    try:
        if _read_small(path) == data:
            return
    except OSError:
        pass
    write_atomic(path, data, mode=0o600)


def _load_module(name: str, path: Path, source: str, functions=_FUNCTIONS):
    """Execute ``source`` (generated by :mod:`~nambu_bch.numeric.codegen` from validated exact data, or read back
    and verified) as module ``name`` whose functions report ``path`` as their file; it must define ``functions``."""
    module = types.ModuleType(name)
    module.__file__ = str(path)
    exec(compile(source, str(path), "exec"), module.__dict__)  # noqa: S102 - our own generated, digest-checked source
    missing = [f for f in functions if not callable(module.__dict__.get(f))]
    if missing:
        raise ValueError(f"generated module lacks {missing}")
    sys.modules[name] = module
    return module


class Kernel:
    """The compiled step loops of one ``(system, word)``.

    Attributes
    ----------
    program : :class:`~nambu_bch.numeric.codegen.StepProgram`
    source : str -- the generated module
    path : pathlib.Path -- where it is cached
    module : the imported module (pure-Python functions, the numpy fallback)
    compile_seconds : dict -- wall time of each numba compilation or cache load, by function name
    interpreted : dict -- steps run on the interpreter because compiling would have cost more
        (:func:`~nambu_bch.numeric.iterate.iterate` with ``backend="auto"``), by function name
    """

    #: The template version an index records (checked when the module is read back) and the functions the
    #: module must define; a subclass generating other loops into this same verified cache sets its own
    #: (:class:`nambu_bch.numeric.complex_codegen.ComplexKernel`) and its :meth:`_render`.
    template = TEMPLATE_VERSION
    functions = _FUNCTIONS
    #: Whether the ``run`` loop also gets a C library (:mod:`~nambu_bch.numeric.clib`, printed from the real step
    #: program); a subclass with other loops sets it False.
    c_library = True

    def __init__(self, system, comp):
        self.system = system
        self.composition = comp
        self.word = str(comp)
        self.N = system.N
        self.key = input_key(system, comp)
        self.directory = cache_dir()
        self.index_path = self.directory / f"nambu_bch_index_{self.key}.json"
        self.from_cache = self._load_cached()
        if not self.from_cache:
            self._generate()
        self._jitted = {}
        self.compile_seconds = {}
        self.interpreted = {}
        #: the constants ``K`` (bytes) whose step passed :func:`~nambu_bch.numeric.guards.check_stability`
        self.stable_constants = set()
        self._library = None  # the C library's run (numeric.clib): None not tried yet, False absent

    def _load_cached(self) -> bool:
        """Use the cached source if its index is intact and the file matches the recorded digest."""
        try:
            meta = json.loads(_read_small(self.index_path).decode("utf-8"))
            if not isinstance(meta, dict) or any(not isinstance(meta.get(k), t) for k, t in _INDEX_FIELDS.items()):
                return False
            if meta["template"] != self.template or not _MODULE_NAME.fullmatch(meta["module"]):
                return False
            if meta["N"] != self.N or meta["n_parameters"] != len(self.system.parameters):
                return False
            path = self.directory / f"{meta['module']}.py"
            data = _read_small(path)
            if hashlib.sha256(data).hexdigest() != meta["sha256"]:
                return False
            source = data.decode("utf-8")
            if f"nambu_bch_kernel_{source_hash(source)}" != meta["module"]:
                return False
            linear = tuple(int(i) for i in meta["linear"] if isinstance(i, int) and 0 <= i < self.N)
            module = _load_module(meta["module"], path, source, self.functions)
        except (OSError, ValueError, SyntaxError, UnicodeDecodeError):  # absent, corrupt or modified: regenerate
            return False
        self.source, self.path, self.module = source, path, module
        self.n_constants, self.linear = meta["n_constants"], linear
        return True

    def _generate(self):
        """Generate the source from the exact sub-flows (sympy), write it and its index, load it."""
        self.source, self.n_constants, self.linear = self._render(self.program)
        name = f"nambu_bch_kernel_{source_hash(self.source)}"
        self.path = self.directory / f"{name}.py"
        data = self.source.encode("utf-8")
        meta = {"template": self.template, "module": name, "sha256": hashlib.sha256(data).hexdigest(),
                "N": self.N, "n_constants": self.n_constants, "n_parameters": len(self.system.parameters),
                "linear": list(self.linear)}
        try:
            _write_file(self.path, data)
            _write_file(self.index_path, json.dumps(meta, sort_keys=True).encode("utf-8"))
        except OSError:  # a read-only cache still runs: the module below comes from memory, not the file
            pass
        self.module = _load_module(name, self.path, self.source, self.functions)

    @staticmethod
    def _render(program) -> tuple:
        """``(source, number of constants, coordinates of the stability check)`` of a program."""
        return python_source(program), len(program.constants), tuple(linear_part(program))

    @property
    def program(self):
        """The :class:`~nambu_bch.numeric.codegen.StepProgram` (derived with sympy on first access)."""
        return step_program(self.system, self.composition)

    def __repr__(self):
        return f"Kernel({self.system.name!r}, {self.word!r}, {self.path.name})"

    # -- constants ----------------------------------------------------------------------------------
    def constants(self, h, params=None) -> np.ndarray:
        """``K = [k_0(h, params), ...]`` as float64 (computed once per run, in Python, by the generated
        ``constants``); a coefficient that is not a finite float64 raises :class:`NumericalRangeError`."""
        values = parameter_values(self.system, params)
        P = [values[p] for p in self.system.parameters]

        def where():  # the run named in a message (formatting the parameters costs more than the constants)
            given = ", ".join(f"{p} = {v:g}" for p, v in values.items())
            return f"h = {float(h):g}" + (f" with {given}" if given else "")

        try:
            K = np.array([float(v) for v in self.module.constants(float(h), P)], dtype=np.float64)
        except ZeroDivisionError:
            raise NumericalRangeError(f"{where()}: a coefficient of the step divides by zero; "
                                      "give non-zero values to the parameters in denominators") from None
        except (OverflowError, ValueError) as exc:
            raise NumericalRangeError(f"{where()}: a coefficient of the step is out of the float64 range ({exc}); "
                                      "rescale the parameters or the step") from None
        if not np.all(np.isfinite(K)):
            raise NumericalRangeError(f"{where()}: a coefficient of the step overflows float64; "
                                      "rescale the parameters or the step")
        return K

    # -- functions ----------------------------------------------------------------------------------
    @staticmethod
    def loop_name(kahan=False, batch=False, fma=False) -> str:
        """The name a compiled loop is known by: ``run``, ``run_batch_kahan``, ``run+contract``, ..."""
        name = ("run_batch" if batch else "run") + ("_kahan" if kahan else "")
        return name + cache_variant(CONTRACT if fma else None)

    def function(self, name: str, backend: str = "numba"):
        """The loop ``name`` (``run``, ``run_kahan``, ``run_batch``, ``run_batch_kahan``, each optionally with the
        suffix ``+contract`` of :meth:`loop_name`: compiled with :data:`CONTRACT`; ``run+contract`` is the generated
        ``run_fma``, whose fused multiply-adds are written out) for ``backend``."""
        name, plus, _ = name.partition("+")
        fma = bool(plus)
        if backend == "numpy":  # the interpreter never contracts
            if name.startswith("run_batch"):
                name = name.replace("run_batch", "run_numpy")
            return getattr(self.module, name)
        key = name + cache_variant(CONTRACT if fma else None)
        fn = self._jitted.get(key)
        if fn is None:
            import numba

            flagged = {}  # the helpers compiled with the loop's own flags (codegen.SELECT_FUNCTION)
            if name.startswith("run") and hasattr(self.module, PAIR_FUNCTION):
                # the loops call the shared-exponential functions: compiled, they are globals of theirs.  The
                # batch loops' redo calls the uncontracted pair function whatever the loop's flags; their
                # branch-free pass, and the single loops, call a copy compiled with the loop's flags (the
                # statements a contracted loop used to hold inline were contracted too)
                self.module.__dict__[PAIR_FUNCTION] = self.function(PAIR_FUNCTION)
                variant = cache_variant(CONTRACT if fma else None)
                if name.startswith("run_batch"):
                    self.module.__dict__[COPY_FUNCTION] = self.function(COPY_FUNCTION)
                    flagged[SELECT_FUNCTION] = self.function(SELECT_FUNCTION + variant)
                elif fma:
                    flagged[PAIR_FUNCTION] = self.function(PAIR_FUNCTION + variant)
            if name.startswith("run_batch"):  # the guards' scan they extend as they load the states
                from .scan import scan_into

                self.module.__dict__[SCAN_FUNCTION] = dispatcher(scan_into)  # numba types a dispatcher global
            source = name
            if fma and name == "run":  # one trajectory: the fused multiply-adds written out (codegen.fused_product)
                source = "run_fma"
                self.module.__dict__[FMA_FUNCTION] = fused_multiply_add()
            py = getattr(self.module, source)
            py = getattr(py, "py_func", py)  # the compiled pair function stands in the module once bound
            if flagged and fma:  # its own globals: the module (and the interpreter) keep the uncontracted helpers
                py = types.FunctionType(py.__code__, {**self.module.__dict__, **flagged}, py.__name__,
                                        py.__defaults__, py.__closure__)
            else:
                self.module.__dict__.update(flagged)
            fn = numba.njit(nogil=True, fastmath=set(CONTRACT) if fma else False, error_model="numpy")(py)
            if self.path.is_file():  # numba caches next to a source file; without one, compile in memory
                enable_private_cache(fn, self.directory / "__pycache__", name)
            self._jitted[key] = fn
        return fn

    def ready(self, name: str) -> bool:
        """Whether the compiled loop ``name`` starts at no real cost: compiled or loaded in this process, or
        numba already imported and the loop's machine code in numba's cache next to the module
        (``__pycache__/<module>.<name>-<line>.py<ver>.nbi``; loading it takes milliseconds, compiling it
        0.1-4 s).  Only a hint for the backend choice: a stale index just costs a compile."""
        if name in self.compile_seconds:
            return True
        if "numba" not in sys.modules:
            return False
        try:
            return any((self.path.parent / "__pycache__").glob(f"{self.path.stem}.{name}-*.nbi"))
        except OSError:
            return False

    @property
    def numpy_matches_compiled(self) -> bool:
        """Whether the numpy batch loop gives the compiled loop's bits for every input: it calls no numpy
        function but ``isfinite`` and ``sqrt`` (correctly rounded).  numpy's own ``exp``, ``expm1``,
        ``log``, ``sinh``, ... differ from the C library's (which the compiled and the interpreted
        single-state loops call) in the last bit for some arguments."""
        body = self.source.partition("\ndef run_numpy(")[2]
        return not (set(re.findall(r"\b_np_(\w+)\(", body)) - {"isfinite", "sqrt"})

    def scan(self, X, workers=1):
        """One compiled pass over a batch ``X`` (N, B): ``(non-finite count, subnormal count, columns)``.

        ``columns`` are the extreme states of :func:`~nambu_bch.numeric.guards.extreme_states`
        (largest / smallest max-norm and product of magnitudes, smallest non-zero component).
        The pass does not depend on the system: :func:`nambu_bch.numeric.scan.scan_range`, compiled once
        for all kernels.  ``workers``: threads, each scanning the column range it will advance
        (:func:`column_ranges`); their results combine into the one-pass result exactly
        (:func:`nambu_bch.numeric.scan.combine`).
        """
        from .scan import RESULT_SIZE, combine, scan_range

        def part(lo, hi):
            res = np.zeros(RESULT_SIZE, dtype=np.int64)
            scan_range(X, lo, hi, res)
            return res

        return _scan_triple(combine(_on_threads(part, column_ranges(X.shape[1], NUMBA_CHUNK, workers))), X.shape[1])

    def compile(self, kahan: bool = False, batch: bool = False, fma: bool = False) -> float:
        """Compile (or load from the disk cache) one loop now; the wall time in seconds."""
        name = self.loop_name(kahan, batch, fma)
        if name in self.compile_seconds:
            return self.compile_seconds[name]
        fn = self.function(name, "numba")
        start = time.perf_counter()
        try:
            self._first_call(fn, kahan, batch)
        except Exception:  # noqa: BLE001 - a corrupt or truncated numba cache entry (.nbi/.nbc): regenerate it
            self._purge_numba_cache(fn)
            self._jitted.pop(name, None)
            fn = self.function(name, "numba")
            start = time.perf_counter()
            self._first_call(fn, kahan, batch)
        self.compile_seconds[name] = time.perf_counter() - start
        if name == "run" and self.c_library and not self.from_cache and self.library() is None:
            # the step program is at hand (generated in this process): build the C library that later processes
            # run without importing numba (numeric.clib)
            from . import clib

            if clib.build(self):
                self._library = None
        return self.compile_seconds[name]

    def library(self):
        """The ``run`` loop of the kernel's cached C library (:mod:`~nambu_bch.numeric.clib`), verified and loaded
        once per process, or None."""
        if self._library is None and not self.c_library:
            self._library = False
        if self._library is None:
            from . import clib

            fn = clib.load(self)
            self._library = fn if fn is not None else False
        return self._library or None

    def _first_call(self, fn, kahan, batch):
        N = self.N
        K = np.zeros(max(1, self.n_constants))
        if batch:
            X = np.zeros((N, 1))
            out = np.zeros((2, N, 1))
            args = (X, np.zeros((N, 1))) if kahan else (X,)
            fn(*args, K, 1, 1, out, NUMBA_CHUNK, 1, 1, 0, 1, _NO_SCAN)
        else:
            x = np.zeros(N)
            out = np.zeros((2, N))
            args = (x, np.zeros(N)) if kahan else (x,)
            fn(*args, K, 1, 1, out)

    def _purge_numba_cache(self, fn):
        """Delete numba's cache files of this kernel module (``<module>.*.nbi`` / ``.nbc``)."""
        where = getattr(getattr(fn, "_cache", None), "_cache_path", None) or str(self.directory / "__pycache__")
        stem = self.path.stem + "."
        try:
            names = os.listdir(where)
        except OSError:
            return
        for entry in names:
            if entry.startswith(stem) and entry.endswith((".nbi", ".nbc")):
                try:
                    os.unlink(os.path.join(where, entry))
                except OSError:
                    pass

    # -- running ------------------------------------------------------------------------------------
    def run(self, x, K, steps, every, out, *, kahan=False, comp=None, backend="numba", fma=False) -> int:
        """Advance one state ``x`` (shape (N,), float64, in place); ``out[0]`` holds the start, ``out[1:]`` is filled.

        ``fma``: the compiled loop may contract ``a*b + c`` (:data:`CONTRACT`); the interpreter ignores it.
        Returns the number of steps done (less than ``steps`` only if a sample became non-finite).
        """
        name = "run_kahan" if kahan else "run"
        if backend == "c":  # the cached C library (iterate's backend="auto" chooses it only when it loaded)
            from .clib import run

            return run(self.library(), x, K, steps, every, out)
        if backend == "numba":
            self.compile(kahan=kahan, fma=fma)
            fn = self.function(self.loop_name(kahan, False, fma))
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

    def run_batch(self, X, K, steps, every, out, *, kahan=False, comp=None, backend="numba", chunk=None,
                  start=False, back=True, fma=False, workers=1, scanned=None) -> int:
        """Advance states ``X`` (shape (N, batch), float64); ``out`` of shape (n, N, batch), ``out[1:]`` is filled.

        ``start``: also copy ``X`` into ``out[0]`` (fused with the pass that loads the states);
        ``back``: write the final states into ``X`` (in place); with ``back=False`` ``X`` is only
        read (the caller's array can be passed as it is) and the final states are ``out[-1]``.
        ``fma`` as in :meth:`run`.  ``workers``: threads running the compiled loop on disjoint column
        ranges (:func:`column_ranges`; the loop releases the GIL, every state is advanced by the same
        operations, so the bits do not depend on it).  ``scanned``: a dict (compiled loop only) that receives,
        under ``"result"``, the guards' scan of ``X`` (:meth:`scan`'s triple) taken as each chunk is loaded, so
        ``X`` is read from memory once; the loop stops before any step at a non-finite or subnormal state of
        ``X`` and -1 is returned (``"result"`` then holds that scan so far).  Returns 0 when every sample written
        is finite, a positive number otherwise.
        """
        name = "run_batch_kahan" if kahan else "run_batch"
        args = (X, comp) if kahan else (X,)
        flags = (int(bool(start)), int(bool(back)))
        B = X.shape[1]
        if backend != "numba":
            fn = self.function(name, "numpy")
            return int(fn(*args, [float(k) for k in K], int(steps), int(every), out, int(chunk or NUMPY_CHUNK),
                          *flags, 0, B))
        self.compile(kahan=kahan, batch=True, fma=fma)
        fn = self.function(self.loop_name(kahan, True, fma))
        chunk = int(chunk or NUMBA_CHUNK)
        ranges = column_ranges(B, chunk, workers)
        def call(lo, hi, res=_NO_SCAN):
            return int(fn(*args, K, int(steps), int(every), out, chunk, *flags, lo, hi, res))

        if scanned is None:
            return sum(_on_threads(call, ranges))
        from .scan import START, combine

        parts = [np.array(START, dtype=np.int64) for _ in ranges]
        bad = _on_threads(call, [(lo, hi, res) for (lo, hi), res in zip(ranges, parts)])
        scanned["result"] = _scan_triple(combine(parts), B)
        return -1 if min(bad) < 0 else sum(bad)


#: The ``res`` argument of a batch loop that does not scan its start states.
_NO_SCAN = np.zeros(0, dtype=np.int64)


def _scan_triple(res, B: int) -> tuple:
    """``(non-finite count, subnormal count, columns)`` of a combined scan result of ``B`` states (the first and
    last state among the columns)."""
    return int(res[0]), int(res[1]), np.unique(np.concatenate([res[2:7], [0, B - 1]]))


def _on_threads(call, ranges) -> list:
    """``[call(lo, hi) for lo, hi in ranges]``, the first range on the calling thread and each other one on a
    thread of its own (``call`` must release the GIL to gain: the compiled loops do, ``nogil=True``).

    The calling thread works instead of waiting, so ``w`` ranges start ``w - 1`` threads.
    """
    if len(ranges) <= 1:
        return [call(*r) for r in ranges]
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(len(ranges) - 1) as pool:
        rest = [pool.submit(call, *r) for r in ranges[1:]]
        first = call(*ranges[0])
        return [first] + [f.result() for f in rest]


def column_ranges(batch: int, chunk: int, workers: int) -> list:
    """``workers`` contiguous ranges ``(lo, hi)`` covering ``range(batch)``, split at multiples of ``chunk``
    (fewer when there are fewer chunks than workers).

    >>> column_ranges(10, 4, 2), column_ranges(10, 4, 8), column_ranges(3, 4, 2)
    ([(0, 4), (4, 10)], [(0, 4), (4, 8), (8, 10)], [(0, 3)])
    """
    chunks = -(-batch // chunk)
    workers = max(1, min(workers, chunks))
    cuts = [min(batch, (chunks * w // workers) * chunk) for w in range(workers + 1)]
    return [(lo, hi) for lo, hi in zip(cuts, cuts[1:]) if hi > lo]


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
    from ..systems.spec import as_system

    system = as_system(system)  # before the memo hashes it
    directory = str(cache_dir())
    if isinstance(word, str):  # resolving a word can be slow (triple jumps: exact algebraic coefficients)
        return _kernel_for_word(system, word, directory)
    comp = composition_for(word, system)
    return _kernel(system, comp, directory)


@lru_cache(maxsize=64)
def _kernel_for_word(system, word, directory):
    comp = composition_for(word, system)
    return _kernel(system, comp, directory)


@lru_cache(maxsize=64)
def _kernel(system, comp, directory):
    if comp.is_complex:  # the generated loops are float64: complex coefficients run on their own complex128 path
        raise InvalidRunError(
            f"composition {comp.name[:60]!r} has complex coefficients; the compiled float64 kernels take real ones: "
            "iterate and check run it in complex128 (nambu_bch.numeric.iterate_complex)")
    return Kernel(system, comp)
