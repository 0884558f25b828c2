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
    field = _Exact(comp)
    defects = [abs(field.K.to_sympy(v)) for q in range(1, table.order + 1) for v in field.defects(2, q).values()]
    bound = getattr(comp, "error_bound", 0.0)
    if table.values:
        assert 0 < bound < 1e-12 and max(float(d) for d in defects) == bound
    else:
        assert bound == 0.0 and all(d == 0 for d in defects)
    assert error_analysis(comp, 2).order == table.order == comp.order
    assert comp.symmetric == table.symmetric
    assert table.reference and comp.citation.startswith(table.reference)


def test_table_stages_match_the_data():
    for table in TABLES.values():
        if table.kind == "stages":
            assert 2 * len(table.values) + 1 == table.stages
        elif table.kind == "ab":
            a, b = table.values
            assert 2 * (len(b) + 1) == table.stages and len(a) == len(b) + 1   # the middle b is the complement
            assert _built(table).pieces.count(2) == table.stages


def test_tables_are_frozen_and_design_only_reads_them():
    with pytest.raises(dataclasses.FrozenInstanceError):
        TABLES["kahan-li"].order = 4
    assert catalog.CatalogComposition is methods.CatalogComposition and catalog.lookup is methods.lookup
    assert catalog.NAMES == tuple(n for n, t in TABLES.items() if t.kind != "jump")
    assert set(catalog.methods()) == {"suzuki", *catalog.NAMES}
