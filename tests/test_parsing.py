"""The safe expression parser (nambu_bch.parsing): exact numbers, whitelist, hostile input.

Property: for *any* text, ``parse_expression`` either returns an exact sympy
expression in the declared symbols or raises ``ExpressionParseError`` -- never
another exception, never a Float, never an undeclared symbol, never a side effect.
"""

from __future__ import annotations

import os

import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from nambu_bch.errors import ExpressionParseError, NambuBCHError
from nambu_bch.parsing import MAX_LENGTH, parse_expression

x1, x2, x3, m, omega = sympy.symbols("x1 x2 x3 m omega")
SYMBOLS = [x1, x2, x3, m, omega]

FAST = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _ok_or_parse_error(text):
    try:
        result = parse_expression(text, SYMBOLS, what="--H")
    except ExpressionParseError as exc:
        message = str(exc)
        assert "\n" not in message and message.startswith("--H"), message
        return None
    assert isinstance(result, sympy.Expr)
    assert not result.has(sympy.Float), result
    assert result.free_symbols <= set(SYMBOLS), result
    return result


# -------------------------------------------------------------------------------------------
# accepted input
# -------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "text, expected",
    [
        ("x2^2/(2*m) + m*omega^2*x1^2/2", x2**2 / (2 * m) + m * omega**2 * x1**2 / 2),  # Eq. (HO1)
        ("x3 - x1**2", x3 - x1**2),  # Eq. (G)
        ("0.1*x1", x1 / 10),
        ("1e-3 + 2.5E2 + 1_000.5", sympy.Rational(1, 1000) + 250 + sympy.Rational(2001, 2)),
        ("-(+x1)", -x1),
        ("2^-1", sympy.Rational(1, 2)),
        ("x1^0.5", sympy.sqrt(x1)),
        ("Rational(1, 3)*x1", x1 / 3),
        ("sin(x1)*cos(x2) + exp(-x3) + sqrt(2) + abs(m) + cbrt(8)", sympy.sin(x1) * sympy.cos(x2) + sympy.exp(-x3) + sympy.sqrt(2) + abs(m) + 2),
        ("pi*E", sympy.pi * sympy.E),
        (" x1 ", x1),
        # the terms added at once: a running sum() rebuilds the Add per term (quadratic; ~0.2 s of every collection)
        ("+".join(f"x1**{k}" for k in range(1, 200)), sympy.Add(*(x1**k for k in range(1, 200)))),
        ("*".join(["x1"] * 400), x1**400),
    ],
)
def test_accepted(text, expected):
    assert sympy.simplify(parse_expression(text, SYMBOLS) - expected) == 0


def test_declared_symbol_shadows_constant():
    E = sympy.Symbol("E")
    assert parse_expression("E + 1", [E]) == E + 1


def test_floats_stay_exact():
    value = parse_expression("0.1 + 0.2", [])
    assert value == sympy.Rational(3, 10) and value.is_Rational


# -------------------------------------------------------------------------------------------
# rejected input
# -------------------------------------------------------------------------------------------
REJECTED = {
    "__import__('os').system('touch /tmp/pwned')": "not accepted",  # character whitelist (was: __import__)
    "().__class__.__bases__[0].__subclasses__()": "not accepted",  # character whitelist (was: whitelisted)
    "x1.__class__": "attribute",
    "x1[0]": "not accepted",  # character whitelist (was: subscript)
    "(lambda: 1)()": "not accepted",  # character whitelist (was: call)
    "lambda: 1": "not accepted",  # character whitelist (was: lambda)
    "eval('1')": "not accepted",  # character whitelist (was: eval)
    "exec('1')": "not accepted",  # character whitelist (was: exec)
    "open('/etc/passwd').read()": "not accepted",  # character whitelist (was: whitelisted)
    "open('/etc/passwd')": "not accepted",  # character whitelist (was: 'open' is not allowed)
    "getattr(x1, 'real')": "not accepted",  # character whitelist (was: getattr)
    "globals()": "globals",
    "sympify('x1')": "not accepted",  # character whitelist (was: sympify)
    "Symbol('y')": "not accepted",  # character whitelist (was: Symbol)
    "y + x1": "'y' is not declared",
    "__builtins__": "not declared",
    "'abc'": "not accepted",  # character whitelist (was: not a number)
    "b'abc'": "not accepted",  # character whitelist (was: not a number)
    "1j": "not a number",
    "True": "not a number",
    "None": "not a number",
    "[x1]": "not accepted",  # character whitelist (was: List)
    "(x1, x2)": "Tuple",
    "{x1: 1}": "not accepted",  # character whitelist (was: Dict)
    "x1 if x1 else 0": "IfExp",
    "x1 < 2": "not accepted",  # character whitelist (was: Compare)
    "x1 and x2": "BoolOp",
    "x1 % 2": "not accepted",  # character whitelist (was: '%')
    "x1 // 2": "'//'",
    "x1 @ x2": "not accepted",  # character whitelist (was: '@')
    "~x1": "not accepted",  # character whitelist (was: '~')
    "x1 << 2": "not accepted",  # character whitelist (was: '<<')
    "sin(x=x1)": "not accepted",  # character whitelist (was: keyword)
    "sin(*[x1])": "not accepted",  # character whitelist (was: Starred)
    "sin": "must be called",
    "sin(x1, x2)": "invalid",
    "Rational(x1, 2)": "invalid",
    "[x for x in ()]": "not accepted",  # character whitelist (was: ListComp)
    "f'{x1}'": "not accepted",  # character whitelist (was: JoinedStr)
    "(y := 1)": "not accepted",  # character whitelist (was: NamedExpr)
    "x1 +": "not a valid expression",
    "x1 = 1": "not accepted",  # character whitelist (was: not a valid expression)
    "import os": "not a valid expression",
    "x1; x2": "not accepted",  # character whitelist (was: not a valid expression)
    "x1\x00": "not accepted",  # character whitelist (was: not a valid expression)
    "": "empty",
    "   ": "empty",
    "x1 ** 100000": "exponent",
    "9**9**9**9": "exponent",
    "((9**999)**999)**999": "bits",
    "x1**(10**1001)": "exponent",
    "(10**999)**50": "bits",
    "1e400": "out of range",
    "1e-400": "out of range",
    "1/0": "divides by zero",
    "x1/(x2-x2)": "divides by zero",
    "0**-1": "divides by zero",
    "log(0)": "not finite",
    "Rational(1, 0)": "not finite",
    "x1**(2*I)": "not declared",
    "sin(" * 100 + "x1" + ")" * 100: "nested",
    "-" * 1500 + "x1": "nested",
    "(" * 300 + "x1" + ")" * 300: "not a valid expression",
    "x1+" * 700 + "x1": "characters long",
    "1/2 # comment": "'#', not accepted",  # the tokenizer would drop the comment
    "x1 # __import__('os')": "not accepted",
    "x1 \\\n + x2": "not accepted",
    "\uff581": "not accepted",  # fullwidth x: NFKC would make it x1
    "(x1 + x2 + 1)**1000": "501501 terms",  # binomial(1002, 2) monomials
    "(x1 + x2 + x3)**100": "5151 terms",  # binomial(102, 2)
    "x1**600 * x2**600": "degree up to 1200",
    "99999999^500": "bits",  # 13500 bits; str() of it would exceed Python's 4300-digit limit
    "10**500": "bits",
    # the AST whitelist is the second line of defence, behind the character whitelist
    "__import__(x1)": "'__import__' is not allowed",
    "open(x1)": "'open' is not allowed",
    "eval(x1)": "'eval' is not allowed",
    "getattr(x1, x2)": "'getattr' is not allowed",
    "x1.real": "attribute",
    "lambda x1: x1": "lambda",
    "(x1).conjugate()": "whitelisted",
}


@pytest.mark.parametrize("text", list(REJECTED))
def test_rejected_with_message(text):
    with pytest.raises(ExpressionParseError) as info:
        parse_expression(text, SYMBOLS, what="--H")
    message = str(info.value)
    assert "\n" not in message and len(message) < 600, message
    assert message.startswith("--H"), message
    assert REJECTED[text].lower() in message.lower(), message


def test_injection_has_no_side_effect(tmp_path):
    target = tmp_path / "pwned"
    for text in (
        f"__import__('os').system('touch {target}')",
        f"open('{target}', 'w')",
        f"().__class__.__base__.__subclasses__()[0]('{target}')",
    ):
        with pytest.raises(ExpressionParseError):
            parse_expression(text, SYMBOLS, what="--H")
    assert not target.exists()
    assert not os.path.exists("/tmp/pwned")


def test_non_string_and_error_family():
    with pytest.raises(ExpressionParseError, match="must be a string"):
        parse_expression(3, SYMBOLS)
    assert issubclass(ExpressionParseError, NambuBCHError) and issubclass(ExpressionParseError, ValueError)


def test_too_long():
    with pytest.raises(ExpressionParseError, match=str(MAX_LENGTH)):
        parse_expression("x1+" * MAX_LENGTH, SYMBOLS, what="--H")


# -------------------------------------------------------------------------------------------
# hypothesis: garbage never escapes as another exception
# -------------------------------------------------------------------------------------------
ALPHABET = st.sampled_from(list("x123mog+-*/^().,e_ ijE'\"[]{}:;=<>!%&|~@#\\") + ["**", "sin(", "__", "lambda", "\n"])


@FAST
@given(st.text(max_size=80))
def test_arbitrary_unicode_text(text):
    _ok_or_parse_error(text)


@FAST
@given(st.lists(ALPHABET, max_size=40).map("".join))
def test_expression_like_garbage(text):
    _ok_or_parse_error(text)


# well-formed random expressions: the parse agrees with sympy's own arithmetic
_atoms = st.one_of(
    st.sampled_from(["x1", "x2", "x3", "m", "omega"]),
    st.integers(0, 50).map(str),
    st.fractions(min_value=-5, max_value=5, max_denominator=9).map(lambda f: f"({f.numerator}/{f.denominator})"),
)


def _combine(children):
    return st.one_of(
        st.tuples(children, st.sampled_from(["+", "-", "*"]), children).map(lambda t: f"({t[0]} {t[1]} {t[2]})"),
        st.tuples(children, st.integers(0, 4)).map(lambda t: f"({t[0]})^{t[1]}"),
        children.map(lambda c: f"-({c})"),
    )


@FAST
@given(st.recursive(_atoms, _combine, max_leaves=12))
def test_wellformed_expressions_match_sympy(text):
    result = parse_expression(text, SYMBOLS)
    names = {s.name: s for s in SYMBOLS}
    assert sympy.expand(result - sympy.sympify(text.replace("^", "**"), locals=names)) == 0


# -------------------------------------------------------------------------------------------
# Unicode as typed in a notebook: mapped by an explicit table, or refused with the mapping
# -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("text, expected", [
    ("m*ω²*x₁²/2", m * omega**2 * x1**2 / 2),
    ("x₂²/(2·m) + m×ω²×x₁²/2", x2**2 / (2 * m) + m * omega**2 * x1**2 / 2),  # Eq. (HO1)
    ("x₃ − x₁²", x3 - x1**2),  # Eq. (G), with the minus sign U+2212
    ("x₁⁻¹ + x₂¹⁰", 1 / x1 + x2**10),
    ("π*x₁ + ω", sympy.pi * x1 + omega),
    ("(x₁ + x₂)³", (x1 + x2)**3),
    ("x1\u00a0+\u00a0x2", x1 + x2),  # no-break spaces
])
def test_unicode_mapped_to_ascii(text, expected):
    assert sympy.expand(parse_expression(text, SYMBOLS) - expected) == 0


def test_greek_names_reach_declared_parameters():
    alpha_, sigma = sympy.symbols("alpha sigma")
    assert parse_expression("α*x₁ + σ", [x1, alpha_, sigma]) == alpha_ * x1 + sigma


@pytest.mark.parametrize("text, fragment", [
    ("xω", "'ω' (-> 'omega') touches another letter"),  # xomega or x*omega?
    ("ωx1", "touches another letter"),
    ("2ω", "touches another letter"),
    ("x1²3", "the superscript '²' is followed by '3'"),  # x^23 or x^2*3?
    ("x²y", "followed by 'y'"),
    ("x1⁻", "'⁻' must be followed by superscript digits"),
    ("λ*x1", "'lambda' is a Python keyword"),
    ("√x1", "write sqrt(...)"),
    ("Αx1", "contains 'Α'"),  # capital alpha looks like A: not in the table
    ("ｘ1", "contains 'ｘ'"),  # fullwidth: never NFKC-normalised
    ("x1\u2028", "not accepted"),  # a line separator stays refused
])
def test_unicode_ambiguous_or_unknown_refused_with_the_mapping(text, fragment):
    with pytest.raises(ExpressionParseError) as info:
        parse_expression(text, SYMBOLS, what="--H")
    message = str(info.value)
    assert "\n" not in message and message.startswith("--H") and fragment in message, message


def test_mapping_result_is_printable_ascii():
    """Round one's guarantee holds after mapping: whatever is parsed is printable ASCII."""
    from nambu_bch.parsing import ALLOWED_PUNCTUATION, GREEK_NAMES, to_ascii

    text = "".join(GREEK_NAMES) + "₀₁₂₃₄₅₆₇₈₉·×−÷"
    spaced = to_ascii(" ".join(text))
    assert spaced.isascii() and spaced.isprintable()
    assert all(ch.isalnum() or ch in ALLOWED_PUNCTUATION for ch in spaced)


# -------------------------------------------------------------------------------------------
# undeclared names: how to declare them, and "did you mean"
# -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("what, text, fragments", [
    ("--H", "x2^2/(2*mm)", ["the name 'mm' is not declared", "did you mean 'm'?", "--param mm (symbolic) or --param mm=VALUE"]),
    ("--G", "x3 - k*x1^2", ["'k' is not declared", "--param k"]),
    ("--system model.toml: H", "x2^2/(2*mass)", ["'mass' is not declared", "the file's parameters"]),
    ("expression", "x2^2/(2*omgea)", ["did you mean 'omega'?", "parameters=['omgea']"]),
    ("--h", "x1", ["'x1' is not declared (a number is expected here)"]),
])
def test_undeclared_name_says_how_to_declare_it(what, text, fragments):
    symbols = [] if what == "--h" else SYMBOLS
    with pytest.raises(ExpressionParseError) as info:
        parse_expression(text, symbols, what=what)
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


def test_no_did_you_mean_for_a_name_far_from_every_declared_one():
    with pytest.raises(ExpressionParseError) as info:
        parse_expression("x1 + kappa", SYMBOLS, what="--H")
    assert "did you mean" not in str(info.value)


# -------------------------------------------------------------------------------------------
# constant towers: bounded from the tree, never evaluated
# -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("text, fragment", [
    ("x2^2/2 + x1^2*cos(exp(exp(exp(2.5))))", "the constant exp(exp(exp(5/2))) may be as large as 2^2.82e+05"),
    ("x1*exp(1000)", "exp(1000) may be as large as 2^1.44e+03"),
    ("x1^exp(exp(10))", "exp(exp(10))"),
    ("x1*pi^pi^pi", "pi**(pi**pi)"),
    ("x1*sinh(exp(10))", "sinh(exp(10))"),
    ("x1*sin(sqrt(-1)*1000)", "may be as large as"),  # sin(1000 i) = i sinh(1000)
    ("x1*exp(700)*exp(700)", "exp(1400)"),
    ("x1*exp(1/(pi - 3))", "cannot be bounded without evaluating it"),
    ("x1*2^(1/(E - 2))", "cannot be bounded"),
])
def test_constant_towers_refused_from_the_tree(text, fragment):
    with pytest.raises(ExpressionParseError) as info:
        parse_expression(text, SYMBOLS, what="--H")
    message = str(info.value)
    assert "\n" not in message and message.startswith("--H") and fragment in message, message
    assert "2^1400" in message or "cannot be bounded" in message, message


@pytest.mark.parametrize("expr", [
    sympy.tan(1), 1 / (sympy.pi - 3), sympy.log(sympy.pi - 3), sympy.tan(1)**2, sympy.tan(1)**-2,
    sympy.exp(sympy.tan(1)), sympy.Abs(sympy.tan(1)) + 1, sympy.tan(1) * 2, sympy.sqrt(sympy.tan(1)),
])
def test_constant_bound_says_unknown_where_the_tree_gives_no_bound(expr):
    """A value that may cancel, ``tan`` and ``log`` of what may be tiny have no upper bound, and neither has what is
    built from them (a power of ``tan(1)`` among them: it raised a TypeError instead)."""
    from nambu_bch.parsing import constant_bound

    assert constant_bound(expr)[0] is None


def test_a_power_of_an_unbounded_constant_is_parsed_or_refused_in_one_line():
    """``tan(1)**2`` is an ordinary constant factor; inside ``exp`` it is refused in one line (both were a TypeError
    from the size bound)."""
    assert parse_expression("tan(1)**2*x1", SYMBOLS, what="--H") == sympy.tan(1)**2 * x1
    with pytest.raises(ExpressionParseError, match=r"^--H .*the constant tan\(1\)\*\*2 in exp cannot be bounded"):
        parse_expression("x1*exp(tan(1)**2)", SYMBOLS, what="--H")


@pytest.mark.parametrize("text", [
    "x1*exp(700)", "x1*exp(-exp(10))", "cos(1/(pi - 3))*x1", "x1*exp(1/(1 + sqrt(2)))", "x1*exp(atan(1/2))",
    "x1*2^(1/2)*3^(1/3)", "x1*E^E^E", "x1*exp(-1/(2*pi))", "x1*cosh(3)*sin(10^300)", "exp(-x1^2/2)*cos(omega*x2)",
])
def test_ordinary_constants_still_accepted(text):
    assert isinstance(parse_expression(text, SYMBOLS, what="--H"), sympy.Expr)


@pytest.mark.parametrize("expr", [
    sympy.exp(sympy.Rational(5, 2)), sympy.exp(sympy.exp(2)), sympy.pi**sympy.pi, sympy.sqrt(7) / 3,
    sympy.cosh(5), sympy.sinh(-4) * sympy.E, (2 + sympy.sqrt(3))**7, sympy.exp(-sympy.exp(3)),
    sympy.asin(sympy.Rational(1, 3)), sympy.log(10**50), 1 / (1 + sympy.pi)**3,
    # one per rule of the table: Abs, sin/cos, tanh, atan, acos, log, roots of a negative base, negative and odd
    # integer powers, a non-rational exponent, signs of products and of sums of one sign
    sympy.Abs(sympy.pi - 4), sympy.sin(3), sympy.cos(sympy.Rational(7, 2)), sympy.tanh(-2), sympy.atan(50),
    sympy.acos(sympy.Rational(-1, 5)), sympy.log(sympy.Rational(1, 10**6)), sympy.cbrt(-7) * sympy.I,
    (-sympy.pi - 5)**-3, sympy.E**(sympy.pi / 3), -3 * sympy.pi * sympy.exp(2), -sympy.pi - sympy.E - 1,
    sympy.exp(-sympy.pi), sympy.cosh(-sympy.E) * sympy.sinh(2),
])
def test_constant_bound_is_an_upper_and_lower_bound(expr):
    """The tree bound brackets the true log2 |value| (checked numerically here, never in the parser)."""
    from nambu_bch.parsing import constant_bound

    upper, lower, sign, real = constant_bound(expr)
    value = sympy.N(abs(expr), 50)
    true = float(sympy.log(value, 2))
    assert upper is not None and lower - 1e-9 <= true <= upper + 1e-9, (upper, true, lower)
    if sign:
        assert sympy.sign(sympy.N(expr, 30)) == sign
