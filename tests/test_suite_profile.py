"""tools/suite_profile.py: the report of a recorded run (the numbers docs/suite_time.md quotes)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

TOOL = Path(__file__).resolve().parents[1] / "tools" / "suite_profile.py"


def _tool():
    spec = importlib.util.spec_from_file_location("suite_profile_tool", TOOL)
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
