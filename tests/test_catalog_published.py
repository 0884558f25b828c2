"""The catalogue against the published values: every method of SplittingOrderConditions.jl's CheckMethods tables whose
coefficients are available, its order (exact order conditions), stages and error constants to the published digits.

Source of the published values: SplittingOrderConditions.jl (Auzinger, Herfort, Hofstaetter, Koch),
``examples/CheckMethods.ipynb``: the first table ("AB / ABC": columns ``AB p``, ``AB LEM``, ``ABC p``, ``ABC LEM`` and
the same four for the associated scheme, ``AB(assoc.)``, ``ABC(assoc.)``) and the second table ("ABC": ``p``,
``LEM``), LEM printed with two decimals (``%8.2f``).  LEM is the 2-norm of the Lyndon coordinates of the leading local
error (:func:`nambu_bch.design.error_analysis`); the ABC column applies a two-part method to three parts by
CheckMethods' rule (:func:`nambu_bch.integrators.composition.three_parts`).  The coefficients are those of
Auzinger, Hofstaetter & Koch's tables (www.asc.tuwien.ac.at/~winfried/splitting), which the notebook reads
(``nambu_bch/integrators/tables.py`` says where each was transcribed from).
"""

from __future__ import annotations

import re
import warnings

import sympy
import pytest

import nambu_bch as nb
from nambu_bch.design import error_analysis
from nambu_bch.design.system_error import field_size
from nambu_bch.integrators.composition import _number
from nambu_bch.integrators.tables import AUZINGER, TABLES

#: CheckMethods.ipynb, first table: (catalogue name, row, published s, AB p, AB LEM, ABC p, ABC LEM).  The
#: ``*-assoc`` entries are the row's ``AB(assoc.)`` and ``ABC(assoc.)`` columns.  ``s`` is the stage count in
#: Auzinger's tables (the name's first number where it has one, else the table file's ``s``).
AB_ROWS = [
    ("12", "Lie-Trotter", 1, 1, 1.00, 1, 1.73),
    ("121", "Strang", 2, 2, 0.56, 2, 1.20),
    ("best-2nd-order", "best 2-stage 2nd order", 2, 2, 0.09, 2, 0.31),
    ("am-32", "AM 3-2", 3, 2, 0.05, 2, 0.18),
    ("milne-22", "Milne 2/2 rational", 2, 2, 0.21, 2, 0.47),
    ("milne-22-assoc", "Milne 2/2 rational (assoc.)", 2, 2, 2.10, 2, 4.72),
    ("emb-32-aks", "Emb 3/2 AKS", 3, 3, 0.25, 3, 1.20),
    ("emb-32-aks-assoc", "Emb 3/2 AKS (assoc.)", 2, 2, 0.10, 2, 0.36),
    ("forest-ruth", "Y 4-4", 4, 4, 3.72, 4, 26.04),
    ("emb-43-ak-p", "Emb 4/3 AK p", 5, 4, 0.06, 4, 0.81),
    ("emb-43-ak-p-assoc", "Emb 4/3 AK p (assoc.)", 5, 3, 0.04, 3, 0.23),
    ("emb-43-ak-s", "Emb 4/3 AK s", 5, 4, 0.24, 4, 1.15),
    ("emb-43-ak-s-assoc", "Emb 4/3 AK s (assoc.)", 5, 3, 0.03, 3, 0.18),
    ("emb-43-m-ak", "Emb 4/3 M/AK", 6, 4, 0.01, 4, 0.36),
    ("blanes-moan", "Emb 4/3 BM PRK/A", 7, 4, 0.01, 4, 0.11),
    ("emb-43-bmprk-a-assoc", "Emb 4/3 BM PRK/A (assoc.)", 4, 3, 0.09, 3, 0.50),
    ("pp-34-a", "PP 3/4 A", 3, 3, 0.25, 3, 1.20),
    ("emb-54-ak", "Emb 5/4 AK (i)", 7, 5, 0.31, 5, 2.24),
    ("emb-54-ak-i-assoc", "Emb 5/4 AK (i) (assoc.)", 7, 4, 0.08, 4, 0.38),
    ("emb-54-ak", "Emb 5/4 AK (ii)", 7, 5, 0.31, 5, 2.24),
    ("emb-54-ak-ii-assoc", "Emb 5/4 AK (ii) (assoc.)", 8, 4, 0.02, 4, 0.14),
    ("emb-54-a", "Emb 5/4 A", 8, 5, 0.15, 5, 1.23),
    ("emb-54-a-assoc", "Emb 5/4 A (assoc.)", 7, 4, 0.05, 4, 0.18),
    ("pp-56-a", "PP 5/6 A", 8, 5, 0.15, 5, 1.23),
    ("yoshida6:121", "Y 8-6", 8, 6, 16.17, 6, 90.86),
    ("kahan-li:121", "KL 10-6", 10, 6, 1.84, 6, 10.70),
    ("blanes-moan-s10", "BM 11-6 PRK", 11, 6, 0.05, 6, 0.45),
    ("milne-22-c-i", "Milne 2/2 c (i)", 2, 2, 0.16, 2, 0.40),
    ("milne-22-c-i-assoc", "Milne 2/2 c (i) (assoc.)", 2, 2, 1.78, 2, 4.44),
    ("milne-22-c-ii", "Milne 2/2 c (ii)", 2, 2, 0.12, 2, 0.35),
    ("milne-22-c-ii-assoc", "Milne 2/2 c (ii) (assoc.)", 2, 2, 2.19, 2, 6.24),
    ("a-33-c", "A 3-3 c", 3, 3, 0.36, 3, 1.49),
    ("emb-32-a-c", "Emb 3/2 A c", 3, 3, 0.26, 3, 0.93),
    ("emb-32-a-c-assoc", "Emb 3/2 A c (assoc.)", 3, 2, 0.15, 2, 0.33),
]

#: CheckMethods.ipynb, second table ("ABC"): (name, row, s, p, LEM).  Y 7-4 and AY 15-6 are Yoshida's triple jump and
#: his sixth-order solution A composed of the notebook's Strang step, which is the package's word ``32123`` (the
#: published Strang LEM 1.48 identifies the letter order; ``12321`` has 1.20).
ABC_ROWS = [
    ("123", "Lie-Trotter", 1, 1, 1.73),
    ("32123", "Strang", 3, 2, 1.48),
    ("pp-34-a-3", "PP 3/4 A 3", 6, 3, 0.67),
    ("triple-jump:32123", "Y 7-4", 7, 4, 31.31),
    ("ak-114", "AK 11-4", 11, 4, 2.34),
    ("yoshida6:32123", "AY 15-6", 15, 6, 125.53),
]


def passes(pieces) -> int:
    """Auzinger's stage count ``s``: the passes ``A B`` (``A B C``) that cover the word, a new pass starting at every
    factor whose piece does not come after the previous factor's piece."""
    return 1 + sum(1 for a, b in zip(pieces, pieces[1:]) if b <= a)


@pytest.mark.parametrize("name, row, s, p, lem, p3, lem3", AB_ROWS, ids=[r[1] for r in AB_ROWS])
def test_ab_table_of_check_methods(name, row, s, p, lem, p3, lem3):
    """First table, row ``row``: the order from the exact order conditions, ``s``, and the AB and ABC LEM to the two
    published decimals."""
    comp = nb.composition(name)
    E, E3 = error_analysis(comp, 2), error_analysis(comp, 3)
    assert (E.order, round(E.value, 2)) == (p, lem)
    assert (E3.order, round(E3.value, 2)) == (p3, lem3)
    assert passes(comp.pieces) == s
    if name in TABLES:
        assert TABLES[name].order == p and TABLES[name].lem in ((lem, lem3), ())


@pytest.mark.parametrize("name, row, s, p, lem", ABC_ROWS, ids=[r[1] for r in ABC_ROWS])
def test_abc_table_of_check_methods(name, row, s, p, lem):
    """Second table ("ABC"), row ``row``: order, ``s`` and LEM to the two published decimals."""
    comp = nb.composition(name)
    E = error_analysis(comp, 3)
    assert (E.order, round(E.value, 2)) == (p, lem)
    assert passes(comp.pieces) == s
    if name in TABLES:
        assert TABLES[name].order == p and TABLES[name].stages == s and TABLES[name].lem == (lem,)


def test_every_transcribed_table_has_its_row():
    """Each table transcribed from Auzinger's tables is pinned above, with the stage count and the published error
    constants it states."""
    pinned = {r[0]: r[2] for r in AB_ROWS} | {r[0]: r[2] for r in ABC_ROWS}
    for table in AUZINGER:
        if table.name != "a-44-c":        # its row ("A 4-4 c") is pinned in tests/test_design_methods.py
            assert pinned[table.name] == table.stages, table.name
        assert table.kind == "word" and not table.takes_word and table.reference and table.lem


def test_rebuilt_factors_agree_with_the_published_digits():
    """The innermost factor of each piece is rebuilt as the complement of the others (exact consistency); the
    published decimal it replaces agrees with it to the digits printed, which checks the transcription."""
    for table in AUZINGER:
        if table.exact:
            continue
        half = nb.composition(table.name).coefficients[:len(table.word)]
        for k in set(table.word):
            inner = table.word.rindex(k)
            published = table.values[inner]
            digits = min(len(d) for d in re.findall(r"\.([0-9]+)", published))
            # ten units of the last digit, at least 1e-16: the tables were computed near double precision, and
            # emb-54-ak-ii-assoc's B coefficients, printed to 18-20 digits, sum to 1 - 3.6e-17
            tolerance = max(10.0 ** (1 - digits), 1e-16)
            assert abs(complex(half[inner] - _number(published, False))) <= tolerance, (table.name, k)


def test_complex_error_field_is_measured_by_its_modulus():
    """The size of a complex error field is the Hermitian norm sqrt(sum |F_i|^2): the real part alone understated the
    leading error of complex methods in ``compare`` (and numpy warned that it discarded the imaginary part)."""
    x1, x2 = sympy.symbols("x1 x2")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert field_size([sympy.I * x1 + x1, x2], "ho", box=[(1, 1), (2, 2)], samples=1) == pytest.approx(6 ** 0.5)


def test_complex_triple_jump_entry_is_the_pinned_row():
    """``a-44-c`` is the composition whose CheckMethods row "A 4-4 c" (0.42 / 1.22) tests/test_design_methods.py pins."""
    from tests.test_design_methods import COMPLEX_TRIPLE_JUMP

    pairs = zip(nb.composition("a-44-c").coefficients, nb.composition(COMPLEX_TRIPLE_JUMP).coefficients)
    assert all(abs(sympy.N(a - b, 60)) < 1e-50 for a, b in pairs)     # the same numbers, written differently
    assert nb.composition("a-44-c").symmetric and nb.composition("a-44-c").is_complex


def test_three_part_entries_refuse_a_two_part_system():
    with pytest.raises(nb.NambuBCHError, match="piece"):
        nb.composition("ak-114").check(nb.model("ho").splitting)


def test_compare_accepts_the_catalogue_names(cli_run, tmp_path):
    """``nambu-bch compare --integrator NAME`` with new real and complex entries: the published orders as slopes."""
    r = cli_run("compare", "--model", "ho", "--integrator", "emb-43-ak-s", "--integrator", "milne-22-c-i",
                "--t-end", "1", "--step-counts", "10,20", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rows = {line.split()[0]: line.split() for line in r.stdout.splitlines() if line.startswith(("emb-", "milne-"))}
    assert rows["emb-43-ak-s"][1] == "4" and rows["milne-22-c-i"][1] == "2"
    assert rows["emb-43-ak-s"][3] == "0.2412" and rows["milne-22-c-i"][3] == "0.1586"
    # |Z_2|max of the complex method: Z_2 = (x2 (1 + 6i)/222, x1 (-7 + 6i)/204) at m = omega = 1 is at most
    # sqrt(37/222^2 + 85/204^2) = 0.0528 on [-1, 1]^2; its real part alone (the size before) at most 0.0346
    assert 0.05 < float(rows["milne-22-c-i"][5]) <= 0.0528
    assert "Warning" not in r.stderr
