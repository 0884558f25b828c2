"""An example of a researcher's own test suite built on ``nambu_bch.testing``.

Run it with ``python -m pytest examples/`` (the plugin is loaded through the
``pytest11`` entry point of the installed package) or, explicitly,
``python -m pytest examples/ -p nambu_bch.testing``.

The fixtures ``ho``, ``ho3``, ``paper_words`` ... come from the plugin; the
assertions check the paper's results exactly.  Each test names the equation
label of Horikoshi's paper it reproduces.
"""

import pytest
import sympy

from nambu_bch.testing import assert_fields_equal, assert_invariant, assert_shadow_pair

# Table (table): the conserved quantities (H_c - H, G_c - G) of the six second-order words.
TABLE = {
    "12321": ("0", "h^2*x2^2/(4*m^2)"),
    "13231": ("0", "h^2*x2^2/(4*m^2)"),
    "31213": ("-omega^2/(4*m)*h^2*x2^2", "-h^2*x2^2/(4*m^2)"),
    "21312": ("-m*omega^4/8*h^2*x1^2", "0"),
    "23132": ("-m*omega^4/8*h^2*x1^2", "0"),
    "32123": ("m*omega^4/8*h^2*x1^2", "omega^2/2*h^2*x1^2"),
}


def test_shadow_hamiltonian_of_position_verlet(ho):
    """Eq. (SHPV1): H_S = H - omega^2 h^2 x2^2/(24 m) + m omega^4 h^2 x1^2/12 + O(h^4)."""
    H_S = ho.H - sympy.sympify("omega**2*h**2*x2**2/(24*m) - m*omega**4*h**2*x1**2/12")
    assert_shadow_pair(ho, "TVT", H_S, order=3)


def test_alpha_family_of_12321(ho3):
    """Eqs. (SH12321c), (SG12321c): a shadow pair for every alpha."""
    H_S = "x2^2/(2*m) + m*omega^2*x3/2 + alpha*omega^2/(12*m)*h^2*x2^2 + alpha*m*omega^4/12*h^2*x1^2"
    G_S = "x3 - x1^2 + h^2*x2^2/(12*m^2) + alpha/(6*m^2)*h^2*x2^2 - (1 - alpha)*omega^2/6*h^2*x1^2"
    assert_shadow_pair(ho3, "12321", H_S, G_S, order=2)


def test_conserved_quantity_of_position_verlet(ho):
    """Eq. (CQPV): H_c = H - omega^2 h^2 x2^2/(8 m) is exactly conserved."""
    assert_invariant(ho, "TVT", "x2^2/(2*m) + m*omega^2*x1^2/2 - omega^2/(8*m)*h^2*x2^2")


@pytest.mark.parametrize("word", sorted(TABLE))
def test_table_of_conserved_quantities(ho3, paper_words, word):
    """Table (table): H_c and G_c of each of the six words are exact invariants."""
    assert word in paper_words
    dH, dG = TABLE[word]
    assert_invariant(ho3, word, f"x2^2/(2*m) + m*omega^2*x3/2 + {dH}")
    assert_invariant(ho3, word, f"x3 - x1^2 + {dG}")


def test_equations_of_motion(ho3, symbols):
    """Eq. (NambuOHeqs): dx/dt = (x2/m, -m omega^2 x1, 2 x1 x2/m)."""
    x1, x2, m, omega = (symbols[k] for k in ("x1", "x2", "m", "omega"))
    assert_fields_equal(ho3.vector_field, (x2 / m, -m * omega**2 * x1, 2 * x1 * x2 / m))


def test_conserved_quantity_is_not_a_shadow_hamiltonian(ho):
    """Eq. (XHc): X_{H_c} != X_eff -- the helper says where and by how much."""
    H_c = "x2^2/(2*m) + m*omega^2*x1^2/2 - omega^2/(8*m)*h^2*x2^2"
    with pytest.raises(AssertionError) as failure:
        assert_shadow_pair(ho, "TVT", H_c, order=2)
    message = str(failure.value)
    assert "at h^2" in message
    assert "d/dx1: -omega**2*x2/(6*m)" in message
    assert "d/dx2: m*omega**4*x1/6" in message


def test_original_G_is_not_invariant(ho3):
    """G itself drifts under Phi^{12321} (Fig. 2): the failure message shows the residual."""
    with pytest.raises(AssertionError, match=r"not invariant under Phi_h = 12321 .* residual I\(Phi_h\(x\)\) - I\(x\) = "):
        assert_invariant(ho3, "12321", "x3 - x1^2")


def test_library_family_is_a_shadow_pair(ho3):
    """The alpha-family that nambu_bch derives (Eqs. SH12321c/SG12321c continued to h^4) passes the independent check."""
    from nambu_bch.shadow import shadow_hamiltonians

    family = shadow_hamiltonians(ho3, "12321", order=4)
    assert family.exists and family.free_parameters == ["alpha"]
    assert_shadow_pair(ho3, "12321", family.H_S, family.G_S, order=4)
