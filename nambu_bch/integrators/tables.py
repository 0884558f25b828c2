"""The composition methods of the literature as frozen coefficient tables: data only, each with its reference.

A table holds what the paper publishes and nothing computed: the order, whether the method is symmetric, its number
of stages, its coefficients (exact formulas are built in :mod:`.composition`, published decimals are kept as the
strings printed in the paper) and, where SplittingOrderConditions.jl's CheckMethods notebook lists them, its error
constants (``lem``).  :mod:`.methods` turns a table into a :class:`~.composition.Composition`;
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
    kind : str         -- ``"jump"``, ``"stages"``, ``"ab"`` or ``"word"`` (module docstring)
    values : tuple     -- published decimals as strings (empty for exact formulas)
    takes_word : bool  -- composes a base word given as ``name:WORD`` (else it is a method of fixed pieces)
    first : int        -- ``"ab"``: the piece of the outermost factors
    structure : str    -- ``""``, ``"rkn"`` or ``"near-integrable"`` (module docstring)
    generalized : tuple -- published generalised order ``(r_1, r_2, ...)`` of a near-integrable method
    exact : bool       -- ``values`` are exact formulas rather than decimals
    word : str         -- ``"word"``: the piece of each listed factor (module docstring)
    lem : tuple        -- published error constants (LEM, two decimals) of SplittingOrderConditions.jl's CheckMethods:
                          ``(AB, ABC)`` for a two-part method (ABC by the notebook's rule for three parts), ``(ABC,)``
                          for a three-part one; empty where none is published
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
    word: str = ""
    lem: tuple = ()


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
                          takes_word=False, lem=(0.01, 0.11))


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
                              takes_word=False, lem=(0.05, 0.45))
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

# The tables of Auzinger, Hofstaetter & Koch, "Coefficients of various splitting methods",
# www.asc.tuwien.ac.at/~winfried/splitting/ -- the files SplittingOrderConditions.jl's examples/CheckMethods.ipynb reads
# (its tables "AB / ABC" and "ABC") -- as transcribed, with the same names, orders, stages and digits, in the Fortran
# module tssm_splitting_schemes.F90 of HaraldHofstaetter/TSSM.  ``*-assoc`` is the "associated scheme" of an embedded
# pair or Milne pair (CheckMethods' columns "AB(assoc.)" and "ABC(assoc.)").  Pieces 1 = A, 2 = B (3 = C).
_AHK = "Auzinger, Hofstaetter & Koch, www.asc.tuwien.ac.at/~winfried/splitting"
_AHKO = "Auzinger, Hofstaetter, Ketcheson & Koch, BIT Numer. Math. 57 (2017) 55"


def _auzinger(name, row, order, stages, lem, word, values, symmetric=False, exact=False, reference=""):
    return MethodTable(name, f"{reference or _AHK} (table {row!r})", order, stages, symmetric, "word", tuple(values),
                       takes_word=False, exact=exact, word=word, lem=lem)


#: Table "best 2-stage 2nd order": a_1 = 1 - sqrt(2)/2, b_1 = sqrt(2)/2, a_2 = b_1, b_2 = a_1 (exact).
BEST_2ND_ORDER = _auzinger("best-2nd-order", "best 2-stage 2nd order", 2, 2, (0.09, 0.31), "1212",
                           ("1 - sqrt(2)/2", "sqrt(2)/2", "sqrt(2)/2", "1 - sqrt(2)/2"), exact=True)
#: "AM 3-2": the best symmetric 3-stage second-order scheme (Auzinger 2015; McLachlan 1995's S2 to 1e-16).
AM_32 = _auzinger("am-32", "AM 3-2", 2, 3, (0.05, 0.18), "121", ("0.193183327503783685", "0.5", "0.613633344992432630"),
                  symmetric=True)
#: "Milne 2/2 rational" and its associated scheme (exact rationals).
MILNE_22 = _auzinger("milne-22", "Milne 2/2 rational", 2, 2, (0.21, 0.47), "1212", ("3/8", "4/5", "5/8", "1/5"),
                     exact=True)
MILNE_22_ASSOC = _auzinger("milne-22-assoc", "Milne 2/2 rational, associated", 2, 2, (2.1, 4.72), "1212",
                           ("3/4", "2", "1/4", "-1"), exact=True)
_AKS32 = ("0.268330095781759925", "0.919661523017399857", "-0.187991618799159782", "-0.187991618799159782",
          "0.919661523017399857", "0.268330095781759925")
#: "Emb 3/2 AKS" (Auzinger & Ketcheson 2014) and "PP 3/4 A", the same coefficients; and the associated scheme.
EMB_32_AKS = _auzinger("emb-32-aks", "Emb 3/2 AKS", 3, 3, (0.25, 1.2), "121212", _AKS32)
PP_34_A = _auzinger("pp-34-a", "PP 3/4 A", 3, 3, (0.25, 1.2), "121212", _AKS32)
EMB_32_AKS_ASSOC = _auzinger("emb-32-aks-assoc", "Emb 3/2 AKS, associated", 2, 2, (0.1, 0.36), "1212",
                             ("0.268330095781759925", "0.683368274569431595", "0.731669904218240075",
                              "0.316631725430568405"))
#: "Emb 4/3 AK p" (Auzinger & Koch 2015) and its associated scheme (a_3 = 0: stages 2 and 3 may be merged).
EMB_43_AK_P = _auzinger("emb-43-ak-p", "Emb 4/3 AK p", 4, 5, (0.06, 0.81), "1212121212",
                        ("0.125962888700250514", "0.333588446797901933", "0.751193431379145450", "-0.338296598434303506",
                         "0.127551831557005609", "0.127551831557005609", "-0.338296598434303506",
                         "0.751193431379145450", "0.333588446797901933", "0.125962888700250514"))
EMB_43_AK_P_ASSOC = _auzinger("emb-43-ak-p-assoc", "Emb 4/3 AK p, associated", 3, 5, (0.04, 0.23), "1212121212",
                              ("0.125962888700250514", "0.333588446797901933", "0.751193431379145450",
                               "-0.338296598434303506", "0", "0.261153550449697153", "-0.242703571757396124",
                               "0.596114052266110425", "0.365547251678000160", "0.147440548920593995"))
#: "Emb 4/3 AK s": the best symmetric 5-stage fourth-order scheme (Auzinger & Koch 2015), and its associated scheme.
EMB_43_AK_S = _auzinger("emb-43-ak-s", "Emb 4/3 AK s", 4, 5, (0.24, 1.15), "12121",
                        ("0.267171359000977615", "-0.361837907604416033", "-0.0338279096695056672",
                         "0.861837907604416033", "0.5333131013370561044"), symmetric=True)
EMB_43_AK_S_ASSOC = _auzinger("emb-43-ak-s-assoc", "Emb 4/3 AK s, associated", 3, 5, (0.03, 0.18), "1212121212",
                              ("0.267171359000977615", "-0.361837907604416033", "-0.0338279096695056672",
                               "0.861837907604416033", "0.5333131013370561044", "0.395088376480991403",
                               "0.267171359000977615", "-0.361837907604416033", "-0.0338279096695056672",
                               "0.466749531123424630"))
#: "Emb 4/3 M/AK": symmetric, optimised (McLachlan 1995 has similar coefficients).  Its associated scheme is not
#: here: as transcribed, its B coefficients sum to 0.6544..., not 1, so the digits are not the published scheme's.
EMB_43_M_AK = _auzinger("emb-43-m-ak", "Emb 4/3 M/AK", 4, 6, (0.01, 0.36), "121212",
                        ("0.093500348726330576", "0.439051727817158558", "-0.069094369881095037",
                         "-0.136536314071511211", "0.4755940211547644618", "0.394969172508705306"), symmetric=True)
#: The associated scheme of "Emb 4/3 BM PRK/A" (Auzinger 2015); the fourth-order method is ``blanes-moan``.
EMB_43_BMPRK_ASSOC = _auzinger("emb-43-bmprk-a-assoc", "Emb 4/3 BM PRK/A, associated", 3, 4, (0.09, 0.5), "12121212",
                               ("0.0792036964311954608", "0.209515106613361891", "0.353172906049773948",
                                "0.634279607840446390", "-0.351497633364616918", "-0.0576123055740887430",
                                "0.919121030883647509", "0.213817591120280462"))
_AK54 = ("0.475018345144539497", "-0.402020995028838599", "0.021856594741098449", "0.345821780864741783",
         "-0.334948298035883491", "0.400962967485371350", "0.512638174652696736", "0.980926531879316517",
         "-0.011978701020553904", "-1.362064898669775624", "-0.032120004263046859", "0.923805029000837468",
         "0.369533888781149572", "0.112569584468347105")
#: "Emb 5/4 AK (i)" and "(ii)" (Auzinger & Ketcheson 2013, 2015): one fifth-order scheme, two associated ones.
EMB_54_AK = _auzinger("emb-54-ak", "Emb 5/4 AK (i), (ii)", 5, 7, (0.31, 2.24), "12121212121212", _AK54)
EMB_54_AK_I_ASSOC = _auzinger("emb-54-ak-i-assoc", "Emb 5/4 AK (i), associated", 4, 7, (0.08, 0.38), "1212121212121",
                              _AK54[:5] + ("0.392182083210588712", "0.541870352983573775", "-0.128645858055930737",
                                           "-0.107236018614181158", "0.554422771123937193", "0.307677712342444599",
                                           "0.238240217885501648", "0.095761311438408329"))
EMB_54_AK_II_ASSOC = _auzinger("emb-54-ak-ii-assoc", "Emb 5/4 AK (ii), associated", 4, 8, (0.02, 0.14), "1212121212121212",
                               _AK54[:8] + ("-0.00596874002994121298", "-1.28006227193004091", "-0.0418443254169191836",
                                            "0.709119365029440952", "0.0616955797702736790", "0.132683037231661766",
                                            "0.31155266917413552658", "0.112569584468347105"))
_A54 = ("0.201651044312324230", "0.578800656272664932", "0.562615975356569200", "0.273128836056524479",
        "0.253874038247554845", "-0.102733803148432142", "-0.835351693190370636", "0.068014946093165092",
        "0.068014946093165092", "-0.835351693190370636", "-0.102733803148432142", "0.253874038247554845",
        "0.273128836056524479", "0.562615975356569200", "0.578800656272664932", "0.201651044312324230")
#: "Emb 5/4 A", the best palindromic 8-stage fifth-order scheme found (Auzinger 2015), "PP 5/6 A" the same
#: coefficients; and the associated scheme.
EMB_54_A = _auzinger("emb-54-a", "Emb 5/4 A", 5, 8, (0.15, 1.23), "12" * 8, _A54)
PP_56_A = _auzinger("pp-56-a", "PP 5/6 A", 5, 8, (0.15, 1.23), "12" * 8, _A54)
EMB_54_A_ASSOC = _auzinger("emb-54-a-assoc", "Emb 5/4 A, associated", 4, 7, (0.05, 0.18), "12" * 7,
                           _A54[:6] + ("-0.726560425753743689", "-0.800888361904193390", "-0.0944858667147550235",
                                       "0.259957296127666422", "0.246962230324312930", "0.594143062900597984",
                                       "0.5559430042277375075", "0.197592313695171715"))

# Complex coefficients (CheckMethods' complex rows).
#: "Milne 2/2 c (i)" and "(ii)" (Auzinger 2015) and their associated schemes: exact Gaussian rationals.
MILNE_22_C_I = _auzinger("milne-22-c-i", "Milne 2/2 c (i)", 2, 2, (0.16, 0.4), "1212",
                         ("12/37 - 2*I/37", "25/34 - I/17", "25/37 + 2*I/37", "9/34 + I/17"), exact=True)
MILNE_22_C_I_ASSOC = _auzinger("milne-22-c-i-assoc", "Milne 2/2 c (i), associated", 2, 2, (1.78, 4.44), "1212",
                               ("4/5 + 2*I/5", "1/2 + I", "1/5 - 2*I/5", "1/2 - I"), exact=True)
MILNE_22_C_II = _auzinger("milne-22-c-ii", "Milne 2/2 c (ii)", 2, 2, (0.12, 0.35), "1212",
                          ("4/13 - I/26", "18/25 - I/25", "9/13 + I/26", "7/25 + I/25"), exact=True)
MILNE_22_C_II_ASSOC = _auzinger("milne-22-c-ii-assoc", "Milne 2/2 c (ii), associated", 2, 2, (2.19, 6.24), "1212",
                                ("1 + I/2", "I", "-I/2", "1 - I"), exact=True)
#: "Emb 3/2 A c" (Auzinger 2015) and its associated scheme: 18-digit complex decimals.
EMB_32_A_C = _auzinger("emb-32-a-c", "Emb 3/2 A c", 3, 3, (0.26, 0.93), "121212",
                       ("0.201639688260407656+0.105972321241365172*I", "0.387747410753696807+0.100071120693574555*I",
                        "0.410612900985895537-0.206043441934939727*I", "0.410612900985895537-0.206043441934939727*I",
                        "0.387747410753696807+0.100071120693574555*I", "0.201639688260407656+0.105972321241365172*I"))
EMB_32_A_C_ASSOC = _auzinger("emb-32-a-c-assoc", "Emb 3/2 A c, associated", 2, 3, (0.15, 0.33), "12121",
                             ("0.201639688260407656+0.105972321241365172*I",
                              "0.387747410753696807+0.100071120693574555*I",
                              "0.502190133760050497-0.0910042566309608042*I",
                              "0.612252589246303193-0.100071120693574555*I",
                              "0.296170177979541847-0.0149680646104043678*I"))
#: "A 3-3 c": B A B A B with b_1 = 1/4 - sqrt(3) i/12, a_1 = 1/2 - sqrt(3) i/6, b_2 = 1/2: the exact solution of the
#: order-3 conditions of that word (the other one is its complex conjugate), whose constants CheckMethods' row lists.
A_33_C = MethodTable("a-33-c", f"{_AHK} (table 'A 3-3 c'); the exact solution of its order-3 conditions", 3, 3, False,
                     "word", ("1/4 - sqrt(3)*I/12", "1/2 - sqrt(3)*I/6", "1/2", "1/2 + sqrt(3)*I/6", "1/4 + sqrt(3)*I/12"),
                     takes_word=False, exact=True, word="21212", lem=(0.36, 1.49))
#: "A 4-4 c": the complex triple jump of the Strang step A B A, g = 1/(2 - c w) with c = 2^(1/3), w = e^(2 pi i/3), exact;
#: written without a denominator, g = (4 + 2 c w + c^2 w^2)/6 (as c^3 w^3 = 2), which the exact routes handle faster.
_G = "(4 - cbrt(2)*(1 - sqrt(3)*I) - cbrt(4)*(1 + sqrt(3)*I)/2)/6"
A_44_C = MethodTable("a-44-c", f"{_AHK} (table 'A 4-4 c'); Castella, Chartier, Descombes & Vilmart, BIT 49 (2009) 487; "
                     "Hansen & Ostermann, BIT 49 (2009) 527", 4, 4, True, "word",
                     (f"{_G}/2", _G, f"(1 - {_G})/2", f"1 - 2*{_G}"), takes_word=False, exact=True, word="1212",
                     lem=(0.42, 1.22))

# Three-part methods (CheckMethods' table "ABC").
#: "PP 3/4 A 3": the best palindromic 6-stage third-order ABC scheme found (Auzinger 2015).
PP_34_A_3 = _auzinger("pp-34-a-3", "PP 3/4 A 3", 3, 6, (0.67,), "123" * 6,
                      ("0.461601939364879971", "-0.266589223588183997", "-0.360420727960349671",
                       "-0.0678710530507800801", "0.0924576733143338354", "0.579154058410941403",
                       "-0.0958868852260720250", "0.674131550273850162", "0.483422668461380403",
                       "0.483422668461380403", "0.674131550273850162", "-0.0958868852260720250",
                       "0.579154058410941403", "0.0924576733143338354", "-0.0678710530507800801",
                       "-0.360420727960349671", "-0.266589223588183997", "0.461601939364879971"))
#: "AK 11-4": symmetric fourth order for three parts, a_1 b_1 c_1 ... a_4 b_4 (b_4 the middle factor) as transcribed
#: in the Python module fh_comm/splitting_method.py of qc-tum/fermi_hubbard_commutators (SplittingMethod.ak_11_4).
AK_114 = _auzinger("ak-114", "AK 11-4", 4, 11, (2.34,), "12312312312",
                   ("0.257069044488538534", "0.296061717549380091", "0.592448417648034871", "0.432582164538475621",
                    "0.704720077493718759", "0.819259857623654322", "-0.031637836548173035", "-0.046163676369010239",
                    "-0.911708275271689193", "-0.158013372478841120", "-0.909236237348177222"),
                   symmetric=True, reference=_AHKO)

#: The tables of CheckMethods' rows, in the notebook's order.
AUZINGER = (BEST_2ND_ORDER, AM_32, MILNE_22, MILNE_22_ASSOC, EMB_32_AKS, EMB_32_AKS_ASSOC, PP_34_A, EMB_43_AK_P,
            EMB_43_AK_P_ASSOC, EMB_43_AK_S, EMB_43_AK_S_ASSOC, EMB_43_M_AK, EMB_43_BMPRK_ASSOC,
            EMB_54_AK, EMB_54_AK_I_ASSOC, EMB_54_AK_II_ASSOC, EMB_54_A, EMB_54_A_ASSOC, PP_56_A, MILNE_22_C_I,
            MILNE_22_C_I_ASSOC, MILNE_22_C_II, MILNE_22_C_II_ASSOC, A_33_C, EMB_32_A_C, EMB_32_A_C_ASSOC, A_44_C,
            PP_34_A_3, AK_114)

#: Every table by name.
TABLES = {t.name: t for t in (TRIPLE_JUMP, SUZUKI, KAHAN_LI, YOSHIDA6, BLANES_MOAN, BLANES_MOAN_S10, MCLACHLAN_S2,
                              MCLACHLAN_S4, MCLACHLAN_S5, BM_SRKN6, BM_SRKN11, BM_SRKN14, MCLACHLAN_SB3A4, PEFRL,
                              SABA2, SABA3, SABA4, SBAB2, SBAB3, ABA864, ABA1064, *AUZINGER)}
#: The tables built by :mod:`.methods` (published decimals, or exact formulas); the jumps are built in :mod:`.composition`.
DECIMAL = tuple(name for name, t in TABLES.items() if t.kind != "jump")
