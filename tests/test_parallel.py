"""Parallel sweeps (:func:`nambu_bch.sweep`): loky and Dask give the serial results, in task order.

The tasks are tiny (a few hundred interpreted steps each), so the cost is that of starting the
worker processes.
"""

from __future__ import annotations

import importlib.util
import sys

import numpy as np
import pytest

import nambu_bch as nb
from nambu_bch.errors import InvalidRunError

#: 24 small checks: three steps times eight starting points, each a dict of keyword arguments
TASKS = [{"system": "ho3", "word": "32123", "h": h, "steps": 200, "x0": (1.0, 0.1 * k, 1.0 + 0.05 * k),
          "include": ("H", "G")} for h in (0.05, 0.1, 0.2) for k in range(8)]


def _views(results):
    return [r.to_dict() for r in results]  # the numbers; CheckResult.seconds is a wall time


def _fails_on_the_third(k):
    if k == 2:
        raise InvalidRunError(f"task {k} refused")
    return k * k


@pytest.fixture(scope="module")
def serial():
    return _views(nb.sweep(nb.check, TASKS, backend="serial"))


@pytest.fixture
def no_temp_outside(tmp_path, monkeypatch):
    """joblib memory-maps large arguments into a temporary folder: keep it under tmp_path."""
    monkeypatch.setenv("JOBLIB_TEMP_FOLDER", str(tmp_path))
    return tmp_path


def test_serial_is_the_plain_loop():
    serial = nb.sweep(nb.check, TASKS[:4], backend="serial")
    assert _views(serial) == _views([nb.check(**task) for task in TASKS[:4]])
    # tuples are positional arguments, anything else is the single argument
    assert nb.sweep(pow, [(2, 3), (3, 2)], backend="serial") == [8, 9]
    assert nb.sweep(abs, [-1, 2.5], backend="serial") == [1, 2.5]
    assert nb.sweep(abs, [], backend="serial") == []


@pytest.mark.skipif(importlib.util.find_spec("joblib") is None, reason="joblib is not installed (nambu_bch[parallel])")
def test_loky_equals_serial_in_task_order(serial, no_temp_outside):
    parallel = nb.sweep(nb.check, TASKS, backend="loky", n_jobs=2)
    assert len(parallel) == len(TASKS) == 24
    assert _views(parallel) == serial
    assert [r.h for r in parallel] == [t["h"] for t in TASKS]
    # arrays come back bit for bit
    runs = [{"system": "ho3", "word": "12321", "h": 0.1, "steps": 50, "x0": (1.0, 0.1 * k, 1.0)} for k in range(4)]
    for a, b in zip(nb.sweep(nb.iterate, runs, n_jobs=2), nb.sweep(nb.iterate, runs, backend="serial")):
        np.testing.assert_array_equal(a, b)
    # a task's exception comes back as the serial loop raises it
    with pytest.raises(InvalidRunError, match="task 2 refused"):
        nb.sweep(_fails_on_the_third, range(5), n_jobs=2)


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None,
                    reason="dask.distributed is not installed (nambu_bch[parallel])")
def test_dask_local_cluster_equals_serial(serial, tmp_path):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      local_directory=str(tmp_path)) as cluster, Client(cluster) as client:
        parallel = nb.sweep(nb.check, TASKS, client=client)
        assert _views(parallel) == serial
        # a tuple task whose first item is callable stays a task, not a piece of Dask's graph
        assert nb.sweep(_apply_first, [(abs, -3), (abs, 4)], client=client) == [3, 4]
        # the default client when backend="dask" is named without one
        assert nb.sweep(abs, [-1, -2], backend="dask") == [1, 2]
        with pytest.raises(InvalidRunError, match="task 2 refused"):
            nb.sweep(_fails_on_the_third, range(5), client=client)


def _apply_first(f, x):
    return f(x)


@pytest.mark.parametrize("kwargs, words", [
    ({"function": 3}, "function must be callable"),
    ({"tasks": 5}, "tasks must be an iterable"),
    ({"tasks": "abc"}, "tasks must be an iterable"),
    ({"backend": "threads"}, "backend must be one of loky, dask, serial"),
    ({"n_jobs": 0}, "n_jobs must be an integer >= 1"),
    ({"n_jobs": 1.5}, "n_jobs must be an integer >= 1"),
    ({"client": object(), "backend": "loky"}, "client is a Dask client"),
])
def test_bad_arguments_are_one_line(kwargs, words):
    args = {"function": abs, "tasks": [1, 2], **kwargs}
    with pytest.raises(InvalidRunError) as info:
        nb.sweep(args.pop("function"), args.pop("tasks"), **args)
    assert words in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("backend, module", [("loky", "joblib"), ("dask", "distributed")])
def test_a_missing_backend_package_is_refused_in_one_line(monkeypatch, backend, module):
    monkeypatch.setitem(sys.modules, module, None)  # import then raises ImportError
    with pytest.raises(InvalidRunError) as info:
        nb.sweep(abs, [1, 2], backend=backend)
    message = str(info.value)
    assert f"needs the package {module}" in message and "nambu_bch[parallel]" in message and "\n" not in message


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None, reason="dask.distributed is not installed")
def test_dask_without_a_client_is_refused_in_one_line():
    import distributed

    try:
        distributed.get_client()
    except ValueError:  # no client in this process: the case under test
        pass
    else:
        pytest.skip("a Dask client is already running in this process")
    with pytest.raises(InvalidRunError, match="needs a cluster: pass client="):
        nb.sweep(abs, [1], backend="dask")
    with pytest.raises(InvalidRunError, match="client must be a distributed.Client"):
        nb.sweep(abs, [1], client="tcp://localhost:8786")
