"""The gauge dimension of the direct route (``OrderSolution.psi_dim``) against a second elimination.

``psi_dim`` is the dimension of ``span{(psi_G, -psi_H) : psi = H^p G^q}`` within the ansatz of an order.  The
route reads it off the degrees of ``H, G`` (algebraically independent: the fitting pairs are independent) or,
for a degenerate pair, off the free columns of the elimination it already did; the reference below is the
former second pass, an elimination of the pairs themselves (``rank`` over the whole ansatz).
"""

from __future__ import annotations

import importlib

import pytest

from nambu_bch import model
from nambu_bch.algebra.ansatz import Ansatz
from nambu_bch.algebra.elimination import SparseMatrix, rank
dr = importlib.import_module("nambu_bch.shadow.direct_route")  # the package exports the function of the same name


def reference_psi_dim(alg, hams, D) -> int:
    """The rank of the pairs ``(psi_G, -psi_H)``, ``psi = H^p G^q``, that are vectors of the degree-``D`` ansatz."""
    n = alg.n
    H, G = hams
    ansatz = Ansatz(n, D, 2)
    vecs = []
    for p in range(D + 2):
        for q in range(D + 2):
            if p + q == 0:
                continue
            pair = (q * H**p * G ** (q - 1) if q else alg.zero, -(p * H ** (p - 1) * G**q) if p else alg.zero)
            vec, ok = {}, True
            for a, poly in enumerate(pair):
                for m, c in poly.items():
                    col = ansatz.index.get((a, m[:n]))
                    if col is None or any(m[n:]):
                        ok = False
                        break
                    vec[col] = c
                if not ok:
                    break
            if ok and vec:
                vecs.append(vec)
    return rank(SparseMatrix.from_rows(vecs, len(ansatz), alg.domain)) if vecs else 0


CASES = [("ho3", "12321", 6), ("ho3", "32123", 6), ("rigid-body", "12321", 4), ("rigid-body[I=1,2,3]", "12321", 6),
         ("lotka-volterra", "12321", 6)]


def system(name):
    """A catalog model; ``rigid-body[I=1,2,3]`` the rigid body with numeric moments (the former rank over QQ(I1, I2, I3)
    at h^6 takes minutes)."""
    if name == "rigid-body[I=1,2,3]":
        return model("rigid-body").substitute({"I1": 1, "I2": 2, "I3": 3})
    return model(name)


# the free-column path over QQ(I1, I2, I3) is the same code as over QQ (the reference rank there takes long)
PATHS = [pytest.param(*case, independent, id=f"{'degrees' if independent else 'free-columns'}-{case[0]}-{case[2]}")
         for independent in (True, False) for case in CASES if independent or case[0] != "rigid-body"]


@pytest.mark.parametrize("name, word, order, independent", PATHS)
def test_psi_dim_equals_second_elimination(monkeypatch, name, word, order, independent):
    """Both ways of reading ``psi_dim`` (degrees; the elimination's free columns) give the former rank, h^2 to h^order."""
    if not independent:  # force the degenerate-pair path on these (independent) pairs: the same number
        monkeypatch.setattr(dr._Solver, "_independent", lambda self: False)
    R = dr.direct_route(system(name), word, order)
    solved = [o for o in R.orders if o.status == "solved"]
    assert R.exists and {o.order for o in solved} >= set(range(2, order + 1, 2))
    for o in solved:
        expected = reference_psi_dim(R.algebra, R.hamiltonians, o.degree)
        assert o.psi_dim == expected, (o.order, o.degree)
        assert 0 < o.psi_dim <= o.kernel_dim


def test_psi_dim_degenerate_pair_is_a_rank():
    """``H, G`` algebraically dependent: the pairs of ``psi = H^p G^q`` are not independent, and the count is not the rank."""
    import sympy

    from nambu_bch.algebra import PolynomialAlgebra

    x1, x2, x3 = sympy.symbols("x1 x2 x3")
    alg = PolynomialAlgebra([x1, x2, x3])
    H = alg.convert(x1 + x2)
    G = alg.convert((x1 + x2) ** 2)
    solver = object.__new__(dr._Solver)
    solver.alg, solver.n, solver.hams, solver._jacobian_rank2 = alg, 3, (H, G), None
    assert not solver._independent()
    D = 4
    ansatz = Ansatz(3, D, 2)
    # the kernel of "no equation": every column is free
    assert solver._psi_dim(ansatz, D, ()) == reference_psi_dim(alg, (H, G), D)


@pytest.mark.parametrize("name", ["ho3[m=1,omega=2]", "rigid-body[I=1,2,3]", "lotka-volterra", "ho[m=1,omega=1]", "n4-single"])
def test_operator_columns_by_laplace_expansion_equal_liouville_field(name):
    """The columns of Eq. (*) from shifted cofactors (``_Solver._monomial_field``) equal the Liouville fields themselves."""
    from nambu_bch import System
    from nambu_bch.algebra import liouville_field
    from nambu_bch.integrators.composition import composition_for

    if name == "n4-single":
        sys_ = System("x1 x2 x3 x4", ["x1**2/2 + x2**2/2 + x3**2/2 + x4**2/2", "x1**2/2 + x2**2 + 3*x3**2/2 + 2*x4**2",
                                      "x1 + x2 + x3 + x4"], name="n4-single", split="single")
    elif name == "rigid-body[I=1,2,3]":
        sys_ = system(name)
    elif "[" in name:
        base, values = name[:-1].split("[")
        sys_ = model(base).substitute(dict(v.split("=") for v in values.split(",")))
    else:
        sys_ = model(name)
    solver = dr._Solver(sys_, composition_for("12321" if sys_.N == 3 else "121" if sys_.N == 2 else "1234321",
                                              sys_.splitting), 2, None)
    assert solver._laplace
    alg, hits = solver.alg, 0
    pad = (0,) * (len(alg.gens) - alg.n)
    for a, e in Ansatz(alg.n, 4, solver.slots).columns:
        slots = list(solver.hams)
        slots[a] = alg.ring.from_dict({e + pad: alg.domain.one})
        fast = solver._monomial_field(slots)
        hits += fast is not None
        assert (fast if fast is not None else solver._field(slots)).components == liouville_field(alg, *slots).components
    assert hits == sum(1 for _, e in Ansatz(alg.n, 4, solver.slots).columns if sum(e) >= 2)
