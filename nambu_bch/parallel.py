"""Parallel sweeps: one package call mapped over many parameter sets, results in task order.

Work-precision studies over words, steps and starting points, ensembles of
:func:`~nambu_bch.numeric.check`, shadow Hamiltonians over a family of systems: each task is
independent, so :func:`sweep` hands them to the worker processes of joblib's ``loky`` backend
(the cores of one machine) or to a Dask cluster (``distributed.Client``), and gathers the
results in the order of the tasks.  Results travel back by pickle (every result type of the
package pickles, ``tests/test_pickle.py``); a sweep returns what the serial loop
``[function(...task...) for task in tasks]`` returns.

joblib and dask are optional: ``pip install 'nambu_bch[parallel]'``.  They are imported only
when a sweep asks for them.
"""

from __future__ import annotations

from .checks import check_int, show
from .errors import InvalidRunError

#: The accepted ``backend`` names.
BACKENDS = ("loky", "dask", "serial")

_EXTRA = "pip install 'nambu_bch[parallel]'"


def sweep(function, tasks, *, backend=None, client=None, n_jobs=None) -> list:
    """``[function(task) for task in tasks]``, run in parallel, results in task order.

    A task is a ``dict`` (keyword arguments: ``function(**task)``), a ``tuple`` (positional
    arguments: ``function(*task)``), or any other object (the single argument: ``function(task)``).
    An exception raised by a task is raised again here, unchanged, as the serial loop would.

    Parameters
    ----------
    function : callable -- e.g. :func:`nambu_bch.check`, :func:`nambu_bch.shadow_hamiltonians`; it and the
        tasks must pickle (a module-level function; joblib and Dask also ship lambdas with cloudpickle)
    tasks : iterable of tasks
    backend : ``"loky"`` | ``"dask"`` | ``"serial"`` | None -- None: ``"dask"`` when ``client`` is given,
        else ``"loky"``; ``"serial"`` is the plain loop in this process (no extra packages)
    client : distributed.Client, optional -- the Dask cluster to run on; with ``backend="dask"`` and no
        client, the current default client (``distributed.get_client()``)
    n_jobs : int >= 1, optional -- loky worker processes (default: one per core); ignored by Dask and serial

    Returns
    -------
    list -- one result per task, in the order of ``tasks``

    Raises
    ------
    InvalidRunError -- a function that is not callable, tasks that are not iterable, an unknown backend,
        a bad ``n_jobs``, a backend whose package is not installed, ``backend="dask"`` without a client

    Examples
    --------
    >>> from nambu_bch import iterate
    >>> tasks = [{"system": "ho", "word": "TVT", "h": h, "steps": 10, "x0": (1.0, 0.0)} for h in (0.1, 0.2)]
    >>> [x[-1].round(6).tolist() for x in sweep(iterate, tasks, backend="serial")]
    [[0.539951, -0.84275], [-0.419189, -0.912473]]
    """
    if not callable(function):
        raise InvalidRunError(f"function must be callable (e.g. nambu_bch.check), got {show(function)}")
    if isinstance(tasks, (str, bytes)):
        raise InvalidRunError(f"tasks must be an iterable of tasks (dicts, tuples or single arguments), "
                              f"got the string {show(tasks)}")
    try:
        tasks = list(tasks)
    except TypeError:
        raise InvalidRunError(f"tasks must be an iterable of tasks (dicts, tuples or single arguments), "
                              f"got {show(tasks)}") from None
    if backend is None:
        backend = "dask" if client is not None else "loky"
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise InvalidRunError(f"backend must be one of {', '.join(BACKENDS)}, got {show(backend)}")
    if client is not None and backend != "dask":
        raise InvalidRunError(f"client is a Dask client: give backend='dask' (or no backend) with it, "
                              f"got backend={backend!r}")
    if n_jobs is not None:
        n_jobs = check_int(n_jobs, "n_jobs", 1)
    if backend == "serial" or not tasks:
        return [_apply(function, task) for task in tasks]
    if backend == "loky":
        joblib = _require("joblib", "loky")
        return list(joblib.Parallel(n_jobs=n_jobs or -1, backend="loky")(
            joblib.delayed(_apply_in_worker)(function, task) for task in tasks))
    return _dask(function, tasks, client)


def _apply(function, task):
    """One task: keyword arguments (dict), positional arguments (tuple), or the single argument."""
    if isinstance(task, dict):
        return function(**task)
    if isinstance(task, tuple):
        return function(*task)
    return function(task)


def _apply_in_worker(function, task):
    """One task in a worker of a parallel sweep: its batches run on one thread (the workers share the cores)."""
    from .numeric.iterate import single_threaded

    with single_threaded():
        return _apply(function, task)


def _dask(function, tasks, client):
    distributed = _require("distributed", "dask")
    if client is None:
        try:
            client = distributed.get_client()
        except ValueError:  # distributed's answer when no client is running
            raise InvalidRunError("backend='dask' needs a cluster: pass client=distributed.Client(...)") from None
    elif not isinstance(client, distributed.Client):
        raise InvalidRunError(f"client must be a distributed.Client, got {show(client)}")
    # Tasks travel in batches, about four per worker thread: Dask's per-task overhead (scheduling, one
    # message each way) is far above the cost of a small task.  pure=False: equal batches are still run
    # once each, as the serial loop runs them.  A batch travels inside a _Packed object, which Dask does
    # not look into: a tuple whose first item is callable would otherwise be read as a task of its graph.
    threads = max(1, sum(client.nthreads().values()))
    size = -(-len(tasks) // (4 * threads))
    batches = [_Packed(function, tasks[i:i + size]) for i in range(0, len(tasks), size)]
    futures = client.map(_run_batch, batches, pure=False)
    return [result for batch in client.gather(futures) for result in batch]


class _Packed:
    """A function and a list of tasks, opaque to Dask."""

    __slots__ = ("function", "tasks")

    def __init__(self, function, tasks):
        self.function, self.tasks = function, tasks

    def __getstate__(self):
        return self.function, self.tasks

    def __setstate__(self, state):
        self.function, self.tasks = state


def _run_batch(packed):
    return [_apply_in_worker(packed.function, task) for task in packed.tasks]


def _require(module, backend):
    """Import the optional ``module`` that ``backend`` needs, or one line saying how to install it."""
    from importlib import import_module

    try:
        return import_module(module)
    except ImportError:
        raise InvalidRunError(f"backend={backend!r} needs the package {module}, which is not installed; "
                              f"{_EXTRA}, or use backend='serial'") from None
