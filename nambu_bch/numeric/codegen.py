"""Code generation: the composed step as a straight-line program, printed once per backend.

The numeric backends never call sympy per step.  Instead, once per
``(system, word)``, the exact sub-flows (:func:`nambu_bch.integrators.exact_flow`)
are turned into a :class:`StepProgram`:

* every sub-flow ``phi^{k_j}_{c_j h}`` becomes an *update* ``x_i <- x_i + d_i``
  for each coordinate it moves, with the increment ``d_i = phi_i(x) - x_i``
  (``x_i (e^u - 1)`` is written ``x_i expm1(u)`` so small steps lose nothing);
  all increments of one sub-flow are computed from the state before it;
* every coordinate-free sub-expression of the increments (products of
  parameters, exact coefficients and ``h``) is *hoisted* into a constant
  ``k_j(h, params)``, evaluated once per run, so the loop body only multiplies
  and adds state values and constants (e.g. ``s0 += k0*s1`` for Eq. hX1e).

The program is then printed with sympy's code printers -- Python for numba and
the pure-Python / numpy / mpmath fallbacks, C (``ccode``) for the reference loop
of ``benchmarks/bench_iterate.py``.  Every printer emits the same operations in
the same order, so the backends agree bit for bit on polynomial flows, and on
``exp`` flows while the shared exponentials stay in the range of their series
(:func:`pair_lines`); beyond it up to the last bits of the libraries' ``expm1``.

Operator order: the updates run in word order, left to right, exactly as the
sub-flows act on a state (:mod:`nambu_bch.integrators.composition`).

Compensated (Kahan) summation -- Higham, *Accuracy and Stability of Numerical
Algorithms*, Sect. 4.3; Hairer, Lubich, Wanner, *Geometric Numerical
Integration*, Sect. VIII.5 -- replaces ``s += d`` by::

    y = d - c;  t = s + y;  c = (t - s) - y;  s = t

with one compensation ``c`` per coordinate carried across all steps.

References
----------
Horikoshi, Sect. 5.5 (numerical results) and Eqs. (hX1e)-(hX3e), (12321).
"""

from __future__ import annotations

import hashlib
import math
import textwrap
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from math import factorial

import sympy
from sympy.codegen.cfunctions import expm1
from sympy.printing.c import C99CodePrinter
from sympy.printing.pycode import PythonCodePrinter

from ..errors import InvalidSystemError
from ..integrators.composition import composition_for
from ..integrators.flows import TIME, exact_flow

#: The step symbol of the constants (same name as in the rest of the package).
STEP = sympy.Symbol("h")

#: Bump when the generated source changes meaning (part of the cache key).
TEMPLATE_VERSION = "11"
#: Steps a batch kernel takes for each state of a chunk before moving to the next state (:func:`_chunk_step`).
JAM_STEPS = 2

_FUNCTIONS = ("exp", "expm1", "log", "sin", "cos", "tan", "sinh", "cosh", "tanh", "sqrt", "atan", "asin", "acos")


@dataclass(frozen=True)
class Update:
    """One sub-flow ``exp(c h X_k)`` as increments ``((i, d_i), ...)`` in the state symbols and constants.

    ``pairs`` are shared exponentials ``(u_j, e_j, f_j, u)``: when a sub-flow needs both
    ``expm1(u)`` and ``expm1(-u)`` (a Lotka-Volterra piece scales one coordinate by ``e^u`` and
    another by ``e^-u``) one ``expm1`` serves both: ``e = expm1(|u|)``, ``f = -e / (1 + e)``
    ``= expm1(-|u|)`` (no cancellation, since ``1 + e >= 1``), swapped when ``u < 0``; the
    increments then use ``e_j = expm1(u)`` and ``f_j = expm1(-u)``.
    """

    piece: int
    coefficient: sympy.Expr
    increments: tuple
    pairs: tuple = ()

    def expanded(self) -> tuple:
        """The increments with the shared exponentials written out (``e_j -> expm1(u)``, ``f_j -> expm1(-u)``)."""
        back = {}
        for _, e, f, u in self.pairs:
            back[e], back[f] = expm1(u), expm1(-u)
        return tuple((i, d.xreplace(back)) for i, d in self.increments)


@dataclass(frozen=True, eq=False)
class StepProgram:
    """The composed step ``Phi_h`` as hoisted constants plus an ordered list of updates.

    Attributes
    ----------
    system_name, word : str
    N : int
    coordinates, parameters : tuple of Symbols of the system
    state : tuple of Symbols ``s0 .. s{N-1}`` used in the increments
    constants : tuple of ``(k_j, expression in the parameters and h)``
    updates : tuple of :class:`Update` in the order they act on the state
    """

    system_name: str
    word: str
    N: int
    coordinates: tuple
    parameters: tuple
    state: tuple
    constants: tuple
    updates: tuple

    def constant_function(self, modules="math"):
        """``f(h, *params) -> [k_0, k_1, ...]`` (lambdified once; ``modules="mpmath"`` for mpf)."""
        exprs = [e for _, e in self.constants] or [sympy.Integer(0)]
        return sympy.lambdify((STEP, *self.parameters), exprs, modules=modules)

    @property
    def n_operations(self) -> int:
        """Floating-point operations per step (adds, multiplies, calls), a rough cost measure."""
        count = 0
        for u in self.updates:
            for _, d in u.increments:
                count += 1 + sympy.count_ops(d)
        return count

    def __repr__(self):
        return (f"StepProgram({self.system_name!r}, {self.word!r}: {len(self.updates)} sub-flows, "
                f"{len(self.constants)} constants, ~{self.n_operations} flops/step)")


def step_program(system, word) -> StepProgram:
    """The :class:`StepProgram` of ``word`` on ``system`` (memoised per system and word).

    Examples
    --------
    >>> from nambu_bch import model
    >>> prog = step_program(model("ho3"), "12321")
    >>> [(u.piece, u.increments) for u in prog.updates][:3]
    [(1, ((0, k0*s1),)), (2, ((1, k1*s0),)), (3, ((2, k2*s0*s1),))]
    >>> prog.constants[:3]
    ((k0, h/(2*m)), (k1, -h*m*omega**2/2), (k2, 2*h/m))
    """
    from ..systems.spec import as_system

    system = as_system(system)
    comp = composition_for(word, system.splitting)
    return _step_program(system, comp)


@lru_cache(maxsize=128)
def _step_program(system, comp) -> StepProgram:
    coords = system.coordinates
    # the internal symbols carry an assumption of their own, so a user's parameter or coordinate
    # named ``s0`` or ``k1`` (a spring constant) never equals them
    state = tuple(sympy.Symbol(f"s{i}", nambu_internal=True) for i in range(len(coords)))
    to_state = dict(zip(coords, state))
    hoister = _Hoister(state)
    updates = []
    n_pairs = 0
    for k, c in comp.factors():
        flow = exact_flow(system.splitting[k], coords)
        raw = []
        for i, (x, e) in enumerate(zip(coords, flow.expressions)):
            d = sympy.sympify(e, strict=True) - x
            if d == 0:
                continue
            d = _with_expm1(sympy.factor_terms(d.subs(TIME, c * STEP)))
            stray = d.free_symbols - set(coords) - set(system.parameters) - {STEP}
            if stray:
                raise InvalidSystemError(f"the flow of piece {k} of {system.name} uses unknown symbols {sorted(map(str, stray))}")
            raw.append((i, d.xreplace(to_state)))
        raw, found = _pair_expm1(raw, n_pairs)
        n_pairs += len(found)
        pairs = []
        for u_sym, e_sym, f_sym, u in found:
            hoister.state |= {e_sym, f_sym}
            pairs.append((u_sym, e_sym, f_sym, hoister.polynomial(u)))
        incs = [(i, hoister.polynomial(d)) for i, d in raw]
        if incs:
            updates.append(Update(k, c, tuple(incs), tuple(pairs)))
    program = StepProgram(system.name, str(comp), len(coords), coords, tuple(system.parameters), state,
                          tuple(hoister.constants), tuple(updates))
    _validate(program, system)
    return program


def _pair_expm1(raw, start):
    """Share ``expm1(u)`` and ``expm1(-u)`` within one sub-flow: ``(increments, [(u_j, e_j, f_j, u), ...])``."""
    args = []
    for _, d in raw:
        for a in d.atoms(expm1):
            if a.args[0] not in args:
                args.append(a.args[0])
    found, subs = [], {}
    for a in args:
        if a.could_extract_minus_sign() or -a not in args or expm1(a) in subs:
            continue
        j = start + len(found)
        u_sym, e_sym, f_sym = (sympy.Symbol(f"{p}{j}", nambu_internal=True) for p in "uef")
        subs[expm1(a)], subs[expm1(-a)] = e_sym, f_sym
        found.append((u_sym, e_sym, f_sym, a))
    if not found:
        return raw, []
    return [(i, d.xreplace(subs)) for i, d in raw], found


#: The only functions generated source may call (each printed as ``_<name>`` / ``_np_<name>`` / ``_mp_<name>``).
ALLOWED_FUNCTIONS = frozenset(_FUNCTIONS)


def check_kernel_expression(expr, symbols, where: str) -> None:
    """Refuse, in one line naming ``where``, an expression a generated kernel must not hold: a singular value
    (``zoo``, ``nan``, ``oo``), a symbol outside ``symbols``, or a function outside :data:`ALLOWED_FUNCTIONS`."""
    if any(expr.has(z) for z in (sympy.zoo, sympy.nan, sympy.oo, -sympy.oo)):
        raise InvalidSystemError(f"{where} is singular ({expr}); check the parameters of the model")
    stray = expr.free_symbols - symbols
    if stray:
        raise InvalidSystemError(f"{where} uses unknown symbols {sorted(map(str, stray))}")
    for f in expr.atoms(sympy.Function):
        if type(f).__name__ not in ALLOWED_FUNCTIONS:
            raise InvalidSystemError(f"{where} calls {type(f).__name__}, which numeric kernels "
                                     f"do not support (supported: {', '.join(sorted(ALLOWED_FUNCTIONS))})")


def _validate(program, system):
    """Refuse a program whose printed source could contain anything but internal names and numbers.

    The increments may use only the state ``s_i``, the constants ``k_j`` and the whitelisted
    functions; the constants only the parameters, ``h`` and those functions; neither may be
    singular (``zoo``, ``nan``, ``oo``).  So no name a user chose ever reaches a kernel
    (no user text reaches the source): parameters enter through ``P[i]``, coordinates through ``x[i]``.
    """
    allowed = set(program.state) | {k for k, _ in program.constants}
    for u in program.updates:
        allowed |= {sym for pair in u.pairs for sym in pair[1:3]}
    params = set(program.parameters) | {STEP}

    def check(expr, symbols, where):
        check_kernel_expression(expr, symbols, f"{where} of {system.name}")

    for u in program.updates:
        for _, d in u.increments:
            check(d, allowed, f"the flow of piece {u.piece}")
        for pair in u.pairs:
            check(pair[3], allowed, f"the flow of piece {u.piece}")
    for k, e in program.constants:
        check(e, params, f"the step coefficient {k}")


def _with_expm1(expr):
    """Rewrite ``exp(u) - 1`` (inside any sum) as ``expm1(u)``."""
    def is_target(e):
        return e.is_Add and any(isinstance(a, sympy.exp) for a in e.args) and -1 in e.args

    def rewrite(e):
        exps = [a for a in e.args if isinstance(a, sympy.exp)]
        rest = [a for a in e.args if a is not exps[0] and a != -1]
        return sympy.Add(expm1(exps[0].args[0]), *rest, evaluate=False) if rest else expm1(exps[0].args[0])

    return expr.replace(is_target, rewrite)


class _Hoister:
    """Replace maximal coordinate-free sub-expressions by constants ``k0, k1, ...`` (deduplicated)."""

    def __init__(self, state):
        self.state = set(state)
        self.constants = []
        self._index = {}

    def constant(self, expr):
        expr = sympy.nsimplify(expr) if expr.has(sympy.Float) else expr
        if expr not in self._index:
            sym = sympy.Symbol(f"k{len(self.constants)}", nambu_internal=True)
            self._index[expr] = sym
            self.constants.append((sym, expr))
        return self._index[expr]

    def polynomial(self, expr):
        """A polynomial increment as ``sum_j k_j * monomial_j``; anything else via :meth:`__call__`."""
        state = sorted(self.state, key=str)
        if not expr.is_polynomial(*state):
            return self(expr)
        terms = []
        for powers, coeff in sympy.Poly(sympy.expand(expr), *state).terms():
            mono = sympy.Mul(*[s**e for s, e in zip(state, powers)])
            if mono == 1:
                terms.append(self.constant(coeff))
            elif coeff in (1, -1):
                terms.append(coeff * mono)
            else:
                terms.append(self.constant(coeff) * mono)
        return sympy.Add(*terms)

    def __call__(self, expr):
        if not (expr.free_symbols & self.state):
            return self.constant(expr)
        if expr.is_Symbol:
            return expr
        if expr.is_Add or expr.is_Mul:
            free = [a for a in expr.args if not (a.free_symbols & self.state)]
            dep = [self(a) for a in expr.args if a.free_symbols & self.state]
            if free:
                dep.insert(0, self.constant(expr.func(*free)))
            return expr.func(*dep)
        if expr.is_Pow:
            base, ex = expr.args
            if ex.free_symbols & self.state:
                return sympy.Pow(self(base), self(ex))
            return sympy.Pow(self(base), ex if ex.is_Integer else self.constant(ex))
        if isinstance(expr, sympy.Function):
            return expr.func(*[self(a) for a in expr.args])
        raise InvalidSystemError(f"cannot generate numeric code for the sub-expression {expr}")


# -- printers -------------------------------------------------------------------------------------------


class _PowMixin:
    """Small integer powers as explicit products, so every backend rounds them identically."""

    def _print_Pow(self, expr, *args, **kwargs):
        base, ex = expr.args
        if ex.is_Integer and 2 <= int(ex) <= 8:
            b = self.parenthesize(base, 100)
            return "(" + "*".join([b] * int(ex)) + ")"
        if ex.is_Integer and -8 <= int(ex) <= -1:
            b = self.parenthesize(base, 100)
            return "(1.0/(" + "*".join([b] * -int(ex)) + "))"
        return super()._print_Pow(expr, *args, **kwargs)


class _KernelPrinter(_PowMixin, PythonCodePrinter):
    """Python printer whose functions are module globals ``<prefix>exp`` etc. (``_exp``, ``_np_exp``, ``_mp_exp``)."""

    def __init__(self, prefix="_"):
        funcs = {f: f"{prefix}{f}" for f in _FUNCTIONS}
        super().__init__({"user_functions": funcs, "fully_qualified_modules": False})
        self._prefix = prefix

    # pi and E (the parser's two constants) as module globals too: ``_pi`` for float64, ``_mp_pi`` at any precision
    def _print_Pi(self, expr):
        return f"{self._prefix}pi"

    def _print_Exp1(self, expr):
        return f"{self._prefix}e"

    def _hprint_Pow(self, expr, rational=False, sqrt="math.sqrt"):
        # sqrt(x) and 1/sqrt(x) (exact radicals in designed coefficients) call the module's own sqrt
        return super()._hprint_Pow(expr, rational=rational, sqrt=f"{self._prefix}sqrt")


class _CPrinter(_PowMixin, C99CodePrinter):
    pass


def print_python(expr, prefix="_") -> str:
    """``expr`` as Python source with functions named ``prefix + name`` (e.g. ``_expm1``)."""
    return _KernelPrinter(prefix).doprint(expr)


def print_c(expr) -> str:
    """``expr`` as C99 source (sympy's ``ccode`` with small powers expanded)."""
    return _CPrinter().doprint(expr)


# -- shared exponentials ---------------------------------------------------------------------------------

#: Below this ``|u|`` the ``expm1(|u|)`` of a shared pair comes from the series of ``cosh - 1`` and ``sinh``
#: (:func:`pair_lines`), above it from the library ``expm1``.
SERIES_LIMIT = 0.5
#: ``1/n!`` correctly rounded: ``cosh a - 1 = z (1/2! + z/4! + ... + z^7/16!)``, ``sinh a - a =
#: a z (1/3! + z/5! + ... + z^6/15!)`` with ``z = a^2``; the first omitted terms are below 2^-60 of
#: ``a`` for ``a <= SERIES_LIMIT``.
_COSH_COEFFS = tuple(repr(float(Fraction(1, factorial(n)))) for n in range(2, 17, 2))
_SINH_COEFFS = tuple(repr(float(Fraction(1, factorial(n)))) for n in range(3, 16, 2))


def _estrin(coeffs, z, z2, z4):
    """``sum_i coeffs[i] z^i`` (degree <= 7) by Estrin's scheme: short dependency chains, same operations everywhere."""
    pairs = [f"({coeffs[i]} + {coeffs[i + 1]}*{z})" if i + 1 < len(coeffs) else coeffs[i]
             for i in range(0, len(coeffs), 2)]
    quads = [f"({pairs[i]} + {z2}*{pairs[i + 1]})" if i + 1 < len(pairs) else pairs[i]
             for i in range(0, len(pairs), 2)]
    return f"({quads[0]} + {z4}*{quads[1]})" if len(quads) == 2 else quads[0]


def pair_lines(u, e, f, value, prefix="_", style="python"):
    """Statements setting ``e = expm1(u)`` and ``f = expm1(-u)`` for ``u = value`` (one shared exponential).

    For ``a = |u| <= SERIES_LIMIT``: ``c = cosh a - 1`` and ``r = sinh a - a`` from their Taylor
    series (Estrin's scheme in ``z = a^2``), ``e = expm1(a) = a + (c + r)`` and ``f0 = (c - r) - a``,
    then one Newton step ``f = f0 - g (1 + f0)`` on ``g = (1 + e)(1 + f0) - 1 = (e + f0) + e f0``
    (``e + f0`` is exact: ``e`` and ``-f0`` are within a factor 2, Sterbenz).  No library call and
    no division: a short dependency chain.  ``e`` is within about 1 ulp of ``expm1(a)`` (the tail
    ``c + r`` is below 0.27 a, so the last addition dominates) and ``f`` is ``-e/(1 + e)`` rounded
    once, so ``(1 + e)(1 + f) = 1`` to half an ulp of ``f``: a Lotka-Volterra piece keeps
    ``G = x1 x2 x3`` (``f0`` alone, as accurate per call, drifted ``G`` 8x more over 2e6 steps;
    ``-e/fl(1 + e)`` 3x more; ``test_lotka_volterra_pieces_keep_G``).  For larger ``a`` (and NaN):
    the library ``expm1`` and ``f = -e / (1 + e)`` (``1 + e >= 1``: no cancellation).  Swapped when
    ``u < 0``.  The mpmath prefix ``_mp_`` keeps the library function at any precision.  ``style``:
    ``"python"`` (scalar, numba), ``"numpy"`` (arrays), ``"c"`` (C99, the benchmark's reference) --
    the same IEEE operations in the same order.

    References
    ----------
    Estrin's scheme: Knuth, *TAOCP* vol. 2, Sect. 4.6.4; Sterbenz's lemma and Newton's correction:
    Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., Sects. 2.5 and 5.4.
    """
    a, z, z2, z4, c, r, f0, g = (f"_{name}{u}" for name in ("a", "z", "zz", "z4", "ch", "sh", "f", "g"))
    if prefix == "_mp_":
        return [f"{u} = {value}", f"{e} = {prefix}expm1(abs({u}))", f"{f} = -{e} / (1.0 + {e})",
                f"if {u} < 0: {e}, {f} = {f}, {e}"]
    series = [f"{z} = {a}*{a}", f"{z2} = {z}*{z}", f"{z4} = {z2}*{z2}",
              f"{c} = {z}*{_estrin(_COSH_COEFFS, z, z2, z4)}",
              f"{r} = ({a}*{z})*{_estrin(_SINH_COEFFS, z, z2, z4)}",
              f"{e} = {a} + ({c} + {r})", f"{f0} = ({c} - {r}) - {a}",
              f"{g} = ({e} + {f0}) + {e}*{f0}", f"{f} = {f0} - {g}*(1.0 + {f0})"]
    library = [f"{e} = {prefix}expm1({a})", f"{f} = -{e} / (1.0 + {e})"]
    if style == "c":  # temporaries declared where they are first set; e and f are declared before the branch
        body = " ".join(("" if line.startswith((e + " ", f + " ")) else "double ") + line + ";" for line in series)
        return [f"double {u} = {value};", f"double {a} = fabs({u});", f"double {e}, {f};",
                f"if ({a} <= {SERIES_LIMIT!r}) {{ {body} }}",
                f"else {{ {e} = expm1({a}); {f} = -{e} / (1.0 + {e}); }}",
                f"if ({u} < 0) {{ double w_ = {e}; {e} = {f}; {f} = w_; }}"]
    if style == "cselect":  # the C twin of "select"
        body = " ".join(("" if line.startswith((e + " ", f + " ")) else "double ") + line + ";" for line in series)
        w = f"_w{u}"
        return [f"double {u} = {value};", f"double {a} = fabs({u});", f"over += {a} <= {SERIES_LIMIT!r} ? 0 : 1;",
                f"double {e}, {f}; {body}",
                f"double {w} = {e}; {e} = {u} < 0 ? {f} : {e}; {f} = {u} < 0 ? {w} : {f};"]
    if style == "select":  # branch-free (vectorisable): the series for every state, ``over`` counts |u| beyond it
        w = f"_w{u}"
        return [f"{u} = {value}", f"{a} = abs({u})", f"over += 0 if {a} <= {SERIES_LIMIT!r} else 1", *series,
                f"{w} = {e}", f"{e} = {f} if {u} < 0 else {e}", f"{f} = {w} if {u} < 0 else {f}"]
    if style == "numpy":
        big = f"_big{u}"
        return [f"{u} = {value}", f"{a} = np.abs({u})", *series, f"{big} = ~({a} <= {SERIES_LIMIT!r})",
                f"if {big}.any(): {e}[{big}] = {prefix}expm1({a}[{big}]); {f}[{big}] = -{e}[{big}] / (1.0 + {e}[{big}])",
                f"{e}, {f} = np.where({u} >= 0, {e}, {f}), np.where({u} >= 0, {f}, {e})"]
    return [f"{u} = {value}", f"{a} = abs({u})", f"if {a} <= {SERIES_LIMIT!r}:",
            *(f"    {line}" for line in series), "else:", *(f"    {line}" for line in library),
            f"if {u} < 0: {e}, {f} = {f}, {e}"]


#: The generated function ``e, f = _expm1_pair(u)`` (:func:`pair_lines` as a function), called by the batch
#: loops' redo; the compiled loops call its compiled form (:meth:`~nambu_bch.numeric.kernels.Kernel.function`).
PAIR_FUNCTION = "_expm1_pair"


#: The generated function ``e, f, o = _expm1_select(u)`` (:func:`pair_lines` style ``"select"`` as a function,
#: ``o`` = 1 when ``|u|`` is beyond the series), called by the batch loops' branch-free pass.  One compiled copy of
#: the series instead of one per sub-flow: numba types and lowers each statement of a function once, and its cost
#: grows with the statements (five inline copies in a Lotka-Volterra 12321 step, twice: plain and Kahan); LLVM
#: inlines the small callee, so the machine code and its vectorisation are those of the inline statements.  A loop
#: compiled with contraction calls a copy compiled with contraction (fast-math flags are per instruction, kept
#: through inlining): the same bits as the statements inline (:meth:`~nambu_bch.numeric.kernels.Kernel.function`).
SELECT_FUNCTION = "_expm1_select"


#: The generated function ``_copy(_dst, _src, nb)``: ``_dst[b] = _src[b]`` for ``b < nb`` -- the memory passes of
#: the batch loops with shared exponentials (:func:`_run_batch_source`), inlined by LLVM like the select function.
COPY_FUNCTION = "_copy"


def pair_function_source() -> str:
    """``def _expm1_pair(x): ... return e0, f0`` -- the statements of :func:`pair_lines` (style ``"python"``) --
    and ``def _expm1_select(x): ... return e0, f0, over`` (style ``"select"``, ``over`` 0 or 1)."""
    body = pair_lines("u0", "e0", "f0", "x")
    select = [line.replace("over += ", "over = ", 1) for line in pair_lines("u0", "e0", "f0", "x", style="select")]
    return f"""

def {PAIR_FUNCTION}(x):
{_indent(body, 4)}
    return e0, f0


def {SELECT_FUNCTION}(x):
{_indent(select, 4)}
    return e0, f0, over


def {COPY_FUNCTION}(_dst, _src, nb):
    for b in range(nb):
        _dst[b] = _src[b]
"""


def expm1_pair(u: float) -> tuple:
    """``(expm1(u), expm1(-u))`` in float64 exactly as the generated kernels compute a shared pair.

    >>> expm1_pair(0.0), expm1_pair(1e-300)
    ((0.0, 0.0), (1e-300, -1e-300))
    """
    scope = {}
    # the generated statements themselves (internal names, the float u as a variable: no text is formatted in)
    exec("\n".join(pair_lines("u0", "e0", "f0", "_x")), {"_expm1": math.expm1, "_x": float(u)}, scope)  # noqa: S102
    return scope["e0"], scope["f0"]


# -- loop bodies ----------------------------------------------------------------------------------------


def body_lines(program: StepProgram, printer, kahan=False, c_syntax=False, vector=False, prefix="_", select=False,
               pair_call=None, fused=False, select_call=None):
    """Statements of one step, ``s_i`` / ``k_j`` / ``d_j`` / ``c_i`` named as in the generated kernels.

    ``vector``: numpy arrays (the shared-exponential swap is a ``np.where``); ``prefix``: of the
    function names (``_``, ``_np_``, ``_mp_``); ``c_syntax``: C99; ``select``: shared exponentials
    without branches (:func:`pair_lines` style ``"select"``, for the vectorised batch loop);
    ``pair_call``: the name of a function computing a shared pair (``e_j, f_j = pair_call(u_j)``,
    :data:`PAIR_FUNCTION`) instead of its statements inline; ``select_call``: likewise for ``select``
    (``e_j, f_j, _o = select_call(u_j)``, ``over += _o``; :data:`SELECT_FUNCTION`); ``fused``: each increment
    that is a product ``p*q`` is added by one fused multiply-add ``s_i = _fma(p, q, s_i)`` (:func:`fused_product`), the
    operands of an update taken before any of its coordinates moves (Python syntax, no Kahan).
    """
    end = ";" if c_syntax else ""
    decl = "double " if c_syntax else ""
    lines = []
    for u in program.updates:
        for us, es, fs, ue in u.pairs:
            if pair_call:
                lines += [f"{us} = {printer(ue)}", f"{es}, {fs} = {pair_call}({us})"]
                continue
            if select_call:
                lines += [f"{us} = {printer(ue)}", f"{es}, {fs}, _o{us} = {select_call}({us})", f"over += _o{us}"]
                continue
            style = ("cselect" if select else "c") if c_syntax else "numpy" if vector else "select" if select else "python"
            lines += pair_lines(str(us), str(es), str(fs), printer(ue), prefix, style)
        names = []
        for j, (i, d) in enumerate(u.increments):
            split = fused_product(d, printer) if fused else None
            if split is not None:
                lines += [f"p{j} = {split[0]}", f"t{j} = {split[1]}"]  # t: unused outside Kahan's lines
                names.append((i, (f"p{j}", f"t{j}")))
                continue
            lines.append(f"{decl}d{j} = {printer(d)}{end}")
            names.append((i, f"d{j}"))
        for i, d in names:
            if isinstance(d, tuple):
                lines.append(f"s{i} = {FMA_FUNCTION}({d[0]}, {d[1]}, s{i})")
            elif kahan:
                lines += [f"{decl}y{i} = {d} - c{i}{end}", f"{decl}t{i} = s{i} + y{i}{end}",
                          f"c{i} = (t{i} - s{i}) - y{i}{end}", f"s{i} = t{i}{end}"]
            else:
                lines.append(f"s{i} += {d}{end}")
    if c_syntax:  # C declares each temporary once per scope: one brace block per update
        return _c_scoped(program, lines, kahan, "cselect" if select else "c")
    return lines


#: The fused multiply-add the ``fused`` lines call: ``llvm.fma`` in the compiled loop
#: (:func:`nambu_bch.compiled.fused_multiply_add`); the interpreter never runs them.
FMA_FUNCTION = "_fma"
#: The name the batch loops call the guards' scan by (:func:`nambu_bch.numeric.scan.scan_into`, bound when they are
#: compiled; ``None`` in the interpreted module, whose batches run the numpy loops).
SCAN_FUNCTION = "_scan_into"


def fused_product(d, printer):
    """``(p, q)`` printed so that ``p*q`` is ``d`` printed (the same operations), or None.

    ``d`` a product ``p*q`` whose printed form is exactly ``<p>*<q>``: Python evaluates a chain of
    ``*`` and ``/`` from the left, so the default loop computes ``p`` first and multiplies by ``q``
    last -- that last multiply and the addition of the increment are what a fused multiply-add
    merges, as gcc's contraction does (``-ffp-contract=fast``).  Anything else (a sum, a function,
    a printed form that does not split this way) is added unfused.
    """
    import sympy

    if not isinstance(d, sympy.Mul):
        return None
    factors = d.as_ordered_factors()
    if len(factors) < 2:
        return None
    head, last = printer(sympy.Mul(*factors[:-1])), printer(factors[-1])
    if printer(d) != f"{head}*{last}" or "+" in head or " - " in head:
        return None
    return head, last


def _c_scoped(program, lines, kahan, style="c"):
    out = []
    it = iter(lines)
    for u in program.updates:
        n = len(u.increments)
        count = len(pair_lines("u", "e", "f", "0", style=style)) * len(u.pairs) + n + n * (4 if kahan else 1)
        block = [next(it) for _ in range(count)]
        out.append("{ " + " ".join(block) + " }")
    return out


# -- module source --------------------------------------------------------------------------------------

_HEADER = '''"""Generated by nambu_bch.numeric.codegen (template {version}); do not edit.

Every name below is internal (s_i state, k_j constants, P[i] parameters); the cache
verifies this file against the digest recorded when it was generated.
"""
import math
import numpy as np

_exp, _expm1, _log, _sqrt = math.exp, math.expm1, math.log, math.sqrt
_sin, _cos, _tan, _sinh, _cosh, _tanh = math.sin, math.cos, math.tan, math.sinh, math.cosh, math.tanh
_atan, _asin, _acos, _isfinite = math.atan, math.asin, math.acos, math.isfinite
_np_exp, _np_expm1, _np_log, _np_sqrt = np.exp, np.expm1, np.log, np.sqrt
_np_sin, _np_cos, _np_tan, _np_sinh, _np_cosh, _np_tanh = np.sin, np.cos, np.tan, np.sinh, np.cosh, np.tanh
_np_atan, _np_asin, _np_acos, _np_isfinite = np.arctan, np.arcsin, np.arccos, np.isfinite
_INF, _MAX, _TINY = math.inf, 1.7976931348623157e308, 2.2250738585072014e-308
_pi, _e, _np_pi, _np_e = math.pi, math.e, math.pi, math.e
_fma = None
'''


# ``_fma = None`` in the header: run_fma's ``a*b + c`` rounded once is ``llvm.fma``, bound when run_fma is compiled
# (:meth:`nambu_bch.numeric.kernels.Kernel.function`); the generated source carries no comment (no ``#`` at all).


def _indent(lines, n):
    pad = " " * n
    return "\n".join(pad + line for line in lines)


def _row_copy(dst, src, call=False):
    """Lines copying the first ``nb`` entries of ``src`` into ``dst`` (chunk arrays; at most one of them a row slice);
    ``call``: one call of the compiled :data:`COPY_FUNCTION` instead of the loop."""
    if call:
        return [f"{COPY_FUNCTION}({dst}, {src}, nb)"]
    if "[" in src:
        return [f"row = {src}", "for b in range(nb):", f"    {dst}[b] = row[b]"]
    if "[" in dst:
        return [f"row = {dst}", "for b in range(nb):", f"    row[b] = {src}[b]"]
    return ["for b in range(nb):", f"    {dst}[b] = {src}[b]"]


def _sampling_loop(step, sample, checks=(), jammed=None):
    """The loop every kernel shares: ``steps`` steps, a sample into ``out[j]`` after each ``every`` of them.

    ``step`` are the lines of one step, ``sample`` the lines that store sample ``j``, ``checks``
    lines run after it (finiteness, progress).  ``jammed``: lines of :data:`JAM_STEPS` steps at once
    (a batch's chunk loop doing them for each state in turn), run while that many steps remain before
    the next sample, ``step`` then for the rest.  Returns lines at indent 0.
    """
    if jammed and step:
        advance = [f"    for _ in range(m // {JAM_STEPS}):", *("        " + line for line in jammed),
                   f"    for _ in range(m % {JAM_STEPS}):", *("        " + line for line in step)]
    else:
        advance = ["    for _ in range(m):", *("        " + line for line in (step or ["pass"]))]  # every piece
        # zero: the step is the identity
    return [
        "n = 0",
        "j = 1",
        "while n < steps:",
        "    m = every if steps - n >= every else steps - n",
        *advance,
        "    n += m",
        *("    " + line for line in sample),
        "    j += 1",
        *("    " + line for line in checks),
    ]


def python_source(program: StepProgram) -> str:
    """The generated kernel module (numba-compatible Python; see :mod:`nambu_bch.numeric.kernels`).

    Functions (``x``/``X`` are updated in place to the final state, ``out[0]`` must hold
    the initial state; they return the number of steps done, fewer than ``steps``
    only when a sample was not finite):

    * ``run(x, K, steps, every, out)`` and ``run_kahan(x, c, K, steps, every, out)`` --
      one trajectory, ``x`` of shape (N,), ``out`` of shape (n_samples, N);
    * ``run_fma(x, K, steps, every, out)`` -- ``run`` with every product increment added by one fused
      multiply-add (:func:`fused_product`; compiled only, for ``fma=True``);
    * ``run_batch(X, K, steps, every, out, chunk, start, back, lo, hi, res)`` and ``run_batch_kahan(X, C, ...)`` --
      ``X`` of shape (N, batch) holds the start states, ``out`` of shape (n_samples, N, batch);
      the columns ``lo <= b < hi`` are processed (disjoint ranges may run in parallel threads: the
      compiled loops release the GIL), in chunks that stay in cache, the inner loop over the chunk.
      ``start``: also copy ``X`` into ``out[0]`` (in the same pass that loads the chunk);
      ``back``: write the final states back into ``X`` (without it ``X`` is only read, and the
      final states are ``out[-1]``).  ``C`` (Kahan compensation) is always updated in place.
      ``res``: an empty int64 array, or the guards' scan result to extend chunk by chunk as the states are
      loaded (:func:`nambu_bch.numeric.scan.scan_into`; -1 is returned at a non-finite or subnormal start state,
      before any step).  They return the number of non-finite values among the samples written (``out[1:]``),
      so the caller checks the result without another pass over it;
    * ``run_numpy(...)`` and ``run_numpy_kahan(...)`` -- the vectorised numpy fallback for
      batches (the same arguments but ``res``, the same operations in the same order; it returns a positive number
      when a sample is not finite, 0 otherwise).
    """
    consts = [f"k{j} = K[{j}]" for j in range(len(program.constants))] or ["pass"]
    scalar = lambda e: print_python(e, "_")  # noqa: E731
    src = [_HEADER.format(version=TEMPLATE_VERSION), f"{SCAN_FUNCTION} = None\n", constants_source(program)]
    if any(u.pairs for u in program.updates):
        src.append(pair_function_source())
    # the single loops call the compiled pair function (LLVM inlines it) rather than repeat its statements per
    # sub-flow: numba's compile grows with the statements it types and lowers
    pair_call = PAIR_FUNCTION if any(u.pairs for u in program.updates) else None
    for kahan in (False, True):
        body = body_lines(program, scalar, kahan)
        src.append(_run_source(program, body_lines(program, scalar, kahan, pair_call=pair_call), consts, kahan))
        if not kahan:
            src.append(_run_fma_source(program, scalar, consts, pair_call))
        src.append(_run_batch_source(program, body, scalar, consts, kahan))
        src.append(_run_numpy_source(program, consts, kahan))
    return "\n".join(src)


def _run_source(program: StepProgram, body, consts, kahan) -> str:
    """``run`` / ``run_kahan``: one trajectory, the state in locals ``s_i``, a sample row per kept step."""
    N = program.N
    s = [f"s{i}" for i in range(N)]
    load = "; ".join(f"{v} = x[{i}]" for i, v in enumerate(s))
    store = "; ".join(f"x[{i}] = {v}" for i, v in enumerate(s))
    finite = " and ".join(f"_isfinite({v})" for v in s)
    sample = "; ".join(f"out[j, {i}] = {v}" for i, v in enumerate(s))
    name = "run_kahan" if kahan else "run"
    args = "x, c, K, steps, every, out" if kahan else "x, K, steps, every, out"
    comp_load = "; ".join(f"c{i} = c[{i}]" for i in range(N))
    comp_store = "; ".join(f"c[{i}] = c{i}" for i in range(N))
    return f"""
def {name}({args}):
{_indent(consts, 4)}
    {load}
    {comp_load if kahan else ''}
{_indent(_sampling_loop(body, [sample], [f"if not ({finite}):", "    break"]), 4)}
    {store}
    {comp_store if kahan else ''}
    return n
"""


def _run_fma_source(program: StepProgram, scalar, consts, pair_call=None) -> str:
    """``run_fma``: ``run`` with the fused multiply-adds written out, the loop of ``fma=True`` for one trajectory.

    Contraction alone (fastmath "contract") left LLVM free to compute a product shared by two consecutive steps
    once (the loop unrolled four times), and a shared product is not fused: the chain through the state got longer
    than gcc's, which fuses every update (docs/numerics.md, "Why fma=True stayed above gcc").
    """
    s = [f"s{i}" for i in range(program.N)]
    load = "; ".join(f"{v} = x[{i}]" for i, v in enumerate(s))
    store = "; ".join(f"x[{i}] = {v}" for i, v in enumerate(s))
    finite = " and ".join(f"_isfinite({v})" for v in s)
    sample = "; ".join(f"out[j, {i}] = {v}" for i, v in enumerate(s))
    return f"""
def run_fma(x, K, steps, every, out):
{_indent(consts, 4)}
    {load}
{_indent(_sampling_loop(body_lines(program, scalar, fused=True, pair_call=pair_call), [sample],
                         [f"if not ({finite}):", "    break"]), 4)}
    {store}
    return n
"""


def _run_batch_source(program: StepProgram, body, scalar, consts, kahan) -> str:
    """``run_batch`` / ``run_batch_kahan``: chunks of states kept in small contiguous arrays, inner loop over the
    chunk; the start states are read from X (copied into out[0] when ``start``), the final ones written back into
    X only when ``back``; the sample pass counts non-finite values (the result check)."""
    N = program.N
    name = "run_batch_kahan" if kahan else "run_batch"
    args = ("X, C, K, steps, every, out, chunk, start, back, lo, hi, res" if kahan else
            "X, K, steps, every, out, chunk, start, back, lo, hi, res")
    # the chunk's rows in one buffer, each row 64-byte aligned: an allocation only 16- or 32-byte aligned
    # splits every 8-wide (AVX-512) load across two cache lines, measured 1.8x slower
    rows = [f"S{i}" for i in range(N)] + ([f"Q{i}" for i in range(N)] if kahan else [])
    pairs = any(u.pairs for u in program.updates)
    spare = [f"R{q}" for q in range(len(rows))] if pairs else []
    alloc = ["W = (chunk + 7) // 8 * 8", f"buf = np.empty({len(rows) + len(spare)} * W + 8)",
             "off = (8 - (buf.ctypes.data // 8) % 8) % 8"]
    alloc += [f"{r} = buf[off + {q} * W:off + {q} * W + chunk]" for q, r in enumerate(rows + spare)]
    alloc += ["scanning = res.shape[0] > 0", "acc = np.empty((2, 3, chunk if scanning else 1))"]
    # the memory passes as one element loop per row (numba vectorises each; a slice assignment
    # ``S0[:nb] = X[0, b0:b0 + nb]`` runs as fast but makes numba compile its broadcasting error
    # path, which doubled the kernel's compile time; one loop over all rows at once measured 3-4x slower).
    # With shared exponentials (a dozen to thirty such loops with the redo's save and restore) each is a call
    # of the one compiled COPY_FUNCTION, which LLVM inlines: the same machine code, compiled by numba once
    gather = [line for i in range(N) for line in _row_copy(f"S{i}", f"X[{i}, b0:b0 + nb]", pairs)]
    gather += [line for i in range(N) for line in _row_copy(f"Q{i}", f"C[{i}, b0:b0 + nb]", pairs)] if kahan else []
    first = [line for i in range(N) for line in _row_copy(f"out[0, {i}, b0:b0 + nb]", f"S{i}", pairs)]
    scatter = [line for i in range(N) for line in _row_copy(f"X[{i}, b0:b0 + nb]", f"S{i}", pairs)]
    comp_back = [line for i in range(N) for line in _row_copy(f"C[{i}, b0:b0 + nb]", f"Q{i}", pairs)] if kahan else []
    # ``res`` non-empty: the guards' scan of the start states (:func:`nambu_bch.numeric.scan.scan_into`, bound
    # to SCAN_FUNCTION when the loop is compiled) extended by each chunk just before it is loaded -- the batch
    # is read from memory once; a non-finite or subnormal start state stops the loop (-1) before any step
    chunk_step = _chunk_step(program, body, scalar, kahan, rows)
    jammed = _chunk_step(program, body, scalar, kahan, rows, JAM_STEPS)
    chunk_sample = []
    for i in range(N):  # the sample, row by row, counting non-finite values as it is written
        chunk_sample += [f"row = out[j, {i}, b0:b0 + nb]", "for b in range(nb):",
                         f"    v = S{i}[b]; row[b] = v; bad += 0 if abs(v) <= _MAX else 1"]
    return f"""
def {name}({args}):
{_indent(consts, 4)}
    bad = 0
{_indent(alloc, 4)}
    for b0 in range(lo, hi, chunk):
        nb = min(chunk, hi - b0)
        if scanning:
            if {SCAN_FUNCTION}(X, b0, b0 + nb, acc, res):
                return -1
{_indent(gather, 8)}
        if start:
{_indent(first, 12)}
{_indent(_sampling_loop(chunk_step, chunk_sample, jammed=jammed), 8)}
        if back:
{_indent(scatter, 12)}
{_indent(comp_back, 8)}
    return bad
"""


def _chunk_step(program: StepProgram, body, scalar, kahan, rows, steps=1) -> list:
    """One step of every state of a chunk (the batch kernel's inner loop); ``steps > 1``: that many steps of each
    state in turn, loaded once and stored once (None for a step with shared exponentials, whose redo is per step).

    Each state still goes through the same operations in the same order, so the bits do not change; the chunk's
    rows are read and written once per ``steps`` steps instead of once per step -- what gcc does to the C loop at
    -O3 (unroll-and-jam of the step loop), and the L1 traffic numba's loop otherwise spends in loads and stores.
    """
    N = program.N
    inner_load = [f"s{i} = S{i}[b]" for i in range(N)] + ([f"c{i} = Q{i}[b]" for i in range(N)] if kahan else [])
    inner_store = [f"S{i}[b] = s{i}" for i in range(N)] + ([f"Q{i}[b] = c{i}" for i in range(N)] if kahan else [])
    if not any(u.pairs for u in program.updates):
        return ["for b in range(nb):", *("    " + line for line in inner_load + body * steps + inner_store)]
    if steps > 1:
        return None
    # shared exponentials: one branch-free pass over the chunk (vectorised); if some |u| left the
    # series range, the chunk's step is undone and redone with the library branch -- the same bits
    # as the branchy loop either way.  The pass and the redo (scalar, rare) call the select and the pair
    # function instead of repeating their statements per sub-flow: a fraction of the source numba compiles
    fast = body_lines(program, scalar, kahan, select_call=SELECT_FUNCTION)
    redo = body_lines(program, scalar, kahan, pair_call=PAIR_FUNCTION)
    saved = [line for q, r in enumerate(rows) for line in _row_copy(f"R{q}", r, call=True)]
    restore = [line for q, r in enumerate(rows) for line in _row_copy(r, f"R{q}", call=True)]
    return [*saved, "over = 0", "for b in range(nb):",
            *("    " + line for line in inner_load + fast + inner_store),
            "if over:", *("    " + line for line in restore),
            "    for b in range(nb):", *("        " + line for line in inner_load + redo + inner_store)]


def _run_numpy_source(program: StepProgram, consts, kahan) -> str:
    """``run_numpy`` / ``run_numpy_kahan``: the vectorised numpy fallback, the same statements on chunk arrays."""
    N = program.N
    name = "run_numpy_kahan" if kahan else "run_numpy"
    args = ("X, C, K, steps, every, out, chunk, start, back, lo, hi" if kahan else
            "X, K, steps, every, out, chunk, start, back, lo, hi")
    vector = lambda e: print_python(e, "_np_")  # noqa: E731
    vbody = body_lines(program, vector, kahan, vector=True, prefix="_np_")
    vload = [f"s{i} = X[{i}, b0:b1].copy()" for i in range(N)] + ([f"c{i} = C[{i}, b0:b1].copy()" for i in range(N)] if kahan else [])
    vfirst = [f"out[0, {i}, b0:b1] = s{i}" for i in range(N)]
    vstore = [f"X[{i}, b0:b1] = s{i}" for i in range(N)]
    vcomp = [f"C[{i}, b0:b1] = c{i}" for i in range(N)] if kahan else []
    vsample = [f"out[j, {i}, b0:b1] = s{i}" for i in range(N)]
    vsample.append("bad += 0 if (" + " and ".join(f"_np_isfinite(s{i}).all()" for i in range(N)) + ") else 1")
    return f"""
def {name}({args}):
{_indent(consts, 4)}
    bad = 0
    for b0 in range(lo, hi, chunk):
        b1 = min(b0 + chunk, hi)
{_indent(vload, 8)}
        if start:
{_indent(vfirst, 12)}
{_indent(_sampling_loop(vbody, vsample), 8)}
        if back:
{_indent(vstore, 12)}
{_indent(vcomp, 8)}
    return bad
"""




def mpmath_source(program: StepProgram) -> str:
    """``run(x, K, steps, every, out)`` for mpmath numbers (functions ``_mp_exp`` etc. from the namespace)."""
    N = program.N
    s = [f"s{i}" for i in range(N)]
    consts = [f"k{j} = K[{j}]" for j in range(len(program.constants))] or ["pass"]
    body = body_lines(program, lambda e: print_python(e, "_mp_"), prefix="_mp_")
    sample = ["; ".join(f"out[j, {i}] = {v}" for i, v in enumerate(s))]
    checks = ["if progress is not None:", "    progress(n)",
              f"if not ({' and '.join(f'_mp_isfinite({v})' for v in s)}):", "    break"]
    return f"""
def run(x, K, steps, every, out, progress=None):
{_indent(consts, 4)}
    {"; ".join(f"{v} = x[{i}]" for i, v in enumerate(s))}
{_indent(_sampling_loop(body, sample, checks), 4)}
    {"; ".join(f"x[{i}] = {v}" for i, v in enumerate(s))}
    return n
"""


def _c_state(program) -> tuple:
    """The C pieces both translation units share: the step's statements, the constants read from ``K``, and the
    state loaded from and stored to ``x``."""
    N = program.N
    return (body_lines(program, print_c, c_syntax=True),
            " ".join(f"const double k{j} = K[{j}];" for j in range(len(program.constants))),
            " ".join(f"double s{i} = x[{i}];" for i in range(N)),
            " ".join(f"x[{i}] = s{i};" for i in range(N)))


def c_source(program: StepProgram) -> str:
    """A C99 translation unit with the same loop: ``run`` and ``run_batch`` (for the benchmark's reference).

    ``long run(double *x, const double *K, long steps)`` advances one state in place;
    ``void run_batch(double *X, const double *K, long steps, long B, long chunk)``
    advances ``X`` of shape (N, B) (row-major) chunk by chunk, inner loop over the chunk,
    exactly like the numba batch kernel (without sampling; with shared exponentials, the same
    branch-free pass and redo).
    """
    N = program.N
    body, consts, decl, store = _c_state(program)
    arrays = " ".join(f"double S{i}[chunk];" for i in range(N))
    gather = " ".join(f"S{i}[b] = X[{i} * B + b0 + b];" for i in range(N))
    scatter = " ".join(f"X[{i} * B + b0 + b] = S{i}[b];" for i in range(N))
    inner_load = " ".join(f"double s{i} = S{i}[b];" for i in range(N))
    inner_store = " ".join(f"S{i}[b] = s{i};" for i in range(N))
    step = f"""for (long b = 0; b < nb; ++b) {{
                {inner_load}
                {chr(10).join('                ' + b for b in body).strip()}
                {inner_store}
            }}"""
    if any(u.pairs for u in program.updates):  # as the numba batch kernel: branch-free pass, redo when needed
        fast = body_lines(program, print_c, c_syntax=True, select=True)
        arrays += " " + " ".join(f"double R{i}[chunk];" for i in range(N))
        save = " ".join(f"R{i}[b] = S{i}[b];" for i in range(N))
        restore = " ".join(f"S{i}[b] = R{i}[b];" for i in range(N))
        step = f"""for (long b = 0; b < nb; ++b) {{ {save} }}
            long over = 0;
            for (long b = 0; b < nb; ++b) {{
                {inner_load}
                {chr(10).join('                ' + b for b in fast).strip()}
                {inner_store}
            }}
            if (over) {{
            for (long b = 0; b < nb; ++b) {{ {restore} }}
            {step}
            }}"""
    return f"""/* Generated by nambu_bch.numeric.codegen (template {TEMPLATE_VERSION}) */
#include <math.h>

long run(double *restrict x, const double *restrict K, long steps) {{
    {consts}
    {decl}
    for (long n = 0; n < steps; ++n) {{
        {chr(10).join('        ' + b for b in body).strip()}
    }}
    {store}
    return steps;
}}

void run_batch(double *restrict X, const double *restrict K, long steps, long B, long chunk) {{
    {consts}
    {arrays}
    for (long b0 = 0; b0 < B; b0 += chunk) {{
        long nb = chunk < B - b0 ? chunk : B - b0;
        for (long b = 0; b < nb; ++b) {{ {gather} }}
        for (long n = 0; n < steps; ++n) {{
            {step}
        }}
        for (long b = 0; b < nb; ++b) {{ {scatter} }}
    }}
}}
"""


def c_run_source(program: StepProgram) -> str:
    """The generated ``run`` as a C translation unit: the loop of a kernel's C library
    (:mod:`~nambu_bch.numeric.clib`).

    ``long run(double *x, const double *K, long steps, long every, double *out)`` has the semantics of the
    Python/numba ``run`` (:func:`python_source`): ``x`` (N,) advanced in place, ``out`` (n_samples, N)
    row-major with ``out[0]`` the start, a sample after each ``every`` steps, the loop stopped at a
    non-finite sample; returns the steps done.  The statements are :func:`body_lines` printed by the C99
    printer -- the same operations in the same order, built without contraction (``-ffp-contract=off``),
    so the samples are numba's bits.  Like every generated source it holds no user text: state ``s_i``,
    constants ``k_j`` and numeric literals only (:func:`check_kernel_expression`).
    """
    N = program.N
    body, consts, decl, store = _c_state(program)
    sample = " ".join(f"out[j * {N} + {i}] = s{i};" for i in range(N))
    finite = " && ".join(f"isfinite(s{i})" for i in range(N))
    return f"""/* Generated by nambu_bch.numeric.codegen (template {TEMPLATE_VERSION}) */
#include <math.h>

long run(double *restrict x, const double *restrict K, long steps, long every, double *restrict out) {{
    {consts}
    {decl}
    long n = 0;
    long j = 1;
    while (n < steps) {{
        long m = steps - n >= every ? every : steps - n;
        for (long r = 0; r < m; ++r) {{
            {chr(10).join('            ' + b for b in body).strip()}
        }}
        n += m;
        {sample}
        j += 1;
        if (!({finite})) break;
    }}
    {store}
    return n;
}}
"""


def constants_source(program: StepProgram) -> str:
    """``constants(h, P) -> [k_0, ...]`` as Python source: the parameters enter as ``P[i]`` (no names).

    Division by a zero parameter raises ``ZeroDivisionError`` and an overflowing ``exp``
    ``OverflowError``; :meth:`~nambu_bch.numeric.kernels.Kernel.constants` turns both into
    one :class:`~nambu_bch.errors.NumericalRangeError` line.
    """
    inner = [sympy.Symbol(f"p{i}", nambu_internal=True) for i in range(len(program.parameters))]
    rename = dict(zip(program.parameters, inner))
    lines = [f"p{i} = P[{i}]" for i in range(len(inner))]
    lines += [f"{k} = {print_python(sympy.sympify(e, strict=True).xreplace(rename), '_')}" for k, e in program.constants]
    names = ", ".join(str(k) for k, _ in program.constants)
    return f"""

def constants(h, P):
{_indent(lines or ["pass"], 4)}
    return [{names}]
"""


def describe(program: StepProgram) -> str:
    """A readable account of the program (state, constants, updates) -- for people, never for source."""
    lines = [f"state {', '.join(f's{i} = {c}' for i, c in enumerate(program.coordinates))}"]
    lines += [f"{k} = {e}" for k, e in program.constants]
    for u in program.updates:
        lines.append(f"piece {u.piece} (coefficient {u.coefficient}): " +
                     ", ".join(f"s{i} += {d}" for i, d in u.increments))
    return "\n".join(lines)


def source_hash(source: str) -> str:
    """A short stable key of a generated source (the kernel cache file name)."""
    return hashlib.sha256((TEMPLATE_VERSION + source).encode()).hexdigest()[:20]


# -- Runge--Kutta steps -------------------------------------------------------------------------------------------
#: Bump when the generated Runge--Kutta source changes meaning.
RK_TEMPLATE_VERSION = "5"

# The generated module is the field, its Jacobian and one entry point per kind of step, each a single function
# with the loops it needs written inline: numba compiles a function on its first call with every function it
# reaches (typed, lowered and optimised apart, then optimised again when linked into the caller), so an explicit
# run compiles two functions, not the Newton iteration and the linear solve besides, and an implicit one pays for
# no second optimisation of a callee.  The fragments below are indented into the entry points by _rk_runs.

#: ``r <- M^-1 r`` for the leading ``{m} x {m}`` block by Gaussian elimination with partial pivoting (``M``
#: overwritten); ``ok`` is False, and ``r`` left half done, when ``M`` is singular.
_RK_SOLVE = """\
ok = True
for k in range({m}):
    p = k
    big = abs(M[k, k])
    for i in range(k + 1, {m}):
        if abs(M[i, k]) > big:
            big = abs(M[i, k])
            p = i
    if not (big > 0.0 and big < _INF):
        ok = False
        break
    if p != k:
        for e in range({m}):
            t = M[k, e]
            M[k, e] = M[p, e]
            M[p, e] = t
        t = r[k]
        r[k] = r[p]
        r[p] = t
    for i in range(k + 1, {m}):
        g = M[i, k] / M[k, k]
        if g != 0.0:
            for e in range(k + 1, {m}):
                M[i, e] -= g * M[k, e]
            r[i] -= g * r[k]
if ok:
    for k in range({m} - 1, -1, -1):
        t = r[k]
        for e in range(k + 1, {m}):
            t -= M[k, e] * r[e]
        r[k] = t / M[k, k]"""

#: The stages ``K_i = f(x + h sum_q a_iq K_q)`` by Newton's method on the ``m = s n`` unknowns, from ``K_i = f(x)``,
#: until the residual no longer shrinks (round-off): ``it`` the iterations used, -1 when the Newton matrix is
#: singular, -2 when the residual did not reach ``tol (1 + max|K|)`` within ``maxit`` iterations.  ``A[k]`` is the
#: tableau of component ``k`` (one tableau for all, or a partitioned pair's two).
_RK_NEWTON = """\
rk_field(x, P, F[0])
for i in range(s):
    for k in range(n):
        K[i, k] = F[0, k]
best = _INF
it = 0
while True:
    for i in range(s):
        for k in range(n):
            acc = 0.0
            for q in range(s):
                acc += A[k, i, q] * K[q, k]
            Y[i, k] = x[k] + h * acc
        rk_field(Y[i], P, F[i])
    size = 0.0
    scale = 0.0
    for i in range(s):
        for k in range(n):
            d = K[i, k] - F[i, k]
            r[i * n + k] = d
            if abs(d) > size:
                size = abs(d)
            if abs(K[i, k]) > scale:
                scale = abs(K[i, k])
    if not (size < _INF):
        it = -2
        break
    if size <= 4.0 * 2.220446049250313e-16 * scale or (size >= best and best <= tol * (1.0 + scale)):
        break
    if size >= best or it >= maxit:
        it = -2
        break
    best = size
    for i in range(s):
        rk_jacobian(Y[i], P, J)
        for a in range(n):
            for q in range(s):
                for e in range(n):
                    M[i * n + a, q * n + e] = (1.0 if (i == q and a == e) else 0.0) - h * A[e, i, q] * J[a, e]
{solve}
    if not ok:
        it = -1
        break
    for i in range(s):
        for k in range(n):
            K[i, k] -= r[i * n + k]
    it += 1"""

#: The run loop every entry point shares: ``{stages}`` computes the increment ``inc`` of one step (or returns
#: ``step - 1`` with ``info[1]`` set); the update (compensated or not), the range check and the sampling are common.
_RK_RUN = """

def {name}(x, c, compensated, h, P, A, b, steps, every, out, maxit, tol, info):
    \"\"\"{what}.
    steps steps from x (updated in place); out[j] gets the state after step j*every (and the last step);
    {work}.  On failure info[1] = 1 (singular), 2 (no convergence) or 3 (not finite),
    info[2] = the step.  Returns the steps done.  A[k] (s x s) and b[k] (s) are the tableau of component k.\"\"\"
    n = x.shape[0]
{arrays}
    inc = np.zeros(n)
    j = 1
    for step in range(1, steps + 1):
{stages}
        finite = True
        for k in range(n):
            if compensated:
                y = inc[k] - c[k]
                t = x[k] + y
                c[k] = (t - x[k]) - y
                x[k] = t
            else:
                x[k] = x[k] + inc[k]
            if not _isfinite(x[k]):
                finite = False
        if not finite:
            info[1] = 3
            info[2] = step
            return step - 1
        if step % every == 0 or step == steps:
            for k in range(n):
                out[j, k] = x[k]
            j += 1
    return steps
"""

#: inc = h sum_i b_i K_i, per component.
_RK_INCREMENT = """\
for k in range(n):
    acc = 0.0
    for i in range(s):
        acc += b[k, i] * K[i, k]
    inc[k] = h * acc"""

#: The stages of an explicit method in order: K_i = f(x + h sum_{q<i} a_iq K_q).
_RK_EXPLICIT = """\
for i in range(s):
    for k in range(n):
        acc = 0.0
        for q in range(i):
            acc += A[k, i, q] * K[q, k]
        Y[i, k] = x[k] + h * acc
    rk_field(Y[i], P, K[i])"""

#: Kahan's step on a quadratic field: x' = x + h (I - h/2 f'(x))^-1 f(x).
_RK_KAHAN = """\
rk_field(x, P, r)
rk_jacobian(x, P, J)
for a in range(n):
    for e in range(n):
        M[a, e] = (1.0 if a == e else 0.0) - 0.5 * h * J[a, e]
{solve}
if not ok:
    info[1] = 1
    info[2] = step
    return step - 1
info[0] += 1
for k in range(n):
    inc[k] = h * r[k]"""

#: The failure of Newton's iteration reported, its iterations counted.
_RK_NEWTON_DONE = """\
if it < 0:
    info[1] = 1 if it == -1 else 2
    info[2] = step
    return step - 1
info[0] += it"""


def _rk_runs() -> str:
    """The three entry points (:func:`nambu_bch.numeric.runge_kutta.iterate_runge_kutta` calls the one its tableau
    needs): ``rk_run_explicit``, ``rk_run_kahan`` and ``rk_run_newton``, written out from :data:`_RK_RUN`."""
    def block(*fragments, depth=8):
        return textwrap.indent("\n".join(fragments), " " * depth)

    newton = _RK_NEWTON.format(solve=block(_RK_SOLVE.format(m="m"), depth=4))
    runs = (
        ("rk_run_explicit", "An explicit method, its stages in order", "info[0] is left as it is",
         ("s = b.shape[1]", "K = np.zeros((s, n))", "Y = np.zeros((s, n))"), (_RK_EXPLICIT, _RK_INCREMENT)),
        ("rk_run_kahan", "Kahan's method: one linear solve a step (A, b unused)", "info[0] += 1 per solve",
         ("J = np.zeros((n, n))", "M = np.zeros((n, n))", "r = np.zeros(n)"),
         (_RK_KAHAN.format(solve=_RK_SOLVE.format(m="n")),)),
        ("rk_run_newton", "The Runge--Kutta step, its stages by Newton's method", "info[0] += the Newton iterations",
         ("s = b.shape[1]", "m = s * n", "K = np.zeros((s, n))", "Y = np.zeros((s, n))", "F = np.zeros((s, n))",
          "J = np.zeros((n, n))", "M = np.zeros((m, m))", "r = np.zeros(m)"), (newton, _RK_NEWTON_DONE, _RK_INCREMENT)),
    )
    return "".join(_RK_RUN.format(name=name, what=what, work=work, arrays=block(*arrays, depth=4),
                                  stages=block(*stages)) for name, what, work, arrays, stages in runs)


def runge_kutta_source(system) -> str:
    """The generated module of the Runge--Kutta steps on ``system``: ``rk_field(y, P, out)`` and
    ``rk_jacobian(y, P, J)`` printed from the system's (validated) vector field, then the fixed Newton and
    linear-solve loops (:func:`_rk_runs`).  Coordinates enter as ``y[i]``, parameters as ``P[i]``: no name a
    user chose reaches the source; the field may use only them and :data:`ALLOWED_FUNCTIONS`, and must be finite.
    """
    coords, params = list(system.coordinates), list(system.parameters)
    s = [sympy.Symbol(f"s{i}") for i in range(len(coords))]
    p = [sympy.Symbol(f"p{i}") for i in range(len(params))]
    rename = dict(zip(coords + params, s + p))
    field = [sympy.sympify(e, strict=True) for e in system.vector_field.to_sympy()]
    jac = sympy.Matrix(field).jacobian(coords)
    allowed = set(s) | set(p)

    def checked(expr, where):
        expr = expr.xreplace(rename)
        check_kernel_expression(expr, allowed, f"{where} of {system.name}")
        return print_python(expr, "_")

    load = [f"    s{i} = y[{i}]" for i in range(len(s))] + [f"    p{i} = P[{i}]" for i in range(len(p))]
    lines = [_HEADER.format(version="rk" + RK_TEMPLATE_VERSION), "", "def rk_field(y, P, out):", *load]
    lines += [f"    out[{i}] = {checked(e, 'the vector field')}" for i, e in enumerate(field)]
    lines += ["", "", "def rk_jacobian(y, P, J):", *load]
    lines += [f"    J[{i}, {k}] = {checked(jac[i, k], 'the Jacobian')}" for i in range(len(s)) for k in range(len(s))]
    return "\n".join(lines) + "\n" + _rk_runs()
