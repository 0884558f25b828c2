"""Property-based hardening of the command line: random argv through ``nambu_bch.cli.main``, in process.

Each argv is a subcommand (or a junk head) followed by a few options: the subcommand's own flags, flags of other
subcommands, abbreviations, unknown flags, bare tokens and ``--flag=value`` forms, with values that are valid and
small, or junk (tests/strategies.py: payloads, towers such as ``exp(exp(exp(2.5)))``, huge numbers, unicode,
control characters).  The contract: exit status 0 or 2; on 2, stderr is exactly one line and stdout is empty;
never a traceback and never an exception out of ``main``.

Paths are confined: every call runs in a directory :data:`DEPTH` levels below the test's ``tmp_path``, no token
starts with ``/`` or ``~`` and no token holds more ``..`` than that depth, so an ``--output``, ``--outdir``,
``--figure`` or ``--system`` value cannot reach outside ``tmp_path``; the test also checks that nothing appeared
beside ``tmp_path`` or in the working directory of the test run.  Numbers that would start a long computation
(orders above 2, degrees above 3, step counts above 100) are not generated.  ``NAMBU_BCH_FUZZ_EXAMPLES`` scales
the number of argv (default 60 per test; see docs/hardening.md).
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from strategies import PAYLOADS, TOWERS, adversarial_text

from nambu_bch.cli import SUBCOMMANDS, build_parser, main

EXAMPLES = int(os.environ.get("NAMBU_BCH_FUZZ_EXAMPLES", "6")) * 10
#: Working directory depth below tmp_path; no generated token holds as many ``..``.
DEPTH = 10
FUZZ = settings(derandomize=True, deadline=None, database=None, max_examples=EXAMPLES,
                phases=(Phase.explicit, Phase.generate, Phase.shrink),
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])

BIG = "1" + "0" * 400
#: Small valid values (and near misses) by flag; a flag not listed gets junk only.
VALUES = {
    "--model": ("ho3", "ho", "rigid-body", "lotka-volterra", "pendulum", "henon-heiles", "nonexistent", "HO3", ""),
    "--integrator": ("12321", "32123", "121", "123", "strang", "yoshida", "lie-trotter", "TVT", "1234", "0",
                     "yoshida:yoshida:121", "1:1/2,2:1,1:1/2", "1:nan,2:1,1:1"),
    "--order": ("0", "1", "2", "-1", "13", "16", BIG, "2.0", "٣", "two", ""),
    "--degree": ("1", "2", "3", "0", "13", BIG, "x"),
    "--limit": ("1", "3", "0", "-1", "junk", BIG),
    "--route": ("direct", "fi", "FI", "other"),
    "--h": ("0.1", "1/20", "0", "-0.1", "nan", "inf", "1e-300", "1e308", "10^400", "2.5"),
    "--alpha": ("1/2", "0", "nan", "-inf", "1e308"),
    "--steps": ("1", "10", "100", "0", "-5", "1e3", BIG, "١٠"),
    "--every": ("1", "5", "0", "1000", BIG),
    "--short-steps": ("1", "10", "0", BIG),
    "--dpi": ("10", "0", "100000", BIG),
    "--x0": ("1,1,1", "1,1", "1,1,1,1", "0.5 0.5 0.5", "nan,1,1", "1e308,1e308,1e308", "exp(exp(exp(2.5))),1,1", ""),
    "--t-end": ("1", "0.5", "0", "-1", "nan", "1e308", BIG),
    "--step-counts": ("4,8", "4 8", "8", "0,4", "-1,4", "4,,8", "1e3,2e3", BIG + ",4"),
    "--H": ("x2^2/2 + x1^2/2", "x2^2/2 + x1^4/4", "x1 + x2 + x3", "x2^2/2 - cos(x1)", "x1^2", "h*x1", ""),
    "--G": ("x1^2", "x3", "x1*x2*x3", "x3 - x1^2"),
    "--coords": ("x1 x2", "x1 x2 x3", "q p", "x1,x2,x3,x4", "h x2", "1x"),
    "--param": ("m=1/2", "m", "omega=2", "m=nan", "h=1", "=1", "m=" + BIG),
    "--split": ("full", "single", "fine", "half"),
    "--bracket": ("canonical", "nambu", "triplets", "lie-poisson", "other"),
    "--name": ("custom", "my-system", "a b", "\\input{x}", "x" * 70),
    "--format": ("latex", "text", "json", "xml"),
    "--fig-format": ("png", "svg", "pdf", "jpg"),
}
#: Edge values of each numeric or text flag (zero, negative, huge, non-finite, a tower), tried one flag at a time by
#: :func:`test_each_flag_edge_value` on every subcommand that has the flag.
EDGE = {
    "--order": ("0", "-1", "13", BIG), "--degree": ("0", "13", BIG), "--limit": ("0", "junk", BIG),
    "--h": ("0", "nan", "1e308", TOWERS[0]), "--alpha": ("nan", "1e308", TOWERS[0]),
    "--steps": ("0", BIG, "1e3"), "--every": ("0", BIG), "--short-steps": ("0", BIG), "--dpi": ("0", BIG),
    "--x0": ("nan,1,1", "1e308,1e308,1e308", TOWERS[0] + ",1,1"), "--t-end": ("0", "1e308", TOWERS[0]),
    "--step-counts": ("0,4", BIG + ",4", "4"), "--param": ("m=" + TOWERS[0], "m=nan", "m=" + BIG),
    "--H": (TOWERS[1], PAYLOADS[0], "x1^2"), "--G": (PAYLOADS[0], "x1^2"), "--coords": ("x1 x1", "h x2"),
    "--model": ("nonexistent", "henon-heiles"), "--integrator": ("1234", "yoshida:yoshida:121"),
    "--chains": ("0", "1", BIG), "--iterations": ("0", BIG), "--burn": ("-1", BIG), "--seed": ("-1", "junk", BIG),
    "--refresh": ("", "x1,x1", "x9"), "--flip": ("x1,x2", "x9"), "--observable": (PAYLOADS[0], TOWERS[1], "x1^2"),
    "--name": ("\\input{x}", "a\nb"), "--output": ("out\n.txt", "out\u202e.txt", "nodir/out.txt"),
}
#: Options whose value is a path: relative, at most DEPTH - 1 levels up.
PATH_FLAGS = ("--output", "--outdir", "--figure", "--system")
NAMES = ("out.txt", "out.json", "fig.png", "fig.svg", "sys.toml", "bad.toml", "missing.toml", "sub", "sub/out.txt",
         "nodir/out.txt", ".", "..", " ", "out\n.txt", "out\u202e.txt", "\x00", "x" * 300, "sub/", "out.pdf")
TOML = 'name = "fuzz"\ncoordinates = ["x1", "x2"]\nH = "x2^2/2 + x1^2/2"\n'


@functools.lru_cache(maxsize=None)
def flags() -> dict:
    """``{subcommand: {flag: takes_value}}`` from the parser, and ``""`` for the top level."""
    parser = build_parser()
    out = {"": {o: a.nargs != 0 for a in parser._actions for o in a.option_strings}}
    subparsers = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, sub in subparsers.choices.items():
        out[name] = {o: a.nargs != 0 for a in sub._actions for o in a.option_strings}
    return out


def all_flags() -> dict:
    merged = {}
    for table in flags().values():
        merged.update(table)
    return merged


@st.composite
def path_value(draw):
    ups = draw(st.integers(0, DEPTH - 2))
    return "../" * ups + draw(st.sampled_from(NAMES))


@st.composite
def value_for(draw, flag):
    """A value for ``flag`` (or for a prefix of it): a path for path options, else valid-and-small or junk."""
    full = next((f for f in PATH_FLAGS if f.startswith(flag) and len(flag) > 2), flag)
    if full in PATH_FLAGS:
        return draw(path_value())
    junk = adversarial_text(12)
    if full in VALUES:
        valid = st.sampled_from(VALUES[full])
        return draw(st.one_of(valid, valid, valid, junk))  # mostly valid: the junk then meets a run that got far
    return draw(junk)


@st.composite
def option(draw, command):
    """One option: ``[flag, value]``, ``[flag]``, ``["--flag=value"]`` or a bare token."""
    own = flags().get(command, {})
    kind = draw(st.sampled_from(("own",) * 6 + ("other", "abbrev", "unknown", "bare", "joined")))
    table = all_flags() if kind == "other" or not own else own
    flag = draw(st.sampled_from(sorted(table)))
    if kind == "abbrev" and flag.startswith("--") and len(flag) > 4:
        flag = flag[: draw(st.integers(3, len(flag) - 1))]
    elif kind == "unknown":
        flag = draw(st.sampled_from(("--bogus", "-x", "---", "--", "-", "--h=", "--order=", "—order", "--OUTPUT")))
    elif kind == "bare":
        return [draw(st.one_of(st.sampled_from(("ho3", "12321", "shadow", *PAYLOADS[:1], *TOWERS[:1])),
                               adversarial_text(12)))]
    takes = table.get(flag, True)
    if not takes:
        return [flag]
    value = draw(value_for(flag))
    if kind == "joined":
        return [f"{flag}={value}"]
    return [flag, value]


def confined(token: str) -> bool:
    """No absolute or home path, and fewer ``..`` than the working directory is deep."""
    starts = (token,) + tuple(token.split("=", 1)[1:])
    return not any(s.startswith(("/", "~")) for s in starts) and token.count("..") < DEPTH


@st.composite
def argv(draw):
    head = draw(st.sampled_from((*SUBCOMMANDS, *SUBCOMMANDS, "", "sh", "SHADOW", "shadoww", "--help", "-h",
                                 "--version", "help", "--model")))
    command = head if head in SUBCOMMANDS else ""
    out = [head] if head else []
    for _ in range(draw(st.integers(1, 4))):
        out += draw(option(command))
    if command == "plot":  # a valid plot run draws four figures: keep its own run short
        out += ["--steps", "20", "--short-steps", "10", "--every", "1", "--dpi", "10"]
    if command in ("shadow", "check", "plot", "conserved", "compare"):
        out.append("--no-progress")
    if not all(confined(t) for t in out):
        from hypothesis import reject

        reject()
    return out


def listing(path: Path) -> list:
    return sorted(os.listdir(path))


def run_main(argv_, capsys):
    """``(status, stdout, stderr)`` of ``main(argv_)``; an exception out of main fails, naming argv."""
    try:
        status = main(list(argv_))
    except BaseException as exc:  # noqa: BLE001  (the point: nothing may leave main)
        capsys.readouterr()  # the next call starts with empty buffers
        first = (str(exc).splitlines() or [""])[0][:160]
        pytest.fail(f"main({argv_!r}) raised {type(exc).__name__}: {first}", pytrace=False)
    out, err = capsys.readouterr()
    return status, out, err


def check_outcome(argv_, status, out, err):
    shown = f"argv {argv_!r}: status {status}, stderr {err[:300]!r}"
    assert "Traceback" not in err, shown
    assert status in (0, 2), shown
    if status == 2:
        assert err.endswith("\n") and err.count("\n") == 1 and err.strip(), f"not one line on stderr: {shown}"
        assert out == "", f"stdout not empty on exit 2: {shown}, stdout {out[:200]!r}"
    else:  # at most the one-line notice "wrote FILE", its name escaped
        assert err.count("\n") <= 1 and "\r" not in err, f"more than one line on stderr: {shown}"


@pytest.fixture
def workdir(tmp_path):
    """The deep working directory, with a valid and an invalid system file and a subdirectory."""
    deep = tmp_path.joinpath(*(f"d{i}" for i in range(DEPTH)))
    deep.mkdir(parents=True)
    (deep / "sys.toml").write_text(TOML)
    (deep / "bad.toml").write_text("coordinates = [\n")
    (deep / "sub").mkdir()
    return deep


@FUZZ
@given(args=argv())
def test_random_argv_gives_status_0_or_one_line_and_2(args, workdir, capsys, tmp_path):
    """Random argv: exit 0, or exit 2 with one line on stderr and nothing on stdout; nothing written outside tmp_path."""
    outside = (tmp_path.parent, Path.cwd())
    before = [listing(p) for p in outside]
    old = os.getcwd()
    os.chdir(workdir)
    try:
        status, out, err = run_main(args, capsys)
    finally:
        os.chdir(old)
    check_outcome(args, status, out, err)
    assert [listing(p) for p in outside] == before, f"argv {args!r} wrote outside tmp_path"


#: argv for the subprocess check, one per subcommand: each must end with status 0 or one line and 2.  Each
#: subprocess pays an interpreter start and the imports; ``check --h exp(exp(exp(2.5)))`` and
#: ``shadow --output ../out\n.txt`` ran here too and run in process in :func:`test_each_flag_edge_value` (the
#: ``--h`` tower and the ``--output`` name with a newline are among its EDGE values).
SUBPROCESS_ARGV = (
    ["shadow", "--model", "pendulum", "--h", "0.1"],
    ["bch", "--order", "0"],
    ["fi", "--limit", "junk"],
    ["check", "--steps", BIG],
    ["models", "--H", PAYLOADS[0]],
)


def test_entry_point_subprocess(workdir):
    """A handful of argv through the installed ``nambu-bch`` entry point: the same contract as in process."""
    exe = Path(sys.executable).with_name("nambu-bch")
    assert exe.exists(), exe
    for args in SUBPROCESS_ARGV:
        proc = subprocess.run([str(exe), *args], cwd=workdir, capture_output=True, text=True, timeout=600,
                              stdin=subprocess.DEVNULL)
        check_outcome(args, proc.returncode, proc.stdout, proc.stderr)


@pytest.mark.parametrize("command", [c for c in SUBCOMMANDS if c != "plot"])  # plot: its valid run draws figures
def test_each_flag_edge_value(command, workdir, capsys, tmp_path):
    """Every edge value of every flag the subcommand has, one at a time (the rest default): the same contract."""
    outside = (tmp_path.parent, Path.cwd())
    before = [listing(p) for p in outside]
    old = os.getcwd()
    os.chdir(workdir)
    failures = []
    try:
        for flag, values in EDGE.items():
            if flag not in flags()[command]:
                continue
            for value in values:
                args = [command, flag, value] + (["--no-progress"] if "--no-progress" in flags()[command] else [])
                if command == "check" and flag != "--steps":
                    args += ["--steps", "10"]
                if command == "compare" and flag != "--step-counts":  # the default six runs up to N = 640 and
                    args += ["--step-counts", "10,20"]                  # a reference of 5120 steps per valid value
                    if flag != "--integrator":  # one method: the default three add kernels and error terms, no edge
                        args += ["--integrator", "strang"]
                try:  # every flag is tried; the failures are listed together
                    check_outcome(args, *run_main(args, capsys))
                except (AssertionError, pytest.fail.Exception) as exc:
                    failures.append(str(exc).splitlines()[0])
    finally:
        os.chdir(old)
    assert [listing(p) for p in outside] == before, f"{command} wrote outside tmp_path"
    assert not failures, "\n".join(failures)
