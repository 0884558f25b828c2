"""``nambu-bch compare``: work-precision comparison of integrators on a system.

The work is :func:`nambu_bch.design.compare`.
"""

from __future__ import annotations

from ..errors import NambuBCHError
from ._options import (add_subcommand, numeric_inputs, output_options, positive_float, positive_int, shown,
                       system_from_args, system_options)
from ._output import emit

HELP = "compare integrators: order, cost, error constant, the system's leading error, measured error vs cost"
EXAMPLES = (
    "examples:\n"
    "  nambu-bch compare --model ho3 --integrator 12321 --integrator triple-jump:12321 --integrator suzuki:12321\n"
    "  nambu-bch compare --model rigid-body --param I1=1 --param I2=2 --param I3=3 --integrator 12321 \\\n"
    "      --integrator 21312 --t-end 5 --step-counts 20,40,80,160 --figure wp.png --format json\n"
    "  nambu-bch compare --integrator strang --integrator kahan-li      # defaults: --model ho3, T = 10\n"
    "  nambu-bch compare --model henon-heiles --x0 0.1,-0.2,0.3,0.25 --integrator 121 --integrator pefrl \\\n"
    "      --integrator bm-srkn6 --integrator saba2 --integrator chin-4a --integrator takahashi-imada\n"
    "\n"
    "integrators: digit words, aliases (strang, lie-trotter, forest-ruth, yoshida:WORD, suzuki[:WORD],\n"
    "kahan-li[:WORD], yoshida6[:WORD], blanes-moan, pefrl, the CheckMethods catalogue such as emb-43-ak-s or\n"
    "milne-22-c-i: docs/integrators.md lists every name) or 'piece:coeff,...'; cost = sub-flow evaluations per\n"
    "step after merging equal neighbours (also across steps); Runge-Kutta methods (midpoint, gauss4, rk4,\n"
    "kahan, ... or --tableau FILE): field evaluations per step, measured (s per Newton iteration); the\n"
    "slope of log(error) vs log(evaluations)\n"
    "is -order. The reference solution is the 6th-order Kahan-Li composition at h_min/8. Force-gradient methods\n"
    "(chin-4a; takahashi-imada, run processed) on canonical T(p) + V(q) systems count a gradient kick as 2\n"
    "evaluations and each of the two processor applications of a run as 2."
)
MAX_INTEGRATORS = 12


def register(sub) -> None:
    p = add_subcommand(sub, "compare", HELP, EXAMPLES, run)
    system_options(p)
    p.add_argument("--integrator", dest="integrators", metavar="WORD", action="append",
                   help="an integrator to compare; repeat (default: the Strang word, its triple jump and Suzuki 5-jump)")
    p.add_argument("--tableau", dest="tableaux", metavar="FILE", action="append",
                   help="a Runge-Kutta method from a TOML tableau file (as for shadow --tableau); repeatable")
    p.add_argument("--t-end", metavar="T", default="10", help="final time T of the runs (default 10)")
    p.add_argument("--step-counts", metavar="N,N,...", default="20,40,80,160,320,640",
                   help="numbers of steps N (h = T/N), at least two (default 20,40,80,160,320,640)")
    p.add_argument("--x0", metavar="X", help="initial state, comma separated (default: the model's, else 1,...,1)")
    p.add_argument("--figure", metavar="FILE", help="write the log-log work-precision plot (.png, .pdf, .svg) atomically")
    output_options(p, "text", choices=("text", "json"))


def _step_counts(text):
    from ..design.compare import MAX_STEPS

    items = [t for t in text.replace(",", " ").split()]
    if len(items) < 2 or len(items) > 20:
        raise NambuBCHError(f"--step-counts {text!r} must list 2 to 20 step counts, e.g. 20,40,80,160")
    counts = [positive_int(t, "--step-counts", MAX_STEPS // 8) for t in items]
    if len(set(counts)) < 2:
        raise NambuBCHError(f"--step-counts {text!r} must hold at least two different step counts")
    return counts


def run(args):
    from ..design import compare
    from ..integrators.composition import strang_word

    system, values = system_from_args(args)
    params, x0 = numeric_inputs(args, system, values)
    words = args.integrators
    tableaux = []
    if args.tableaux:
        from ..integrators.tableau_file import load_tableau

        tableaux = [load_tableau(path) for path in args.tableaux]
    if not words and not tableaux:
        strang = strang_word(len(system.splitting))
        words = [strang, f"triple-jump:{strang}", f"suzuki:{strang}"] if len(strang) > 1 else [strang]
    words = list(words or [])
    if len(words) + len(tableaux) > MAX_INTEGRATORS:
        raise NambuBCHError(f"--integrator/--tableau given {len(words) + len(tableaux)} times; compare accepts at most "
                            f"{MAX_INTEGRATORS}")
    for w in words:
        if not w.strip() or len(w) > 200:
            raise NambuBCHError(f"--integrator {w[:40]!r} must be a non-empty string of at most 200 characters")
    if args.figure is not None and not args.figure.lower().endswith((".png", ".pdf", ".svg")):
        raise NambuBCHError(f"--figure {shown(args.figure)}: give a file name ending in .png, .pdf or .svg")
    t_end = positive_float(args.t_end, "--t-end")
    if t_end > 1e5:
        raise NambuBCHError(f"--t-end {args.t_end!r} must be at most 1e5")
    counts = _step_counts(args.step_counts)
    result = compare(system, words + tableaux, t_end=t_end, steps=counts, x0=x0, params=params)
    if args.figure:
        try:
            result.figure(args.figure)
        except OSError as exc:
            raise NambuBCHError(f"--figure {shown(args.figure)}: cannot write the file ({exc.strerror or exc})") from None

    def data():
        from .. import render

        return {**render.system_dict(system), **result.to_dict()}  # the coordinates and bracket analysed, too

    emit(args, text=result.table, data=data, system=system)
