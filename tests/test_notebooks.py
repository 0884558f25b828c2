"""The notebooks in notebooks/ execute without error (nbclient, kernel python3, per-cell timeout).

The notebooks are committed without outputs; this runs them top to bottom in a
fresh kernel whose working directory is the repository root, and checks that
results render as LaTeX (``text/latex`` outputs from ``_repr_latex_``).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

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


def test_notebooks_present():
    names = {p.stem for p in NOTEBOOKS}
    assert {"01_hamiltonian_warmup", "02_fi_route_ho3", "03_exact_and_figures", "04_beyond_the_paper", "05_speed_accuracy"} <= names
