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
    a palindromic two-part method alternating the pieces, starting with piece ``first`` (1 unless stated):
    ``A(a_1) B(b_1) A(a_2) ... B(b_1) A(a_1)``; ``values`` are the outer coefficients of the first piece and of the
    other one up to the middle.  The piece with an odd number of factors has the middle factor
    ``1 - 2 sum(outer)``; the other has a middle pair ``1/2 - sum(outer)`` each (so ``len(values[0]) ==
    len(values[1]) + 1`` when the first piece has the middle factor, equal lengths when the other one has it).
    ``stages`` counts the factors of piece 2 (force evaluations), one less when piece 2 is outermost (first same as
    last).

Structure.  ``structure`` names the problem class on which the published order holds: ``""`` every splitting,
``"rkn"`` ``T(p) + V(q)`` with ``T`` quadratic (piece 1 = ``T``, piece 2 = ``V``; :mod:`nambu_bch.design.structure`),
``"near-integrable"`` ``A + eps B`` (piece 1 = ``A``), with the published generalised order in ``generalized``.
``exact`` tables give their coefficients as exact formulas (trusted internal text, read by ``sympify(strict=True)``).
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
    first : int        -- ``"ab"``: the piece of the outermost factors
    structure : str    -- ``""``, ``"rkn"`` or ``"near-integrable"`` (module docstring)
    generalized : tuple -- published generalised order ``(r_1, r_2, ...)`` of a near-integrable method
    exact : bool       -- ``values`` are exact formulas rather than decimals
    """

    name: str
    reference: str
    order: int
    stages: int
    symmetric: bool
    kind: str
    values: tuple = ()
    takes_word: bool = True
    first: int = 1
    structure: str = ""
    generalized: tuple = ()
    exact: bool = False


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


# Runge-Kutta-Nystrom methods: piece 1 = T(p) (drift), piece 2 = V(q) (kick); orders hold for T quadratic in p.
_BM = "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 3"
#: SRKN_6^b: kicks b_1, b_2, b_3 (b_4 = 1 - 2 sum, the middle) and drifts a_1, a_2 (a_3 = 1/2 - a_1 - a_2).
BM_SRKN6 = MethodTable("bm-srkn6", f"{_BM} (SRKN_6^b)", 4, 6, True, "ab",
                       (("0.0829844064174052", "0.396309801498368", "-0.0390563049223486"),
                        ("0.245298957184271", "0.604872665711080")),
                       takes_word=False, first=2, structure="rkn")
#: SRKN_11^b: kicks b_1..b_5 (middle pair b_6 = 1/2 - sum) and drifts a_1..a_5 (middle a_6 = 1 - 2 sum).
BM_SRKN11 = MethodTable("bm-srkn11", f"{_BM} (SRKN_11^b)", 6, 11, True, "ab",
                        (("0.0414649985182624", "0.198128671918067", "-0.0400061921041533", "0.0752539843015807",
                          "-0.0115113874206879"),
                         ("0.123229775946271", "0.290553797799558", "-0.127049212625417", "-0.246331761062075",
                          "0.357208872795928")),
                        takes_word=False, first=2, structure="rkn")
#: PEFRL: drifts xi, chi (middle 1 - 2(xi + chi)); kicks (1 - 2 lambda)/2 = 1/2 - lambda, then the pair lambda.
#: xi = 0.1786178958448091, lambda = -0.2123418310626054, chi = -0.06626458266981849 as published.
PEFRL = MethodTable("pefrl", "Omelyan, Mryglod & Folk, Comput. Phys. Commun. 146 (2002) 188 (PEFRL)", 4, 4,
                    True, "ab", (("0.1786178958448091", "-0.06626458266981849"), ("0.7123418310626054",)),
                    takes_word=False)
#: SRKN_14^a: drifts a_1..a_7 (middle a_8 = 1 - 2 sum) and kicks b_1..b_6 (middle pair b_7 = 1/2 - sum); the digits
#: as transcribed in Principia's integrators/methods.hpp (BlanesMoan2002SRKN14A).
BM_SRKN14 = MethodTable("bm-srkn14", f"{_BM} (SRKN_14^a)", 6, 14, True, "ab",
                        (("0.0378593198406116", "0.102635633102435", "-0.0258678882665587", "0.314241403071447",
                          "-0.130144459517415", "0.106417700369543", "-0.00879424312851058"),
                         ("0.09171915262446165", "0.183983170005006", "-0.05653436583288827", "0.004914688774712854",
                          "0.143761127168358", "0.328567693746804")),
                        takes_word=False, structure="rkn")
_McL = "McLachlan, SIAM J. Sci. Comput. 16 (1995) 151"
#: SB3A_4: drifts a_1, a_2 (middle 1 - 2 sum = 2/3), kicks 1 then the pair -1/2; 20 digits as transcribed in
#: Principia's integrators/methods.hpp (McLachlan1995SB3A4).
MCLACHLAN_SB3A4 = MethodTable("mclachlan-sb3a4", f"{_McL} (SB3A, 4 stages)", 4, 4, True, "ab",
                              (("0.18819521776883821787", "-0.021528551102171551201"), ("1",)),
                              takes_word=False, structure="rkn")

# General two-part methods (any splitting).
#: Blanes-Moan S10: a_1..a_5 (middle 1 - 2 sum) and b_1..b_4 (middle pair 1/2 - sum), as in blanes-moan (S6).
BLANES_MOAN_S10 = MethodTable("blanes-moan-s10", "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 2 (S10)",
                              6, 10, True, "ab",
                              (("0.0502627644003922", "0.413514300428344", "0.0450798897943977", "-0.188054853819569",
                                "0.541960678450780"),
                               ("0.148816447901042", "-0.132385865767784", "0.067307604692185", "0.432666402578175")),
                              takes_word=False)
#: McLachlan's S2 = A(b) B(1/2) A(1 - 2b) B(1/2) A(b), b = 0.19318332750378357396 (the minimum-norm 2-stage
#: method; 20 digits as transcribed in Principia's integrators/methods.hpp, McLachlan1995S2).
MCLACHLAN_S2 = MethodTable("mclachlan-s2", f"{_McL} (S2, 2 stages)", 2, 2, True, "ab",
                           (("0.19318332750378357396",), ()), takes_word=False)
#: McLachlan's S4 (4 stages, order 4): A outer b_1, b_2 (middle 1 - 2 sum); B outer 6/11 (middle pair -1/22).
MCLACHLAN_S4 = MethodTable("mclachlan-s4", f"{_McL} (S4, 4 stages)", 4, 4, True, "ab",
                           (("0.16913927992207204518", "-0.29918620390405079951"), ("0.54545454545454545455",)),
                           takes_word=False)
#: McLachlan's S5 (5 stages, order 4): A outer b_1, b_2 (middle pair 1/2 - sum); B outer 0.4, -0.1 (middle 0.4).
MCLACHLAN_S5 = MethodTable("mclachlan-s5", f"{_McL} (S5, 5 stages)", 4, 5, True, "ab",
                           (("0.089269454226475244887", "-0.097336042636895508015"), ("0.4", "-0.1")),
                           takes_word=False)

# Near-integrable methods for A + eps B (piece 1 = A): nodes and weights of Gauss (SABA) and Lobatto (SBAB)
# quadrature, exact; Laskar & Robutel give the generalised order (2n, 2).
_LR = "Laskar & Robutel, Celest. Mech. Dyn. Astr. 80 (2001) 39, Sect. 3"
SABA2 = MethodTable("saba2", f"{_LR} (SABA_2)", 2, 2, True, "ab", (("1/2 - sqrt(3)/6",), ()), takes_word=False,
                    structure="near-integrable", generalized=(4, 2), exact=True)
SABA3 = MethodTable("saba3", f"{_LR} (SABA_3)", 2, 3, True, "ab", (("1/2 - sqrt(15)/10",), ("5/18",)),
                    takes_word=False, structure="near-integrable", generalized=(6, 2), exact=True)
SABA4 = MethodTable("saba4", f"{_LR} (SABA_4)", 2, 4, True, "ab",
                    (("1/2 - sqrt(525 + 70*sqrt(30))/70", "(sqrt(525 + 70*sqrt(30)) - sqrt(525 - 70*sqrt(30)))/70"),
                     ("1/4 - sqrt(30)/72",)),
                    takes_word=False, structure="near-integrable", generalized=(8, 2), exact=True)
SBAB2 = MethodTable("sbab2", f"{_LR} (SBAB_2)", 2, 2, True, "ab", (("1/6",), ()), takes_word=False, first=2,
                    structure="near-integrable", generalized=(4, 2), exact=True)
SBAB3 = MethodTable("sbab3", f"{_LR} (SBAB_3)", 2, 3, True, "ab", (("1/12",), ("1/2 - sqrt(5)/10",)),
                    takes_word=False, first=2, structure="near-integrable", generalized=(6, 2), exact=True)

#: Blanes, Casas, Farres, Laskar, Makazaga & Murua's ABA864 and ABA1064 for A + eps B: the published 16-digit
#: coefficients alpha_1.. of the form chi*(alpha_1) chi(alpha_2) chi*(alpha_3) ... (chi = exp(alpha A) exp(alpha B) and
#: its adjoint), as transcribed in a public Python integrator; merged here into the ABA form, a_1 = alpha_1,
#: b_i = alpha_(2i-1) + alpha_(2i), a_(i+1) = alpha_(2i) + alpha_(2i+1) (exact sums of the decimals).  ABA864: A outer
#: a_1..a_3 (middle pair a_4 = 1/2 - sum), B outer b_1..b_3 (middle b_4 = 1 - 2 sum); ABA1064: A outer a_1..a_4 (middle
#: a_5 = 1 - 2 sum), B outer b_1..b_3 (middle pair b_4 = 1/2 - sum).  Their generalised orders (8, 6, 4) and (10, 6, 4)
#: are checked by tests/test_families_on_systems.py to the decimals' accuracy.
_BCFLMM = "Blanes, Casas, Farres, Laskar, Makazaga & Murua, Appl. Numer. Math. 68 (2013) 58"
ABA864 = MethodTable("aba864", f"{_BCFLMM} (ABA864)", 4, 7, True, "ab",
                     (("0.07113342649822312", "0.2411534279566401", "0.5214117617728147"),
                      ("0.18308368747219722", "0.3107828598985748", "-0.0265646185119588")),
                     takes_word=False, structure="near-integrable", generalized=(8, 6, 4))
ABA1064 = MethodTable("aba1064", f"{_BCFLMM} (ABA1064)", 4, 8, True, "ab",
                      (("0.03809449742241219", "0.14529871611691375", "0.2076276957255412", "0.4359097036515261"),
                       ("0.0958588808370752", "0.20444615314299874", "0.2170703479789911")),
                      takes_word=False, structure="near-integrable", generalized=(10, 6, 4))

#: Every table by name.
TABLES = {t.name: t for t in (TRIPLE_JUMP, SUZUKI, KAHAN_LI, YOSHIDA6, BLANES_MOAN, BLANES_MOAN_S10, MCLACHLAN_S2,
                              MCLACHLAN_S4, MCLACHLAN_S5, BM_SRKN6, BM_SRKN11, BM_SRKN14, MCLACHLAN_SB3A4, PEFRL,
                              SABA2, SABA3, SABA4, SBAB2, SBAB3, ABA864, ABA1064)}
#: The tables built by :mod:`.methods` (published decimals, or exact formulas); the jumps are built in :mod:`.composition`.
DECIMAL = tuple(name for name, t in TABLES.items() if t.kind != "jump")
