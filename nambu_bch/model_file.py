"""User systems from TOML files (``nambu-bch ... --system FILE``).

Format (every expression is parsed by the safe parser, never evaluated)::

    # my_oscillator.toml
    name = "my-ho3"                                   # optional
    coordinates = ["x1", "x2", "x3"]                  # or "x1 x2 x3"
    H = "x2^2/(2*m) + m*omega^2*x3/2"                 # first Hamiltonian
    G = "x3 - x1^2"                                   # second (N = 3); omit for N = 2
    # hamiltonians = ["...", "...", "..."]            # instead of H/G, e.g. for N >= 4
    parameters = ["m", "omega"]                       # symbolic parameters, or a table
    # [parameters]                                    # with numeric values used by
    # m = 1                                           # 'check' and 'plot'
    # omega = "1/2"
    split = "full"                                    # or "single" (split only H); canonical: "fine"
    bracket = "nambu"                                 # optional: inferred from N and the count of Hamiltonians
    description = "..."                               # optional
    citation = "..."                                  # optional

Unknown keys are an error naming the accepted ones, so typos do not pass
silently.
"""

from __future__ import annotations

import os
import stat
import tomllib

from .errors import InvalidSystemError
from .parsing import parse_expression
from .systems.system import USER_NAME

#: Largest accepted model file, in bytes.
MAX_FILE_SIZE = 64 * 1024
KEYS = ("name", "coordinates", "H", "G", "hamiltonians", "parameters", "split", "bracket", "description", "citation")


def parse_value(text, what: str):
    """An exact real number from ``text`` (``"1"``, ``"0.1"``, ``"1/2"``, ``"sqrt(2)"``) or from a TOML number."""
    if isinstance(text, bool):
        raise InvalidSystemError(f"{what} must be a number, got {text!r}")
    if isinstance(text, int):
        text = str(text)
    elif isinstance(text, float):
        text = repr(text)
    value = parse_expression(text, [], what=what)
    if not value.is_number or value.is_real is False or value.free_symbols:
        raise InvalidSystemError(f"{what} = {text!r} is not a real number; give e.g. 1, 0.5 or 1/2")
    return value


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
    from .systems.spec import SystemSpec

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


def _read_regular_file(shown, flag="--system", error=InvalidSystemError) -> bytes:
    """The bytes of the regular file ``shown``, at most :data:`MAX_FILE_SIZE`; devices, FIFOs, directories refused.

    The size is checked on the open file (``fstat``) and enforced while reading, so
    ``/dev/zero`` or a file that grows while it is read cannot exhaust memory.  ``flag`` names the option in the
    messages, ``error`` is the exception raised (the tableau files of :mod:`nambu_bch.integrators.tableau_file`).
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(shown, flags)  # O_NONBLOCK: opening a FIFO does not wait for a writer
    except ValueError:  # an embedded NUL
        raise error(f"{flag} {shown[:40]!r}: not a usable file name") from None
    except OSError as exc:
        raise error(f"{flag} {shown}: cannot read the file ({exc.strerror or exc})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            kind = "a directory" if stat.S_ISDIR(info.st_mode) else "not a regular file (device, FIFO or socket)"
            raise error(f"{flag} {shown}: {kind}; give a TOML file")
        if info.st_size > MAX_FILE_SIZE:
            raise error(f"{flag} {shown}: file is {info.st_size} bytes; at most {MAX_FILE_SIZE} are accepted")
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, 65536)
            if not chunk:
                break
            total += len(chunk)
            if total > MAX_FILE_SIZE:
                raise error(f"{flag} {shown}: file is larger than {MAX_FILE_SIZE} bytes, the most accepted")
            chunks.append(chunk)
        return b"".join(chunks)
    except OSError as exc:
        raise error(f"{flag} {shown}: cannot read the file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)


def _labels(count):
    if count == 2:
        return ["H", "G"]
    return ["H"] + [f"hamiltonians[{k}]" for k in range(1, count)]
