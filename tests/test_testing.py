"""nambu_bch.testing: the assertions (in-process) and the plugin in a separate pytest run (examples/)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import sympy

from nambu_bch.testing import assert_fields_equal, assert_invariant, assert_shadow_pair, liouville_components

REPO = Path(__file__).resolve().parents[1]
x1, x2, x3, m, omega, h, alpha = sympy.symbols("x1 x2 x3 m omega h alpha")


def test_fixtures_come_from_the_plugin(ho, ho3, rigid_body, lotka_volterra, ho3_composite, paper_words, symbols):
    assert [s.name for s in (ho, ho3, rigid_body, lotka_volterra, ho3_composite)] == [
        "ho", "ho3", "rigid-body", "lotka-volterra", "ho3-composite"]
    assert "12321" in paper_words and len(paper_words) == 6
    assert symbols["alpha"] == alpha


def test_the_entry_point_is_the_light_plugin_module():
    """pyproject's pytest11 entry point names the fixtures' own module (pytest imports it in every test run of any
    project where the package is installed: test_printing checks it imports no sympy); nambu_bch.testing re-exports
    the same fixtures for ``-p nambu_bch.testing``."""
    import tomllib

    from nambu_bch import _pytest_plugin, testing

    entry = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["entry-points"]["pytest11"]
    assert entry == {"nambu_bch": "nambu_bch._pytest_plugin"}
    assert all(getattr(testing, name) is getattr(_pytest_plugin, name) for name in _pytest_plugin.__all__)


def test_liouville_components_match_the_library(ho3, rigid_body):
    """X_{H,G} by the Jacobian determinant agrees with System.vector_field (Eq. gLiouville)."""
    for S in (ho3, rigid_body):
        assert_fields_equal(liouville_components(S.coordinates, *S.hamiltonians), S.vector_field)


def test_assert_fields_equal_failure_shows_residual(ho3):
    with pytest.raises(AssertionError) as info:
        assert_fields_equal(ho3.vector_field, (x2 / m, -m * omega**2 * x1, 0), msg="Eq. (NambuOHeqs): ")
    text = str(info.value)
    assert text.startswith("Eq. (NambuOHeqs): fields differ") and "d/dx3: 2*x1*x2/m" in text
    assert "d/dx1" not in text
    with pytest.raises(AssertionError, match="2 and 3 coordinates"):
        assert_fields_equal((x1, x2), (x1, x2, x3))


def test_assert_shadow_pair_paper_values(ho, ho3):
    """Eq. (SHPV1) (with an O(h^4) term, dropped) and Eqs. (SH12321c), (SG12321c) for every alpha."""
    H_S = ho.H - omega**2 * h**2 * x2**2 / (24 * m) + m * omega**4 * h**2 * x1**2 / 12 + sympy.O(h**4)
    assert_shadow_pair(ho, "TVT", H_S, order=3)
    H_S = ho3.H + alpha * omega**2 / (12 * m) * h**2 * x2**2 + alpha * m * omega**4 / 12 * h**2 * x1**2
    G_S = ho3.G + h**2 * x2**2 / (12 * m**2) + alpha / (6 * m**2) * h**2 * x2**2 - (1 - alpha) * omega**2 / 6 * h**2 * x1**2
    assert_shadow_pair(ho3, "12321", H_S, G_S, order=2)


def test_assert_shadow_pair_non_polynomial(ho):
    """Eq. (SHPV2): H_S^e = F(omega h) H_c, compared through h^4 by series expansion."""
    y = omega * h
    F = 2 * sympy.asin(y / 2) / (y * sympy.sqrt(1 - y**2 / 4))
    H_c = ho.H - omega**2 / (8 * m) * h**2 * x2**2
    assert_shadow_pair(ho, "TVT", F * H_c, order=4)


def test_assert_shadow_pair_failures(ho, ho3):
    with pytest.raises(AssertionError) as info:
        assert_shadow_pair(ho, "TVT", ho.H, order=2)
    assert "at h^2:" in str(info.value) and "at h^0" not in str(info.value)
    with pytest.raises(AssertionError, match="give G_S"):
        assert_shadow_pair(ho3, "12321", ho3.H)
    with pytest.raises(AssertionError, match="G_S must be None"):
        assert_shadow_pair(ho, "TVT", ho.H, "x1")


def test_assert_invariant(ho3):
    """Eqs. (CQ12321H), (CQ12321G); G alone is not invariant."""
    assert_invariant(ho3, "12321", ho3.H)
    assert_invariant(ho3, "12321", ho3.G + h**2 * x2**2 / (4 * m**2))
    with pytest.raises(AssertionError, match=r"x3 - x1\*\*2|-x1\*\*2 \+ x3"):
        assert_invariant(ho3, "12321", "x3 - x1^2")


def test_assert_invariant_rejects_unsafe_string(ho3):
    from nambu_bch.errors import ExpressionParseError

    with pytest.raises(ExpressionParseError):
        assert_invariant(ho3, "12321", "__import__('os').getcwd()")


def _pytest(*extra):
    # the example suite uses no hypothesis: its plugin (an entry point like the package's) would import hypothesis in
    # the child, about a third of the child's CPU
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:hypothesispytest", "examples/",
         *extra],
        cwd=REPO, env=env, capture_output=True, text=True, timeout=300,
    )


def test_example_suite_runs_with_the_entry_point_plugin():
    """The pytest11 entry point provides the fixtures; the example suite passes (incl. its failure-message checks)."""
    done = _pytest()
    assert done.returncode == 0, done.stdout + done.stderr
    assert "passed" in done.stdout and "failed" not in done.stdout


def test_example_suite_with_explicit_plugin():
    """``-p nambu_bch.testing`` loads the plugin explicitly (here with the entry point disabled)."""
    done = _pytest("-p", "no:nambu_bch", "-p", "nambu_bch.testing", "-k", "verlet or motion or not_invariant")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "4 passed" in done.stdout, done.stdout


def test_a_failing_invariant_names_a_witness_and_the_lowest_power(ho3, rigid_body):
    """A residual proved non-zero at a rational point is reported there, with its lowest power of h (no simplify)."""
    with pytest.raises(AssertionError) as info:
        assert_invariant(ho3, "12321", "x3 - x1^2")
    text = str(info.value)
    assert "at h = " in text and "lowest power of h (numerically there):" in text and text.endswith("h^3")
    with pytest.raises(AssertionError) as info:
        assert_invariant(rigid_body, "123", rigid_body.H)   # Lie-Trotter: the energy moves at h^2
    text = str(info.value)
    assert text.endswith("h^2") and len(text) < 1000


def test_a_long_residual_is_cut():
    from nambu_bch.testing import MAX_SHOWN, _short

    long = sympy.Add(*(x1**k for k in range(200)))
    assert len(_short(long)) < MAX_SHOWN + 40 and _short(long).endswith("(200 terms)")
