"""The two tiers of the suite (tests/conftest.py ``DEEP``; docs/suite_time.md): every entry names tests that exist.

A renamed test or parameter would otherwise move a whole table to the deep tier (a case kept by name that no longer
exists keeps nothing) or leave a deep entry matching nothing, without any test failing.
"""

from __future__ import annotations

import pytest


def _cases(collected, f, n):
    return {name[len(n) + 1:-1] if name != n else "" for file, name in collected
            if file == f and (name == n or name.startswith(n + "["))}


def test_every_deep_entry_and_kept_case_exists(request):
    collected = getattr(request.config, "nambu_bch_collected", None)
    deep = getattr(request.config, "nambu_bch_deep", None)
    if collected is None or deep is None:
        pytest.skip("tests/conftest.py did not record the collection")
    files = {f for f, _ in collected}
    checked = 0
    for f, n, keep in deep:
        if f not in files:  # a run of some files only
            continue
        cases = _cases(collected, f, n)
        if not cases:  # the file was collected in part (a node id, or -k before collection)
            continue
        checked += 1
        if not callable(keep):
            missing = [k for k in keep if k not in cases]
            assert not missing, f"tests/conftest.py DEEP keeps {missing} of {f}::{n}, which has no such case"
        else:
            assert any(keep(c) for c in cases), f"tests/conftest.py DEEP keeps no case of {f}::{n}"
    if not checked:
        pytest.skip("none of the files DEEP names was collected")


def test_diagonal_keeps_one_case_per_row():
    from conftest import _diagonal  # the helper only: a pure function of the id

    keep = _diagonal(19)
    rows = ["iterate-h", "check-x0", "ModifiedSolution.numeric()(t, x0)-t", "shadow_along-word"]
    for row in rows:
        assert sum(keep(f"{row}-{k}") for k in range(19)) == 1, row


def test_cli_run_subprocess_case_is_deep():
    """``cli_run``'s subprocess case is deep for every test that asks for the fixture, listed in DEEP or not."""
    from conftest import CLI_RUNNERS

    cases = {getattr(p, "values", (p,))[0]: getattr(p, "marks", ()) for p in CLI_RUNNERS}
    assert set(cases) == {"in-process", "subprocess"}
    assert [m.name for m in cases["subprocess"]] == ["deep"] and not cases["in-process"]




def test_every_long_and_deep_entry_names_a_test_function():
    """Each ``LONG`` and ``DEEP`` entry names a test function of its file, whatever this run collected: a renamed
    test would silently leave the deep tier (test_every_deep_entry_and_kept_case_exists cannot tell a renamed test
    from a file collected in part) or its ``LONG`` group (tests sharing a compiled loop or a shared result, run in a
    row by one worker)."""
    import re
    from pathlib import Path

    from conftest import DEEP, LONG

    here, functions = Path(__file__).parent, {}
    for f in {f for f, *_ in LONG + DEEP}:  # the def lines (parsing the ~60 files would take seconds)
        if f.startswith("test_"):
            functions[f] = set(re.findall(r"^[ \t]*def[ \t]+(test_\w+)", (here / f).read_text(encoding="utf-8"), re.M))
        else:  # a module of the package whose docstring examples are collected: its items are module.function
            (source,) = (here.parent / "nambu_bch").rglob(f)
            module = ".".join(source.relative_to(here.parent).with_suffix("").parts)
            functions[f] = {f"{module}.{name}" for name in
                            re.findall(r"^[ \t]*def[ \t]+(\w+)", source.read_text(encoding="utf-8"), re.M)}
    long_ = [(f, n) for f, n in LONG  # a name prefix; with a parameter id, the whole function name before it
             if not any(name == n.partition("[")[0] if "[" in n else name.startswith(n) for name in functions[f])]
    deep = [(f, n) for f, n, _ in DEEP if n not in functions[f]]
    assert not long_ and not deep, f"tests/conftest.py names no test function: LONG {long_}, DEEP {deep}"


def test_indexed_tier_lookup_is_the_first_matching_deep_entry(request):
    """conftest looks a test up in ``DEEP`` by (file, function name) (linear in the items); the answer is the
    definition's: the first ``DEEP`` entry of the file naming the test's function decides, by its kept cases."""
    from conftest import DEEP, _in_deep_tier, _index_tiers

    collected = getattr(request.config, "nambu_bch_collected", None)
    if collected is None:
        pytest.skip("tests/conftest.py did not record the collection")
    by_file = {}
    for f, n, keep in DEEP:
        by_file.setdefault(f, []).append((n, keep))
    deep_index, _ = _index_tiers()
    checked = 0
    for f, name in collected:
        for n, keep in by_file.get(f, ()):
            if name == n or name.startswith(n + "["):
                pid = name[len(n) + 1:-1] if name != n else ""
                expected = not (keep(pid) if callable(keep) else pid in keep)
                break
        else:
            expected = False
        assert _in_deep_tier(f, name, deep_index) == expected, (f, name)
        checked += 1
    assert checked == len(collected)
