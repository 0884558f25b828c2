r"""Every LaTeX output compiles with pdflatex, without overfull lines (docs/latex.md).

Skipped only when no ``pdflatex`` is installed (CI installs TeX Live, see .ci/run).  Each
document is compiled with ``-halt-on-error``; the log must show no error and no
``Overfull \hbox`` (a line running off the page).  Both forms are compiled: the CLI's
``--standalone`` document, and the API's ``aligned`` block (``sympy.latex(result)``) put in
``\[ ... \]`` as the docs say.
"""

import shutil
import subprocess

import pytest
import sympy

from nambu_bch import (
    System,
    conserved_quantities,
    effective_field,
    exact_shadow_hamiltonians,
    formal_bch,
    model,
)
from nambu_bch.cli import main
from nambu_bch.errors import InvalidSystemError
from nambu_bch.printing import PREAMBLE, latex_text

import shared_results as shared

PDFLATEX = shutil.which("pdflatex")
pytestmark = pytest.mark.skipif(PDFLATEX is None, reason="no pdflatex installed (CI installs TeX Live)")


def compile_tex(source, tmp_path, name="doc"):
    """pdflatex ``source``; returns the log (asserting success)."""
    tex = tmp_path / f"{name}.tex"
    tex.write_text(source)
    done = subprocess.run([PDFLATEX, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape", tex.name],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    log = (tmp_path / f"{name}.log").read_text(errors="replace")
    assert done.returncode == 0, f"pdflatex failed on {name}:\n{done.stdout[-3000:]}"
    assert (tmp_path / f"{name}.pdf").exists()
    return log


def assert_fits(log, name):
    overfull = [line for line in log.splitlines() if "Overfull \\hbox" in line]
    assert not overfull, f"{name}: lines run off the page: {overfull}"


CLI = [
    ("shadow",),                                                          # Eqs. (SH12321c), (SG12321c)
    ("shadow", "--model", "ho", "--integrator", "TVT", "--order", "4"),   # N = 2 (Eq. SHPV1 and h^4)
    ("shadow", "--model", "rigid-body", "--integrator", "123"),          # obstructed: the certificate
    ("shadow", "--model", "rigid-body", "--integrator", "123", "--route", "fi", "--order", "1"),
    ("shadow", "--model", "rigid-body"),                                  # long factored coefficients
    ("shadow", "--model", "lotka-volterra"),
    ("shadow", "--integrator", "32123", "--route", "fi"),
    ("conserved",), ("conserved", "--integrator", "31213"), ("conserved", "--model", "rigid-body"),  # Table (table)
    ("conserved", "--model", "ho", "--integrator", "forest-ruth"),     # rational in h, radicals: split factors
    ("exact", "--order", "4"), ("exact", "--model", "ho", "--integrator", "lie-trotter", "--order", "3"),
    ("bch",), ("bch", "--field", "--terms"), ("bch", "--model", "ho", "--integrator", "TVT", "--order", "4"),
    ("fi",), ("fi", "--model", "ho3", "--integrator", "12321"),          # Eqs. (1AX)-(2BY), (CL5)-(CL8)
    ("models", "--format", "latex"),
    ("shadow", "--H", "x2^2/2 + x1^4/4"),
]
HOSTILE = r"a_b}\input{/etc/hostname}%$&#~^\\"


@pytest.mark.parametrize("argv", CLI, ids=[" ".join(a) for a in CLI])
def test_cli_latex_compiles(argv, tmp_path, capsys):
    assert main([*argv, "--standalone"]) == 0
    document = capsys.readouterr().out
    assert document.startswith("\\documentclass") and document.rstrip().endswith("\\end{document}")
    assert "\\input" not in document and "\\text{h^" not in document and "**" not in document
    log = compile_tex(document, tmp_path)
    assert_fits(log, " ".join(argv))
    # the default output (no --standalone) is the same body: align* environments for a document with amsmath
    assert main(list(argv)) == 0
    fragment = capsys.readouterr().out
    assert fragment in document and fragment.lstrip().startswith("\\begin{align*}")


def test_api_blocks_compile_in_display_math(tmp_path):
    r"""``sympy.latex(result)`` is an ``aligned`` block: it compiles inside ``\[ ... \]`` (README: where it belongs)."""
    ho3 = model("ho3")
    objects = [
        shared.family("ho3", "12321"), shared.family("rigid-body", "123", 2),  # test_shadow's, computed once
        conserved_quantities(ho3, "32123"), exact_shadow_hamiltonians(ho3, "12321"),
        formal_bch("12321", 5), effective_field(ho3.splitting, "12321", 2),
    ]
    rb = model("rigid-body")  # a hostile name is refused at the door and neutralised by latex_text anyway
    with pytest.raises(InvalidSystemError):
        System(rb.coordinates, rb.hamiltonians, rb.parameters, name=HOSTILE, split=rb.split)
    assert "\\input" not in latex_text(HOSTILE) and r"\_" in latex_text(HOSTILE)
    body = "\n".join("\\[\n" + sympy.latex(obj) + "\n\\]" for obj in objects)
    log = compile_tex(PREAMBLE + "\\begin{document}\n" + body + "\n\\end{document}\n", tmp_path, "api")
    assert_fits(log, "api blocks")
    # the Jupyter form is the same block in $$ ... $$
    assert all(obj._repr_latex_() == "$$" + sympy.latex(obj) + "$$" for obj in objects)
