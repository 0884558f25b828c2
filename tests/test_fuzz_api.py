"""Property-based hardening of the Python API: every public callable, adversarial arguments, one exception family.

Each public function of ``nambu_bch`` and of its subpackages (the names pinned in tests/test_public_api.py, plus
``nambu_bch.testing``) is called with a cheap valid call (:data:`BASE`) in which one or two arguments are replaced
by adversarial values (tests/strategies.py: wrong types, ``None``, bools, nan/inf/-0.0, ``10**400``, zero and
negative counts, empty, huge and hostile strings, unicode, control characters, numpy arrays of the wrong shape or
dtype, nested containers, unknown model names, bad words).  The contract: the call returns, or raises a subclass of
:class:`nambu_bch.NambuBCHError` whose message is one non-empty line; any other exception fails, and so does a
string that was run as Python code.

Finite numbers in the strategies are small (or huge enough to be refused), and the valid calls are small, so that
an accepted argument never starts a long computation.  ``NAMBU_BCH_FUZZ_EXAMPLES`` sets the number of examples per
callable (default 8; e.g. 500 for a long local run), see docs/hardening.md.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import inspect
import itertools
import os
import sys

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from strategies import CODE_MARKER, PAYLOADS, adversarial_values

from nambu_bch import NambuBCHError

EXAMPLES = int(os.environ.get("NAMBU_BCH_FUZZ_EXAMPLES", "6"))
#: Callables whose valid call takes seconds (drawing figures, timing runs): examples divided by this factor.
COSTLY = {"nambu_bch.paper_figures": EXAMPLES, "nambu_bch.numeric.precision_study": 2, "nambu_bch.shadow.decide": 2}


def fuzz_settings(qualname):
    # no "explain" phase: it traces every line of a failing call again, which is slow for the numeric calls
    return settings(derandomize=True, deadline=None, database=None, max_examples=max(1, EXAMPLES // COSTLY.get(qualname, 1)),
                    phases=(Phase.explicit, Phase.generate, Phase.shrink),
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large])

#: The public modules: the package and the subpackages whose ``__all__`` tests/test_public_api.py pins, and the
#: pytest helpers (their expression arguments are user text too).
MODULES = ("nambu_bch", "nambu_bch.algebra", "nambu_bch.bch", "nambu_bch.cli", "nambu_bch.design", "nambu_bch.exact",
           "nambu_bch.integrators", "nambu_bch.numeric", "nambu_bch.shadow", "nambu_bch.systems", "nambu_bch.testing")

#: Public callables that are not called here, and why.  Everything else needs an entry in :data:`BASE`.
NOT_FUZZED = {
    "nambu_bch.cli.main": "the command line: tests/test_fuzz_cli.py drives it with random argv",
    "nambu_bch.NambuBCHError": "an exception class", "nambu_bch.cli.UsageError": "an exception class",
    "nambu_bch.design.NoSolutionError": "an exception class",
    "nambu_bch.algebra.ExactRing": "a protocol (the declared ring interface), never constructed",
    "nambu_bch.sweep": "runs the caller's function on the caller's tasks and raises their exceptions unchanged, as "
                       "the serial loop would; its own arguments: tests/test_parallel.py",
}
#: Result records: built by the library and returned to the user, who reads them; their constructors store fields.
RECORDS = (
    "ConservedQuantities", "EffectiveField", "ExactShadow", "FormalBCH", "ModifiedSolution", "ShadowFamily",
    "Splitting", "CatalogComposition", "Comparison", "DesignedComposition", "ErrorConstant", "LeadingError",
    "OrderConditions", "Template", "LinearCore", "ExactFlow", "CheckResult", "DriftFit", "FigureSet", "HScan", "Kernel",
    "OrderFit", "PrecisionStudy", "StepProgram", "TruncationStudy", "DirectResult", "Existence", "FICommutator",
    "FINested", "FIOrder", "FIRepresentation", "FIResult", "OrderSolution", "Piece", "FieldBackend",
    "ExpressionBackend", "PolynomialBackend", "ShadowTrajectory", "ButcherTableau", "SeparableShadow", "ContractionSum",
    "Contraction", "NumericalShadow", "ModifiedEquation", "MonteCarloRun", "Estimate", "GradientField", "GradientShadow",
    "GradientCheck", "DensityBrackets",
)


def public_callables() -> dict:
    """``{qualified name: object}`` of every callable in the public modules' ``__all__`` (first home wins)."""
    out, seen = {}, set()
    for module in MODULES:
        mod = importlib.import_module(module)
        for name in mod.__all__:
            obj = getattr(mod, name)
            if not callable(obj) or inspect.ismodule(obj) or id(obj) in seen:
                continue
            seen.add(id(obj))
            out[f"{module}.{name}"] = obj
    return out


# --------------------------------------------------------------------------------------------
# valid, cheap calls: the arguments that are not replaced
# --------------------------------------------------------------------------------------------
@functools.lru_cache(maxsize=None)
def valid():
    """Small valid objects shared by the base calls (built once per process)."""
    import sympy

    from nambu_bch import PolynomialAlgebra, VectorField, composition, direct_route, full_split, model, shadow_hamiltonians

    ho3 = model("ho3")
    x1, x2, x3 = ho3.coordinates
    alg = PolynomialAlgebra(ho3.coordinates, ho3.parameters)
    family = shadow_hamiltonians(ho3, "12321")
    return dict(
        ho3=ho3, ho=model("ho"), x=(x1, x2, x3), alg=alg, split=full_split(ho3), comp=composition("12321"),
        field=VectorField(alg, [x2, -x1, 0]), H=ho3.hamiltonians[0], G=ho3.hamiltonians[1], sympy=sympy,
        piece=full_split(ho3).pieces[0], AC=ho3.splitting[1].terms[0], BD=ho3.splitting[2].terms[0],
        lie_trotter=direct_route(ho3, "123", 1), H_S=family.H_S, G_S=family.G_S, ho_qp=_verlet_ho(),
    )


def _verlet_ho(h=0.1, steps=8):
    """Velocity Verlet samples ``(q, p)`` of q'' = -q from (1, 0): a valid trajectory for ``numerical_shadow``."""
    q, p, qs, ps = 1.0, 0.0, [1.0], [0.0]
    for _ in range(steps):
        p -= h / 2 * q
        q += h * p
        p -= h / 2 * q
        qs.append(q), ps.append(p)
    return qs, ps


def _base_table():
    """``{qualified name: v -> {parameter: value}}``: a cheap valid call of each callable (``"*"``: the ``*args``)."""
    sys3 = lambda v: dict(system=v["ho3"], word="12321")  # noqa: E731
    num = lambda v: dict(system=v["ho3"], word="12321", h=0.1, steps=10, x0=(1.0, 1.0, 1.0))  # noqa: E731
    return {
        "nambu_bch.clear_caches": lambda v: {},
        "nambu_bch.cli.build_parser": lambda v: {},
        # systems
        "nambu_bch.System": lambda v: dict(coordinates=v["x"], hamiltonians=(v["H"], v["G"]), parameters=v["ho3"].parameters),
        "nambu_bch.model": lambda v: dict(name="ho3"),
        "nambu_bch.model_names": lambda v: {},
        "nambu_bch.systems.full_split": lambda v: dict(system=v["ho3"]),
        "nambu_bch.systems.single_split": lambda v: dict(system=v["ho3"]),
        "nambu_bch.systems.separate": lambda v: dict(expr=v["H"], coordinates=v["x"]),
        "nambu_bch.systems.canonical_split": lambda v: dict(system=v["ho"]),
        "nambu_bch.systems.triplet_split": lambda v: dict(system=v["ho3"]),
        "nambu_bch.systems.infer_bracket": lambda v: dict(n_coords=3, n_hams=2),
        "nambu_bch.systems.is_separable": lambda v: dict(expr=v["H"], coordinates=v["x"]),
        # algebra
        "nambu_bch.algebra.PolynomialAlgebra": lambda v: dict(coordinates=v["x"]),
        "nambu_bch.algebra.VectorField": lambda v: dict(algebra=v["alg"], components=[v["x"][1], -v["x"][0], 0]),
        "nambu_bch.algebra.is_symplectic": lambda v: dict(map_components=v["x"][:2], coordinates=v["x"][:2]),
        "nambu_bch.algebra.satisfies_nambu_condition": lambda v: dict(map_components=v["x"], coordinates=v["x"]),
        "nambu_bch.algebra.lie_bracket": lambda v: dict(X=v["field"], Y=v["field"]),
        "nambu_bch.algebra.liouville_field": lambda v: {"algebra": v["alg"], "*": (v["H"], v["G"])},
        "nambu_bch.algebra.nambu_bracket": lambda v: {"algebra": v["alg"], "*": (v["x"][0], v["H"], v["G"])},
        "nambu_bch.algebra.poisson_bracket": lambda v: dict(algebra=v["ho"].algebra, A=v["x"][0], B=v["x"][1]),
        "nambu_bch.algebra.field_backend": lambda v: dict(algebra=v["alg"], fields={}),
        "nambu_bch.algebra.jacobian": lambda v: dict(map_components=v["x"], coordinates=v["x"]),
        # integrators
        "nambu_bch.Composition": lambda v: dict(pieces=(1, 2, 1), coefficients=(v["sympy"].Rational(1, 2), 1,
                                                                                 v["sympy"].Rational(1, 2))),
        "nambu_bch.composition": lambda v: dict(spec="12321"),
        "nambu_bch.integrators.composed_map": lambda v: dict(splitting=v["split"], comp=v["comp"]),
        "nambu_bch.integrators.exact_flow": lambda v: dict(piece=v["piece"], coordinates=v["x"]),
        "nambu_bch.integrators.step_function": lambda v: dict(splitting=v["split"], comp=v["comp"]),
        "nambu_bch.integrators.composition_for": lambda v: dict(spec="12321", target=v["ho3"]),
        "nambu_bch.integrators.parameter_values": lambda v: dict(system=v["ho3"]),
        "nambu_bch.integrators.strang_word": lambda v: dict(n=3),
        "nambu_bch.integrators.subflow_functions": lambda v: dict(splitting=v["split"], comp=v["comp"]),
        # bch
        "nambu_bch.formal_bch": lambda v: dict(comp=v["comp"], max_degree=3),
        "nambu_bch.effective_field": lambda v: dict(splitting=v["split"], comp=v["comp"]),
        "nambu_bch.bch.effective_field_bch": lambda v: dict(splitting=v["split"], comp=v["comp"]),
        "nambu_bch.bch.expand_terms": lambda v: dict(terms=[((1, 2), 1)], splitting=v["split"]),
        "nambu_bch.bch.BracketEvaluator": lambda v: dict(leaf_value=lambda k: k),
        "nambu_bch.bch.check_order": lambda v: dict(order=2),
        "nambu_bch.bch.clear_cache": lambda v: {},
        "nambu_bch.bch.estimate_size": lambda v: dict(n_generators=3, max_degree=3),
        "nambu_bch.bch.is_bracket": lambda v: dict(tree=(1, 2)),
        "nambu_bch.bch.lie_to_associative": lambda v: dict(terms=[(1, (1, 2))]),
        "nambu_bch.bch.lyndon_words": lambda v: dict(n_letters=2, degree=3),
        "nambu_bch.bch.standard_bracketing": lambda v: dict(word=(1, 2)),
        "nambu_bch.bch.terms_to_latex": lambda v: dict(terms=[((1, 2), 1)]),
        "nambu_bch.bch.tree_degree": lambda v: dict(tree=(1, 2)),
        "nambu_bch.bch.tree_to_associative": lambda v: dict(tree=(1, 2)),
        "nambu_bch.bch.tree_to_latex": lambda v: dict(tree=(1, 2)),
        "nambu_bch.bch.witt_dimension": lambda v: dict(n_letters=2, degree=3),
        # shadow
        "nambu_bch.shadow_hamiltonians": sys3,
        "nambu_bch.shadow.direct_route": sys3,
        "nambu_bch.shadow.fi_route": sys3,
        "nambu_bch.shadow.representations": lambda v: dict(algebra=v["alg"], a=v["AC"], b=v["AC"], c=v["BD"]),
        "nambu_bch.shadow.LiouvilleSum": lambda v: dict(algebra=v["alg"]),
        "nambu_bch.shadow.LiouvilleTerm": lambda v: dict(slots=(v["x"][0], v["x"][1])),
        "nambu_bch.shadow.JetAlgebra": lambda v: dict(coordinates=v["x"], functions=("f",), max_order=2),
        "nambu_bch.shadow.commutator_terms": lambda v: dict(algebra=v["alg"], left=v["AC"], right=v["BD"],
                                                            way="a"),
        "nambu_bch.shadow.count_brackets": lambda v: dict(system=v["ho3"], word="12321", order=2),
        "nambu_bch.shadow.decide": lambda v: dict(result=v["lie_trotter"], measure=False),
        "nambu_bch.shadow.double_commutator_terms": lambda v: dict(algebra=v["alg"], a=v["AC"], b=v["AC"], c=v["BD"],
                                                                   label="1AX"),
        "nambu_bch.shadow.fi_brackets": lambda v: dict(system=v["ho3"], word="12321", order=2),
        "nambu_bch.shadow.separable_shadow": lambda v: dict(word="212", order=2, d=2),
        "nambu_bch.algebra.CoefficientField": lambda v: dict(domain=v["sympy"].QQ),
        "nambu_bch.shadow.density_shadow": lambda v: dict(system=v["ho3"], method="midpoint", density=1, order=2),
        "nambu_bch.shadow.density_brackets": lambda v: dict(system=v["ho3"], method="midpoint", order=2, density=1),
        # exact
        "nambu_bch.exact.F": lambda v: dict(x=0.5),
        "nambu_bch.exact.F_series": lambda v: dict(x=v["sympy"].Symbol("z"), order=4),
        "nambu_bch.conserved_quantities": sys3,
        "nambu_bch.exact_shadow_hamiltonians": sys3,
        "nambu_bch.exact.is_invariant": lambda v: dict(system=v["ho3"], word="12321", quantity=v["G"]),
        "nambu_bch.exact.modified_equations": lambda v: dict(system=v["ho3"], word="12321", kind="s"),
        "nambu_bch.modified_solution": lambda v: dict(system=v["ho3"], word="12321", kind="s"),
        # Runge-Kutta methods
        "nambu_bch.integrators.butcher_tableau": lambda v: dict(method="midpoint"),
        "nambu_bch.modified_equation": lambda v: dict(system=v["ho3"], method="midpoint", order=2),
        "nambu_bch.runge_kutta_shadow": lambda v: dict(system=v["ho3"], method="midpoint", order=2),
        "nambu_bch.numeric.rk_iterate": lambda v: dict(system=v["ho3"], method="midpoint", h=0.1, steps=10,
                                                       x0=(1.0, 1.0, 1.0)),
        "nambu_bch.numeric.rk_step_function": lambda v: dict(system=v["ho3"], method="midpoint"),
        "nambu_bch.exact.linear_core": lambda v: dict(coordinates=v["x"][:2], rhs=(v["x"][1], -v["x"][0])),
        # design
        "nambu_bch.compare": lambda v: dict(system=v["ho3"], words=("12321",), t_end=1.0, steps=(4, 8), samples=5),
        "nambu_bch.composition_order": lambda v: dict(spec="12321"),
        "nambu_bch.design.runge_kutta_error_constant": lambda v: dict(method="midpoint"),
        "nambu_bch.error_constant": lambda v: dict(spec="121", parts=2),
        "nambu_bch.leading_error": lambda v: dict(system=v["ho3"], word="12321", samples=5),
        "nambu_bch.optimize_composition": lambda v: dict(spec="strang", parts=2, order=4, stages=3, starts=1, dps=15),
        "nambu_bch.order_conditions": lambda v: dict(spec="strang", order=2, parts=2, stages=1),
        "nambu_bch.design.cost": lambda v: dict(comp=v["comp"]),
        "nambu_bch.design.error_analysis": lambda v: dict(spec="121", parts=2),
        "nambu_bch.design.field_size": lambda v: dict(components=(v["x"][1], -v["x"][0], 0), system=v["ho3"], samples=5),
        "nambu_bch.design.methods": lambda v: {},
        "nambu_bch.design.gradient_effective_field": lambda v: dict(system=v["ho"], spec="chin-4a", order=2),
        "nambu_bch.design.gradient_shadow": lambda v: dict(system=v["ho"], spec="chin-4a", order=2),
        "nambu_bch.design.template": lambda v: dict(spec="strang", parts=2, stages=1),
        # numeric
        "nambu_bch.check": num,
        "nambu_bch.iterate": num,
        "nambu_bch.numeric.iterate_chunks": num,
        "nambu_bch.numeric.iterate_gradient": lambda v: dict(system=v["ho"], spec="chin-4a", h=0.1, steps=10, x0=(1.0, 0.0)),
        "nambu_bch.numeric.iterate_processed": lambda v: dict(system=v["ho"], kernel="takahashi-imada", h=0.1, steps=10,
                                                              x0=(1.0, 0.0)),
        "nambu_bch.numeric.gradient_check": lambda v: dict(system=v["ho"], method="chin-4a", h=0.2, steps=5, x0=(1.0, 0.0),
                                                           halvings=1),
        "nambu_bch.numeric.iterate_complex": lambda v: dict(system=v["ho"], word="1:1/2+I/2,2:1,1:1/2-I/2", h=0.1,
                                                           steps=10, x0=(1.0, 0.0)),
        "nambu_bch.numeric.sample_times": lambda v: dict(h=0.1, steps=10),
        "nambu_bch.shadow_along": lambda v: dict(system=v["ho3"], word="12321", trajectory=[[1.0, 1.0, 1.0]] * 4, h=0.1,
                                                 which=("H", "H_S")),
        "nambu_bch.numeric.numerical_shadow": lambda v: dict(q=v["ho_qp"][0], p=v["ho_qp"][1], forces_or_system=v["ho"],
                                                             h=0.1),
        "nambu_bch.numeric.hybrid_monte_carlo": lambda v: dict(system=v["ho"], word="212", h=0.5, steps=2, chains=20,
                                                               iterations=2, burn=0, seed=0),
        "nambu_bch.paper_figures": lambda v: dict(outdir="figures", t_short=1.0, t_long=2.0, every_long=1, dpi=10),
        "nambu_bch.numeric.Progress": lambda v: dict(total=10, enabled=False),
        "nambu_bch.numeric.RunningStats": lambda v: {},
        "nambu_bch.numeric.cache_dir": lambda v: {},
        "nambu_bch.numeric.drift_rate": lambda v: dict(t=[0.0, 1.0, 2.0], values=[0.0, 1.0, 2.0]),
        "nambu_bch.numeric.fit_order": lambda v: dict(hs=[0.1, 0.05], errors=[1e-2, 2.5e-3]),
        "nambu_bch.numeric.h_scan": lambda v: dict(system=v["ho3"], word="12321", hs=(0.1, 0.2), steps=10),
        "nambu_bch.numeric.kernel": sys3,
        "nambu_bch.numeric.n_samples": lambda v: dict(steps=10, every=1),
        "nambu_bch.numeric.numba_available": lambda v: {},
        "nambu_bch.numeric.observed_order": lambda v: dict(system=v["ho3"], word="12321", hs=(0.1, 0.05), T=0.2,
                                                           x0=(1.0, 1.0, 1.0)),
        # the interpreter: compiling the two loops it times (1 s cold) is no concern of the argument checks
        "nambu_bch.numeric.precision_study": lambda v: dict(system=v["ho3"], word="12321", steps=10, every=5,
                                                            mp_steps=5, dps=15, repeats=1, timing_steps=10,
                                                            backend="numpy"),
        "nambu_bch.numeric.quantities": lambda v: dict(system=v["ho3"], word="12321", h=0.1),
        "nambu_bch.numeric.sample_steps": lambda v: dict(steps=10),
        "nambu_bch.numeric.step_program": sys3,
        "nambu_bch.numeric.truncation_study": lambda v: dict(system=v["ho3"], word="12321", orders=(2,), steps=10,
                                                             every=5),
        # pytest helpers
        "nambu_bch.testing.assert_fields_equal": lambda v: dict(X=v["field"], Y=v["field"]),
        "nambu_bch.testing.assert_invariant": lambda v: dict(system=v["ho3"], word="12321", I="x3 - x1^2 + h^2*x2^2/(4*m^2)"),
        "nambu_bch.testing.assert_shadow_pair": lambda v: dict(system=v["ho3"], word="12321", H_S=v["H_S"], G_S=v["G_S"]),
        "nambu_bch.testing.liouville_components": lambda v: {"coordinates": v["x"], "*": (v["H"], v["G"])},
    }


BASE = _base_table()
#: The pytest helpers raise ``AssertionError`` by design when their check fails (with a multi-line report).
ASSERTIONS = {"nambu_bch.testing.assert_fields_equal", "nambu_bch.testing.assert_invariant",
              "nambu_bch.testing.assert_shadow_pair"}


def _is_record(qualname: str) -> bool:
    return qualname.rsplit(".", 1)[1] in RECORDS


def fuzzed() -> list:
    return sorted(q for q in public_callables() if q not in NOT_FUZZED and not _is_record(q))


def parameters(obj) -> list:
    """The names a call may replace: the signature's parameters (``"*"`` for ``*args``; ``**kwargs`` left out)."""
    out = []
    for p in inspect.signature(obj).parameters.values():
        if p.kind is p.VAR_POSITIONAL:
            out.append("*")
        elif p.kind is not p.VAR_KEYWORD and not p.name.startswith("_"):
            out.append(p.name)
    return out


def required(obj) -> set:
    return {p.name for p in inspect.signature(obj).parameters.values()
            if p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)}


# --------------------------------------------------------------------------------------------
# the table covers the surface
# --------------------------------------------------------------------------------------------
def test_every_public_callable_is_covered():
    """A new public callable fails here until it has a base call in BASE (or a reason in NOT_FUZZED / RECORDS)."""
    assert sorted(set(fuzzed()) - set(BASE)) == []
    assert sorted(set(BASE) - set(fuzzed())) == []  # no stale entries
    assert sorted(set(NOT_FUZZED) - set(public_callables())) == []
    for qualname, obj in public_callables().items():
        if qualname in BASE:  # the base call names every required parameter, and only real ones
            names = set(BASE[qualname](valid()))
            assert required(obj) <= names, f"{qualname}: the base call lacks {sorted(required(obj) - names)}"
            assert names <= set(parameters(obj)), f"{qualname}: unknown parameters {sorted(names - set(parameters(obj)))}"


# --------------------------------------------------------------------------------------------
# the property
# --------------------------------------------------------------------------------------------
def _invoke(obj, kwargs):
    """``obj(**kwargs)``; with ``"*"`` the parameters before ``*args`` go by position, then the ``*args``."""
    kwargs = dict(kwargs)
    if "*" not in kwargs:
        return obj(**kwargs)
    star = kwargs.pop("*")
    names = parameters(obj)
    positional = [kwargs.pop(n) for n in names[: names.index("*")] if n in kwargs]
    if not isinstance(star, (list, tuple)):
        star = (star,)
    return obj(*positional, *star, **kwargs)


def _consume(result):
    """Run a lazy result far enough to see its errors (a generator of chunks)."""
    if inspect.isgenerator(result):
        for _ in itertools.islice(result, 3):
            pass
    return result


def _short(value, limit=70) -> str:
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**20:
        return f"{'-' if value < 0 else ''}<{len(str(abs(value)))}-digit int>"
    try:
        text = repr(value)
    except Exception as exc:  # noqa: BLE001  (a value whose repr fails still names its type)
        text = f"<{type(value).__name__}: repr raised {type(exc).__name__}>"
    return text if len(text) <= limit else text[: limit - 12] + f"...<{len(text)}>"


def describe(qualname, kwargs) -> str:
    return f"{qualname}({', '.join(f'{k}={_short(v)}' for k, v in kwargs.items())})"


def check_call(qualname, obj, kwargs):
    """Call ``obj(**kwargs)``: it returns or raises a one-line NambuBCHError; no string is run as code."""
    sys.modules.pop(CODE_MARKER, None)
    problem = None
    try:
        _consume(_invoke(obj, kwargs))
    except NambuBCHError as exc:
        message = str(exc)
        if not message.strip() or "\n" in message or "\r" in message:
            problem = f"raised {type(exc).__name__} with a message that is not one line: {_short(message, 200)}"
    except AssertionError as exc:
        if qualname not in ASSERTIONS:
            problem = f"raised AssertionError: {_short(str(exc), 160)}"
    except Exception as exc:  # noqa: BLE001  (the point: anything outside the family is a failure, named)
        problem = f"raised {type(exc).__name__}: {_short((str(exc).splitlines() or [''])[0], 160)}"
    if sys.modules.pop(CODE_MARKER, None) is not None:
        pytest.fail(f"{describe(qualname, kwargs)} ran a string argument as Python code"
                    + (f" (and then {problem})" if problem else ""), pytrace=False)
    if problem:
        pytest.fail(f"{describe(qualname, kwargs)} {problem}", pytrace=False)


@contextlib.contextmanager
def deep_cwd(root, depth=12):
    """Work ``depth`` directories below ``root``: a relative path a value may form (``../``) stays under ``root``."""
    path = root.joinpath(*(f"d{i}" for i in range(depth)))
    path.mkdir(parents=True, exist_ok=True)
    old = os.getcwd()
    os.chdir(path)
    try:
        yield path
    finally:
        os.chdir(old)


@st.composite
def fuzzed_call(draw, qualname):
    """The base call of ``qualname`` with one or two of its parameters replaced by adversarial values."""
    obj = public_callables()[qualname]
    kwargs = BASE[qualname](valid())
    names = parameters(obj)
    if not names:
        return kwargs
    chosen = draw(st.lists(st.sampled_from(names), min_size=1, max_size=min(2, len(names)), unique=True))
    for name in chosen:
        if name == "*":
            kwargs["*"] = draw(st.lists(adversarial_values(), max_size=3))
        else:
            kwargs[name] = draw(adversarial_values())
    return kwargs


@pytest.mark.parametrize("qualname", sorted(BASE))
def test_public_callable_raises_only_the_family(qualname, tmp_path_factory):
    """Adversarial arguments: the call returns or raises a one-line NambuBCHError (see the module docstring)."""
    obj = public_callables()[qualname]
    root = tmp_path_factory.mktemp("fuzz")
    with deep_cwd(root):  # the base call returns: in a fuzzed call, a replaced argument is all that is wrong
        _consume(_invoke(obj, BASE[qualname](valid())))

    @fuzz_settings(qualname)
    @given(kwargs=fuzzed_call(qualname))
    def run(kwargs):
        with deep_cwd(root):
            check_call(qualname, obj, kwargs)

    run()


@pytest.mark.parametrize("qualname", sorted(BASE))
def test_no_string_argument_is_run_as_code(qualname, tmp_path):
    """Each parameter in turn receives a Python payload, as the string and as the elements of a list (for the
    callables in COSTLY only the form that fits: a list where the parameter holds a sequence): never evaluated."""
    obj = public_callables()[qualname]
    defaults = {p.name: p.default for p in inspect.signature(obj).parameters.values()}
    failures = []
    for name in parameters(obj):
        usual = BASE[qualname](valid()).get(name, defaults.get(name))
        as_list = [PAYLOADS[0]] * max(1, len(usual) if isinstance(usual, (list, tuple)) else 3)
        if qualname not in COSTLY:
            forms = (PAYLOADS[0], as_list)
        else:
            forms = (as_list,) if name == "*" or (isinstance(usual, (list, tuple)) and usual) else (PAYLOADS[0],)
        for value in forms:
            kwargs = BASE[qualname](valid())
            kwargs[name] = value
            with deep_cwd(tmp_path):
                try:
                    check_call(qualname, obj, kwargs)
                except pytest.fail.Exception as exc:  # every parameter is tried; code execution is listed first
                    failures.append(str(exc))
    failures.sort(key=lambda text: "as Python code" not in text)
    assert not failures, "\n".join(failures)
