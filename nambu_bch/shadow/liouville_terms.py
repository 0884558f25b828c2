"""Unevaluated Liouville terms ``c X_{P_1, ..., P_{N-1}}`` and their formal sums.

Two levels:

* :class:`LiouvilleTerm` -- one term ``c X_{P,Q}`` with arbitrary functions in
  the ``N - 1`` slots (polynomials or any sympy expressions, e.g. generic
  ``Function`` s), kept unevaluated: antisymmetry (:meth:`canonical` orders the
  slots, with the sign of the permutation), the vanishing rule
  (:meth:`vanishes`: ``X_{P,Q} = 0`` iff ``grad P x grad Q = 0``, i.e. iff all
  ``(N-1)``-minors of the gradients vanish), evaluation on demand
  (:meth:`field`).
* :class:`LiouvilleSum` -- a formal sum of terms with *monomial* slots, i.e.
  the quotient of the span of symbols ``X_{m_1..m_{N-1}}`` by multilinearity
  (slots are expanded into monomials), antisymmetry and the vanishing rule.
  For monomials ``m_j = x^{a_j}`` one has ``grad m_j = m_j (a_j / x)``, so the
  gradients are dependent exactly when the exponent vectors ``a_j`` are
  linearly dependent: the vanishing rule is a rank test on integer vectors
  (``X_{A, -2 x_2^2/m^2} = 0`` in Eq. BCH5 because ``A ~ x_2^2``).  This is the
  bookkeeping of the paper's FI calculation (Eqs. CL5-CL8, BCH5): two formal
  sums are equal when they are equal *as the paper manipulates them*; equal
  formal sums give equal fields, not necessarily conversely.

References
----------
Horikoshi, Eqs. (gLiouville), (L2), (BCH5) (the rule ``X_{A,-2x_2^2/m^2} = 0``).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import sympy
from sympy.core.sorting import default_sort_key
from sympy.polys.domains import QQ
from sympy.polys.polyerrors import CoercionFailed
from sympy.polys.rings import PolyElement

from ..algebra import PolynomialAlgebra, VectorField, liouville_field
from ..algebra.brackets import permutation_sign
from ..algebra.elimination import SparseMatrix, rank
from ..checks import check_sequence, check_type, is_int, show
from ..errors import NambuBCHError
from ..parsing import as_expression


@dataclass(frozen=True)
class LiouvilleTerm:
    """``coefficient * X_{slots}`` kept unevaluated.

    Examples
    --------
    >>> import sympy
    >>> x1, x2, x3, m = sympy.symbols("x1 x2 x3 m")
    >>> t = LiouvilleTerm((x3, x2**2), 2)
    >>> t.canonical()
    LiouvilleTerm(slots=(x2**2, x3), coefficient=-2)
    >>> LiouvilleTerm((x2**2/(2*m), -2*x2**2/m**2)).vanishes((x1, x2, x3))   # Eq. BCH5
    True
    """

    slots: tuple
    coefficient: object = sympy.Integer(1)

    def __post_init__(self):
        # ring elements (exact sparse polynomials) are kept as they are: nested brackets stay fast
        object.__setattr__(self, "slots", tuple(s if isinstance(s, PolyElement) else as_expression(s, None, "a slot of a LiouvilleTerm")
                                                for s in check_sequence(self.slots, "slots", "expressions")))
        object.__setattr__(self, "coefficient", as_expression(self.coefficient, None, "the coefficient of a LiouvilleTerm"))

    @property
    def expressions(self) -> tuple:
        """The slots as sympy expressions."""
        return tuple(s.as_expr() if isinstance(s, PolyElement) else s for s in self.slots)

    def __neg__(self):
        return LiouvilleTerm(self.slots, -self.coefficient)

    def scale(self, c) -> "LiouvilleTerm":
        return LiouvilleTerm(self.slots, self.coefficient * as_expression(c, None, "a LiouvilleTerm's scale"))

    def canonical(self) -> "LiouvilleTerm":
        """Slots in sympy's canonical order, the coefficient times the permutation's sign (antisymmetry)."""
        exprs = self.expressions
        order = sorted(range(len(exprs)), key=lambda i: default_sort_key(exprs[i]))
        return LiouvilleTerm(tuple(exprs[i] for i in order), permutation_sign(order) * self.coefficient)

    def vanishes(self, coordinates) -> bool:
        """``X_{slots} = 0``: every ``(N-1)``-minor of the slots' gradients is zero (exact, sympy)."""
        if self.coefficient == 0:
            return True
        J = sympy.Matrix([[sympy.diff(P, x) for x in coordinates] for P in self.expressions])
        n = len(coordinates)
        for skip in range(n):
            cols = [j for j in range(n) if j != skip]
            if sympy.expand(J[:, cols].det(method="berkowitz")) != 0:
                return False
        return True

    def field(self, algebra) -> VectorField:
        """The concrete field ``coefficient * X_{slots}`` (Eq. gLiouville)."""
        return liouville_field(algebra, *self.slots).scale(self.coefficient)

    def expand(self, algebra) -> "LiouvilleSum":
        """The formal monomial sum (polynomial slots only)."""
        return LiouvilleSum.from_slots(algebra, self.slots, self.coefficient)

    def to_latex(self) -> str:
        body = "X_{" + ", ".join(sympy.latex(sympy.factor(s)) for s in self.expressions) + "}"
        c = self.coefficient
        return body if c == 1 else (f"-{body}" if c == -1 else rf"\left({sympy.latex(c)}\right){body}")

    def __str__(self):
        body = "X_{" + ", ".join(str(sympy.factor(s)) for s in self.expressions) + "}"
        return body if self.coefficient == 1 else f"({self.coefficient})*{body}"


@lru_cache(maxsize=None)
def _dependent(exponents: tuple) -> bool:
    """Are the integer vectors linearly dependent (exact rank over QQ)?"""
    if not exponents:
        return False
    rows = [{c: QQ(v) for c, v in enumerate(e) if v} for e in exponents]
    return rank(SparseMatrix.from_rows(rows, len(exponents[0]), QQ)) < len(rows)


@lru_cache(maxsize=None)
def canonical_key(monomials: tuple):
    """``(sign, key)`` of ``X_{x^{a_1}, ..., x^{a_{N-1}}}``: sorted exponents and the sign; ``(0, None)`` if it vanishes."""
    if len(set(monomials)) < len(monomials) or _dependent(monomials):
        return 0, None
    order = sorted(range(len(monomials)), key=lambda i: monomials[i])
    return permutation_sign(order), tuple(monomials[i] for i in order)


class _Context:
    """Canonical keys (sorted entries, sign) and the vanishing rule for one algebra and atom list."""

    def __init__(self, algebra, atoms):
        self.algebra, self.atoms = algebra, atoms
        self.cache: dict = {}

    def key(self, entries):
        if entries in self.cache:
            return self.cache[entries]
        if len(set(entries)) < len(entries):
            out = (0, None)
        elif all(kind == 0 for kind, _ in entries):
            sign, key = canonical_key(tuple(v for _, v in entries))
            out = (sign, None if key is None else tuple((0, v) for v in key))
        else:
            slots = [_ATOMS[v] if kind == 1 else sympy.Mul(*(x**e for x, e in zip(self.algebra.coordinates, v)))
                     for kind, v in entries]
            if liouville_field(self.algebra, *slots).is_zero():
                out = (0, None)
            else:
                order = sorted(range(len(entries)), key=lambda i: entries[i])
                out = (permutation_sign(order), tuple(entries[i] for i in order))
        self.cache[entries] = out
        return out


_CONTEXTS: dict = {}
_ATOMS: list = []  # atom expressions by id: keys of formal sums name atoms by content, not by position
_ATOM_IDS: dict = {}


def _atom_id(expr) -> int:
    if expr not in _ATOM_IDS:
        _ATOM_IDS[expr] = len(_ATOMS)
        _ATOMS.append(expr)
    return _ATOM_IDS[expr]


def _context(algebra, atoms) -> _Context:
    # keyed by content (the ring and coordinates fix the vanishing rule), not by id(): an id is
    # reused after the algebra is freed, and a dict keyed by ids only grows
    key = (algebra.ring, algebra.coordinates, atoms)
    if key not in _CONTEXTS:
        if len(_CONTEXTS) > 256:
            _CONTEXTS.clear()
        _CONTEXTS[key] = _Context(algebra, atoms)
    return _CONTEXTS[key]


def clear_cache() -> None:
    """Forget the canonical-key contexts and the key caches (atom ids are kept: live sums use them)."""
    _CONTEXTS.clear()
    canonical_key.cache_clear()
    _dependent.cache_clear()


def _to_domain(algebra, c):
    """A number / sympy constant / domain element as an element of the algebra's coefficient domain."""
    if isinstance(c, (int, sympy.Basic, Fraction)):
        return algebra.domain.from_sympy(sympy.sympify(c, strict=True))
    return algebra.domain.convert(c)


def _checked_key(algebra, key) -> tuple:
    """A user's term key of a :class:`LiouvilleSum`: a tuple of slot entries ``(0, exponents)`` or ``(1, atom id)``."""
    def entry_ok(entry):
        if not (isinstance(entry, tuple) and len(entry) == 2):
            return False
        kind, value = entry
        if kind == 0 and not isinstance(kind, bool):
            return isinstance(value, tuple) and len(value) == algebra.n and all(is_int(e, 0) for e in value)
        return kind == 1 and not isinstance(kind, bool) and is_int(value, 0, len(_ATOMS) - 1)

    if not (isinstance(key, tuple) and key and all(entry_ok(e) for e in key)):
        raise NambuBCHError(f"a key of LiouvilleSum terms must be a tuple of slot entries (0, exponents of the "
                            f"{algebra.n} coordinates) or (1, atom id), got {show(key)}")
    return key


def _checked_coefficient(algebra, value):
    """A user's coefficient of a :class:`LiouvilleSum` term as an element of the algebra's coefficient domain."""
    if algebra.domain.of_type(value):
        return value
    c = as_expression(value, None, "a coefficient of LiouvilleSum terms")
    try:
        return _to_domain(algebra, c)
    except (CoercionFailed, TypeError, ValueError):
        raise NambuBCHError(f"a coefficient of LiouvilleSum terms must be a number of the algebra's coefficient "
                            f"field (rational in {', '.join(map(str, algebra.parameters)) or 'no parameters'}), "
                            f"got {show(value)}") from None


class LiouvilleSum:
    """A formal sum ``sum_k c_k X_{e_k1, ..., e_k(N-1)}`` modulo multilinearity, antisymmetry, vanishing.

    Each slot entry ``e`` is a basis element: a coordinate monomial ``x^a``
    (key ``(0, a)``) or, optionally, an *atom* -- a function kept whole (key ``(1, id)``, by content),
    such as a separable piece ``A = x_2^2/(2m)`` of ``H`` (key ``(1, k)``).
    Atoms keep the bookkeeping of the paper's FI calculation: ``X_{B, x_2^2}``
    (a piece of ``H`` in the first slot, so it belongs to ``X_{H, dG}``) and
    ``X_{x_2^2, C}`` (a piece of ``G`` in the second slot) are different formal
    terms even though ``B`` and ``C`` are both multiples of ``x_3``.  Without
    atoms every slot is expanded into monomials.  Keys are sorted tuples of
    entries; coefficients live in the algebra's coefficient domain.

    Examples
    --------
    >>> import sympy
    >>> from nambu_bch import model
    >>> x2, m, omega = sympy.symbols("x2 m omega")
    >>> S = model("ho3"); alg = S.algebra
    >>> (A, C), (B, D) = S.splitting[1].terms[0], S.splitting[2].terms[0]   # Eqs. (hX1), (hX2)
    >>> LiouvilleSum.from_slots(alg, (A, -2*A)).is_zero()        # antisymmetric part / vanishing
    True
    >>> lhs = LiouvilleSum.from_slots(alg, (B + A, C + D))          # X_{H,G}
    >>> lhs == sum((LiouvilleSum.from_slots(alg, t) for p in S.splitting.pieces for t in p.terms), LiouvilleSum.zero(alg))
    True
    >>> atoms = (A, B, C, D)
    >>> LiouvilleSum.from_slots(alg, (B, x2**2), atoms=atoms) == LiouvilleSum.from_slots(alg, (-m*omega**2*x2**2/2, C), atoms=atoms)
    False
    >>> LiouvilleSum.from_slots(alg, (B, x2**2)) == LiouvilleSum.from_slots(alg, (-m*omega**2*x2**2/2, C))
    True
    """

    __slots__ = ("algebra", "terms", "atoms")

    def __init__(self, algebra, terms=None, atoms=()):
        check_type(algebra, PolynomialAlgebra, "algebra")
        atoms = tuple(as_expression(a, algebra.symbol_table, "an atom of a LiouvilleSum")
                      for a in check_sequence(atoms, "atoms", "expressions"))
        if terms is not None:
            terms = {_checked_key(algebra, k): _checked_coefficient(algebra, v)
                     for k, v in check_type(terms, dict, "terms").items()}
        self._set(algebra, terms, atoms)

    def _set(self, algebra, terms, atoms):
        self.algebra = algebra
        self.atoms = atoms
        self.terms = {k: v for k, v in (terms or {}).items() if v}

    @classmethod
    def _trusted(cls, algebra, terms, atoms) -> "LiouvilleSum":
        """A sum built by this module from checked parts (canonical keys, domain coefficients): not checked again."""
        self = cls.__new__(cls)
        self._set(algebra, terms, atoms)
        return self

    @classmethod
    def zero(cls, algebra, atoms=()) -> "LiouvilleSum":
        return cls(algebra, None, atoms)

    @classmethod
    def from_slots(cls, algebra, slots, coefficient=1, atoms=()) -> "LiouvilleSum":
        """Expand ``coefficient * X_{slots}`` multilinearly into canonical terms (slots equal to an atom stay whole)."""
        n = algebra.n
        atoms = tuple(as_expression(a, algebra.symbol_table, "an atom of a LiouvilleSum") for a in atoms)
        polys = []
        for s in slots:
            s_expr = algebra.to_sympy(s) if algebra.is_polynomial(s) else as_expression(s, algebra.symbol_table, "a slot")
            if atoms and s_expr in atoms:
                polys.append([((1, _atom_id(s_expr)), algebra.domain.one)])
                continue
            p = algebra.convert(s)
            if not algebra.is_polynomial(p):
                raise NambuBCHError(f"formal Liouville sums need polynomial slots, got {s}")
            items = []
            for mon, c in p.items():
                if any(mon[n:]):
                    raise NambuBCHError(f"formal Liouville sums need slots free of {algebra.constants}, got {s}")
                items.append(((0, mon[:n]), c))
            polys.append(items)
        coeff = _to_domain(algebra, coefficient)
        terms: dict = {}
        context = _context(algebra, atoms)
        cls._expand(polys, 0, (), coeff, terms, context)
        return cls._trusted(algebra, terms, atoms)

    @staticmethod
    def _expand(polys, i, entries, coeff, out, context):
        if i == len(polys):
            sign, key = context.key(entries)
            if sign:
                out[key] = out.get(key, 0) + sign * coeff
            return
        for entry, c in polys[i]:
            LiouvilleSum._expand(polys, i + 1, entries + (entry,), coeff * c, out, context)

    # -- linear structure ---------------------------------------------------------
    def __add__(self, other):
        out = dict(self.terms)
        for k, v in other.terms.items():
            out[k] = out.get(k, 0) + v
        return LiouvilleSum._trusted(self.algebra, out, self.atoms or other.atoms)

    __radd__ = lambda self, other: self if other == 0 else self.__add__(other)  # noqa: E731  (sum())

    def __neg__(self):
        return LiouvilleSum._trusted(self.algebra, {k: -v for k, v in self.terms.items()}, self.atoms)

    def __sub__(self, other):
        return self + (-other)

    def scale(self, c) -> "LiouvilleSum":
        c = _to_domain(self.algebra, c)
        return LiouvilleSum._trusted(self.algebra, {k: c * v for k, v in self.terms.items()}, self.atoms)

    def is_zero(self) -> bool:
        return not self.terms

    def __eq__(self, other):
        if not isinstance(other, LiouvilleSum):
            return NotImplemented
        return (self - other).is_zero()

    def __hash__(self):
        return hash(frozenset(self.terms))

    def __reduce__(self):
        """Pickle with the atoms of the keys by content: atom ids are this process's."""
        keys = tuple(tuple((kind, _ATOMS[v] if kind == 1 else v) for kind, v in key) for key in self.terms)
        return _liouville_sum_from, (self.algebra, keys, tuple(self.terms.values()), self.atoms)

    # -- evaluation and output --------------------------------------------------------
    def monomial(self, entry) -> sympy.Expr:
        """The function of a slot entry: ``x^a`` for ``(0, a)``, the atom for ``(1, k)``."""
        kind, value = entry
        if kind == 1:
            return _ATOMS[value]
        return sympy.Mul(*(x**e for x, e in zip(self.algebra.coordinates, value)))

    def field(self) -> VectorField:
        """Evaluate: the concrete vector field ``sum_k c_k X_{...}``."""
        A = self.algebra
        total = VectorField.zero(A)
        for key, c in self.terms.items():
            total = total + liouville_field(A, *(self.monomial(e) for e in key)).scale(A.domain.to_sympy(c))
        return total

    def items(self):
        """``[(sympy coefficient, (sympy monomials...)), ...]`` in canonical order."""
        to = self.algebra.domain.to_sympy
        return [(to(self.terms[k]), tuple(self.monomial(e) for e in k)) for k in sorted(self.terms)]

    def to_latex(self) -> str:
        parts = []
        for c, mons in self.items():
            body = "X_{" + ", ".join(sympy.latex(mo) for mo in mons) + "}"
            parts.append(rf"\left({sympy.latex(c)}\right){body}")
        return " + ".join(parts) if parts else "0"

    def __repr__(self):
        return "LiouvilleSum(" + " + ".join(f"({c})*X_{{{', '.join(map(str, mons))}}}" for c, mons in self.items()) + ")"


def _liouville_sum_from(algebra, keys, coefficients, atoms) -> LiouvilleSum:
    """The sum described by :meth:`LiouvilleSum.__reduce__`, its keys canonical again under this process's atom ids."""
    context = _context(algebra, atoms)
    terms: dict = {}
    for key, c in zip(keys, coefficients):
        sign, canonical = context.key(tuple((kind, _atom_id(v) if kind == 1 else v) for kind, v in key))
        terms[canonical] = terms.get(canonical, algebra.domain.zero) + (c if sign > 0 else -c)
    return LiouvilleSum._trusted(algebra, terms, atoms)
