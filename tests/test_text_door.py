"""Text reaches sympy only through the whitelist parser: no public call evaluates a string.

``sympy.sympify`` (and every sympy function that sympifies its arguments: ``subs``, ``diff``,
``Matrix``, ``nsimplify``, containers of strings) runs ``eval`` on text.  Every public callable
that accepts an expression must therefore read text with :func:`nambu_bch.parsing.parse_expression`
(through :func:`nambu_bch.parsing.as_expression`).  Two tests keep it so:

* :func:`test_no_public_call_evaluates_text` drives each such callable with payloads that would
  leave a trace if evaluated (a file under ``tmp_path``, an entry in ``sys.modules``) and expects a
  one-line ``NambuBCHError`` and no trace;
* :func:`test_text_reaches_eval_only_in_the_parser` reads the package's source.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest
import shared_results as shared
import sympy

import nambu_bch as nb
from nambu_bch import testing
from nambu_bch.algebra import PolynomialAlgebra, VectorField, liouville_field, nambu_bracket, poisson_bracket
from nambu_bch.algebra.structure import is_symplectic, satisfies_nambu_condition
from nambu_bch.design.system_error import field_size
from nambu_bch.errors import NambuBCHError
from nambu_bch.exact.factor import F_series
from nambu_bch.parsing import as_expression, parse_expression
from nambu_bch.shadow.averaging import orbit_functions
from nambu_bch.shadow.existence import _check_params
from nambu_bch.shadow.fundamental_identity import commutator_terms, double_commutator_terms
from nambu_bch.systems import separate

PACKAGE = Path(nb.__file__).resolve().parent
MODULE_MARK = "nambu_bch_text_door_mark"
x1, x2, x3, m, omega, h = sympy.symbols("x1 x2 x3 m omega h")


def _payloads(marker: Path) -> list:
    """Texts that sympify would run: each leaves a file or a ``sys.modules`` entry behind."""
    return [
        f"__import__('pathlib').Path(r'{marker}').touch()",
        f"__import__('sys').modules.__setitem__('{MODULE_MARK}', 1)",
        f"x1 + __import__('pathlib').Path(r'{marker}').touch()",
    ]


HO3 = nb.model("ho3")
HO = nb.model("ho")
ALG = HO3.algebra
AC, BD = HO3.splitting[1].terms[0], HO3.splitting[2].terms[0]


def _family():
    return nb.shadow_hamiltonians(HO, "121")


def _modified_solution():
    return nb.modified_solution(HO, "121", "o")


# name -> f(payload): every public callable that accepts an expression, with the payload where an
# expression goes.  A payload that is a list tests that containers are not sympified either.
CALLS = {
    "System hamiltonian": lambda p: nb.System("x1 x2 x3", [p, "x3 - x1^2"], "m omega"),
    "System hamiltonians list": lambda p: nb.System("x1 x2 x3", [[p], "x3"]),
    "System.substitute": lambda p: HO3.substitute({"m": p}),
    "is_invariant": lambda p: nb.is_invariant(HO3, "12321", p),
    "is_invariant list": lambda p: nb.is_invariant(HO3, "12321", [p]),
    "assert_fields_equal X": lambda p: testing.assert_fields_equal([p, 0, 0], [0, 0, 0]),
    "assert_fields_equal Y": lambda p: testing.assert_fields_equal(HO3.vector_field, [p, 0, 0]),
    "liouville_components": lambda p: testing.liouville_components((x1, x2), p),
    "assert_shadow_pair H_S": lambda p: testing.assert_shadow_pair(HO3, "12321", p, "x3 - x1^2"),
    "assert_shadow_pair G_S": lambda p: testing.assert_shadow_pair(HO3, "12321", HO3.H, p),
    "assert_shadow_pair G_S list": lambda p: testing.assert_shadow_pair(HO3, "12321", HO3.H, [[p]]),
    "assert_invariant": lambda p: testing.assert_invariant(HO3, "12321", p),
    "assert_invariant list": lambda p: testing.assert_invariant(HO3, "12321", [p]),
    "PolynomialAlgebra.convert": lambda p: ALG.convert(p),
    "PolynomialAlgebra.convert list": lambda p: ALG.convert([p]),
    "PolynomialAlgebra extension": lambda p: PolynomialAlgebra([x1, x2], extension=[p]),
    "PolynomialAlgebra.to_sympy": lambda p: ALG.to_sympy(p),
    "VectorField": lambda p: VectorField(ALG, [p, 0, 0]),
    "VectorField.apply": lambda p: HO3.vector_field.apply(p),
    "liouville_field": lambda p: liouville_field(ALG, p, x3),
    "poisson_bracket": lambda p: poisson_bracket(HO.algebra, p, x1),
    "nambu_bracket": lambda p: nambu_bracket(ALG, p, x2, x3),
    "is_symplectic": lambda p: is_symplectic([p, x2], [x1, x2]),
    "satisfies_nambu_condition": lambda p: satisfies_nambu_condition([p, x2, x3], [x1, x2, x3]),
    "F": lambda p: nb.F(p),
    "F_series": lambda p: F_series(p, 4),
    "composition coefficient": lambda p: nb.composition([(p, 1), (1, 2)]),
    "composition word": lambda p: nb.composition(p),
    "shadow_hamiltonians word": lambda p: nb.shadow_hamiltonians(HO3, p),
    "LiouvilleTerm slot": lambda p: nb.LiouvilleTerm((p, x3)),
    "LiouvilleTerm coefficient": lambda p: nb.LiouvilleTerm((x2, x3), p),
    "LiouvilleTerm.scale": lambda p: nb.LiouvilleTerm((x2, x3)).scale(p),
    "LiouvilleSum.from_slots": lambda p: nb.LiouvilleSum.from_slots(ALG, (p, x3)),
    "LiouvilleSum.from_slots atoms": lambda p: nb.LiouvilleSum.from_slots(ALG, (x2, x3), atoms=[p]),
    "commutator_terms": lambda p: commutator_terms(ALG, AC, BD, "a", p),
    "double_commutator_terms": lambda p: double_commutator_terms(ALG, AC, AC, BD, "1AX", p),
    "ShadowFamily.member": lambda p: _family().member(alpha=p),
    "ModifiedSolution.at x0": lambda p: _modified_solution().at(x0=[p, 1]),
    "ModifiedSolution.at t": lambda p: _modified_solution().at(x0=[1, 1], t=p),
    "separate": lambda p: separate(p, [x1, x2, x3]),
    "field_size": lambda p: field_size([p, 0, 0], HO3),
    "orbit_functions params": lambda p: orbit_functions(HO3, [x1], {m: p, omega: 1}),
    "orbit_functions integrand": lambda p: orbit_functions(HO3, [p], {m: 1, omega: 1}),
    # the params of shadow_hamiltonians(..., params=) as the existence decision reads them
    "shadow_hamiltonians params": lambda p: _check_params(HO3, {"m": p}),
    "parse_expression": lambda p: parse_expression(p, [x1]),
    "as_expression": lambda p: as_expression(p, [x1]),
}


@pytest.mark.parametrize("name", list(CALLS))
def test_no_public_call_evaluates_text(name, tmp_path):
    """Each payload is refused in one line by the package's exception family, and leaves no trace."""
    marker = tmp_path / "evaluated"
    sys.modules.pop(MODULE_MARK, None)
    for payload in _payloads(marker):
        with pytest.raises(NambuBCHError) as info:
            CALLS[name](payload)
        message = str(info.value)
        assert "\n" not in message and 0 < len(message) < 1000, message
        assert not marker.exists(), f"{name} evaluated {payload!r}"
        assert MODULE_MARK not in sys.modules, f"{name} evaluated {payload!r}"


@pytest.mark.parametrize("name, call, expected", [
    ("is_invariant", lambda: nb.is_invariant(HO3, "12321", "x3 - x1^2 + h^2*x2^2/(4*m^2)"), True),  # Eq. (CQ12321G)
    ("substitute", lambda: HO3.substitute({"m": "1/2"}).H, omega**2 * x3 / 4 + x2**2),
    ("convert", lambda: ALG.to_sympy(ALG.convert("x1^2 + h*m")), x1**2 + h * m),
    ("liouville_components", lambda: testing.liouville_components((x1, x2), "x2^2/2 + x1^2/2"), (x2, -x1)),
    ("VectorField", lambda: VectorField(ALG, ["x2/m", 0, 0]).to_sympy(), (x2 / m, 0, 0)),
    ("member", lambda: _family().member(alpha="1/2") == _family().member(alpha=sympy.Rational(1, 2)), True),
    ("F_series", lambda: F_series("x", 2), sympy.Symbol("x")**2 / 6 + 1),
])
def test_text_still_works_where_it_is_meant_to(name, call, expected):
    assert call() == expected


def test_fields_equal_reads_text_with_the_fields_symbols():
    testing.assert_fields_equal(HO3.vector_field, ["x2/m", "-m*ω²*x₁", "2*x1*x2/m"])
    with pytest.raises(AssertionError):
        testing.assert_fields_equal(HO3.vector_field, ["x2", 0, "2*x1*x2/m"])


# ----------------------------------------------------------------------------------------------
# the source: text is evaluated only in the parser
# ----------------------------------------------------------------------------------------------
#: The only places outside the parser that run text as code, and why each is safe: the text is
#: source the package generated itself from already-parsed expressions (symbol names checked
#: against ``SYMBOL_NAME``), and the kernel's source is digest-checked before it runs.
GENERATED_SOURCE = {
    ("numeric/kernels.py", "exec"): 1,  # the compiled kernel's generated, digest-checked source
    ("numeric/kernels.py", "compile"): 1,
    ("numeric/precision.py", "exec"): 1,  # the mpmath twin of the kernel, generated from the same program
    ("numeric/precision.py", "compile"): 1,
    ("numeric/codegen.py", "exec"): 1,  # the generated expm1 pair statements (internal names; the float is a variable)
}


def _called_name(node: ast.Call):
    """``f`` for ``f(...)`` and ``obj.f(...)``; ``None`` for other callees."""
    func = node.func
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return func.attr
    return None


def _strict(node: ast.Call) -> bool:
    return any(k.arg == "strict" and isinstance(k.value, ast.Constant) and k.value.value is True for k in node.keywords)


def test_text_reaches_eval_only_in_the_parser():
    """Outside ``nambu_bch/parsing.py``, no call in the package can turn text into code.

    The rule, checked on the AST of every module of the package:

    * ``sympify(...)`` / ``sympy.sympify(...)`` / ``S(...)`` must pass ``strict=True`` (which
      refuses ``str``, containers and arrays instead of evaluating them); the parser's own
      :func:`~nambu_bch.parsing.as_expression` is where text is read, and it parses it;
    * ``parse_expr`` is never called;
    * ``eval`` is never called, and ``exec``/``compile`` (a call by that bare name, i.e. the
      builtins; methods such as ``re.compile`` or ``Kernel.compile`` are attribute calls and do not
      count) only at the listed sites that run source the package generated itself.

    A new call that breaks the rule fails here; a new site of generated source must be added to
    ``GENERATED_SOURCE`` with its reason.
    """
    offences, sites = [], {}
    for path, tree in shared.package_trees(str(PACKAGE)).items():
        rel = path.relative_to(PACKAGE).as_posix()
        if rel == "parsing.py":
            continue
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = _called_name(node)
            bare = isinstance(node.func, ast.Name)
            where = f"{rel}:{node.lineno}"
            if name in ("sympify", "S") and not (name == "S" and not bare and not _is_sympy(node.func)):
                if not _strict(node):
                    offences.append(f"{where}: {name}(...) without strict=True")
            elif name == "parse_expr":
                offences.append(f"{where}: parse_expr")
            elif bare and name == "eval":
                offences.append(f"{where}: eval")
            elif bare and name in ("exec", "compile"):
                sites[(rel, name)] = sites.get((rel, name), 0) + 1
    for site, count in sites.items():
        if GENERATED_SOURCE.get(site, 0) < count:
            offences.append(f"{site[0]}: {count} call(s) of {site[1]} (allowed: {GENERATED_SOURCE.get(site, 0)})")
    assert not offences, "text may reach eval outside the parser:\n" + "\n".join(offences)


def _is_sympy(func: ast.Attribute) -> bool:
    """``sympy.S`` (the sympifier), as opposed to another object's attribute ``S``."""
    return isinstance(func.value, ast.Name) and func.value.id in ("sympy", "sp")


def test_the_source_scan_catches_what_it_forbids(tmp_path, monkeypatch):
    """The scan is not vacuous: a module with each forbidden call is reported."""
    fake = tmp_path / "pkg"
    fake.mkdir()
    (fake / "parsing.py").write_text("import sympy\nsympy.sympify('x')\n")
    (fake / "bad.py").write_text(
        "import sympy\nsympy.sympify(t)\nsympy.S(t)\nparse_expr(t)\neval(t)\nexec(t)\nsympy.sympify(t, strict=True)\n"
        "import re\nre.compile('x')\n")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", fake)
    with pytest.raises(AssertionError) as info:
        test_text_reaches_eval_only_in_the_parser()
    text = str(info.value)
    for line, what in ((2, "sympify"), (3, "S"), (4, "parse_expr"), (5, "eval")):
        assert f"bad.py:{line}: {what}" in text, text
    assert "bad.py: 1 call(s) of exec" in text and "bad.py:7" not in text and "compile" not in text, text
