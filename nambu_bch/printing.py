r"""One rendering layer for every result: sympy printer hooks, series by powers of ``h``, LaTeX layout.

Every result class (``ShadowFamily``, ``ConservedQuantities``, ``ExactShadow``,
``FormalBCH``, ``EffectiveField``) inherits :class:`Printable` and defines two
methods, ``to_latex()`` and ``to_text()``; the mixin turns them into sympy's
printer hooks (``sympy.latex(result)``, ``sympy.sstr(result)``), ``str(result)``
and Jupyter's ``_repr_latex_``.

LaTeX convention (docs/latex.md)
--------------------------------
``to_latex()`` returns one ``\begin{aligned} ... \end{aligned}`` block: rows
``lhs &= rhs`` aligned at the relation, long right-hand sides broken between
terms (``&\quad + ...``) at about :data:`WIDTH` characters of printed math, and
brackets that span a break written ``\Bigl( ... \Bigr)`` (``\left``/``\right``
cannot span lines).  The block belongs in display math with ``amsmath``
loaded: ``\[ ... \]``, ``equation*``, or ``$$ ... $$`` in Jupyter/MathJax.
:func:`display` turns blocks into ``align*`` environments (a fragment for a
document body that may break across pages, what the CLI prints) and
:func:`standalone` writes a complete document.
User text (system names, words) reaches LaTeX only through :func:`latex_text`.

Series convention
-----------------
A quantity ``S(h)`` close to a Hamiltonian ``H`` is shown as the paper writes
Eqs. (SH12321c), (SG12321c) and Table (table): ``S = H + h^2 (...) + h^4 (...) + O(h^p)``,
the coefficient of each power of ``h`` collected and its monomials' coefficients
factored (:func:`h_coefficients`).
"""

from __future__ import annotations

import re

import sympy

from .printable import Printable  # the mixin imports nothing: results served without sympy use it
from .symbols import STEP

__all__ = [
    "Printable", "HSeries", "bracket_sum", "WIDTH", "h_coefficients", "laid_out", "series_tokens", "series_text", "sum_tokens",
    "signed",
    "aligned", "latex_text", "display", "standalone", "flatten",
]


#: Estimated width of one display line, in characters of printed math (``article``, 10 pt, no overfull boxes).
WIDTH = 58


# --------------------------------------------------------------------------------------------
# series by powers of h
# --------------------------------------------------------------------------------------------
def _coefficients(expr, gens):
    """``[(exponents, coefficient)]`` of the expanded ``expr`` as a polynomial in ``gens``, highest monomial first
    (lex, as ``Poly.terms()``), zero coefficients left out; ``None`` when ``expr`` is not a polynomial in ``gens``.

    The terms are grouped by their power products and each group is added once: linear in the number of
    terms.  (``Poly(expr, *gens)`` with symbolic coefficients adds them one by one into a growing sympy
    ``Add``, quadratic: minutes for the h^6 shadow pair of the rigid body with symbolic moments of inertia.)
    """
    index = {g: i for i, g in enumerate(gens)}
    groups: dict = {}
    for term in sympy.Add.make_args(expr):
        exponents, rest = [0] * len(gens), []
        for factor in sympy.Mul.make_args(term):
            base, e = factor.as_base_exp()
            if base in index and e.is_Integer and e >= 0:
                exponents[index[base]] += int(e)
            elif factor.has(*gens):  # not a power product: a negative power, or an unexpanded factor
                if not expr.is_polynomial(*gens):
                    return None
                return [(m, c) for m, c in sympy.Poly(expr, *gens).terms() if c != 0]
            else:
                rest.append(factor)
        groups.setdefault(tuple(exponents), []).append(sympy.Mul(*rest))
    out = ((m, sympy.Add(*cs)) for m, cs in groups.items())
    return sorted(((m, c) for m, c in out if c != 0), reverse=True)


def _factored(c):
    """``factor(c)``; a complex coefficient as ``factor(a) + I*factor(b)`` (``a``, ``b`` free of ``I``), so that
    ``factor`` does not pull ``I`` out of ``a + b I`` and print ``I*(b - a I)``."""
    if not c.has(sympy.I):
        return sympy.factor(c)
    c = sympy.expand(c)
    b = c.coeff(sympy.I)
    a = sympy.expand(c - sympy.I * b)
    if a.has(sympy.I) or b.has(sympy.I):
        return sympy.factor(c)
    return sympy.factor(a) + sympy.I * sympy.factor(b)


def _by_monomial(expr, coordinates):
    """The expanded ``expr`` as a sum over monomials of the coordinates, each coefficient factored (unevaluated Add)."""
    coefficients = _coefficients(expr, coordinates) if coordinates else None
    if coefficients is None:
        return sympy.factor(expr)
    return by_monomials([(m, _factored(c)) for m, c in coefficients], coordinates)


def by_monomials(rows, coordinates):
    """``sum c_m x^m`` as an unevaluated ``Add`` in the order of ``rows`` (``[(exponent tuple, factored c_m)]``,
    highest monomial first): the layout of :func:`h_coefficients` from coefficients already factored."""
    terms = [c * sympy.Mul(*(x**e for x, e in zip(coordinates, m))) for m, c in rows]
    if not terms:
        return sympy.Integer(0)
    return sympy.Add(*terms, evaluate=False) if len(terms) > 1 else terms[0]


def h_coefficients(expr, base, coordinates, step=STEP):
    """``[(k, c_k)]`` with ``expr - base = sum_k c_k step^k``, lowest power first; ``None`` if not polynomial in ``step``.

    Each ``c_k`` is laid out by monomials of the coordinates with factored coefficients
    (``(I2 - I3)/(I2 I3) x1 x2`` rather than one long common denominator), the layout of
    Eqs. (SH12321c), (SG12321c).

    >>> x, m = sympy.symbols("x m")
    >>> h_coefficients(x**2/2 + sympy.Symbol("h")**2 * x**2/(4*m), x**2/2, [x])
    [(2, x**2/(4*m))]
    """
    diff = sympy.expand(sympy.sympify(expr, strict=True) - sympy.sympify(base, strict=True))
    if diff == 0:
        return []
    coefficients = _coefficients(diff, [step])
    if coefficients is None:
        return None
    return sorted(((m[0], _by_monomial(c, coordinates)) for m, c in coefficients), key=lambda item: item[0])


def laid_out(by_power: dict, coordinates) -> list:
    """``[(k, c_k)]`` of :func:`h_coefficients` from the powers of ``h`` already separated: ``by_power`` maps
    ``k`` to the expanded sympy form of ``c_k`` (an exact result's own per-order data), so the sum is never expanded
    and regrouped; each ``c_k`` is laid out by monomials with factored coefficients, zero ones left out.

    >>> x, m = sympy.symbols("x m")
    >>> laid_out({2: x**2/(4*m)}, [x])
    [(2, x**2/(4*m))]
    """
    return [(k, _by_monomial(c, coordinates)) for k, c in sorted(by_power.items()) if c != 0]


def signed(term, first=False) -> str:
    """``+ t`` / ``- t`` LaTeX of one term (``first``: no ``+``), as sympy's Add printer writes signs."""
    term = sympy.sympify(term, strict=True)
    if term.could_extract_minus_sign():
        return "- " + sympy.latex(-term)
    return ("" if first else "+ ") + sympy.latex(term)


def _ordered_terms(expr):
    from sympy.printing.latex import LatexPrinter

    return LatexPrinter()._as_ordered_terms(expr)


def _term_tokens(term, first) -> list:
    r"""One term as tokens: itself, or -- when wider than a line -- ``rest \Bigl(p_1 + ...\Bigr) \Bigl(q_1 + ...\Bigr)^{-1}``
    split at the terms of its long polynomial factors ``p`` (numerator) and ``q`` (denominator): the long factored
    coefficients of the rigid body, the rational-in-h invariants of triple-jump words."""
    whole = signed(term, first)
    if width(whole) <= WIDTH - 8:
        return [whole]
    sign = term.could_extract_minus_sign()
    body = -term if sign else term
    factors = sympy.Mul.make_args(body)

    def long_poly(f):
        base = f.base if isinstance(f, sympy.Pow) and f.exp == -1 else f
        return isinstance(base, sympy.Add) and width(sympy.latex(base)) > 12

    split = [f for f in factors if long_poly(f)]
    if not split:
        return [whole]
    rest = sympy.Mul(*[f for f in factors if not long_poly(f)])
    split.sort(key=lambda f: isinstance(f, sympy.Pow))  # numerators first
    tokens = []
    for f in split:
        inverse = isinstance(f, sympy.Pow)
        inner = sum_tokens(f.base if inverse else f)
        inner[0] = r"\Bigl(" + inner[0]
        inner[-1] += r"\Bigr)" + ("^{-1}" if inverse else "")
        tokens += inner
    tokens[0] = ("- " if sign else ("" if first else "+ ")) + ("" if rest == 1 else sympy.latex(rest)) + tokens[0]
    return tokens


def sum_tokens(expr, first=True) -> list:
    """The terms of ``expr`` in sympy's printed order, each a signed LaTeX token (a line may break between them)."""
    expr = sympy.sympify(expr, strict=True)
    terms = _ordered_terms(expr) if isinstance(expr, sympy.Add) else [expr]
    return [tok for i, t in enumerate(terms) for tok in _term_tokens(t, first and i == 0)]


def series_tokens(base_latex, expr, base, coordinates, remainder=None, step=STEP, coefficients=None) -> list:
    r"""Tokens of ``base + h^k (c_k) + ... + O(h^remainder)``; ``\Bigl( \Bigr)`` may span line breaks.

    Falls back to ``base + (expr - base)`` term by term when the difference is not
    polynomial in ``h`` (conserved quantities of triple-jump words are rational in ``h``).
    ``coefficients``: the ``[(k, c_k)]`` of :func:`h_coefficients` when the caller has them (:func:`laid_out`).
    """
    if coefficients is None:
        coefficients = h_coefficients(expr, base, coordinates, step)
    tokens = [base_latex]
    if coefficients is None:  # rational in h: by monomials of the coordinates, coefficients factored
        tokens += sum_tokens(_by_monomial(sympy.expand(sympy.sympify(expr, strict=True) - sympy.sympify(base, strict=True)), coordinates), first=False)
    for k, c in coefficients or ():
        inner = sum_tokens(c, first=(k != 0))
        power = sympy.latex(step**k) if k else ""
        if k == 0:  # the h-free part: its terms as they are
            tokens += inner
            continue
        if len(inner) == 1:  # one monomial: + h^k t, no brackets
            tokens.append(signed(step**k * c))
            continue
        inner[0] = rf"+ {power}\Bigl({inner[0]}"
        inner[-1] = rf"{inner[-1]}\Bigr)"
        tokens += inner
    if remainder is not None:
        tokens.append(rf"+ O({sympy.latex(step ** remainder)})")
    if tokens[0] == "0" and len(tokens) > 1:  # 0 + ... -> ...
        first = tokens[1]
        tokens = [first[2:] if first.startswith("+ ") else first, *tokens[2:]]
    if tokens[0] == "0" and len(tokens) == 1 and remainder is None:
        return tokens
    return tokens


def series_text(base_text, expr, base, coordinates, remainder=None, step=STEP, coefficients=None) -> str:
    """Plain-text twin of :func:`series_tokens`: ``H + h**2*(...) - h**4*x1**2/12 + O(h^4)``.

    >>> x, h = sympy.symbols("x h")
    >>> series_text("H", x**2/2 - h**2*x**2/8 + h**4*(x + x**2), x**2/2, [x], 6)
    'H - h**2*x**2/8 + h**4*(x**2 + x) + O(h^6)'
    """
    if coefficients is None:
        coefficients = h_coefficients(expr, base, coordinates, step)
    text = base_text
    if coefficients is None:
        text += f" + ({sympy.expand(sympy.sympify(expr, strict=True) - sympy.sympify(base, strict=True))})"
    for k, c in coefficients or ():
        if isinstance(c, sympy.Add) or k == 0:
            text += " + " + (f"{step}**{k}*({c})" if k > 1 else (f"{step}*({c})" if k == 1 else f"({c})"))
        else:
            term = sympy.sympify(step**k * c, strict=True)
            text += f" - {-term}" if term.could_extract_minus_sign() else f" + {term}"
    if remainder is not None:
        text += f" + O({step}^{remainder})"
    return text


class HSeries(Printable):
    r"""An expression shown as the paper writes a shadow Hamiltonian: ``lhs = H + h^2(...) + O(h^p)``.

    For a quantity typed in from the paper, a family member, a difference: anything near a
    Hamiltonian ``base`` (see :func:`series_tokens`).

    Parameters
    ----------
    lhs : str -- LaTeX of the left-hand side, e.g. ``"H_S"``
    expr, base : sympy expressions
    base_name : str -- LaTeX of ``base`` (``"H"``; ``"0"`` prints ``expr`` itself by powers of h)
    coordinates : sequence of Symbols (monomials whose coefficients are factored)
    remainder : int, optional -- print ``+ O(h^remainder)``

    >>> x, h = sympy.symbols("x h")
    >>> print(HSeries("H_S", x**2/2 + h**2*x**2/12, x**2/2, "H", [x], 4))
    H_S = H + h**2*x**2/12 + O(h^4)
    """

    def __init__(self, lhs, expr, base, base_name, coordinates, remainder=None):
        self.lhs, self.expr, self.base, self.base_name = lhs, sympy.sympify(expr, strict=True), sympy.sympify(base, strict=True), base_name
        self.coordinates, self.remainder = tuple(coordinates), remainder

    def to_latex(self) -> str:
        return aligned([(self.lhs, "=", series_tokens(self.base_name, self.expr, self.base, self.coordinates, self.remainder))])

    def to_text(self) -> str:
        plain = lambda t: t.replace("{", "").replace("}", "").replace("\\", "")  # noqa: E731
        body = series_text(plain(self.base_name), self.expr, self.base, self.coordinates, self.remainder)
        return f"{plain(self.lhs)} = " + (body[4:] if body.startswith("0 + ") else body)

    def __repr__(self):
        return f"HSeries({self.lhs!r}, {self.expr})"


def bracket_sum(lhs, items, names=None, remainder=None, step=STEP) -> str:
    r"""``lhs &= c_1 h^{k_1} [X,[X,X]] + ...`` as an ``aligned`` block, one token per bracket term.

    ``items`` are ``(coefficient, tree, power_of_h)``; trees are printed by
    :func:`nambu_bch.bch.lyndon.tree_to_latex` (generators ``X_{k}`` or Liouville terms
    ``X_{A,B}``), e.g. the Liouville-term expansion of Eq. (BCH4).
    """
    from .bch.lyndon import terms_to_latex

    tokens = []
    for c, tree, k in items:
        tok = terms_to_latex([(c, tree, step**k)], names)
        tokens.append(tok if not tokens else ("- " + tok[1:] if tok.startswith("-") else "+ " + tok))
    if remainder is not None:
        tokens.append(f"+ O({sympy.latex(step ** remainder)})")
    return aligned([(lhs, "=", tokens or ["0"])])


# --------------------------------------------------------------------------------------------
# layout
# --------------------------------------------------------------------------------------------
_WORD = re.compile(r"\\([A-Za-z]+|.)|(.)", re.S)
_ZERO_WIDTH = {"left", "right", "Bigl", "Bigr", "bigl", "bigr", "big", "Big", "mathrm", "rm", "operatorname",
               "displaystyle", "limits", "!", ",", ";", ":", " "}


def _group(text, i):
    """``(content, next index)`` of the brace group at ``text[i]`` (or the single character there)."""
    while i < len(text) and text[i] == " ":
        i += 1
    if i >= len(text):
        return "", i
    if text[i] != "{":
        m = _WORD.match(text, i)
        return m.group(0), m.end()
    depth, j = 0, i
    while j < len(text):
        if text[j] == "\\":
            j += 2
            continue
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return text[i + 1 : j], j + 1
        j += 1
    return text[i + 1 :], len(text)


def width(latex: str) -> float:
    r"""Estimated printed width of a LaTeX math string, in characters (``\frac`` counts its wider part).

    >>> width(r"\frac{x_{2}^{2}}{2 m} + x_{3}")
    6.3
    """
    total, i = 0.0, 0
    while i < len(latex):
        m = _WORD.match(latex, i)
        i = m.end()
        command, char = m.group(1), m.group(2)
        if command in ("frac", "dfrac", "tfrac"):
            num, i = _group(latex, i)
            den, i = _group(latex, i)
            total += max(width(num), width(den)) + 0.4
        elif command in ("text", "overset", "mathrm", "operatorname"):
            arg, i = _group(latex, i)
            total += width(arg) if command != "text" else len(arg) * 0.8
            if command == "overset":
                base, i = _group(latex, i)
                total += width(base)
        elif command in ("quad",):
            total += 2
        elif command in ("qquad",):
            total += 4
        elif command is not None:
            total += 0 if command in _ZERO_WIDTH else 1
        elif char in "^_":
            arg, i = _group(latex, i)
            total += 0.7 * width(arg)
        elif char in "{} \n&":
            continue
        elif char in "+-=<>":  # binary operators and relations carry space on both sides
            total += 1.8
        else:
            total += 1
    return round(total, 1)


def aligned(rows, line_width: float = WIDTH) -> str:
    r"""An ``aligned`` block of rows ``(lhs, relation, tokens)``, broken between tokens to ``line_width``.

    ``tokens`` is a list of LaTeX pieces (each a term with its sign); a row longer than
    ``line_width`` continues on ``&\quad`` lines.  A row with an empty ``lhs`` and
    ``relation`` is a text row written ``&tokens``.

    >>> print(aligned([("H_{S}", "=", ["H", r"+ \frac{h^{2}}{12}", "+ O(h^{4})"])]))
    \begin{aligned}
    H_{S} &= H + \frac{h^{2}}{12} + O(h^{4})
    \end{aligned}
    """
    lines = []
    for r, (lhs, rel, tokens) in enumerate(rows):
        head = f"{lhs} &{rel} " if (lhs or rel) else "&"
        indent = width(lhs) + width(rel) + 1
        current, used = [], indent
        out = []
        for tok in tokens or ["0"]:
            w = width(tok) + 1
            if current and used + w > line_width:
                out.append(" ".join(current))
                current, used = [], 6.0
            current.append(tok)
            used += w
        out.append(" ".join(current))
        text = head + (" \\\\\n&\\quad ".join(out))
        lines.append(text)
    return "\\begin{aligned}\n" + " \\\\\n".join(lines) + "\n\\end{aligned}"


_TEXT_SAFE = re.compile(r"[A-Za-z0-9 .,:;=/()+*\-\[\]<>!?']+")


def latex_text(text) -> str:
    r"""User text (a system name, a word) as math-mode LaTeX that cannot inject commands.

    Runs of safe characters (letters, digits, space, ``.,:;=/()+*-[]<>!?'``) go into
    ``\text{...}``; ``_`` becomes ``\_``; every other character is dropped as ``?``.

    >>> latex_text("my_model}\\x")
    '\\text{my}\\_\\text{model??x}'
    """
    out, pending = [], []
    for ch in str(text):
        if ch == "_":
            if pending:
                out.append(r"\text{" + "".join(pending) + "}")
                pending = []
            out.append(r"\_")
        else:
            pending.append(ch if _TEXT_SAFE.fullmatch(ch) else "?")
    if pending:
        out.append(r"\text{" + "".join(pending) + "}")
    return "".join(out)


def display(*blocks) -> str:
    r"""``aligned`` blocks as a document-body fragment: each an ``align*`` environment with the same rows.

    ``align*`` (unlike ``aligned`` inside ``\[ \]``) may break across pages under
    ``\allowdisplaybreaks``, so long results (the rigid body at order 4) fit; needs ``amsmath``.
    """
    out = []
    for block in blocks:
        if block:
            body = block.strip("\n").replace("\\begin{aligned}", "\\begin{align*}").replace("\\end{aligned}", "\\end{align*}")
            out.append(body)
    return "\n".join(out) + "\n"


PREAMBLE = "\\documentclass[10pt]{article}\n\\usepackage{amsmath}\n\\allowdisplaybreaks\n"


def standalone(fragment: str, title: str | None = None) -> str:
    r"""A complete LaTeX document around a fragment of :func:`display` blocks (compiles with pdflatex)."""
    head = "" if title is None else "\\noindent " + "$" + latex_text(title) + "$\n"
    return PREAMBLE + "\\begin{document}\n" + head + fragment.rstrip("\n") + "\n\\end{document}\n"


def flatten(block: str) -> str:
    r"""An ``aligned`` block as one line (alignment points and breaks removed), e.g. to compare with the paper."""
    text = re.sub(r"\\(begin|end)\{aligned\}", "", block)
    text = text.replace("\\\\\n&\\quad ", " ").replace("\\\\\n", " ").replace("&", "")
    text = text.replace(r"\Bigl(", r"\left(").replace(r"\Bigr)", r"\right)")
    return " ".join(text.split())
