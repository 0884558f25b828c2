"""The composition methods of the literature as frozen coefficient tables: data only, each with its reference.

A table holds what the paper publishes and nothing computed: the order, whether the method is symmetric, its number
of stages, and its coefficients (exact formulas are built in :mod:`.composition`, published decimals are kept as the
strings printed in the paper).  :mod:`.methods` turns a table into a :class:`~.composition.Composition`;
:mod:`nambu_bch.design` only reads these tables.  ``tests/test_integrators_methods.py`` checks each table against its
order conditions: exactly for exact coefficients, to the stated bound for decimals.

Kinds
-----
``"jump"``
    an exact composition of ``stages`` steps of a symmetric base word (``NAME:WORD``), built in :mod:`.composition`;
``"stages"``
    a palindromic composition of ``stages`` steps of a symmetric second-order base word with steps
    ``gamma_1 h, ..., gamma_k h, gamma_mid h, gamma_k h, ..., gamma_1 h``; ``values`` are ``gamma_1 .. gamma_k``
    (outermost first) and ``gamma_mid = 1 - 2 (gamma_1 + ... + gamma_k)``;
``"ab"``
    a palindromic two-part method ``A(a_1) B(b_1) A(a_2) ... B(b_1) A(a_1)``; ``values`` are ``(a_1, a_2, ...)`` and
    ``(b_1, b_2, ...)`` up to the middle, whose coefficients are the complements (``a_mid = 1 - 2 sum a``,
    ``b_mid = 1/2 - sum b``).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class MethodTable:
    """A composition method as published.

    Attributes
    ----------
    name : str         -- the name ``composition()`` accepts (``name`` or ``name:WORD``)
    reference : str
    order : int
    stages : int       -- base steps (``"jump"``, ``"stages"``) or A/B pairs (``"ab"``)
    symmetric : bool
    kind : str         -- ``"jump"``, ``"stages"`` or ``"ab"`` (module docstring)
    values : tuple     -- published decimals as strings (empty for exact formulas)
    takes_word : bool  -- composes a base word given as ``name:WORD`` (else it is a method of fixed pieces)
    """

    name: str
    reference: str
    order: int
    stages: int
    symmetric: bool
    kind: str
    values: tuple = ()
    takes_word: bool = True


TRIPLE_JUMP = MethodTable("triple-jump", "Yoshida, Phys. Lett. A 150 (1990) 262; Forest & Ruth, Physica D 43 (1990) 105",
                          4, 3, True, "jump")
SUZUKI = MethodTable("suzuki", "Suzuki, Phys. Lett. A 146 (1990) 319", 4, 5, True, "jump")
#: gamma_1 .. gamma_4 of the Kahan-Li p6 s9 composition, as published (gamma_5 the middle one).
KAHAN_LI = MethodTable(
    "kahan-li", "Kahan & Li, Math. Comp. 66 (1997) 1089; Hairer, Lubich, Wanner, GNI, Sect. V.3.2, Eq. (3.11)", 6, 9,
    True, "stages",
    ("0.39216144400731413927925056", "0.33259913678935943859974864", "-0.70624617255763935980996482",
     "0.08221359629355080023149045"))
#: w_3, w_2, w_1 of Yoshida's sixth-order solution A (outermost first); w_0 = 1 - 2(w_1 + w_2 + w_3).
YOSHIDA6 = MethodTable("yoshida6", "Yoshida, Phys. Lett. A 150 (1990) 262, Table 1, solution A", 6, 7, True, "stages",
                       ("0.784513610477560", "0.235573213359357", "-1.17767998417887"))
#: a_1, a_2, a_3 and b_1, b_2 of Blanes-Moan S6; a_4 = 1 - 2(a_1 + a_2 + a_3), b_3 = 1/2 - b_1 - b_2.
BLANES_MOAN = MethodTable("blanes-moan", "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 2 (S6)", 4, 6,
                          True, "ab",
                          (("0.0792036964311957", "0.353172906049774", "-0.0420650803577195"),
                           ("0.209515106613362", "-0.143851773179818")),
                          takes_word=False)

#: Every table by name.
TABLES = {t.name: t for t in (TRIPLE_JUMP, SUZUKI, KAHAN_LI, YOSHIDA6, BLANES_MOAN)}
#: The tables with published decimals (built by :mod:`.methods`); the jumps are built in :mod:`.composition`.
DECIMAL = tuple(name for name, t in TABLES.items() if t.kind != "jump")
