"""The public entries check their arguments: a wrong type, a payload string or a huge size is one NambuBCHError line.

Each case was found by the property sweep (tests/test_fuzz_api.py) as a foreign exception (``AttributeError``,
``TypeError``, ``KeyError``...), a string run as code, or a call that did not return; here each is pinned by name.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest
import sympy
from strategies import CODE_MARKER, PAYLOADS

import nambu_bch as nb
from nambu_bch import NambuBCHError
from nambu_bch.errors import ResourceLimitError
from nambu_bch.algebra import jacobian
from nambu_bch.bch import expand_terms, standard_bracketing, tree_to_associative, witt_dimension
from nambu_bch.exact import linear_core
from nambu_bch.integrators import parameter_values
from nambu_bch.numeric import kernel
from nambu_bch.shadow import JetAlgebra, commutator_terms, count_brackets, decide, double_commutator_terms, fi_brackets
from nambu_bch.systems import canonical_split, infer_bracket, is_separable, triplet_split
from nambu_bch.testing import assert_fields_equal, assert_invariant, assert_shadow_pair, liouville_components

X = sympy.symbols("x1 x2 x3")
PAYLOAD = PAYLOADS[0]


def ho3():
    return nb.model("ho3")


def alg():
    return ho3().algebra


def slots():
    S = ho3()
    return S.splitting[1].terms[0], S.splitting[2].terms[0]


CASES = {
    "PolynomialAlgebra(None)": lambda: nb.PolynomialAlgebra(None),
    "PolynomialAlgebra([])": lambda: nb.PolynomialAlgebra([]),
    "PolynomialAlgebra(extension=None)": lambda: nb.PolynomialAlgebra(X, extension=None),
    "JetAlgebra(None)": lambda: JetAlgebra(None, "f", 2),
    "JetAlgebra(names)": lambda: JetAlgebra(["x1"], "f", 2),
    "JetAlgebra(max_order=[])": lambda: JetAlgebra(X, "f", []),
    "poisson_bracket(algebra=list)": lambda: nb.poisson_bracket([PAYLOAD], X[0], X[1]),
    "nambu_bracket(algebra=None)": lambda: nb.nambu_bracket(None, *X),
    "liouville_field(algebra=str)": lambda: nb.liouville_field(PAYLOAD, X[1], X[2]),
    "jacobian(None)": lambda: jacobian(None, X),
    "is_symplectic(None)": lambda: nb.is_symplectic(None, X[:2]),
    "satisfies_nambu_condition(None)": lambda: nb.satisfies_nambu_condition(None, X),
    "LiouvilleTerm(None)": lambda: nb.LiouvilleTerm(None),
    "LiouvilleSum(algebra=None)": lambda: nb.LiouvilleSum(None),
    "LiouvilleSum(terms=str)": lambda: nb.LiouvilleSum(alg(), PAYLOAD),
    "LiouvilleSum(terms={1: 2})": lambda: nb.LiouvilleSum(alg(), {1: 2}),
    "commutator_terms(algebra=None)": lambda: commutator_terms(None, *slots(), "a"),
    "commutator_terms(way=list)": lambda: commutator_terms(alg(), *slots(), [PAYLOAD]),
    "double_commutator_terms(label=str)": lambda: double_commutator_terms(alg(), slots()[0], *slots(), PAYLOAD),
    "double_commutator_terms(a=str)": lambda: double_commutator_terms(alg(), PAYLOAD, *slots(), "1AX"),
    "single_split(None)": lambda: nb.single_split(None),
    "canonical_split(None)": lambda: canonical_split(None),
    "triplet_split(None)": lambda: triplet_split(None),
    "infer_bracket(None)": lambda: infer_bracket(None, 2),
    "infer_bracket(str)": lambda: infer_bracket(PAYLOAD, 2),
    "is_separable(coordinates=None)": lambda: is_separable(X[0], None),
    "is_invariant(system=None)": lambda: nb.is_invariant(None, "12321", X[0]),
    "is_invariant(system=list)": lambda: nb.is_invariant([PAYLOAD], "12321", X[0]),
    "parameter_values(None)": lambda: parameter_values(None),
    "kernel(system=list)": lambda: kernel([PAYLOAD], "12321"),
    "composed_map(h=str)": lambda: nb.composed_map(ho3().splitting, "12321", PAYLOAD),
    "composed_map(h=None)": lambda: nb.composed_map(ho3().splitting, "12321", None),
    "exact_flow(coordinates=list)": lambda: nb.exact_flow(ho3().splitting.pieces[0], [PAYLOAD] * 3),
    "expand_terms(terms=str)": lambda: expand_terms(PAYLOAD, ho3().splitting),
    "expand_terms(terms=None)": lambda: expand_terms(None, ho3().splitting),
    "expand_terms(splitting=str)": lambda: expand_terms([((1, 2), 1)], PAYLOAD),
    "expand_terms(evaluators=str)": lambda: expand_terms([((1, 2), 1)], ho3().splitting, evaluators=PAYLOAD),
    "expand_terms(leaf 9)": lambda: expand_terms([(1, (1, 9))], ho3().splitting),
    "fi_route(terms=str)": lambda: nb.fi_route(ho3(), "12321", terms=PAYLOAD),
    "fi_route(terms=[str])": lambda: nb.fi_route(ho3(), "12321", terms=[PAYLOAD]),
    "count_brackets(system=None)": lambda: count_brackets(None, "12321", 2),
    "fi_brackets(system=str)": lambda: fi_brackets(PAYLOAD, "12321", 2),
    "decide(result=None)": lambda: decide(None, measure=False),
    "decide(points=str)": lambda: decide(nb.direct_route(ho3(), "123", 1), measure=False, points=PAYLOAD),
    "decide(rtol=str)": lambda: decide(nb.direct_route(ho3(), "123", 1), measure=False, rtol=PAYLOAD),
    "witt_dimension(list)": lambda: witt_dimension([PAYLOAD], 3),
    "witt_dimension(array)": lambda: witt_dimension(np.zeros(0), 3),
    "standard_bracketing(letters=True)": lambda: standard_bracketing((1, 2), letters=True),
    "tree_to_associative(list)": lambda: tree_to_associative([PAYLOAD]),
    "tree_to_associative(array)": lambda: tree_to_associative(np.zeros(0)),
    "optimize_composition(starts=str)": lambda: nb.optimize_composition("strang", 2, 4, 3, starts=PAYLOAD),
    "optimize_composition(seed=str)": lambda: nb.optimize_composition("strang", 2, 4, 3, starts=1, seed=PAYLOAD),
    "liouville_components(None)": lambda: liouville_components(None, X[1], X[2]),
    "liouville_components(str)": lambda: liouville_components(PAYLOAD, X[1], X[2]),
    "assert_fields_equal(coordinates=True)": lambda: assert_fields_equal([X[1]], [X[1]], coordinates=True),
    "assert_invariant(system=None)": lambda: assert_invariant(None, "12321", "x3 - x1^2"),
    "assert_invariant(h=str)": lambda: assert_invariant(ho3(), "12321", "x3 - x1^2", h=PAYLOAD),
    "assert_shadow_pair(system=None)": lambda: assert_shadow_pair(None, "12321", X[0], X[1]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_wrong_argument_is_one_family_line(case):
    with pytest.raises(NambuBCHError) as info:
        CASES[case]()
    assert "\n" not in str(info.value) and str(info.value).strip()


CODE = {
    "jacobian(coordinates=[payload])": lambda: jacobian(X, [PAYLOAD] * 3),
    "is_symplectic(coordinates=[payload])": lambda: nb.is_symplectic(X[:2], [PAYLOAD] * 2),
    "liouville_components(coordinates=[payload])": lambda: liouville_components([PAYLOAD] * 3, X[1], X[2]),
    "linear_core(rhs=[payload])": lambda: linear_core(X[:2], [PAYLOAD] * 2),
}


@pytest.mark.parametrize("case", sorted(CODE))
def test_payload_in_a_sequence_is_not_run(case):
    sys.modules.pop(CODE_MARKER, None)
    with pytest.raises(NambuBCHError):
        CODE[case]()
    assert sys.modules.pop(CODE_MARKER, None) is None


HUGE = {  # each was a call that did not return: refused from its size, before the work
    "JetAlgebra(70 coordinates)": lambda: JetAlgebra(sympy.symbols("y0:70"), "f", 2),
    "JetAlgebra(max_order=2**63-1)": lambda: JetAlgebra(X, "f", 2**63 - 1),
    "witt_dimension(degree=2**63-1)": lambda: witt_dimension(2, 2**63 - 1),
    "representations(a=payload)": lambda: nb.representations(alg(), PAYLOAD, *slots()),
    "optimize_composition(starts=2**63-1)": lambda: nb.optimize_composition("strang", 2, 4, 3, starts=2**63 - 1),
}


@pytest.mark.parametrize("case", sorted(HUGE))
def test_huge_request_is_refused_up_front(case):
    with pytest.raises(NambuBCHError):
        HUGE[case]()


def test_jet_algebra_multi_indices_are_unchanged():
    """The jets are listed without the ``(k+1)^N`` product, in the same order as before."""
    J = JetAlgebra(X, "AB", 2)
    assert len(J.jets) == 2 * 10 and J.jets[:4] == [("A", (0, 0, 0)), ("A", (0, 0, 1)), ("A", (0, 0, 2)),
                                                    ("A", (0, 1, 0))]
    with pytest.raises(ResourceLimitError):
        JetAlgebra(X, "ABCDEFGH", 20)


MORE = {  # found with NAMBU_BCH_FUZZ_EXAMPLES=30
    "jacobian(empty arrays)": lambda: jacobian(np.zeros(0), np.zeros(0)),
    "is_symplectic(empty arrays)": lambda: nb.is_symplectic(np.zeros(0), np.zeros(0)),
    "satisfies_nambu_condition(empty arrays)": lambda: nb.satisfies_nambu_condition(np.zeros(0), np.zeros(0)),
    "tree_to_latex(bytearray leaf)": lambda: __import__("nambu_bch.bch", fromlist=["x"]).tree_to_latex(
        bytearray(b"x1"), names={"m": 1}),
    "Progress(enabled=array)": lambda: __import__("nambu_bch.numeric", fromlist=["x"]).Progress(0, enabled=np.zeros(0)),
    "assert_invariant(I=None)": lambda: assert_invariant(ho3(), "12321", None),
}


@pytest.mark.parametrize("case", sorted(MORE))
def test_more_wrong_arguments_are_one_family_line(case):
    with pytest.raises(NambuBCHError) as info:
        MORE[case]()
    assert "\n" not in str(info.value)


def test_composed_map_takes_an_expression_as_the_step():
    """``h`` may be ``-h`` (time reversal) or a number; text is read, never run."""
    S = ho3().splitting
    h = sympy.Symbol("h")
    forward, backward = nb.composed_map(S, "12321"), nb.composed_map(S, "12321", -h)
    assert backward == tuple(sympy.expand(e.subs(h, -h)) for e in forward)
    assert nb.composed_map(S, "12321", "-h") == backward


@pytest.mark.parametrize("name", ["\\input{/etc/passwd}", "x}", "a b", "lambda", "x" * 40, "1x", ""])
def test_names_given_as_text_are_symbol_names(name):
    """A name string becomes a Symbol only if it is a plain identifier: nothing that acts in LaTeX or source."""
    with pytest.raises(NambuBCHError) as info:
        nb.PolynomialAlgebra(["x1", name])
    assert "\n" not in str(info.value) and "symbol name" in str(info.value)
