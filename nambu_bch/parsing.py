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

Constant subexpressions are bounded too, without evaluating them: an upper bound
on ``log2 |c|`` is carried through the tree (``exp(a) <= e^|a|``,
``|a*b| = |a| |b|``, ``|sin(a)| <= 1`` for real ``a`` ...) and a constant whose
bound exceeds ``2^``:data:`MAX_BITS` is refused (``cos(exp(exp(exp(2.5))))``:
evaluating it, even only to print or compare it, would need tens of thousands
of digits).  Where no bound follows from the tree (the argument of ``exp`` is
``1/(pi - 3)``: a difference may cancel), ``exp``, ``sinh``, ``cosh`` and a
non-integer power refuse it rather than risk such a tower.

Unicode as typed in a notebook is mapped to ASCII by an explicit table, never by
NFKC normalisation: Greek letters to their names (``ω`` -> ``omega``), subscript
digits to digits (``x₁`` -> ``x1``), superscript digits to a power (``x²`` ->
``x^2``), ``·``/``×`` to ``*`` and ``−`` to ``-``.  A mapping that could read two
ways (``xω`` -> ``xomega``?, ``x²3``) or a character outside the table is refused,
with the mapping in the message.  After mapping, the ASCII rules above apply.

An undeclared name is refused with how to declare it (``--param m`` on the
command line, ``parameters=`` in Python) and a "did you mean" when it is close
to a declared one.

Long sums and products (``x1 + x1**2 + ... + x1**300``) are walked
iteratively, so they count as one level of nesting however many terms they
have.
"""

from __future__ import annotations

import ast
import keyword
import math
import re
import numbers
import warnings
from decimal import Decimal, InvalidOperation
from fractions import Fraction

import sympy
from sympy.polys.rings import PolyElement

from .checks import check_sequence, show
from .errors import ExpressionParseError, did_you_mean

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

#: Unicode letters typed in notebooks -> their ASCII names.  Only letters that do not look like a
#: Latin letter: capital Alpha, Beta, ... and omicron are Latin look-alikes and stay refused.
GREEK_NAMES = {
    "α": "alpha", "β": "beta", "γ": "gamma", "δ": "delta", "ε": "epsilon", "ϵ": "epsilon",
    "ζ": "zeta", "η": "eta", "θ": "theta", "ϑ": "theta", "ι": "iota", "κ": "kappa", "μ": "mu",
    "µ": "mu", "ν": "nu", "ξ": "xi", "π": "pi", "ρ": "rho", "σ": "sigma", "τ": "tau",
    "υ": "upsilon", "φ": "phi", "ϕ": "phi", "χ": "chi", "ψ": "psi", "ω": "omega",
    "Γ": "Gamma", "Δ": "Delta", "Θ": "Theta", "Λ": "Lambda", "Ξ": "Xi", "Π": "Pi", "Σ": "Sigma",
    "Φ": "Phi", "Ψ": "Psi", "Ω": "Omega",
}
#: Operators and spaces with one ASCII reading.
UNICODE_OPERATORS = {"·": "*", "⋅": "*", "×": "*", "−": "-", "÷": "/", "\u00a0": " "}
_SUBSCRIPTS = {chr(0x2080 + d): str(d) for d in range(10)}
_SUPERSCRIPTS = {"⁰": "0", "¹": "1", "²": "2", "³": "3", "⁴": "4", "⁵": "5", "⁶": "6", "⁷": "7", "⁸": "8", "⁹": "9"}
#: Characters with a known reading that is refused, and what to write instead.
_UNICODE_ADVICE = {"λ": "'lambda' is a Python keyword; name the parameter e.g. lam",
                   "√": "write sqrt(...)", "ℏ": "write hbar"}


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
    original = text
    text = to_ascii(text, what)
    if len(text) > MAX_LENGTH:
        raise ExpressionParseError(
            f"{what} is {len(text)} characters long once written in ASCII; at most {MAX_LENGTH} are accepted"
        )
    bad = sorted({ch for ch in text if not (ch.isascii() and (ch.isalnum() or ch in ALLOWED_PUNCTUATION))})
    if bad:
        shown = "".join(bad) if all(ch.isprintable() for ch in bad) else ascii("".join(bad))
        raise ExpressionParseError(
            f"{what} {_shown(original)} contains {shown!r}, not accepted; expressions use ASCII letters, digits, "
            f"spaces and {ALLOWED_PUNCTUATION.strip()} (and the Greek letters, sub- and superscript digits "
            f"that map to them, e.g. ω -> omega, x₁ -> x1, x² -> x^2)"
        )
    names = _symbol_table(symbols, what)
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


def as_expression(value, symbols, what: str = "expression") -> sympy.Expr:
    """The one door from a user's value to a sympy expression: text is parsed, never ``sympify``-ed.

    Every public function that accepts an expression passes it through here, because
    ``sympy.sympify`` (and every sympy function that sympifies its arguments implicitly:
    ``expr.subs({x: "..."})``, ``sympy.diff("...", x)``, containers of strings) runs
    ``eval`` on text.

    * ``str``: :func:`parse_expression` with ``symbols`` (the whitelist parser); ``symbols=None``
      where there is no symbol table to read text with (text is then refused);
    * a sympy expression: itself;
    * ``int`` (and numpy integers), :class:`fractions.Fraction`: the exact number; a sparse
      polynomial (``PolyElement``): its expression;
    * anything else that sympy converts without reading text (``sympify(value, strict=True)``:
      floats, numpy floats, objects with ``_sympy_``) to an expression: that expression;
    * anything else (``bool``, ``None``, bytes, lists, dicts, arrays, non-``Expr`` sympy objects):
      :class:`~nambu_bch.errors.ExpressionParseError` naming ``what`` and the type.

    >>> import sympy
    >>> x1 = sympy.Symbol("x1")
    >>> as_expression("x1^2/2", [x1]), as_expression(Fraction(1, 3), [x1]), as_expression(x1 + 1, [])
    (x1**2/2, 1/3, x1 + 1)
    >>> as_expression(["x1"], [x1], what="quantity")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    nambu_bch.errors.ExpressionParseError: quantity must be a sympy expression, a number or a string ..., got list
    """
    if isinstance(value, str):
        if symbols is None:
            raise ExpressionParseError(
                f"{what} {_shown(value)}: text is not accepted here (no system to read its names with); "
                "pass a sympy expression, e.g. sympy.Symbol('x1')**2")
        return parse_expression(value, symbols, what=what)
    if isinstance(value, sympy.Expr):
        return value
    if isinstance(value, Fraction):
        return sympy.Rational(value.numerator, value.denominator)
    if isinstance(value, PolyElement):  # an exact sparse polynomial of the package's algebras
        return value.as_expr()
    if not isinstance(value, (bool, bytes, bytearray, list, tuple, dict, set, frozenset, sympy.Basic)) and value is not None:
        if isinstance(value, numbers.Integral):
            return sympy.Integer(int(value))
        try:
            converted = sympy.sympify(value, strict=True)
        except (sympy.SympifyError, TypeError, ValueError, ArithmeticError):
            converted = None
        if isinstance(converted, sympy.Expr):
            return converted
    raise ExpressionParseError(
        f"{what} must be a sympy expression, a number or a string such as 'x2^2/2 + x1^2/2', "
        f"got {type(value).__name__}{'' if isinstance(value, (list, tuple, dict, set)) else ' ' + _shown(repr(value), 40)}"
    )


#: A symbol name given as text: ASCII letters, digits and underscores (no look-alikes, no LaTeX or source syntax).
SYMBOL_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}\Z")


def as_symbols(value, what: str = "coordinates", names: bool = False) -> tuple:
    """``value`` as a tuple of sympy Symbols, else one line naming ``what`` (never a sympified string).

    A sequence (:func:`~nambu_bch.checks.check_sequence`) of Symbols; with ``names=True`` a string item
    is a name (:data:`SYMBOL_NAME`, not a Python keyword) and becomes ``Symbol(name)``: the name is not read
    as an expression, and nothing that could act in LaTeX or generated source becomes a symbol.
    """
    out = []
    for item in check_sequence(value, what, "sympy Symbols"):
        if names and isinstance(item, str):
            if not SYMBOL_NAME.match(item) or keyword.iskeyword(item):
                raise ExpressionParseError(f"{what}: {show(item)} is not a symbol name; use ASCII letters, digits and "
                                           "'_', starting with a letter, at most 32 characters (e.g. x1, omega)")
            item = sympy.Symbol(item)
        if not isinstance(item, sympy.Symbol):
            raise ExpressionParseError(f"{what} must be sympy Symbols{' or names' if names else ''}, got {show(item)}")
        out.append(item)
    return tuple(out)


def to_ascii(text: str, what: str = "expression") -> str:
    """``text`` with the Unicode a notebook user types mapped to ASCII by an explicit table (never NFKC).

    Greek letters become their names (:data:`GREEK_NAMES`), subscript digits
    digits, a run of superscript digits (optionally after ``⁻``) a power, and
    ``· ⋅ × − ÷`` and the no-break space their ASCII operators.  A Greek letter
    touching another letter (``xω``: ``xomega``, or ``x*omega``?) or a superscript
    followed by a letter or digit (``x²3``) reads two ways and is refused, as is a
    ``⁻`` without digits; the message gives the mapping.  ``λ`` (``lambda`` is a
    Python keyword) and ``√`` are refused with advice.  Characters outside the
    table are left for the caller's ASCII check to refuse.

    >>> to_ascii("x₂²/(2*m) + m*ω²*x₁²/2")
    'x2^2/(2*m) + m*omega^2*x1^2/2'
    >>> to_ascii("xω")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    nambu_bch.errors.ExpressionParseError: expression 'xω': 'ω' (-> 'omega') touches another letter or digit, ...
    """
    if text.isascii():
        return text
    out = []
    i, n = 0, len(text)

    def refuse(why):
        raise ExpressionParseError(f"{what} {_shown(text)}: {why}; write it in ASCII (e.g. ω -> omega, x₁ -> x1, x² -> x^2)")

    while i < n:
        ch = text[i]
        if ch in GREEK_NAMES:
            name = GREEK_NAMES[ch]
            before = text[i - 1] if i else ""
            after = text[i + 1] if i + 1 < n else ""
            if (before.isalpha() or before in _SUBSCRIPTS or before.isdigit()) or after.isalpha():
                refuse(f"{ch!r} (-> {name!r}) touches another letter or digit, so the name it makes is ambiguous; "
                       f"separate it with '*' or write the name")
            out.append(name)
        elif ch in _SUBSCRIPTS:
            out.append(_SUBSCRIPTS[ch])
        elif ch in _SUPERSCRIPTS or ch == "⁻":
            j = i + (ch == "⁻")
            while j < n and text[j] in _SUPERSCRIPTS:
                j += 1
            digits = "".join(_SUPERSCRIPTS[c] for c in text[i + (ch == "⁻"):j])
            if not digits:
                refuse("'⁻' must be followed by superscript digits (x⁻¹ -> x^(-1))")
            if j < n and (text[j].isalnum() or text[j] in _SUBSCRIPTS):
                refuse(f"the superscript {text[i:j]!r} is followed by {text[j]!r}; write the power with ^ "
                       f"(x{text[i:j]} -> x^{'(-' + digits + ')' if ch == '⁻' else digits})")
            out.append(f"^(-{digits})" if ch == "⁻" else f"^{digits}")
            i = j
            continue
        elif ch in UNICODE_OPERATORS:
            out.append(UNICODE_OPERATORS[ch])
        elif ch in _UNICODE_ADVICE:
            refuse(f"{ch!r} is not accepted: {_UNICODE_ADVICE[ch]}")
        else:
            out.append(ch)
        i += 1
    return "".join(out)


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


def _magnitude(log2_bound: float) -> str:
    """``1.2e+05``-style text of a log2 bound (``inf``: beyond the float range)."""
    return "(beyond 10^308)" if log2_bound == math.inf else f"{log2_bound:.3g}"


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


def undeclared_hint(name: str, declared, what: str) -> str:
    """How to declare ``name`` where ``what`` comes from, and a "did you mean" for a close declared name.

    ``--H``/``--G`` (the command line): ``--param NAME``; a model file (``--system ...``): its
    ``parameters``; other flags take numbers only, so no hint; the Python API: ``parameters=``; where no
    names are declared at all, a number is expected.
    """
    if not declared:
        return " (a number is expected here)"
    hint = did_you_mean(name, [n for n in (*declared, *_CONSTANTS) if n not in ("h", "alpha")])
    if what.startswith("--system"):
        return f"{hint}; declare it in the file's parameters"
    if what in ("--H", "--G"):
        return f"{hint}; declare it with --param {name} (symbolic) or --param {name}=VALUE"
    if what.startswith("--"):
        return hint
    return f"{hint}; declare it with parameters=[{name!r}] (e.g. System(..., parameters=[{name!r}]))"


_LOG2E = math.log2(math.e)
#: Functions whose value grows exponentially with their argument: they refuse an argument with no bound.
_GROWING = (sympy.exp, sympy.sinh, sympy.cosh)


def _exp2(u: float) -> float:
    """``2**u`` as a float, ``inf`` beyond the float range."""
    return math.inf if u > 1000 else 2.0**u


def constant_bound(expr, memo=None):
    """``(upper, lower, sign, real)``: bounds on ``log2 |expr|`` of a constant, read from its tree alone.

    Nothing is evaluated: ``|exp(a)| <= e^|a|``, ``|a*b| = |a| |b|``, ``|a + b| <= 2 max(|a|, |b|)``,
    ``|sin(a)| <= 1`` for real ``a``, ``|sqrt(a)| = |a|^(1/2)`` ...; ``lower`` (for divisions) is known
    for numbers, products and sums of terms of one sign, else ``-inf``.  ``upper`` is ``None`` where no
    bound follows from the tree (a division by a difference that may cancel, ``tan``, ``log`` of a
    value that may be tiny); ``inf`` when the bound overflows a float.  ``sign`` is +1/-1 when known
    from the tree, else 0; ``real`` is True when the tree shows the value real.

    >>> up = constant_bound(sympy.exp(sympy.exp(sympy.Rational(5, 2))))[0]  # e^(e^2.5) = 1.95e5 = 2^17.57
    >>> 17.57 < up < 17.58
    True
    >>> constant_bound(1 / (sympy.pi - 3))[0] is None
    True
    """
    if memo is None:
        memo = {}
    found = memo.get(expr)
    if found is None:
        found = memo[expr] = _bound(expr, memo)
    return found


#: The bound of a constant with no bound from its tree (``upper`` None; nothing known of its sign or reality).
_UNKNOWN = (None, -math.inf, 0, False)


def _bound_leaf(e):
    """Bounds of a number, ``pi``, ``E`` or ``I`` (exact, from the value); ``None`` for any other node."""
    if e.is_Rational:
        if e == 0:
            return (-math.inf, -math.inf, 0, True)
        v = math.log2(abs(e.p)) - math.log2(e.q)
        return (v, v, 1 if e > 0 else -1, True)
    if e is sympy.pi or e is sympy.E:
        v = math.log2(float(e))
        return (v, v, 1, True)
    if e is sympy.I:
        return (0.0, 0.0, 0, False)
    return None


def _bound_add(e, args):
    """``|a + b + ..| <= n max |.|``; a lower bound only when every term has the same known sign."""
    ups = [a[0] for a in args]
    if None in ups:
        return _UNKNOWN
    signs = {a[2] for a in args}
    sign = signs.pop() if len(signs) == 1 else 0
    lower = max(a[1] for a in args) if sign else -math.inf
    return (max(ups) + math.log2(len(args)), lower, sign, all(a[3] for a in args))


def _bound_mul(e, args):
    """``log2 |a b ..| = sum log2 |.|`` for both bounds; the signs multiply."""
    if any(a[0] is None for a in args):
        return _UNKNOWN
    return (sum(a[0] for a in args), sum(a[1] for a in args), math.prod(a[2] for a in args), all(a[3] for a in args))


def _bound_integer_power(k, base):
    """``b^k``, ``k`` an integer: ``k`` times the base's bounds (swapped for ``k < 0``); no upper bound from a base
    without one (``k > 0``) or without a lower bound (``k < 0``: a base that may be tiny)."""
    ub, lb, sb, rb = base
    if k > 0:
        up, low = (None if ub is None else k * ub), k * lb
    else:
        up, low = (k * lb if lb > -math.inf else None), (k * ub if ub is not None else -math.inf)
        if ub is None:
            up = None
    sign = (sb if k % 2 else 1) if sb else (1 if k % 2 == 0 and rb else 0)
    return (up, low, sign, rb)


def _bound_pow(e, args):
    """``b^k``: integer ``k`` (:func:`_bound_integer_power`), rational ``k`` (``k`` times the base's bounds),
    else ``|b^k| = |exp(k log b)| <= exp(2^ue (|log2 b| + 4.6))`` (the 4.6 covers ``pi |Im k| / ln 2``)."""
    base, (ue, le, se, re) = args
    ub, lb, sb, rb = base
    k = e.exp
    if k.is_Integer:
        return _bound_integer_power(int(k), base)
    if ub is None or ue is None:
        return _UNKNOWN
    if k.is_Rational:
        up, low = (float(k) * ub, float(k) * lb) if k > 0 else (float(k) * lb, float(k) * ub)
        if up != up or low != low:  # inf * 0
            return _UNKNOWN
        return (up, low, 1 if sb == 1 and rb else 0, sb == 1 and rb)
    up = _exp2(ue) * (max(abs(ub), abs(lb)) + 4.6)
    real = sb == 1 and rb and re
    return (up, -up, 1 if real else 0, real)


def _bound_growing(func, arg):
    """``exp``, ``sinh``, ``cosh``: ``|f(a)| <= e^|a|``; ``exp`` of a real ``a`` of known sign is on one side of 1."""
    ua, la, sa, ra = arg
    up = _exp2(ua) * _LOG2E
    if func is sympy.exp and ra and sa:  # e^a <= 1 for a < 0, >= 1 for a > 0
        return (0.0, -up, 1, True) if sa < 0 else (up, 0.0, 1, True)
    return (up, 0.0 if (func is sympy.cosh and ra) else -up, 1 if ra and func is not sympy.sinh else 0, ra)


def _bound_sin_cos(func, arg):
    """``|sin a|, |cos a| <= 1`` for real ``a``, else ``<= e^|a|``."""
    ua, la, sa, ra = arg
    return (0.0 if ra else _exp2(ua) * _LOG2E, -math.inf, 0, ra)


def _bound_tanh(func, arg):
    """``|tanh a| <= 1`` for real ``a``."""
    return (0.0, -math.inf, 0, True) if arg[3] else _UNKNOWN


def _bound_atan(func, arg):
    """``|atan a| <= pi/2 < 2`` for real ``a``."""
    return (1.0, -math.inf, 0, True) if arg[3] else _UNKNOWN


def _bound_asin_acos(func, arg):
    """``|asin a|, |acos a| <= pi + 1.1 + ln |a|`` (the principal branch, any complex ``a``)."""
    return (math.log2(math.pi + 1.1 + max(arg[0], 0.0) * math.log(2)), -math.inf, 0, False)


def _bound_log(func, arg):
    """``|log a| <= |ln |a|| + pi``: needs a lower bound on ``|a|`` (a value that may be tiny has none)."""
    ua, la, sa, ra = arg
    if not la > -math.inf:
        return _UNKNOWN
    return (math.log2(max(abs(ua), abs(la)) * math.log(2) + math.pi), -math.inf, 0, sa == 1 and ra)


#: The rules for a function of one argument whose upper bound is known (``Abs`` is taken before that check).
_FUNCTION_BOUNDS = {sympy.exp: _bound_growing, sympy.sinh: _bound_growing, sympy.cosh: _bound_growing,
                    sympy.sin: _bound_sin_cos, sympy.cos: _bound_sin_cos, sympy.tanh: _bound_tanh,
                    sympy.atan: _bound_atan, sympy.asin: _bound_asin_acos, sympy.acos: _bound_asin_acos,
                    sympy.log: _bound_log}


def _bound_function(e, args):
    """A function of one argument by :data:`_FUNCTION_BOUNDS` (``|Abs a| = |a|``); anything else has no bound."""
    if len(args) != 1:
        return _UNKNOWN
    arg = args[0]
    if e.func is sympy.Abs:
        return (arg[0], arg[1], 1, True)
    rule = _FUNCTION_BOUNDS.get(e.func)
    if rule is None or arg[0] is None:
        return _UNKNOWN
    return rule(e.func, arg)


def _bound(e, memo):
    """:func:`constant_bound` of one node from its arguments' bounds: a table of rules per kind of node."""
    leaf = _bound_leaf(e)
    if leaf is not None:
        return leaf
    args = [constant_bound(a, memo) for a in e.args]
    rule = _bound_add if e.is_Add else _bound_mul if e.is_Mul else _bound_pow if e.is_Pow else _bound_function
    return rule(e, args)


class _Builder:
    """Walks a whitelisted ``ast`` tree and builds the sympy expression."""

    def __init__(self, names, what, text, source):
        self.names, self.what, self.text, self.source = names, what, text, source
        self.bounds: dict = {}

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
        """Reject exact numbers too large to be a physical input, and constants too large to evaluate."""
        if isinstance(value, sympy.Rational):
            if max(abs(value.p).bit_length(), abs(value.q).bit_length()) > MAX_BITS:
                self.fail(f"a number in it has more than {MAX_BITS} bits")
        elif isinstance(value, sympy.Expr) and value.is_number:
            self.bounded(value)
        elif isinstance(value, (sympy.Add, sympy.Mul)):
            # sympy merges constants on its own (exp(700)*x1*exp(700) = x1*exp(1400)): bound the merged parts
            for part in value.args:
                if part.is_number and not part.is_Rational:
                    self.bounded(part)
        return value

    def bounded(self, value):
        """The tree bound of a constant (:func:`constant_bound`); refuses one that may exceed ``2^MAX_BITS``."""
        bound = constant_bound(value, self.bounds)
        if bound[0] is not None and bound[0] > MAX_BITS:
            self.fail(f"the constant {_shown(str(value), 50)[1:-1]} may be as large as 2^{_magnitude(bound[0])} "
                      f"(constants are accepted up to 2^{MAX_BITS}, judged from the expression without evaluating it)")
        return bound

    def growing(self, name, argument):
        """``exp``/``sinh``/``cosh`` of a constant, or a constant non-integer power: its size must be bounded."""
        if isinstance(argument, sympy.Expr) and argument.is_number and self.bounded(argument)[0] is None:
            self.fail(f"the constant {_shown(str(argument), 50)[1:-1]} in {name} cannot be bounded without evaluating it "
                      "(a difference that may cancel, tan or log); write it as a decimal")

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
            self.fail(f"the name {node.id!r} is not declared{undeclared_hint(node.id, self.names, self.what)}")
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
            # bound before comparing: the comparisons below evaluate the exponent
            self.growing("the exponent", exponent)
            if not exponent.is_Integer:
                self.growing("the base of a non-integer power", base)
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
        if ALLOWED_FUNCTIONS[name] in _GROWING and len(args) == 1:
            self.growing(name, args[0])
        try:
            value = ALLOWED_FUNCTIONS[name](*args)
        except (TypeError, ValueError, ArithmeticError) as exc:
            shown = ", ".join(map(str, args))
            self.fail(f"{name}({shown}) is invalid ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})")
        return self.sized(value)
