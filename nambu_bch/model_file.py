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
silently.  This module holds the format (its keys, the bounded read of a private regular file, parameter values);
:func:`nambu_bch.systems.spec.load_spec` reads a file into a :class:`~nambu_bch.systems.spec.SystemSpec` and
:func:`nambu_bch.systems.spec.load_system` builds its system.
"""

from __future__ import annotations

import os
import stat

from .errors import InvalidSystemError
from .parsing import parse_expression

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
