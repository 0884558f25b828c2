"""Which system a request means: one specification, one validator, one builder.

A system is chosen by a built-in model name, a TOML file (:func:`load_spec`), or
Hamiltonians with coordinates and parameters.  The command line (``--model``, ``--system``, ``--H``/``--G``),
the TOML loader and the API (:func:`as_system`) each describe their input as a
:class:`SystemSpec`; :meth:`SystemSpec.validate` checks it before any expression is parsed and
:meth:`SystemSpec.build` makes the :class:`~nambu_bch.systems.System`.

Every check is the one :class:`~nambu_bch.systems.System` applies (:func:`~nambu_bch.systems.system.check_symbols`,
:func:`~nambu_bch.systems.system.infer_bracket`, :func:`~nambu_bch.systems.system.check_name`), prefixed by
the input as its producer names it (``labels``: ``--coords 'x1 1x'``, ``--system FILE``), so a bad input has
one message and one exception type, :class:`~nambu_bch.errors.InvalidSystemError`.
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass

from ..errors import InvalidSystemError, shown
from ..model_file import KEYS, _labels, _read_regular_file, parse_value
from .catalog import model
from .system import (USER_NAME, System, check_hamiltonian_count, check_name, check_parameter_names, check_symbols,
                     infer_bracket)

#: The keys of ``SystemSpec.labels`` and what each names (the default label is empty: the API's wording).
LABEL_KEYS = {
    "model": "the input choosing a built-in model (--model)",
    "file": "the input choosing a TOML file (--system)",
    "hamiltonians": "the input giving the Hamiltonians (--H), as one of the ways of choosing a system",
    "count": "the Hamiltonians as a whole (their count)",
    "choice": "the accepted ways of choosing a system, listed when two are given",
    "coordinates": "the coordinate names",
    "parameters": "the parameter names and values",
    "system": "the system as a whole (the bracket its counts imply); '{coords}' stands for the coordinates",
    "name": "the system's name",
}


@dataclass(frozen=True)
class SystemSpec:
    """A system as requested: exactly one of ``model``, ``file`` or ``hamiltonians``, and how to adapt it.

    Attributes
    ----------
    model : str or None -- a built-in model name
    file : str or None -- a TOML file (:mod:`nambu_bch.model_file`)
    hamiltonians : tuple of (text, label) -- the expressions and how messages name each (``--H``, ``--G``);
        plain expressions are named ``H``, ``G`` (``H1, H2, ..`` for more)
    coordinates : tuple of names (or one string ``"x1 x2"``), or None -- None: ``x1..xN`` inferred from the
        expressions (command line)
    parameters : tuple of names (or one string) -- declared parameters (with a model or file: those given values)
    values : tuple of (name, exact value) (or a dict) -- parameter values given with the request
    split, bracket : str or None -- the splitting and the bracket (None: the system's own / inferred)
    name : str or None -- the name of a system given by expressions (None: ``"custom"``)
    description, citation : str
    labels : tuple of (key, label) (or a dict) -- how messages name each input (:data:`LABEL_KEYS`)

    Examples
    --------
    >>> spec = SystemSpec(hamiltonians=["x2**2/2 + x1**2/2"], coordinates="x1 x2", name="oscillator")
    >>> S = spec.build()
    >>> S.name, S.bracket, S.H
    ('oscillator', 'canonical', x1**2/2 + x2**2/2)
    >>> SystemSpec(model="ho3", file="my.toml").build()
    Traceback (most recent call last):
    ...
    nambu_bch.errors.InvalidSystemError: model and file both choose the system; give only one of model, file, hamiltonians
    """

    model: str | None = None
    file: str | None = None
    hamiltonians: tuple = ()
    coordinates: tuple | None = None
    parameters: tuple = ()
    values: tuple = ()
    split: str | None = None
    bracket: str | None = None
    name: str | None = None
    description: str = ""
    citation: str = ""
    labels: tuple = ()

    def __post_init__(self):
        # the API's conveniences, read as System reads them: "x1 x2" for names, plain expressions for (text, label)
        for key in ("coordinates", "parameters"):
            value = getattr(self, key)
            if isinstance(value, str):
                object.__setattr__(self, key, tuple(value.replace(",", " ").split()))
            elif isinstance(value, list):
                object.__setattr__(self, key, tuple(value))
        for key in ("values", "labels"):  # {name: value} and {key: label} as pairs (the value stays frozen)
            if isinstance(getattr(self, key), dict):
                object.__setattr__(self, key, tuple(getattr(self, key).items()))
        hams = self.hamiltonians
        if isinstance(hams, str):
            hams = (hams,)
        if not isinstance(hams, (tuple, list)):
            raise InvalidSystemError(f"hamiltonians must be a list of expressions, got {type(hams).__name__}")
        names = ["H"] if len(hams) == 1 else ["H", "G"] if len(hams) == 2 else [f"H{k + 1}" for k in range(len(hams))]
        object.__setattr__(self, "hamiltonians", tuple(
            h if isinstance(h, tuple) and len(h) == 2 else (h, name) for h, name in zip(hams, names)))

    def label(self, key: str, default: str = "") -> str:
        """How the messages name input ``key`` (:data:`LABEL_KEYS`)."""
        return dict(self.labels).get(key, default)

    def _where(self, key: str) -> str:
        text = self.label(key)
        return f"{text}: " if text else ""

    # -- the validator ---------------------------------------------------------------------------------------
    def validate(self) -> tuple:
        """Check the request before any expression is parsed; the coordinate names (inferred when not given).

        Raises :class:`InvalidSystemError` naming the input (by its label) and what is accepted.
        """
        expressions = bool(self.hamiltonians) or self.coordinates is not None
        chosen = [self.label(k, k) for k, v in (("model", self.model), ("file", self.file),
                                                ("hamiltonians", expressions)) if v]
        accepted = self.label("choice", "model, file, hamiltonians")
        if len(chosen) > 1:
            raise InvalidSystemError(f"{' and '.join(chosen)} both choose the system; give only one of {accepted}")
        if not chosen:
            raise InvalidSystemError(f"no system is chosen; give one of {accepted}")
        if self.name is not None:
            check_name(self.name, self.label("name", "name"))
            if not expressions:
                raise InvalidSystemError(f"{self.label('name', 'name')} {shown(self.name)} names a system given by "
                                         "its Hamiltonians; a built-in model or a file keeps its own name")
        if not expressions:
            check_parameter_names(self.parameters, self._where("parameters"))
            return ()
        if not self.hamiltonians:
            raise InvalidSystemError(f"{self.label('coordinates', 'coordinates')} needs the Hamiltonians "
                                     f"({self.label('hamiltonians', 'hamiltonians')})")
        count = len(self.hamiltonians)
        check_hamiltonian_count(count, self._where("count"))
        coords = self.coordinates
        if coords is None:
            coords = tuple(f"x{i}" for i in range(1, (count + 1 if count > 1 else 2) + 1))
            _check_inferred_coordinates([str(text) for text, _ in self.hamiltonians], coords, self.parameters, self.bracket)
        check_symbols(coords, self.parameters, self._where("coordinates"), self._where("parameters"))
        # the command line names the coordinates it inferred: "{coords}" in the label stands for them
        infer_bracket(len(coords), count, self.bracket, where=self._where("system").replace("{coords}", repr(" ".join(coords))))
        return coords

    # -- the builder -----------------------------------------------------------------------------------------
    def build(self, defaults: dict | None = None):
        """The :class:`~nambu_bch.systems.System` this specification names (validated first).

        Parameters
        ----------
        defaults : dict, optional
            Filled with the numeric parameter values a TOML ``file`` gives (exact sympy numbers): numeric
            defaults of a run, not substituted symbolically.
        """
        coords = self.validate()
        if self.hamiltonians:
            return self._from_expressions(coords)
        if self.file:
            inner = load_spec(self.file)
            system = inner.build()
            if defaults is not None:
                defaults.update(dict(inner.values))
            source = f"the system of {shown(self.file)}"
        else:
            system = model(self.model)
            source = f"model {system.name}"
        self._check_parameters_of(system, source)
        if self.bracket:
            return system.with_bracket(self.bracket, self.split)
        return system.with_split(self.split) if self.split else system

    def _from_expressions(self, coords):
        import sympy

        from ..parsing import parse_expression

        symbols = [sympy.Symbol(s) for s in (*coords, *self.parameters)]
        parsed = [parse_expression(text, symbols, what=label) if isinstance(text, str) else text
                  for text, label in self.hamiltonians]
        return System(coords, parsed, self.parameters, name=self.name or "custom", split=self.split,
                      bracket=self.bracket, description=self.description, citation=self.citation)

    def _check_parameters_of(self, system, source) -> None:
        """The parameters of a request on a model or file name parameters it has, each with a value."""
        label = self.label("parameters", "parameter")
        have = {p.name for p in system.parameters}
        extra = [n for n in self.parameters if n not in have]
        if extra:
            names = ", ".join(str(s) for s in system.parameters) or "none"
            raise InvalidSystemError(f"{label} {extra[0]}: {source} has parameters {names}")
        given = dict(self.values)
        declared = [n for n in self.parameters if n not in given]
        if declared:  # a declaration without a value would change nothing
            raise InvalidSystemError(f"{label} {declared[0]} without a value declares a parameter of a user system (--H); "
                                     f"{source} has it already: give a value, e.g. {label} {declared[0]}=1")


_COORDINATE = re.compile(r"(?<![A-Za-z0-9_])x([1-9][0-9]*)(?![A-Za-z0-9_])", re.ASCII)


def _check_inferred_coordinates(hams, coords, names, bracket) -> None:
    """Without ``--coords`` the coordinates are ``x1..xN`` with N from the number of Hamiltonians (2 for one,
    else one more than their number); refuse when the highest ``x<k>`` the expressions use is not ``xN``.

    ``--H 'x2^2/2 + x1^2/2' --G 'x1^2'`` would otherwise be analysed on ``x1 x2 x3`` (a Nambu system in
    which x3 appears nowhere), and ``--H`` using ``x3`` would be refused as an undeclared name.
    """
    found = {f"x{m}" for text in hams for m in _COORDINATE.findall(text)} - set(names)
    if not found:
        return  # no coordinate-like name: the parser names whatever is undeclared
    used = sorted(found, key=lambda name: int(name[1:]))
    top = int(used[-1][1:])
    if top == len(coords):
        return
    flags = "--H" + (f" and {len(hams) - 1} --G use" if len(hams) > 1 else " uses")
    try:
        kind = f", {infer_bracket(len(coords), len(hams), bracket)} bracket"
    except InvalidSystemError:
        kind = ""
    count = f"{len(hams)} Hamiltonians mean" if len(hams) > 1 else "one Hamiltonian means"
    meant = f"{flags} {', '.join(used)}; without --coords, {count} a system on {' '.join(coords)} (N = {len(coords)}{kind})"
    if top < len(coords):
        unused = coords[top:]
        appear = f"{unused[0]} appears" if len(unused) == 1 else f"{', '.join(unused)} appear"
        raise InvalidSystemError(
            f"{meant}, in which {appear} in no Hamiltonian; pass --coords {' '.join(coords)!r} to analyse that system"
        )
    wanted = " ".join(f"x{k}" for k in range(1, top + 1))
    raise InvalidSystemError(f"{meant}; pass --coords {wanted!r} for the coordinates the expressions use "
                             "(--param NAME declares a parameter)")


def as_system(system, what: str = "system") -> "System":
    """``system`` itself, the built-in model of that name, or the system a :class:`~nambu_bch.systems.spec.SystemSpec`
    builds; else :class:`InvalidSystemError` in one line.  The one reading of a ``system`` argument of the API."""
    if isinstance(system, System):
        return system
    if isinstance(system, str):
        return model(system)
    if isinstance(system, SystemSpec):
        return system.build()
    raise InvalidSystemError(f"{what} must be a System or a built-in model name such as 'ho3', got {type(system).__name__}")


# -- the TOML producer (the format: :mod:`nambu_bch.model_file`) ----------------------------------------------
def load_system(path, values: dict | None = None):
    """The :class:`~nambu_bch.systems.System` the TOML file at ``path`` defines.

    Parameters
    ----------
    path : str or path-like
    values : dict, optional
        Filled with the numeric parameter values the file gives (exact sympy numbers).

    Raises
    ------
    InvalidSystemError
        On a missing / unreadable / oversized file, TOML syntax errors, unknown
        keys or a malformed entry; :class:`ExpressionParseError` on a bad expression.
    """
    spec = load_spec(path)
    system = spec.build()
    if values is not None:
        values.update(dict(spec.values))
    return system


def load_spec(path):
    """The :class:`~nambu_bch.systems.spec.SystemSpec` of the TOML file at ``path`` (read and its shape checked;
    the system itself is checked and built by :meth:`~nambu_bch.systems.spec.SystemSpec.build`)."""
    shown = os.fspath(path)
    raw = _read_regular_file(shown)
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise InvalidSystemError(f"--system {shown}: not valid TOML ({' '.join(str(exc).split())})") from None
    except UnicodeDecodeError:
        raise InvalidSystemError(f"--system {shown}: not valid TOML (not UTF-8 text)") from None
    except RecursionError:
        raise InvalidSystemError(f"--system {shown}: not accepted (arrays or tables nested too deeply)") from None
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise InvalidSystemError(f"--system {shown}: unknown key(s) {', '.join(unknown)}; accepted keys are {', '.join(KEYS)}")

    def text_list(key, value):
        if isinstance(value, str):
            value = value.replace(",", " ").split()
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise InvalidSystemError(f"--system {shown}: {key} must be a list of strings or one string, got {value!r}")
        return value

    if "coordinates" not in data:
        raise InvalidSystemError(f"--system {shown}: the key 'coordinates' is missing (e.g. coordinates = [\"x1\", \"x2\"])")
    coordinates = text_list("coordinates", data["coordinates"])
    if "hamiltonians" in data:
        if "H" in data or "G" in data:
            raise InvalidSystemError(f"--system {shown}: give either 'hamiltonians' or 'H'/'G', not both")
        hams = data["hamiltonians"]
        if not isinstance(hams, list) or not all(isinstance(v, str) for v in hams):
            raise InvalidSystemError(f"--system {shown}: hamiltonians must be a list of strings")
    else:
        if "H" not in data:
            raise InvalidSystemError(f"--system {shown}: the key 'H' (or 'hamiltonians') is missing")
        hams = [data["H"]] + ([data["G"]] if "G" in data else [])
        if not all(isinstance(v, str) for v in hams):
            raise InvalidSystemError(f"--system {shown}: H and G must be strings such as \"x2^2/2 + x1^2/2\"")
    params = data.get("parameters", [])
    values = {}
    if isinstance(params, dict):
        names = list(params)
        values = {key: parse_value(value, f"--system {shown}: parameter {key}") for key, value in params.items()}
    else:
        names = text_list("parameters", params)
    for key in ("name", "split", "description", "citation", "bracket"):
        if key in data and not isinstance(data[key], str):
            raise InvalidSystemError(f"--system {shown}: {key} must be a string, got {data[key]!r}")
    if "name" in data:
        name = data["name"]
    else:  # the file's base name when it is a valid name, else 'custom'
        stem = os.path.splitext(os.path.basename(shown))[0]
        name = stem if USER_NAME.match(stem) else "custom"
    where = f"--system {shown}"
    labels = {"coordinates": where, "parameters": where, "count": where, "system": where, "name": f"{where}: name"}
    return SystemSpec(
        hamiltonians=tuple((text, f"{where}: {label}") for text, label in zip(hams, _labels(len(hams)))),
        coordinates=tuple(coordinates), parameters=tuple(names), values=tuple(values.items()),
        split=data.get("split"), bracket=data.get("bracket"), name=name,
        description=data.get("description", ""), citation=data.get("citation", ""), labels=tuple(labels.items()),
    )
