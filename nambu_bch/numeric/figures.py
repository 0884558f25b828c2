"""The paper's Figs. 1-4, regenerated from their captions (matplotlib, Agg canvas, no pyplot state).

All four figures iterate ``Phi^{32123}_h`` on the N = 3 oscillator ``ho3`` with
``m = omega = 1``, ``h = 0.1`` and ``x(0) = (1, 1, 1)`` (Sect. 5.5):

1. ``H(t) - H(0)`` (solid) and ``H_c(t) - H_c(0)`` (dashed);
2. ``G(t) - G(0)`` (solid) and ``G_c(t) - G_c(0)`` (dashed);
3. ``x3^o(t) - x3(t)`` (solid), data every 100 steps: the beat between the
   frequencies ``omega`` and ``F(omega h) tilde omega`` (Eq. OHsol);
4. ``x3^c(t) - x3(t)`` (solid) and ``x3^s(t) - x3(t)`` (dashed, Eqs. CQsol and
   SHsol); a second panel magnifies ``x3^s - x3`` to show it is round-off.

The beat of Fig. 3 has period ``pi / |omega - omega_eff|`` ~ 7.5e3 for
``h = 0.1`` (``omega_eff = 2 asin(omega h / 2) / h``), so the long span of
Figs. 3-4 defaults to ``t = 2 10^4`` (2 10^5 steps), about 2.6 beats.

The figures are drawn on :class:`matplotlib.figure.Figure` with an Agg canvas,
so a caller's pyplot backend (Jupyter inline, Qt) is left untouched.

References
----------
Horikoshi, Sect. 5.5, Figs. 1-4, Eqs. (OHsol), (CQsol), (SHsol), Table (table).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..atomic import write_atomic
from ..errors import InvalidRunError
from .diagnostics import errors_along, quantities, solution_differences
from .iterate import as_system, iterate, sample_times

#: File names written by :func:`paper_figures`.
FIGURE_NAMES = ("fig1", "fig2", "fig3", "fig4")


def _figure(width=6.4, height=3.84, ncols=1):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * (1 if ncols == 1 else 1.55), height))
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(1, ncols, k + 1) for k in range(ncols)]
    return fig, axes


def paper_figures(outdir, *, word="32123", h=0.1, x0=(1.0, 1.0, 1.0), params=None, t_short=100.0,
                  t_long=20000.0, every_long=100, dpi=100, fmt="png", system="ho3") -> dict:
    """Write Figs. 1-4 of the paper to ``outdir`` (``fig1.png`` ... ``fig4.png``); returns ``{name: path}``.

    Parameters
    ----------
    outdir : str or Path (created if missing)
    word, h, x0, params, system : the run (defaults: the paper's ``32123``, ``h = 0.1``, ``(1, 1, 1)``, ``m = omega = 1``)
    t_short : float -- time span of Figs. 1-2 (every step plotted)
    t_long : float -- time span of Figs. 3-4 (long enough for the beat)
    every_long : int -- sampling of Figs. 3-4 (the paper plots every 100 steps)
    dpi : int; fmt : ``"png"``, ``"pdf"`` or ``"svg"``

    Returns
    -------
    dict -- ``{"fig1": Path, ..., "fig4": Path}``

    References
    ----------
    Horikoshi, Sect. 5.5, Figs. 1-4.
    """
    if fmt not in ("png", "pdf", "svg"):
        raise InvalidRunError(f"figure format must be png, pdf or svg, got {fmt!r}")
    system = as_system(system)
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    h = float(h)
    n_short = max(1, int(round(t_short / h)))
    n_long = max(every_long, int(round(t_long / h)) // every_long * every_long)
    label = rf"$\Phi^{{{word}}}_h$, $h = {h:g}$"

    short = iterate(system, word, h, n_short, x0, params, 1)
    t = sample_times(h, n_short, 1)
    errs = errors_along(short, quantities(system, word, h, params, which=("H", "G", "H_c", "G_c")), system.coordinates)
    paths = {}
    for name, (a, b) in {"fig1": ("H", "H_c"), "fig2": ("G", "G_c")}.items():
        if a not in errs:
            continue
        fig, (ax,) = _figure()
        ax.plot(t, errs[a], "-", lw=1.0, color="C0", label=f"${a}(t) - {a}(0)$")
        if b in errs:
            sub = b.replace("_c", "_{c}")
            ax.plot(t, errs[b], "--", lw=1.2, color="C3", label=f"${sub}(t) - {sub}(0)$")
        ax.set_xlabel("$t$")
        ax.set_ylabel("error")
        ax.set_title(f"Time evolution by {label}", fontsize=10)
        ax.axhline(0, color="0.7", lw=0.5, zorder=0)
        _headroom(ax)
        ax.legend(loc="upper right", fontsize=9, ncol=2)
        ax.set_xlim(t[0], t[-1])
        paths[name] = _save(fig, outdir / f"{name}.{fmt}", dpi)

    long = iterate(system, word, h, n_long, x0, params, every_long)
    tl = sample_times(h, n_long, every_long)
    diffs = solution_differences(system, word, h, n_long, every_long, x0, long, params)
    last = system.coordinates[-1]
    o, c, s = (f"{last}_{k}" for k in "ocs")
    tex = str(last).replace("x", "x_") if str(last).startswith("x") else str(last)
    if o in diffs:
        fig, (ax,) = _figure()
        ax.plot(tl, diffs[o], "-", lw=0.4, color="C0",
                label=f"${tex}^{{\\rm o}}(t) - {tex}^{{{word}}}(t)$ (every {every_long} steps)")
        ax.set_xlabel("$t$")
        ax.set_ylabel("difference")
        ax.set_title(f"Original-Hamiltonian solution vs {label}: the beat", fontsize=10)
        _headroom(ax, 0.2)
        ax.legend(loc="upper right", fontsize=9)
        ax.set_xlim(tl[0], tl[-1])
        paths["fig3"] = _save(fig, outdir / f"fig3.{fmt}", dpi)
    if c in diffs and s in diffs:
        fig, (ax, zoom) = _figure(ncols=2)
        ax.plot(tl, diffs[c], "-", lw=0.4, color="C0", label=f"${tex}^{{\\rm c}}(t) - {tex}^{{{word}}}(t)$")
        ax.plot(tl, diffs[s], "--", lw=1.5, color="C3", label=f"${tex}^{{\\rm s}}(t) - {tex}^{{{word}}}(t)$")
        ax.set_xlabel("$t$")
        ax.set_ylabel("difference")
        ax.set_title(f"Conserved-quantity and shadow solutions vs {label}", fontsize=9)
        _headroom(ax, 0.3)
        ax.legend(loc="upper right", fontsize=8, ncol=2)
        ax.set_xlim(tl[0], tl[-1])
        zoom.plot(tl, diffs[s], "-", lw=0.4, color="C3", label=f"${tex}^{{\\rm s}}(t) - {tex}^{{{word}}}(t)$ (magnified)")
        zoom.set_xlabel("$t$")
        zoom.set_title(f"magnified: max {np.max(np.abs(diffs[s])):.1e} (round-off)", fontsize=9)
        _headroom(zoom, 0.2)
        zoom.legend(loc="upper left", fontsize=8)
        zoom.set_xlim(tl[0], tl[-1])
        zoom.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))
        fig.tight_layout()
        paths["fig4"] = _save(fig, outdir / f"fig4.{fmt}", dpi)
    return paths


def _headroom(ax, frac=0.35):
    """Extend the y-range upwards so the legend sits above the data."""
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + frac * (hi - lo))


def _save(fig, path, dpi):
    if not fig.get_tight_layout():
        fig.tight_layout()
    buffer = io.BytesIO()
    fmt = Path(path).suffix.lstrip(".") or "png"
    fig.savefig(buffer, format=fmt, dpi=dpi, metadata={"Software": None} if fmt == "png" else None)
    write_atomic(path, buffer.getvalue())
    return path
