"""A Nambu (N >= 3) or Hamiltonian (N = 2) system: coordinates, Hamiltonians, parameters."""

from __future__ import annotations

import keyword
import re
from dataclasses import dataclass, field
from functools import cached_property

import sympy

from ..algebra import PolynomialAlgebra, VectorField, liouville_field
from ..checks import check_int, show
from ..errors import InvalidSystemError, NambuBCHError
from ..parsing import SYMBOL_NAME, as_expression
from .pieces import build_canonical_split, build_full_split, build_single_split, build_triplet_split

#: Symbols reserved by the package: the step and the family parameter.
RESERVED_SYMBOLS = ("h", "alpha")
#: Most coordinates of a system: the Nambu bracket of N - 1 Hamiltonians is an N x N
#: determinant (N! terms), and the splittings and words grow with N.
MAX_COORDINATES = 8
#: Most parameters of a system (each is a generator of the coefficient field).
MAX_PARAMETERS = 16
#: A name given by a user (``--name``, the TOML ``name``): LaTeX-safe and source-safe.
USER_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]{0,63}\Z")
#: Any system name (also the derived ``ho3[m=1/2]``): no quote, backslash, brace, ``#``, ``$``, ``%``, ``&``, ``~``, ``^`` or newline.
SYSTEM_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_.+\-=/,*()\[\] ]{0,199}\Z")


def check_name(name, what: str = "name", strict: bool = True) -> str:
    r"""``name`` if it is a safe system name, else :class:`InvalidSystemError` in one line.

    ``strict`` (user input): ``^[A-Za-z][A-Za-z0-9_-]{0,63}$``.  Otherwise also the
    characters ``. + = / , * ( ) [ ]`` and spaces of derived names such as
    ``ho3[m=1/2]``.  Names appear in LaTeX (``\text{...}``), JSON and generated
    source, so a backslash, brace, quote or ``#`` never passes
    (``\input{/etc/passwd}`` is refused).

    >>> check_name("my-ho3")
    'my-ho3'
    >>> check_name("\\input{/etc/passwd}", "--name")
    Traceback (most recent call last):
    ...
    nambu_bch.errors.InvalidSystemError: --name '\\input{/etc/passwd}' is not accepted; a name is a letter followed by at most 63 letters, digits, '_' or '-'
    """
    pattern = USER_NAME if strict else SYSTEM_NAME
    if not isinstance(name, str) or not pattern.match(name):
        shown = repr(name if not isinstance(name, str) or len(name) <= 60 else name[:57] + "...")
        rule = ("a letter followed by at most 63 letters, digits, '_' or '-'" if strict else
                "a letter followed by at most 199 letters, digits, spaces or . _ + - = / , * ( ) [ ]")
        raise InvalidSystemError(f"{what} {shown} is not accepted; a name is {rule}")
    return name


#: The kinds of bracket a system may carry (see :func:`infer_bracket`).
BRACKETS = ("canonical", "nambu", "triplets", "lie-poisson")

#: Splits accepted per bracket kind; the first is the default.
SPLITS = {
    "canonical": ("full", "fine"),
    "nambu": ("full", "single"),
    "triplets": ("full", "single"),
    "lie-poisson": ("single", "full"),
}

_ACCEPTED = ("accepted: 1 Hamiltonian on N = 2d coordinates (canonical, q = the first d, p = the last d), "
             "N - 1 Hamiltonians on N (Nambu), 2 Hamiltonians on N = 3n (Nambu's canonical triplets), "
             "or bracket='lie-poisson' with 1 Hamiltonian on N = 3")


def infer_bracket(n_coords: int, n_hams: int, bracket=None, where: str = "") -> str:
    """The bracket of a system from the number of coordinates and of Hamiltonians.

    * one Hamiltonian on ``N = 2d``: ``"canonical"`` (``q`` = the first ``d``
      coordinates, ``p`` = the last ``d``; Eq. Poisson);
    * ``N - 1`` Hamiltonians on ``N >= 3``: ``"nambu"`` (the Jacobian, Eq. NB);
    * two Hamiltonians on ``N = 3n``, ``n >= 2``: ``"triplets"`` (the sum of the
      3x3 Jacobians over consecutive triplets; Nambu 1973, Sect. III);
    * ``bracket="lie-poisson"``: one Hamiltonian on ``N = 3`` with the so(3)
      Lie-Poisson bracket ``{f, g} = {f, g, |x|^2/2}`` (the rigid body).

    An explicit ``bracket`` must agree with the counts (it overrides only the
    ambiguous cases ``N = 2``, where canonical = Nambu, and ``N = 3`` with two
    Hamiltonians, where triplets = Nambu).

    Raises
    ------
    InvalidSystemError
        naming the counts and what is accepted.

    Examples
    --------
    >>> infer_bracket(4, 1), infer_bracket(3, 2), infer_bracket(6, 2), infer_bracket(3, 1, "lie-poisson")
    ('canonical', 'nambu', 'triplets', 'lie-poisson')

    ``where`` prefixes a message with the input as the caller names it (:class:`~nambu_bch.systems.spec.SystemSpec`).
    """
    try:
        return _infer_bracket(n_coords, n_hams, bracket)
    except InvalidSystemError as exc:
        if not where:
            raise
        raise InvalidSystemError(f"{where}{exc}") from None


def _infer_bracket(n_coords, n_hams, bracket):
    N, k = check_int(n_coords, "n_coords", 1), check_int(n_hams, "n_hams", 1)
    if bracket is not None and (not isinstance(bracket, str) or bracket not in BRACKETS):
        raise InvalidSystemError(f"bracket {show(bracket)} is not known; accepted are {', '.join(BRACKETS)} (or None to infer)")
    if bracket == "lie-poisson":
        if (N, k) != (3, 1):
            raise InvalidSystemError(
                f"bracket='lie-poisson' takes 1 Hamiltonian on N = 3 coordinates (the rigid body), got {k} on N = {N}")
        return bracket
    counts = sorted({c for c, ok in ((1, N % 2 == 0), (N - 1, N >= 3), (2, N % 3 == 0 and N > 3)) if ok})
    if k not in counts:
        listed = (
            ", ".join(map(str, counts[:-1])) + " or " + str(counts[-1]) if len(counts) > 1 else str(counts[0]))
        why = (" (one Hamiltonian needs an even N = 2d, the canonical bracket)" if k == 1 else
               " (two Hamiltonians on N > 3 need N = 3n, Nambu's canonical triplets)" if k == 2 else "")
        raise InvalidSystemError(
            f"a system on {N} coordinates needs {listed} Hamiltonian(s), got {k}{why}; {_ACCEPTED}")
    inferred = "canonical" if k == 1 and N % 2 == 0 else "nambu" if k == N - 1 else "triplets"
    if bracket is None or bracket == inferred:
        return inferred
    same = {("canonical", "nambu"): N == 2, ("nambu", "canonical"): N == 2, ("nambu", "triplets"): N == 3,
            ("triplets", "nambu"): N == 3}
    if same.get((inferred, bracket)):
        return bracket
    raise InvalidSystemError(
        f"bracket={bracket!r} does not fit {k} Hamiltonian(s) on N = {N} coordinates (that is {inferred!r}); {_ACCEPTED}")


def _as_symbols(names, what, where=""):
    if isinstance(names, str):
        names = names.replace(",", " ").split()
    if isinstance(names, sympy.Symbol):
        names = (names,)
    try:
        names = list(names)
    except TypeError:
        raise InvalidSystemError(f"{where}{what}s must be a string such as 'x1 x2 x3' or a list of names/Symbols, got {names!r}") from None
    out = []
    for n in names:
        if isinstance(n, str):
            n = sympy.Symbol(_symbol_name(n, what, where))
        if not isinstance(n, sympy.Symbol):
            raise InvalidSystemError(f"{where}{what} must be symbols or names, got {n!r}")
        _symbol_name(n.name, what, where)
        out.append(n)
    return tuple(out)


def _symbol_name(name, what, where=""):
    if not SYMBOL_NAME.match(name) or keyword.iskeyword(name):
        shown = repr(name if len(name) <= 40 else name[:37] + "...")
        raise InvalidSystemError(
            f"{where}{what} name {shown} is not a valid symbol name; use ASCII letters, digits and '_', "
            "starting with a letter, at most 32 characters (e.g. x1, omega)"
        )
    return name


def check_symbols(coordinates, parameters, where: str = "", where_parameters: str | None = None) -> tuple:
    """``(coordinates, parameters)`` as Symbols, checked: valid distinct names, none reserved, within the size limits.

    The one check of a system's symbols, for :class:`System` and for :class:`~nambu_bch.systems.spec.SystemSpec`;
    ``where`` (``"--coords 'x1 x2': "``, ``"--system FILE: "``) and ``where_parameters`` (default ``where``)
    prefix the message with the input as the caller names it.  Raises :class:`InvalidSystemError`.
    """
    wp = where if where_parameters is None else where_parameters
    coords = _as_symbols(coordinates, "coordinate", where)
    params = _as_symbols(parameters, "parameter", wp)
    if len(coords) > MAX_COORDINATES:
        raise InvalidSystemError(
            f"{where}a system on {len(coords)} coordinates is refused: at most {MAX_COORDINATES} are accepted "
            f"(the Nambu bracket of N - 1 Hamiltonians has N! terms)"
        )
    _check_parameter_count(params, wp)
    if len(coords) < 2:
        raise InvalidSystemError(f"{where}a system needs at least 2 coordinates, got {len(coords)}")
    if len(set(coords)) != len(coords) or set(coords) & set(params):
        raise InvalidSystemError(f"{where}coordinates {coords} and parameters {params} must be distinct symbols")
    _check_reserved(coords, where)
    _check_reserved(params, wp)
    return coords, params


def check_parameter_names(names, where: str = "") -> tuple:
    """Parameter names as Symbols, checked as :func:`check_symbols` checks them (for a request on a model or file)."""
    params = _as_symbols(names, "parameter", where)
    _check_parameter_count(params, where)
    _check_reserved(params, where)
    return params


def _check_parameter_count(params, where):
    if len(params) > MAX_PARAMETERS:
        raise InvalidSystemError(f"{where}a system with {len(params)} parameters is refused: at most {MAX_PARAMETERS} are accepted")


def _check_reserved(symbols, where):
    for s in symbols:
        if s.name in RESERVED_SYMBOLS:
            raise InvalidSystemError(f"{where}the symbol {s.name!r} is reserved (step / family parameter); rename it")


def check_hamiltonian_count(count: int, where: str = "") -> None:
    """Refuse more than ``MAX_COORDINATES - 1`` Hamiltonians before any is parsed (the bracket has N! terms)."""
    if count > MAX_COORDINATES - 1:
        raise InvalidSystemError(f"{where}{count} Hamiltonians are refused: at most {MAX_COORDINATES - 1} are accepted")


@dataclass(frozen=True, eq=False)
class System:
    """Coordinates ``x_1..x_N`` driven by Hamiltonians through a bracket inferred from their numbers.

    The equations of motion are ``df/dt = {f, H_1, ..., H_{N-1}}`` (Eq. NambuEq;
    Eq. HamiltonEq for N = 2), i.e. ``dx/dt = X_{H_1..H_{N-1}}``; one Hamiltonian on
    ``N = 2d`` coordinates is canonical (``df/dt = {f, H}``, q first, p last), two on
    ``N = 3n`` are Nambu's canonical triplets (:func:`infer_bracket`).

    Parameters
    ----------
    coordinates : str or sequence of Symbols/names, e.g. ``"x1 x2 x3"``
    hamiltonians : sequence of sympy expressions (or strings parsed safely)
    parameters : str or sequence of Symbols/names, e.g. ``"m omega"``
    name : str, optional
    split : ``"full"`` to split every Hamiltonian per coordinate (Eqs. X1-X3),
        or ``"single"`` to split only the first one (the paper's footnote).
        Canonical systems: ``"full"`` = pieces T(p), V(q) (so ``121`` is position
        Verlet), ``"fine"`` = T and V further split into independent parts.
        Default: the first accepted split of the bracket (``"single"`` for Lie-Poisson).
    bracket : ``None`` (inferred, :func:`infer_bracket`), ``"canonical"``, ``"nambu"``,
        ``"triplets"`` or ``"lie-poisson"``.
    description, citation : str, optional

    Examples
    --------
    >>> S = System("x1 x2 x3", ["x2**2/(2*m) + m*omega**2*x3/2", "x3 - x1**2"], "m omega")
    >>> S.N, S.H
    (3, m*omega**2*x3/2 + x2**2/(2*m))
    """

    coordinates: tuple
    hamiltonians: tuple
    parameters: tuple = ()
    name: str = "custom"
    split: str | None = None
    description: str = ""
    citation: str = ""
    piece_labels: tuple = field(default=(), compare=False)
    bracket: str | None = None

    def __post_init__(self):
        coords, params = check_symbols(self.coordinates, self.parameters)
        object.__setattr__(self, "coordinates", coords)
        object.__setattr__(self, "parameters", params)
        check_name(self.name, "system name", strict=False)
        for key in ("description", "citation"):
            text = getattr(self, key)
            if not isinstance(text, str) or len(text) > 500 or not text.isprintable():
                raise InvalidSystemError(f"{key} of a system must be printable text of at most 500 characters, got {str(text)[:40]!r}")
        hams = self.hamiltonians
        if isinstance(hams, (str, sympy.Basic)):
            hams = (hams,)
        if not isinstance(hams, (list, tuple)):
            raise InvalidSystemError(f"hamiltonians must be a list of expressions (strings or sympy), got {type(hams).__name__}")
        check_hamiltonian_count(len(hams))
        hams = tuple(self._parse(H) for H in hams)
        casimir = sympy.Add(*(x**2 for x in coords)) / 2
        if self.bracket == "lie-poisson" and len(hams) == 2 and sympy.expand(hams[1] - casimir) == 0:
            hams = hams[:1]  # a copy of a Lie-Poisson system (the Casimir is already there)
        bracket = infer_bracket(len(coords), len(hams), self.bracket)
        if bracket == "lie-poisson":
            hams = (hams[0], casimir)
        object.__setattr__(self, "bracket", bracket)
        allowed = set(coords) | set(params)
        for k, H in enumerate(hams):
            stray = H.free_symbols - allowed
            if stray:
                raise InvalidSystemError(
                    f"Hamiltonian {self._ham_name(k, len(hams))} = {H} uses {sorted(map(str, stray))}, "
                    f"which are neither coordinates {[str(c) for c in coords]} nor parameters {[str(p) for p in params]}"
                )
            if not H.free_symbols & set(coords):
                raise InvalidSystemError(f"Hamiltonian {self._ham_name(k, len(hams))} = {H} does not depend on any coordinate")
        object.__setattr__(self, "hamiltonians", hams)
        accepted = SPLITS[bracket]
        split = accepted[0] if self.split is None else self.split
        if not isinstance(split, str) or split not in accepted:
            raise InvalidSystemError(
                f"split {split!r} does not apply to a {bracket} system; accepted are {', '.join(accepted)}")
        object.__setattr__(self, "split", split)

    def _parse(self, H):
        if isinstance(H, str):
            return as_expression(H, (*self.coordinates, *self.parameters), "expression")
        if not isinstance(H, sympy.Expr):
            try:
                H = as_expression(H, (), "Hamiltonian")
            except NambuBCHError:
                raise InvalidSystemError(f"Hamiltonian {H!r} is not a sympy expression") from None
        # symbolic code never sees floats: read 0.5 as 1/2 (the decimal the user wrote)
        return sympy.nsimplify(H, rational=True) if H.has(sympy.Float) else H

    @staticmethod
    def _ham_name(k, count):
        return "H" if k == 0 else ("G" if count == 2 else f"H{k + 1}")

    # -- views --------------------------------------------------------------------
    @property
    def N(self) -> int:
        return len(self.coordinates)

    @property
    def H(self) -> sympy.Expr:
        return self.hamiltonians[0]

    @property
    def G(self):
        """The second Hamiltonian (``None`` for N = 2)."""
        return self.hamiltonians[1] if len(self.hamiltonians) > 1 else None

    @cached_property
    def algebra(self) -> PolynomialAlgebra:
        """Polynomials in the coordinates and the step ``h`` over ``QQ(parameters)``."""
        return PolynomialAlgebra(self.coordinates, self.parameters, constants=(sympy.Symbol("h"),))

    @cached_property
    def vector_field(self) -> VectorField:
        """``X_{H,G}`` (Eq. gLiouville), or ``X_H`` for N = 2."""
        return liouville_field(self.algebra, *self.hamiltonians)

    @cached_property
    def splitting(self):
        """The default splitting of this system (see :mod:`nambu_bch.systems.splitting`)."""
        if self.bracket == "canonical":
            return build_canonical_split(self, fine=self.split == "fine")
        if self.bracket == "triplets":
            return build_triplet_split(self, single=self.split == "single")
        return build_full_split(self) if self.split == "full" else build_single_split(self)

    @property
    def dof(self):
        """Degrees of freedom ``d`` of a canonical system (``N = 2d``), else ``None``."""
        return self.N // 2 if self.bracket == "canonical" else None

    def equations_of_motion(self) -> tuple:
        """``dx_i/dt`` as sympy expressions (e.g. Eq. NambuOHeqs for ``ho3``)."""
        return self.vector_field.to_sympy()

    def symbols(self) -> dict:
        """Name -> Symbol for every symbol a user expression may use (plus ``h``, ``alpha``)."""
        names = {s.name: s for s in (*self.coordinates, *self.parameters)}
        names.update({n: sympy.Symbol(n) for n in RESERVED_SYMBOLS})
        return names

    def substitute(self, values) -> "System":
        """The system with parameter values substituted exactly: ``{name: exact value}`` (``--param m=1/2``).

        The substituted parameters leave ``parameters``; the name records the values
        (``ho3[m=1/2]``), shortened to ``ho3[m substituted]`` when that would not be a
        safe name (:data:`SYSTEM_NAME`).  No values: the system itself.

        >>> from nambu_bch import model
        >>> S = model("ho3").substitute({"m": sympy.Rational(1, 2)})
        >>> S.name, S.parameters, S.H
        ('ho3[m=1/2]', (omega,), omega**2*x3/4 + x2**2)
        """
        if not values:
            return self
        if not isinstance(values, dict):
            raise InvalidSystemError(f"substitute takes a dict {{name: exact value}}, got {type(values).__name__}")
        # text values are parsed (numbers only: a value may not name a symbol), never sympified
        values = {k: as_expression(v, (), f"the value of {k}") for k, v in values.items()}
        subs = {p: values[p.name] for p in self.parameters if p.name in values}
        rest = tuple(p for p in self.parameters if p.name not in values)
        hams = tuple(H.subs(subs) for H in self.hamiltonians)
        label = ",".join(f"{k}={v}" for k, v in values.items())
        name = f"{self.name}[{label}]"
        if not SYSTEM_NAME.match(name):  # a long or unusual value: keep the name short and safe
            name = f"{self.name}[{','.join(values)} substituted]"
        return self._replaced(hamiltonians=hams, parameters=rest, name=name)

    def with_split(self, split: str) -> "System":
        """The same system split another way (``"full"``, ``"single"``, ``"fine"``; :mod:`nambu_bch.systems.splitting`)."""
        return self if split == self.split else self._replaced(split=split)

    def with_bracket(self, bracket: str, split: str | None = None) -> "System":
        """The same Hamiltonians under another bracket (``split=None``: that bracket's default split)."""
        if bracket == self.bracket:
            return self if split is None else self.with_split(split)
        return self._replaced(bracket=bracket, split=split)

    def _replaced(self, **changes) -> "System":
        fields = dict(coordinates=self.coordinates, hamiltonians=self.hamiltonians, parameters=self.parameters,
                      name=self.name, split=self.split, description=self.description, citation=self.citation,
                      bracket=self.bracket)
        fields.update(changes)
        return System(**fields)

    def to_latex(self) -> str:
        labels = ["H", "G"] if len(self.hamiltonians) == 2 else [f"H_{{{k + 1}}}" for k in range(len(self.hamiltonians))]
        if len(self.hamiltonians) == 1:
            labels = ["H"]
        return ",\\quad ".join(f"{lab} = {sympy.latex(H)}" for lab, H in zip(labels, self.hamiltonians))

    def _repr_latex_(self):
        return f"${self.to_latex()}$"

    def __repr__(self):
        return f"System(name={self.name!r}, coordinates={self.coordinates}, hamiltonians={self.hamiltonians}, parameters={self.parameters})"
