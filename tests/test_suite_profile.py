"""tools/suite_profile.py: the report of a recorded run (the numbers docs/suite_time.md quotes)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

TOOL = Path(__file__).resolve().parents[1] / "tools" / "suite_profile.py"


def _tool(path=TOOL):
    spec = importlib.util.spec_from_file_location(path.stem + "_tool", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_report_sums_tests_per_worker_and_file_and_lists_compiles(tmp_path):
    records = {
        "gw0": [{"k": "start", "cpu": 0.5, "t": 0, "load": [1.0, 1.0, 1.0]},
                {"k": "test", "test": "tests/test_a.py::test_x", "own": 2.0, "ch": 0.5, "wall": 2.6},
                {"k": "numba", "test": "tests/test_a.py::test_x", "fn": "m.run", "cpu": 1.25}],
        "gw1": [{"k": "test", "test": "tests/test_b.py::test_y", "own": 1.0, "ch": 0.0, "wall": 1.0},
                {"k": "test", "test": "tests/test_a.py::test_z", "own": 0.25, "ch": 0.0, "wall": 0.3}],
    }
    for worker, lines in records.items():
        (tmp_path / f"{worker}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    text = _tool().report(tmp_path, n_tests=2, n_files=5)
    assert text.splitlines()[0] == "tests 3, per-test CPU 3.8 s (own 3.2, children 0.5)"
    assert "  gw0: 2.5 s" in text and "  gw1: 1.2 s" in text and "gw0 start: CPU 0.5 s, load 1.0" in text
    files = text.split("--- files\n")[1].split("\n--- tests")[0].splitlines()
    assert files == ["    2.8 tests/test_a.py", "    1.0 tests/test_b.py"]
    assert "  2.00   0.50 tests/test_a.py::test_x" in text and "test_z" not in text.split("--- tests")[1].split("---")[0]
    assert text.endswith("--- numba compiles: 1, 1.2 s\n  1.25 m.run  <- tests/test_a.py::test_x")


def test_compiles_of_the_test_that_first_imports_numba_are_recorded(tmp_path, monkeypatch):
    """The dispatcher is patched as its module is executed (a finder on sys.meta_path), not only between tests: a
    stand-in module under another name, imported during a "test", has its compile recorded with that test."""
    import sys

    tool = _tool()
    name = "suite_profile_stand_in_dispatcher"
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / f"{name}.py").write_text(
        "class Dispatcher:\n"
        "    def __init__(self, fn):\n"
        "        self.py_func = fn\n"
        "    def compile(self, sig):\n"
        "        import time\n"
        "        end = time.process_time() + 0.06\n"  # above the plugin's 0.05 s of CPU
        "        while time.process_time() < end:\n"
        "            pass\n")
    monkeypatch.syspath_prepend(str(tmp_path / "src"))
    monkeypatch.setattr(tool, "_DIR", str(tmp_path / "records"))
    monkeypatch.setattr(tool, "_WORKER", "main")  # under xdist it names the worker
    monkeypatch.setattr(tool, "_DISPATCHER", name)
    monkeypatch.setattr(tool, "_state", {"test": "tests/test_a.py::test_first", "depth": 0, "file": None})
    monkeypatch.setattr(sys, "meta_path", list(sys.meta_path))
    monkeypatch.delitem(sys.modules, name, raising=False)
    tool.pytest_configure(None)
    module = __import__(name)
    module.Dispatcher(test_compiles_of_the_test_that_first_imports_numba_are_recorded).compile(("float64",))
    tool._state["file"].close()
    records = [json.loads(line) for line in (tmp_path / "records" / "main.jsonl").read_text().splitlines()]
    assert [r["k"] for r in records] == ["start", "numba"]
    assert records[1]["test"] == "tests/test_a.py::test_first" and records[1]["cpu"] > 0.05
    assert records[1]["fn"].endswith("test_compiles_of_the_test_that_first_imports_numba_are_recorded")


def test_report_names_a_loop_compiled_more_than_once_and_where(tmp_path):
    """A loop compiled twice in one cache directory (two workers at once) and a second fast-math variant of a function
    (fma=True's "+contract") are told apart: the variant is its own loop, the repeat is listed with worker and test."""
    records = {
        "gw0": [{"k": "numba", "test": "t.py::test_a", "fn": "m.run_batch", "cpu": 2.5, "variant": "", "where": "/c"},
                {"k": "numba", "test": "t.py::test_f", "fn": "m.run_batch", "cpu": 2.0, "variant": "+contract",
                 "where": "/c"}],
        "gw1": [{"k": "numba", "test": "t.py::test_b", "fn": "m.run_batch", "cpu": 2.25, "variant": "", "where": "/c"},
                {"k": "numba", "test": "t.py::test_p", "fn": "m.run", "cpu": 0.5, "variant": "", "where": "/tmp/1"},
                {"k": "numba", "test": "t.py::test_q", "fn": "m.run", "cpu": 0.25, "variant": "", "where": "/tmp/2"}],
    }
    for worker, lines in records.items():
        (tmp_path / f"{worker}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    text = _tool().report(tmp_path)
    assert "  2.00 m.run_batch+contract  <- t.py::test_f" in text
    assert text.split("--- compiled more than once\n")[1].splitlines() == [
        "  4.75 m.run_batch: 2 times, one directory",
        "         2.50 gw0 t.py::test_a",
        "         2.25 gw1 t.py::test_b",
        "  0.75 m.run: 2 times, 2 directories",
        "         0.50 gw1 t.py::test_p",
        "         0.25 gw1 t.py::test_q"]


def test_compile_cost_takes_triples_and_says_how_otherwise(capsys):
    """tools/compile_cost.py (docs/suite_time.md's per-kind compile table): arguments come in triples; anything else
    is its usage line and exit 2, before numba or the package is imported."""
    tool = _tool(TOOL.with_name("compile_cost.py"))
    for argv in ([], ["ho3", "32123"], ["ho3", "32123", "run", "ho"]):
        assert tool.main(argv) == 2
        assert capsys.readouterr().err.startswith("usage: compile_cost.py SYSTEM WORD LOOP")


def test_report_gives_the_runs_wall_time_each_collection_and_the_exit(tmp_path):
    records = {
        "main": [{"k": "start", "cpu": 0.5, "t": 100.0}, {"k": "end", "cpu": 9.0, "t": 160.0}],
        "gw0": [{"k": "start", "cpu": 0.5, "t": 101.0}, {"k": "collected", "cpu": 8.0, "t": 109.5},
                {"k": "end", "cpu": 50.0, "t": 158.0}],
        "gw1": [{"k": "start", "cpu": 0.5, "t": 101.5}, {"k": "collected", "cpu": 8.0, "t": 110.0},
                {"k": "end", "cpu": 49.0, "t": 159.5}],
    }
    for worker, lines in records.items():
        (tmp_path / f"{worker}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    text = _tool().report(tmp_path)
    assert "  wall: the run 60.0 s" in text
    assert "  wall: gw0 collection 8.5 s" in text and "  wall: gw1 collection 8.5 s" in text
    assert "  wall: the last worker's end -> the run's end 0.5 s" in text
