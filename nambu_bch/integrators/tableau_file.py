"""Butcher tableaux from TOML files: exact coefficients as text, checked against the order they claim.

A tableau file (read like a model file: a private regular file of bounded size, :mod:`nambu_bch.model_file`)::

    name = "lobatto3c"                      # letters, digits, '-' and '_' (what the output calls the method)
    reference = "Hairer-Wanner II, Table IV.5.11"
    order = 2                               # claimed: every order condition of order <= 2 must hold
    A = [["1/2", "-1/2"], ["1/2", "1/2"]]   # s x s, s <= MAX_STAGES
    b = ["1/2", "1/2"]
    c = ["0", "1"]                          # optional; if given, c_i = sum_j a_ij must hold exactly

Each coefficient is a string (or a TOML integer) read by the whitelist parser (:func:`nambu_bch.model_file.parse_value`:
numbers, ``+ - * / ^``, ``sqrt`` ...), never by ``eval`` or ``sympify``.  The claimed ``order`` is checked exactly
against the conditions ``Phi(t) = 1/gamma(t)`` on every rooted tree with at most ``order`` vertices (Hairer, Lubich,
Wanner, *Geometric Numerical Integration*, Sect. III.1); zero is decided by expanding in the field the coefficients
generate (square roots of rationals), so a tableau whose conditions need deeper radical identities is refused.
"""

from __future__ import annotations

import os
import re
import tomllib

import sympy

from ..errors import InvalidCompositionError
from .runge_kutta import ButcherTableau

#: Most stages accepted (an s-stage tableau has s^2 + s coefficients; the order check grows with s and the order).
MAX_STAGES = 6
#: Highest order claimed that is checked (115 trees of 8 vertices ... the modified equation accepts h^8).
MAX_CLAIMED_ORDER = 8
KEYS = ("name", "reference", "order", "A", "b", "c")
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]{0,39}")


def load_tableau(path, flag: str = "--tableau") -> ButcherTableau:
    """The :class:`~nambu_bch.integrators.runge_kutta.ButcherTableau` the TOML file at ``path`` defines.

    Raises
    ------
    InvalidCompositionError -- one line naming the file and the offending key: unreadable or oversized file, TOML
        syntax, unknown keys, a malformed or non-real coefficient, ``c`` not the row sums, an order condition of the
        claimed order that fails.
    """
    from ..model_file import _read_regular_file

    shown = os.fspath(path)
    raw = _read_regular_file(shown, flag, InvalidCompositionError)
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError) as exc:
        why = "not UTF-8 text" if isinstance(exc, UnicodeDecodeError) else " ".join(str(exc).split())[:200]
        raise InvalidCompositionError(f"{flag} {shown}: not valid TOML ({why})") from None
    return tableau_from_dict(data, f"{flag} {shown}")


def tableau_from_dict(data: dict, where: str = "tableau") -> ButcherTableau:
    """The checked tableau of a parsed tableau file (see the module docstring); ``where`` prefixes the messages."""
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise InvalidCompositionError(f"{where}: unknown key(s) {', '.join(unknown)}; accepted keys are {', '.join(KEYS)}")
    missing = [k for k in ("name", "order", "A", "b") if k not in data]
    if missing:
        raise InvalidCompositionError(f"{where}: missing key(s) {', '.join(missing)} (name, order, A and b are required)")
    name = data["name"]
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise InvalidCompositionError(f"{where}: name must be 1-40 letters, digits, '-' or '_' starting with a letter, "
                                      f"got {str(name)[:40]!r}")
    reference = data.get("reference", "tableau file")
    if not isinstance(reference, str) or len(reference) > 300:
        raise InvalidCompositionError(f"{where}: reference must be a string of at most 300 characters")
    order = data["order"]
    if isinstance(order, bool) or not isinstance(order, int) or not 1 <= order <= MAX_CLAIMED_ORDER:
        raise InvalidCompositionError(f"{where}: order must be an integer 1..{MAX_CLAIMED_ORDER}, got {str(order)[:20]!r}")
    A, b = data["A"], data["b"]
    if not isinstance(b, list) or not 1 <= len(b) <= MAX_STAGES:
        raise InvalidCompositionError(f"{where}: b must be a list of 1..{MAX_STAGES} coefficients")
    s = len(b)
    if not isinstance(A, list) or len(A) != s or not all(isinstance(row, list) and len(row) == s for row in A):
        raise InvalidCompositionError(f"{where}: A must be a list of {s} rows of {s} coefficients (b has {s})")
    A = tuple(tuple(_coefficient(a, f"{where}: A[{i + 1}][{j + 1}]") for j, a in enumerate(row)) for i, row in enumerate(A))
    b = tuple(_coefficient(x, f"{where}: b[{i + 1}]") for i, x in enumerate(b))
    sums = tuple(sympy.expand(sum(row, sympy.Integer(0))) for row in A)
    if "c" in data:
        c = data["c"]
        if not isinstance(c, list) or len(c) != s:
            raise InvalidCompositionError(f"{where}: c must be a list of {s} coefficients")
        for i, x in enumerate(c):
            if sympy.expand(_coefficient(x, f"{where}: c[{i + 1}]") - sums[i]) != 0:
                raise InvalidCompositionError(f"{where}: c[{i + 1}] = {x!r} is not the row sum {sums[i]} of A; "
                                              "give c_i = sum_j a_ij or leave c out")
    tableau = ButcherTableau(name, A, b, sums, order, reference)
    failed = first_failed_condition(tableau, order)
    if failed is not None:
        tree, phi, want = failed
        raise InvalidCompositionError(f"{where}: the claimed order {order} fails the order condition of the tree {tree} "
                                      f"({len(_vertices(tree))} vertices): Phi = {phi}, 1/gamma = {want}")
    return tableau


def first_failed_condition(tableau, order: int):
    """``(tree, Phi(t), 1/gamma(t))`` of the first tree with at most ``order`` vertices whose condition fails, else None."""
    from ..bseries import rooted_trees as T

    for n in range(1, order + 1):
        for t in T.trees(n):
            phi, want = T.elementary_weight(t, tableau), sympy.Rational(1, T.density(t))
            if sympy.expand(phi - want) != 0:
                return t, sympy.expand(phi), want
    return None


def _vertices(tree) -> list:
    return [tree] + [v for child in tree for v in _vertices(child)]


def _coefficient(value, what):
    from ..errors import NambuBCHError
    from ..model_file import parse_value

    if isinstance(value, float):
        raise InvalidCompositionError(f"{what} = {value!r}: give exact coefficients as strings (\"1/3\", \"sqrt(3)/6\")")
    if not isinstance(value, (str, int)) or isinstance(value, bool) or (isinstance(value, str) and len(value) > 200):
        raise InvalidCompositionError(f"{what} must be a string of at most 200 characters such as \"1/2\", "
                                      f"got {str(value)[:40]!r}")
    try:
        x = parse_value(value, what)
    except NambuBCHError as exc:
        raise InvalidCompositionError(str(exc).splitlines()[0]) from None
    if x.has(sympy.Float):
        raise InvalidCompositionError(f"{what} = {value!r}: give an exact coefficient (\"1/10\", not \"0.1\")")
    return x
