"""Record the command line's outputs for a corpus of requests, or compare them byte for byte with a recording.

A refactor of the exact engine must not change a single printed byte.  This tool runs a fixed corpus of
requests (:data:`CORPUS`: every built-in model, both routes, h^2 to h^8, each existence outcome, and the
``conserved``, ``exact``, ``bch``, ``fi`` and ``check`` subcommands, in LaTeX, text and JSON), each in a fresh
``nambu-bch`` process with progress bars off, and keeps stdout, stderr and the exit code of each.

    python tools/output_corpus.py record DIR      # DIR/NN-name.out, DIR/manifest.json (SHA-256 of each)
    python tools/output_corpus.py compare DIR     # exit 1 and a short diff for each request that differs

``--jobs N`` runs N requests at a time (default 2), ``--only SUBSTRING`` a subset.  Nothing in the corpus prints a
time, so two runs of the same tree agree byte for byte.
"""

from __future__ import annotations

import argparse
import difflib
import hashlib
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from nambu_bch.atomic import write_atomic  # noqa: E402  (the package's writer: atomic, never over a non-regular file)

#: (name, argv) of each request; names are unique and safe as file names.
CORPUS: tuple[tuple[str, tuple[str, ...]], ...] = (
    # the paper's example and its routes and orders
    ("shadow-ho3-default", ("shadow",)),
    ("shadow-ho3-h4-text", ("shadow", "--order", "4", "--format", "text")),
    ("shadow-ho3-h6-json", ("shadow", "--order", "6", "--format", "json")),
    ("shadow-ho3-h4-fi", ("shadow", "--order", "4", "--route", "fi")),
    ("shadow-ho3-32123-h4", ("shadow", "--integrator", "32123", "--order", "4")),
    ("shadow-ho3-13231-h4-json", ("shadow", "--integrator", "13231", "--order", "4", "--format", "json")),
    ("shadow-ho3-yoshida-h4", ("shadow", "--integrator", "yoshida", "--order", "4", "--format", "text")),
    ("shadow-ho3-standalone", ("shadow", "--standalone")),
    ("shadow-ho3-param", ("shadow", "--param", "m=1/2", "--order", "4", "--format", "text")),
    # every built-in model at h^2 (the default word), text
    *((f"shadow-{m}-h2", ("shadow", "--model", m, "--format", "text")) for m in (
        "ho", "rigid-body", "lotka-volterra", "ho3-composite", "pendulum", "henon-heiles", "fpu-beta", "toda",
        "exp-well", "rational", "rigid-body-lp", "ho3-pair")),
    # higher orders, other routes, existence outcomes
    ("shadow-ho-h8-json", ("shadow", "--model", "ho", "--order", "8", "--format", "json")),
    ("shadow-rigid-body-h4-latex", ("shadow", "--model", "rigid-body", "--order", "4")),
    ("shadow-rigid-body-123-h2", ("shadow", "--model", "rigid-body", "--integrator", "123", "--format", "text")),
    ("shadow-rigid-body-numeric-h8", ("shadow", "--model", "rigid-body", "--param", "I1=1", "--param", "I2=2",
                                      "--param", "I3=3", "--order", "8", "--format", "json")),
    ("shadow-lotka-volterra-h4-fi", ("shadow", "--model", "lotka-volterra", "--order", "4", "--route", "fi",
                                     "--format", "text")),
    ("shadow-lotka-volterra-h6-json", ("shadow", "--model", "lotka-volterra", "--order", "6", "--format", "json")),
    ("shadow-lotka-volterra-h4-no-existence", ("shadow", "--model", "lotka-volterra", "--order", "4", "--degree", "3",
                                               "--no-existence", "--format", "text")),
    ("shadow-pendulum-h4-json", ("shadow", "--model", "pendulum", "--order", "4", "--format", "json")),
    ("shadow-henon-heiles-h4", ("shadow", "--model", "henon-heiles", "--order", "4", "--format", "text")),
    ("shadow-ho3-pair-h4", ("shadow", "--model", "ho3-pair", "--order", "4", "--format", "text")),
    ("shadow-user-H-G", ("shadow", "--H", "x2^2/2 + x3", "--G", "x3 - x1^2", "--format", "json")),
    ("shadow-user-canonical", ("shadow", "--H", "p^2/2 + q^4/4", "--coords", "q p", "--order", "4",
                               "--format", "text")),
    # the other symbolic subcommands
    ("conserved-ho3-12321", ("conserved",)),
    ("conserved-ho3-32123-json", ("conserved", "--integrator", "32123", "--format", "json")),
    ("conserved-ho-text", ("conserved", "--model", "ho", "--format", "text")),
    ("exact-ho3", ("exact",)),
    ("exact-ho3-h4-json", ("exact", "--order", "4", "--format", "json")),
    ("exact-ho3-13231-text", ("exact", "--integrator", "13231", "--format", "text")),
    ("bch-12321-h5", ("bch", "--integrator", "12321", "--order", "5")),
    ("bch-121-h6-json", ("bch", "--model", "ho", "--integrator", "121", "--order", "6", "--format", "json")),
    ("bch-ho3-field-terms", ("bch", "--order", "3", "--field", "--terms", "--format", "text")),
    ("bch-rigid-body-field-json", ("bch", "--model", "rigid-body", "--order", "4", "--field", "--format", "json")),
    ("fi-ho3", ("fi",)),
    ("fi-ho3-h4-text", ("fi", "--order", "4", "--limit", "20", "--format", "text")),
    ("fi-lotka-volterra-json", ("fi", "--model", "lotka-volterra", "--format", "json")),
    # numerics (deterministic: no timings are printed)
    ("check-ho3", ("check", "--steps", "200")),
    ("check-rigid-body-json", ("check", "--model", "rigid-body", "--order", "4", "--steps", "200", "--format", "json")),
    ("models", ("models",)),
    # Runge-Kutta and Kahan methods: the direct route on the modified field
    ("shadow-rigid-body-gauss4-h4-json", ("shadow", "--integrator", "gauss4", "--model", "rigid-body", "--order", "4",
                                          "--format", "json")),
    ("shadow-rigid-body-midpoint-text", ("shadow", "--integrator", "midpoint", "--model", "rigid-body", "--format", "text")),
)


def run_one(name: str, argv: tuple[str, ...]) -> bytes:
    """stdout, stderr and exit code of one request in a fresh process, as one byte string."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100", MPLBACKEND="Agg")
    cmd = [sys.executable, "-m", "nambu_bch", *argv]
    if argv[0] in {"shadow", "conserved", "check"}:
        cmd.append("--no-progress")
    proc = subprocess.run(cmd, capture_output=True, env=env, cwd=ROOT, timeout=600, check=False)
    return b"".join((b"$ nambu-bch ", " ".join(argv).encode(), b"\n", b"exit %d\n" % proc.returncode,
                     b"--- stdout\n", proc.stdout, b"--- stderr\n", proc.stderr))


def file_name(index: int, name: str) -> str:
    return f"{index:02d}-{name}.out"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=("record", "compare"))
    parser.add_argument("directory", type=Path)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--only", default="", help="run only the requests whose name contains this")
    args = parser.parse_args(argv)
    todo = [(i, n, a) for i, (n, a) in enumerate(CORPUS) if args.only in n]
    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        outputs = list(pool.map(lambda t: run_one(t[1], t[2]), todo))
    if args.mode == "record":
        args.directory.mkdir(parents=True, exist_ok=True)
        manifest = {}
        for (i, n, _), out in zip(todo, outputs):
            write_atomic(args.directory / file_name(i, n), out)
            manifest[file_name(i, n)] = hashlib.sha256(out).hexdigest()
        write_atomic(args.directory / "manifest.json", json.dumps(manifest, indent=1) + "\n")
        print(f"recorded {len(todo)} requests in {args.directory}")
        return 0
    differ, new = 0, []
    for (i, n, _), out in zip(todo, outputs):
        try:
            old = (args.directory / file_name(i, n)).read_bytes()
        except FileNotFoundError:  # a request added to the corpus after this recording: nothing to compare with
            new.append(n)
            continue
        if old != out:
            differ += 1
            print(f"DIFFERS {n}")
            diff = difflib.unified_diff(old.decode(errors="replace").splitlines(), out.decode(errors="replace").splitlines(),
                                        "recorded", "now", lineterm="", n=1)
            print("\n".join(list(diff)[:40]))
    compared = len(todo) - len(new)
    print(f"{compared - differ} of {compared} recorded requests identical"
          + (f"; {len(new)} not in the recording (added later): {', '.join(new)}" if new else ""))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
