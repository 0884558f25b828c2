"""Batches split across threads (``iterate(workers=...)``): the same bits for every number of threads.

Each state of a batch is advanced by the same compiled operations whichever thread runs it, so the samples
must be equal bit for bit to the one-thread run and to the single-trajectory loop; the threads only divide
the states into contiguous ranges (:func:`nambu_bch.numeric.kernels.column_ranges`).
"""

import importlib

import numpy as np
import pytest

import nambu_bch as nb
from nambu_bch.errors import InvalidRunError, NumericalRangeError
from nambu_bch.numeric.kernels import column_ranges

RNG = np.random.default_rng(7)
iterate_module = importlib.import_module("nambu_bch.numeric.iterate")  # the package re-exports the function


# each batch loop once: ho3/32123's plain and ho/TVT's Kahan batch loops (the fast tier's compiles of those kinds,
# test_numeric.py's test_batch_numba_numpy_and_single_agree_bitwise), Lotka-Volterra's two (deep, tests/conftest.py)
@pytest.mark.parametrize("model, word, kahan", [("ho3", "32123", False), ("ho", "TVT", True),
                                                ("lotka-volterra", "12321", False), ("lotka-volterra", "12321", True)])
def test_threads_give_the_one_thread_bits(model, word, kahan):
    S = nb.model(model)
    X = RNG.uniform(0.5, 1.5, (S.N, 1100))  # chunks of 256: five, split unevenly over the threads
    one = nb.iterate(S, word, 0.05, 60, X, every=7, kahan=kahan, backend="numba", workers=1)
    for workers in (2, 3, 8):
        assert np.array_equal(nb.iterate(S, word, 0.05, 60, X, every=7, kahan=kahan, backend="numba",
                                         workers=workers), one)
    single = nb.iterate(S, word, 0.05, 60, X[:, 1000], every=7, kahan=kahan, backend="numba")
    assert np.array_equal(one[:, :, 1000], single)


def test_threads_fill_the_callers_array_and_leave_x0_alone():
    X = RNG.uniform(0.5, 1.5, (3, 700))
    keep = X.copy()
    out = np.empty((4, 3, 700))
    got = nb.iterate("ho3", "32123", 0.1, 30, X, every=10, out=out, backend="numba", workers=2)
    assert got is out and np.array_equal(X, keep)
    assert np.array_equal(out, nb.iterate("ho3", "32123", 0.1, 30, X, every=10, backend="numba", workers=1))


def test_an_overflow_in_any_thread_is_reported():
    X = np.ones((3, 600))
    X[:, 550] = 1e300  # in the second thread's range: its count of non-finite samples must reach the caller
    with pytest.raises(NumericalRangeError):
        nb.iterate("lotka-volterra", "12321", 0.1, 50, X, backend="numba", workers=2, check_stable=False)


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2", True])
def test_workers_must_be_a_positive_integer(bad):
    with pytest.raises(InvalidRunError, match="workers"):
        nb.iterate("ho3", "32123", 0.1, 10, np.ones((3, 4)), workers=bad)


def test_ranges_cover_the_batch_at_chunk_boundaries():
    for batch in (0, 1, 255, 256, 257, 1000, 4096):
        for workers in (1, 2, 3, 16):
            ranges = column_ranges(batch, 256, workers)
            assert [b for lo, hi in ranges for b in range(lo, hi)] == list(range(batch))
            assert all(lo % 256 == 0 for lo, _ in ranges) and len(ranges) <= workers


def test_the_default_uses_threads_only_for_enough_work(monkeypatch):
    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)
    monkeypatch.setattr(iterate_module, "available_threads", lambda: 2)
    assert iterate_module.batch_workers(None, 10, 100) == 1  # 1000 trajectory-steps: not worth a thread
    assert iterate_module.batch_workers(None, 100_000, 100) == 2
    assert iterate_module.batch_workers(3, 10, 1) == 3  # an explicit count is taken as given


def test_sweep_tasks_and_numba_num_threads_limit_the_default(monkeypatch):
    from nambu_bch import parallel

    monkeypatch.setenv("NUMBA_NUM_THREADS", "1")
    assert iterate_module.available_threads() == 1
    monkeypatch.delenv("NUMBA_NUM_THREADS")
    # a sweep's task runs with one thread per process: the worker processes already share the cores
    assert parallel._apply_in_worker(iterate_module.available_threads, ()) == 1
    with iterate_module.single_threaded():
        assert iterate_module.batch_workers(None, 10**6, 10**3) == 1


def test_threads_scan_their_own_ranges_and_find_the_one_pass_extremes():
    """The guards' scan of a threaded batch runs on each thread's range of states; combined, the counts and the
    extreme states are those of one pass over the whole batch (the first state reaching an extreme wins, also
    when the tie spans two ranges), so the range check sees the same states for every number of threads."""
    from nambu_bch.numeric import kernel
    from nambu_bch.numeric.guards import scan_states

    rng = np.random.default_rng(11)
    X = rng.uniform(0.5, 1.5, (3, 5000)) * 10.0 ** rng.integers(-60, 60, (3, 5000))
    X[:, 4000] = X[:, 17]  # a tie across ranges: column 17 must win
    X[:, 2600] = X[:, 4900] = 0.0
    want = scan_states(X)
    kern = kernel("ho3", "32123")
    for workers in (1, 2, 3, 8):
        got = kern.scan(X, workers)
        assert got[:2] == want[:2] and np.array_equal(got[2], want[2])
    Y = X.copy()
    Y[0, 10], Y[2, 4999], Y[1, 3000] = np.nan, 1e-310, np.inf  # in the first, the last and a middle range
    assert kern.scan(Y, 3)[:2] == scan_states(Y)[:2] == (2, 1)


def test_the_batch_loop_scans_x0_as_it_loads_it():
    """A large compiled batch makes no pass of its own over x0: the loop extends the guards' scan chunk by chunk
    (numeric.scan.scan_into) and finds the one-pass counts and extreme states for every chunk size and number of
    threads -- so the range check sees the states a separate pass would give it, and the samples keep their bits."""
    from nambu_bch.numeric import kernel
    from nambu_bch.numeric.guards import scan_states

    rng = np.random.default_rng(12)
    X = rng.uniform(0.5, 1.5, (3, 5000)) * 10.0 ** rng.integers(-60, 60, (3, 5000))
    X[:, 4000] = X[:, 17]
    X[:, 2600] = 0.0
    want = scan_states(X)
    kern = kernel("ho3", "32123")
    K = kern.constants(0.01)
    for chunk, workers in ((256, 1), (100, 3), (5000, 2)):
        scanned, out = {}, np.empty((2, 3, 5000))
        kern.run_batch(X, K, 1, 1, out, chunk=chunk, start=True, back=False, workers=workers, scanned=scanned)
        assert scanned["result"][:2] == want[:2] and np.array_equal(scanned["result"][2], want[2])
        assert np.array_equal(out, nb.iterate("ho3", "32123", 0.01, 1, X, backend="numpy", check_stable=False))


def test_a_large_batch_runs_without_a_separate_scan(monkeypatch):
    """The compiled batch path never calls Kernel.scan (the pass the fused loop replaces); bad states of x0 are
    still refused with the message of the checked-up-front path, wherever they are."""
    from nambu_bch.numeric.kernels import Kernel

    X = RNG.uniform(0.5, 1.5, (3, iterate_module.SCAN_BATCH + 300))
    want = nb.iterate("ho3", "32123", 0.1, 20, X, every=5, backend="numpy")
    monkeypatch.setattr(Kernel, "scan", lambda *a, **k: pytest.fail("a separate scan of x0"))
    for workers in (1, 2):
        assert np.array_equal(nb.iterate("ho3", "32123", 0.1, 20, X, every=5, backend="numba", workers=workers), want)
    for col, value, message in ((4300, np.nan, "non-finite value nan"), (5, -np.inf, "non-finite value -inf"),
                                (4395, 1e-310, "below the smallest normal"), (2000, 1e200, "overflows float64")):
        Y = X.copy()
        Y[1, col] = value
        for workers in (1, 2):
            with pytest.raises(NumericalRangeError, match=message):
                nb.iterate("ho3", "32123", 0.1, 20, Y, every=5, backend="numba", workers=workers)
