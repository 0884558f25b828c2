"""Force-gradient pieces and processed methods of two-part splittings: order and error constants, exactly.

Word series.  Every factor is the exponential of a Lie polynomial in the pieces ``X_1`` (``A``, the kinetic part or
the drift) and ``X_2`` (``B``, the potential or the kick), weighted by ``h`` per letter; products, ``exp`` and ``log``
are computed as truncated series over the words in the letters 1, 2 with coefficients in the exact field of the
data (:mod:`nambu_bch.design.words` does the same for single-letter factors by a faster dynamic programme).  The
error terms ``E_q`` of ``log Phi`` are read off on the Lyndon words (their coordinates ``v``), and a quotient by the
RKN relations (:mod:`nambu_bch.design.structure`) is applied as there.

Force-gradient factors.  A factor ``(2, b, c)`` is ``exp(b h X_2 + c h^3 [X_2, [X_1, X_2]])``.  In the package's
operator convention (``X_H f = {f, H}``, so ``[X_F, X_G] = -X_{{F,G}}``) the double bracket is, for ``H = T(p) +
V(q)`` with ``T = |p|^2/2``, the Lie operator of ``{V, {T, V}} = -|grad V|^2`` (the sign enters twice), so the factor
is the exact flow for time ``b h`` of the modified potential ``V - (c/b) h^2 |grad V|^2``: a kick with the force of
that potential.  Chin's 4A, ``B(1/6) A(1/2) B~(2/3) A(1/2) B(1/6)`` with ``B~ = B + (h^2/48) [B, [A, B]]`` in his
operator form, has ``c = (2/3)(1/48) = 1/72``: the classical modified potential ``V - (h^2/48) |grad V|^2``
(``tests/test_design_generalized.py`` checks the sign on the harmonic oscillator numerically; the ``+`` sign of
the imaginary-time propagator ``exp(-eps (T + V))`` is the other convention).

Processed methods.  A kernel ``K`` and a processor ``P`` give ``P K P^(-1)`` (``n`` steps cost ``n`` kernels and
one processor pair); the processor changes ``log K`` by ``exp(ad_Z)``, ``Z = log P``.  The kernel has *effective
order* ``p`` if some ``Z`` makes ``exp(ad_Z) log K = h(X_1 + X_2) + O(h^(p+1))``.  Degree by degree: the degree-``q``
term ``E_q`` of the current series can be removed iff ``v(E_q)`` lies in ``v([L_(q-1), X])``, ``X = X_1 + X_2``
(then ``Z_(q-1)`` with ``[Z_(q-1), X] = -E_q`` is applied to the whole series); the first degree where it cannot
fixes ``p``, and the effective error constant is the 2-norm of ``(p+1)! v(E_(p+1))`` minus its orthogonal
projection on ``v([L_p, X])`` -- the part no processor removes.  The kernel's conditions at degree ``q >= 3`` are
``dim L_q - dim L_(q-1)`` (``ad_X`` is injective on ``L_(q-1)`` there): 1, 1, 3, 3, 9 for ``q = 3..7``, and none at
``q = 2``.

References
----------
Chin, *Symplectic integrators from composite operator factorizations*, Phys. Lett. A 226 (1997) 344 (4A);
Takahashi & Imada, J. Phys. Soc. Jpn. 53 (1984) 3765 (the processed kernel with ``V + (h^2/24) |grad V|^2``);
Blanes, Casas & Ros, *Symplectic integration with processing: a general study*, SIAM J. Sci. Comput. 21 (1999) 711;
Blanes, Casas & Murua, Acta Numerica 33 (2024), Sects. 3-4.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import factorial

import sympy
from sympy.polys.domains import QQ

from ..algebra.fields import number_field
from ..checks import is_int, show
from ..errors import InvalidCompositionError, InvalidOrderError
from .structure import _residual, _squared_norm, check_structure
from .words import lyndon_defect_words

#: Highest degree (word length) of the series computed here: 2^9 words at the top degree.
MAX_SERIES_DEGREE = 9
#: Most factors of a force-gradient composition or kernel.
MAX_GENERALIZED_FACTORS = 60


@dataclass(frozen=True)
class GradientComposition:
    """A two-part composition whose factors may carry a force-gradient term.

    ``factors`` is a tuple of ``(piece, b, c)``: the factor ``exp(b h X_piece + c h^3 [X_2, [X_1, X_2]])``, ``c = 0``
    for a plain sub-flow (``c`` only on piece 2).  Coefficients are exact sympy numbers; ``error_bound`` is the
    stated accuracy of a composition built from published decimals (residuals below it count as zero).
    """

    factors: tuple
    name: str = ""
    order: int = 0
    citation: str = ""
    error_bound: float = 0.0

    @property
    def is_complex(self) -> bool:
        return any(not sympy.sympify(x, strict=True).is_real for _, b, c in self.factors for x in (b, c))

    def __str__(self):
        return self.name or ",".join(f"{k}:{b}" + (f"+{c}C" if c else "") for k, b, c in self.factors)


def gradient_composition(factors, name: str = "", order: int = 0, citation: str = "") -> GradientComposition:
    """A :class:`GradientComposition` from ``[(piece, b), (piece, b, c), ...]`` (exact numbers or their text).

    Each piece's ``b`` must sum to one; ``c`` (the coefficient of ``h^3 [X_2, [X_1, X_2]]``) is allowed on piece 2.
    """
    from ..integrators.composition import _exact, sums_not_one

    if not isinstance(factors, (list, tuple)) or not 1 <= len(factors) <= MAX_GENERALIZED_FACTORS:
        raise InvalidCompositionError(
            f"a force-gradient composition is a list of 1..{MAX_GENERALIZED_FACTORS} factors (piece, b[, c]), got {show(factors)}")
    out = []
    for item in factors:
        if not isinstance(item, (list, tuple)) or len(item) not in (2, 3) or item[0] not in (1, 2) or isinstance(item[0], bool):
            raise InvalidCompositionError(
                f"a factor is (piece, b) or (2, b, c) with piece 1 or 2, got {show(item)} in {show(factors)}")
        b = _exact(item[1], name or "force-gradient composition")
        c = _exact(item[2], name or "force-gradient composition") if len(item) == 3 else sympy.Integer(0)
        if c != 0 and item[0] != 2:
            raise InvalidCompositionError(f"the force-gradient term [X_2,[X_1,X_2]] goes with piece 2, got {show(item)}")
        out.append((item[0], b, c))
    pieces = {p for p, _, _ in out}
    bad = sums_not_one([(p, b) for p, b, _ in out] + [(k, sympy.Integer(0)) for k in (1, 2) if k not in pieces])
    if bad:
        k, total = min(bad.items(), key=lambda item: item[0])
        raise InvalidCompositionError(f"the coefficients b of piece {k} in {show(factors)} sum to {total}, not 1")
    return GradientComposition(tuple(out), name, order, citation)


# ---------------------------------------------------------------------------------------------
# truncated word series


class _Series:
    """Word series over the letters 1, 2 truncated above ``degree``, coefficients in the field ``K``."""

    def __init__(self, K, degree):
        self.K, self.D = K, degree

    def mul(self, x: dict, y: dict) -> dict:
        out: dict = {}
        zero = self.K.zero
        for u, a in x.items():
            room = self.D - len(u)
            for v, b in y.items():
                if len(v) <= room:
                    w = u + v
                    out[w] = out.get(w, zero) + a * b
        return {w: c for w, c in out.items() if c != zero}

    def exp(self, y: dict) -> dict:
        """``exp(y)`` for ``y`` without constant term."""
        out, power = {(): self.K.one}, {(): self.K.one}
        for k in range(1, self.D + 1):
            power = self.mul(power, y)
            if not power:
                break
            scale = self.K.convert(sympy.Rational(1, k))
            power = {w: c * scale for w, c in power.items()}
            for w, c in power.items():
                out[w] = out.get(w, self.K.zero) + c
        return out

    def log(self, s: dict) -> dict:
        """``log(s)`` for ``s = 1 + (terms of degree >= 1)``."""
        q = {w: c for w, c in s.items() if w}
        out: dict = {}
        power = {(): self.K.one}
        for k in range(1, self.D + 1):
            power = self.mul(power, q)
            if not power:
                break
            scale = self.K.convert(sympy.Rational((-1) ** (k + 1), k))
            for w, c in power.items():
                out[w] = out.get(w, self.K.zero) + c * scale
        return {w: c for w, c in out.items() if c != self.K.zero}

    def bracket(self, x: dict, y: dict) -> dict:
        xy, yx = self.mul(x, y), self.mul(y, x)
        out = dict(xy)
        for w, c in yx.items():
            out[w] = out.get(w, self.K.zero) - c
        return {w: c for w, c in out.items() if c != self.K.zero}

    def exp_ad(self, z: dict, y: dict) -> dict:
        """``exp(ad_z) y = y + [z, y] + [z, [z, y]]/2 + ...``."""
        out, term = dict(y), dict(y)
        for k in range(1, self.D + 1):
            term = self.bracket(z, term)
            if not term:
                break
            scale = self.K.convert(sympy.Rational(1, k))
            term = {w: c * scale for w, c in term.items()}
            for w, c in term.items():
                out[w] = out.get(w, self.K.zero) + c
        return {w: c for w, c in out.items() if c != self.K.zero}


def _field(numbers):
    K, elems = number_field(numbers)
    if K.is_ZZ:
        K, elems = QQ, [QQ.convert(e) for e in elems]
    return K, elems


def _gradient_term(K, c):
    """``c [2, [1, 2]]`` expanded: ``c (2*212 - 221 - 122)``."""
    return {(2, 1, 2): 2 * c, (2, 2, 1): -c, (1, 2, 2): -c}


def _log_of(comp: GradientComposition, degree: int):
    """``(K, series, log Phi)`` truncated at ``degree``."""
    K, elems = _field([x for _, b, c in comp.factors for x in (b, c)])
    S = _Series(K, degree)
    product = {(): K.one}
    for i, (k, _, _) in enumerate(comp.factors):
        b, c = elems[2 * i], elems[2 * i + 1]
        y = {(k,): b} if b != K.zero else {}
        if c != K.zero:
            for w, v in _gradient_term(K, c).items():
                y[w] = y.get(w, K.zero) + v
        product = S.mul(product, S.exp(y))
    return K, S, S.log(product)


def _coordinates(K, series: dict, q: int) -> list:
    """``q! v(E_q)``: the Lyndon coordinates of the degree-``q`` part, times ``q!``, as exact sympy numbers."""
    scale = K.convert(factorial(q))
    return [K.to_sympy(series.get(w, K.zero) * scale) for w in lyndon_defect_words(2, q)]


def _check_degree(degree):
    if not is_int(degree, 2, MAX_SERIES_DEGREE):
        raise InvalidOrderError(f"max_degree must be an integer in 2..{MAX_SERIES_DEGREE}, got {degree!r}")


def gradient_analysis(spec, structure=None, max_degree: int = 7):
    """Order and error constant of a composition with force-gradient factors (module docstring), exactly.

    The LEM is the 2-norm of ``(p+1)! v(E_(p+1))`` (for plain compositions the LEM of
    :func:`~nambu_bch.design.error_constant`); with ``structure="rkn"`` modulo the RKN ideal.

    Parameters
    ----------
    spec : GradientComposition, a list accepted by :func:`gradient_composition`, or a catalogue name (``"chin-4a"``)
    structure : ``None`` or ``"rkn"``
    max_degree : int -- the highest degree computed (the order found is at most ``max_degree - 1``)

    Returns
    -------
    ErrorConstant (``composition`` the :class:`GradientComposition`, ``parts = 2``)

    Examples
    --------
    >>> gradient_analysis("chin-4a").order
    4
    """
    from .conditions import ErrorConstant

    comp = _gradient_spec(spec)
    structure = check_structure(structure)
    _check_degree(max_degree)
    bound = comp.error_bound
    K, _, log = _log_of(comp, max_degree)
    for q in range(1, max_degree + 1):
        values = _coordinates(K, log, q)
        if q == 1:
            values = [v - 1 for v in values]
        residual = _residual(values, q, structure)
        if any((abs(complex(x)) > bound) if bound else x != 0 for x in residual):
            squared = _squared_norm(residual, comp.is_complex)
            return ErrorConstant(comp, 2, q - 1, squared, dict(zip(lyndon_defect_words(2, q), residual)), bound, structure)
    raise InvalidOrderError(f"composition {str(comp)!r} has order >= {max_degree}; raise max_degree (at most {MAX_SERIES_DEGREE})")


# ---------------------------------------------------------------------------------------------
# processing


@dataclass(frozen=True)
class EffectiveOrder:
    """The effective order of a kernel and what no processor removes.

    Attributes
    ----------
    kernel : Composition or GradientComposition
    order : int             -- the effective order ``p``
    squared : sympy number  -- the squared effective error constant (degree ``p + 1``, module docstring), exact
    processor : dict        -- ``{q: coordinates of Z_q on the Lyndon brackets P_u}``: the processor's log
                               ``Z = sum h^q Z_q``, degree by degree (one choice: ``Z_q`` is determined up to the
                               kernel of ``ad_X``, multiples of ``X`` at ``q = 1``)
    structure : str
    """

    kernel: object
    order: int
    squared: object
    processor: dict
    structure: str = ""

    @property
    def value(self) -> float:
        return float(sympy.sqrt(self.squared).evalf(30))


def _bracket_basis(S, q):
    """The Lyndon bracket polynomials ``P_u`` of length ``q`` as word series (coefficients in ``S.K``)."""
    from ..bch.lyndon import standard_bracketing, tree_to_associative

    out = []
    for u in lyndon_defect_words(2, q):
        poly = tree_to_associative(standard_bracketing(u))
        out.append({tuple(w): S.K.convert(sympy.Integer(c)) for w, c in poly.items() if c})
    return out


def effective_order(kernel, structure=None, max_degree: int = 7) -> EffectiveOrder:
    """The effective order of a kernel (processed method ``P K P^(-1)``), exactly (module docstring).

    Parameters
    ----------
    kernel : a composition spec of the pieces 1 and 2, or a force-gradient composition (:func:`gradient_composition`)
    structure : ``None`` or ``"rkn"`` -- remove the RKN ideal as well (RKN problems)
    max_degree : int

    References
    ----------
    Blanes, Casas & Ros, SIAM J. Sci. Comput. 21 (1999) 711.

    Examples
    --------
    Strang's kernel cannot be processed beyond order 2; the Takahashi-Imada kernel reaches 4:

    >>> effective_order("121").order, effective_order("takahashi-imada").order
    (2, 4)
    """
    comp = _gradient_spec(kernel)
    if comp.error_bound:
        raise InvalidCompositionError(f"effective_order needs exact coefficients; {str(comp)!r} has published decimals")
    structure = check_structure(structure)
    _check_degree(max_degree)
    K, S, log = _log_of(comp, max_degree)
    X = {(1,): K.one, (2,): K.one}
    processor = {}
    for q in range(2, max_degree + 1):
        values = _coordinates(K, log, q)
        basis = _bracket_basis(S, q - 1)
        images = [S.bracket(P, X) for P in basis]     # [P_u, X]
        columns = [_coordinates(K, image, q) for image in images]
        if structure == "rkn":
            from .structure import rkn_ideal

            columns += [list(v) for v in rkn_ideal(q)]
        residual = _project_out(values, columns)
        if any(x != 0 for x in residual):
            return EffectiveOrder(comp, q - 1, _squared_norm(residual, comp.is_complex), processor, structure)
        # Z with [Z, X] = -E_q: solve in the coordinates of the images, then conjugate the whole series
        alphas = _solve(columns[:len(images)], values, extra=columns[len(images):])
        if alphas is None:  # E_q lies in the RKN ideal plus the image: only the image part is removable
            alphas = [0] * len(images)
        # both sides carry the factor q!: sum a_u [P_u, X] = E_q, so Z_(q-1) = -sum a_u P_u
        z: dict = {}
        for a, P in zip(alphas, basis):
            if a != 0:
                factor = K.from_sympy(-a)
                for w, c in P.items():
                    z[w] = z.get(w, K.zero) + factor * c
        z = {w: c for w, c in z.items() if c != K.zero}
        processor[q - 1] = [sympy.expand(-a) for a in alphas]
        if z:
            log = S.exp_ad(z, log)
    raise InvalidOrderError(f"kernel {str(comp)!r} has effective order >= {max_degree}; raise max_degree (at most {MAX_SERIES_DEGREE})")


def _project_out(values, columns):
    """``values`` minus its orthogonal projection on the span of ``columns`` (exact)."""
    if not columns:
        return list(values)
    M = sympy.Matrix(columns).T
    rank_cols = M.columnspace()
    if not rank_cols:
        return list(values)
    B = sympy.Matrix.hstack(*rank_cols)
    d = sympy.Matrix(values)
    coeffs = (B.T * B).inv() * (B.T * d)
    return [sympy.expand(x) for x in d - B * coeffs]


def _solve(columns, values, extra=()):
    """Coefficients ``a`` with ``sum a_j columns_j + (something in extra) = values``, or ``None``."""
    n = len(columns)
    M = sympy.Matrix([*columns, *extra]).T
    sol, params = M.gauss_jordan_solve(sympy.Matrix(values))
    sol = sol.subs({p: 0 for p in params})
    return [sympy.expand(x) for x in sol[:n]]


# ---------------------------------------------------------------------------------------------
# the catalogue of force-gradient methods and kernels


def _catalogue():
    R = sympy.Rational
    return {
        # Chin, Phys. Lett. A 226 (1997) 344, algorithm 4A: B(1/6) A(1/2) B~(2/3) A(1/2) B(1/6),
        # B~ = B + (h^2/48)[B,[A,B]], i.e. c = (2/3)(1/48) (module docstring)
        "chin-4a": (((2, R(1, 6)), (1, R(1, 2)), (2, R(2, 3), R(1, 72)), (1, R(1, 2)), (2, R(1, 6))), 4,
                    "Chin, Phys. Lett. A 226 (1997) 344, algorithm 4A"),
        # Takahashi & Imada, J. Phys. Soc. Jpn. 53 (1984) 3765: the kernel A(1/2) B~(1) A(1/2) with
        # B~ = B + (h^2/24)[B,[A,B]] (c = 1/24); effective order 4 with a processor
        "takahashi-imada": (((1, R(1, 2)), (2, 1, R(1, 24)), (1, R(1, 2))), 2,
                            "Takahashi & Imada, J. Phys. Soc. Jpn. 53 (1984) 3765 (processed kernel)"),
    }


GRADIENT_METHODS = tuple(_catalogue())
#: The catalogue kernels that are run processed (``P K P^(-1)``, :mod:`nambu_bch.numeric.force_gradient`).
PROCESSED_KERNELS = ("takahashi-imada",)


def _gradient_spec(spec) -> GradientComposition:
    if isinstance(spec, GradientComposition):
        return spec
    if isinstance(spec, str) and spec.strip().lower() in GRADIENT_METHODS:
        factors, order, citation = _catalogue()[spec.strip().lower()]
        return gradient_composition(factors, spec.strip().lower(), order, citation)
    if isinstance(spec, (list, tuple)) and spec and isinstance(spec[0], (list, tuple)) and len(spec[0]) in (2, 3):
        return gradient_composition(spec)
    from ..integrators.composition import composition as make_composition

    comp = make_composition(spec, 2)
    if set(comp.pieces) != {1, 2}:
        raise InvalidCompositionError(f"composition {comp.name!r} must use exactly the pieces 1 and 2, got {sorted(set(comp.pieces))}")
    return GradientComposition(tuple((k, c, sympy.Integer(0)) for k, c in comp.factors()), comp.name, comp.order,
                               comp.citation, float(getattr(comp, "error_bound", 0.0) or 0.0))
