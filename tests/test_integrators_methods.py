"""The literature's coefficient tables (integrators/tables.py): frozen data, each checked against its order conditions."""

from __future__ import annotations

import dataclasses

import pytest

import nambu_bch as nb
from nambu_bch.design import catalog
from nambu_bch.design.conditions import _Exact, error_analysis
from nambu_bch.integrators import methods
from nambu_bch.integrators.tables import TABLES, MethodTable


def _built(table: MethodTable):
    return nb.composition(table.name if not table.takes_word else f"{table.name}:121")


@pytest.mark.parametrize("name", sorted(TABLES))
def test_table_meets_its_order_conditions(name):
    """Every Lyndon defect of length <= order vanishes: exactly for exact coefficients, to the stated bound (computed
    exactly from the published decimals read as rationals) for decimal tables; the next length does not vanish."""
    table = TABLES[name]
    comp = _built(table)
    bound = getattr(comp, "error_bound", 0.0)
    if table.structure == "rkn":  # the published order holds modulo the RKN ideal (tests/test_design_structure.py)
        assert 0 < bound < 1e-12
        assert error_analysis(comp, structure="rkn").order == table.order == comp.order
        return
    field = _Exact(comp)
    parts = comp.n_pieces    # two-part methods, and the three-part ones of CheckMethods' ABC table
    defects = [abs(complex(field.K.to_sympy(v))) for q in range(1, table.order + 1)
               for v in field.defects(parts, q).values()]
    if table.values and not table.exact and table.generalized:  # the bound covers the generalised conditions too
        assert 0 <= max(float(d) for d in defects) <= bound < 1e-12
    elif table.values and not table.exact:   # (0 when the decimals meet every condition exactly, as symmetry may)
        assert 0 <= bound < 1e-12 and max(float(d) for d in defects) == bound
    else:
        assert bound == 0.0 and all(d == 0 for d in defects)
    assert error_analysis(comp, parts).order == table.order == comp.order
    assert comp.symmetric == table.symmetric
    assert table.reference and comp.citation.startswith(table.reference)


def test_table_stages_match_the_data():
    for table in TABLES.values():
        if table.kind == "stages":
            assert 2 * len(table.values) + 1 == table.stages
        elif table.kind == "ab":
            x, y = table.values
            assert len(x) in (len(y), len(y) + 1)   # the middle factor (1 - 2 sum) is the first piece's or the other's
            fsal = 1 if table.first == 2 else 0     # piece 2 outermost: its last factor is the next step's first
            assert _built(table).pieces.count(2) - fsal == table.stages


def test_tables_are_frozen_and_design_only_reads_them():
    with pytest.raises(dataclasses.FrozenInstanceError):
        TABLES["kahan-li"].order = 4
    assert catalog.CatalogComposition is methods.CatalogComposition and catalog.lookup is methods.lookup
    assert catalog.NAMES == tuple(n for n, t in TABLES.items() if t.kind != "jump")
    assert set(catalog.methods()) == {"suzuki", *catalog.NAMES}
