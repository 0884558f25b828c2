"""Whether compiled (numba) code may be used, and where its machine code may be cached: one place for both.

numba is optional at run time: ``NAMBU_BCH_DISABLE_NUMBA=1`` (or numba missing) sends the numeric
kernels to their numpy fallback and the formal BCH series to the pure-Python dense engine; both
paths are tested.  Every compiled function of the package is made by :func:`njit` (or given
:func:`enable_private_cache`), never by ``numba.njit(cache=True)``: numba's own cache would read
pickles from directories the package does not check.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import threading


def numba_available() -> bool:
    """numba installed and not disabled by ``NAMBU_BCH_DISABLE_NUMBA=1`` (read at every call; numba is
    located, not imported: importing it costs ~0.3 s, paid only when compiled code first runs)."""
    if os.environ.get("NAMBU_BCH_DISABLE_NUMBA", "").strip().lower() in ("1", "true", "yes", "on"):
        return False
    if "numba" in sys.modules:
        return True
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False


#: Largest numba cache file read back (an index or one compiled overload; the package's are below 1 MB).
MAX_NUMBA_FILE = 32 * 2**20
#: First bytes of every numba cache file the package writes; a SHA-256 of the rest follows them.
_MAGIC = b"nambu_bch numba cache 1\n"
#: ``{(cache root, directory name): private directory or None}`` of :func:`numba_cache_directory`.
_NUMBA_DIRS: dict = {}


def njit(**options):
    """``numba.njit(**options)`` whose machine code is kept only in the package's private cache, verified on reading,
    made on first use (:class:`LazyDispatcher`).

    Use it instead of ``numba.njit(cache=True)``: numba's own cache goes to ``$NUMBA_CACHE_DIR``, the
    source tree's ``__pycache__`` or ``~/.cache/numba`` -- directories the package does not check -- and
    unpickles whatever it finds there.  See :func:`enable_private_cache`.  Decorating imports nothing:
    a module of compiled functions can be imported (and its numpy twins run) without numba's ~0.3 s import.
    """
    def decorate(fn):
        return LazyDispatcher(fn, options)

    return decorate


_LAZY_LOCK = threading.Lock()


class LazyDispatcher:
    """A compiled function of :func:`njit` whose numba dispatcher is made when it is first called or inspected.

    The first use imports numba, makes the dispatchers of every :class:`LazyDispatcher` of the same
    module (``numba.njit(**options)`` and :func:`enable_private_cache`) and puts them in the module's
    namespace in place of the wrappers: numba types a call from one compiled function to another
    through the callee's global, which must be a dispatcher by then.  A wrapper held elsewhere (imported
    by name before the first use) forwards calls and attributes to its dispatcher; :func:`dispatcher`
    gives the dispatcher itself (what a generated module calling it from compiled code must bind).
    Making the dispatcher compiles nothing: numba compiles on the first call with new argument types.
    """

    def __init__(self, fn, options):
        self.py_func = fn
        self.options = dict(options)
        self._dispatcher = None
        self.__doc__, self.__name__, self.__qualname__ = fn.__doc__, fn.__name__, fn.__qualname__
        self.__module__ = fn.__module__
        self.__wrapped__ = fn

    @property
    def dispatcher(self):
        """The numba dispatcher (made, with those of the rest of the module, on first use)."""
        made = self._dispatcher
        if made is None:
            with _LAZY_LOCK:  # a threaded first call (the guards' scan) makes each dispatcher once
                if self._dispatcher is None:
                    _make_module_dispatchers(self.py_func.__globals__)
                made = self._make()  # (made above unless this wrapper is not one of its module's globals)
        return made

    def _make(self):
        if self._dispatcher is None:
            import numba

            _register_typeof()
            made = numba.njit(**self.options)(self.py_func)
            enable_private_cache(made)
            self._dispatcher = made
        return self._dispatcher

    def __call__(self, *args, **kwargs):
        return self.dispatcher(*args, **kwargs)

    def __getattr__(self, name):  # signatures, overloads, inspect_types, ...: the dispatcher's
        if name.startswith("__") or name in ("py_func", "options", "_dispatcher"):  # copy/pickle probes, __init__
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __repr__(self):
        state = "made" if self._dispatcher is not None else "not made yet"
        return f"<compiled function {self.__module__}.{self.__qualname__} ({state})>"


_TYPEOF_REGISTERED = False


def _register_typeof() -> None:
    """Let numba type a wrapper held as a global of other compiled code as its dispatcher (made then)."""
    global _TYPEOF_REGISTERED
    if not _TYPEOF_REGISTERED:
        from numba.core.typing.typeof import typeof_impl

        typeof_impl.register(LazyDispatcher)(lambda value, context: typeof_impl(value.dispatcher, context))
        _TYPEOF_REGISTERED = True


def _make_module_dispatchers(namespace: dict) -> None:
    """Replace every :class:`LazyDispatcher` of ``namespace`` (a module's globals) by its numba dispatcher."""
    for name, value in list(namespace.items()):
        if isinstance(value, LazyDispatcher) and value.py_func.__globals__ is namespace:
            namespace[name] = value._make()


def dispatcher(function):
    """The numba dispatcher of ``function`` (a :class:`LazyDispatcher` made now), or ``function`` itself."""
    return function.dispatcher if isinstance(function, LazyDispatcher) else function


def numba_cache_directory(py_file):
    """The private directory for the machine code of the functions of ``py_file``, or None (then nothing is cached).

    ``<cache root>/numba/<directory name>_<SHA-1 of the directory>`` (the names numba itself would use
    under ``$NUMBA_CACHE_DIR``), every level private (:func:`nambu_bch.private_dirs.private_directory`;
    the per-user temp directory when the cache root is not; never a throw-away one).
    """
    import hashlib

    from .private_dirs import cache_root, private_directory

    where = os.path.dirname(os.path.abspath(py_file))
    name = f"{os.path.basename(where)}_{hashlib.sha1(where.encode()).hexdigest()}"
    key = (str(cache_root()), name)
    if key not in _NUMBA_DIRS:  # once per module directory: a dozen functions share it (the caller re-checks it)
        try:
            _NUMBA_DIRS[key] = private_directory("numba", name, fresh=False)
        except OSError:
            _NUMBA_DIRS[key] = None
    return _NUMBA_DIRS[key]


def cache_variant(fastmath) -> str:
    """The suffix of a cache entry's name for the ``fastmath`` option it was compiled with (``""`` without).

    numba's cache keys an entry by the function's bytecode and signature, not by its compile
    flags, so the same function compiled with and without contraction (``{"contract"}``) would
    load each other's machine code; the suffix keeps their files apart.

    >>> cache_variant(False), cache_variant({"contract"}), cache_variant(True)
    ('', '+contract', '+fast')
    """
    if not fastmath:
        return ""
    return "+" + "+".join(sorted(fastmath) if isinstance(fastmath, (set, frozenset, list, tuple)) else ["fast"])


def enable_private_cache(dispatcher, directory=None, name=None) -> bool:
    """Give a numba dispatcher a disk cache in ``directory`` (default :func:`numba_cache_directory`); whether it got one.

    ``name``: the name its cache files carry (default the function's qualified name), followed by
    :func:`cache_variant` of its ``fastmath`` option.

    The cache is used only while the directory is private (:func:`nambu_bch.private_dirs.untrusted`,
    checked again before every read and write); each file is written atomically with a SHA-256 of its
    content and read back through :func:`nambu_bch.private_dirs.read_private` (a private regular file,
    never a link, FIFO or device, size bounded), and numba unpickles it only if the digest matches,
    so a file planted or damaged there is compiled over, never loaded.  Without a private directory,
    or if numba's caching internals are not the ones this was written for, the function is compiled
    in memory in each process (what ``cache=False`` does).
    """
    import inspect

    from .private_dirs import untrusted

    try:
        py_file = inspect.getfile(dispatcher.py_func)
        if directory is None:
            directory = numba_cache_directory(py_file)
        if directory is None or untrusted(directory) is not None or not os.path.exists(py_file):
            return False
        variant = cache_variant(getattr(dispatcher, "targetoptions", {}).get("fastmath"))
        dispatcher._cache = _cache_class()(dispatcher.py_func, str(directory), variant, name)
    except (ImportError, AttributeError, TypeError, OSError):
        return False
    return True


_FMA = None


def fused_multiply_add():
    """A numba intrinsic ``fma(a, b, c)``: ``a*b + c`` rounded once (LLVM's ``llvm.fma.f64``, one instruction on
    a CPU with an FMA unit, else the C library's correctly rounded ``fma``), made on first use (importing
    numba costs ~0.3 s).  The fused kernels bind it to the name their source calls
    (:data:`nambu_bch.numeric.codegen.FMA_FUNCTION`).

    References: IEEE 754-2008, fusedMultiplyAdd; LLVM Language Reference, ``llvm.fma.*``.
    """
    global _FMA
    if _FMA is None:
        from numba import types
        from numba.extending import intrinsic

        @intrinsic
        def fma(typingctx, a, b, c):
            sig = types.float64(types.float64, types.float64, types.float64)

            def codegen(context, builder, signature, args):
                return builder.fma(*args)

            return sig, codegen

        _FMA = fma
    return _FMA


def _verified(path):
    """The payload of a cache file we wrote (digest checked), or None."""
    import hashlib

    from .private_dirs import read_private

    try:
        data = read_private(path, MAX_NUMBA_FILE)
    except OSError:
        return None
    head = len(_MAGIC) + 32
    if not data.startswith(_MAGIC) or len(data) < head:
        return None
    payload = data[head:]
    return payload if hashlib.sha256(payload).digest() == data[len(_MAGIC):head] else None


def _write_verified(path, payload: bytes) -> None:
    """Write ``payload`` with its digest, atomically, mode 0600."""
    import hashlib

    from .atomic import write_atomic

    write_atomic(path, _MAGIC + hashlib.sha256(payload).digest() + payload, mode=0o600)


_CACHE_CLASS = None


def _cache_class():
    """The cache class of :func:`enable_private_cache` (defined on first use: importing numba costs ~0.3 s)."""
    global _CACHE_CLASS
    if _CACHE_CLASS is None:
        _CACHE_CLASS = _define_cache_class()
    return _CACHE_CLASS


def _define_cache_class():
    """numba's ``FunctionCache`` with the locator and the file format described in :func:`enable_private_cache`.

    It replaces two things of numba's: the choice of directory (``CacheImpl`` tries ``$NUMBA_CACHE_DIR``
    and ``$NUMBA_CACHE_LOCATOR_CLASSES`` first) and ``IndexDataCacheFile``'s reads and writes (``open``
    and ``pickle.load`` on whatever is there).
    """
    import hashlib
    import inspect
    import io
    import pickle

    from numba.core import caching

    from .private_dirs import read_private, untrusted

    class PrivateLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
        def __init__(self, py_func, py_file, directory):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._cache_path = directory

        def ensure_cache_path(self):  # before every save: still private?
            reason = untrusted(self._cache_path)
            if reason:
                raise OSError(reason)

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):  # numba's stamp is a digest too, but read with a plain open (a FIFO blocks)
            return hashlib.sha256(read_private(self._py_file, MAX_NUMBA_FILE, owned=False)).digest()

    class PrivateImpl(caching.CompileResultCacheImpl):
        def __init__(self, py_func, directory, variant, name=None):  # numba's __init__ without its locator search
            self._lineno = py_func.__code__.co_firstlineno
            qualname = name or getattr(py_func, "__qualname__", py_func.__name__)
            filename = inspect.getfile(py_func)
            self._locator = PrivateLocator(py_func, filename, directory)
            modname = os.path.splitext(os.path.basename(filename))[0]
            self._filename_base = self.get_filename_base(f"{modname}.{qualname}{variant}", getattr(sys, "abiflags", ""))

    class VerifiedFile(caching.IndexDataCacheFile):
        def _private(self):
            return untrusted(self._cache_path) is None

        def _load_index(self):
            payload = _verified(self._index_path) if self._private() else None
            if payload is None:  # absent, damaged, planted, or the directory is no longer private
                return {}
            try:
                stream = io.BytesIO(payload)
                if pickle.load(stream) != self._version:
                    return {}
                stamp, overloads = pickle.loads(stream.read())
            except Exception:  # noqa: BLE001 - an index of ours this numba cannot read: start afresh
                return {}
            if stamp != self._source_stamp or not isinstance(overloads, dict):
                return {}
            return overloads

        def _save_index(self, overloads):
            self._check_private()
            payload = pickle.dumps(self._version, protocol=-1) + self._dump((self._source_stamp, overloads))
            _write_verified(self._index_path, payload)

        def _load_data(self, name):
            if os.path.basename(name) != name or not self._private():
                raise OSError(f"{name}: not a cache file of a private directory")
            payload = _verified(self._data_path(name))
            if payload is None:
                raise OSError(f"{name}: absent or damaged")  # load() then compiles
            return pickle.loads(payload)

        def _save_data(self, name, data):
            self._check_private()
            _write_verified(self._data_path(name), self._dump(data))

        def _check_private(self):
            if not self._private():
                raise OSError(f"{self._cache_path} is no longer private")

    class PrivateFunctionCache(caching.FunctionCache):
        def __init__(self, py_func, directory, variant="", name=None):  # numba's Cache.__init__, the classes above
            self._name = repr(py_func)
            self._py_func = py_func
            self._impl = PrivateImpl(py_func, directory, variant, name)
            self._cache_path = directory
            self._cache_file = VerifiedFile(cache_path=directory, filename_base=self._impl.filename_base,
                                            source_stamp=self._impl.locator.get_source_stamp())
            self.enable()

        def load_overload(self, sig, target_context):
            try:
                return super().load_overload(sig, target_context)
            except Exception:  # noqa: BLE001 - a verified file this numba cannot rebuild: compile it again
                return None

        def save_overload(self, sig, data):
            try:
                super().save_overload(sig, data)
            except OSError:  # full disk, read-only, no longer private: the compiled function still runs
                pass

    return PrivateFunctionCache
