"""Compiled loops for compositions with complex coefficients: the complex128 step generated, compiled and cached.

A composition ``Phi_h = exp(c_1 h X_{k_1}) ... exp(c_s h X_{k_s})`` with complex ``c_j`` acts on ``C^N``
(:mod:`~nambu_bch.numeric.complex_iterate`).  :func:`complex_program` turns the exact sub-flows
(:func:`nambu_bch.integrators.exact_flow`) into straight-line statements once per ``(system, composition)``:

* factor ``j`` sets the time ``t = c_j h`` (complex128, ``T[j]``) and assigns to every coordinate it moves
  its new value ``phi_i(x, t)``, all computed from the state before the factor, exactly the expressions
  the interpreted reference evaluates;
* the parameter-only factors of every term (``1/m``, ``-m omega^2``, ``(I2 - I1)/(I1 I2)``) are hoisted into
  real constants ``k_j(params)`` (:class:`~nambu_bch.numeric.codegen._Hoister`, the real kernels' hoisting),
  computed once per run, so one compiled loop serves every ``h`` and every parameter value.

:func:`complex_source` prints it as a module (:func:`~nambu_bch.numeric.codegen.print_python`: small powers as
products, the entire functions as ``cmath``'s) and :class:`ComplexKernel` puts that module into the kernels'
private verified cache and compiles its loops with numba (:class:`~nambu_bch.numeric.kernels.Kernel`: the
source's digest checked before it is executed, numba's machine code kept and verified by
:func:`nambu_bch.compiled.enable_private_cache`).  Only validated exact data reaches the source: the state and
the time are internal names, parameters enter as ``P[i]`` and the coefficients as the ``repr`` of their
complex128 values.

Bits.  The compiled loop performs the reference's operations: complex products as ``(ac - bd, ad + bc)`` and
sums componentwise with no contraction (numba without fast-math), ``exp``/``sin``/``cos`` of a complex
argument from the C library's real functions as CPython's ``cmath`` does, and the internal names ordered
like the model's symbols so each product associates as the reference's does.  Where the parameter factors
of a term are computed exactly (the default parameters of the built-in models) the trajectories agree bit
for bit with :func:`~nambu_bch.numeric.complex_iterate.iterate_complex` on ``backend="numpy"`` (one state);
otherwise they differ by the rounding of those constants, a few ulps per step.

References
----------
S. Blanes, F. Casas, A. Murua, *Splitting methods with complex coefficients*, SeMA J. 50 (2010) 47--61, Sect. 4;
Python's ``Objects/complexobject.c`` (``_Py_c_prod``) and ``Modules/cmathmodule.c`` (``cmath_exp_impl``), and
numba's ``numba/cpython/cmathimpl.py``, for the operations both sides perform.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import sympy

from ..errors import InvalidRunError, NumericalRangeError
from ..integrators.composition import composition_for
from ..integrators.flows import TIME, exact_flow
from .codegen import _Hoister, _indent, _sampling_loop, check_kernel_expression, constants_source, print_python
from .complex_flows import ENTIRE, check_entire, coefficient_value
from .kernels import Kernel, cache_dir

#: Bump when the generated source changes meaning (the template an index records also carries this file's digest).
COMPLEX_TEMPLATE_VERSION = "1"


@dataclass(frozen=True, eq=False)
class ComplexProgram:
    """The complex step as hoisted real constants and one block of assignments per factor.

    Attributes
    ----------
    system_name, word : str
    N : int
    coordinates, parameters : tuple of the system's Symbols
    variables : tuple -- the internal Symbols of the coordinates (``v..``), in coordinate order
    time : Symbol -- the internal Symbol of the sub-flows' time
    constants : tuple of ``(k_j, expression in the parameters)`` (real)
    factors : tuple of ``(piece, exact coefficient, complex128 coefficient, ((i, new x_i), ...))``
    """

    system_name: str
    word: str
    N: int
    coordinates: tuple
    parameters: tuple
    variables: tuple
    time: sympy.Symbol
    constants: tuple
    factors: tuple

    def __repr__(self):
        return (f"ComplexProgram({self.system_name!r}, {self.word[:60]!r}: {len(self.factors)} sub-flows, "
                f"{len(self.constants)} constants)")


def complex_program(system, word) -> ComplexProgram:
    """The :class:`ComplexProgram` of a composition with complex coefficients on ``system`` (memoised).

    Raises :class:`~nambu_bch.errors.InvalidRunError` for a sub-flow that is not entire
    (:func:`~nambu_bch.numeric.complex_iterate.check_entire`).

    Examples
    --------
    >>> prog = complex_program("ho", "1:1/4+I/4,2:1/2+I/2,1:1/2,2:1/2-I/2,1:1/4-I/4")
    >>> prog.factors[0][2], prog.factors[0][3]
    ((0.25+0.25j), ((0, k0*v0*v2 + v1),))
    >>> prog.constants[0]
    (k0, 1/m)
    """
    from ..systems.spec import as_system

    system = as_system(system)
    return _complex_program(system, composition_for(word, system.splitting))


@lru_cache(maxsize=64)
def _complex_program(system, comp) -> ComplexProgram:
    coords = tuple(system.coordinates)
    # internal names ordered as the model's symbols are, so sympy orders every product as it does for the
    # reference's expressions (a complex product is not associative in floating point)
    ranked = sorted((*coords, TIME), key=sympy.default_sort_key)
    width = len(str(len(ranked)))
    rename = {s: sympy.Symbol(f"v{r:0{width}d}", nambu_internal=True) for r, s in enumerate(ranked)}
    variables, time_symbol = tuple(rename[c] for c in coords), rename[TIME]
    hoister = _Hoister((*variables, time_symbol))
    allowed = {*variables, time_symbol}
    factors = []
    flows = {}
    for k, c in comp.factors():
        if k not in flows:
            exprs = [sympy.sympify(e, strict=True) for e in exact_flow(system.splitting[k], coords).expressions]
            check_entire(system, comp, k, exprs)
            moves = []
            for i, (x, e) in enumerate(zip(coords, exprs)):
                if e == x:
                    continue
                new = hoister.polynomial(e.xreplace(rename))
                check_kernel_expression(new, allowed | {s for s, _ in hoister.constants},
                                        f"the flow of piece {k} of {system.name}")
                moves.append((i, new))
            flows[k] = tuple(moves)
        if flows[k]:
            factors.append((k, c, coefficient_value(comp, c), flows[k]))
    for s, e in hoister.constants:
        check_kernel_expression(e, set(system.parameters), f"the step coefficient {s} of {system.name}")
    return ComplexProgram(system.name, str(comp), len(coords), coords, tuple(system.parameters), variables,
                          time_symbol, tuple(hoister.constants), tuple(factors))


# -- module source --------------------------------------------------------------------------------------

_HEADER = '''"""Generated by nambu_bch.numeric.complex_codegen (template {version}); do not edit.

A composition with complex coefficients: state and times complex128, constants float64.  Every name below is
internal (v_i state, k_j constants, P[i] parameters, T[j] times; _pi and _e the constants); the cache verifies this
file against the digest recorded when it was generated.
"""
import cmath
import math

_exp, _expm1, _log, _sqrt = math.exp, math.expm1, math.log, math.sqrt
_sin, _cos, _tan, _sinh, _cosh, _tanh = math.sin, math.cos, math.tan, math.sinh, math.cosh, math.tanh
_atan, _asin, _acos = math.atan, math.asin, math.acos
_pi, _e, _cpi, _ce = math.pi, math.e, math.pi, math.e  # pi and E under both prefixes (constants, loop)
{loop_functions}
_cisfinite = cmath.isfinite
'''


def complex_source(program: ComplexProgram) -> str:
    """The generated module of a :class:`ComplexProgram`.

    Functions:

    * ``constants(h, P) -> [k_0, ...]`` -- the real constants (:func:`~nambu_bch.numeric.codegen.constants_source`);
    * ``times(h) -> [c_0 h, ...]`` -- the complex times of the factors, ``c_j`` as complex128 times the float ``h``
      (the reference's ``complex(N(c_j, 17)) * h``);
    * ``run(x, T, K, steps, every, out, project)`` -- one trajectory, ``x`` complex128 of shape (N,) (updated to
      the final state), ``out`` complex128 of shape (n_samples, N), ``out[0]`` the start; ``project``: the real part
      after every step; returns the steps done (fewer than ``steps`` only if a sample was not finite);
    * ``run_batch(X, T, K, steps, every, out, project)`` -- every column of ``X`` (N, batch) advanced alone, samples
      into ``out`` (n_samples, N, batch); ``X`` is only read; returns the least number of steps done over the columns.
    """
    N = program.N
    v = [str(s) for s in program.variables]
    lines = []
    for j, (_, _, _, moves) in enumerate(program.factors):
        lines.append(f"{program.time} = t{j}")
        lines += [f"w{i} = {print_python(e, '_c')}" for i, e in moves]
        lines += [f"{v[i]} = w{i}" for i, _ in moves]
    project = ["if project:", *(f"    {s} = complex({s}.real, 0.0)" for s in v)] if lines else []
    step = lines + project
    consts = [f"k{j} = K[{j}]" for j in range(len(program.constants))]
    consts += [f"t{j} = T[{j}]" for j in range(len(program.factors))]
    finite = " and ".join(f"_cisfinite({s})" for s in v)
    values = ", ".join(f"complex({value.real!r}, {value.imag!r}) * h" for _, _, value, _ in program.factors)

    def loop(index, indent):
        sample = ["; ".join(f"out[j, {i}{index}] = {s}" for i, s in enumerate(v))]
        return _indent(_sampling_loop(step, sample, [f"if not ({finite}):", "    break"]), indent)

    # the loop calls only entire functions of the state (everything else is hoisted), each as cmath's
    names = [f.__name__ for f in ENTIRE]
    loop_functions = f"{', '.join('_c' + n for n in names)} = {', '.join('cmath.' + n for n in names)}"
    header = _HEADER.format(version=ComplexKernel.template, loop_functions=loop_functions)
    return f"""{header}{constants_source(program)}

def times(h):
    return [{values}]


def run(x, T, K, steps, every, out, project):
{_indent(consts or ["pass"], 4)}
    {"; ".join(f"{s} = x[{i}]" for i, s in enumerate(v))}
{loop("", 4)}
    {"; ".join(f"x[{i}] = {s}" for i, s in enumerate(v))}
    return n


def run_batch(X, T, K, steps, every, out, project):
{_indent(consts or ["pass"], 4)}
    done = steps
    for b in range(X.shape[1]):
        {"; ".join(f"{s} = X[{i}, b]" for i, s in enumerate(v))}
{loop(", b", 8)}
        if n < done:
            done = n
    return done
"""


def _template() -> str:
    """The template an index of a complex kernel records: the version and a digest of this generator's code."""
    try:
        digest = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]
    except OSError:  # pragma: no cover - no source on disk (frozen): the version alone
        digest = "frozen"
    return f"complex-{COMPLEX_TEMPLATE_VERSION}-{digest}"


class ComplexKernel(Kernel):
    """The compiled complex128 loops of one ``(system, composition with complex coefficients)``.

    A :class:`~nambu_bch.numeric.kernels.Kernel` whose module is :func:`complex_source`: the same private
    verified cache (index, digest-checked source, numba's machine code), the same compile-on-first-use.  The
    loops are ``run`` and ``run_batch``; :meth:`constants` returns the complex times and the real constants.
    """

    template = _template()
    functions = ("constants", "times", "run", "run_batch")
    c_library = False   # numeric.clib prints the real step program only

    @staticmethod
    def _render(program) -> tuple:
        return complex_source(program), len(program.constants), ()

    @property
    def program(self):
        """The :class:`ComplexProgram` (derived with sympy on first access)."""
        return complex_program(self.system, self.composition)

    def constants(self, h, params=None) -> tuple:
        """``(T, K)``: the complex times ``c_j h`` (complex128) and the real constants ``k_j(params)`` (float64,
        :meth:`Kernel.constants <nambu_bch.numeric.kernels.Kernel.constants>`, its errors included)."""
        K = super().constants(h, params)
        T = np.array(self.module.times(float(h)), dtype=np.complex128).reshape(-1)
        if not np.all(np.isfinite(T)):
            raise NumericalRangeError(f"h = {float(h):g}: a complex time c_j h of the step overflows complex128; "
                                      "take a smaller h")
        return T, K

    def _first_call(self, fn, kahan, batch):
        N = self.N
        T = np.zeros(max(1, len(self.module.times(0.0))), dtype=np.complex128)
        K = np.zeros(max(1, self.n_constants))
        if batch:
            fn(np.zeros((N, 1), dtype=np.complex128), T, K, 1, 1, np.zeros((2, N, 1), dtype=np.complex128), False)
        else:
            fn(np.zeros(N, dtype=np.complex128), T, K, 1, 1, np.zeros((2, N), dtype=np.complex128), False)

    def run(self, x, T, K, steps, every, out, *, project=False) -> int:
        """Advance one state ``x`` (complex128, shape (N,), in place) on the compiled loop; ``out[1:]`` is filled.
        Returns the number of steps done (fewer than ``steps`` only if a sample was not finite)."""
        self.compile()
        return int(self.function("run")(x, T, K, int(steps), int(every), out, bool(project)))

    def run_batch(self, X, T, K, steps, every, out, *, project=False) -> int:
        """Advance every column of ``X`` (complex128, shape (N, batch), only read) on the compiled loop; ``out[1:]``
        is filled.  Returns the least number of steps done over the columns."""
        self.compile(batch=True)
        return int(self.function("run_batch")(X, T, K, int(steps), int(every), out, bool(project)))


def complex_kernel(system, word) -> ComplexKernel:
    """The :class:`ComplexKernel` of ``word`` (complex coefficients) on ``system`` (memoised in the process, cached
    on disk across processes)."""
    from ..systems.spec import as_system

    system = as_system(system)
    comp = composition_for(word, system.splitting)
    key = (system, comp, str(cache_dir()))
    kern = _KERNELS.get(key)
    if kern is None:
        if not comp.is_complex:
            raise InvalidRunError(f"composition {comp.name[:60]!r} has real coefficients: its compiled loops are the "
                                  "float64 kernels (nambu_bch.numeric.kernels.kernel)")
        if len(_KERNELS) >= MAX_KERNELS:  # the oldest goes: a process rarely runs many complex compositions
            _KERNELS.pop(next(iter(_KERNELS)))
        kern = _KERNELS[key] = ComplexKernel(system, comp)
    return kern


def compiled_in_process(system, comp, batch: bool) -> bool:
    """Whether this process already holds the complex kernel of ``comp`` on ``system`` with its loop compiled or
    loaded (running it then costs nothing extra); never generates anything."""
    kern = _KERNELS.get((system, comp, str(cache_dir())))
    return kern is not None and kern.loop_name(batch=batch) in kern.compile_seconds


#: Complex kernels kept in the process (the oldest is dropped beyond it).
MAX_KERNELS = 64
_KERNELS: dict = {}
