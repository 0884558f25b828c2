"""The CLI's JSON output against its JSON Schema (docs/schema/nambu-bch.schema.json, docs/json.md).

Each document is checked twice: by the schema (shape) and by sympy (content: the
series by order re-sum to the flat expressions; the brackets read back).
"""

import copy
import json
from pathlib import Path

import jsonschema
import pytest
import sympy

from nambu_bch.cli import main

SCHEMA = json.loads((Path(__file__).resolve().parents[1] / "docs" / "schema" / "nambu-bch.schema.json").read_text())
h = sympy.Symbol("h")


def validator(kind):
    schema = {"$schema": SCHEMA["$schema"], "$defs": SCHEMA["$defs"], "$ref": f"#/$defs/{kind}"}
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    return jsonschema.Draft202012Validator(schema)


def run(capsys, *argv):
    assert main([*argv, "--format", "json"]) == 0
    return json.loads(capsys.readouterr().out)


def symbols(data):
    names = [*data["coordinates"], *data["parameters"], "h", "alpha"]
    return {n: sympy.Symbol(n) for n in names}


def read(data, text):
    return sympy.sympify(text, locals=symbols(data))


def resum(data, series):
    return sum((read(data, c) * h ** int(k) for k, c in series.items()), sympy.Integer(0))


def test_schema_is_a_valid_draft_2020_12_schema():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    assert set(SCHEMA["$defs"]) >= {"shadow", "conserved", "exact", "bch", "fi", "models"}


def test_shadow_series_by_order_resum_to_H_S_and_G_S(capsys):
    """Eqs. (SH12321c), (SG12321c): the h^0 and h^2 coefficients; ho TVT (N = 2) through h^4 (Eq. SHPV1 and beyond)."""
    for argv in (("shadow",), ("shadow", "--integrator", "32123", "--route", "fi"),
                 ("shadow", "--model", "ho", "--integrator", "TVT", "--order", "4")):
        data = run(capsys, *argv)
        validator("shadow").validate(data)
        names = ["H_S", "G_S"] if data["G"] is not None else ["H_S"]
        assert sorted(data["series"]) == sorted(names)
        for name in names:
            assert sympy.expand(resum(data, data["series"][name]) - read(data, data[name])) == 0
            assert read(data, data["series"][name]["0"]) == read(data, data[name[0]])  # h^0: the Hamiltonian itself
        odd = [k for name in names for k in data["series"][name] if int(k) % 2]
        assert not odd  # symmetric words: odd powers vanish (HLW Thm. IX.3.2)
        assert data["certificate"] is None and data["gauge"]


def test_shadow_gauge_directions_are_in_the_kernel(capsys):
    """Every gauge direction (dH, dG) at h^2 satisfies X_{dH,G} + X_{H,dG} = 0 (the kernel of Eq. L2's operator)."""
    from nambu_bch import model
    from nambu_bch.algebra import liouville_field

    data = run(capsys, "shadow")
    validator("shadow").validate(data)
    system = model("ho3")
    H, G = system.hamiltonians
    for direction in data["gauge"]["2"]:
        dH, dG = read(data, direction["dH"]), read(data, direction["dG"])
        total = liouville_field(system.algebra, dH, G) + liouville_field(system.algebra, H, dG)
        assert total.is_zero(), direction


def test_obstructed_shadow_has_the_certificate_as_data(capsys, monkeypatch):
    """ho3 under 123 (non-symmetric): obstructed at h^1 (test_shadow.py's non-symmetric words); the certificate is
    data.  The README's rigid body under 123 is the same JSON over QQ(I1, I2, I3) at three times the cost; its
    obstruction at h^1 is test_shadow.py's test_rigid_body_non_symmetric_word_is_obstructed_at_h1."""
    # the measured drift's runs on the interpreter (the same bits): compiling their loop is no concern of the schema
    monkeypatch.setenv("NAMBU_BCH_DISABLE_NUMBA", "1")
    data = run(capsys, "shadow", "--model", "ho3", "--integrator", "123")
    validator("shadow").validate(data)
    assert data["exists"] is False and data["H_S"] is None and data["series"] == {}
    cert = data["certificate"]
    assert cert["kind"] == "left-null-functional" and cert["order"] == data["failed_order"] == 1
    assert {t["component"] for t in cert["terms"]} <= set(data["coordinates"])
    assert read(data, cert["value"]) != 0
    # the same numbers as the human-readable obstruction text
    assert str(read(data, cert["value"])) in data["obstruction"] or cert["value"] in data["obstruction"]
    fi = run(capsys, "shadow", "--model", "ho3", "--integrator", "123", "--route", "fi", "--order", "1")
    validator("shadow").validate(fi)
    assert fi["exists"] is False and fi["certificate"]["kind"] == "fi-rows"


def test_conserved_series_is_table_row(capsys):
    """Table (table), row 31213: H_c = H - h^2 omega^2 x2^2/(4m), G_c = G - h^2 x2^2/(4 m^2)."""
    data = run(capsys, "conserved", "--integrator", "31213")
    validator("conserved").validate(data)
    m, omega, x2 = (sympy.Symbol(n) for n in ("m", "omega", "x2"))
    assert read(data, data["series"]["H_c"]["2"]) == -omega**2 * x2**2 / (4 * m)
    assert read(data, data["series"]["G_c"]["2"]) == -x2**2 / (4 * m**2)
    for name in ("H_c", "G_c"):
        assert sympy.expand(resum(data, data["series"][name]) - read(data, data[name])) == 0


def test_exact_series_and_remainder(capsys):
    """Eqs. (ESH12321), (ESG12321) through h^4; F(omega h) is even, so the remainder is O(h^6)."""
    data = run(capsys, "exact", "--order", "4")
    validator("exact").validate(data)
    assert data["remainder_power"] == 6 and set(data["series"]["H_S"]) == {"0", "2", "4"}
    assert sympy.expand(resum(data, data["series"]["H_S"]) - read(data, data["H_S_series"])) == 0
    assert sympy.expand(resum(data, data["series"]["G_S"]) - read(data, data["G_S_series"])) == 0
    # independently: the Taylor series of the closed form F(omega h)^alpha H_c
    exact = read(data, data["H_S"])
    taylor = sympy.series(exact, h, 0, 5).removeO()
    assert sympy.expand(taylor - read(data, data["H_S_series"])) == 0      # expanded Laurent polynomials: exact


def test_bch_terms_json_brackets_are_sympy_readable(capsys):
    """bch --terms: each bracket is text sympify reads back as nested lists of X(slots), the same tree (Eq. BCH4)."""
    data = run(capsys, "bch", "--field", "--terms")
    validator("bch").validate(data)
    X = sympy.Function("X")
    loc = {**symbols(data), "X": X}

    def as_tree(node):
        if isinstance(node, dict):
            return [as_tree(t) for t in node["bracket"]]
        if isinstance(node, int):
            return sympy.Symbol(f"X{node}")
        return X(*[read(data, s) for s in node])

    for item in data["liouville_terms"]:
        parsed = sympy.sympify(item["bracket"], locals=loc)
        assert parsed == as_tree(item["tree"]), item["bracket"]
        assert "\\" not in item["bracket"]  # not LaTeX
    for item in data["terms"]:
        assert sympy.sympify(item["bracket"]) == as_tree(item["tree"])
    assert len(data["X_eff"]) == 3  # Z_0, Z_1 (= 0, symmetric word), Z_2


def test_schema_rejects_malformed_documents(capsys):
    """The schema is not vacuous: wrong keys, wrong series, floats and unknown fields fail."""
    good = run(capsys, "shadow")
    v = validator("shadow")
    v.validate(good)
    broken = []
    for change in (
        lambda d: d.pop("series"),
        lambda d: d["series"]["H_S"].update({"x": "1"}),
        lambda d: d["series"]["H_S"].update({"4": 0.5}),
        lambda d: d.update({"unexpected": 1}),
        lambda d: d.update({"exists": False}),                  # then obstruction and failed_order are required
        lambda d: d["gauge"]["2"][0].update({"dQ": "1"}),
    ):
        d = copy.deepcopy(good)
        change(d)
        broken.append(not v.is_valid(d))
    assert all(broken), broken
    # the existence keys of the shadow JSON are allowed (optional)
    d = copy.deepcopy(good)
    d.update(polynomial=True, drift=None, evidence={"kind": "test"})
    v.validate(d)


@pytest.mark.parametrize("kind,argv", [("conserved", ("conserved", "--model", "rigid-body")),
                                       ("shadow", ("shadow", "--model", "lotka-volterra"))])
def test_other_models_validate(capsys, kind, argv):
    """No invariant near H (rigid body, Table-style search of degree 2) and a second model validate too."""
    data = run(capsys, *argv)
    validator(kind).validate(data)


def test_fi_and_models_validate(capsys):
    """fi: the eight forms (Eqs. 1AX-2BY), with ho3 the four non-vanishing h^2 terms of Eq. (BCH4); models: the catalogue."""
    generic = run(capsys, "fi")
    validator("fi").validate(generic)
    assert [f["label"] for f in generic["forms"]] == ["1AX", "1AY", "1BX", "1BY", "2AX", "2AY", "2BX", "2BY"]
    on_ho3 = run(capsys, "fi", "--model", "ho3", "--integrator", "12321")
    validator("fi").validate(on_ho3)
    assert len(on_ho3["representations"]) == 4
    bad = copy.deepcopy(on_ho3)
    del bad["model"]                       # representations need the system they were computed on
    assert not validator("fi").is_valid(bad)
    models = run(capsys, "models")
    validator("models").validate(models)
    assert {m["model"] for m in models["models"]} >= {"ho", "ho3", "rigid-body", "lotka-volterra"}


def test_sample_json_matches_its_schema(capsys):
    """``nambu-bch sample`` (hybrid Monte Carlo): the document's shape, and <x1^2> = 1 for the oscillator at m = omega = 1."""
    data = run(capsys, "sample", "--model", "ho", "--integrator", "212", "--h", "0.5", "--steps", "2", "--chains", "200",
               "--iterations", "20", "--seed", "2", "--target", "H_S", "--alpha", "0")
    validator("sample").validate(data)
    e = data["expectations"]["x1^2"]
    assert data["target"] == "H_S" and abs(e["value"] - 1) < 5 * e["error"]
