"""Compiled bytecode shared by the processes of one test session, compiled once by the workers together.

Under ``pytest -n 2`` every worker imports the whole package (``--doctest-modules``) and every test module (which
pytest rewrites for its assert messages) before it runs a test.  Where no ``.pyc`` exists -- a fresh clone, or any
checkout on a machine that sets ``PYTHONDONTWRITEBYTECODE`` (this suite's machines do) -- each worker compiles all of
it from source, the same work twice at the same moment (about two thirds of a worker's 11 s of collection), and every
subprocess a test starts (``python -m nambu_bch``, pytest, a notebook kernel, loky workers) compiles the package again.

:func:`precompile` instead lets each xdist worker, before collecting, compile the files of the run's initial paths
into their ``__pycache__`` in its own order (worker 0 from the first file on, worker 1 from the last backwards),
skipping any file whose bytecode another worker has already written; the two meet in the middle, and each then
imports everything from bytecode.  Package modules get CPython's own ``.pyc`` (:func:`py_compile.compile`, written
atomically, checked against the source's time stamp and size when imported); test modules and ``conftest.py`` get
the rewritten ``.pyc`` that pytest's import hook itself reads and checks against the source's hash.  Bytecode that the
processes would not have written themselves (``PYTHONDONTWRITEBYTECODE``) is removed when the session ends
(:func:`snapshot` / :func:`remove_new`), so the checkout is left as it was found.

Nothing here decides what a test does; if pytest's private rewrite functions are not there (a pytest other than 8-9),
the test modules are simply compiled by each worker as before.
"""

from __future__ import annotations

import importlib.util
import os
import py_compile
from pathlib import Path

PYCACHE = "__pycache__"


def initial_sources(config) -> list[Path]:
    """The ``.py`` files under the run's initial paths (``testpaths`` or the command line), inside the rootdir."""
    root = Path(str(config.rootpath)).resolve()
    files: list[Path] = []
    for arg in config.args:
        path = Path(arg.split("::", 1)[0])
        path = (path if path.is_absolute() else Path(str(config.invocation_params.dir)) / path).resolve()
        if root not in path.parents and path != root:
            continue
        if path.is_file() and path.suffix == ".py":
            files.append(path)
        elif path.is_dir():
            files.extend(sorted(p for p in path.rglob("*.py") if PYCACHE not in p.parts))
    return list(dict.fromkeys(files))


def _rewritten_by_pytest(path: Path) -> bool:
    """Test modules (pytest's default ``python_files``, which this project keeps) and conftest files: pytest
    rewrites their asserts."""
    return path.name == "conftest.py" or path.name.startswith("test_") or path.name.endswith("_test.py")


def _fresh_cpython_pyc(source: Path, pyc: str) -> bool:
    """Whether ``pyc`` is a complete CPython ``.pyc`` of ``source``'s current version (time stamp and size)."""
    try:
        with open(pyc, "rb") as f:
            header = f.read(16)
        st = source.stat()
    except OSError:
        return False
    if len(header) < 16 or header[:4] != importlib.util.MAGIC_NUMBER or int.from_bytes(header[4:8], "little") != 0:
        return False  # another format (hash-based): let the import decide
    return (int.from_bytes(header[8:12], "little") == (int(st.st_mtime) & 0xFFFFFFFF)
            and int.from_bytes(header[12:16], "little") == (st.st_size & 0xFFFFFFFF))


def pytest_rewriter(config):
    """``compile(path)`` writing the rewritten ``.pyc`` pytest's import hook reads, or None if pytest lacks the parts."""
    try:
        from _pytest.assertion import rewrite
        from _pytest.assertion.rewrite import PYC_TAIL, _read_pyc, _rewrite_test, _write_pyc, get_cache_dir
        state = config.stash[rewrite.assertstate_key]
    except (ImportError, AttributeError, KeyError):
        return None

    def compile_test_module(path: Path) -> bool:
        cache = get_cache_dir(path)
        pyc = cache / (path.name[:-3] + PYC_TAIL)
        if _read_pyc(path, pyc) is not None:
            return False  # already there: the other worker wrote it
        cache.mkdir(exist_ok=True)
        source_hash, co = _rewrite_test(path, config)
        return bool(_write_pyc(state, co, source_hash, pyc))

    return compile_test_module


def order_for(files: list[Path], worker: int, workers: int) -> list[Path]:
    """The order in which worker ``worker`` of ``workers`` compiles ``files``: worker 1 of 2 backwards from the end,
    otherwise each worker from its own start (its share's first file) round the list."""
    if workers == 2 and worker == 1:
        return files[::-1]
    start = len(files) * worker // max(workers, 1)
    return files[start:] + files[:start]


def precompile(files: list[Path], worker: int, workers: int, rewrite=None) -> int:
    """Compile ``files`` into their ``__pycache__`` in :func:`order_for`'s order, skipping those whose bytecode is
    already there and current; ``rewrite`` (from :func:`pytest_rewriter`) compiles the test modules, which are
    skipped without it.  Returns how many files this call compiled."""
    done = 0
    for path in order_for(files, worker, workers):
        try:
            if _rewritten_by_pytest(path):
                if rewrite is not None and path.name != "conftest.py":  # conftest files are imported already
                    done += rewrite(path)
                continue
            pyc = importlib.util.cache_from_source(str(path))
            if not _fresh_cpython_pyc(path, pyc):
                py_compile.compile(str(path), cfile=pyc, doraise=True)
                done += 1
        except (OSError, SyntaxError, py_compile.PyCompileError, ValueError):
            continue  # unwritable or unparsable here: the import reports it, as it would have anyway
    return done


def snapshot(files: list[Path]) -> set[str]:
    """The ``__pycache__`` directories of ``files`` that exist now, and the ``.pyc`` files in them."""
    seen: set[str] = set()
    for directory in {str(f.parent / PYCACHE) for f in files}:
        try:
            entries = [os.path.join(directory, e.name) for e in os.scandir(directory) if e.name.endswith(".pyc")]
        except OSError:
            continue
        seen.add(directory)
        seen.update(entries)
    return seen


def remove_new(files: list[Path], before: set[str]) -> None:
    """Remove what the session added: ``.pyc`` files (regular files only) not there at :func:`snapshot` time, and
    ``__pycache__`` directories it made that are empty after that."""
    for directory in {str(f.parent / PYCACHE) for f in files}:
        try:
            entries = list(os.scandir(directory))
        except OSError:
            continue
        for e in entries:
            path = os.path.join(directory, e.name)
            if e.name.endswith(".pyc") and path not in before and e.is_file(follow_symlinks=False):
                try:
                    os.unlink(path)
                except OSError:
                    pass
        if directory not in before:
            try:
                os.rmdir(directory)  # only if empty
            except OSError:
                pass
