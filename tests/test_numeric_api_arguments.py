"""Every public numeric entry point refuses a bad argument with one NambuBCHError line, before any work.

The table below names each numeric function of ``nambu_bch.numeric``, ``nambu_bch.exact`` and
``nambu_bch.design`` (and ``shadow_hamiltonians``' order) with arguments that work; each argument in
turn is replaced by values of the wrong kind or out of range.  Whatever the function does with
them, only :class:`nambu_bch.NambuBCHError` may come out, on one line.  A value that happens to be
accepted (``0`` steps, a negative step) must simply run: the baseline runs are tiny.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest
import sympy

import nambu_bch as nb
from nambu_bch import design, exact, numeric
from nambu_bch.checks import MAX_ORDER, finite_float
from nambu_bch.errors import (InvalidOrderError, InvalidRunError, NambuBCHError, NumericalRangeError,
                              ResourceLimitError)

#: Values of the wrong kind or out of range (one of each class the attack on the API used).
BAD = [None, True, "abc", b"x", 10**400, -10**400, float("nan"), float("inf"), [], (1, 2), {"a": 1},
       np.array([1.0, 2.0]), np.array([[np.nan]]), sympy.Symbol("x"), sympy.Integer(10)**400, 1j, object(),
       2**63, np.float64("nan")]

S = "ho3"


def _solution_numeric(params=None, h=0.1):
    return exact.modified_solution(S, "32123", "c").numeric(params=params, h=h)


def _solution_call(t=(0.0, 1.0), x0=(1.0, 1.0, 1.0)):
    return exact.modified_solution(S, "32123", "c").numeric()(t, x0)


def _figure(path="wp.png", dpi=20):
    return design.compare("ho", ["121"], t_end=1.0, steps=(10, 20), samples=20).figure(path, dpi)


def _direct_route(**kw):
    from nambu_bch.shadow.direct_route import direct_route

    return direct_route(**kw)


def _effective_field(**kw):
    from nambu_bch.bch.backward import effective_field

    return effective_field(**kw)


def _chunks(**kw):
    return list(numeric.iterate_chunks(**kw))


#: A velocity Verlet run of the oscillator, a valid trajectory for ``numerical_shadow``.
_HO = numeric.iterate("ho", "212", 0.1, 10, [1.0, 0.0])

ENTRIES = {
    "iterate": (numeric.iterate, dict(system=S, word="32123", h=0.1, steps=10, x0=[1.0, 1.0, 1.0], params=None,
                                       every=1, kahan=False, dps=None, backend="auto", progress=False, chunk=None,
                                       check_stable=True, out=None, fma=False, workers=None)),
    "iterate_complex": (numeric.iterate_complex, dict(system="ho", word="1:1/2+I/2,2:1,1:1/2-I/2", h=0.1, steps=10,
                                                      x0=[1.0, 0.0], params=None, every=1, project=False,
                                                      backend="auto")),
    "iterate_chunks": (_chunks, dict(system=S, word="32123", h=0.1, steps=10, x0=[1.0, 1.0, 1.0], every=1,
                                     chunk_samples=4)),
    "check": (numeric.check, dict(system=S, word="32123", h=0.1, steps=10, x0=[1.0, 1.0, 1.0], params=None, order=2,
                                  alpha=0.5, every=1, include=("H",), chunk_samples=None, kahan=False, backend="auto")),
    "shadow_along": (numeric.shadow_along, dict(system=S, word="12321", trajectory=[[1.0, 1.0, 1.0]] * 4, h=0.1,
                                                order=2, alpha=0.5, params=None, t=None, which=("H",))),
    "numerical_shadow": (numeric.numerical_shadow, dict(q=_HO[:, :1], p=_HO[:, 1:], forces_or_system="ho", h=0.1, order=4,
                                                        word="212", potential=None, params=None, check_steps=True)),
    "iterate_gradient": (numeric.iterate_gradient, dict(system="ho", spec="chin-4a", h=0.1, steps=10, x0=[1.0, 0.0],
                                                        params=None, every=1)),
    "iterate_processed": (numeric.iterate_processed, dict(system="ho", kernel="takahashi-imada", h=0.1, steps=10,
                                                          x0=[1.0, 0.0], params=None, every=1, max_degree=7)),
    "gradient_check": (numeric.gradient_check, dict(system="ho", method="chin-4a", h=0.2, steps=5, x0=[1.0, 0.0],
                                                    params=None, halvings=1)),
    "hybrid_monte_carlo": (numeric.hybrid_monte_carlo, dict(system="ho", word="212", h=0.5, steps=2, refresh=None,
                                                            flip=None, target="H", order=4, alpha=0.5, chains=20,
                                                            iterations=2, burn=0, x0=None, params=None, seed=0,
                                                            backend="auto")),
    "rk_iterate": (numeric.rk_iterate, dict(system=S, method="midpoint", h=0.1, steps=10, x0=[1.0, 1.0, 1.0], params=None,
                                            every=1)),
    "rk_step_function": (numeric.rk_step_function, dict(system=S, method="midpoint", params=None)),
    "sample_times": (numeric.sample_times, dict(h=0.1, steps=10, every=1)),
    "sample_steps": (numeric.sample_steps, dict(steps=10, every=1)),
    "n_samples": (numeric.n_samples, dict(steps=10, every=1)),
    "quantities": (numeric.quantities, dict(system=S, word="32123", h=0.1, params=None, order=2, alpha=0.5,
                                            which=("H",))),
    "drift_rate": (numeric.drift_rate, dict(t=[0.0, 1.0, 2.0], values=[0.0, 1.0, 2.0])),
    "fit_order": (numeric.fit_order, dict(hs=[0.1, 0.05], errors=[1e-2, 2.5e-3])),
    "observed_order": (numeric.observed_order, dict(system=S, word="32123", hs=[0.1, 0.05], T=1.0, x0=[1.0, 1.0, 1.0],
                                                    params=None, quantity="x")),
    "h_scan": (numeric.h_scan, dict(system=S, word="32123", hs=[0.1], steps=10, x0=None, params=None, names=("H",),
                                    backend="auto")),
    "truncation_study": (numeric.truncation_study, dict(system=S, word="32123", orders=(2,), h=0.1, steps=10, every=1,
                                                        alpha=0.5, x0=None)),
    "precision_study": (numeric.precision_study, dict(system=S, word="32123", h=0.1, steps=20, every=10, mp_steps=10,
                                                      dps=20, names=("H_c",), repeats=1, timing_steps=10, x0=None)),
    "paper_figures": (numeric.paper_figures, dict(h=0.1, x0=None, t_short=1.0, t_long=1.0, every_long=1, dpi=20,
                                                  fmt="png")),
    "compare": (design.compare, dict(system="ho", words=["121"], t_end=2.0, steps=(10, 20), x0=None, params=None,
                                     box=None, samples=20)),
    "Comparison.figure": (_figure, dict(path="wp.png", dpi=20)),
    "leading_error": (design.leading_error, dict(system="ho", word="121", box=None, samples=20, params=None, seed=0,
                                                 hamiltonian=False)),
    "F_series": (exact.F_series, dict(x=0.5, order=4)),
    "modified_solution": (exact.modified_solution, dict(system=S, word="32123", kind="o")),
    "modified_equations": (exact.modified_equations, dict(system=S, word="32123", kind="o")),
    "ModifiedSolution.numeric": (_solution_numeric, dict(params=None, h=0.1)),
    "ModifiedSolution.numeric()(t, x0)": (_solution_call, dict(t=[0.0, 1.0], x0=[1.0, 1.0, 1.0])),
    "F": (exact.F, dict(x=0.5)),
    "shadow_hamiltonians": (nb.shadow_hamiltonians, dict(system=S, word="12321", order=2, route="direct", degree=None,
                                                         existence=True, params=None, max_unknowns=2000,
                                                         progress=False)),
    "direct_route": (_direct_route, dict(system=S, word="12321", order=2, degree=None, max_unknowns=None,
                                         progress=False)),
    "effective_field": (_effective_field, dict(splitting=nb.model(S).splitting, comp="12321", order=2, fast=True)),
}

#: Public functions of the numeric subpackage that take no numeric argument a user chooses (kernels and
#: the step program are addressed by system and word only, checked by ``composition_for``).
NOT_NUMERIC = {"cache_dir", "numba_available", "kernel", "step_program"}


def test_the_table_covers_every_numeric_function():
    public = {name for name in numeric.__all__ if inspect.isfunction(getattr(numeric, name))}
    assert public - NOT_NUMERIC <= set(ENTRIES)


CASES = [(name, arg, bad) for name, (_, kw) in ENTRIES.items() for arg in kw for bad in BAD]


@pytest.mark.parametrize("name, arg, bad", CASES, ids=[f"{n}-{a}-{i % len(BAD)}" for i, (n, a, _) in enumerate(CASES)])
def test_bad_argument_gives_one_nambu_error_line(name, arg, bad, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing is written, but if a figure were, it would land here
    fn, kw = ENTRIES[name]
    try:
        fn(**{**kw, arg: bad})
    except NambuBCHError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 700, str(exc)


# -- the items one by one -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("arg", ["h", "x0", "alpha", "params"])
def test_check_refuses_numbers_beyond_float64_naming_the_argument(arg):
    value = {"h": 10**400, "x0": [10**400, 1, 1], "alpha": 10**400, "params": {"m": 10**400}}[arg]
    kw = dict(h=0.1, steps=10, x0=[1.0, 1.0, 1.0])
    kw[arg] = value
    with pytest.raises(NumericalRangeError, match=r"(h|x0|alpha|parameter m) .*(float64|not finite)"):
        numeric.check("ho3", "32123", **kw)


def test_steps_beyond_the_run_bound_are_refused_before_any_work(monkeypatch):
    import importlib

    iterate_module = importlib.import_module("nambu_bch.numeric.iterate")
    def no_kernel(*a, **k):
        raise AssertionError("a kernel was requested for a run that is refused from its arguments")

    monkeypatch.setattr(iterate_module, "kernel", no_kernel)
    for steps in (10**400, 2**63, 10**10 + 1):
        with pytest.raises(ResourceLimitError, match="trajectory-steps"):
            numeric.check("ho3", "32123", 0.1, steps, [1.0, 1.0, 1.0])
        with pytest.raises(ResourceLimitError, match="trajectory-steps"):
            numeric.iterate("ho3", "32123", 0.1, steps, [1.0, 1.0, 1.0], every=steps)
    with pytest.raises(ResourceLimitError, match="mpmath"):
        numeric.iterate("ho3", "32123", 0.1, 10**6 + 1, [1.0, 1.0, 1.0], every=10**6, dps=20)
    with pytest.raises(ResourceLimitError, match="x 20000 states"):
        numeric.iterate("ho", "121", 0.1, 10**6, np.ones((2, 20000)), every=10**6)


def test_a_streamed_block_is_bounded_like_a_sample_array():
    with pytest.raises(InvalidRunError, match="chunk_samples"):
        numeric.check("ho3", "32123", 0.1, 10, [1.0, 1.0, 1.0], chunk_samples=10**12)


def test_every_beyond_steps_samples_like_every_equal_steps():
    a = numeric.iterate("ho3", "32123", 0.1, 7, [1.0, 1.0, 1.0], every=2**70)
    b = numeric.iterate("ho3", "32123", 0.1, 7, [1.0, 1.0, 1.0], every=7)
    assert np.array_equal(a, b) and a.shape == (2, 3)


@pytest.mark.parametrize("order", [10**400, MAX_ORDER + 1, -1, 2.5, True, "2"])
def test_check_refuses_an_order_outside_the_one_range(order):
    with pytest.raises(InvalidOrderError, match=f"between 0 and {MAX_ORDER}|non-negative integer"):
        numeric.check("ho3", "32123", 0.1, 10, [1.0, 1.0, 1.0], order=order)


def test_order_range_is_one_definition_for_api_and_cli():
    from nambu_bch.bch.backward import check_order
    from nambu_bch.cli import _options

    assert _options.MAX_CLI_ORDER == MAX_ORDER
    assert check_order(MAX_ORDER) == MAX_ORDER
    with pytest.raises(InvalidOrderError):
        check_order(MAX_ORDER + 1)


@pytest.mark.parametrize("name, word", [("ho3", "12321"), ("ho", "121"), ("pendulum", "121")])
@pytest.mark.parametrize("route", ["direct", "fi"])
def test_order_zero_is_the_unperturbed_pair(name, word, route):
    """Through h^0 the shadow Hamiltonians are the system's own: H_S = H, G_S = G (no correction kept)."""
    system = nb.model(name)
    family = nb.shadow_hamiltonians(system, word, order=0, route=route)
    assert family.exists
    assert sympy.simplify(family.H_S - system.hamiltonians[0]) == 0
    if len(system.hamiltonians) > 1:
        assert sympy.simplify(family.G_S - system.hamiltonians[1]) == 0


def test_check_at_order_zero_measures_h_as_h_s():
    r = numeric.check("ho3", "32123", 0.1, 200, [1.0, 1.0, 1.0], order=0, include=("H", "H_S"))
    assert r.max_abs_error["H_S"] == r.max_abs_error["H"]


@pytest.mark.parametrize("value, fine", [(1, 1.0), ("0.25", 0.25), (sympy.Rational(1, 8), 0.125), (0.0, 0.0)])
def test_finite_float_accepts_real_numbers(value, fine):
    assert finite_float(value, "h") == fine


@pytest.mark.parametrize("value, error", [
    (10**400, NumericalRangeError), (sympy.exp(sympy.exp(10)), NumericalRangeError),
    (sympy.exp(-sympy.Integer(10)**4), NumericalRangeError), ("1e-400", NumericalRangeError),
    (float("nan"), NumericalRangeError), ("junk", InvalidRunError), (sympy.Symbol("x"), InvalidRunError),
    (np.array([1.0, 2.0]), InvalidRunError), (1j, InvalidRunError), (None, InvalidRunError), (True, InvalidRunError),
])
def test_finite_float_refuses_in_one_line_naming_the_argument(value, error):
    with pytest.raises(error, match="^--alpha "):
        finite_float(value, "--alpha")


def test_sample_times_validates_its_arguments():
    assert numeric.sample_times(0.5, 4, 3).tolist() == [0.0, 1.5, 2.0]
    with pytest.raises(InvalidRunError, match="every"):
        numeric.sample_times(0.1, 10, 0)
    with pytest.raises(NumericalRangeError, match="h = "):
        numeric.sample_times(10**400, 10)
    with pytest.raises(NumericalRangeError, match="last sample time"):
        numeric.sample_times(1e300, 10**9, 10**9)
    with pytest.raises(ResourceLimitError, match="GiB"):
        numeric.sample_steps(10**12)


def test_compare_takes_one_word_and_refuses_a_number():
    C = design.compare("ho", "121", t_end=1.0, steps=(10, 20))
    assert [r["integrator"] for r in C.rows] == ["121"]
    with pytest.raises(NambuBCHError, match="words must be a list"):
        design.compare("ho", 1.5)
    with pytest.raises(InvalidRunError, match="steps must be a list of positive integers"):
        design.compare("ho", ["121"], steps=(10.5, 20))


def test_modified_solution_refuses_an_array_kind():
    with pytest.raises(NambuBCHError, match="kind must be one of"):
        exact.modified_solution(nb.model("ho3"), "32123", np.array(["o", "c"]))


# -- defaults from the system ---------------------------------------------------------------------------------------


def test_every_model_documents_a_default_x0_of_its_size():
    from nambu_bch.systems.catalog import DEFAULT_X0, default_x0

    assert set(DEFAULT_X0) == set(nb.model_names())
    for name in nb.model_names():
        x0, where = default_x0(nb.model(name))
        assert len(x0) == nb.model(name).N and where == f"the default x0 of {name}"


def test_henon_heiles_default_is_a_bounded_orbit_used_by_check_and_compare():
    from nambu_bch.systems.catalog import DEFAULT_X0

    hh = nb.model("henon-heiles")
    q1, q2, p1, p2 = DEFAULT_X0["henon-heiles"]
    energy = float(hh.H.subs(dict(zip(hh.coordinates, (q1, q2, p1, p2)))))
    assert 0 < energy < 1 / 6  # below the escape energy: the orbit stays in the well
    r = numeric.check(hh, "121", 0.1, 500, include=("H",))  # the orbit is the concern, not the exact quantities
    assert r.x0 == list(DEFAULT_X0["henon-heiles"]) and np.isfinite(r.max_abs_error["H"])
    C = design.compare(hh, ["121"], t_end=5.0, steps=(20, 40))
    assert C.x0 == DEFAULT_X0["henon-heiles"] and np.isfinite(C.rows[0]["best_error"])


def test_an_escaping_orbit_is_named_by_its_x0():
    with pytest.raises(NumericalRangeError, match=r"reference run of compare; x0 as given.*x0 = \[1.0, 1.0, 1.0, 1.0\]|"
                                                  r"x0 = \[1.0, 1.0, 1.0, 1.0\].*reference run of compare; x0 as given"):
        design.compare("henon-heiles", ["121"], x0=(1, 1, 1, 1))
    # the orbit escapes at step 80: a run short enough for backend="auto" to interpret (no compile)
    with pytest.raises(NumericalRangeError, match=r"from x0 = \[1.0, 1.0, 1.0, 1.0\] overflowed.*escapes"):
        numeric.check("henon-heiles", "121", 0.05, 2_000, [1.0, 1.0, 1.0, 1.0])


def test_a_failing_default_x0_is_named_as_the_default(monkeypatch):
    from nambu_bch.systems import catalog

    monkeypatch.setitem(catalog.DEFAULT_X0, "henon-heiles", (1.0, 1.0, 1.0, 1.0))
    with pytest.raises(NumericalRangeError, match="the default x0 of henon-heiles"):
        numeric.check("henon-heiles", "121", 0.05, 2_000)
    with pytest.raises(NumericalRangeError, match="is the default x0 of henon-heiles"):
        design.compare("henon-heiles", ["121"])


def test_cli_uses_the_model_default_x0(capsys):
    from nambu_bch.cli import main

    assert main(["check", "--model", "henon-heiles", "--steps", "200", "--format", "json"]) == 0
    assert '"x0": [\n    0.0,\n    0.1,\n    0.5,\n    0.0\n  ]' in capsys.readouterr().out


@pytest.mark.parametrize("argv, flag", [
    (["check", "--alpha", "exp(exp(exp(2.5)))"], "--alpha"),
    (["check", "--h", "10^350"], "--h"),
    (["check", "--x0", "10^350,1,1"], "--x0"),
    (["check", "--param", "m=10^350"], "parameter m"),
    (["compare", "--t-end", "10^350"], "--t-end"),
])
def test_cli_refuses_overflowing_values_naming_the_flag(argv, flag, capsys):
    from nambu_bch.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and flag in err and "Traceback" not in err


@pytest.mark.parametrize("sub", ["shadow", "check"])
def test_cli_order_zero_answers(sub, capsys):
    from nambu_bch.cli import main

    assert main([sub, "--order", "0"] + (["--steps", "50"] if sub == "check" else ["--format", "text"])) == 0
    assert "Traceback" not in capsys.readouterr().err


def test_step_program_takes_a_model_name_like_every_numeric_entry():
    assert numeric.step_program("ho3", "12321").word == numeric.step_program(nb.model("ho3"), "12321").word
    with pytest.raises(NambuBCHError, match="System or a built-in model name"):
        numeric.step_program(1.5, "121")


def test_default_x0_of_every_model_runs_a_long_orbit():
    """The documented defaults are orbits a check of t = 10^3 can follow (no escape, no float64 overflow)."""
    import importlib

    strang = importlib.import_module("nambu_bch.integrators.composition").strang_word
    for name in ("henon-heiles", "toda", "rational", "lotka-volterra", "exp-well"):
        system = nb.model(name)
        numeric.check(system, strang(len(system.splitting)), 0.01, 100_000, every=1000, include=("H",))
