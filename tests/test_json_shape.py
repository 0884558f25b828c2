"""One JSON shape for the API and the command line: ``--format json`` prints the result's ``to_dict()`` and nothing else.

For every subcommand that prints symbolic or diagnostic results (shadow on both routes, conserved, exact
with and without ``--order``, check, bch with and without ``--field --terms``, fi with and without a
system and with ``--order``), the printed document equals the result's ``to_dict()`` after the JSON round
trip, and the README's read-back recipe works on ``to_dict()`` from Python.
"""

from __future__ import annotations

import json

import pytest
import sympy

import nambu_bch as nb
from nambu_bch.cli import main
from nambu_bch.render import to_json


def cli_json(capsys, *argv) -> dict:
    assert main([*argv, "--format", "json"]) == 0
    return json.loads(capsys.readouterr().out)


def api_json(result, **kwargs) -> dict:
    """``result.to_dict()`` as the CLI would print it (the JSON round trip: tuples become lists, keys strings)."""
    return json.loads(to_json(result.to_dict(**kwargs)))


@pytest.mark.parametrize("argv, route", [
    (("--model", "ho3", "--integrator", "32123"), "direct"),
    (("--model", "ho3", "--integrator", "12321", "--order", "4"), "fi"),
    (("--model", "ho", "--integrator", "TVT", "--order", "4"), "direct"),
])
def test_shadow_cli_json_is_to_dict(capsys, argv, route):
    data = cli_json(capsys, "shadow", *argv, "--route", route)
    args = dict(zip(argv[::2], argv[1::2]))
    family = nb.shadow_hamiltonians(nb.model(args["--model"]), args["--integrator"], int(args.get("--order", 2)), route=route)
    assert data == api_json(family)
    assert data["parameters"] and ("fi_span" in data) and (data["fi_span"] is None) == (route == "direct")


def test_readme_read_back_recipe_works_on_to_dict():
    """README: names from ``coordinates + parameters``; the same recipe reads ``to_dict()`` from Python."""
    data = nb.shadow_hamiltonians(nb.model("ho3"), "32123").to_dict()
    names = {n: sympy.Symbol(n) for n in data["coordinates"] + data["parameters"] + ["h", "alpha"]}
    H_S = sympy.sympify(data["H_S"], locals=names)
    assert sympy.expand(H_S - nb.shadow_hamiltonians(nb.model("ho3"), "32123").H_S) == 0


def test_conserved_cli_json_is_to_dict(capsys):
    data = cli_json(capsys, "conserved", "--model", "ho3", "--integrator", "31213")
    assert data == api_json(nb.conserved_quantities(nb.model("ho3"), "31213"))
    assert data["parameters"] == ["m", "omega"] and data["integrator"] == "31213"


@pytest.mark.parametrize("order", [None, 2])
def test_exact_cli_json_is_to_dict(capsys, order):
    argv = ("exact", "--model", "ho3", "--integrator", "12321", *(("--order", str(order)) if order else ()))
    data = cli_json(capsys, *argv)
    assert data == api_json(nb.exact_shadow_hamiltonians(nb.model("ho3"), "12321"), order=order)
    assert ("H_S_series" in data) == (order is not None)


def test_check_cli_json_is_to_dict_apart_from_timing(capsys):
    """check: the same report (the wall time is no part of the JSON)."""
    data = cli_json(capsys, "check", "--model", "ho3", "--integrator", "32123", "--h", "0.1", "--steps", "200",
                    "--x0", "1,1,1")
    report = nb.check(nb.model("ho3"), "32123", 0.1, 200, (1.0, 1.0, 1.0), params={"m": 1.0, "omega": 1.0})
    assert data == api_json(report)
    assert data["coordinates"] == ["x1", "x2", "x3"] and data["parameters"] == ["m", "omega"]


def test_fi_order_cli_json_is_to_dict(capsys):
    """fi --order K: the brackets' list (FIBrackets) prints its to_dict(), the limit applied to brackets and directions."""
    from nambu_bch.shadow.fi_route import fi_brackets

    data = cli_json(capsys, "fi", "--model", "ho3", "--integrator", "12321", "--order", "4", "--limit", "2")
    shown = fi_brackets(nb.model("ho3"), "12321", 4, limit=2)
    assert data == api_json(shown)
    assert data["total"] == shown.total == 6 and len(data["brackets"]) == 2 and data["parameters"] == ["m", "omega"]


@pytest.mark.parametrize("flags", [(), ("--field", "--terms")])
def test_bch_cli_json_is_to_dict(capsys, flags):
    from nambu_bch.bch.report import bch_report

    data = cli_json(capsys, "bch", "--model", "ho3", "--integrator", "12321", *flags)
    report = bch_report(nb.model("ho3"), nb.composition("12321"), 2, field=bool(flags), terms=bool(flags))
    assert data == api_json(report)
    assert ("X_eff" in data) == ("liouville_terms" in data) == bool(flags) and data["parameters"] == ["m", "omega"]


@pytest.mark.parametrize("argv", [(), ("--model", "ho3", "--integrator", "12321")])
def test_fi_cli_json_is_to_dict(capsys, argv):
    """fi: the eight forms alone, or with a system each h^2 double commutator in them (FIForms)."""
    from nambu_bch.shadow.fi_route import FIForms, fi_forms

    data = cli_json(capsys, "fi", *argv)
    S = nb.model("ho3")
    result = fi_forms(S, "12321") if argv else FIForms(S, nb.composition("12321"))
    assert data == api_json(result)
    assert len(data["forms"]) == 8 and ("representations" in data) == bool(argv)
