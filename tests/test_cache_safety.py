"""The on-disk caches are verified before they are trusted, numba's machine code included.

Three families of attack on a cache, each run where it would do harm:

* a pickle planted where numba would look (``$NUMBA_CACHE_DIR``, a common workaround for a read-only
  HOME, or the package's own numba directory without a valid digest) must never be unpickled;
* the ``models`` listing cache, truncated, damaged or carrying terminal escapes, is computed again,
  never printed;
* a FIFO, a symbolic link or a directory in place of any cache file neither blocks nor is read.

Probes that could hang if a regression opened a FIFO run in a subprocess; its timeout is only a
safety net (never a timing assertion).  Every file a test writes is under ``tmp_path``.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import os
import pickle
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from nambu_bch import compiled, private_dirs

REPO = Path(__file__).resolve().parent.parent
SAFETY_NET = 600  # seconds; a probe that hangs fails instead of blocking the suite

numba_only = pytest.mark.skipif(not compiled.numba_available(), reason="numba not installed or disabled")


class _Marker:
    """Unpickling this creates the directory ``path``: the visible side effect of a planted pickle."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (os.mkdir, (self.path,))


def _env(tmp_path, **extra):
    """The environment of a probe: this checkout, the cache root and the temporary directory under tmp_path."""
    (tmp_path / "tmp").mkdir(exist_ok=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(REPO), NAMBU_BCH_CACHE=str(tmp_path / "cache"), TMPDIR=str(tmp_path / "tmp"))
    env.update({k: str(v) for k, v in extra.items()})
    return env


def _probe(code, env):
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=SAFETY_NET)
    assert done.returncode == 0, done.stderr
    return done


#: Runs every compiled path of the package once (a kernel single and batch loop, the batch scan, the BCH
#: engine's Lyndon table) and compares each with its pure-Python twin.
RUN = """
import json
import numpy as np
from nambu_bch.numeric.iterate import iterate
from nambu_bch.numeric.guards import scan_states
from nambu_bch.numeric.scan import scan
from nambu_bch.bch.modular import lyndon_table
from nambu_bch.bch.lyndon import witt_dimension

a = iterate("ho", "121", 0.125, 400, [1.0, 0.5], backend="numba", every=400)
b = iterate("ho", "121", 0.125, 400, [1.0, 0.5], backend="numpy", every=400)
X = np.array([[1.0, 0.0, 2.0], [0.5, 3.0, 1.0]])
A = iterate("ho", "121", 0.125, 50, X, backend="numba")
B = iterate("ho", "121", 0.125, 50, X, backend="numpy")
S = np.array([[1.0, np.inf, 2.0], [0.5, 3.0, 1e-310]])
res = np.zeros(7, dtype=np.int64)
scan(S, res)
twin = scan_states(S)
words = lyndon_table(2, 6)[1]
print(json.dumps({"run": bool(np.array_equal(a, b)), "batch": bool(np.array_equal(A, B)),
                  "scan": [int(res[0]), int(res[1])] == [int(twin[0]), int(twin[1])] == [1, 1],
                  "lyndon": len(words) == sum(witt_dimension(2, d) for d in range(1, 7))}))
"""

#: The two cheapest compiled loops, one from each kind of cache directory: the ho/121 kernel's single-trajectory
#: loop (``kernels/``) and the batch scan (the package's ``numba/``), each compared with its pure-Python twin.  The
#: probes that damage cache files run this instead of :data:`RUN`: every compiled function reads its files through
#: the same verified cache class (:func:`nambu_bch.compiled.enable_private_cache`), so recompiling two small loops
#: over damaged files proves what recompiling all of them did, at a fraction of the compile time.
SMALL = """
import json
import numpy as np
from nambu_bch.numeric.iterate import iterate
from nambu_bch.numeric.guards import scan_states
from nambu_bch.numeric.scan import scan

a = iterate("ho", "121", 0.125, 400, [1.0, 0.5], backend="numba", every=400)
b = iterate("ho", "121", 0.125, 400, [1.0, 0.5], backend="numpy", every=400)
S = np.array([[1.0, np.inf, 2.0], [0.5, 3.0, 1e-310]])
res = np.zeros(7, dtype=np.int64)
scan(S, res)
twin = scan_states(S)
print(json.dumps({"run": bool(np.array_equal(a, b)),
                  "scan": [int(res[0]), int(res[1])] == [int(twin[0]), int(twin[1])] == [1, 1]}))
"""

#: ``check`` (whose backend choice looks into the kernel and numba caches first: a FIFO there once hung it), then
#: :data:`SMALL`, then the ``models`` listing, in one fresh process (each step the first in it to read its files).
CHECK_SMALL_LISTING = """
import contextlib, io, json
from nambu_bch.numeric.diagnostics import check
r = check('ho', '121', 0.1, 200, [1.0, 0.0])
print(json.dumps({"check": bool(r.max_abs_error['H'] < 1e-2)}))
""" + SMALL + """
from nambu_bch.cli import main
listing = io.StringIO()
with contextlib.redirect_stdout(listing):
    status = main(['models', '--format', 'text'])
print(json.dumps({"status": status, "listing": listing.getvalue()}))
"""


def _results(done) -> dict:
    """The JSON lines a probe printed, merged."""
    out = {}
    for line in done.stdout.strip().splitlines():
        if line.startswith("{"):
            out.update(json.loads(line))
    return out


def _run_ok(env):
    out = _results(_probe(RUN, env))
    assert out == {"run": True, "batch": True, "scan": True, "lyndon": True}, out


def _small_ok(env):
    out = _results(_probe(SMALL, env))
    assert out == {"run": True, "scan": True}, out


@pytest.fixture(scope="module")
def warm(tmp_path_factory):
    """A cache root filled once by RUN, ``check`` and the listing (compiling cold costs tens of seconds on a loaded
    machine; one process), and the honest listing; each test works on its own copy (:func:`_copy_warm`)."""
    base = tmp_path_factory.mktemp("warm")
    env = _env(base)
    out = _results(_probe(RUN + CHECK_SMALL_LISTING, env))
    listing = out.pop("listing")
    assert listing.startswith("ho") and out == {"run": True, "batch": True, "scan": True, "lyndon": True,
                                                "check": True, "status": 0}, out
    return base / "cache", listing


def _copy_warm(warm, tmp_path):
    """``tmp_path/cache``: a copy of the warm cache (modes kept), and the probes' environment for it."""
    import shutil

    shutil.copytree(warm[0], tmp_path / "cache", symlinks=True)
    return tmp_path / "cache", _env(tmp_path)


def _functions(kernel_root):
    """The Python functions numba compiles on the RUN paths: the ho/121 kernel's (cached under ``kernel_root``)
    and the package's own."""
    from nambu_bch import model
    from nambu_bch.bch import modular
    from nambu_bch.numeric import kernels, scan

    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("NAMBU_BCH_CACHE", str(kernel_root))
        patch.setattr(kernels, "_CACHE_DIRS", {})
        kernel = kernels.Kernel(model("ho"), kernels.composition_for("121", model("ho")))
    found = [getattr(kernel.module, name) for name in ("run", "run_batch")]
    for module in (scan, modular):
        found += [obj.py_func for obj in vars(module).values() if hasattr(obj, "py_func")]
    return found


def _numba_index(py_func, cache_dir):
    """Where numba itself (``NUMBA_CACHE_DIR=cache_dir``) reads the index of ``py_func``: its own classes say."""
    from numba.core import caching, config

    saved = config.CACHE_DIR
    config.CACHE_DIR = str(cache_dir)
    try:
        return Path(caching.FunctionCache(py_func)._cache_file._index_path)
    finally:
        config.CACHE_DIR = saved


# -- numba's own cache -------------------------------------------------------------------------------------------------


@numba_only
def test_pickles_planted_under_numba_cache_dir_are_never_loaded(tmp_path, warm):
    """NUMBA_CACHE_DIR pointing into a directory everyone can write, with a pickle planted for every function the
    package compiles (the kernels, the batch scan, the BCH engine): nothing is unpickled, every result is right."""
    root, env = _copy_warm(warm, tmp_path)
    shared = tmp_path / "numba-shared"
    shared.mkdir()
    os.chmod(shared, 0o777)
    planted, indexes = [], []
    for fn in _functions(root):
        index = _numba_index(fn, shared)
        index.parent.mkdir(parents=True, exist_ok=True)
        marker = tmp_path / f"ran-{len(planted)}"
        index.write_bytes(pickle.dumps(_Marker(marker)))
        planted.append(marker)
        indexes.append(index)
    assert len(planted) > 10
    _run_ok({**env, "NUMBA_CACHE_DIR": str(shared)})
    assert not any(m.exists() for m in planted)
    # control: numba's own cache would have run the pickle (proves the plant sits where numba reads)
    _probe(f"import pickle; pickle.load(open({str(indexes[0])!r}, 'rb'))", _env(tmp_path))
    assert planted[0].exists()


def _private_index(fn, directory):
    return Path(compiled._cache_class()(fn, str(directory))._cache_file._index_path)


@numba_only
def test_private_numba_cache_unpickles_only_verified_files(tmp_path, warm):
    """In the package's own numba directories, a file without the digest the package writes (a raw pickle in
    numba's format, a truncated entry) is compiled over and rewritten in the verified format, never unpickled.

    Every index gets a planted pickle; the probe (:data:`SMALL`) then recompiles one loop of each directory, the
    ho/121 kernel's ``run`` (``kernels/``) and ``scan_range`` (``numba/``), over their planted index and truncated data."""
    root, env = _copy_warm(warm, tmp_path)
    indexes = sorted(root.rglob("*.nbi"))
    data = sorted(root.rglob("*.nbc"))
    assert {p.relative_to(root).parts[0] for p in indexes} == {"kernels", "numba"}
    for path in indexes + data:
        assert path.read_bytes().startswith(compiled._MAGIC) and stat.S_IMODE(path.stat().st_mode) == 0o600
    read = sorted(root.rglob("*.run-*.nbi")) + sorted((root / "numba").rglob("scan.scan_range-*.nbi"))
    truncated = sorted(root.rglob("*.run-*.nbc")) + sorted((root / "numba").rglob("scan.scan_range-*.nbc"))
    assert {p.relative_to(root).parts[0] for p in read} == {p.relative_to(root).parts[0] for p in truncated} \
        == {"kernels", "numba"}
    markers = []
    for i, path in enumerate(indexes):
        markers.append(tmp_path / f"ran-{i}")
        path.write_bytes(pickle.dumps(_Marker(markers[-1])))  # numba's format: a bare pickle
    for path in truncated:
        path.write_bytes(path.read_bytes()[:100])  # truncated
    _small_ok(env)
    assert not any(m.exists() for m in markers)
    assert all(p.read_bytes().startswith(compiled._MAGIC) for p in read + truncated)  # compiled over, rewritten
    # a planted entry *with* a valid digest is refused too once the directory is not private
    fn = next(f for f in _functions(root) if f.__name__ == "scan_range")
    index = _private_index(fn, _numba_dir(root, fn))
    assert index.exists()
    marker = tmp_path / "ran-digest"
    payload = pickle.dumps(_Marker(marker))
    index.write_bytes(compiled._MAGIC + hashlib.sha256(payload).digest() + payload)
    os.chmod(index.parent, 0o777)
    _small_ok(env)
    assert not marker.exists()


def _numba_dir(root, fn):
    where = os.path.dirname(os.path.abspath(inspect.getfile(fn)))
    return root / "numba" / f"{os.path.basename(where)}_{hashlib.sha1(where.encode()).hexdigest()}"


@numba_only
def test_every_compiled_function_uses_the_private_cache():
    """No function of the package keeps numba's default cache (``cache=True``): each has the private cache or none."""
    from numba.core.caching import NullCache

    from nambu_bch.bch import modular
    from nambu_bch.numeric import scan

    cls = compiled._cache_class()
    dispatchers = [obj for module in (scan, modular) for obj in vars(module).values() if hasattr(obj, "py_func")]
    assert len(dispatchers) >= 15
    for d in dispatchers:
        assert type(d._cache) in (cls, NullCache), (d, type(d._cache))
    for path in (REPO / "nambu_bch").rglob("*.py"):
        text = path.read_text()
        assert "cache=True" not in text.replace("``numba.njit(cache=True)``", ""), path


def test_numba_cache_directory_is_private_or_none(tmp_path, monkeypatch):
    """The directory numba's machine code goes to: private at every level, else none (nothing cached)."""
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(tmp_path / "shared" / "cache"))
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path / "tmp"))
    monkeypatch.setattr(compiled, "_NUMBA_DIRS", {})
    (tmp_path / "tmp").mkdir()
    (tmp_path / "shared").mkdir()
    here = str(REPO / "nambu_bch" / "numeric" / "scan.py")
    good = compiled.numba_cache_directory(here)
    assert good.parent == tmp_path / "shared" / "cache" / "numba" and private_dirs.untrusted(good) is None
    os.chmod(tmp_path / "shared", 0o777)  # a parent anyone can write: the cache root could be swapped
    os.chmod(tmp_path / "tmp", 0o777)
    assert "sticky" in private_dirs.untrusted(good)  # what enable_private_cache checks before using it
    compiled._NUMBA_DIRS.clear()
    assert compiled.numba_cache_directory(here) is None


# -- the models listing cache -----------------------------------------------------------------------------------------


def _listing(monkeypatch, capsys, root):
    from nambu_bch.cli import main

    monkeypatch.setenv("NAMBU_BCH_CACHE", str(root))
    assert main(["models", "--format", "text"]) == 0
    return capsys.readouterr().out


def _entry(root):
    (entry,) = (root / "cli").glob("*.txt")
    return entry


def test_truncated_listing_cache_is_recomputed(tmp_path, monkeypatch, capsys):
    """A listing entry cut to 100 bytes was printed with exit 0: its digest no longer matches, so it is computed."""
    root = tmp_path / "cache"
    honest = _listing(monkeypatch, capsys, root)
    entry = _entry(root)
    entry.write_bytes(entry.read_bytes()[:100])
    assert _listing(monkeypatch, capsys, root) == honest
    assert stat.S_IMODE(entry.stat().st_mode) == 0o600
    assert _entry(root).read_text().endswith(honest)  # rewritten whole
    body = entry.read_text().partition("\n")[2]
    entry.write_text(entry.read_text().partition("\n")[0] + "\n" + body.replace("ho3", "hx3", 1))  # one byte changed
    assert _listing(monkeypatch, capsys, root) == honest


@pytest.mark.parametrize("planted", ["\x1b]0;pwned\x07\x1b[2J", "ok\rplanted", "\u202eplanted", "a\x00b"])
def test_listing_cache_never_prints_control_characters(tmp_path, monkeypatch, capsys, planted):
    """A planted entry with terminal escapes (even with a matching digest) is not printed: the listing is computed."""
    root = tmp_path / "cache"
    honest = _listing(monkeypatch, capsys, root)
    from nambu_bch.cli.cache import _HEADER

    text = planted + "\n" + honest
    _entry(root).write_text(_HEADER + hashlib.sha256(text.encode()).hexdigest() + "\n" + text)
    shown = _listing(monkeypatch, capsys, root)
    assert shown == honest and planted not in shown


def test_listing_cache_under_a_parent_others_can_write_is_not_used(tmp_path, monkeypatch, capsys):
    """A cache root whose parent directory anyone can write (no sticky bit) is not private: nothing is cached."""
    shared = tmp_path / "shared"
    shared.mkdir()
    os.chmod(shared, 0o777)
    honest = _listing(monkeypatch, capsys, shared / "cache")
    assert not list((shared / "cache").rglob("*.txt"))
    os.chmod(shared, 0o1777)  # sticky, like /tmp: others cannot rename what is ours
    assert _listing(monkeypatch, capsys, shared / "cache") == honest
    assert len(list((shared / "cache").rglob("*.txt"))) == 1


# -- non-regular files in place of cache files -------------------------------------------------------------------------


def _replace_with(path, kind, tmp_path):
    path.unlink()
    if kind == "fifo":
        os.mkfifo(path, 0o600)
    elif kind == "symlink":
        elsewhere = tmp_path / f"elsewhere-{path.name}"
        elsewhere.write_text("planted")
        os.chmod(elsewhere, 0o600)
        path.symlink_to(elsewhere)
    else:
        path.mkdir(mode=0o700)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
@pytest.mark.parametrize("kind", ["fifo", "symlink", "directory"])
def test_special_files_in_place_of_cache_files_neither_block_nor_are_read(tmp_path, warm, kind):
    """A FIFO (which hung ``check``), a symbolic link or a directory in place of each kind of cache file: the
    kernel index and source, numba's index and data files (a kernel's and the package's), the models listing.
    A fresh process runs ``check``, the two small loops and the listing over them (:data:`CHECK_SMALL_LISTING`):
    right results, nothing blocks; a planted link's target is never changed."""
    root, env = _copy_warm(warm, tmp_path)
    targets = (sorted((root / "kernels").glob("nambu_bch_*")) + sorted((root / "kernels").rglob("*.run-*.nb?"))
               + sorted((root / "numba").rglob("scan.scan-*.nb?")) + sorted((root / "cli").glob("*.txt")))
    assert {".json", ".py", ".nbi", ".nbc", ".txt"} <= {p.suffix for p in targets}
    for path in targets:
        _replace_with(path, kind, tmp_path)
    out = _results(_probe(CHECK_SMALL_LISTING, env))
    assert out == {"check": True, "run": True, "scan": True, "status": 0, "listing": warm[1]}, out
    for path in targets:
        assert not path.is_symlink() or Path(os.readlink(path)).read_text() == "planted"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_read_private_refuses_what_is_not_a_private_regular_file(tmp_path):
    """The one verified read: FIFO, socket-like specials, symlink, directory, foreign mode, oversized -- all OSError,
    and a FIFO is refused without blocking (probed in a subprocess, the timeout only a safety net)."""
    good = tmp_path / "good"
    good.write_bytes(b"x" * 10)
    os.chmod(good, 0o600)
    assert private_dirs.read_private(good, 10) == b"x" * 10
    with pytest.raises(OSError, match="larger"):
        private_dirs.read_private(good, 9)
    link = tmp_path / "link"
    link.symlink_to(good)
    with pytest.raises(OSError, match="symbolic link"):
        private_dirs.read_private(link, 100)
    with pytest.raises(OSError, match="not a file"):
        private_dirs.read_private(tmp_path, 100)
    os.chmod(good, 0o620)
    with pytest.raises(OSError, match="writable by group or others"):
        private_dirs.read_private(good, 100)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo, 0o600)
    code = ("from nambu_bch.private_dirs import read_private\n"
            f"try:\n    read_private({str(fifo)!r}, 100)\nexcept OSError as exc:\n    print('refused:', exc)\n")
    assert "refused:" in _probe(code, _env(tmp_path)).stdout


def test_untrusted_checks_every_directory_above(tmp_path):
    """A private directory under a parent anyone can write (no sticky bit) is not trusted: the parent's owner
    could rename it and put theirs in its place.  A sticky parent (``/tmp``) is fine."""
    shared = tmp_path / "shared"
    own = shared / "a" / "cache"
    own.mkdir(parents=True, mode=0o700)
    os.chmod(shared / "a", 0o700)
    assert private_dirs.untrusted(own) is None
    os.chmod(shared, 0o777)
    assert "writable by group or others without the sticky bit" in private_dirs.untrusted(own)
    os.chmod(shared, 0o1777)
    assert private_dirs.untrusted(own) is None
    os.chmod(shared, 0o755)
    elsewhere = tmp_path / "open"
    elsewhere.mkdir(mode=0o777)
    os.chmod(elsewhere, 0o777)
    (elsewhere / "real").mkdir(mode=0o700)
    (shared / "via").symlink_to(elsewhere)  # a safe-looking path through a symlink into an open directory
    assert "above" in private_dirs.untrusted(shared / "via" / "real")


def test_kernel_cache_under_an_open_parent_falls_back(tmp_path, monkeypatch):
    """The kernel cache refuses a root whose parent anyone can write and says so in CACHE_NOTES."""
    from nambu_bch.numeric import kernels

    shared = tmp_path / "shared"
    shared.mkdir()
    os.chmod(shared, 0o777)
    monkeypatch.setenv("NAMBU_BCH_CACHE", str(shared / "cache"))
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    monkeypatch.setattr(kernels, "_CACHE_DIRS", {})
    monkeypatch.setattr(kernels, "CACHE_NOTES", {})
    directory = kernels.cache_dir()
    assert directory == tmp_path / "tmp" / f"nambu_bch-{os.geteuid()}" / "kernels"
    assert "without the sticky bit" in kernels.CACHE_NOTES[str(shared / "cache")]
