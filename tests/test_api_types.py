"""Wrong argument types and values at the public entries: one NambuBCHError naming the argument, never a crash."""

from __future__ import annotations

import pytest
import sympy

import nambu_bch as nb
from nambu_bch import bch, design, exact, integrators
from nambu_bch.errors import InvalidCompositionError, InvalidRunError, NambuBCHError, NoExactResultError, UnknownModelError

x1, x2 = sympy.symbols("x1 x2")


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: integrators.strang_word(2**63 - 1), InvalidRunError, "Strang word"),  # used to hang
        (lambda: integrators.strang_word(()), InvalidRunError, "Strang word"),
        (lambda: bch.estimate_size(0, 0), InvalidRunError, "n_generators"),  # used to recurse without end
        (lambda: bch.estimate_size("", 3), InvalidRunError, "n_generators"),
        (lambda: bch.estimate_size(3, 10**6), InvalidRunError, "max_degree"),
        (lambda: bch.check_order(2, limit=None), InvalidRunError, "limit"),
        (lambda: bch.lyndon_words("", 3), InvalidRunError, "n_letters"),
        (lambda: bch.witt_dimension("", 3), InvalidRunError, "n_letters"),
        (lambda: exact.linear_core("", (x2, -x1)), NoExactResultError, "coordinates"),
        (lambda: exact.linear_core({1: 2}, (x2, -x1)), NoExactResultError, "coordinates"),
        (lambda: exact.linear_core(1, (x2, -x1)), NoExactResultError, "coordinates"),
        (lambda: exact.linear_core((x1, x2), (x2,)), NoExactResultError, "right-hand side"),
        (lambda: design.cost(2), InvalidRunError, "comp"),
        (lambda: nb.lie_bracket(0, 0), InvalidRunError, "VectorField"),
        (lambda: nb.Composition(pieces=int, coefficients=(1,)), InvalidCompositionError, "pieces"),
        (lambda: nb.Composition(pieces=(1,), coefficients=5), InvalidCompositionError, "coefficients"),
        (lambda: nb.VectorField(algebra=0, components=0), InvalidRunError, "PolynomialAlgebra"),
        (lambda: nb.VectorField(nb.PolynomialAlgebra([x1, x2]), 0), NambuBCHError, "components"),
    ],
)
def test_wrong_argument_is_one_named_error(call, error, words):
    with pytest.raises(error, match=words) as info:
        call()
    assert "\n" not in str(info.value)


def test_valid_calls_unchanged():
    assert integrators.strang_word(3) == "12321"
    assert bch.estimate_size(3, 7)["lyndon"] == 508
    assert bch.lyndon_words(2, 3) == [(0, 0, 1), (0, 1, 1)]
    assert exact.linear_core((x1, x2), (x2, -x1)).Omega == 1
    assert design.cost(nb.composition("12321")) == (4, 1)


def test_one_stage_strang_template_is_answered():
    # a univariate Groebner basis (python-flint) once failed on the ordering given by name
    C = nb.optimize_composition("strang", parts=2, order=2, stages=1)
    assert C.pieces == (1, 2, 1)
    assert C.coefficients == (sympy.Rational(1, 2), 1, sympy.Rational(1, 2))


def test_array_in_a_message_is_shown_on_one_line():
    import numpy as np

    with pytest.raises(UnknownModelError) as info:
        nb.model(np.ones((3, 3, 3)))
    message = str(info.value)
    assert "\n" not in message and "unknown model array(" in message


def test_cli_and_library_share_the_one_line_helpers():
    from nambu_bch import errors
    from nambu_bch.cli import _options

    assert _options.one_line is errors.one_line and _options.shown is errors.shown
    assert errors.one_line("a\n  b\x1b") == "a b\\x1b"


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: bch.standard_bracketing(None), "word"),
        (lambda: bch.standard_bracketing(""), "Lyndon word"),
        (lambda: bch.lie_to_associative(2), "terms"),
        (lambda: bch.lie_to_associative("20"), "coefficient, tree"),
        (lambda: bch.terms_to_latex(None), "terms"),
        (lambda: bch.terms_to_latex("x(:("), "coefficient, tree"),
        (lambda: bch.tree_to_latex(0, names=0), "names"),
        (lambda: nb.full_split(2), "System"),
        (lambda: __import__("nambu_bch.algebra", fromlist=["field_backend"]).field_backend(1, {}), "PolynomialAlgebra"),
        (lambda: nb.exact_flow(float("nan"), "strang:"), "Piece"),
        (lambda: nb.exact_flow(nb.model("ho3").splitting.pieces[0], 0), "coordinates"),
    ],
)
def test_wrong_object_is_refused_at_the_entry(call, words):
    with pytest.raises(InvalidRunError, match=words):
        call()


def test_objects_still_accepted():
    S = nb.model("ho3").splitting
    assert bch.standard_bracketing((0, 0, 1), letters=(1, 2)) == (1, (1, 2))
    assert bch.lie_to_associative([(1, (1, (2, 3))), (1, (2, (3, 1))), (1, (3, (1, 2)))]) == {}
    assert bch.tree_to_latex((1, (1, 2))) == "[X_{1},[X_{1},X_{2}]]"
    assert nb.exact_flow(S.pieces[0], S.system.coordinates).kind
    assert len(nb.full_split(nb.model("ho3")).pieces) == 3


@pytest.mark.parametrize("kwargs, words", [({"total": None}, "total"), ({"total": "True"}, "total"),
                                           ({"total": 3, "delay": float("nan")}, "delay")])
def test_progress_arguments_are_checked(kwargs, words):
    from nambu_bch.numeric import Progress

    with pytest.raises(NambuBCHError, match=words):
        Progress(enabled=False, **kwargs)


def test_exact_with_a_transcendental_parameter_is_refused_with_a_reason(capsys):
    # m = exp(2) is not in the polynomial ring; the composed map once failed there with AttributeError
    from nambu_bch.cli import main

    assert main(["exact", "--param", "m=exp(2)"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "m=exp(2)" in err
