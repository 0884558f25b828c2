"""``nambu-bch plot``: the paper's Figs. 1-4 for a word on a system (:func:`nambu_bch.numeric.paper_figures`)."""

from __future__ import annotations

import os

from ..errors import NambuBCHError
from ._options import (add_subcommand, integrator_from_args, integrator_options, numeric_inputs, numeric_options,
                       output_options, progress_option, shown, system_from_args, system_options)
from ._output import emit

HELP = "regenerate the paper's Figs. 1-4 as PNG files"
EXAMPLES = ("examples:\n  nambu-bch plot --integrator 32123 --outdir figures    # Figs. 1-4 of the paper (h = 0.1)\n"
            "  nambu-bch plot --integrator 12321 --outdir /tmp/figs --steps 20000 --every 10")


def register(sub) -> None:
    p = add_subcommand(sub, "plot", HELP, EXAMPLES, run)
    progress_option(p)
    system_options(p)
    integrator_options(p, default="32123 on ho3 (the paper's Figs. 1-4), else the Strang word 12..n..21")
    p.add_argument("--outdir", metavar="DIR", default=".", help="directory for fig1.png .. fig4.png (default .)")
    numeric_options(p, {"h": 0.1, "steps": "200000 (t = 20000 at h = 0.1)", "every": 100})
    p.add_argument("--short-steps", metavar="N", help="steps of the Figs. 1-2 run (default 1000, t = 100 at h = 0.1)")
    p.add_argument("--dpi", metavar="DPI", help="resolution of the images (default 100)")
    p.add_argument("--fig-format", choices=("png", "pdf", "svg"), default="png", help="image format (default png)")
    output_options(p, "text", choices=("text", "json"))


def run(args):
    outdir = args.outdir
    if not os.path.isdir(outdir):
        try:
            os.makedirs(outdir, exist_ok=True)
        except (OSError, ValueError) as exc:
            raise NambuBCHError(f"--outdir {shown(outdir)}: cannot create the directory ({exc.strerror or exc})") from None
    system, values = system_from_args(args)
    if args.integrator is None and system.name == "ho3":
        args.integrator = "32123"  # the paper's Figs. 1-4
    word, comp = integrator_from_args(args, system)
    params, x0 = numeric_inputs(args, system, values)
    kwargs = {"word": word, "h": args.h, "x0": x0, "params": params, "system": system, "fmt": args.fig_format}
    if args.steps is not None:
        kwargs["t_long"] = args.steps * args.h
    if args.short_steps is not None:
        kwargs["t_short"] = args.short_steps * args.h
    if args.every is not None:
        kwargs["every_long"] = args.every
    if args.dpi is not None:
        kwargs["dpi"] = args.dpi
    from ..numeric.figures import paper_figures

    files = paper_figures(outdir, **kwargs)
    files = [os.fspath(f) for f in (files.values() if isinstance(files, dict) else files)]

    def data():
        from .. import render

        return {**render.system_dict(system), "outdir": os.fspath(outdir), "files": files}

    emit(args, text=lambda: "\n".join(files), data=data, system=system)

