"""python-flint behind one seam: the only module of the package that imports ``flint``.

python-flint (FLINT's exact arithmetic in C) is a dependency, but every exact computation of the
package also has a pure path (sympy's rings and ``DomainMatrix``, the multi-modular RREF), with the
same results.  This module decides which one runs and converts between the two worlds:

* :func:`available` -- python-flint is importable and not switched off by ``NAMBU_BCH_DISABLE_FLINT=1``
  (read at every call, so a test can switch it with ``monkeypatch.setenv``);
* :func:`module` -- the ``flint`` module itself, for code that has already chosen the flint path;
* the polynomial contexts, cached per number of variables: :func:`fmpz_mpoly_context` (``ZZ[v0..]``)
  and :func:`fmpq_mpoly_context` (``QQ[v0..]``), both lexicographic.  Their variables are named
  ``v0, v1, ..``: only the order matters (it is the order of the sympy ring's generators, so the
  exponent tuples agree), and flint accepts ASCII names only while a symbol may be called ``ω``;
* the conversions of scalars and exponents: :func:`fmpq` (a sympy ``QQ`` element, ``int`` or ``fmpq``
  as ``fmpq``), :func:`to_qq` (``fmpq`` as sympy's ``QQ``), :func:`qq_is_fmpq` (sympy's ground types are
  flint's: no conversion needed), :func:`exponents` (a flint polynomial's exponents as Python ints).

References
----------
FLINT documentation, ``fmpq``, ``fmpq_mat``, ``fmpz_mpoly``, ``fmpq_mpoly``; python-flint.
"""

from __future__ import annotations

import contextlib
import contextvars
import importlib
import os

#: the imported module (or ``None`` when python-flint is missing), filled on first use
_MODULE: list = []

_FMPZ_CONTEXTS: dict = {}  # number of variables -> fmpz_mpoly_ctx (lex)
_FMPQ_CONTEXTS: dict = {}  # number of variables -> fmpq_mpoly_ctx (lex)
_QQ_IS_FMPQ: dict = {}  # a sympy ground type -> is it flint's fmpq
#: the exponent memo of the outermost :func:`shared_exponents` scope (``None`` outside one): flint's tuples -> Python's
_EXPONENTS: contextvars.ContextVar = contextvars.ContextVar("flint_exponents", default=None)


def _import():
    if not _MODULE:
        try:
            _MODULE.append(importlib.import_module("flint"))
        except ImportError:
            _MODULE.append(None)
    return _MODULE[0]


def disabled() -> bool:
    """``NAMBU_BCH_DISABLE_FLINT`` is set to a true value (``1``, ``true``, ``yes``, ``on``)."""
    return os.environ.get("NAMBU_BCH_DISABLE_FLINT", "").strip().lower() in ("1", "true", "yes", "on")


def available() -> bool:
    """python-flint is installed and not disabled by ``NAMBU_BCH_DISABLE_FLINT=1`` (read at every call).

    python-flint is a dependency; when it is missing or switched off every computation runs on its
    pure path (sympy's rings, the multi-modular RREF or ``DomainMatrix``), with the same results.
    """
    if disabled():
        return False
    flint = _import()
    return flint is not None and hasattr(flint, "fmpq_mat")


def module():
    """The ``flint`` module, for a caller that chose the flint path (:func:`available`) or needs flint's types
    regardless of the switch (the extended rings have no pure path; :func:`available` guards their use)."""
    flint = _import()
    if flint is None:
        raise ImportError("python-flint is not installed")
    return flint


def fmpz_mpoly_context(nvars: int):
    """flint's ``fmpz_mpoly_ctx`` of ``ZZ[v0, .., v_{nvars-1}]``, lexicographic (cached)."""
    ctx = _FMPZ_CONTEXTS.get(nvars)
    if ctx is None:
        ctx = _FMPZ_CONTEXTS[nvars] = module().fmpz_mpoly_ctx.get(tuple(f"v{i}" for i in range(nvars)), "lex")
    return ctx


def fmpq_mpoly_context(nvars: int):
    """flint's ``fmpq_mpoly_ctx`` of ``QQ[v0, .., v_{nvars-1}]``, lexicographic (cached)."""
    ctx = _FMPQ_CONTEXTS.get(nvars)
    if ctx is None:
        ctx = _FMPQ_CONTEXTS[nvars] = module().fmpq_mpoly_ctx.get(tuple(f"v{i}" for i in range(nvars)), "lex")
    return ctx


def is_fmpq(value) -> bool:
    """``value`` is a flint ``fmpq``."""
    return isinstance(value, module().fmpq)


def fmpq(value, denominator: int = 1):
    """An exact rational as flint's ``fmpq``: an ``fmpq`` unchanged, an ``int`` (over ``denominator``), or any
    rational with ``numerator``/``denominator`` (sympy's ``QQ`` elements, ``fractions.Fraction``)."""
    flint = _MODULE[0] if _MODULE and _MODULE[0] is not None else module()
    if isinstance(value, flint.fmpq):
        return value
    if isinstance(value, int):
        return flint.fmpq(value, denominator)
    return flint.fmpq(int(value.numerator), int(value.denominator))


def qq_is_fmpq(coefficient_type) -> bool:
    """sympy's ``QQ`` element type ``coefficient_type`` is flint's ``fmpq`` (sympy's flint ground types): values pass
    between the two without conversion."""
    known = _QQ_IS_FMPQ.get(coefficient_type)
    if known is None:
        known = _QQ_IS_FMPQ[coefficient_type] = coefficient_type is module().fmpq
    return known


def fmpq_mat(nrows: int, ncols: int):
    """A zero ``nrows x ncols`` flint ``fmpq_mat``."""
    return module().fmpq_mat(nrows, ncols)


@contextlib.contextmanager
def shared_exponents():
    """A scope in which :func:`exponents` converts each distinct exponent tuple once (nested scopes share the
    outermost memo): the polynomials of one exact solve have few distinct exponents, and a lookup is cheaper than
    converting each ``fmpz``."""
    if _EXPONENTS.get() is not None:
        yield
        return
    token = _EXPONENTS.set({})
    try:
        yield
    finally:
        _EXPONENTS.reset(token)


def exponents(p, memo: dict | None = None) -> list:
    """The exponent tuples of a flint polynomial's terms as Python ints (flint returns ``fmpz`` exponents, which
    must not leak into sympy's rings), in the order of ``p.coeffs()``.

    ``memo``: a dict from flint's exponent tuples to the converted ones (default: the one of the enclosing
    :func:`shared_exponents` scope, if any)."""
    if memo is None:
        memo = _EXPONENTS.get()
    if memo is None:
        return [tuple(map(int, m)) for m in p.monoms()]
    out = []
    for m in p.monoms():
        e = memo.get(m)
        if e is None:
            e = memo[m] = tuple(map(int, m))
        out.append(e)
    return out
