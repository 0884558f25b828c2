"""Runge--Kutta methods on the command line and in tableau files: each new path in process and as a subprocess
(conftest's ``cli_run``), bad input in process.

Tableau file: Lobatto IIIC with s = 2 (Hairer, Wanner, *Solving ODEs II*, Table IV.5.11: A = [[1/2, -1/2], [1/2, 1/2]],
b = (1/2, 1/2), order 2); its order conditions of order 3 fail, so claiming 3 is refused.
"""

from __future__ import annotations

import json

import pytest

from nambu_bch.cli import main
from nambu_bch.errors import InvalidCompositionError
from nambu_bch.integrators.runge_kutta import TABLEAUX
from nambu_bch.integrators.tableau_file import load_tableau
from nambu_bch.shadow import shadow_hamiltonians

LOBATTO = '''name = "lobatto3c"
reference = "Lobatto IIIC, s = 2; Hairer-Wanner II, Table IV.5.11"
order = 2
A = [["1/2", "-1/2"], ["1/2", "1/2"]]
b = ["1/2", "1/2"]
c = ["0", "1"]
'''
GAUSS4 = '''name = "my-gauss4"
order = 4
A = [["1/4", "1/4 - sqrt(3)/6"], ["1/4 + sqrt(3)/6", "1/4"]]
b = ["1/2", "1/2"]
'''


def _file(tmp_path, text, name="t.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_shadow_integrator_gauss4_json_subprocess(tmp_path, cli_run):
    r = cli_run("shadow", "--integrator", "gauss4", "--model", "ho3", "--order", "4", "--format", "json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    data = json.loads(r.stdout)
    assert data["integrator"] == "gauss4" and data["exists"] is True and data["free_parameters"] == ["alpha"]


def test_shadow_tableau_file_subprocess(tmp_path, cli_run):
    path = _file(tmp_path, LOBATTO)
    r = cli_run("shadow", "--tableau", path, "--model", "ho", "--format", "text", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "lobatto3c on ho, order 2" in r.stdout and "H_S = H + h**2*(" in r.stdout


def test_check_integrator_midpoint_subprocess(tmp_path, cli_run):
    r = cli_run("check", "--model", "rigid-body", "--integrator", "midpoint", "--steps", "100", "--format", "json",
             cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    errors = json.loads(r.stdout)["max_abs_error"]
    assert errors["H"] < 1e-13 and errors["G"] < 1e-13          # quadratic invariants: kept to round-off


def test_compare_across_families_subprocess(tmp_path, cli_run):
    path = _file(tmp_path, LOBATTO)
    r = cli_run("compare", "--model", "ho", "--integrator", "121", "--integrator", "gauss4", "--integrator", "kahan",
             "--tableau", path, "--t-end", "1", "--step-counts", "10,20", "--format", "json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rows = {row["integrator"]: row for row in json.loads(r.stdout)["integrators"]}
    assert set(rows) == {"121", "gauss4", "kahan", "lobatto3c"}
    assert rows["kahan"]["cost"] == 2.0 and rows["gauss4"]["order"] == 4 and rows["gauss4"]["cost"] > 2


def test_tableau_file_is_checked(tmp_path):
    T = load_tableau(_file(tmp_path, GAUSS4))
    assert T.A == TABLEAUX["gauss4"].A and T.order == 4 and T.symmetric
    assert load_tableau(_file(tmp_path, LOBATTO)).c == (0, 1)


@pytest.mark.parametrize("text, fragment", [
    (LOBATTO.replace("order = 2", "order = 3"), "the claimed order 3 fails the order condition"),
    (LOBATTO.replace('c = ["0", "1"]', 'c = ["0", "1/2"]'), "c[2] = '1/2' is not the row sum 1 of A"),
    (LOBATTO.replace('"-1/2"', '-0.5'), "give exact coefficients as strings"),
    (LOBATTO.replace('"-1/2"', '"__import__(1)"'), "A[1][2]"),
    (LOBATTO + "quadratic_only = true\n", "unknown key(s) quadratic_only"),
    (LOBATTO.replace('b = ["1/2", "1/2"]', 'b = ["1/2"]'), "A must be a list of 1 rows"),
    ("name = 'x'\n", "missing key(s) order, A, b"),
    ("name = = 1", "not valid TOML"),
])
def test_bad_tableau_file_is_one_line(tmp_path, capsys, text, fragment):
    path = _file(tmp_path, text)
    with pytest.raises(InvalidCompositionError, match=None) as info:
        load_tableau(path)
    assert fragment in str(info.value) and "\n" not in str(info.value)
    code = main(["shadow", "--model", "ho", "--tableau", str(path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and fragment in err[0]


@pytest.mark.parametrize("argv, fragment", [
    (["shadow", "--integrator", "midpoint", "--tableau", "{f}"], "either --integrator or --tableau"),
    (["shadow", "--tableau", "{d}"], "--tableau {d}: a directory"),
    (["shadow", "--tableau", "{d}/absent.toml"], "cannot read the file"),
    (["shadow", "--integrator", "midpoint", "--route", "fi"], "use route='direct'"),
    (["check", "--model", "fpu-beta", "--integrator", "kahan", "--steps", "2"], "only on quadratic vector fields"),
    (["check", "--model", "rigid-body", "--integrator", "gauss6", "--h", "50", "--steps", "2", "--x0", "3,2,1",
      "--param", "I1=1", "--param", "I2=2", "--param", "I3=3"],
     "(h = 50); lower h"),
    (["fi", "--integrator", "gauss4"], "is a Runge-Kutta method, not a composition"),
])
def test_bad_runge_kutta_requests_are_one_line(tmp_path, capsys, argv, fragment):
    f = _file(tmp_path, LOBATTO)
    argv = [a.format(f=f, d=tmp_path) for a in argv]
    code = main(argv)
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in captured.err and captured.out == ""
    assert fragment.format(d=tmp_path) in lines[0], lines[0]


def test_divergence_certifies_no_pair():
    """Implicit midpoint on the rigid body (docs/runge_kutta.md): H and G are kept, yet div Z_2 != 0 -- certified."""
    F = shadow_hamiltonians("rigid-body", "midpoint", order=2)
    assert F.exists is False and F.evidence["method"] == "divergence"
    assert "x1*x2*x3*(I1 - I2)*(I1 - I3)*(I2 - I3)/(2*I1**2*I2**2*I3**2)" in F.evidence["reason"]


def test_check_tableau_and_latex_in_process(tmp_path, capsys):
    """check --tableau runs the file's method; shadow --format latex prints the family of a Runge--Kutta method."""
    path = _file(tmp_path, LOBATTO)
    assert main(["check", "--model", "ho", "--tableau", str(path), "--steps", "50", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["integrator"] == "lobatto3c" and data["max_abs_error"]["H"] > 0
    assert main(["shadow", "--model", "lotka-volterra", "--integrator", "midpoint", "--format", "latex"]) == 0
    out = capsys.readouterr().out
    assert "H_{S} &= H + h^{2}" in out and "O(h^{4})" in out
