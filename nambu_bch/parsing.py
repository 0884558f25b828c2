"""Safe parsing of user expressions (CLI flags, model files, ``System("...")``).

Nothing is ``eval``-ed.  The text is parsed by Python's :mod:`ast` module and
the tree is walked with a whitelist:

* numbers -- integers, and decimals kept **exact** (``0.1`` is ``1/10``, never
  the nearest double; ``1e-3`` is ``1/1000``);
* the declared symbols, plus the constants ``pi`` and ``E`` unless a symbol
  of that name is declared;
* ``+ - * /`` and ``**`` (``^`` is read as power, as physicists write it),
  unary signs and parentheses;
* calls of the functions in :data:`ALLOWED_FUNCTIONS`, positional arguments
  only.

Only printable ASCII is read (letters, digits, spaces and ``+-*/^().,_``):
a ``#`` (which Python's tokenizer would silently drop as a comment), a
backslash, quotes, braces, control characters and non-ASCII letters (which
Python would NFKC-normalise into other names) are refused before parsing.
Anything else -- attribute access, subscripts, undeclared names (including
``__import__``, ``eval``, ``open``), keyword or starred arguments, lambdas,
strings, comparisons, comprehensions -- raises
:class:`~nambu_bch.errors.ExpressionParseError` whose one-line message names
the input (``what``) and lists what is accepted.  So do inputs that would only
cost time or memory: text longer than :data:`MAX_LENGTH` characters, nesting
deeper than :data:`MAX_DEPTH`, exponents larger than :data:`MAX_EXPONENT` in
absolute value, exact numbers of more than :data:`MAX_BITS` bits, decimal
literals with an exponent beyond ``1e±``:data:`MAX_DECIMAL_EXPONENT`, results
that are not finite (``1/0``, ``log(0)``, ``Rational(1, 0)``), and polynomials
whose expansion would have more than :data:`MAX_TERMS` terms or total degree
above :data:`MAX_DEGREE` (``(x1+x2+1)**1000``: estimated from the number of
terms and the exponent, before anything is expanded).

Long sums and products (``x1 + x1**2 + ... + x1**300``) are walked
iteratively, so they count as one level of nesting however many terms they
have.
"""

from __future__ import annotations

import ast
import math
import warnings
from decimal import Decimal, InvalidOperation

import sympy

from .errors import ExpressionParseError

#: Longest accepted input, in characters.
MAX_LENGTH = 2000
#: Deepest accepted nesting of operators and calls (chains of + - or * / count once).
MAX_DEPTH = 60
#: Largest accepted absolute value of a numeric exponent.
MAX_EXPONENT = 1000
#: Largest accepted size of an exact integer, numerator or denominator, in bits (about 420 digits).
MAX_BITS = 1400
#: Most terms the expanded polynomial may have (estimated before expansion).
MAX_TERMS = 5000
#: Highest total degree of the expanded polynomial.
MAX_DEGREE = 1000
#: The only characters an expression may contain (besides letters and digits).
ALLOWED_PUNCTUATION = " +-*/^().,_"
#: Largest accepted decimal exponent of a literal such as ``1e300``.
MAX_DECIMAL_EXPONENT = 300

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
_OPERATOR_NAMES = {
    ast.Mod: "%", ast.FloorDiv: "//", ast.MatMult: "@", ast.BitAnd: "&", ast.BitOr: "|",
    ast.BitXor: "^", ast.LShift: "<<", ast.RShift: ">>", ast.Invert: "~", ast.Not: "not",
}
_NON_FINITE = (sympy.zoo, sympy.nan, sympy.oo, -sympy.oo)


def _shown(text: str, limit: int = 60) -> str:
    """``repr`` of the input, shortened so that a message stays one readable line."""
    return repr(text if len(text) <= limit else text[: limit - 3] + "...")


def parse_expression(text: str, symbols, what: str = "expression") -> sympy.Expr:
    """Parse ``text`` into a sympy expression using only ``symbols``.

    Parameters
    ----------
    text : str
        The user's expression, e.g. ``"x2^2/(2*m) + m*omega^2*x1^2/2"``.
    symbols : iterable of sympy Symbols, or a dict name -> Symbol
        The only names the expression may use (besides ``pi``, ``E`` and the
        whitelisted functions).
    what : str
        How the error message names the input, e.g. ``"--H"``.

    Returns
    -------
    sympy.Expr
        Exact: decimals become ``Rational``; no ``Float`` is ever created.

    Raises
    ------
    ExpressionParseError
        With a one-line message naming ``what``, the offending construct and
        what is accepted.

    Examples
    --------
    >>> import sympy
    >>> x1, m = sympy.symbols("x1 m")
    >>> parse_expression("x1^2/(2*m)", [x1, m])
    x1**2/(2*m)
    >>> parse_expression("0.1*x1 + 2.5e-1", [x1])
    x1/10 + 1/4
    >>> parse_expression("__import__(x1)", [x1], what="--H")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    nambu_bch.errors.ExpressionParseError: --H '__import__(x1)': the call of '__import__' is not allowed; ...
    >>> parse_expression("1/2 # a comment Python would drop", [], what="--h")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    nambu_bch.errors.ExpressionParseError: --h '1/2 # a comment Python would drop' contains '#', not accepted; ...
    """
    if not isinstance(text, str):
        raise ExpressionParseError(f"{what} must be a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionParseError(
            f"{what} is {len(text)} characters long; at most {MAX_LENGTH} are accepted"
        )
    if not text.strip():
        raise ExpressionParseError(f"{what} is empty; give an expression such as 'x2^2/2 + x1^2/2'")
    bad = sorted({ch for ch in text if not (ch.isascii() and (ch.isalnum() or ch in ALLOWED_PUNCTUATION))})
    if bad:
        shown = "".join(bad) if all(ch.isprintable() for ch in bad) else ascii("".join(bad))
        raise ExpressionParseError(
            f"{what} {_shown(text)} contains {shown!r}, not accepted; expressions use ASCII letters, digits, "
            f"spaces and {ALLOWED_PUNCTUATION.strip()}"
        )
    names = _symbol_table(symbols, what)
    original = text
    # '^' means power to physicists; Python would parse it as xor with the wrong precedence
    source = text.replace("^", "**").strip()
    try:
        with warnings.catch_warnings():
            # "invalid decimal literal" and friends: the input is rejected or accepted on its own terms
            warnings.simplefilter("ignore", SyntaxWarning)
            tree = ast.parse(source, mode="eval")
    except (SyntaxError, ValueError, MemoryError, RecursionError) as exc:
        why = getattr(exc, "msg", None) or str(exc) or type(exc).__name__
        raise ExpressionParseError(
            f"{what} {_shown(original)} is not a valid expression ({why}); "
            "write e.g. 'x2^2/(2*m) + m*omega^2*x1^2/2'"
        ) from None
    builder = _Builder(names, what, original, source)
    try:
        result = builder.visit(tree.body, 0)
    except RecursionError:
        raise ExpressionParseError(f"{what} {_shown(original)} is nested too deeply") from None
    if not isinstance(result, sympy.Expr):
        builder.fail("it is not an algebraic expression")
    if result.has(*_NON_FINITE):
        builder.fail("it is not finite (division by zero, log(0) or similar)")
    terms, degree = expansion_size(result)
    if terms > MAX_TERMS or degree > MAX_DEGREE:
        builder.fail(
            f"expanded it would have about {terms if terms < 10**15 else '> 10^15'} terms of degree up to {degree} "
            f"(at most {MAX_TERMS} terms and degree {MAX_DEGREE} are accepted)"
        )
    return result


def _symbol_table(symbols, what):
    if isinstance(symbols, dict):
        table = dict(symbols)
    elif isinstance(symbols, (list, tuple, set, frozenset)) or hasattr(symbols, "__iter__") and not isinstance(symbols, (str, bytes)):
        table = {}
        for s in symbols:
            if not isinstance(s, sympy.Symbol):
                raise ExpressionParseError(f"{what}: symbols must be sympy Symbols, got {s!r}")
            table[s.name] = s
    else:
        raise ExpressionParseError(f"{what}: symbols must be a list of sympy Symbols or a dict name -> Symbol, got {type(symbols).__name__}")
    if not all(isinstance(k, str) and isinstance(v, sympy.Basic) for k, v in table.items()):
        raise ExpressionParseError(f"{what}: the symbol table must map names to sympy Symbols")
    return table


_CAP = 10**18


def expansion_size(expr) -> tuple:
    """``(terms, degree)``: an upper estimate of the size of ``expr`` fully expanded, without expanding it.

    Sums add term counts, products multiply them, and a power ``p**n`` of a
    ``t``-term polynomial has at most ``binomial(n + t - 1, t - 1)`` terms (the
    number of monomials of degree ``n`` in ``t`` letters); degrees add in
    products and multiply in powers.  Non-polynomial parts (``sin(x1)``,
    ``sqrt(x1)``) count as one term of degree one.  Capped at ``10**18``.

    >>> import sympy
    >>> x1, x2 = sympy.symbols("x1 x2")
    >>> expansion_size((x1 + x2 + 1)**1000)
    (501501, 1000)
    >>> expansion_size(x1**2/2 + x2**2/2)
    (2, 2)
    """
    if expr.is_Atom:
        return (1, 1 if expr.is_Symbol else 0)
    if expr.is_Add:
        sizes = [expansion_size(a) for a in expr.args]
        return (min(_CAP, sum(t for t, _ in sizes)), max(d for _, d in sizes))
    if expr.is_Mul:
        terms, degree = 1, 0
        for a in expr.args:
            t, d = expansion_size(a)
            terms, degree = min(_CAP, terms * t), degree + d
        return terms, degree
    if expr.is_Pow and expr.exp.is_Integer:
        t, d = expansion_size(expr.base)
        n = abs(int(expr.exp))
        if t == 1:
            return (1, d * n)
        # monomials of degree n in t letters; computed only while it stays below the cap
        terms = math.comb(n + t - 1, t - 1) if min(n, t - 1) < 64 else _CAP
        return (min(_CAP, terms), d * n)
    return (1, 1)


class _Builder:
    """Walks a whitelisted ``ast`` tree and builds the sympy expression."""

    def __init__(self, names, what, text, source):
        self.names, self.what, self.text, self.source = names, what, text, source

    def fail(self, why):
        accepted = ", ".join(sorted(self.names)) or "none"
        raise ExpressionParseError(
            f"{self.what} {_shown(self.text)}: {why}; accepted are numbers, the symbols ({accepted}), "
            f"pi, E, + - * / ** ^, parentheses and the functions {', '.join(sorted(ALLOWED_FUNCTIONS))}"
        )

    # -- numbers ----------------------------------------------------------------------
    def number(self, node):
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(f"the literal {_shown(repr(value), 30)} is not a number")
        if isinstance(value, int):
            return self.sized(sympy.Integer(value))
        # keep the decimal text exact: 0.1 means 1/10, not the nearest double
        literal = (ast.get_source_segment(self.source, node) or repr(value)).replace("_", "")
        try:
            dec = Decimal(literal)
        except InvalidOperation:
            self.fail(f"the number {literal!r} is not understood")
        if not dec.is_finite() or abs(dec.adjusted()) > MAX_DECIMAL_EXPONENT:
            self.fail(f"the number {literal!r} is out of range (|exponent| <= {MAX_DECIMAL_EXPONENT} accepted)")
        sign, digits, exponent = dec.as_tuple()
        mantissa = int("".join(map(str, digits)) or "0") * (-1 if sign else 1)
        if exponent >= 0:
            return self.sized(sympy.Integer(mantissa * 10**exponent))
        return self.sized(sympy.Rational(mantissa, 10**-exponent))

    def sized(self, value):
        """Reject exact numbers too large to be a physical input."""
        if isinstance(value, sympy.Rational):
            if max(abs(value.p).bit_length(), abs(value.q).bit_length()) > MAX_BITS:
                self.fail(f"a number in it has more than {MAX_BITS} bits")
        return value

    # -- the walk ---------------------------------------------------------------------
    def visit(self, node, depth):
        if depth > MAX_DEPTH:
            self.fail(f"it is nested more than {MAX_DEPTH} levels deep")
        if isinstance(node, ast.Constant):
            return self.number(node)
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            if node.id in _CONSTANTS:
                return _CONSTANTS[node.id]
            if node.id in ALLOWED_FUNCTIONS:
                self.fail(f"the function {node.id!r} must be called, e.g. {node.id}(x)")
            self.fail(f"the name {node.id!r} is not declared")
        if isinstance(node, ast.UnaryOp):
            if not isinstance(node.op, (ast.UAdd, ast.USub)):
                self.fail(f"the operator {_OPERATOR_NAMES.get(type(node.op), type(node.op).__name__)!r} is not allowed")
            value = self.visit(node.operand, depth + 1)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.BinOp):
            if type(node.op) not in _BINARY:
                self.fail(f"the operator {_OPERATOR_NAMES.get(type(node.op), type(node.op).__name__)!r} is not allowed")
            if isinstance(node.op, (ast.Add, ast.Sub)):
                return self.chain(node, depth, (ast.Add, ast.Sub))
            if isinstance(node.op, (ast.Mult, ast.Div)):
                return self.chain(node, depth, (ast.Mult, ast.Div))
            return self.power(node, depth)
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        if isinstance(node, ast.Attribute):
            self.fail("attribute access is not allowed")
        if isinstance(node, ast.Subscript):
            self.fail("subscripts are not allowed")
        if isinstance(node, ast.Lambda):
            self.fail("lambda is not allowed")
        self.fail(f"the construct {type(node).__name__} is not allowed")

    def chain(self, node, depth, ops):
        """``a + b - c + ...`` or ``a * b / c ...``: walk the left spine without recursion."""
        operands = []
        while isinstance(node, ast.BinOp) and isinstance(node.op, ops):
            operands.append((node.op, node.right))
            node = node.left
        result = self.visit(node, depth + 1)
        for op, right in reversed(operands):
            value = self.visit(right, depth + 1)
            if isinstance(op, ast.Div) and value == 0:
                self.fail("it divides by zero")
            result = self.sized(_BINARY[type(op)](result, value))
        return result

    def power(self, node, depth):
        base = self.visit(node.left, depth + 1)
        exponent = self.visit(node.right, depth + 1)
        if exponent.is_number:
            if exponent.is_real is False:
                self.fail(f"the exponent {exponent} is not real")
            if exponent.is_real and abs(exponent) > MAX_EXPONENT:
                self.fail(f"the exponent {exponent} is larger than {MAX_EXPONENT} in absolute value")
            if base.is_Rational and exponent.is_Rational and base != 0:
                bits = max(abs(base.p).bit_length(), abs(base.q).bit_length())
                if bits * abs(exponent) > MAX_BITS:
                    self.fail(f"a power in it would have more than {MAX_BITS} bits")
            if base == 0 and exponent.is_real and exponent < 0:
                self.fail("it divides by zero")
        return self.sized(base**exponent)

    def call(self, node, depth):
        if not isinstance(node.func, ast.Name):
            self.fail("only calls of the whitelisted functions by name are allowed")
        name = node.func.id
        if name not in ALLOWED_FUNCTIONS:
            self.fail(f"the call of {name!r} is not allowed")
        if node.keywords:
            self.fail(f"keyword arguments are not allowed (in {name})")
        args = [self.visit(a, depth + 1) for a in node.args]
        try:
            return self.sized(ALLOWED_FUNCTIONS[name](*args))
        except (TypeError, ValueError, ArithmeticError) as exc:
            shown = ", ".join(map(str, args))
            self.fail(f"{name}({shown}) is invalid ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})")
