"""Error constants, order and order conditions of compositions, from the Lyndon defects.

``error_constant(spec, parts)`` is the local error measure of a composition of
order ``p`` (Auzinger, Hofstaetter, Ketcheson, Koch, BIT 57 (2017) 55, Sect. 2;
SplittingOrderConditions.jl, notebook ``CheckMethods``):

    LEM = || ( (p+1)! [w] (Phi - exp(X_1 + ... + X_n)) )_{w Lyndon, |w| = p+1} ||_2,

with the package's operator order ``Phi = exp(c_1 X_{k_1}) ... exp(c_s X_{k_s})``
and the alphabet ``1 < 2 < ... < n``.  (SplittingOrderConditions.jl writes the
product the other way round; for palindromic compositions the two agree, and they
reproduce its table: Lie-Trotter 1.00 / 1.73, Strang 0.56 / 1.20, triple jump
3.72 / 26.04 for 2 / 3 parts.)

``order_conditions(template, order)`` are the same defects with symbolic
coefficients: polynomials in the template's unknowns (exact, over QQ) that vanish
iff the composition has order ``>= order``.

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. III.3-III.5, V.3;
module :mod:`nambu_bch.design.words`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from math import factorial

import sympy
from sympy.polys.domains import QQ
from sympy.polys.rings import ring

from ..checks import is_int, show
from ..errors import InvalidCompositionError, InvalidOrderError
from ..integrators.composition import MAX_FACTORS, Composition
from ..integrators.composition import composition as make_composition
from ..integrators.composition import three_parts
from ..integrators.composition import with_error_bound
from .defects import ErrorConstant, _check_work, _Exact
from .structure import check_structure, rkn_annihilator, structured_analysis
from .words import log_coefficients

#: Highest degree ``p + 1`` searched when the order of a composition is determined.
MAX_DEGREE = 12


def _check_parts(parts):
    if parts is not None and not is_int(parts, 1):
        raise InvalidCompositionError(f"parts must be a positive integer (the number of pieces X_1..X_n), got {parts!r}")
    return parts


def _parts(comp: Composition, parts) -> int:
    parts = comp.n_pieces if _check_parts(parts) is None else parts
    used = set(comp.pieces)
    if used != set(range(1, parts + 1)):
        raise InvalidCompositionError(
            f"composition {comp.name!r} uses pieces {sorted(used)}, but an error constant for {parts} parts "
            f"needs every piece 1..{parts} (the scheme must be consistent with exp(X_1 + ... + X_{parts}))"
        )
    return parts


def _on_three_parts(comp: Composition) -> Composition:
    """``comp`` (pieces 1 and 2) applied to three parts by :func:`~nambu_bch.integrators.composition.three_parts`;
    a method with decimal coefficients keeps a stated ``error_bound``, recomputed exactly for the new factors."""
    abc = three_parts(comp)
    if getattr(comp, "structure", ""):  # the published order needs the structure: bound the general conditions only
        abc = replace(abc, order=error_analysis(comp, 2).order)
    return with_error_bound(abc, 3) if getattr(comp, "error_bound", 0.0) else abc


def error_analysis(spec, parts: int | None = None, structure=None) -> ErrorConstant:
    """Order and error constant of ``spec`` for ``parts`` pieces, exactly (see :func:`error_constant`).

    A method of the two pieces 1 and 2 asked for ``parts=3`` is applied to three parts by CheckMethods' ABC rule
    (:func:`~nambu_bch.integrators.composition.three_parts`), as the ABC column of its table is computed.
    ``structure="rkn"`` (two pieces, 1 = kinetic ``T(p)`` quadratic in the momenta, 2 = potential ``V(q)``): order
    and constant on the RKN quotient, :func:`nambu_bch.design.structure.structured_analysis`.
    """
    if check_structure(structure):
        if parts not in (None, 2):
            raise InvalidCompositionError(f"structure {structure!r} is defined for two parts, got parts={parts!r}")
        return structured_analysis(spec, structure)
    comp = make_composition(spec, _check_parts(parts))
    if parts == 3 and set(comp.pieces) == {1, 2}:  # a two-part method on three parts: CheckMethods' ABC column
        comp = _on_three_parts(comp)
    parts = _parts(comp, parts)
    field = _Exact(comp)
    bound = float(getattr(comp, "error_bound", 0.0) or 0.0)

    def vanishes(defects):
        if bound:
            return all(abs(complex(field.K.to_sympy(v))) <= bound for v in defects.values())
        return all(v == field.K.zero for v in defects.values())

    for degree in range(2, MAX_DEGREE + 1):
        _check_work(parts, degree, len(comp.pieces), f"order of {comp.name!r}")
        defects = field.defects(parts, degree)
        if not vanishes(defects):
            exact = {w: field.K.to_sympy(v) for w, v in defects.items()}
            if comp.is_complex:  # the 2-norm of a complex vector: sum |v|^2
                squared = sympy.expand(sum(v * sympy.conjugate(v) for v in exact.values()))  # exact: no guessing
            else:
                squared = field.K.to_sympy(sum((v * v for v in defects.values()), field.K.zero))
            return ErrorConstant(comp, parts, degree - 1, squared, exact, bound)
    raise InvalidOrderError(
        f"composition {comp.name!r} has order >= {MAX_DEGREE} (or its defects vanish to degree {MAX_DEGREE}); "
        f"error constants are computed up to order {MAX_DEGREE - 1}"
    )


def error_constant(spec, parts: int | None = None, structure=None) -> float:
    """The local error measure LEM of a composition of order ``p`` (2-norm of the Lyndon defects of length ``p+1``).

    ``LEM = || (p+1)! [w](Phi - exp(X_1 + ... + X_parts)) ||_2`` over the Lyndon words ``w``
    of length ``p + 1`` (alphabet ``1 < 2 < ...``), ``Phi`` in the package's operator order;
    computed exactly (in QQ or the algebraic field of the coefficients), returned as a float.

    Parameters
    ----------
    spec : word, alias or Composition (``"12"``, ``"strang"``, ``"forest-ruth"``, ``"triple-jump:12321"``)
    parts : int, optional -- number of pieces (default: the largest piece used); every piece
        ``1..parts`` must occur, except that a method of pieces 1 and 2 is applied to ``parts=3`` by
        CheckMethods' ABC rule (:func:`~nambu_bch.integrators.composition.three_parts`)
    structure : ``None`` or ``"rkn"`` -- the constant on the RKN quotient (piece 1 = ``T(p)``, piece 2 = ``V(q)``;
        :mod:`nambu_bch.design.structure`)

    References
    ----------
    Auzinger, Hofstaetter, Ketcheson, Koch, BIT 57 (2017) 55, Sect. 2 (LEM);
    SplittingOrderConditions.jl, ``examples/CheckMethods.ipynb`` (published values).

    Examples
    --------
    >>> round(error_constant("lie-trotter", 2), 6), round(error_constant("lie-trotter", 3), 6)
    (1.0, 1.732051)
    >>> round(error_constant("strang", 2), 6), round(error_constant("12321", 3), 6)
    (0.559017, 1.198958)
    """
    return error_analysis(spec, parts, structure).value


def composition_order(spec, parts: int | None = None, structure=None) -> int:
    """The order ``p`` of a composition from its exact Lyndon defects (on the RKN quotient with ``structure="rkn"``).

    >>> composition_order("forest-ruth"), composition_order("123")
    (4, 1)
    """
    return error_analysis(spec, parts, structure).order


# ---------------------------------------------------------------------------------------------
# templates with symbolic coefficients


@dataclass(frozen=True)
class Template:
    """A composition whose coefficients are polynomials (linear forms) in free unknowns.

    Attributes
    ----------
    name : str
    parts : int
    pieces : tuple of int              -- per factor, in operator order
    coefficients : tuple of sympy Expr -- per factor, in the unknowns
    unknowns : tuple of sympy Symbol
    kind : str                         -- ``"stages"`` (composition of a symmetric base step) or ``"word"``
    base : str                         -- the base word of a ``"stages"`` template
    """

    name: str
    parts: int
    pieces: tuple
    coefficients: tuple
    unknowns: tuple
    kind: str = "word"
    base: str = ""

    def instantiate(self, values, name=None, order=1, citation="") -> Composition:
        """The :class:`Composition` with the unknowns replaced by the exact ``values`` (dict or sequence)."""
        if not isinstance(values, dict):
            values = dict(zip(self.unknowns, values))
        subs = {sympy.Symbol(str(k)) if isinstance(k, str) else k: v for k, v in values.items()}
        coeffs = tuple(sympy.expand(c.subs(subs)) for c in self.coefficients)
        return Composition(self.pieces, coeffs, name or self.name, order, citation)

    def __str__(self):
        return self.name


def _merged(factors):
    pieces, coeffs = [], []
    for k, c in factors:
        if pieces and pieces[-1] == k:
            coeffs[-1] = sympy.expand(coeffs[-1] + c)
        else:
            pieces.append(k)
            coeffs.append(c)
    return tuple(pieces), tuple(coeffs)


def template(spec, parts: int | None = None, stages: int | None = None) -> Template:
    """A :class:`Template` for order conditions and design.

    Parameters
    ----------
    spec : str or Template
        * ``"strang"`` or a palindromic digit word such as ``"12321"``: the palindromic
          composition of ``stages`` steps of that symmetric base scheme with steps
          ``gamma_1 h, gamma_2 h, ..., gamma_2 h, gamma_1 h`` (adjacent equal sub-flows merged);
        * ``"word:1213121"``: that word with one free coefficient per factor, ``a1, a2, ...``,
          tied palindromically (``a_j = a_{s+1-j}``) when the word is a palindrome;
          ``"word-general:WORD"``: no tying.
    parts : int -- number of pieces (needed by ``"strang"``)
    stages : int -- number of steps of the base scheme (``"strang"`` / base words)

    Examples
    --------
    >>> T = template("strang", parts=2, stages=3)
    >>> T.pieces, T.coefficients
    ((1, 2, 1, 2, 1, 2, 1), (gamma1/2, gamma1, gamma1/2 + gamma2/2, gamma2, gamma1/2 + gamma2/2, gamma1, gamma1/2))
    """
    if isinstance(spec, Template):
        return spec
    if not isinstance(spec, str) or not spec.strip():
        raise InvalidCompositionError(f"a template is 'strang', a palindromic word such as '12321', or 'word:WORD'; got {spec!r}")
    text = spec.strip().lower()
    if text.startswith(("word:", "word-general:")):
        kind, word = text.split(":", 1)
        if not word.isdigit() or "0" in word or len(word) < 2:
            raise InvalidCompositionError(f"template {spec!r}: the word must consist of piece digits 1-9, e.g. 'word:1213121'")
        pieces = tuple(int(ch) for ch in word)
        tie = kind == "word" and pieces == pieces[::-1]
        s = len(pieces)
        n_free = (s + 1) // 2 if tie else s
        unknowns = tuple(sympy.Symbol(f"a{j}") for j in range(1, n_free + 1))
        coeffs = tuple(unknowns[min(j, s - 1 - j)] if tie else unknowns[j] for j in range(s))
        n = max(pieces)
        if set(pieces) != set(range(1, n + 1)):
            raise InvalidCompositionError(f"template {spec!r} must use every piece 1..{n}")
        return Template(f"{kind}:{word}", n, pieces, coeffs, unknowns, "word")
    if not is_int(stages, 1, MAX_FACTORS):  # the composition it builds has at least `stages` factors
        raise InvalidCompositionError(f"template {spec!r} needs stages = an integer in 1..{MAX_FACTORS} (number of base "
                                      f"steps), got {show(stages)}")
    if text == "strang":
        if not is_int(parts, 2):
            raise InvalidCompositionError(f"template 'strang' needs parts >= 2 (the number of pieces), got {parts!r}")
        word = "".join(str(k) for k in range(1, parts + 1))
        word = word + word[-2::-1]
    else:
        word = text
    if not (word.isdigit() and "0" not in word and len(word) % 2 == 1 and word == word[::-1] and len(word) > 1):
        raise InvalidCompositionError(
            f"template {spec!r}: use 'strang', a palindromic digit word of odd length such as '12321', or 'word:WORD'"
        )
    base = make_composition(word)
    n_free = (stages + 1) // 2
    gammas = tuple(sympy.Symbol(f"gamma{j}") for j in range(1, n_free + 1))
    factors = []
    for i in range(stages):
        g = gammas[min(i, stages - 1 - i)]
        factors.extend((k, c * g) for k, c in base.factors())
    pieces, coeffs = _merged(factors)
    n = max(base.pieces)
    if parts is not None and parts != n:
        raise InvalidCompositionError(f"template {spec!r} has {n} pieces, but parts={parts} was given")
    return Template(f"{word}x{stages}", n, pieces, coeffs, gammas, "stages", word)


@dataclass(frozen=True)
class OrderConditions:
    """Polynomial order conditions of a template: ``expr == 0`` for each ``(Lyndon word, expr)``.

    Attributes
    ----------
    template : Template
    order : int
    equations : tuple of (word, sympy Expr) -- the non-vanishing defects of lengths ``1..order``
    unknowns : tuple of sympy Symbol
    """

    template: Template
    order: int
    equations: tuple
    unknowns: tuple

    @property
    def polynomials(self) -> list:
        """The distinct conditions, each as a primitive integer polynomial (proportional ones listed once)."""
        seen, out = set(), []
        for _, e in self.equations:
            poly = sympy.Poly(e, *self.unknowns).primitive()[1]
            if poly.LC() < 0:
                poly = -poly
            key = poly.as_expr()
            if key not in seen:
                seen.add(key)
                out.append(key)
        return out

    def __len__(self):
        return len(self.equations)

    def to_latex(self) -> str:
        """The distinct conditions (:attr:`polynomials`), one per line."""
        rows = [rf"{sympy.latex(e)} &= 0" for e in self.polynomials]
        return r"\begin{aligned}" + r" \\ ".join(rows) + r"\end{aligned}"

    def _repr_latex_(self):
        return f"${self.to_latex()}$"

    def __reduce__(self):
        """Pickle the equations expanded: sympy's own pickle re-evaluates ``factor_terms``' ``-(2 a + b)/4``
        into ``-a/2 - b/4``, so the copy would print differently."""
        expanded = tuple((w, sympy.expand(e)) for w, e in self.equations)
        return _order_conditions_from, (self.template, self.order, expanded, self.unknowns)


def _order_conditions_from(template, order, expanded, unknowns) -> OrderConditions:
    """The conditions :meth:`OrderConditions.__reduce__` described, in :func:`order_conditions`' form."""
    return OrderConditions(template, order, tuple((w, sympy.factor_terms(e)) for w, e in expanded), unknowns)


def symbolic_defects(T: Template, degree: int) -> dict:
    """``{Lyndon word w: q! [w](log Phi - sum X)}`` of length ``q = degree``, exact polynomials in the unknowns.

    Homogeneous of degree ``q`` for ``q >= 2``; at the first non-vanishing degree these are the
    Lyndon defects of ``Phi - exp(sum X)`` whose 2-norm is the error constant.
    """
    return {w: p.as_expr() for w, p in defect_polynomials(T, degree).items()}


def defect_polynomials(T: Template, degree: int) -> dict:
    """:func:`symbolic_defects` as sparse polynomials of ``QQ[unknowns]`` (sympy ``PolyElement``, generators in
    the order of ``T.unknowns``), for callers that go on computing with them."""
    _check_work(T.parts, degree, len(T.pieces) * degree, f"template {T.name!r}")
    R, *_ = ring([str(u) for u in T.unknowns], QQ)
    factors = [(k, R.from_expr(c) if c.free_symbols else R(c)) for k, c in zip(T.pieces, T.coefficients)]
    d = log_coefficients(factors, T.parts, degree, R.one, R.zero, lambda a, b: R(sympy.Rational(a, b)))
    scale = 1 if degree == 1 else factorial(degree)
    return {w: p * scale for w, p in d.items()}


def order_conditions(spec, order: int, parts: int | None = None, stages: int | None = None,
                     structure=None) -> OrderConditions:
    """The polynomial conditions on the free coefficients of a template for order ``>= order``.

    ``sum_j c_j - 1 = 0`` per piece (consistency) and the coefficients ``q! [w] log Phi`` of the
    Lyndon words ``w`` of lengths ``q = 2..order`` (:func:`nambu_bch.design.words.log_coefficients`),
    with symbolic coefficients, computed exactly in ``QQ[unknowns]``: homogeneous polynomials
    of degree ``q``.  Identically vanishing ones (e.g. even lengths of symmetric templates)
    are dropped.

    ``structure="rkn"`` (two pieces, 1 = kinetic ``T(p)`` quadratic in the momenta, 2 = potential ``V(q)``): at
    degrees ``q >= 4`` the conditions are ``a . v(E_q) = 0`` for a basis ``a`` of the annihilator of the RKN ideal
    (:func:`nambu_bch.design.structure.rkn_annihilator`, each labelled by a Lyndon word): ``E_q`` may lie in the ideal
    that vanishes for RKN problems, so fewer conditions (2, 1, 2, 2, 4, 5, ... instead of 2, 1, 2, 3, 6, 9, ...).

    Examples
    --------
    Symmetric compositions of a symmetric step: order 4 needs ``sum gamma = 1`` and
    ``sum gamma^3 = 0`` (Hairer, Lubich, Wanner, Sect. V.3.2):

    >>> C = order_conditions("strang", 4, parts=2, stages=3)
    >>> C.polynomials
    [2*gamma1 + gamma2 - 1, 2*gamma1**3 + gamma2**3]
    """
    T = template(spec, parts, stages)
    if not is_int(order, 1):
        raise InvalidOrderError(f"order must be a positive integer, got {order!r}")
    if order >= MAX_DEGREE:
        raise InvalidOrderError(f"order conditions are generated up to order {MAX_DEGREE - 1}, got {order}")
    structure = check_structure(structure)
    if structure and T.parts != 2:
        raise InvalidCompositionError(f"structure {structure!r} is defined for two pieces, template {T.name!r} has {T.parts}")
    eqs = []
    for q in range(1, order + 1):
        if structure and q >= 4:
            polys = defect_polynomials(T, q)
            words = sorted(polys)
            defects = {}
            zero = polys[words[0]].ring.zero
            for label, row in rkn_annihilator(q):
                defects[label] = sum((polys[w] * a for w, a in zip(words, row) if a), zero).as_expr()
        else:
            defects = symbolic_defects(T, q)
        for w, e in defects.items():
            e = sympy.factor_terms(sympy.expand(e))
            if e != 0:
                eqs.append((w, e))
    return OrderConditions(T, order, tuple(eqs), T.unknowns)
