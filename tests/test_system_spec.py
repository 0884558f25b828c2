"""One system specification: the command line, the TOML loader, System and the API read "which system" the same way.

A bad input gives one message (prefixed by the input as its source names it: a flag, the file) and one exception
type, InvalidSystemError, whichever way the system was requested.
"""

from __future__ import annotations

import pytest

from nambu_bch import model
from nambu_bch.cli import main
from nambu_bch.errors import InvalidSystemError
from nambu_bch.systems.spec import load_system
from nambu_bch.systems import System
from nambu_bch.systems.spec import SystemSpec
from nambu_bch.systems.spec import as_system

BAD = [
    # (coordinates, Hamiltonians, parameters, the message System gives)
    ("x1 1x", ["x1"], "", "coordinate name '1x' is not a valid symbol name; use ASCII letters"),
    ("x1 lambda", ["x1"], "", "coordinate name 'lambda' is not a valid symbol name"),
    ("x1 h", ["x1"], "", "the symbol 'h' is reserved (step / family parameter); rename it"),
    ("x1 x2", ["x1 + x2"], "2m", "parameter name '2m' is not a valid symbol name"),
    ("x1 x2", ["x1 + x2"], "alpha", "the symbol 'alpha' is reserved (step / family parameter); rename it"),
    (" ".join(f"x{i}" for i in range(1, 10)), ["x1"], "", "a system on 9 coordinates is refused: at most 8 are accepted"),
    ("x1 x2 x3", ["x1"], "", "a system on 3 coordinates needs 2 Hamiltonian(s), got 1"),
    ("x1 x2 m", ["x1 + m"], "m", "must be distinct symbols"),
]


def _cli_line(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0]
    return err[0]


@pytest.mark.parametrize("coords, hams, params, message", BAD)
def test_one_message_per_bad_input_from_every_source(coords, hams, params, message, tmp_path, capsys):
    with pytest.raises(InvalidSystemError) as api:
        System(coords, hams, params)
    assert message in str(api.value)
    core = str(api.value)
    path = tmp_path / "bad.toml"
    path.write_text(f'coordinates = "{coords}"\nhamiltonians = {hams!r}\n'.replace("'", '"')
                    + (f'parameters = "{params}"\n' if params else ""))
    with pytest.raises(InvalidSystemError) as toml:
        load_system(path)
    assert str(toml.value) == f"--system {path}: {core}"
    with pytest.raises(InvalidSystemError) as spec:
        SystemSpec(hamiltonians=hams, coordinates=coords, parameters=params).build()
    assert str(spec.value) == core
    argv = ["models", "--H", hams[0], "--coords", coords] + sum((["--param", p] for p in params.split()), [])
    line = _cli_line(capsys, argv)
    assert line.endswith(core) and line.startswith("nambu-bch models: error: --")


def test_the_hamiltonians_are_counted_before_any_is_parsed(capsys):
    """Eight Hamiltonians (at most seven are accepted) are refused by count, from each source, with one message."""
    hams = [f"x{i}" for i in range(1, 9)]
    core = "8 Hamiltonians are refused: at most 7 are accepted"
    with pytest.raises(InvalidSystemError, match=core):
        System(" ".join(f"x{i}" for i in range(1, 9)), hams)
    line = _cli_line(capsys, ["models", "--H", hams[0]] + sum((["--G", h] for h in hams[1:]), []))
    assert line.endswith(f"--H and 7 --G: {core}")
    with pytest.raises(InvalidSystemError, match=core):
        SystemSpec(hamiltonians=["x1 +"] * 8, coordinates="x1 x2").build()   # never parsed


def test_every_system_argument_is_read_by_one_function():
    """as_system, the numeric API's and shadow_hamiltonians' reading of ``system``: one message, one type."""
    from nambu_bch import numeric
    from nambu_bch.numeric.iterate import as_system as numeric_as_system
    from nambu_bch.shadow import shadow_hamiltonians

    messages = set()
    for call in (lambda: as_system(1.5), lambda: numeric_as_system(1.5), lambda: shadow_hamiltonians(1.5, "121"),
                 lambda: numeric.iterate(1.5, "121", 0.1, 2)):
        with pytest.raises(InvalidSystemError) as exc:
            call()
        messages.add(str(exc.value))
    assert messages == {"system must be a System or a built-in model name such as 'ho3', got float"}
    assert numeric_as_system is as_system   # one function, not a wrapper with a message of its own
    assert as_system(SystemSpec(model="ho3")).hamiltonians == model("ho3").hamiltonians
    assert numeric_as_system(SystemSpec(model="ho3", split="single")).split == "single"


def test_a_specification_chooses_exactly_one_system():
    with pytest.raises(InvalidSystemError, match="model and hamiltonians both choose the system"):
        SystemSpec(model="ho3", hamiltonians=["x1"], coordinates="x1 x2").build()
    with pytest.raises(InvalidSystemError, match="no system is chosen; give one of model, file, hamiltonians"):
        SystemSpec().build()
    with pytest.raises(InvalidSystemError, match="coordinates needs the Hamiltonians"):
        SystemSpec(coordinates="x1 x2").build()
    with pytest.raises(InvalidSystemError, match="parameter k: model ho3 has parameters m, omega"):
        SystemSpec(model="ho3", parameters=("k",), values={"k": 1}).build()
    with pytest.raises(InvalidSystemError, match="name 'mine' names a system given by its Hamiltonians"):
        SystemSpec(model="ho3", name="mine").build()
    S = SystemSpec(hamiltonians=[model("ho3").H, model("ho3").G], parameters="m omega").build()   # sympy, x1..x3
    assert S.coordinates == model("ho3").coordinates and S.name == "custom"


def test_a_file_specification_fills_the_numeric_defaults(tmp_path):
    path = tmp_path / "osc.toml"
    path.write_text('coordinates = "x1 x2 x3"\nH = "x2^2/(2*m) + m*x3/2"\nG = "x3 - x1^2"\n[parameters]\nm = "1/2"\n')
    defaults = {}
    S = SystemSpec(file=str(path), split="single").build(defaults)
    assert S.name == "osc" and S.split == "single" and {k: str(v) for k, v in defaults.items()} == {"m": "1/2"}
