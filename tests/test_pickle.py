"""Every public result pickles and unpickles to an equal result, also across processes.

Results go back from joblib, Dask and multiprocessing workers by pickle; the rings and coefficient
fields inside them pickle as a plain exact description (:mod:`nambu_bch.algebra.polynomial`).
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import json
import pickle

import numpy as np
import pytest
import sympy

import nambu_bch as nb

import shared_results as shared

SUBPACKAGES = ("algebra", "bch", "design", "exact", "integrators", "numeric", "shadow", "systems")


def _ho3():
    return nb.model("ho3")


def _fi_route():
    from nambu_bch.shadow import fi_route
    return fi_route(_ho3(), "12321", order=2)


@functools.lru_cache(maxsize=None)  # the numerical decision (a few seconds), shared by the tests that read it
def _existence():
    return shared.family("rigid-body", "123", 2).existence


def _triple_jump_field():
    return nb.effective_field(nb.model("ho").splitting, "triple-jump:121", order=2)


#: one cheap builder per public result type (the type's name -> a function returning an instance)
BUILDERS = {
    "PolynomialAlgebra": lambda: _ho3().algebra,
    "VectorField": lambda: _ho3().vector_field,
    "EffectiveField": lambda: nb.effective_field(_ho3().splitting, "12321", order=4),
    "FormalBCH": lambda: nb.formal_bch("12321", 3),
    "ButcherTableau": lambda: nb.butcher_tableau("gauss4"),
    "DensityBrackets": lambda: importlib.import_module("nambu_bch.shadow").density_brackets("ho3", "midpoint", 2, density=1),
    "BCHReport": lambda: importlib.import_module("nambu_bch.bch.report").bch_report(_ho3(), nb.composition("12321"), 2,
                                                                                     field=True, terms=True),
    "CatalogComposition": lambda: nb.composition("kahan-li:121"),
    "GradientField": lambda: importlib.import_module("nambu_bch.design").gradient_effective_field("ho", "chin-4a", 2),
    "GradientShadow": lambda: importlib.import_module("nambu_bch.design").gradient_shadow("ho", "chin-4a", 2),
    "GradientCheck": lambda: importlib.import_module("nambu_bch.numeric").gradient_check("ho", "chin-4a", 0.2, 5,
                                                                                         (1.0, 0.0), halvings=1),
    "Comparison": lambda: nb.compare("ho", ["121", "forest-ruth"], t_end=1.0, steps=(10, 20), samples=50),
    "DesignedComposition": lambda: nb.optimize_composition("strang", parts=2, order=4, stages=3),
    "ErrorConstant": lambda: importlib.import_module("nambu_bch.design").error_analysis("strang", 2),
    "LeadingError": lambda: nb.leading_error("ho", "121", samples=50),
    "OrderConditions": lambda: nb.order_conditions("strang", 4, parts=2, stages=3),
    "Template": lambda: importlib.import_module("nambu_bch.design").template("strang", parts=2, stages=3),
    "NoSolutionError": lambda: importlib.import_module("nambu_bch.design").NoSolutionError("no solution"),
    "ConservedQuantities": lambda: nb.conserved_quantities(_ho3(), "32123"),
    "ExactShadow": lambda: nb.exact_shadow_hamiltonians(_ho3(), "12321"),
    "LinearCore": lambda: importlib.import_module("nambu_bch.exact").linear_core(
        sympy.symbols("x1 x2"), (sympy.Symbol("x2"), -sympy.Symbol("x1"))),
    "ModifiedSolution": lambda: nb.modified_solution(nb.model("ho"), "121", "o"),
    "Composition": lambda: nb.composition("12321"),
    "ExactFlow": lambda: nb.exact_flow(_ho3().splitting.pieces[0], _ho3().coordinates),
    "CheckResult": lambda: nb.check(_ho3(), "32123", h=0.1, steps=200, x0=(1, 1, 1)),
    "DriftFit": lambda: importlib.import_module("nambu_bch.numeric").drift_rate([0.0, 1.0, 2.0, 3.0], [0.0, 0.1, 0.2, 0.3]),
    "OrderFit": lambda: importlib.import_module("nambu_bch.numeric").fit_order([0.1, 0.05, 0.025], [1e-2, 2.5e-3, 6.25e-4]),
    "HScan": lambda: importlib.import_module("nambu_bch.numeric").h_scan("ho3", "32123", hs=(0.1, 0.2), steps=50,
                                                                       x0=(1, 1, 1)),
    "TruncationStudy": lambda: importlib.import_module("nambu_bch.numeric").truncation_study(
        "ho3", "32123", orders=(2,), steps=100, every=10, x0=(1, 1, 1)),
    "PrecisionStudy": lambda: importlib.import_module("nambu_bch.numeric").precision_study(
        "ho3", "32123", h=0.1, steps=200, every=10, mp_steps=50, dps=20, repeats=1, timing_steps=100, x0=(1, 1, 1),
        backend="numpy"),  # "auto" would compile (or load) two numba loops for the timings: not what is pickled
    "ShadowTrajectory": lambda: nb.shadow_along(_ho3(), "12321", nb.iterate(_ho3(), "12321", 0.1, 20, (1, 1, 1)), 0.1),
    "NumericalShadow": lambda: importlib.import_module("nambu_bch.numeric").numerical_shadow(
        *np.hsplit(nb.iterate("ho", "212", 0.1, 20, (1.0, 0.0)), 2), "ho", 0.1),
    "MonteCarloRun": lambda: importlib.import_module("nambu_bch.numeric").hybrid_monte_carlo(
        "ho", "212", 0.5, 2, chains=20, iterations=3, seed=0),
    "Estimate": lambda: importlib.import_module("nambu_bch.numeric").Estimate(1.0, 0.1),
    "RunningStats": lambda: importlib.import_module("nambu_bch.numeric").RunningStats(),
    "CoefficientField": lambda: importlib.import_module("nambu_bch.algebra").PolynomialAlgebra(
        sympy.symbols("x1 x2"), [sympy.Symbol("m")], extension=[sympy.cbrt(2)]).coefficient_field,
    "DirectResult": lambda: importlib.import_module("nambu_bch.shadow").direct_route(_ho3(), "12321", order=4),
    "Existence": _existence,
    "FIResult": _fi_route,
    "FIOrder": lambda: importlib.import_module("nambu_bch.shadow").fi_route(_ho3(), "12321", order=4).orders[0],
    "FICommutator": lambda: nb.shadow_hamiltonians(_ho3(), "12321", order=2, route="fi").details.commutators[0],
    "FIRepresentation": lambda: nb.shadow_hamiltonians(_ho3(), "12321", order=2,
                                                       route="fi").details.commutators[0].representations[0],
    "FIBrackets": lambda: importlib.import_module("nambu_bch.shadow").fi_brackets(_ho3(), "12321", 4, limit=3),
    "FINested": lambda: importlib.import_module("nambu_bch.shadow").fi_brackets(_ho3(), "12321", 4, limit=3)[0],
    "FIForms": lambda: importlib.import_module("nambu_bch.shadow.fi_route").fi_forms(_ho3(), "12321"),
    "LiouvilleSum": lambda: nb.shadow_hamiltonians(_ho3(), "12321", order=2,
                                                   route="fi").details.commutators[0].representations[0].formal,
    "LiouvilleTerm": lambda: nb.LiouvilleTerm((sympy.Symbol("x3"), sympy.Symbol("x2") ** 2), 2),
    "OrderSolution": lambda: nb.shadow_hamiltonians(_ho3(), "12321", order=4).corrections._solutions[2],
    "ShadowFamily": lambda: nb.shadow_hamiltonians(_ho3(), "12321", order=4),
    "ModifiedEquation": lambda: nb.modified_equation(nb.model("ho"), "gauss4", order=2),
    "SeparableShadow": lambda: importlib.import_module("nambu_bch.shadow").separable_shadow("212", 4),
    "ContractionSum": lambda: importlib.import_module("nambu_bch.shadow").separable_shadow("212", 2).series[2],
    "Contraction": lambda: importlib.import_module("nambu_bch.shadow").Contraction.of([1, 1], [(0, 1)]),
    "Piece": lambda: _ho3().splitting.pieces[0],
    "Splitting": lambda: _ho3().splitting,
    "System": lambda: _ho3(),
}

#: public classes that are not results (engines, live state, compiled code), with the reason
NOT_RESULTS = {
    "ExpressionBackend": "arithmetic engine of an algebra, rebuilt from it",
    "FieldBackend": "arithmetic engine of an algebra, rebuilt from it",
    "ExactRing": "the declared ring protocol (a typing.Protocol, no instances of its own)",
    "PolynomialBackend": "arithmetic engine of an algebra, rebuilt from it",
    "BracketEvaluator": "a memo of bracket values during one computation",
    "JetAlgebra": "the arithmetic of the non-polynomial route, rebuilt from the system",
    "Progress": "a live progress display",
    "Kernel": "compiled machine code, rebuilt from the per-process cache",
    "StepProgram": "generated source for the compiled kernel, rebuilt per process",
    "FigureSet": "matplotlib figures from paper_figures, minutes of iteration",
}

# extra results of more expensive or less common shapes, also round-tripped
EXTRA = {
    "ShadowFamily rigid-body h^2": lambda: nb.shadow_hamiltonians(nb.model("rigid-body"), "12321", order=2),
    "ShadowFamily ho h^4 fi": lambda: nb.shadow_hamiltonians(nb.model("ho"), "121", order=4, route="fi"),
    "ShadowFamily none": lambda: shared.family("rigid-body", "123", 2),
    "EffectiveField triple jump (cube root of 2)": _triple_jump_field,
}


def _public_result_types() -> set[str]:
    """Classes named in the subpackages' ``__all__`` and classes the public functions return (by annotation)."""
    names = set()
    for sub in SUBPACKAGES:
        module = importlib.import_module(f"nambu_bch.{sub}")
        for name in module.__all__:
            value = getattr(module, name)
            if inspect.isclass(value):
                names.add(name)
            elif inspect.isfunction(value):
                annotation = inspect.signature(value).return_annotation
                text = annotation if isinstance(annotation, str) else getattr(annotation, "__name__", "")
                if text[:1].isupper() and text.isidentifier() and text not in {"Path", "None"}:
                    names.add(text)
    from nambu_bch.bch.report import bch_report
    from nambu_bch.shadow.fi_route import fi_forms

    names |= {inspect.signature(f).return_annotation for f in (bch_report, fi_forms)}
    return names


def test_every_public_result_type_has_a_builder():
    missing = _public_result_types() - set(BUILDERS) - set(NOT_RESULTS)
    assert not missing, f"public result types without a pickle test: {sorted(missing)}"
    assert not set(BUILDERS) & set(NOT_RESULTS)


def _views(result) -> dict:
    """Everything a user reads off a result: printed text, LaTeX, JSON, and == where the type defines it."""
    plain = type(result).__repr__ is object.__repr__ and type(result).__str__ is object.__str__
    out = {} if plain else {"str": str(result)}  # a default repr shows the address
    for name in ("to_latex", "to_dict"):
        method = getattr(result, name, None)
        if callable(method):
            value = method()
            out[name] = json.dumps(value, sort_keys=True, default=str) if name == "to_dict" else value
    return out


def _same(a, b, depth=0) -> bool:
    """Equal exact data: ``==`` where a type defines it; dataclasses and plain objects (``System`` compares by
    identity, so every result holding one would differ from its copy) field by field; arrays elementwise."""
    if type(a) is not type(b):
        return False
    if depth > 30 or a is b:
        return True
    if dataclasses.is_dataclass(a):
        return all(_same(getattr(a, f.name), getattr(b, f.name), depth + 1) for f in dataclasses.fields(a) if f.compare)
    if isinstance(a, np.ndarray):
        return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k], depth + 1) for k in a)
    if isinstance(a, (list, tuple)):
        return (len(a) == len(b) and all(_same(x, y, depth + 1) for x, y in zip(a, b))
                and _same(getattr(a, "__dict__", {}), getattr(b, "__dict__", {}), depth + 1))
    if inspect.isroutine(a):
        return getattr(a, "__qualname__", None) == getattr(b, "__qualname__", None)
    if type(a).__eq__ is object.__eq__ and hasattr(a, "__dict__"):
        return _same(vars(a), vars(b), depth + 1)
    if isinstance(a, sympy.Expr):
        # sympy's own pickle rebuilds an expression through its constructors, so an unevaluated form that
        # solve/factor_terms left (e.g. 2/3 + (a + 2 b)/6) comes back evaluated: the same number
        return a == b or sympy.expand(a - b) == 0
    if isinstance(a, float) and a != a:
        return b != b
    return bool(a == b)


def _round_trip(result):
    copy = pickle.loads(pickle.dumps(result))
    assert type(copy) is type(result)
    assert _views(copy) == _views(result)
    if isinstance(result, Exception):
        assert copy.args == result.args
    else:
        assert _same(copy, result)
    return copy


@pytest.mark.parametrize("name", sorted(BUILDERS))
def test_result_round_trip(name):
    result = BUILDERS[name]()
    assert type(result).__name__ == name
    _round_trip(result)


@pytest.mark.parametrize("name", sorted(EXTRA))
def test_more_results_round_trip(name):
    _round_trip(EXTRA[name]())


#: the result types that compare by value (``==`` and ``hash`` on their exact data, :mod:`nambu_bch.values`)
VALUE_TYPES = ("ShadowFamily", "EffectiveField", "FormalBCH", "ConservedQuantities", "ExactShadow", "ModifiedSolution",
               "ShadowTrajectory", "Existence", "ModifiedEquation")


@pytest.mark.parametrize("name", VALUE_TYPES)
def test_copy_is_equal(name):
    """``pickle.loads(pickle.dumps(r)) == r`` with the same hash: equality on the exact data, not on identity."""
    result = BUILDERS[name]()
    copy = pickle.loads(pickle.dumps(result))
    assert copy == result and result == copy and hash(copy) == hash(result)
    assert copy != object() and (copy == None) is False  # noqa: E711  (NotImplemented, then identity)
    assert pickle.loads(pickle.dumps(copy)) == result  # a copy's key, computed for ==, is not pickled stale


@pytest.mark.parametrize("name", ["FormalBCH triple jump", "EffectiveField triple jump (cube root of 2)"])
def test_copy_is_equal_over_an_algebraic_field(name):
    """Coefficients in QQ<2^(1/3)> (the triple jump) compare and hash as exact field elements after a round trip."""
    result = {"FormalBCH triple jump": lambda: nb.formal_bch("triple-jump:121", 3), **EXTRA}[name]()
    copy = pickle.loads(pickle.dumps(result))
    assert copy == result and hash(copy) == hash(result)


def test_different_results_differ():
    """Results of different requests compare unequal (the key is not too coarse)."""
    ho3 = _ho3()
    pairs = [
        (nb.shadow_hamiltonians(ho3, "12321", order=4), nb.shadow_hamiltonians(ho3, "32123", order=4)),
        (nb.shadow_hamiltonians(ho3, "12321", order=4), nb.shadow_hamiltonians(ho3, "12321", order=2)),
        (nb.shadow_hamiltonians(nb.model("ho"), "121", order=4, route="fi"),
         nb.shadow_hamiltonians(nb.model("ho"), "121", order=4)),
        (nb.effective_field(ho3.splitting, "12321", order=4), nb.effective_field(ho3.splitting, "32123", order=4)),
        (nb.formal_bch("12321", 3), nb.formal_bch("121", 3)),
        (nb.conserved_quantities(ho3, "32123"), nb.conserved_quantities(ho3, "12321")),
        (nb.modified_equation(nb.model("ho"), "gauss4", order=2),
         nb.modified_equation(nb.model("ho"), "midpoint", order=2)),
    ]
    for a, b in pairs:
        assert a != b and not a == b, type(a).__name__
    # the same request twice: equal although every object inside (the systems too) is a new one
    assert nb.shadow_hamiltonians(nb.model("ho"), "121", order=2) == nb.shadow_hamiltonians(nb.model("ho"), "121", order=2)


def test_equality_keeps_the_sympy_sums_unbuilt():
    """Comparing direct-route families reads the exact corrections: the sympy shadows stay pending."""
    a = nb.shadow_hamiltonians(_ho3(), "12321", order=4)
    b = pickle.loads(pickle.dumps(a))
    assert a == b and hash(a) == hash(b)
    assert callable(a.__dict__["_shadows"]) and callable(b.__dict__["_shadows"])


def test_exact_data_survive():
    """The copy's exact polynomials are the original's: same sympy forms, same ring elements, same classes."""
    fam = nb.shadow_hamiltonians(_ho3(), "12321", order=4)
    copy = pickle.loads(pickle.dumps(fam))
    assert sympy.expand(copy.H_S - fam.H_S) == 0 and sympy.expand(copy.G_S - fam.G_S) == 0
    X = nb.effective_field(_ho3().splitting, "12321", order=4)
    Y = pickle.loads(pickle.dumps(X))
    assert Y.field == X.field and Y.field.bracket(X.field).is_zero()
    assert all(type(c) is type(d) for c, d in zip(Y.field.components, X.field.components))


def test_algebra_rebuilds_from_its_description():
    """QQ, QQ(m) with a constant, QQ<2^(1/3)>(m), QQ<sqrt(2), i>: the algebra and its polynomials come back equal."""
    x, y, m = sympy.symbols("x y m", positive=True)
    for algebra in (nb.PolynomialAlgebra([x, y]), nb.PolynomialAlgebra([x, y], [m], [sympy.Symbol("h")]),
                    nb.PolynomialAlgebra([x, y], [m], extension=[sympy.cbrt(2)]),
                    nb.PolynomialAlgebra([x, y], extension=[sympy.sqrt(2), sympy.I])):
        copy = pickle.loads(pickle.dumps(algebra))
        assert copy == algebra and hash(copy) == hash(algebra) and copy.ring == algebra.ring
        assert copy.coordinates[0].is_positive
        number = 1 + algebra.extension[0] if algebra.extension else 1
        p = algebra.convert(number * x**2 * y / (3 + (m if algebra.parameters else 0)))
        q = pickle.loads(pickle.dumps(p))
        assert q == p and copy.is_polynomial(q) and q * q == p * p


def test_unpickled_symbols_print_as_the_originals():
    """A rebuilt generator is Symbol("x1"), not an equal Symbol("x1", commutative=True) that sympy's cache would
    then put into later, unrelated expressions (their srepr, and the fast conversion's identity with expand)."""
    A = _ho3().algebra
    copy = pickle.loads(pickle.dumps(A))
    assert [sympy.srepr(s) for s in copy.coordinates + copy.parameters + copy.constants] == \
        [sympy.srepr(s) for s in A.coordinates + A.parameters + A.constants]


def test_pickle_is_plain_data():
    """A polynomial's pickle names no ground-type class (flint, gmpy2) and no sympy ring, field or domain."""
    S = _ho3()
    data = pickle.dumps(S.algebra.convert(S.H * sympy.Symbol("h") / 3))
    for name in (b"flint", b"gmpy2", b"sympy"):
        assert name not in data


def test_rings_a_computation_passes_to_pickle():
    """A ring's ``clone`` keeps the class: polynomials over ZZ (cleared denominators) pickle too."""
    R = _ho3().algebra.ring.clone(domain=sympy.ZZ)
    q = R.from_dict({(2, 0, 0, 0): sympy.ZZ(6), (0, 1, 0, 0): sympy.ZZ(1)})
    assert pickle.loads(pickle.dumps(q)) == q


def test_algebraic_numbers_written_in_another_primitive_element():
    """A pickle from a sympy that chose another primitive element for QQ<sqrt(2), i> is read through sympy."""
    from nambu_bch.algebra.polynomial import _polynomial_from

    x, y = sympy.symbols("x y")
    A = nb.PolynomialAlgebra([x, y], extension=[sympy.sqrt(2), sympy.I])
    # sqrt(2) written in the primitive element a = sqrt(2) (dense coefficients [1, 0] = a)
    p = _polynomial_from(A.ring, (((1, 0), ((1, 1), (0, 1))),), sympy.sqrt(2))
    assert p == A.convert(sympy.sqrt(2) * x)


def test_sympy_rings_are_untouched():
    """Importing nambu_bch changes nothing in a user's own sympy rings (they still pickle as sympy decides)."""
    R, x = sympy.ring("x", sympy.QQ)
    assert type(R) is sympy.polys.rings.PolyRing and type(x) is sympy.polys.rings.PolyElement


# -- in worker processes ------------------------------------------------------------------

#: One case per result type a worker typically sends back.  The rigid body's family is taken at h^2: the same type
#: over the same parameter field QQ(I1, I2, I3) as at h^4, whose printing alone costs ~12 s of CPU per process (the
#: h^4 family crosses the processes in "ho3 12321 h^4").
WORKER_CASES = ("ho3 12321 h^4", "rigid-body 12321 h^2", "ho3 conserved 32123", "ho3 exact 12321",
                "ho 121 h^4 fi", "ho3 effective field h^4", "rigid-body 123 none", "rigid-body algebra",
                "ho3 formal bch", "ho modified solution", "ho3 trajectory", "ho modified equation")


def _compute(case: str):
    system, what = case.split(" ", 1)
    S = nb.model(system)
    if what == "conserved 32123":
        return nb.conserved_quantities(S, "32123")
    if what == "exact 12321":
        return nb.exact_shadow_hamiltonians(S, "12321")
    if what == "effective field h^4":
        return nb.effective_field(S.splitting, "12321", order=4)
    if what == "algebra":
        return S.algebra
    if what == "formal bch":
        return nb.formal_bch("12321", 3)
    if what == "modified solution":
        return nb.modified_solution(S, "121", "o")
    if what == "trajectory":
        return nb.shadow_along(S, "12321", nb.iterate(S, "12321", 0.1, 20, (1, 1, 1)), 0.1)
    if what == "modified equation":
        return nb.modified_equation(S, "gauss4", order=2)
    if what == "123 none":
        return nb.shadow_hamiltonians(S, "123", order=2)
    word, order, *route = what.split()
    return nb.shadow_hamiltonians(S, word, order=int(order[2:]), route=route[0] if route else "direct")


def test_results_come_back_from_loky_workers():
    """Every case computed in joblib/loky workers (one pool of two for this module, through
    :func:`nambu_bch.parallel.sweep`) and sent back by pickle: each equals, hashes and prints as the same case
    computed here."""
    pytest.importorskip("joblib")
    from nambu_bch.parallel import sweep

    remote = sweep(_compute, WORKER_CASES, backend="loky", n_jobs=2)
    for case, result in zip(WORKER_CASES, remote):
        local = _compute(case)
        assert type(result) is type(local), case
        assert result == local and hash(result) == hash(local), case
        assert _views(result) == _views(local), case
    # an algebra from another process equals, and hashes like, this process's: content-keyed caches hit
    algebra = remote[WORKER_CASES.index("rigid-body algebra")]
    assert algebra == nb.model("rigid-body").algebra and hash(algebra) == hash(nb.model("rigid-body").algebra)
    assert {algebra: 1}.get(nb.model("rigid-body").algebra) == 1
