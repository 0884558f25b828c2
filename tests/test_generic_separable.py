"""The generic shadow Hamiltonian of H = |p|^2/2 + V(q) in tensor form (shadow/generic_separable.py).

Checked three ways: the tensor algebra's own laws (antisymmetry, Jacobi, structural zeros); the substituted answer
against the package's concrete ``shadow_hamiltonians`` (verified there against backward error analysis) for
Henon-Heiles (d = 2), the pendulum (d = 1), Kepler (d = 2, non-polynomial) and a d = 3 polynomial potential,
compared exactly in the extended ring (algebra/extended.py) up to an additive constant, the only freedom of a
one-Hamiltonian shadow; and numerically, the drift of the substituted H_S^[4] along ``iterate`` scales as h^6.
"""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest
import sympy
from shared_results import family, generic

from nambu_bch import NambuBCHError, System, iterate, model
from nambu_bch.algebra.extended import ExtendedRing
from nambu_bch.shadow.generic import P_, Q, V_FUN, poisson_structure, substitute
from nambu_bch.shadow.generic_separable import (Contraction, ContractionSum, SeparableShadow,
                                                separable_shadow)

h = sympy.Symbol("h")
T, V = ContractionSum.kinetic(), ContractionSum.potential()


def terms(s: ContractionSum) -> dict:
    return {t.to_text(): c for c, t in s.items()}


# -- the tensor algebra ---------------------------------------------------------------------------------
def test_second_brackets_are_the_textbook_contractions():
    assert terms(T.bracket(V)) == {"∇V·p": -1}                   # {T, V} = -p.grad V
    assert terms(T.bracket(T.bracket(V))) == {"V''(p,p)": 1}
    assert terms(V.bracket(V.bracket(T))) == {"∇V·∇V": 1}
    assert not V.bracket(V) and not T.bracket(T)                 # structural zeros
    assert not V.bracket(V.bracket(V.bracket(T)))                # a function of q only commutes with V


def _sums():
    """A few sums of contractions of mixed p-degree: nested brackets of T and V."""
    a = T.bracket(V)
    b = V.bracket(a)
    c = T.bracket(a) + b.scaled(Fraction(3, 7))
    return [a, b, c, T + V.scaled(2)]


def test_bracket_is_antisymmetric_and_satisfies_jacobi():
    sums = _sums()
    for x in sums:
        for y in sums:
            assert x.bracket(y) == y.bracket(x).scaled(-1)
    x, y, z = sums[:3]
    jacobi = x.bracket(y.bracket(z)) + y.bracket(z.bracket(x)) + z.bracket(x.bracket(y))
    assert not jacobi and jacobi == ContractionSum()


def test_equal_trees_merge_whatever_the_root():
    # V''(p, V''p) built from either end is one contraction
    a = Contraction.of([1, 1], [(0, 1)])
    b = Contraction.of([1, 1], [(1, 0)])
    c = Contraction.of([0, 1, 1], [(0, 1), (0, 2)])   # V''(V''p, V''p): the middle node has no p
    d = Contraction.of([1, 0, 1], [(1, 0), (1, 2)])
    assert a == b and c == d and a != c
    assert a.to_text() == "V''(p,V''p)" and c.to_text() == "V''(V''p,V''p)"
    assert Contraction.of([0, 2, 0], [(0, 1), (1, 2)]).to_text() == "V^(4)(p,p,∇V,∇V)"
    assert Contraction.of([0, 2], [(0, 1)]).to_text() == "V'''(p,p,∇V)"
    assert Contraction.of([1, 1, 0], [(0, 1), (1, 2)]).to_text() == "V'''(p,∇V,V''p)"
    # a tensor with its parent's slot open is a vector: V'''(p,p,·)
    assert Contraction.of([3, 2], [(0, 1)]).to_text() == "V^(4)(p,p,p,V'''(p,p,·))"
    assert Contraction.of([3, 2], [(0, 1)]).to_latex() == r"V^{(4)}\left(p,p,p,V'''\left(p,p,\cdot\right)\right)"


# -- the answer -----------------------------------------------------------------------------------------
# The coefficients below are the package's formal BCH series evaluated on the trees; their h^2 part is the
# symmetric BCH formula (Hairer, Lubich, Wanner, Sect. III.4.2; Horikoshi Eq. BCH1), and both orders are
# confirmed against the concrete systems below (whose shadow Hamiltonians are verified by backward error
# analysis) and for d = 1 against the generic T(p) + V(q) answer in undefined functions.
VELOCITY_VERLET = {
    2: {"V''(p,p)": Fraction(1, 12), "∇V·∇V": Fraction(-1, 24)},
    4: {"V^(4)(p,p,p,p)": Fraction(-1, 720), "V'''(p,p,∇V)": Fraction(1, 120), "V''(p,V''p)": Fraction(1, 60),
        "V''(∇V,∇V)": Fraction(-1, 240)},
}
POSITION_VERLET = {
    2: {"V''(p,p)": Fraction(-1, 24), "∇V·∇V": Fraction(1, 12)},
    4: {"V^(4)(p,p,p,p)": Fraction(7, 5760), "V'''(p,p,∇V)": Fraction(-1, 80), "V''(p,V''p)": Fraction(-1, 240),
        "V''(∇V,∇V)": Fraction(1, 60)},
}


@pytest.fixture(scope="module")
def verlet():
    return {"212": separable_shadow("212", 4), "121": separable_shadow("121", 4)}


@pytest.mark.parametrize("word, expected", [("212", VELOCITY_VERLET), ("121", POSITION_VERLET)])
def test_verlet_terms_through_h4(verlet, word, expected):
    R = verlet[word]
    assert terms(R.series[0]) == {"p·p": Fraction(1, 2), "V": 1}
    assert not R.series[1] and not R.series[3]                   # symmetric words: even powers only
    assert {j: terms(R.series[j]) for j in (2, 4)} == expected


@pytest.mark.parametrize("word", ["212", "121"])
def test_d1_agrees_with_the_generic_answer_in_undefined_functions(word):
    # shadow/generic.py: H = T(p) + V(q) with T, V undefined, d = 1, a different code path (sympy derivatives)
    ours = separable_shadow(word, 2).substitute_series(V_FUN(Q), q=[Q], p=[P_])
    theirs = generic(word, 2).series
    for j in range(3):
        assert sympy.expand(substitute(theirs[j], T=P_**2 / 2) - ours[j].doit()) == 0


# -- substituted into concrete systems, compared exactly ----------------------------------------------
D3 = System("q1 q2 q3 p1 p2 p3", ["(p1^2 + p2^2 + p3^2)/2 + q1*q2*q3 + q3^4/4"], (), name="quartic-3d")


def _same_up_to_constant(system, a, b) -> bool:
    """``a - b`` has zero gradient in the extended exact ring (normal forms, no simplify)."""
    ring = ExtendedRing(system.coordinates, system.parameters, [a, b])
    diff = ring.convert(a) - ring.convert(b)
    return all(not ring.diff(diff, i) for i in range(system.N))


def _check_against_concrete(system, word, concrete_HS, verlet):
    d = system.N // 2
    kinetic, potential = poisson_structure(system)[0]
    assert kinetic == sum(x**2 for x in system.coordinates[d:]) / 2
    ours = verlet[word].substitute_series(potential, q=system.coordinates[:d], p=system.coordinates[d:])
    theirs = sympy.expand(concrete_HS)
    for j in range(5):
        assert _same_up_to_constant(system, theirs.coeff(h, j), ours[j]), (system.name, word, j)


@pytest.mark.parametrize("name, word", [("henon-heiles", "212"), ("henon-heiles", "121"), ("pendulum", "212"),
                                        ("pendulum", "121"), ("kepler", "212"), ("kepler", "121")])
def test_substituted_equals_the_concrete_shadow_hamiltonian(verlet, name, word):
    _check_against_concrete(model(name), word, family(name, word, 4).H_S, verlet)


def test_substituted_equals_the_concrete_shadow_hamiltonian_d3(verlet):
    from nambu_bch import shadow_hamiltonians

    _check_against_concrete(D3, "212", shadow_hamiltonians(D3, "212", order=4).H_S, verlet)


def test_the_exact_comparison_sees_a_difference(verlet):
    # velocity Verlet's generic answer is not position Verlet's concrete one: the comparison is not vacuous
    system = model("henon-heiles")
    with pytest.raises(AssertionError):
        _check_against_concrete(system, "212", family("henon-heiles", "121", 4).H_S, verlet)


def test_non_symmetric_word_has_odd_powers():
    # Lie-Trotter: not symmetric, so every power of h is present
    R = separable_shadow("12", 3)
    assert R.series[1] and R.series[3]
    system = model("henon-heiles")
    _check_against_concrete_orders(system, R, family("henon-heiles", "12", 3).H_S, 4)


@pytest.mark.parametrize("word", ["212", "121"])
def test_pendulum_through_h6(word):
    R = separable_shadow(word, 6)
    assert len(R.series[6].terms) == 10
    _check_against_concrete_orders(model("pendulum"), R, family("pendulum", word, 6).H_S, 7)


def _check_against_concrete_orders(system, R, concrete, n):
    d = system.N // 2
    ours = R.substitute_series(poisson_structure(system)[0][1], q=system.coordinates[:d], p=system.coordinates[d:])
    theirs = sympy.expand(concrete)
    for j in range(n):
        assert _same_up_to_constant(system, theirs.coeff(h, j), ours[j])


# -- numerically: H_S^[4] drifts like h^6 (H_S^[2] like h^4) --------------------------------------------
def test_substituted_h2_and_h4_drift_like_h4_and_h6(verlet):
    from nambu_bch.design.compare import slope

    system = model("henon-heiles")
    coords = system.coordinates
    series = verlet["212"].substitute_series(poisson_structure(system)[0][1], q=coords[:2], p=coords[2:])
    H2 = sympy.lambdify([*coords, h], series[0] + h**2 * series[2], "numpy")
    H4 = sympy.lambdify([*coords, h], series[0] + h**2 * series[2] + h**4 * series[4], "numpy")
    steps_sizes, drifts = [0.2, 0.1, 0.05], {2: [], 4: []}
    for step in steps_sizes:
        X = iterate(system, "212", step, int(round(4 / step)), x0=(0.0, 0.3, 0.4, 0.1))
        for k, H in ((2, H2), (4, H4)):
            values = H(*X.T, step)
            drifts[k].append(float(np.max(np.abs(values - values[0]))))
    assert 3.5 < slope(steps_sizes, drifts[2]) < 4.5, drifts
    assert 5.5 < slope(steps_sizes, drifts[4]) < 6.5, drifts


# -- printing, JSON, substitution -----------------------------------------------------------------------
def test_text_latex_and_json(verlet):
    R = verlet["212"]
    assert "h^4: -1/720 V^(4)(p,p,p,p) + 1/120 V'''(p,p,∇V) + 1/60 V''(p,V''p) - 1/240 V''(∇V,∇V)" in R.to_text()
    latex = R.to_latex()
    assert r"\tfrac{1}{12}\,V''\left(p,p\right)" in latex and r"\nabla V\cdot \nabla V" in latex
    data = json.loads(json.dumps(R.to_dict()))
    assert data["kind"] == "generic-separable" and data["integrator"] == "212" and data["order"] == 4
    row = {t["term"]: t for t in data["series"]["4"]}["V''(p,V''p)"]
    assert row["coefficient"] == "1/60" and row["nodes"] == [{"derivative": 2, "p": 1}] * 2 and row["edges"] == [[0, 1]]


def test_substitute_reads_floats_as_the_decimals_written():
    q1, p1 = sympy.symbols("q1 p1")
    assert separable_shadow("212", 2).substitute(sympy.Float(1.5) * q1, d=1) == \
        separable_shadow("212", 2).substitute(sympy.Rational(3, 2) * q1, d=1)


def test_substitute_with_default_symbols_and_a_string():
    R = separable_shadow("212", 2, d=2)
    q1, q2, p1, p2 = sympy.symbols("q1 q2 p1 p2")
    HS = R.substitute("q1^2/2 + q2^4/4")
    expected = (p1**2 + p2**2) / 2 + q1**2 / 2 + q2**4 / 4 + h**2 * (
        (p1**2 + 3 * q2**2 * p2**2) / 12 - (q1**2 + q2**6) / 24)
    assert sympy.expand(HS - expected) == 0


def test_substitution_is_returned_in_the_ring_normal_form(verlet):
    # the pendulum V = -cos q: the h^4 term as the concrete route prints it (sin/cos reduced by s^2 + c^2 = 1)
    x1, x2 = sympy.symbols("x1 x2")
    ours = verlet["212"].substitute_series(-sympy.cos(x1), q=["x1"], p=["x2"])
    assert ours[4] == (x2**4 * sympy.cos(x1) / 720 - x2**2 * sympy.sin(x1)**2 / 40 + x2**2 / 60
                       - sympy.sin(x1)**2 * sympy.cos(x1) / 240)
    assert ours[2] == x2**2 * sympy.cos(x1) / 12 - sympy.sin(x1)**2 / 24


@pytest.mark.parametrize("call, match", [
    (lambda: separable_shadow("123", 2), "piece"),
    (lambda: separable_shadow("212", 13), "order"),
    (lambda: separable_shadow("212", 2, d=0), "d"),
    (lambda: separable_shadow("212", 2).substitute("q1^2"), "dimension"),
    (lambda: separable_shadow("212", 2).substitute("q1^2 + p1", d=1), "p1"),
    (lambda: separable_shadow("212", 2).substitute(sympy.Symbol("p1") * sympy.Symbol("q1"), d=1), "only"),
    (lambda: separable_shadow("212", 2).substitute("q1", q=["q1"], p=["q1"]), "distinct"),
    (lambda: separable_shadow("212", 2).substitute("q1", q=["q 1"], p=["p1"]), "symbol name"),
    (lambda: separable_shadow("212", 4).substitute("q1^3", d=64), "index sums"),
    (lambda: separable_shadow("212", 4).substitute("sin(sin(sin(sin(sin(sin(sin(sin(q1))))))))", d=1), "estimated"),
    (lambda: separable_shadow("212", 2).substitute(None, d=1), "V must be"),
    (lambda: separable_shadow("212", 2).substitute(sympy.Matrix([1]), d=1), "V must be"),
    (lambda: separable_shadow("212", 2).substitute(sympy.zoo, d=1), "finite"),
    (lambda: separable_shadow("212", 2).substitute(sympy.Symbol("h") * sympy.Symbol("q1"), d=1), "reserved"),
    (lambda: separable_shadow("212", 2).substitute("q1", q=["h"], p=["p1"]), "reserved"),
])
def test_bad_input_is_one_line_of_the_family(call, match):
    with pytest.raises(NambuBCHError, match=match) as info:
        call()
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("plegs, edges", [([], []), ([1, 1], []), ([1, 1], [(0, 0)]), ([1, 1], [(0, 2)]),
                                          ([1, 1, 1], [(0, 1), (1, 0)]), ([-1], []), ("12", []), ([1, 1], [(0,)])])
def test_contraction_of_refuses_what_is_not_a_tree(plegs, edges):
    with pytest.raises(NambuBCHError):
        Contraction.of(plegs, edges)


def test_result_type():
    assert isinstance(separable_shadow("TVT", 2), SeparableShadow)
    assert repr(separable_shadow("121", 2, d=3)) == "SeparableShadow('121', order=2, d=3)"
    assert separable_shadow("TVT", 2).series == separable_shadow("121", 2).series


# -- the command line ------------------------------------------------------------------------------------
def test_cli_prints_the_generic_answer_as_json(cli_run, tmp_path):
    run = cli_run("shadow", "--generic-separable", "--integrator", "212", "--order", "4", "--dim", "2",
                  "--format", "json", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    data = json.loads(run.stdout)
    assert data["kind"] == "generic-separable" and data["dimension"] == 2
    assert {t["term"]: t["coefficient"] for t in data["series"]["2"]} == {"V''(p,p)": "1/12", "∇V·∇V": "-1/24"}


@pytest.mark.parametrize("argv, message", [
    (["--generic-separable", "--model", "ho"], "takes no --model"),
    (["--generic-separable", "--dim", "0"], "--dim 0"),
    (["--dim", "2"], "--generic-separable only"),
    (["--generic-separable", "--integrator", "123"], "123"),
])
def test_cli_bad_generic_request_is_one_line(argv, message, capsys):
    from nambu_bch.cli import main

    assert main(["shadow", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err and "Traceback" not in err


def test_cli_text(capsys):
    from nambu_bch.cli import main

    assert main(["shadow", "--generic-separable", "--integrator", "121", "--order", "2", "--format", "text"]) == 0
    assert "h^2: -1/24 V''(p,p) + 1/12 ∇V·∇V" in capsys.readouterr().out


def test_json_matches_the_schema(capsys):
    # docs/schema/nambu-bch.schema.json, $defs/generic_separable (docs/json.md); the CLI prints to_dict()
    from pathlib import Path

    jsonschema = pytest.importorskip("jsonschema")
    from nambu_bch.cli import main

    schema = json.loads((Path(__file__).resolve().parents[1] / "docs" / "schema" / "nambu-bch.schema.json").read_text())
    validator = jsonschema.Draft202012Validator({"$schema": schema["$schema"], "$defs": schema["$defs"],
                                                 "$ref": "#/$defs/generic_separable"})
    assert main(["shadow", "--generic-separable", "--integrator", "12", "--order", "3", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    validator.validate(data)
    assert data == json.loads(json.dumps(separable_shadow("12", 3).to_dict()))
    assert data["dimension"] is None and data["series"]["1"]
