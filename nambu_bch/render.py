"""Rendering of results as text, LaTeX or JSON, and atomic output files.

JSON convention (docs/json.md, "Conventions"): every symbolic expression is a
string that ``sympy.sympify`` reads back with the system's symbol names, e.g.
``sympify(data["H_S"], locals={"x1": Symbol("x1"), ..., "h": Symbol("h")})``
(``str`` of a sympy expression; no floats appear in symbolic output); numbers
of numeric diagnostics are JSON numbers; absent quantities are ``null``; series
by order are ``{"k": coefficient of h^k}``.  The format is documented in
docs/json.md with a JSON Schema (docs/schema/nambu-bch.schema.json).

LaTeX: results are ``aligned`` blocks (:mod:`nambu_bch.printing`); the CLI prints
them as ``align*`` environments, or a complete document (:func:`latex_document`).

The text format is the JSON content laid out one ``key: value`` per line, for
reading in a terminal and for ``grep``.
"""

from __future__ import annotations

from . import atomic

import json
import math

import numpy as np
import sympy

__all__ = ["expression", "jsonable", "to_json", "to_text", "system_dict", "write_output", "latex_document",
           "bracket_text", "bracket_tree", "result_head"]


def expression(value):
    """A sympy expression as a sympify-able string (``None`` stays ``None``)."""
    if value is None:
        return None
    if not isinstance(value, sympy.Basic) and hasattr(value, "as_expr"):  # a sparse-ring element
        value = value.as_expr()
    return str(sympy.sympify(value, strict=True))


def jsonable(obj):
    """``obj`` with sympy objects turned into strings and numpy numbers into Python numbers."""
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, (int,)) and not isinstance(obj, bool):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else str(obj)
    if isinstance(obj, np.generic):
        return jsonable(obj.item())
    if isinstance(obj, np.ndarray):
        return [jsonable(v) for v in obj.tolist()]
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, sympy.Basic) or hasattr(obj, "as_expr"):
        return expression(obj)
    return str(obj)


def to_json(data) -> str:
    """Pretty JSON text of ``data`` (see :func:`jsonable`), with a final newline."""
    return json.dumps(jsonable(data), indent=2) + "\n"


def to_text(data, indent: str = "") -> str:
    """``key: value`` lines; nested dicts are indented, lists of dicts numbered."""
    data = jsonable(data)
    lines = []
    if isinstance(data, list):
        for i, item in enumerate(data, 1):
            if isinstance(item, dict):
                lines.append(f"{indent}[{i}]")
                lines.append(to_text(item, indent + "  ").rstrip("\n"))
            else:
                lines.append(f"{indent}- {item}")
        return "\n".join(lines) + "\n"
    for key, value in data.items():
        if isinstance(value, dict):
            lines.append(f"{indent}{key}:")
            lines.append(to_text(value, indent + "  ").rstrip("\n"))
        elif isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
            lines.append(f"{indent}{key}:")
            lines.append(to_text(value, indent + "  ").rstrip("\n"))
        elif isinstance(value, list):
            lines.append(f"{indent}{key}: {', '.join(map(str, value)) if value else '(none)'}")
        else:
            lines.append(f"{indent}{key}: {'null' if value is None else value}")
    return "\n".join(line for line in lines if line) + "\n"


def system_dict(system) -> dict:
    """The system part of every JSON result: name, coordinates, parameters, ``H``, ``G``."""
    hams = system.hamiltonians
    data = {
        "model": system.name,
        "coordinates": [str(x) for x in system.coordinates],
        "parameters": [str(p) for p in system.parameters],
        "H": expression(hams[0]),
        "G": expression(hams[1]) if len(hams) > 1 else None,
        "bracket": getattr(system, "bracket", None),
    }
    if len(hams) > 2:
        data["hamiltonians"] = [expression(H) for H in hams]
    return data


def result_head(system, integrator, **extra) -> dict:
    """The head of every result's JSON (its ``to_dict()``): :func:`system_dict`, the integrator's name, ``extra``."""
    data = system_dict(system)
    data["integrator"] = integrator
    data.update(extra)
    return data


def latex_document(blocks, standalone: bool = False) -> str:
    r"""LaTeX output of the CLI: each ``aligned`` block in ``\[ ... \]`` (a fragment for a document with
    ``amsmath``), or with ``standalone`` a complete document (see :mod:`nambu_bch.printing`, docs/latex.md)."""
    from .printing import display
    from .printing import standalone as document

    blocks = [blocks] if isinstance(blocks, str) else list(blocks)
    fragment = display(*blocks)
    return document(fragment) if standalone else fragment


def bracket_text(tree) -> str:
    """A bracket tree as sympy-readable text: ``[X(a, b),[X(c, d),X(e, f)]]`` (leaves ``X(slots)`` or ``Xk``).

    ``sympy.sympify`` reads it back as nested lists of ``X(...)`` applications, the slots
    with the system's symbol names.

    >>> import sympy
    >>> x1, x2 = sympy.symbols("x1 x2")
    >>> bracket_text(((x2**2 / 2, x1), (x1, 1)))
    '[X(x2**2/2, x1),X(x1, 1)]'
    """
    if _is_tree(tree):
        return f"[{bracket_text(tree[0])},{bracket_text(tree[1])}]"
    if isinstance(tree, tuple):
        return "X(" + ", ".join(expression(e) for e in tree) + ")"
    return f"X{tree}"


def bracket_tree(tree):
    """A bracket tree as JSON: ``[left, right]`` for a bracket, a list of slot strings (or an int) for a leaf."""
    if _is_tree(tree):
        return {"bracket": [bracket_tree(tree[0]), bracket_tree(tree[1])]}
    if isinstance(tree, tuple):
        return [expression(e) for e in tree]
    return tree


def _is_tree(node) -> bool:
    from .bch.lyndon import is_bracket

    return is_bracket(node)


def write_output(text: str, path) -> None:
    """Write ``text`` to ``path``: atomically for a regular file, as a stream through a device or FIFO (:func:`nambu_bch.atomic.write_output`)."""
    atomic.write_output(path, text)


# --------------------------------------------------------------------------------------------
# the eight fundamental-identity forms, printed from shadow.fundamental_identity.formal_form (Eqs. 1AX-2BY)
# --------------------------------------------------------------------------------------------
def _fi_terms(label: str, bracket_open: str, bracket_close: str) -> list:
    """Signed terms ``"+ X_{..}"`` of the right-hand side of Eq. (label), braces of the slots written as given."""
    from .shadow.fundamental_identity import formal_form

    def slot(text):
        return text.replace("{", bracket_open).replace("}", bracket_close)

    return [("+ " if s > 0 else "- ") + "X_{" + ",".join(slot(t) for t in slots) + "}" for s, slots in formal_form(label)]


def fi_form_text(label: str) -> str:
    """``[X_{A,B},[X_{C,D},X_{E,F}]] = ...`` in representation ``label``, plain text (Eqs. 1AX-2BY).

    >>> fi_form_text("1AX")
    '[X_{A,B},[X_{C,D},X_{E,F}]] = X_{{{E,C,D},A,B},F} + X_{{E,C,D},{F,A,B}} + X_{{E,A,B},{F,C,D}} + X_{E,{{F,C,D},A,B}}'
    """
    return "[X_{A,B},[X_{C,D},X_{E,F}]] = " + " ".join(_fi_terms(label, "{", "}")).lstrip("+ ")


def fi_form_tokens(label: str) -> list:
    """The right-hand side of :func:`fi_form_latex` as signed LaTeX terms (for line breaking)."""
    tokens = _fi_terms(label, r"\{", r"\}")
    tokens[0] = tokens[0][2:] if tokens[0].startswith("+ ") else tokens[0]
    return tokens


def fi_forms_latex(labels=None) -> str:
    r"""The eight forms of ``[X_{A,B},[X_{C,D},X_{E,F}]]`` (Eqs. 1AX-2BY) as one ``aligned`` block, aligned at ``=``."""
    from .printing import aligned
    from .shadow.fundamental_identity import FI_LABELS

    lhs = "[X_{A,B},[X_{C,D},X_{E,F}]]"
    return aligned([(lhs, rf"\overset{{\rm {lab}}}{{=}}", fi_form_tokens(lab)) for lab in labels or FI_LABELS])


def fi_representations_latex(title: str, coefficient, commutator, forms) -> str:
    r"""One ``h^2`` double commutator and its FI representations (Eqs. CL5-CL8) as an ``aligned`` block.

    ``title`` is user text (word, system name) and goes through :func:`nambu_bch.printing.latex_text`;
    ``commutator`` is ``(a, b, d)`` of slot tuples, ``forms`` ``{label: [LiouvilleTerm, ...]}``.
    """
    from .printing import aligned, latex_text, signed

    a, b, d = ("X_{" + ", ".join(sympy.latex(sympy.factor(s)) for s in t) + "}" for t in commutator)
    head = latex_text(title) + r":\quad h^{2}\," + signed(coefficient, first=True) + rf" [{a}, [{b}, {d}]]"

    def tokens(terms):
        toks = [t.to_latex() for t in terms] or ["0"]
        return [tok if i == 0 or tok.startswith("-") else "+ " + tok for i, tok in enumerate(toks)]

    return aligned([("", "", [head])] + [("", rf"\overset{{\rm {lab}}}{{=}}", tokens(terms)) for lab, terms in forms.items()])


def fi_form_latex(label: str) -> str:
    r"""``[X_{A,B},[X_{C,D},X_{E,F}]] \overset{\rm label}{=} ...`` in LaTeX (Eqs. 1AX-2BY)."""
    return r"[X_{A,B},[X_{C,D},X_{E,F}]] \overset{\rm " + label + "}{=} " + " ".join(fi_form_tokens(label))
