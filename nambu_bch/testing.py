"""pytest helpers and plugin: assertions for one's own test suite, and fixtures for the built-in models.

The plugin is registered through the ``pytest11`` entry point ``nambu_bch``
(pyproject.toml: the light module :mod:`nambu_bch._pytest_plugin`, which defines
the fixtures and imports sympy only when one is used), so installing the package
makes the fixtures available in any pytest run; ``pytest -p nambu_bch.testing``
loads them explicitly (this module re-exports them).

Fixtures: ``ho``, ``ho3``, ``rigid_body``, ``lotka_volterra``,
``ho3_composite`` (the built-in :func:`~nambu_bch.model` systems),
``paper_words`` (the six second-order words of Sect. 5.1) and ``symbols``
(name -> Symbol for ``x1..x3``, ``m``, ``omega``, ``h``, ``alpha``, ...).

Assertions (each raises ``AssertionError`` with the residual spelled out):

* :func:`assert_fields_equal` -- two vector fields agree component by component;
* :func:`assert_shadow_pair` -- ``X_{H_S, G_S} = X_eff + O(h^(order+1))``
  (Eq. L2 for N = 3, Eq. L1 for N = 2), checked against
  :func:`~nambu_bch.bch.effective_field` (backward error analysis);
* :func:`assert_invariant` -- ``I(Phi_h(x)) = I(x)`` exactly for the composed
  map (:func:`~nambu_bch.integrators.composed_map`), e.g. Eqs. (CQ12321H),
  (CQ12321G) and Table (table).

Example (``examples/test_paper_results.py`` has more)::

    from nambu_bch.testing import assert_invariant

    def test_table_row_12321(ho3):
        assert_invariant(ho3, "12321", "x3 - x1**2 + h**2*x2**2/(4*m**2)")  # G_c, Eq. (CQ12321G)
"""

from __future__ import annotations

import sympy

# the plugin's fixtures, defined in the entry point's light module; here for ``pytest -p nambu_bch.testing``
from ._pytest_plugin import ho, ho3, ho3_composite, lotka_volterra, paper_words, rigid_body, symbols  # noqa: F401
from .algebra.zero import witness
from .errors import NambuBCHError
from .parsing import as_expression, as_symbols
from .symbols import STEP
from .systems.spec import as_system

__all__ = [
    "assert_fields_equal",
    "assert_invariant",
    "assert_shadow_pair",
    "liouville_components",
]



# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------
def _as_expr(value, system, what):
    """A sympy expression from a sympy object or a string (parsed safely with the system's symbols)."""
    if value is None:
        return None
    return as_expression(value, system.symbols(), what)


def _text_symbols(coordinates, values) -> dict:
    """Names a text component may use: the coordinates, ``h``, ``alpha`` and the symbols of the sympy values."""
    names = {s.name: s for v in values if isinstance(v, sympy.Basic) for s in v.free_symbols if isinstance(s, sympy.Symbol)}
    names.update({n: sympy.Symbol(n) for n in ("h", "alpha")})
    names.update({s.name: s for s in coordinates if isinstance(s, sympy.Symbol)})
    return names


def _raw_components(field) -> tuple:
    if hasattr(field, "to_sympy"):
        return tuple(field.to_sympy())
    if isinstance(field, (str, bytes)) or not hasattr(field, "__iter__"):
        raise NambuBCHError(f"a vector field must be a VectorField, an EffectiveField or a sequence of components, "
                            f"got {type(field).__name__}")
    return tuple(field)


def liouville_components(coordinates, *hamiltonians, parameters=()) -> tuple:
    """``X_{H_1..H_{N-1}}^i = {x_i, H_1, ..., H_{N-1}}`` as sympy expressions (any ``h``, ``alpha`` allowed).

    The Nambu bracket is the Jacobian determinant ``det d(f, H_1..H_{N-1})/d(x_1..x_N)``
    (Eq. NB; Eq. Poisson for N = 2), so ``X_H = (dH/dx2, -dH/dx1)`` for N = 2.
    A Hamiltonian given as text is read by :func:`~nambu_bch.parsing.parse_expression` in the
    coordinates, ``h``, ``alpha``, the ``parameters`` (Symbols or names) and the symbols of the
    other Hamiltonians.

    >>> x1, x2 = sympy.symbols("x1 x2")
    >>> liouville_components((x1, x2), (x1**2 + x2**2) / 2)
    (x2, -x1)
    >>> liouville_components((x1, x2), "x2^2/(2*m) + m*omega^2*x1^2/2", parameters="m omega")
    (x2/m, -m*omega**2*x1)
    """
    coords = as_symbols(coordinates, "coordinates")
    extra = as_symbols(parameters.split() if isinstance(parameters, str) else parameters, "parameters", names=True)
    if len(hamiltonians) != len(coords) - 1:
        raise NambuBCHError(f"a Liouville field on {len(coords)} coordinates needs {len(coords) - 1} Hamiltonians, "
                            f"got {len(hamiltonians)}")
    names = _text_symbols((*coords, *extra), hamiltonians)
    hamiltonians = [as_expression(Hk, names, f"Hamiltonian {k + 1}") for k, Hk in enumerate(hamiltonians)]
    grads = [[sympy.diff(Hk, x) for x in coords] for Hk in hamiltonians]
    out = []
    for i in range(len(coords)):
        row = [sympy.Integer(1 if j == i else 0) for j in range(len(coords))]
        out.append(sympy.expand(sympy.Matrix([row, *grads]).det(method="berkowitz")))
    return tuple(out)


def _zero_or_simplified(expr):
    """``0`` if ``expr`` vanishes identically, else a non-zero residual (cheap tests first).

    A residual that a numeric witness (:func:`~nambu_bch.algebra.zero.witness`) proves non-zero is returned
    expanded, never simplified: a failing assertion must not spend minutes making its message pretty.
    """
    expr = sympy.expand(expr)
    if expr == 0:
        return sympy.Integer(0)
    if expr.is_rational_function() and sympy.cancel(expr) == 0:
        return sympy.Integer(0)
    if witness(expr) is not None:
        return expr
    return sympy.simplify(expr)


#: Longest residual printed in a failure message (a longer one is cut, with its number of terms).
MAX_SHOWN = 300


def _short(expr) -> str:
    """``expr`` as text of at most :data:`MAX_SHOWN` characters (the cut says how many terms it has)."""
    text = str(expr)
    if len(text) <= MAX_SHOWN:
        return text
    return f"{text[:MAX_SHOWN]}... ({len(sympy.Add.make_args(expr))} terms)"


def _first_order(residual, point):
    """``(k, c)``: numerically, ``residual ~ c h^k`` as ``h -> 0`` at ``point`` (the other symbols fixed), or ``None``.

    From the values at ``h = 2^-12`` and ``2^-13`` at 100 digits (the terms of size one cancel down to
    ``h^k``): ``k = log2(r(h) / r(h/2))`` rounded.
    """
    if STEP not in residual.free_symbols:
        return None
    fixed = {x: v for x, v in point.items() if x != STEP}
    values = []
    for e in (12, 13):
        h = sympy.Rational(1, 2**e)
        found = witness(residual, {**fixed, STEP: h}, digits=100, tolerance=1e-70)
        if found is None:
            return None
        values.append((h, found[1]))
    (h1, r1), (_, r2) = values
    ratio = abs(r1 / r2)
    if ratio <= 0:
        return None
    k = int(round(float(sympy.log(ratio, 2))))
    return k, (r1 / h1**k).evalf(6)


def _truncate(expr, order):
    """Coefficients of ``h^0 .. h^order`` of ``expr`` (a polynomial in ``h`` or a series)."""
    expr = sympy.expand(expr)
    if expr.is_polynomial(STEP):
        poly = sympy.Poly(expr, STEP)
        return [_zero_or_simplified(poly.coeff_monomial(STEP**k)) for k in range(order + 1)]
    series = sympy.series(expr, STEP, 0, order + 1).removeO()
    return [_zero_or_simplified(sympy.expand(series).coeff(STEP, k)) for k in range(order + 1)]


def _residual_report(coordinates, residuals, header):
    lines = [header]
    for x, r in zip(coordinates, residuals):
        if r != 0:
            lines.append(f"    d/d{x}: {_short(r)}")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# assertions
# --------------------------------------------------------------------------------------------
def assert_fields_equal(X, Y, coordinates=None, msg: str = ""):
    """Assert ``X == Y`` component by component (exactly, after ``simplify``).

    Parameters
    ----------
    X, Y : VectorField, EffectiveField or sequence of sympy expressions or strings (text is read by
        :func:`~nambu_bch.parsing.parse_expression` in the coordinates, ``h``, ``alpha``, the field's
        algebra and the symbols of the other components)
    coordinates : sequence of Symbols, optional
        Names for the failure message (default: taken from ``X`` or ``x1..xN``).
    msg : str
        Prefix of the failure message.
    """
    __tracebackhide__ = True
    a, b = _raw_components(X), _raw_components(Y)
    if len(a) != len(b):
        raise AssertionError(f"{msg}fields on {len(a)} and {len(b)} coordinates cannot be equal")
    algebra = getattr(X, "algebra", None) or getattr(Y, "algebra", None)
    if coordinates is None:
        coordinates = algebra.coordinates if algebra is not None else sympy.symbols(f"x1:{len(a) + 1}")
    coordinates = as_symbols(coordinates, "coordinates")
    names = _text_symbols(coordinates, (*a, *b))
    if algebra is not None:
        names.update(algebra.symbol_table)
    a = tuple(as_expression(c, names, f"component {i + 1} of X") for i, c in enumerate(a))
    b = tuple(as_expression(c, names, f"component {i + 1} of Y") for i, c in enumerate(b))
    residuals = [_zero_or_simplified(u - v) for u, v in zip(a, b)]
    if any(r != 0 for r in residuals):
        raise AssertionError(_residual_report(coordinates, residuals, f"{msg}fields differ; residual X - Y:"))


def assert_shadow_pair(system, word, H_S, G_S=None, order: int = 2):
    """Assert that ``(H_S, G_S)`` are shadow Hamiltonians of ``word`` through ``h^order``.

    Checks ``X_{H_S, G_S} - X_eff = O(h^(order+1))`` coefficient by coefficient,
    ``X_eff`` from :func:`~nambu_bch.bch.effective_field` (backward error
    analysis of the composed map, Eqs. eL1/eL2).  Any free family parameter
    (``alpha``) must drop out, i.e. the identity must hold for every value
    (the paper's Eqs. SH12321c/SG12321c hold for all ``alpha``).

    Parameters
    ----------
    system : System
    word : str or Composition
    H_S, G_S : sympy expressions or strings in the system's symbols, ``h`` and
        ``alpha``; ``G_S`` is ``None`` for N = 2 (for N >= 4 pass a sequence
        ``[H_S2, H_S3, ...]`` as ``G_S``).  Truncation terms ``O(h**k)`` are dropped.
    order : int
        Highest power of ``h`` compared.
    """
    __tracebackhide__ = True
    from .bch import effective_field

    system = as_system(system)
    hams = [_as_expr(H_S, system, "H_S")]
    if isinstance(G_S, (list, tuple)):
        hams += [_as_expr(G, system, "G_S") for G in G_S]
    elif G_S is not None:
        hams.append(_as_expr(G_S, system, "G_S"))
    hams = [H.removeO() if isinstance(H, sympy.Basic) and H.has(sympy.Order) else H for H in hams]
    expected = len(system.hamiltonians)
    if len(hams) != expected:
        raise AssertionError(
            f"{system.name} has {expected} Hamiltonian(s); got {len(hams)} shadow Hamiltonian(s) "
            f"({'give G_S' if expected > len(hams) else 'G_S must be None for N = 2'})"
        )
    X_eff = effective_field(system.splitting, word, order)
    failures = []
    for k, residuals in enumerate(_shadow_residuals(system, hams, X_eff, order)):
        if any(r != 0 for r in residuals):
            failures.append(_residual_report(system.coordinates, residuals, f"  at h^{k}:"))
    if failures:
        raise AssertionError(
            f"X_{{H_S,G_S}} != X_eff + O(h^{order + 1}) for {system.name}, word {word}; "
            "residual X_{H_S,G_S} - X_eff:\n" + "\n".join(failures)
        )


def _shadow_residuals(system, hams, X_eff, order):
    """``[[r^1_k, ..., r^N_k] for k in 0..order]``, ``r_k`` the ``h^k`` coefficient of ``X_{hams} - X_eff``.

    Polynomial shadow Hamiltonians are handled in the package's exact sparse ring
    (coefficients in ``QQ(parameters)``, extra symbols such as ``alpha`` as ring
    constants); anything else (``F(omega h)``, ``asin``) by sympy series in ``h``.
    """
    from .algebra import VectorField, liouville_field

    allowed = set(system.coordinates) | set(system.parameters) | {STEP}
    extra = sorted(set().union(*(Hk.free_symbols for Hk in hams)) - allowed, key=str)
    # complex or radical coefficients (1/4 + I/4, 2^(1/3)): the ring over the composition's field
    algebra = system.algebra.with_constants(STEP, *extra, extension=X_eff.composition.extension)
    converted = [algebra.convert(Hk) for Hk in hams]
    if all(algebra.is_polynomial(c) for c in converted):
        X_S = liouville_field(algebra, *converted)
        rhs = VectorField(algebra, X_eff.to_sympy())
        if all(algebra.is_polynomial(c) for c in (*X_S.components, *rhs.components)):
            index = algebra.n + algebra.constants.index(STEP)
            diffs = [a - b for a, b in zip(X_S.components, rhs.components)]
            out = []
            for k in range(order + 1):
                row = []
                for d in diffs:
                    part = d.ring.from_dict({m[:index] + (0,) + m[index + 1:]: c for m, c in d.items() if m[index] == k})
                    row.append(algebra.to_sympy(part) if part else sympy.Integer(0))  # non-zero: printed, not factored
                out.append(row)
            return out
    lhs = liouville_components(system.coordinates, *hams)
    columns = [_truncate(a - b, order) for a, b in zip(lhs, X_eff.to_sympy())]
    return [[c[k] for c in columns] for k in range(order + 1)]


def assert_invariant(system, word, I, h=STEP):
    """Assert that ``I`` is an exact invariant of the composed map: ``I(Phi_h(x)) - I(x) = 0``.

    ``Phi_h`` is :func:`~nambu_bch.integrators.composed_map` (exact in ``h``,
    all orders), so this checks e.g. the conserved quantities of Table (table)
    with no truncation.

    Parameters
    ----------
    system : System
    word : str or Composition
    I : sympy expression or string in the system's symbols and ``h``
    """
    __tracebackhide__ = True
    from .integrators import composed_map

    system = as_system(system)
    expr = as_expression(I, system.symbols(), "I")
    image = composed_map(system.splitting, word, h)
    moved = expr.subs(dict(zip(system.coordinates, image)), simultaneous=True)
    residual = moved - expr
    found = witness(residual)  # a non-zero value at a point fails at once, before any expansion
    if found is None:
        residual = _zero_or_simplified(residual)
        if residual == 0:
            return
        found = witness(residual)
    where, first = "", ""
    if found is not None:
        point, value = found
        where = f"; at {', '.join(f'{x} = {v}' for x, v in point.items())} it is {value.evalf(6)}"
        leading = _first_order(residual, point)
        if leading is not None:
            first = f"; lowest power of h (numerically there): {leading[1]} h^{leading[0]}"
    raise AssertionError(
        f"{expr} is not invariant under Phi_h = {word} for {system.name}; "
        f"residual I(Phi_h(x)) - I(x) = {_short(residual)}{where}{first}"
    )

