"""The generic shadow Hamiltonian of a splitting of ``H = |p|^2/2 + V(q)`` in any dimension, in tensor form.

For ``H = T(p) + V(q)`` with ``T = p.p/2`` on ``R^d x R^d`` and ``V`` an undefined smooth function, the
BCH series of a composition of ``e^{c h X_T}`` and ``e^{c h X_V}`` (piece 1 = T, piece 2 = V, the package's
canonical T|V split: ``121`` is position Verlet, ``212`` velocity Verlet), evaluated in the Poisson algebra
with ``[X_A, X_B] = X_{{B, A}}`` (Eq. CL1), is the shadow Hamiltonian

    H_S = H + sum_j h^j sum_w c_w {..{H_a, H_b}..},

and every nested bracket of ``T`` and ``V`` is a polynomial in ``p`` whose coefficients are full contractions
of the derivative tensors ``V^(k)(q)`` with ``p`` and with each other, e.g. ``{T, {T, V}} = V''(p, p)``,
``{V, {V, T}} = grad V . grad V`` (cf. Hairer, Lubich, Wanner, Sect. IX.4).

A contraction is a *tree*: its vertices are the tensors ``V^(k)`` (degree ``k``) and the ``p``'s (leaves);
an edge is a summed index.  Only trees occur: ``T`` and ``V`` are trees, and ``{A, B}`` of two trees
joins them by one edge (the index ``i`` of ``dA/dq_i dB/dp_i``), so neither traces (``Delta V``, which would
bring ``d``) nor cycles occur, and the answer is the same for every ``d``.  A tree is stored as its canonical
rooted form (the least over all roots of the sorted nested tuples), so equal contractions merge and a
cancellation leaves a structural zero.  Different trees are different functions of a generic ``V`` for large
``d``; for small ``d`` some coincide (for ``d = 1`` ``V''(p,p) grad V.grad V = V''(grad V, grad V) p.p``),
which :meth:`SeparableShadow.substitute` makes visible.

References
----------
Horikoshi, Sect. 4 and Eqs. (CL1), (BCH1), (BCH2); Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, 2nd ed., Sects. IX.3-IX.4 (modified equations of the Stoermer-Verlet scheme); R. D. Skeel and
D. J. Hardy, SIAM J. Sci. Comput. 23 (2001) 1172 (modified Hamiltonians of the leapfrog/Verlet method).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from fractions import Fraction

import sympy

from ..errors import InvalidCompositionError, NambuBCHError, ResourceLimitError

#: Most index sums (``d ** degree`` per tensor, added over the terms) a substitution accepts: each is a sympy
#: product, about 10^4 a second.
MAX_INDEX_SUMS = 200_000

# A contraction in canonical rooted form: a tensor node is ``(number of p legs, (child, child, ...))`` with the
# children sorted; ``T_KEY`` stands for ``p.p`` (two p's joined, no tensor), so ``T = T_KEY / 2``.
T_KEY = ("T",)

_NON_FINITE = (sympy.zoo, sympy.nan, sympy.oo, -sympy.oo)


# ------------------------------------------------------------------------------------------------------
# trees: canonical form and its inverse
# ------------------------------------------------------------------------------------------------------
def _rooted(plegs, nbrs, node, parent):
    return (plegs[node], tuple(sorted(_rooted(plegs, nbrs, c, node) for c in nbrs[node] if c != parent)))


def _canonical(plegs, edges):
    """The canonical form of the tree with ``plegs[i]`` p's on node ``i`` and the given edges."""
    nbrs = [[] for _ in plegs]
    for u, v in edges:
        nbrs[u].append(v)
        nbrs[v].append(u)
    return min(_rooted(plegs, nbrs, r, None) for r in range(len(plegs)))


def _unpack(key):
    """``(plegs, edges)`` of a canonical form (node 0 the root)."""
    plegs, edges = [], []

    def walk(form, parent):
        me = len(plegs)
        plegs.append(form[0])
        if parent is not None:
            edges.append((parent, me))
        for child in form[1]:
            walk(child, me)

    walk(key, None)
    return plegs, edges


def _bracket_keys(a, b):
    """``{A, B}`` of two contractions (canonical forms or ``T_KEY``) as ``{key: int}``; ``{f, g} = f_q g_p - f_p g_q``
    (the package's canonical bracket: ``X_F f = {f, F}``)."""
    out: dict = {}

    def add(key, c):
        out[key] = out.get(key, 0) + c
        if not out[key]:
            del out[key]

    if a == T_KEY and b == T_KEY:
        return out
    if a == T_KEY or b == T_KEY:
        sign, other = (-2, b) if a == T_KEY else (2, a)
        plegs, edges = _unpack(other)
        for node in range(len(plegs)):  # {A, p.p} = 2 A_q . p: one more p on a node (Leibniz)
            legs = list(plegs)
            legs[node] += 1
            add(_canonical(legs, edges), sign)
        return out
    pa, ea = _unpack(a)
    pb, eb = _unpack(b)
    na = len(pa)
    edges = ea + [(u + na, v + na) for u, v in eb]
    for x in range(na):
        for y in range(len(pb)):
            # A_q at node x times B_p at a p of node y, and minus A_p at a p of x times B_q at y:
            # the same joined tree with one p fewer on y, resp. on x
            for sign, count in ((1, pb[y]), (-1, pa[x])):
                if not count:
                    continue
                legs = pa + pb
                legs[x if sign < 0 else na + y] -= 1
                add(_canonical(legs, edges + [(x, na + y)]), sign * count)
    return out


# ------------------------------------------------------------------------------------------------------
# the exact data type
# ------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Contraction:
    """One full contraction of derivative tensors of ``V`` with ``p`` (a tree; see the module docstring).

    ``key`` is the canonical rooted form; :attr:`nodes` / :attr:`edges` list the tensors (``derivative`` = the
    order ``k`` of ``V^(k)``, ``p`` = how many of its slots take ``p``) and the summed indices between them.

    >>> Contraction.of([2], []).to_text(), Contraction.of([0, 0], [(0, 1)]).to_text()
    ("V''(p,p)", '∇V·∇V')
    """

    key: tuple

    @classmethod
    def of(cls, plegs, edges) -> "Contraction":
        """The contraction of the tree with ``plegs[i]`` p's on tensor ``i`` and ``edges`` (pairs of tensors)."""
        from ..checks import check_int, check_sequence

        plegs = [check_int(n, "p legs of a tensor", 0, 64) for n in check_sequence(plegs, "plegs", "integers")]
        pairs = []
        for e in check_sequence(edges, "edges", "pairs of tensor numbers"):
            pair = [check_int(i, "tensor number in edges", 0, len(plegs) - 1)
                    for i in check_sequence(e, "edge", "tensor numbers", length=2)]
            if pair[0] == pair[1]:
                raise NambuBCHError(f"an edge joins two different tensors, got {e!r}")
            pairs.append(tuple(pair))
        nbrs = [[] for _ in plegs]
        for u, v in pairs:
            nbrs[u].append(v)
            nbrs[v].append(u)
        seen, stack = {0}, [0]
        while stack and plegs:
            for c in nbrs[stack.pop()]:
                if c not in seen:
                    seen.add(c)
                    stack.append(c)
        if not plegs or len(pairs) != len(plegs) - 1 or len(seen) != len(plegs):
            raise NambuBCHError("a contraction is a tree: at least one tensor, connected, one edge fewer than tensors; "
                                f"got {len(plegs)} tensors and edges {pairs}")
        return cls(_canonical(plegs, pairs))

    @property
    def is_kinetic(self) -> bool:
        return self.key == T_KEY

    def _graph(self):
        plegs, edges = _unpack(self.key)
        deg = list(plegs)
        for u, v in edges:
            deg[u] += 1
            deg[v] += 1
        return plegs, edges, deg

    @property
    def nodes(self) -> list:
        if self.is_kinetic:
            return []
        plegs, _, deg = self._graph()
        return [{"derivative": k, "p": n} for k, n in zip(deg, plegs)]

    @property
    def edges(self) -> list:
        return [] if self.is_kinetic else [list(e) for e in self._graph()[1]]

    @property
    def p_degree(self) -> int:
        return 2 if self.is_kinetic else sum(self._graph()[0])

    def _rooted_for_printing(self):
        """``(plegs, neighbours, root)`` with the root a tensor of the highest degree (ties: least rooted form)."""
        plegs, edges, deg = self._graph()
        nbrs = [[] for _ in plegs]
        for u, v in edges:
            nbrs[u].append(v)
            nbrs[v].append(u)
        root = min(range(len(plegs)), key=lambda r: (-deg[r], _rooted(plegs, nbrs, r, None)))
        return plegs, nbrs, root

    def _render(self, style):
        if self.is_kinetic:
            return style["pp"]
        plegs, nbrs, root = self._rooted_for_printing()

        def args(node, parent):
            children = sorted((c for c in nbrs[node] if c != parent), key=lambda c: _rooted(plegs, nbrs, c, node))
            return [style["p"]] * plegs[node] + [vector(c, node) for c in children]

        def vector(node, parent):  # the tensor with its parent's slot open: a vector
            a = args(node, parent)
            if not a:
                return style["grad"]
            if len(a) == 1:
                inner = a[0] if a[0] in (style["p"], style["grad"]) else style["paren"](a[0])
                return style["V"](2) + style["apply"] + inner
            return style["V"](len(a) + 1) + style["paren"](",".join([*a, style["slot"]]))

        a = args(root, None)
        if not a:
            return "V"
        if len(a) == 1:
            return style["grad"] + style["dot"] + a[0]
        return style["V"](len(a)) + style["paren"](",".join(a))

    def to_text(self) -> str:
        """Index-free text: ``V''(p,p)``, ``∇V·∇V``, ``V''(p,V''p)``, ``V^(4)(p,p,p,p)``.

        A tensor with one slot open is a vector: ``V''p``, ``V'''(p,p,·)``.
        """
        return self._render(_TEXT)

    def to_latex(self) -> str:
        r"""Index-free LaTeX: ``V''(p,p)``, ``\nabla V\cdot\nabla V``, ``V^{(4)}(p,p,p,p)``."""
        return self._render(_LATEX)

    def index_sums(self, d: int) -> int:
        """How many products :meth:`evaluate` forms in dimension ``d`` (``d ** degree`` per tensor)."""
        return 0 if self.is_kinetic else sum(d**k for k in self._graph()[2])

    def evaluate(self, derivative, q_count: int, p_symbols):
        """The contraction for a concrete ``V``: ``derivative(idx)`` = ``d^k V / dq_idx`` (``idx`` sorted)."""
        if self.is_kinetic:
            return sympy.Add(*(x**2 for x in p_symbols))
        plegs, nbrs, root = self._rooted_for_printing()
        d = q_count

        def contract(node, parent, extra):
            children = [c for c in nbrs[node] if c != parent]
            vectors = [list(p_symbols)] * plegs[node] + [[contract(c, node, (i,)) for i in range(d)] for c in children]
            total = []
            for idx in itertools.product(range(d), repeat=len(vectors)):
                factor = derivative(tuple(sorted(idx + extra)))
                if factor == 0:
                    continue
                for vec, i in zip(vectors, idx):
                    factor = factor * vec[i]
                total.append(factor)
            return sympy.Add(*total)

        return contract(root, None, ())


def _primes(k, latex):
    if k <= 3:
        return "V" + "'" * k
    return f"V^{{({k})}}" if latex else f"V^({k})"


_TEXT = {"pp": "p·p", "p": "p", "grad": "∇V", "dot": "·", "apply": "", "slot": "·",
         "V": lambda k: _primes(k, False), "paren": lambda s: f"({s})"}
_LATEX = {"pp": r"p\cdot p", "p": "p", "grad": r"\nabla V", "dot": r"\cdot ", "apply": r"\,",
          "slot": r"\cdot", "V": lambda k: _primes(k, True), "paren": lambda s: rf"\left({s}\right)"}


class ContractionSum:
    """An exact sum ``sum_t c_t t`` of :class:`Contraction` s with ``Fraction`` coefficients (zero = empty).

    The Poisson bracket of two sums (:meth:`bracket`) is computed on the trees, bilinearly.

    >>> T, V = ContractionSum.kinetic(), ContractionSum.potential()
    >>> print(T.bracket(T.bracket(V)).to_text())
    V''(p,p)
    >>> print(V.bracket(V.bracket(T)).to_text())
    ∇V·∇V
    """

    __slots__ = ("terms",)

    def __init__(self, terms=None):
        self.terms = {k: Fraction(c) for k, c in (terms or {}).items() if c}

    @classmethod
    def kinetic(cls) -> "ContractionSum":
        return cls({T_KEY: Fraction(1, 2)})

    @classmethod
    def potential(cls) -> "ContractionSum":
        return cls({(0, ()): 1})

    def __bool__(self):
        return bool(self.terms)

    def __eq__(self, other):
        return isinstance(other, ContractionSum) and self.terms == other.terms

    def __add__(self, other):
        if not isinstance(other, ContractionSum):
            return NotImplemented
        out = dict(self.terms)
        for k, c in other.terms.items():
            out[k] = out.get(k, 0) + c
        return ContractionSum(out)

    def scaled(self, c) -> "ContractionSum":
        return ContractionSum({k: v * Fraction(c) for k, v in self.terms.items()})

    def bracket(self, other) -> "ContractionSum":
        """``{self, other}`` with ``{f, g} = sum_i df/dq_i dg/dp_i - df/dp_i dg/dq_i``."""
        from ..checks import check_type

        check_type(other, ContractionSum, "other")
        out: dict = {}
        for a, ca in self.terms.items():
            for b, cb in other.terms.items():
                for k, n in _bracket_keys(a, b).items():
                    out[k] = out.get(k, 0) + ca * cb * n
        return ContractionSum(out)

    def items(self) -> list:
        """``[(Fraction, Contraction)]``, higher powers of ``p`` first, then fewer tensors, then canonical order."""
        pairs = [(c, Contraction(k)) for k, c in self.terms.items()]
        return sorted(pairs, key=lambda t: (-t[1].p_degree, len(t[1].nodes), () if t[1].is_kinetic else t[1].key))

    def to_text(self) -> str:
        return _join_terms([(c, t.to_text()) for c, t in self.items()], latex=False)

    def to_latex(self) -> str:
        return _join_terms([(c, t.to_latex()) for c, t in self.items()], latex=True)

    def __repr__(self):
        return f"ContractionSum({self.to_text()!r})"


def _coefficient(c: Fraction, latex: bool, first: bool) -> str:
    sign = "-" if c < 0 else ("" if first else "+")
    a = abs(c)
    if a == 1:
        mag = ""
    elif latex:
        mag = rf"\tfrac{{{a.numerator}}}{{{a.denominator}}}\," if a.denominator != 1 else f"{a.numerator}\\,"
    else:
        mag = f"{a} "
    return (sign + " " if sign and not first else sign) + mag


def _join_terms(pairs, latex: bool) -> str:
    if not pairs:
        return "0"
    return " ".join(_coefficient(c, latex, i == 0) + s for i, (c, s) in enumerate(pairs))


# ------------------------------------------------------------------------------------------------------
# the shadow Hamiltonian
# ------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SeparableShadow:
    """The generic ``H_S`` of a composition for ``H = p.p/2 + V(q)``: ``series[j]`` is the coefficient of ``h^j``.

    Attributes
    ----------
    composition : Composition -- piece 1 = T, piece 2 = V
    order : int -- highest power of ``h``
    series : dict ``j -> ContractionSum`` (``series[0] = p.p/2 + V``)
    d : int or None -- the dimension substitutions default to (``q1..qd``, ``p1..pd``)
    """

    composition: object
    order: int
    series: dict
    d: int | None = None

    @property
    def word(self) -> str:
        return self.composition.name

    def to_text(self) -> str:
        lines = [f"H_S of {self.word} for H = p·p/2 + V(q), q, p in R^{self.d or 'd'}, through h^{self.order}:"]
        for j, s in sorted(self.series.items()):
            if s:
                lines.append(f"  h^{j}: {s.to_text()}" if j else f"  H  : {s.to_text()}")
        return "\n".join(lines)

    def to_latex(self) -> str:
        from ..printing import aligned

        tokens = []
        for j, s in sorted(self.series.items()):
            if not s:
                continue
            body = s.to_latex()
            tokens.append(body if j == 0 else rf"+ h^{{{j}}}\Bigl({body}\Bigr)")
        tokens.append(rf"+ O(h^{{{self.order + 1}}})")
        return aligned([(r"H_{S}", "=", tokens)])

    def _repr_latex_(self):
        return "$" + self.to_latex() + "$"

    def __repr__(self):
        return f"SeparableShadow({self.word!r}, order={self.order}, d={self.d})"

    def __str__(self):
        return self.to_text()

    def to_dict(self) -> dict:
        """JSON-able: the word, order, and per power of ``h`` the terms with coefficient, text, LaTeX and tree."""
        series = {}
        for j, s in sorted(self.series.items()):
            series[str(j)] = [{"coefficient": str(c), "term": t.to_text(), "latex": t.to_latex(),
                               "nodes": t.nodes, "edges": t.edges} for c, t in s.items()]
        return {"kind": "generic-separable", "integrator": self.word, "order": self.order,
                "H": "p·p/2 + V(q)", "dimension": self.d, "pieces": {"1": "T = p·p/2", "2": "V(q)"},
                "series": series}

    def substitute_series(self, V, d=None, q=None, p=None) -> dict:
        """``{j: sympy expression}``: each ``series[j]`` for a concrete potential ``V(q)``.

        Parameters
        ----------
        V : sympy expression, or a string parsed by :func:`nambu_bch.parsing.parse_expression`
        d : int, optional -- default: the result's ``d``, else ``len(q)``
        q, p : sequences of ``d`` symbols or names (default ``q1..qd``, ``p1..pd``; e.g. ``["x1"]``, ``["x2"]``
            for the pendulum's coordinates)

        Returns
        -------
        dict -- each coefficient in the normal form of the extended exact ring (:mod:`nambu_bch.algebra.extended`:
        polynomials expanded, radicals and exp/sin/cos reduced by their relations) when the ring takes ``V``'s atoms,
        else as the contraction sums built it (e.g. for an undefined ``V``)
        """
        q, p, V = self._inputs(V, d, q, p)
        work = sum(t.index_sums(len(q)) for s in self.series.values() for t in map(Contraction, s.terms))
        if work > MAX_INDEX_SUMS:
            raise ResourceLimitError(f"substituting V in d = {len(q)} through h^{self.order}: about {work} index sums "
                                     f"(at most {MAX_INDEX_SUMS} are accepted; estimated before any work): lower "
                                     "the order or d")
        memo: dict = {(): V}

        def derivative(idx):
            found = memo.get(idx)
            if found is None:
                found = memo[idx] = sympy.diff(derivative(idx[:-1]), q[idx[-1]])
            return found

        out = {}
        for j, s in sorted(self.series.items()):
            out[j] = sympy.Add(*(sympy.Rational(c.numerator, c.denominator) * t.evaluate(derivative, len(q), p)
                                 for c, t in s.items()))
        return _normal_forms(out, q + p, V)

    def substitute(self, V, d=None, q=None, p=None) -> sympy.Expr:
        """The concrete ``H_S = sum_j h^j series[j]`` for a potential ``V(q)`` (see :meth:`substitute_series`).

        >>> q1, p1 = sympy.symbols("q1 p1")
        >>> separable_shadow("212", 2).substitute(q1**4 / 4, d=1).coeff(sympy.Symbol("h"), 2)
        p1**2*q1**2/4 - q1**6/24
        """
        h = sympy.Symbol("h")
        return sympy.Add(*(h**j * e for j, e in self.substitute_series(V, d, q, p).items()))

    def _inputs(self, V, d, q, p):
        from types import SimpleNamespace

        from ..checks import check_int
        from ..parsing import as_expression, as_symbols
        from .generic import check_work

        if d is None:
            d = self.d if self.d is not None else (len(q) if q is not None else None)
        if d is None:
            raise NambuBCHError("substitute needs the dimension: give d=... or the symbols q=[...]")
        d = check_int(d, "d", 1, 64)
        q = tuple(sympy.symbols(f"q1:{d + 1}")) if q is None else as_symbols(q, "q", names=True)
        p = tuple(sympy.symbols(f"p1:{d + 1}")) if p is None else as_symbols(p, "p", names=True)
        if len(q) != d or len(p) != d or len(set(q + p)) != 2 * d:
            raise NambuBCHError(f"substitute: q and p must be {d} distinct symbols each, got q={q}, p={p}")
        _check_not_reserved((*q, *p))
        V = as_expression(V, q, "V")
        if V.has(sympy.Float):  # symbolic code never sees floats: 0.5 is read as 1/2, as System does
            V = sympy.nsimplify(V, rational=True)
        _check_not_reserved(V.free_symbols)
        if V.free_symbols & set(p) or V.has(*_NON_FINITE) or getattr(V, "is_Matrix", False):
            raise NambuBCHError(f"V must be a finite function of q = {', '.join(map(str, q))} (and parameters) only, "
                                f"got {str(V)[:80]}")
        # the concrete route's size estimate of the same derivatives (BCH brackets of T and V up to order + 1 letters)
        check_work(SimpleNamespace(coordinates=q, name=f"V = {str(V)[:40]}"), 2, (V,), self.order)
        return q, p, V


def _check_not_reserved(symbols) -> None:
    from ..systems.system import RESERVED_SYMBOLS

    clash = sorted(x.name for x in symbols if x.name in RESERVED_SYMBOLS)
    if clash:
        raise NambuBCHError(f"substitute: the symbol {clash[0]!r} is reserved (step / family parameter); rename it")


def _normal_forms(series: dict, coordinates, V) -> dict:
    """``series`` in the extended ring's normal form, or unchanged when the ring refuses an atom of ``V``."""
    from ..algebra.extended import extended_ring

    parameters = sorted((x for x in V.free_symbols if x not in coordinates), key=str)
    if any(not isinstance(x, sympy.Symbol) for x in parameters):
        return series
    ring = extended_ring(coordinates, parameters, [V, *series.values()])
    if ring is None:
        return series
    return {j: ring.to_sympy(ring.convert(e)) for j, e in series.items()}


def separable_shadow(word="212", order: int = 4, d: int | None = None) -> SeparableShadow:
    """The generic shadow Hamiltonian of ``word`` for ``H = p.p/2 + V(q)`` through ``h^order``, in tensor form.

    The coefficients are those of the package's formal BCH series (:func:`~nambu_bch.bch.formal_bch`) of the
    composition on the canonical T|V split (piece 1 = ``T = p.p/2``, piece 2 = ``V``), evaluated on
    :class:`ContractionSum` s with ``[X_A, X_B] = X_{{B, A}}`` (Eq. CL1).  For velocity Verlet (``212``)

        H_S = H + h^2 (V''(p,p)/12 - grad V.grad V/24)
                + h^4 (-V''''(p,p,p,p)/720 + V'''(p,p,grad V)/120 + V''(p,V''p)/60 - V''(grad V,grad V)/240) + ...

    (the h^2 term is the symmetric BCH formula, HLW Sect. III.4.2; both orders are checked in the tests against
    the package's concrete shadow Hamiltonians, which are verified by backward error analysis).

    Parameters
    ----------
    word : composition spec over the two pieces (``212``, ``121``, ``TVT``, ``yoshida``, ``1:c,2:c,...``)
        with rational coefficients
    order : int -- highest power of ``h`` (at most :data:`nambu_bch.checks.MAX_ORDER`)
    d : int, optional -- the dimension that :meth:`SeparableShadow.substitute` assumes by default; the tensor
        form itself holds for every ``d``

    Returns
    -------
    SeparableShadow

    Examples
    --------
    >>> print(separable_shadow("212", 2).series[2].to_text())
    1/12 V''(p,p) - 1/24 ∇V·∇V
    """
    from ..bch.backward import check_order
    from ..bch.evaluation import BracketEvaluator
    from ..bch.formal import formal_bch
    from ..checks import check_int
    from ..integrators.composition import composition_for
    from .generic import generic_system

    order = check_order(order)  # at most 12: h^12 (269 trees) takes a few seconds
    if d is not None:
        d = check_int(d, "d", 1, 64)
    try:
        comp = composition_for(word, generic_system().splitting)  # the T|V split: piece 1 = T, piece 2 = V
    except InvalidCompositionError as exc:
        raise InvalidCompositionError(f"generic H = |p|^2/2 + V(q) (piece 1 = T, piece 2 = V): {exc}") from None
    if comp.extension:
        raise InvalidCompositionError(f"{comp.name}: the generic tensor form needs rational coefficients "
                                      "(algebraic ones are accepted by shadow_hamiltonians on a concrete system)")
    leaves = {1: ContractionSum.kinetic(), 2: ContractionSum.potential()}
    evaluator = BracketEvaluator(leaves, bracket=lambda A, B: B.bracket(A), is_zero=lambda s: not s)
    series_bch = formal_bch(comp, order + 1)
    series = {}
    for j in range(order + 1):
        total = ContractionSum()
        for c, tree in series_bch.terms(j + 1):
            value = evaluator.value(tree)
            if value is not None:
                c = sympy.Rational(c)
                total = total + value.scaled(Fraction(int(c.p), int(c.q)))
        series[j] = total
    return SeparableShadow(comp, order, series, d)
