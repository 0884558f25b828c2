"""Safe parsing of user expressions (CLI flags, model files, ``System("...")``).

Nothing is ``eval``-ed.  The text is parsed by Python's ``ast`` module and the
tree is walked with a whitelist: numbers, the declared symbols, ``+ - * / **``
(``^`` is read as power), unary signs, parentheses and calls of the functions
in :data:`ALLOWED_FUNCTIONS`.  Anything else (attribute access, subscripts,
names not declared, keyword arguments, lambdas, strings, comprehensions, very
long input) raises :class:`~nambu_bch.errors.ExpressionParseError`.
"""

from __future__ import annotations

import ast

import sympy

from .errors import ExpressionParseError

MAX_LENGTH = 2000
MAX_DEPTH = 60
MAX_EXPONENT = 1000

#: name -> sympy callable, the only functions a user expression may call.
ALLOWED_FUNCTIONS = {
    "sqrt": sympy.sqrt, "exp": sympy.exp, "log": sympy.log,
    "sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan,
    "sinh": sympy.sinh, "cosh": sympy.cosh, "tanh": sympy.tanh,
    "asin": sympy.asin, "acos": sympy.acos, "atan": sympy.atan,
    "cbrt": sympy.cbrt, "Rational": sympy.Rational, "abs": sympy.Abs,
}
_CONSTANTS = {"pi": sympy.pi, "E": sympy.E}

_BINARY = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
}


def parse_expression(text: str, symbols, what: str = "expression") -> sympy.Expr:
    """Parse ``text`` into a sympy expression using only ``symbols``.

    Parameters
    ----------
    text : str
    symbols : iterable of sympy Symbols or a dict name -> Symbol
    what : str
        How the error message names the input, e.g. ``"--H"``.

    Examples
    --------
    >>> import sympy
    >>> x1, m = sympy.symbols("x1 m")
    >>> parse_expression("x1^2/(2*m)", [x1, m])
    x1**2/(2*m)
    """
    if not isinstance(text, str):
        raise ExpressionParseError(f"{what} must be a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionParseError(f"{what} is {len(text)} characters long; at most {MAX_LENGTH} are accepted")
    if not text.strip():
        raise ExpressionParseError(f"{what} is empty")
    names = dict(symbols) if isinstance(symbols, dict) else {s.name: s for s in symbols}
    # '^' means power to physicists; Python would parse it as xor with the wrong precedence
    text = text.replace("^", "**")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError) as exc:
        raise ExpressionParseError(f"{what} {text!r} is not a valid expression ({exc.msg if hasattr(exc, 'msg') else exc})") from None
    try:
        return _Builder(names, what, text).visit(tree.body, 0)
    except RecursionError:
        raise ExpressionParseError(f"{what} is nested too deeply") from None


class _Builder:
    def __init__(self, names, what, text):
        self.names, self.what, self.text = names, what, text

    def fail(self, why):
        accepted = ", ".join(sorted(self.names)) or "none"
        raise ExpressionParseError(
            f"{self.what} {self.text!r}: {why}; accepted are numbers, the symbols ({accepted}), "
            f"+ - * / ** ^, parentheses and the functions {', '.join(sorted(ALLOWED_FUNCTIONS))}"
        )

    def visit(self, node, depth):
        if depth > MAX_DEPTH:
            self.fail("it is nested too deeply")
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                self.fail(f"the literal {node.value!r} is not a number")
            if isinstance(node.value, float):
                # keep the decimal text exact: 0.1 means 1/10, not the nearest double
                return sympy.Rational(ast.get_source_segment(self.text.strip(), node) or repr(node.value))
            return sympy.Integer(node.value)
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            if node.id in _CONSTANTS:
                return _CONSTANTS[node.id]
            self.fail(f"the name {node.id!r} is not declared")
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
            value = self.visit(node.operand, depth + 1)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            left, right = self.visit(node.left, depth + 1), self.visit(node.right, depth + 1)
            if isinstance(node.op, ast.Pow) and right.is_number and abs(right) > MAX_EXPONENT:
                self.fail(f"the exponent {right} is larger than {MAX_EXPONENT}")
            if isinstance(node.op, ast.Div) and right == 0:
                self.fail("it divides by zero")
            return _BINARY[type(node.op)](left, right)
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in ALLOWED_FUNCTIONS:
                name = node.func.id if isinstance(node.func, ast.Name) else ast.dump(node.func)[:40]
                self.fail(f"the call of {name!r} is not allowed")
            if node.keywords:
                self.fail("keyword arguments are not allowed")
            args = [self.visit(a, depth + 1) for a in node.args]
            try:
                return ALLOWED_FUNCTIONS[node.func.id](*args)
            except (TypeError, ValueError) as exc:
                self.fail(f"{node.func.id}{tuple(args)} is invalid ({exc})")
        if isinstance(node, ast.Attribute):
            self.fail("attribute access is not allowed")
        self.fail(f"the construct {type(node).__name__} is not allowed")
