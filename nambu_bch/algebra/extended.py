"""An exact ring for non-polynomial Hamiltonians: the input's functions become variables with relations.

Each non-polynomial atom of the input becomes a generator of a polynomial ring over ``QQ`` (the
parameters are further generators, never differentiated):

* ``exp(a)`` -> ``E`` with ``E' = a' E``;
* ``sin(a)``, ``cos(a)`` -> ``S``, ``C`` with ``S' = a' C``, ``C' = -a' S`` and ``C^2 = 1 - S^2``;
* ``P^(k/2)`` (a square root of a polynomial ``P``) -> ``u^k`` with ``u^2 = P``, ``u' = u P' / (2 P)``;
* ``1/P`` (a denominator) -> a negative power of each irreducible factor ``D`` of ``P``.

Arguments that are rational multiples of one another share one generator (``exp(2 x) = E^2``,
``sin(2 x) = 2 S C``); nested atoms (``sin(sin x)``) are generators over the lower ones.  An element is
``N / prod D_j^(a_j)``: ``N`` a polynomial (python-flint ``fmpq_mpoly``, lexicographic, the algebraic
generators ``C``, ``u`` first) reduced modulo ``S^2 + C^2 - 1`` and ``u^2 - P``, the ``D_j`` the
irreducible denominators and the exponential generators (units).  Derivatives (the chain rule through the
generators) and products keep elements in this form, so brackets, the backward error analysis and the
check of a shadow Hamiltonian are polynomial arithmetic.

Why the zero test is exact
--------------------------
Let ``B = QQ[x, S, E, parameters]``.  The coordinates, the ``S`` and the ``E`` are algebraically
independent when the exponential arguments, and separately the trigonometric ones, are linearly
independent over ``QQ`` modulo constants (Ax, *On Schanuel's conjectures*, Ann. Math. 93 (1971) 252,
Theorem 3, applied to the arguments ``a`` and ``i a``; checked here on the arguments' terms, and
arguments with a constant part are refused).  ``C`` and ``u`` are square roots over ``Frac(B)`` of
``1 - S^2`` and ``P``; the extension has full degree ``2^k`` exactly when no product of a non-empty
subset of the radicands is a square in ``Frac(B)`` (Kummer theory; checked on their squarefree parts,
over ``GF(2)``), and then ``R = B[C, u] / (S^2 + C^2 - 1, u^2 - P)`` is a domain, free over ``B`` with the
monomials of degree < 2 in each ``C``, ``u`` as basis.  The relations have pairwise coprime leading
terms ``C^2``, ``u^2`` in the lexicographic order with ``C``, ``u`` first, so they are a Groebner basis
(Cox, Little, O'Shea, *Ideals, Varieties, and Algorithms*, Sect. 2.9, Prop. 4) and the remainder of the
division by them is the normal form.  An element ``N / prod D^a`` is zero exactly when ``N`` is (the
``D`` are non-zero in the domain ``R``), so the zero test is ``N == 0`` on the normal form, with no
simplification.  Inputs outside these conditions raise :class:`~nambu_bch.errors.NoExactResultError`.
"""

from __future__ import annotations

import sympy

from ..errors import NoExactResultError
from . import _flint
from .ring import declare

#: The functions the ring accepts as atoms (everything else is refused).
_TRIG = (sympy.sin, sympy.cos)


def _refuse(what, why):
    shown = str(what)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    raise NoExactResultError(f"{shown}: {why} (the extended exact ring accepts polynomials in the coordinates and "
                             "parameters, exp, sin, cos of them, square roots of polynomials and their quotients)")


def _linear_part(arg, coordinates):
    """``{term: rational}`` of an exponential/trigonometric argument (its terms with rational coefficients)."""
    parts = sympy.expand(arg).as_coefficients_dict()
    out = {}
    for term, c in parts.items():
        if not term.has(*coordinates):
            _refuse(arg, "an argument with a constant part")
        if not c.is_Rational:
            _refuse(arg, "an argument with a non-rational coefficient")
        out[term] = sympy.Rational(c)
    return out


class _Direction:
    """Arguments that are rational multiples of one vector ``v``: the generator is ``exp``/``sin`` of ``base * v``."""

    def __init__(self, vector, key):
        self.vector = vector   # {term: rational}, the first term's coefficient 1
        self.key = key
        self.multiples = set()  # rationals r with argument = r v
        self.base = None        # the rational g with every multiple an integer multiple of g

    def finish(self):
        from math import gcd, lcm

        nums = [abs(r.p) for r in self.multiples]
        dens = [r.q for r in self.multiples]
        self.base = sympy.Rational(gcd(*nums), lcm(*dens))

    def expression(self):
        return sympy.Add(*(self.base * c * t for t, c in self.vector.items()))


def _direction_key(linear):
    terms = sorted(linear, key=sympy.default_sort_key)
    first = linear[terms[0]]
    return tuple((t, linear[t] / first) for t in terms), first


def powers_of(memo, base, e):
    """``base**e`` (sympy), remembered: the atoms of a large expression are few and repeat."""
    key = (base, e)
    p = memo.get(key)
    if p is None:
        p = memo[key] = base ** e
    return p


class Element:
    """``num / prod D_j^(den_j)`` of an :class:`ExtendedRing` (``num`` in normal form; immutable)."""

    __slots__ = ("ring", "num", "den")

    def __init__(self, ring, num, den):
        self.ring, self.num, self.den = ring, num, den

    def __bool__(self):
        return not self.num.is_zero()

    def __add__(self, other):
        return self.ring.add(self, other if isinstance(other, Element) else self.ring.constant(other))

    __radd__ = __add__

    def __neg__(self):
        return Element(self.ring, -self.num, self.den)

    def __sub__(self, other):
        return self + (-other if isinstance(other, Element) else -self.ring.scalar(other))

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, other):
        if isinstance(other, Element):
            return self.ring.mul(self, other)
        return Element(self.ring, self.num * self.ring.scalar(other), self.den)

    __rmul__ = __mul__

    def __pow__(self, n: int):
        out, base = self.ring.one, self
        while n:
            if n & 1:
                out = out * base
            n >>= 1
            if n:
                base = base * base
        return out

    def __repr__(self):
        return f"Element({self.ring.to_sympy(self)})"


@declare(vector_fields=False)
class ExtendedRing:
    """The exact ring of the atoms of ``expressions`` over ``QQ[coordinates, parameters]`` (module docstring).

    Parameters
    ----------
    coordinates : sequence of sympy Symbols -- differentiated by :meth:`diff`
    parameters : sequence of sympy Symbols -- constants (may occur in denominators)
    expressions : sympy expressions whose atoms (exp, sin, cos, square roots, denominators) the ring adopts

    Raises
    ------
    NoExactResultError
        for an atom outside the accepted kinds or relations this ring cannot make canonical.

    Examples
    --------
    >>> q1, q2 = sympy.symbols("q1 q2")
    >>> R = ExtendedRing([q1, q2], [], [1 / sympy.sqrt(q1**2 + q2**2), sympy.cos(q1)])
    >>> V = R.convert(-1 / sympy.sqrt(q1**2 + q2**2))
    >>> R.to_sympy(R.diff(V, 0)) == q1 / (q1**2 + q2**2)**sympy.Rational(3, 2)
    True
    >>> bool(R.convert(sympy.sin(q1)**2 + sympy.cos(q1)**2 - 1))
    False
    """

    def __init__(self, coordinates, parameters=(), expressions=()):
        self.coordinates = tuple(coordinates)
        self.parameters = tuple(parameters)
        self.n = len(self.coordinates)
        exprs = [sympy.sympify(e, strict=True) for e in expressions]
        self._discover(exprs)
        self._build()
        #: no exp, sin, cos or square root: the elements are rational functions
        self.rational = not (self._trig or self._exps or self._radicands)

    # -- construction ---------------------------------------------------------------
    def _discover(self, exprs):
        coords, params = self.coordinates, self.parameters
        allowed = set(coords) | set(params)
        self._exp_dirs, self._trig_dirs = {}, {}
        self._radicands, self._denominators = [], []
        seen = set()

        def walk(e):
            if e in seen:
                return
            seen.add(e)
            for a in e.args:
                walk(a)
            if e.is_Symbol:
                if e not in allowed:
                    _refuse(e, "a symbol that is neither a coordinate nor a parameter")
            elif e.is_Number:
                if not e.is_Rational:
                    _refuse(e, "a number that is not rational")
            elif e.is_NumberSymbol or e is sympy.I:
                _refuse(e, "a transcendental or complex constant")
            elif e.is_Add or e.is_Mul:
                pass
            elif e.is_Pow:
                b, x = e.base, e.exp
                if b is sympy.E:
                    self._add_direction(self._exp_dirs, x)
                elif x.is_Integer:
                    if x < 0:
                        self._denominators.append(b)
                elif x.is_Rational and x.q == 2:
                    if b not in self._radicands:
                        self._radicands.append(b)
                else:
                    _refuse(e, "a power other than an integer or half-integer one")
            elif isinstance(e, sympy.exp):
                self._add_direction(self._exp_dirs, e.args[0])
            elif isinstance(e, _TRIG):
                self._add_direction(self._trig_dirs, e.args[0])
            else:
                _refuse(e, "a function this ring has no rule for")

        for e in exprs:
            walk(e)
        for dirs in (self._exp_dirs, self._trig_dirs):
            for d in dirs.values():
                d.finish()
            self._check_independent(list(dirs.values()))

    def _add_direction(self, dirs, arg):
        linear = _linear_part(arg, self.coordinates)
        key, first = _direction_key(linear)
        d = dirs.get(key)
        if d is None:
            d = dirs[key] = _Direction({t: c for t, c in key}, key)
        d.multiples.add(first)

    def _check_independent(self, dirs):
        if len(dirs) < 2:
            return
        terms = sorted({t for d in dirs for t in d.vector}, key=sympy.default_sort_key)
        M = sympy.Matrix([[d.vector.get(t, 0) for t in terms] for d in dirs])
        if M.rank() < len(dirs):
            _refuse(", ".join(str(d.expression()) for d in dirs),
                    "arguments that are linearly dependent over QQ (relations such as exp(x + y) = exp(x) exp(y))")

    def _build(self):
        trig = list(self._trig_dirs.values())
        exps = list(self._exp_dirs.values())
        names = ([f"C{k}" for k in range(len(trig))] + [f"u{k}" for k in range(len(self._radicands))]
                 + [str(x) for x in self.coordinates] + [f"S{k}" for k in range(len(trig))]
                 + [f"E{k}" for k in range(len(exps))] + [str(p) for p in self.parameters])
        ctx = self._ctx = _flint.fmpq_mpoly_context(len(names))
        self.names = tuple(names)
        gens = ctx.gens()
        nt, nr, n = len(trig), len(self._radicands), self.n
        self._C = gens[:nt]
        self._u = gens[nt:nt + nr]
        self._x = gens[nt + nr:nt + nr + n]
        self._S = gens[nt + nr + n:nt + nr + n + nt]
        self._E = gens[nt + nr + n + nt:nt + nr + n + nt + len(exps)]
        self._p = gens[nt + nr + n + nt + len(exps):]
        self._algebraic = nt + nr
        self._zero_poly = ctx.from_dict({})
        self._one_poly = ctx.from_dict({(0,) * len(names): 1})
        self._trig, self._exps = trig, exps
        self._trig_index = {d.key: k for k, d in enumerate(trig)}
        self._exp_index = {d.key: k for k, d in enumerate(exps)}
        # the relations C^2 - (1 - S^2), u^2 - P (a Groebner basis: coprime leading terms C^2, u^2); cosines, not
        # sines, are reduced so that the h^2 term of a potential -cos q keeps its sin(q)^2 = V'(q)^2
        self._relations = [(k, self._C[k] ** 2 - (1 - self._S[k] ** 2)) for k in range(nt)]
        self._plain_memo = {}
        radicand_polys = []
        for j, b in enumerate(self._radicands):
            P = self._plain(b)
            if any(P.degrees()[i] for i in range(self._algebraic)):
                _refuse(b, "a square root of an expression holding cos or another square root")
            radicand_polys.append(P)
            self._relations.append((nt + j, self._u[j] ** 2 - P))
        self._check_kummer(radicand_polys)
        # the denominators: the exponential generators (units) and the irreducible factors of the rest
        dens = list(self._E)
        for b in [*self._denominators, *radicand_polys]:
            P = b if isinstance(b, type(self._one_poly)) else self._plain(b)
            if P.is_zero():
                _refuse(b, "a division by zero")
            for j, u in enumerate(self._u):  # a power of a square root in a denominator: 1/u = u/P is known
                d = P.degrees()[nt + j]
                if d:
                    q, r = divmod(P, u ** d)
                    P = q if r.is_zero() else P
            if any(P.degrees()[i] for i in range(self._algebraic)):
                _refuse(b, "a denominator holding cos or a square root")
            for f, _ in P.factor()[1]:
                if f.is_constant() or any(f == d for d in dens):
                    continue
                dens.append(f)
        self._dens = dens
        self._m = len(dens)
        self._zero_den = (0,) * self._m
        self.zero = Element(self, self._zero_poly, self._zero_den)
        self.one = Element(self, self._one_poly, self._zero_den)
        self._dpow_memo = {}
        self._convert_memo = {}
        self._power_memo, self._atoms_sympy, self._dens_sympy_memo = {}, None, None  # the sympy edge
        self._den_derivs = {}  # (i, j) -> d D_j / d x_i, on first use (after the generators it holds)
        # 1/u_j = u_j / P_j with P_j = c prod D^m
        self._u_inverse = [self._inverse_of(self._u[j], radicand_polys[j]) for j in range(nr)]
        # derivatives of the generators by each coordinate, lower atoms first (their rules use the lower ones)
        self._gen_derivs = [[] for _ in range(n)]
        at_x, at_s, at_e = nt + nr, nt + nr + n, nt + nr + n + nt  # the generators' positions
        for i in range(n):
            self._gen_derivs[i].append((at_x + i, self.one))
        for kind, k, d in self._atom_order():
            arg = self._element_of(d.expression()) if kind != "u" else None
            for i in range(n):
                if kind == "u":
                    dP = self.diff(Element(self, radicand_polys[k], self._zero_den), i)
                    if not dP:
                        continue
                    # u' = P' / (2 u) = P' u^(-1) / 2
                    self._gen_derivs[i].append((nt + k, dP * self._u_inverse[k] * sympy.Rational(1, 2)))
                    continue
                da = self.diff(arg, i)
                if not da:
                    continue
                if kind == "trig":
                    S, C = self._atom(self._S[k]), self._atom(self._C[k])
                    self._gen_derivs[i].append((at_s + k, da * C))
                    self._gen_derivs[i].append((k, -(da * S)))
                else:
                    self._gen_derivs[i].append((at_e + k, da * self._atom(self._E[k])))

    def _atom_order(self):
        """The atoms, each after the atoms its argument holds (by the depth of the argument's expression tree)."""
        items = [("trig", k, d) for k, d in enumerate(self._trig)] + [("exp", k, d) for k, d in enumerate(self._exps)]
        items += [("u", k, None) for k in range(len(self._radicands))]

        def depth(e):
            return 1 + max((depth(a) for a in e.args), default=0)

        return sorted(items, key=lambda it: depth(self._radicands[it[1]]) if it[0] == "u" else depth(it[2].expression()))

    def _check_kummer(self, radicands):
        """Refuse square roots whose radicands (with the ``1 - S^2`` of the cosines) are multiplicatively dependent
        modulo squares: then some product of them is a square and the relations are not a canonical form."""
        vectors = []
        keys: dict = {}
        polys = [1 - s ** 2 for s in self._S] + list(radicands)
        for P in polys:
            content, factors = P.factor()
            bits = 0
            c = sympy.Rational(int(content.p), int(content.q))
            if c < 0:
                bits |= 1 << keys.setdefault("-1", len(keys))
            for prime, e in sympy.factorint(abs(c.p) * c.q).items():
                if e % 2:
                    bits |= 1 << keys.setdefault(prime, len(keys))
            for f, e in factors:
                if e % 2:
                    bits |= 1 << keys.setdefault(("factor", str(f)), len(keys))  # flint's factors are monic
            vectors.append(bits)
        # Gaussian elimination over GF(2)
        pivots: dict = {}
        for v, P in zip(vectors, polys):
            while v:
                top = v.bit_length() - 1
                if top not in pivots:
                    pivots[top] = v
                    break
                v ^= pivots[top]
            if not v:
                _refuse(P, "square roots whose product is a square (not independent)")

    # -- conversion -----------------------------------------------------------------------
    def _direction_of(self, dirs, index, arg):
        linear = _linear_part(arg, self.coordinates)
        key, first = _direction_key(linear)
        k = index.get(key)
        if k is None:
            _refuse(arg, "an argument this ring was not built with")
        multiple = first / dirs[k].base
        if not multiple.is_Integer:
            _refuse(arg, "an argument that is not an integer multiple of the ring's generator")
        return k, int(multiple)

    def _trig_poly(self, k, n, cosine):
        """``cos(n a)``/``sin(n a)`` in ``S = sin a``, ``C = cos a`` (Chebyshev recurrences), ``n`` a non-zero integer;
        not yet reduced."""
        S, C = self._S[k], self._C[k]
        sign = 1
        if n < 0:
            n, sign = -n, (1 if cosine else -1)
        c0, c1 = self._one_poly, C
        s0, s1 = self._zero_poly, S
        for _ in range(n - 1):
            c0, c1 = c1, C * c1 * 2 - c0
            s0, s1 = s1, C * s1 * 2 - s0
        return (c1 if cosine else s1) * sign

    def _plain(self, e):
        """A polynomial of the construction (no denominators): coordinates, parameters, generators."""
        memo = self._plain_memo
        if e in memo:
            return memo[e]
        if e.is_Symbol:
            out = self._x[self.coordinates.index(e)] if e in self.coordinates else self._p[self.parameters.index(e)]
        elif e.is_Rational:
            out = self._one_poly * _flint.fmpq(int(e.p), int(e.q))
        elif e.is_Add:
            out = self._zero_poly
            for a in e.args:
                out = out + self._plain(a)
        elif e.is_Mul:
            out = self._one_poly
            for a in e.args:
                out = self._reduce(out * self._plain(a))
        elif e.is_Pow and e.exp.is_Integer and e.exp >= 0 and e.base is not sympy.E:
            out = self._reduce(self._plain(e.base) ** int(e.exp))
        elif isinstance(e, _TRIG):
            k, m = self._direction_of(self._trig, self._trig_index, e.args[0])
            out = self._reduce(self._trig_poly(k, m, isinstance(e, sympy.cos)))
        elif isinstance(e, sympy.exp) or (e.is_Pow and e.base is sympy.E):
            k, m = self._direction_of(self._exps, self._exp_index, e.exp if e.is_Pow else e.args[0])
            if m < 0:
                _refuse(e, "a negative power of an exponential inside a square root or denominator")
            out = self._E[k] ** m
        elif e.is_Pow and e.exp.is_Rational and e.exp.q == 2 and e.exp > 0 and e.base in self._radicands:
            j = self._radicands.index(e.base)
            out = self._reduce(self._u[j] ** int(e.exp.p))
        else:
            _refuse(e, "an expression that is not a polynomial in the ring's generators")
        memo[e] = out
        return out

    def _reduce(self, p):
        """The normal form of a polynomial modulo the relations (remainder by the Groebner basis)."""
        if not self._relations or p.is_zero():
            return p
        degrees = p.degrees()
        for k, g in self._relations:
            if degrees[k] >= 2:
                p = divmod(p, g)[1]
        return p

    def _atom(self, g):
        return Element(self, g, self._zero_den)

    def _inverse_of(self, numerator, P):
        """``numerator / P`` as an element, ``P`` a product of a rational and the ring's denominators."""
        den = [0] * self._m
        rest = P
        for j, D in enumerate(self._dens):
            while not rest.is_constant():
                q, r = divmod(rest, D)
                if not r.is_zero():
                    break
                rest, den[j] = q, den[j] + 1
        if not rest.is_constant() or rest.is_zero():
            raise NoExactResultError(f"the ring has no inverse of {P} (not a product of its denominators)")
        c = rest.leading_coefficient()
        return Element(self, numerator * (1 / c), tuple(den))

    def scalar(self, value):
        """An exact rational as a flint ``fmpq`` (the scalars of the ring)."""
        if isinstance(value, int) or _flint.is_fmpq(value):
            return _flint.fmpq(value)
        value = sympy.sympify(value, strict=True)
        if not value.is_Rational:
            raise NoExactResultError(f"{value} is not a rational number (the ring's scalars are rational)")
        return _flint.fmpq(int(value.p), int(value.q))

    # -- the ring protocol (nambu_bch.algebra.ring.ExactRing) -------------------------------
    @property
    def gens(self) -> tuple:
        """The generators as elements: the coordinates first, then ``C``, ``u``, ``S``, ``E`` and the parameters."""
        return tuple(self._atom(g) for g in (*self._x, *self._C, *self._u, *self._S, *self._E, *self._p))

    def common(self, *values) -> tuple:
        """The values as elements (every value of this ring is one)."""
        return tuple(v if isinstance(v, Element) else self.convert(v) for v in values)

    @staticmethod
    def is_zero(value) -> bool:
        """Zero on the normal form: the numerator is the zero polynomial."""
        return not value

    @staticmethod
    def is_polynomial(value) -> bool:
        """Every element is a ring element (no general sympy expressions here)."""
        return isinstance(value, Element)

    def constant(self, value) -> Element:
        return Element(self, self._one_poly * self.scalar(value), self._zero_den)

    def convert(self, expr) -> Element:
        """A sympy expression in the ring's atoms as an :class:`Element` (refused when it has other atoms); an
        element of this ring unchanged."""
        if isinstance(expr, Element) and expr.ring is self:
            return expr
        return self._element_of(sympy.sympify(expr, strict=True))

    def _element_of(self, e):
        memo = self._convert_memo
        found = memo.get(e)
        if found is not None:
            return found
        if e.is_Add:
            out = self.zero
            for a in e.args:
                out = out + self._element_of(a)
        elif e.is_Mul:
            out = self.one
            for a in e.args:
                out = out * self._element_of(a)
        elif e.is_Pow and e.base is not sympy.E and e.exp.is_Rational and not (e.exp.q == 2 and e.base in self._radicands):
            if not e.exp.is_Integer:
                _refuse(e, "a power other than an integer one or a square root of the ring's radicands")
            k = int(e.exp)
            base = self._element_of(e.base)
            out = base ** k if k >= 0 else self.inverse(base) ** (-k)
        elif e.is_Pow and e.base is not sympy.E and e.exp.is_Rational:  # u^k, k odd
            j = self._radicands.index(e.base)
            k = int(e.exp.p)
            out = self._atom(self._u[j]) ** k if k >= 0 else self._u_inverse[j] ** (-k)
        elif isinstance(e, sympy.exp) or (e.is_Pow and e.base is sympy.E):
            k, m = self._direction_of(self._exps, self._exp_index, e.exp if e.is_Pow else e.args[0])
            out = Element(self, self._E[k] ** m, self._zero_den) if m >= 0 else Element(
                self, self._one_poly, tuple(-m if j == k else 0 for j in range(self._m)))
        elif isinstance(e, _TRIG):
            k, m = self._direction_of(self._trig, self._trig_index, e.args[0])
            out = Element(self, self._reduce(self._trig_poly(k, m, isinstance(e, sympy.cos))),
                          self._zero_den)
        else:
            out = Element(self, self._plain(e), self._zero_den)
        memo[e] = out
        return out

    def inverse(self, x: Element) -> Element:
        """``1 / x`` for ``x`` a rational times a product of the ring's denominators and square roots."""
        num = x.num
        if num.is_zero():
            raise NoExactResultError("division by zero in the extended ring")
        # a power of u_j in the numerator: 1/u_j is known
        out = self.one
        degrees = num.degrees()
        for j, u in enumerate(self._u):
            d = degrees[len(self._C) + j]
            if d:
                q, r = divmod(num, u ** d)
                if not r.is_zero():
                    raise NoExactResultError(f"the ring has no inverse of {self.to_sympy(x)}")
                num, out = q, out * self._u_inverse[j] ** d
        inv = self._inverse_of(self._dpow(x.den), num)
        return out * inv

    def _dpow(self, exponents):
        p = self._dpow_memo.get(exponents)
        if p is None:
            p = self._one_poly
            for D, a in zip(self._dens, exponents):
                if a:
                    p = p * D ** a
            self._dpow_memo[exponents] = p
        return p

    def to_sympy(self, x: Element) -> sympy.Expr:
        """``x`` as an expanded sympy expression: one term per monomial of the numerator, over its denominators.

        The numerator's part on each basis monomial in ``C``, ``u`` is put in lowest terms by itself (so
        ``u / P^3`` and ``P / P^3`` print as ``P^(-5/2)`` and ``P^(-2)``); the powers of an exponential
        generator in the numerator and the denominator join in one ``exp(k a)``; the numerator is
        distributed over the denominators' powers as ``sympy.expand`` does.
        """
        groups: dict = {}
        for m, c in zip(x.num.monoms(), x.num.coeffs()):
            groups.setdefault(tuple(m[:self._algebraic]), {})[tuple(map(int, m))] = c
        terms = []
        for part in groups.values():
            terms += self._terms(self.lowest_terms(Element(self, self._ctx.from_dict(part), x.den)))
        return sympy.Add(*terms)

    def _terms(self, x: Element) -> list:
        atoms = self._generator_expressions()
        powers = self._power_memo
        n_exp, first_exp = len(self._exps), len(atoms) - len(self.parameters) - len(self._exps)
        dens = self._dens_sympy()
        shared = [powers_of(powers, d, -a) for d, a in zip(dens[n_exp:], x.den[n_exp:]) if a]
        terms = []
        for m, c in zip(x.num.monoms(), x.num.coeffs()):
            factors = [sympy.Rational(int(c.p), int(c.q))]
            for k, (a, e) in enumerate(zip(atoms, m)):
                if first_exp <= k < first_exp + n_exp:
                    e = int(e) - x.den[k - first_exp]
                    if e:
                        factors.append(sympy.exp(e * self._exps[k - first_exp].expression()))
                elif e:
                    factors.append(powers_of(powers, a, int(e)))
            terms.append(sympy.Mul(*factors, *shared))
        return terms

    def lowest_terms(self, x: Element) -> Element:
        """``x`` with no denominator ``D`` dividing its numerator: the canonical form ``N / prod D^a``.

        A ``D`` is free of the reduced generators (``C``, ``u``), so it divides ``N`` exactly when it divides
        each of ``N``'s coefficients on the basis monomials, and the quotient is still reduced; with the ``D``
        distinct irreducibles of the factorial ring ``B``, the minimal exponents are unique.
        """
        num, den = x.num, list(x.den)
        if num.is_zero():
            return self.zero
        for j, D in enumerate(self._dens):
            while den[j]:
                q, r = divmod(num, D)
                if not r.is_zero():
                    break
                num, den[j] = q, den[j] - 1
        return Element(self, num, tuple(den))

    def _generator_expressions(self):
        if self._atoms_sympy is None:
            out = [sympy.cos(d.expression()) for d in self._trig]
            out += [sympy.sqrt(b) for b in self._radicands]
            out += list(self.coordinates)
            out += [sympy.sin(d.expression()) for d in self._trig]
            out += [sympy.exp(d.expression()) for d in self._exps]
            out += list(self.parameters)
            self._atoms_sympy = out
        return self._atoms_sympy

    def _dens_sympy(self):
        if self._dens_sympy_memo is None:
            atoms = self._generator_expressions()
            self._dens_sympy_memo = [
                sympy.Add(*(sympy.Rational(int(c.p), int(c.q)) * sympy.Mul(*(a ** int(e) for a, e in zip(atoms, m) if e))
                            for m, c in zip(D.monoms(), D.coeffs()))) for D in self._dens]
        return self._dens_sympy_memo

    # -- arithmetic -------------------------------------------------------------------------
    def add(self, a: Element, b: Element) -> Element:
        if a.num.is_zero():
            return b
        if b.num.is_zero():
            return a
        if a.den == b.den:
            return Element(self, a.num + b.num, a.den)
        top = tuple(max(i, j) for i, j in zip(a.den, b.den))
        na = a.num * self._dpow(tuple(t - i for t, i in zip(top, a.den)))
        nb = b.num * self._dpow(tuple(t - j for t, j in zip(top, b.den)))
        return Element(self, na + nb, top)

    def mul(self, a: Element, b: Element) -> Element:
        if a.num.is_zero() or b.num.is_zero():
            return self.zero
        return Element(self, self._reduce(a.num * b.num), tuple(i + j for i, j in zip(a.den, b.den)))

    def diff(self, x: Element, i: int, dens: bool = True) -> Element:
        """``d x / d coordinate_i`` by the chain rule through the generators (and the quotient rule)."""
        num = x.num
        groups: dict = {}
        for g, dg in self._gen_derivs[i]:
            d = num.derivative(g)
            if d.is_zero():
                continue
            term = self._reduce(d * dg.num)
            groups[dg.den] = groups[dg.den] + term if dg.den in groups else term
        if dens:
            for j, a in enumerate(x.den):
                if not a:
                    continue
                dD = self._den_derivs.get((i, j))
                if dD is None:
                    dD = self._den_derivs[(i, j)] = self.diff(Element(self, self._dens[j], self._zero_den), i, False)
                if not dD:
                    continue
                key = tuple(e + (1 if k == j else 0) for k, e in enumerate(dD.den))
                term = self._reduce(num * dD.num) * (-a)
                groups[key] = groups[key] + term if key in groups else term
        out = self.zero
        for key, p in groups.items():
            out = out + Element(self, p, key)
        if out.num.is_zero():
            return self.zero
        return Element(self, out.num, tuple(i + j for i, j in zip(out.den, x.den)))


def extended_ring(coordinates, parameters, expressions):
    """The :class:`ExtendedRing` of ``expressions``, or ``None`` when one of their atoms is refused or python-flint
    is missing or switched off (``NAMBU_BCH_DISABLE_FLINT=1``): the callers then work in sympy expressions."""
    if not _flint.available():
        return None
    try:
        return ExtendedRing(coordinates, parameters, expressions)
    except NoExactResultError:
        return None


class ExtendedBackend:
    """The field backend (:class:`~nambu_bch.algebra.backend.FieldBackend`) on an :class:`ExtendedRing`:
    components are :class:`Element` s, scalars flint ``fmpq``; :meth:`vector_field` returns the components."""

    laurent = False

    def __init__(self, ring: ExtendedRing, fields: dict):
        self.ring = ring
        self.algebra = ring
        self.coordinates = tuple(ring._atom(x) for x in ring._x)
        self.zero, self.one = ring.zero, ring.one
        self.fields = {k: tuple(ring.convert(c) for c in comps) for k, comps in fields.items()}

    def derivative(self, f, i: int):
        return self.ring.diff(f, i)

    def apply(self, X, f):
        out = self.zero
        if not f:
            return out
        for i, c in enumerate(X):
            if c:
                d = self.ring.diff(f, i)
                if d:
                    out = out + c * d
        return out

    def bracket(self, X, Y):
        return tuple(self.apply(X, Y[i]) - self.apply(Y, X[i]) for i in range(len(X)))

    @staticmethod
    def is_zero(X) -> bool:
        return not any(X)

    @staticmethod
    def is_zero_function(f) -> bool:
        return not f

    def field(self, values):
        return tuple(values)

    @staticmethod
    def values(X):
        return X

    def vector_field(self, values):
        return tuple(values)

    def constants(self, numbers) -> list:
        return [self.ring.scalar(c) for c in numbers]

    def rational(self, q):
        return self.ring.scalar(q)

