"""The density bracket on the command line and in JSON: Kahan's method on the Euler top in two Nambu brackets.

Sources: docs/runge_kutta.md, "The density bracket" (the table: standard bracket obstructed at h^2 with the
certificate value -(I1-I2)(I1-I3)(I2-I3)/(2 I1^2 I2^2 I3^2); density rho = phi, the invariant measure dx/phi of
Kahan's map, admits a pair); Celledoni, McLachlan, Owren, Quispel, J. Phys. A 46 (2013) 025201 (modified
measures of Kahan's method).  The JSON is validated against docs/schema/nambu-bch.schema.json ($defs/density_bracket).
"""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import sympy

from nambu_bch.cli._main import main
from nambu_bch.shadow import density_brackets

SCHEMA = json.loads((Path(__file__).resolve().parents[1] / "docs" / "schema" / "nambu-bch.schema.json").read_text())


@pytest.fixture(scope="module")
def kahan_json():
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["shadow", "--model", "rigid-body", "--integrator", "kahan", "--density", "--format", "json"]) == 0
    return json.loads(out.getvalue())


def test_json_names_the_bracket_with_a_pair_and_certifies_the_other(kahan_json):
    data = kahan_json
    schema = {"$schema": SCHEMA["$schema"], "$defs": SCHEMA["$defs"], "$ref": "#/$defs/density_bracket"}
    jsonschema.Draft202012Validator(schema).validate(data)
    assert data["admits"] == ["density"] and data["integrator"] == "kahan" and data["order"] == 2
    standard, weighted = data["brackets"]["standard"], data["brackets"]["density"]
    assert standard["exists"] is False and standard["evidence"]["method"] == "divergence"
    I1, I2, I3 = sympy.symbols("I1 I2 I3")
    value = sympy.sympify(standard["certificate"]["value"], locals={"I1": I1, "I2": I2, "I3": I3})
    assert sympy.expand(value + (I1 - I2) * (I1 - I3) * (I2 - I3) / (2 * I1**2 * I2**2 * I3**2)) == 0
    assert weighted["exists"] is True and weighted["certificate"] is None


def test_density_is_kahans_invariant_measure(kahan_json):
    from nambu_bch import model
    from nambu_bch.bseries import euler_top_density

    S = model("rigid-body")
    names = {str(s): s for s in (*S.coordinates, *S.parameters, sympy.Symbol("h"))}
    assert sympy.expand(sympy.sympify(kahan_json["density"], locals=names) - euler_top_density(S)) == 0


def test_refusals_are_one_line(capsys):
    for argv, why in ((["--integrator", "midpoint"], "--density takes --integrator kahan"),
                      (["--integrator", "kahan", "--route", "fi"], "--route fi"),
                      (["--model", "ho3", "--integrator", "kahan"], "not an Euler top")):
        argv = (["--model", "rigid-body"] if "--model" not in argv else []) + argv
        assert main(["shadow", *argv, "--density"]) == 2
        err = capsys.readouterr().err.strip()
        assert why in err and "\n" not in err


def test_api_with_a_given_density_of_one_is_the_standard_question_twice():
    D = density_brackets("ho3", "midpoint", 2, density=1)
    assert D.admits == ("standard", "density") and D.standard.H_S == D.weighted.H_S
    assert D.to_text().startswith("midpoint on ho3, order 2: a pair in the standard bracket and the density bracket")
    assert D.to_latex().startswith(r"\begin{gathered}") and D.to_dict()["kind"] == "density-bracket"
