"""Reduced row echelon form over ``QQ(parameters)`` with python-flint's multivariate polynomials.

sympy's field ``QQ(p_1, .., p_k)`` keeps each element as a reduced fraction and cancels it
with a polynomial gcd in Python at every addition and multiplication (``heugcd``); the
Gauss-Jordan elimination of the shadow solve over ``QQ(I1, I2, I3)`` spends nearly all its
time there.  Here the same elimination runs on pairs ``(n, d)`` of flint ``fmpz_mpoly``
(integer polynomials, gcds in C), with the same normal form as sympy's field:

    n, d in ZZ[p_1, .., p_k] coprime (content included), the leading coefficient of ``d``
    (lexicographic order, the parameters in the field's order) positive, ``0 = 0/1``.

A rational function has exactly one such representation, so the elements converted back
(:func:`to_field`, without a further cancellation) are the ones sympy's own arithmetic gives,
and the reduced echelon form -- unique -- is identical to ``DomainMatrix.rref`` over the field.

Arithmetic (Knuth, TAOCP vol. 2, Sect. 4.5.1, Henrici's reductions): ``a/b * c/d`` cancels the
cross gcds ``(a, d)`` and ``(c, b)``; ``a/b - c/d`` with ``g = gcd(b, d)`` is
``(a d/g - c b/g) / (b d/g)``, whose only common factors with the denominator divide ``g``.

References
----------
Knuth, *The Art of Computer Programming*, vol. 2, Sect. 4.5.1 (rational arithmetic); FLINT
``fmpz_mpoly_gcd``; sympy ``PolyElement.cancel`` (the normal form).
"""

from __future__ import annotations

import contextlib
import contextvars

from . import _flint
from ._flint import exponents
from .fields import CoefficientField


def context(domain):
    """The flint ``fmpz_mpoly_ctx`` of the parameters of ``domain = QQ(params)`` (lexicographic, same order),
    or ``None`` when ``domain`` is not a fraction field over ``QQ`` with the lexicographic order."""
    field = CoefficientField.recognise(domain)
    return field.flint_context() if field is not None else None


def generic_context(nvars: int):
    """flint's ``fmpz_mpoly_ctx`` in ``nvars`` variables (lexicographic); the variables are named ``v0, v1, ..``:
    only their order matters, and flint accepts ASCII names only (a parameter may be called ``ω``)."""
    return _flint.fmpz_mpoly_context(nvars)


def _integer_poly(p, ctx):
    """``(P, c)`` with ``p = P / c``, ``P`` in ``ZZ[params]`` (flint), ``c`` a positive integer (``p`` a sympy polynomial)."""
    return _integer_terms(p.items(), ctx)


def _integer_terms(items, ctx):
    """``(P, c)`` of ``{exponent: rational}`` items (sympy's ``QQ`` elements or flint ``fmpq``: both have
    ``numerator``/``denominator``)."""
    items = [(m, int(q.numerator), int(q.denominator)) for m, q in items]
    c = 1
    for _, _, den in items:
        if den != 1:
            c = c * den // _gcd(c, den)
    return ctx.from_dict({m: num * (c // den) for m, num, den in items}), c


def integer_poly(p, ctx):
    """A sympy polynomial over ``QQ`` in the parameters as ``(P, c)``: ``p = P / c``, ``P`` a flint ``fmpz_mpoly``."""
    return _integer_poly(p, ctx)


def quotient_terms(terms: dict, denominator, ctx):
    """``sum_e t_e P^e / denominator`` as a normalised pair; ``None`` when it is zero.

    ``terms``: ``{exponent tuple: rational}`` (sympy ``QQ`` or flint ``fmpq``); ``denominator``: ``(P, c)``
    from :func:`integer_poly` (the polynomial ``P / c``, non-zero)."""
    n, cn = _integer_terms(terms.items(), ctx)
    if n.is_zero():
        return None
    d, cd = denominator
    return normalize(n * cd, d * cn)


def _gcd(a, b):
    while b:
        a, b = b, a % b
    return a


def normalize(n, d):
    """``n/d`` in the normal form (module docstring): coprime, ``lc(d) > 0``, zero as ``0/1``."""
    if n.is_zero():
        return n, d.context().from_dict({(0,) * d.context().nvars(): 1})
    g = n.gcd(d)
    if not g.is_one():
        n, d = n / g, d / g
    if d.leading_coefficient() < 0:
        n, d = -n, -d
    return n, d


#: the conversion memo of the outermost :func:`shared_conversions` scope (``None`` outside one):
#: ``id(element) -> (element, context, pair)``; the element is held, so its id stays its own while it is there
_SHARED: contextvars.ContextVar = contextvars.ContextVar("frac_rref_shared", default=None)


@contextlib.contextmanager
def shared_conversions():
    """A scope in which every field element crosses to flint once: :func:`from_field` and :func:`to_field` record
    the pairs of the elements they meet or make (by identity, the elements held until the scope ends).

    One exact solve passes the same coefficients through several eliminations (the two canonical members of an
    order, the operator columns shared by the orders, the solutions fed back as cross terms): inside the scope
    each is converted once, and the exponent tuples flint returns are converted to Python's once per distinct
    tuple (:func:`~nambu_bch.algebra._flint.shared_exponents`, which the scope opens).  The pair of an element is a function of its value (the normal form of the module docstring), so the
    memo changes no result; nested scopes share the outermost memo.
    """
    if _SHARED.get() is not None:
        yield
        return
    token = _SHARED.set({})
    try:
        with _flint.shared_exponents():
            yield
    finally:
        _SHARED.reset(token)


def from_field(v, ctx):
    """A field element (sympy ``FracElement`` of ``QQ(params)``) as a normalised pair ``(n, d)`` of ``fmpz_mpoly``."""
    shared = _SHARED.get()
    if shared is not None:
        hit = shared.get(id(v))
        if hit is not None and hit[0] is v and hit[1] is ctx:
            return hit[2]
        pair = _from_field(v, ctx)
        shared[id(v)] = (v, ctx, pair)
        return pair
    return _from_field(v, ctx)


def _from_field(v, ctx):
    numer, denom = v.numer, v.denom
    if numer.is_ground and denom.is_ground:  # a rational number (most entries of the shadow solves)
        q = numer.LC / denom.LC  # sympy's QQ: reduced, positive denominator -- the normal form of a constant
        return ctx.constant(int(q.numerator)), ctx.constant(int(q.denominator))
    n, cn = _integer_poly(numer, ctx)
    d, cd = _integer_poly(denom, ctx)
    if cn == 1 and cd == 1:
        return normalize(n, d)  # sympy's own normal form (a gcd of one, unless built with raw_new unreduced)
    return normalize(n * cd, d * cn)


def to_field(pair, domain):
    """The pair ``(n, d)`` (normal form) as the element of ``domain`` sympy's arithmetic would give (no cancellation)."""
    n, d = pair
    field = domain.field
    make, coeff = field.ring.dtype, domain.domain.dtype  # PolyElement from (monomial, coefficient) pairs; QQ's type
    native = _flint.qq_is_fmpq(coeff)  # flint ground types: fmpz coefficients convert directly

    zero = (0,) * len(field.ring.gens)

    def poly(p):
        if p.is_constant():  # most entries of an elimination: no exponents to convert
            c = p.leading_coefficient() if not p.is_zero() else None
            return make([(zero, coeff(c if native else int(c)))] if c is not None else [])
        cs = p.coeffs() if native else [int(c) for c in p.coeffs()]
        return make(zip(exponents(p), map(coeff, cs)))

    out = field.raw_new(poly(n), poly(d))
    shared = _SHARED.get()
    if shared is not None:
        shared[id(out)] = (out, n.context(), pair)
    return out


def mul(a, b):
    """``a * b`` of two normalised pairs (cross cancellation: no gcd of the products)."""
    an, ad = a
    bn, bd = b
    g1 = an.gcd(bd)
    g2 = bn.gcd(ad)
    if not g1.is_one():
        an, bd = an / g1, bd / g1
    if not g2.is_one():
        bn, ad = bn / g2, ad / g2
    n, d = an * bn, ad * bd
    if d.leading_coefficient() < 0:
        n, d = -n, -d
    return n, d


def sub(a, b):
    """``a - b`` of two normalised pairs (Henrici: only ``gcd(b_d, a_d)`` can cancel)."""
    an, ad = a
    bn, bd = b
    if ad == bd:
        n = an - bn
        if n.is_zero():
            return n, ad.context().from_dict({(0,) * ad.context().nvars(): 1})
        return normalize(n, ad) if not ad.is_one() else (n, ad)
    g = ad.gcd(bd)
    if g.is_one():
        return an * bd - bn * ad, ad * bd  # lc of a product of positive-lc polynomials is positive
    a1, b1 = ad / g, bd / g
    n = an * b1 - bn * a1
    if n.is_zero():
        return n, ad.context().from_dict({(0,) * ad.context().nvars(): 1})
    g2 = n.gcd(g)
    if not g2.is_one():
        n, bd = n / g2, bd / g2  # g2 divides g, hence bd
    d = a1 * bd
    if d.leading_coefficient() < 0:  # flint's gcds have positive leading coefficients: never, kept as a guard
        n, d = -n, -d
    return n, d


def inverse(a):
    """``1 / a`` of a non-zero normalised pair."""
    n, d = a
    if n.leading_coefficient() < 0:
        return -d, -n
    return d, n


def rref(rows: dict, ncols: int, ctx):
    """Reduced row echelon form of ``{row: {column: (n, d)}}`` (non-zero normalised pairs): ``(R, pivots)``.

    Gauss-Jordan by columns; the pivot row of a column is the candidate with the fewest entries
    (any choice gives the same, unique, reduced form).  ``R`` is ``{k: {column: pair}}`` for the
    ``rank`` pivot rows in pivot order, pivot entries one.
    """
    one = ctx.from_dict({(0,) * ctx.nvars(): 1})
    work = {i: dict(r) for i, r in rows.items() if r}
    by_col: dict = {}
    for i, r in work.items():
        for j in r:
            by_col.setdefault(j, set()).add(i)
    pivot_rows = []
    done: set = set()
    for col in range(ncols):
        holders = by_col.get(col)
        if not holders:
            continue
        candidates = [i for i in holders if i not in done]
        if not candidates:
            continue
        p = min(candidates, key=lambda i: (len(work[i]), i))
        prow = work[p]
        inv = inverse(prow[col])
        if not (inv[0].is_one() and inv[1].is_one()):
            prow = {j: (mul(v, inv) if j != col else (one, one)) for j, v in prow.items()}
        else:
            prow = dict(prow)
        prow[col] = (one, one)
        work[p] = prow
        for i in list(holders):
            if i == p:
                continue
            r = work[i]
            f = r.pop(col)
            for j, v in prow.items():
                if j == col:
                    continue
                t = mul(f, v)
                old = r.get(j)
                if old is None:
                    r[j] = (-t[0], t[1])
                    by_col.setdefault(j, set()).add(i)
                else:
                    s = sub(old, t)
                    if s[0].is_zero():
                        del r[j]
                        by_col[j].discard(i)
                    else:
                        r[j] = s
        by_col[col] = {p}
        done.add(p)
        pivot_rows.append((col, p))
    R = {k: work[p] for k, (col, p) in enumerate(pivot_rows)}
    return R, tuple(col for col, _ in pivot_rows)


def normal_forms(vectors, kernel, priority, domain, ctx) -> list:
    """The normal forms of ``vectors`` modulo ``span(kernel)`` for the column order ``priority``, on flint pairs.

    The same vectors as :func:`~nambu_bch.algebra.elimination.normal_form` of each (the unique ``v + k``,
    ``k`` in the span, vanishing on the greedily first priority columns the kernel can clear): the kernel is
    brought to reduced echelon form once, with the columns in ``priority`` order (:func:`rref`), and each
    vector loses its entries on the pivot columns, ``x <- x - x_p R_p``.  The values are elements of ``domain``
    (``QQ(params)``, ``ctx`` its flint context) and come back in sympy's normal form; the entries of a result
    are ordered by descending position in ``priority``, as the elimination in reverse priority of
    :meth:`~nambu_bch.algebra.ansatz.Ansatz.solve_canonical` orders its particular solutions.
    """
    position = {c: i for i, c in enumerate(priority)}
    rows = {r: {position[c]: from_field(v, ctx) for c, v in vec.items() if v} for r, vec in enumerate(kernel)}
    R, pivots = rref(rows, len(priority), ctx) if rows else ({}, ())
    out = []
    for vec in vectors:
        x = {position[c]: from_field(v, ctx) for c, v in vec.items() if v}
        for r, p in enumerate(pivots):
            f = x.get(p)
            if f is None:
                continue
            for c, w in R[r].items():
                t = mul(f, w)
                old = x.get(c)
                s = (-t[0], t[1]) if old is None else sub(old, t)
                if s[0].is_zero():
                    x.pop(c, None)
                else:
                    x[c] = s
        out.append({priority[c]: to_field(x[c], domain) for c in sorted(x, reverse=True)})
    return out
