"""sympy's canonical order of sums and products, computed by a sort key: building the printed edge fast.

sympy keeps the arguments of ``Add`` and ``Mul`` sorted by ``Basic.compare`` (``sympy.core.add._addsort``,
``sympy.core.mul._mulsort``), a Python comparison function called ``O(n log n)`` times per sum, each call
walking both expressions.  For the large sums the exact routes hand to sympy at the end (a shadow Hamiltonian of
thousands of terms) that sort is most of the cost of building the expression.  :func:`sort_key` is a key with
exactly the order of ``Basic.compare``, computed once per distinct subexpression, so Python's sort compares
tuples in C; :func:`canonical_add` builds the sum of distinct terms with it, the same object ``sympy.Add`` gives.

``Basic.compare(a, b)``: the classes first (``sympy.core.basic._cmp_name``: the position in
``ordering_of_classes``, classes not in it after those in it and by name among themselves), then the length of
``_hashable_content()``, then its items in turn (sympy objects recursively, anything else by Python's
``<``).  The key is the tuple ``(class rank, class name, length, item keys ..)`` with exactly that
lexicographic order.  A content that holds a ``frozenset`` (sympy compares those as a ``Basic`` of their
elements, in iteration order) has no key here: the callers then fall back to sympy's own construction.

:func:`coordinate_coefficients` gives the coefficients of a ring element's coordinate monomials as the
expressions ``sympy.factor`` prints, from python-flint's factorisation instead of sympy's.

References
----------
sympy ``Basic.compare``, ``Add.flatten``, ``Mul.flatten``, ``factor`` (``sympy/core``, ``sympy/polys/polytools.py``,
sympy 1.14); FLINT ``fmpz_mpoly_factor``.
"""

from __future__ import annotations

import math

import sympy
from sympy.core import basic as _basic

from . import _flint


class _NoKey(Exception):
    """An expression whose ``Basic.compare`` order :func:`sort_key` does not reproduce (the caller falls back)."""


def _class_key(cls) -> tuple:
    """``_cmp_name``'s order of classes as a tuple: known classes by position, the others after them by name."""
    order, name = _basic.ordering_of_classes, cls.__name__
    return (order.index(name), "") if name in order else (len(order) + 1, name)


def sort_key(expr, memo: dict | None = None) -> tuple:
    """A key whose tuple order is the order of ``Basic.compare`` (``a.compare(b) < 0`` iff ``key(a) < key(b)``).

    Parameters
    ----------
    expr : sympy.Basic
    memo : dict, optional -- keys already computed (subexpressions repeat: the same powers of symbols)

    Returns
    -------
    tuple

    Raises
    ------
    _NoKey -- the expression's content holds something compared otherwise (a ``frozenset``)

    >>> x, y = sympy.symbols("x y")
    >>> terms = [y**2, 3*x, x*y, sympy.Integer(2), x**3*y]
    >>> from functools import cmp_to_key
    >>> sorted(terms, key=sort_key) == sorted(terms, key=cmp_to_key(sympy.Basic.compare))
    True
    """
    if memo is not None:
        key = memo.get(expr)
        if key is not None:
            return key
    content = expr._hashable_content()
    items = []
    for item in content:
        if isinstance(item, sympy.Basic):
            items.append(sort_key(item, memo))
        elif isinstance(item, frozenset):
            raise _NoKey(f"{type(expr).__name__} holds a set")
        else:
            items.append(item)
    key = (*_class_key(type(expr)), len(content), *items)
    if memo is not None:
        memo[expr] = key
    return key


def product_key(product, argument_keys) -> tuple:
    """:func:`sort_key` of a product (or sum) whose arguments' keys are known: ``(class, length, argument keys)``."""
    return (*_class_key(type(product)), len(argument_keys), *argument_keys)


def canonical_add(terms, memo: dict | None = None):
    """``sympy.Add(*terms)`` for terms whose non-numeric parts are distinct: the same expression, sorted by key.

    ``Add`` collects the finite numbers into one leading coefficient and the terms ``c * s`` by their part ``s``
    without a numeric factor; when the other terms are products, powers or symbols and no two share ``s``
    (distinct monomials, as in the expanded shadows) its arguments are those terms themselves in the order of
    ``Basic.compare`` (``sympy.core.add.Add.flatten``).  Anything else -- repeated parts, non-commutative or
    infinite terms, a term that is itself a sum, an expression without a key -- goes through ``sympy.Add``.

    Parameters
    ----------
    terms : sequence of sympy expressions
    memo : dict, optional -- :func:`sort_key`'s memo, shared between the sums of one result

    Returns
    -------
    sympy.Expr -- equal to ``sympy.Add(*terms)``, with the same arguments in the same order

    >>> x, y = sympy.symbols("x y")
    >>> terms = [x*y/2, sympy.Integer(3), y**2, x**3]
    >>> canonical_add(terms).args == sympy.Add(*terms).args
    True
    """
    terms = list(terms)
    coeff = sympy.S.Zero
    rest, seen = [], set()
    for t in terms:
        if not isinstance(t, sympy.Expr):  # Python numbers, sets, matrices: sympy decides
            return sympy.Add(*terms)
        if t.is_Number:
            coeff += t
            if not coeff.is_finite:
                return sympy.Add(*terms)
            continue
        # products, powers and symbols only (Add.flatten treats sums, orders, unevaluated powers of numbers,
        # infinities, matrices and non-commutative terms otherwise)
        if not (t.is_Mul or t.is_Symbol or (t.is_Pow and not t.base.is_Number)) or not t.is_commutative:
            return sympy.Add(*terms)
        part = t.as_coeff_Mul()[1]
        if part in seen:
            return sympy.Add(*terms)
        seen.add(part)
        rest.append(t)
    if not rest:
        return coeff
    try:
        keys = [sort_key(t, memo) for t in rest]
    except _NoKey:
        return sympy.Add(*terms)
    ordered = [t for _, _, t in sorted(zip(keys, range(len(rest)), rest))]
    if coeff:
        ordered.insert(0, coeff)
    if len(ordered) == 1:
        return ordered[0]
    return sympy.Add._from_args(ordered, True)


# -- factored coefficients ----------------------------------------------------------------------
def _integer_parts(p) -> tuple:
    """``(P, c)`` with ``p = P / c`` for a sympy polynomial over ``QQ``: ``P`` as ``{exponents: int}``, ``c > 0``."""
    items = [(m, int(q.numerator), int(q.denominator)) for m, q in p.items()]
    c = math.lcm(*(d for _, _, d in items)) if items else 1
    return {m: a * (c // d) for m, a, d in items}, c


def coordinate_coefficients(poly, n: int):
    """``[(exponents, factored coefficient)]`` of a ring element over ``QQ`` or ``QQ(parameters)`` as polynomial in its
    first ``n`` generators (the coordinates), highest monomial first, each coefficient exactly the expression
    ``sympy.factor`` gives for it -- computed by python-flint's factorisation; ``None`` when that path does not
    apply (python-flint unavailable or switched off, an algebraic coefficient field).

    The coefficient of a coordinate monomial is a rational function ``N / D`` of the parameters and the ring's
    further generators (``alpha``, ...), ``N, D`` in ``ZZ[..]`` over a common denominator.  ``sympy.factor``
    writes it as ``_keep_coeff(c, prod f_i^k_i)``: the irreducible factors of numerator and denominator over
    ``ZZ``, each primitive with a positive leading coefficient in the lexicographic order of its generators
    sorted by ``sympy.polys.polyutils._sort_gens``, equal factors collected, ``c`` the rational content
    (``sympy.polys.polytools._symbolic_factor``).  Factorisation in ``ZZ[..]`` is unique up to signs, and flint's
    ``fmpz_mpoly.factor`` normalises its factors the same way in the order of its context, which is built in
    sympy's generator order: so the factors, the content and hence the expression are sympy's.

    Parameters
    ----------
    poly : PolyElement -- over ``QQ`` or ``QQ(parameters)``
    n : int -- the number of leading generators that are laid out (the rest join the coefficients)

    Returns
    -------
    list of ``(exponent tuple of length n, sympy expression)`` or None

    References
    ----------
    sympy ``factor``/``factor_list`` (``sympy/polys/polytools.py``); FLINT ``fmpz_mpoly_factor``.
    """
    from sympy.core.mul import _keep_coeff
    from sympy.polys.polyutils import _sort_gens
    from sympy.polys.polyutils import expr_from_dict

    if not _flint.available():
        return None
    domain = poly.ring.domain
    fraction = getattr(domain, "is_FractionField", False)
    if not (domain.domain.is_QQ if fraction else domain.is_QQ):
        return None
    params = tuple(domain.field.ring.symbols) if fraction else ()
    extra = tuple(poly.ring.symbols[n:])
    variables = extra + params
    order = _sort_gens(variables)
    place = [order.index(s) for s in variables]
    nvars = len(order)
    if nvars == 0:
        ctx = None
    else:
        ctx = _flint.fmpz_mpoly_context(nvars)

    def embed(extra_exps, terms):  # {param exponents: int} times extra^e, in the sorted variables
        out = {}
        for e, a in terms.items():
            key = [0] * nvars
            for i, k in zip(place, tuple(extra_exps) + tuple(e)):
                key[i] = k
            out[tuple(key)] = a
        return out

    groups: dict = {}
    for m, c in poly.items():
        groups.setdefault(m[:n], []).append((m[n:], c))
    rows = []
    for mono, parts in groups.items():
        if ctx is None:  # no parameters, no further generators: a rational number
            (_, c), = parts
            rows.append((mono, sympy.Rational(int(c.numerator), int(c.denominator))))
            continue
        nums, dens = [], []
        for e, c in parts:
            if fraction:
                pn, cn = _integer_parts(c.numer)
                pd, cd = _integer_parts(c.denom)
                nums.append(ctx.from_dict(embed(e, {k: v * cd for k, v in pn.items()})))
                dens.append(ctx.from_dict(embed((0,) * len(e), {k: v * cn for k, v in pd.items()})))
            else:
                nums.append(ctx.from_dict(embed(e, {(): int(c.numerator)})))
                dens.append(ctx.from_dict(embed((0,) * len(e), {(): int(c.denominator)})))
        D = dens[0]
        for d in dens[1:]:
            g = D.gcd(d)
            D = D * (d / g)
        N = ctx.from_dict({})
        for a, d in zip(nums, dens):
            N = N + a * (D / d)
        rows.append((mono, _factored(N, D, order, _keep_coeff, expr_from_dict)))
    return sorted(rows, key=lambda row: row[0], reverse=True)


def _factored(N, D, gens, keep_coeff, expr_from_dict):
    """``sympy.factor(N / D)`` of two flint ``fmpz_mpoly`` in the generators ``gens`` (sympy's order)."""
    cn, fn = N.factor()
    cd, fd = D.factor()
    powers: dict = {}  # a factor's terms -> its exponent (numerator minus denominator)
    for factors, sign in ((fn, 1), (fd, -1)):
        for f, k in factors:
            key = tuple(zip(map(tuple, f.monoms()), map(int, f.coeffs())))
            powers[key] = powers.get(key, 0) + sign * int(k)
    product = sympy.Mul(*[expr_from_dict({tuple(map(int, m)): sympy.Integer(a) for m, a in key}, *gens) ** k
                          for key, k in powers.items() if k])
    return keep_coeff(sympy.Rational(int(cn), int(cd)), product)
