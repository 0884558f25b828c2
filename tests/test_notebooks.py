"""The notebooks in notebooks/ execute without error or warning (nbclient, kernel python3, per-cell timeout).

The notebooks are committed without outputs; this runs them top to bottom in a
fresh kernel whose working directory is the repository root, and checks that
results render as LaTeX (``text/latex`` outputs from ``_repr_latex_``) and that no
output cell shows a warning (tqdm's ``IProgress not found`` when ipywidgets is missing).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))
CELL_TIMEOUT = 180


def _ensure_kernel():
    """Install the ``python3`` kernel spec of this interpreter if no kernel spec of that name exists."""
    from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel

    try:
        KernelSpecManager().get_kernel_spec("python3")
    except NoSuchKernel:  # pragma: no cover - depends on the environment
        from ipykernel.kernelspec import install

        install(user=True, kernel_name="python3")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes(path, monkeypatch):
    # imported here, not at collection: jupyter's client costs every pytest process ~0.35 s to import, and the fast
    # tier runs one notebook in one of the two workers
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    _ensure_kernel()
    monkeypatch.setenv("PYTHONPATH", str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    book = nbformat.read(path, as_version=4)
    assert all(not c.get("outputs") for c in book.cells if c.cell_type == "code"), f"{path.name} is committed with outputs"
    client = nbclient.NotebookClient(
        book, timeout=CELL_TIMEOUT, kernel_name="python3", resources={"metadata": {"path": str(REPO)}},
    )
    client.execute()
    errors = [o for c in book.cells if c.cell_type == "code" for o in c.outputs if o.get("output_type") == "error"]
    assert not errors, errors
    latex = [o for c in book.cells if c.cell_type == "code" for o in c.outputs if "text/latex" in o.get("data", {})]
    assert latex, f"{path.name}: no result rendered as LaTeX"
    warned = [text for text in _output_texts(book) if any(w in text for w in WARNING_TEXT)]
    assert not warned, f"{path.name}: warnings in the output cells: {warned}"


#: Text that no output cell may contain (tqdm's ``IProgress not found`` without ipywidgets, any Python warning).
WARNING_TEXT = ("Warning", "IProgress", "warn(")


def _output_texts(book) -> list:
    """Every text an executed notebook shows: streams (stdout, stderr) and the plain-text form of results."""
    out = []
    for cell in book.cells:
        for o in cell.get("outputs", []) if cell.cell_type == "code" else []:
            if o.get("output_type") == "stream":
                out.append(o.get("text", ""))
            else:
                text = o.get("data", {}).get("text/plain", "")
                out.append("".join(text) if isinstance(text, list) else text)
    return out


def test_warning_scan_sees_tqdm_s_message():
    """The scan of the test above finds tqdm's warning where a kernel prints it (stderr stream)."""
    nbformat = pytest.importorskip("nbformat")
    book = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("x")])
    book.cells[0].outputs = [nbformat.v4.new_output("stream", name="stderr",
                                                    text="TqdmWarning: IProgress not found. Please update jupyter and ipywidgets.")]
    assert any(w in t for t in _output_texts(book) for w in WARNING_TEXT)


def test_progress_bar_is_plain_without_ipywidgets(monkeypatch):
    """Without ipywidgets the default stream gets tqdm's text bar (tqdm.auto is not imported, so it cannot warn)."""
    import sys
    import warnings

    from tqdm.std import tqdm as plain

    from nambu_bch import progress

    monkeypatch.setattr(progress, "widgets_available", lambda: False)
    monkeypatch.setattr(progress, "_in_jupyter", lambda: True)
    monkeypatch.delitem(sys.modules, "tqdm.auto", raising=False)
    monkeypatch.delitem(sys.modules, "tqdm.autonotebook", raising=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        bar = progress._bar(10, "run", None, 0.0, 0.0, "step")
    try:
        assert type(bar) is plain and "tqdm.auto" not in sys.modules
    finally:
        bar.close()


def test_notebooks_present():
    names = {p.stem for p in NOTEBOOKS}
    assert {"01_hamiltonian_warmup", "02_fi_route_ho3", "03_exact_and_figures", "04_beyond_the_paper", "05_speed_accuracy"} <= names
