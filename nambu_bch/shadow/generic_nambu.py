"""The generic Nambu question: shadow pairs for *arbitrary* separable H = sum H_i(x_i), G = sum G_i(x_i) (N = 3).

The full split of such a system (Eqs. HGs, X1-X3) is not a Poisson splitting, so the
BCH series on Hamiltonians (:mod:`nambu_bch.shadow.generic`) does not apply.  Instead the
direct route's equation at ``h^2`` for a symmetric word (no cross terms),

    X_{dH, G} + X_{H, dG} = Z_2,

is posed over *differential polynomials*: polynomials with rational coefficients in the
jets ``H_i^{(k)}(x_i)``, ``G_i^{(k)}(x_i)`` (algebraically independent for generic
functions), with the total derivative ``D_j`` raising the order of the jets of index ``j``
(Olver, *Applications of Lie Groups to Differential Equations*, Sect. 2.3).  Two gradings
make the ansatz finite and complete: scaling ``H -> lambda H``, ``G -> mu G`` (the pieces
are bilinear, ``Z_2`` has bidegree (3, 3), so ``dH`` has bidegree (3, 2) and ``dG`` (2, 3)),
and the number of derivatives per coordinate (``Z_2^i`` has multidegree ``(3,3,3) - e_i``,
so ``dH``, ``dG`` have multidegree ``(2, 2, 2)``).  Every universal differential-polynomial
solution has its homogeneous part of these degrees, so an inconsistent system proves that
*no* such universal formula exists (explicit ``x``-dependence and rational functions of the
jets are outside the ansatz).

Result (``tests/test_any_system.py``): for every Strang word ``12321, 21312, 31213`` (and
``13231``) the system is inconsistent at ``h^2``: **there is no universal shadow pair at h^2
that is a differential polynomial in H_i, G_i**, hence none at h^4 either (the direct route
stops at the first obstructed order).  Concrete systems escape this: ``ho3`` has one with
constant jets, the rigid body one with denominators ``I2 - I3`` that no differential polynomial
can produce.  The jet evaluation of ``Z_2`` is checked against the concrete effective field of
the rigid body.

References
----------
Horikoshi, Sect. 4 (general procedure), Eqs. (HGs), (X1)-(X3), (L2); Olver, Sect. 2.3.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations_with_replacement

import sympy
from sympy.polys.domains import QQ
from sympy.polys.rings import ring

from ..algebra.backend import PolynomialBackend
from ..algebra.elimination import SparseMatrix, solve_affine
from ..bch.evaluation import BracketEvaluator
from ..bch.formal import formal_bch
from ..errors import InvalidOrderError

_EPS = {(1, 2, 3): 1, (2, 3, 1): 1, (3, 1, 2): 1, (1, 3, 2): -1, (3, 2, 1): -1, (2, 1, 3): -1}


class JetRing:
    """Polynomials in the jets ``h{i}_{k} = H_i^{(k)}(x_i)``, ``g{i}_{k} = G_i^{(k)}(x_i)``, ``k <= max_order``.

    A coefficient ring of its own (no coordinate generators: ``x_i`` enters only through the jets of
    index ``i``); vector-field arithmetic on it is :class:`~nambu_bch.algebra.backend.PolynomialBackend`
    with :meth:`diff` (the total derivative) as derivative, :attr:`backend`.
    """

    n = 3
    domain = QQ

    def __init__(self, max_order: int = 6):
        self.K = max_order
        self.names = [f"{f}{i}_{k}" for f in "hg" for i in (1, 2, 3) for k in range(max_order + 1)]
        self.R, *gens = ring(self.names, QQ)
        self.ring = self.R
        self.jet = {(f, i, k): gens[self.names.index(f"{f}{i}_{k}")] for f in "hg" for i in (1, 2, 3)
                    for k in range(max_order + 1)}
        # each jet's position among the generators (the ring's own ``index`` compares elements one by one)
        self._pos = {key: self.names.index(f"{key[0]}{key[1]}_{key[2]}") for key in self.jet}
        self.backend = PolynomialBackend.on_ring(self)

    def D(self, p, j):
        """Total derivative ``d/dx_j``: ``sum_k d p / d f_j^{(k)} * f_j^{(k+1)}`` over ``f = h, g``.

        One pass over the terms of ``p`` per jet (the chain rule term by term) instead of a ring ``diff``, a product
        and a sum per jet; the terms are accumulated in the same order, so the result is the same dict.
        """
        R, K, pos = self.R, self.K, self._pos
        if any(m[pos[(f, j, K)]] for f in "hg" for m in p):
            raise InvalidOrderError(f"jet order {K} too small for this computation")
        out, zero = R.zero, R.domain.zero
        get = out.get
        for f in "hg":
            for k in range(K):
                a, b = pos[(f, j, k)], pos[(f, j, k + 1)]
                for m, c in p.items():
                    e = m[a]
                    if e:
                        n = list(m)
                        n[a] -= 1
                        n[b] += 1
                        n = tuple(n)
                        v = get(n, zero) + c * e
                        if v:
                            out[n] = v
                        else:
                            del out[n]
        return out

    def diff(self, p, index: int):
        """``D_{index + 1}`` (0-based ``index``, the derivative the field backend uses)."""
        return self.D(p, index + 1)

    def field(self, A, B):
        """``X_{A,B}^i = {x_i, A, B}`` (Eq. NB) with total derivatives."""
        dA = [self.D(A, j) for j in (1, 2, 3)]
        dB = [self.D(B, j) for j in (1, 2, 3)]
        return tuple(sum((s * dA[j - 1] * dB[k - 1] for (a, j, k), s in _EPS.items() if a == i), self.R.zero)
                     for i in (1, 2, 3))

    def to_sympy(self, p):
        return p.as_expr()


@dataclass
class GenericNambuResult:
    """The ``h^2`` equation for generic separable ``H, G`` and a word: consistent or not, with a certificate."""

    word: str
    unknowns: int
    equations: int
    consistent: bool
    corrections: tuple | None
    certificate: dict | None
    Z2: tuple


def generic_nambu_h2(word: str = "12321", max_order: int = 6) -> GenericNambuResult:
    """Decide whether a universal differential-polynomial shadow pair exists at ``h^2`` (full split, N = 3).

    Examples
    --------
    >>> generic_nambu_h2("12321").consistent
    False
    """
    J = JetRing(max_order)
    R = J.R
    H = {i: J.jet[("h", i, 0)] for i in (1, 2, 3)}
    G = {i: J.jet[("g", i, 0)] for i in (1, 2, 3)}
    Ht, Gt = H[1] + H[2] + H[3], G[1] + G[2] + G[3]

    def add(X, Y):
        return tuple(a + b for a, b in zip(X, Y))

    # the full split, Eqs. (X1)-(X3): piece i moves x_i
    pieces = {1: add(J.field(H[2], G[3]), J.field(H[3], G[2])), 2: add(J.field(H[3], G[1]), J.field(H[1], G[3])),
              3: add(J.field(H[1], G[2]), J.field(H[2], G[1]))}
    B = J.backend
    evaluator = BracketEvaluator({k: B.field(X) for k, X in pieces.items()}, B.bracket, B.is_zero)

    series = formal_bch(word, 3)
    Z2 = (R.zero,) * 3
    for c, tree in series.terms(3):
        X = evaluator.value(tree)
        if X is not None:
            Z2 = tuple(a + R.domain.convert(sympy.Rational(c)) * b for a, b in zip(Z2, B.values(X)))

    def monomials(nh, ng):
        # products of nh h-jets and ng g-jets whose derivative counts per coordinate are (2, 2, 2), in the order of
        # the nested enumeration (h-part, then g-part); the g-parts are grouped by their multidegree once
        jh = [("h", i, k) for i in (1, 2, 3) for k in range(max_order)]
        jg = [("g", i, k) for i in (1, 2, 3) for k in range(max_order)]

        def multidegree(keys):
            md = [0, 0, 0]
            for _, i, k in keys:
                md[i - 1] += k
            return tuple(md)

        by_md: dict = {}
        for gs in combinations_with_replacement(jg, ng):
            md = multidegree(gs)
            if max(md) <= 2:
                by_md.setdefault(md, []).append(gs)
        out = []
        for hs in combinations_with_replacement(jh, nh):
            md = multidegree(hs)
            for gs in by_md.get(tuple(2 - d for d in md), ()):
                m = R.one
                for key in hs + gs:
                    m *= J.jet[key]
                out.append(m)
        return out

    cols = [("H", m) for m in monomials(3, 2)] + [("G", m) for m in monomials(2, 3)]
    rows: dict = {}
    vecs = []
    for slot, m in cols:
        X = J.field(m, Gt) if slot == "H" else J.field(Ht, m)
        vecs.append({rows.setdefault((i, mono), len(rows)): c for i, comp in enumerate(X) for mono, c in comp.items()})
    rhs = {rows.setdefault((i, mono), len(rows)): c for i, comp in enumerate(Z2) for mono, c in comp.items()}
    res = solve_affine(SparseMatrix.from_columns(vecs, len(rows), QQ), [rhs])
    corrections = certificate = None
    if res.consistent:
        sol = res.particular[0]
        corrections = tuple(sympy.Add(*(QQ.to_sympy(v) * cols[c][1].as_expr() for c, v in sol.items() if cols[c][0] == s))
                            for s in "HG")
    else:
        inverse = {r: key for key, r in rows.items()}
        certificate = {(inverse[r][0] + 1, R({inverse[r][1]: 1}).as_expr()): QQ.to_sympy(v) for r, v in res.certificate.items()}
    return GenericNambuResult(word, len(cols), len(rows), res.consistent, corrections, certificate,
                              tuple(p.as_expr() for p in Z2))
