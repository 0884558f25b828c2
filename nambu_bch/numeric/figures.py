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

import os
import tempfile
from pathlib import Path

import numpy as np
import sympy

from ..checks import finite_float
from ..errors import InvalidRunError, NambuBCHError
from ..integrators.step import parameter_values
from .diagnostics import _exact, _try, numpy_function, quantities
from .guards import MAX_RUN_STEPS, check_count, check_inputs, check_work, initial_state
from .iterate import as_system, iterate_chunks
from .samples import n_samples

#: File names written by :func:`paper_figures`.
FIGURE_NAMES = ("fig1", "fig2", "fig3", "fig4")
#: Most points drawn per curve; longer runs are drawn as their min/max envelope per bucket of samples.
MAX_POINTS = 40_000
#: Highest resolution of a figure (dots per inch): a 6.4 x 3.84 inch figure at 1200 dpi is already 35 Mpixel.
MAX_DPI = 1200


class FigureSet(dict):
    """``{name: Path}`` of the files written (empty if none were), plus ``.figures``: ``{name: Figure}``.

    A dict, so code that used the paths keeps working; the matplotlib figures are there to
    show in Jupyter (``fs.figures["fig3"]``) or to restyle and save again.
    """

    def __init__(self, paths, figures):
        super().__init__(paths)
        self.figures = dict(figures)

    def _repr_html_(self):  # pragma: no cover - Jupyter display only
        return None


def _figure(dpi, width=6.4, height=3.84, ncols=1):
    """A figure at the resolution it is saved at: laid out (``tight_layout``) and drawn at one dpi, its text
    is measured once per string (matplotlib caches the mathtext layout per resolution)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * (1 if ncols == 1 else 1.55), height), dpi=dpi)
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(1, ncols, k + 1) for k in range(ncols)]
    return fig, axes


class _Envelope:
    """Streamed series for plotting: all samples if few, else per bucket of ``size`` samples its min and max.

    Also the exact ``max |y|`` of the whole series (for titles).  Blocks must start on bucket
    boundaries (``iterate_chunks`` with ``chunk_samples - 1`` a multiple of ``size``).
    """

    def __init__(self, size):
        self.size = size
        self.t, self.y = [], []
        self.max_abs = 0.0

    def add(self, t, y):
        if not y.size:
            return
        self.max_abs = max(self.max_abs, float(np.max(np.abs(y))))
        if self.size == 1:
            self.t.append(t)
            self.y.append(y)
            return
        m = -(-y.size // self.size)
        pad = m * self.size - y.size
        yy = np.concatenate([y, np.full(pad, np.nan)]).reshape(m, self.size)
        lo, hi = np.nanmin(yy, axis=1), np.nanmax(yy, axis=1)
        tt = t[::self.size]
        self.t.append(np.repeat(tt, 2))
        self.y.append(np.column_stack([lo, hi]).ravel())

    def arrays(self):
        return np.concatenate(self.t), np.concatenate(self.y)


def _stream(system, word, h, steps, every, x0, params, names=(), kinds=""):
    """Run once, streamed; ``{quantity error or x_k difference: _Envelope}`` and the bucket size.

    Quantities ``Q(t) - Q(0)`` for ``names`` (where defined), solution differences
    ``x^kind(t) - x(t)`` of the last coordinate for ``kinds`` (where a closed form exists).
    """
    total = n_samples(steps, every)
    size = 1 if total <= MAX_POINTS else -(-total // (MAX_POINTS // 2))
    block = max(size, (1 << 16) // size * size)
    exprs = quantities(system, word, h, params, which=names) if names else {}
    fns = {q: numpy_function(e, system.coordinates) for q, e in exprs.items()}
    sols = {}
    for kind in kinds:
        sol = _try(lambda k=kind: _exact().modified_solution(system, word, k).numeric(params=params, h=float(h)))
        if sol is not None:
            sols[kind] = sol
    last = system.N - 1
    env = {q: _Envelope(size) for q in fns}
    env.update({k: _Envelope(size) for k in sols})
    x0f = np.asarray(x0, dtype=np.float64)
    start = {}
    with np.errstate(all="ignore"):
        for numbers, samples in iterate_chunks(system, word, h, steps, x0, params, every, chunk_samples=block + 1):
            t = float(h) * numbers.astype(np.float64)
            for q, fn in fns.items():
                v = fn(samples)
                if q not in start:
                    start[q] = v[0]
                env[q].add(t, v - start[q])
            for kind, sol in sols.items():
                env[kind].add(t, sol(t, x0f)[last] - samples[:, last])
    bad = [q for q, e in env.items() if not np.isfinite(e.max_abs)]
    if bad:
        raise NambuBCHError(f"the plotted {', '.join(bad)} of {system.name} under {word} are not finite "
                            "(float64 overflow); rescale the initial state or the parameters")
    return env, size


def paper_figures(outdir=None, *, word="32123", h=0.1, x0=None, params=None, t_short=100.0,
                  t_long=20000.0, every_long=100, dpi=100, fmt="png", system="ho3") -> FigureSet:
    """Draw Figs. 1-4 of the paper and write them to ``outdir`` as one set (``fig1.png`` ... ``fig4.png``).

    The runs are streamed (:func:`~nambu_bch.numeric.iterate.iterate_chunks`): a run of more
    than :data:`MAX_POINTS` samples is drawn as the min/max envelope of buckets of samples,
    so memory stays bounded.  The files are written all or nothing: every figure is rendered
    and staged in a temporary file in ``outdir`` first, then each is moved into place; a file
    error removes the staged files and raises one :class:`~nambu_bch.errors.NambuBCHError` line.

    Parameters
    ----------
    outdir : str or Path, optional -- created if missing; None: draw only, write nothing
    word, h, x0, params, system : the run (defaults: the paper's ``32123``, ``h = 0.1``, the model's documented
        x0 -- ``(1, 1, 1)`` for ho3 --, ``m = omega = 1``)
    t_short : float -- time span of Figs. 1-2 (every step plotted)
    t_long : float -- time span of Figs. 3-4 (long enough for the beat)
    every_long : int -- sampling of Figs. 3-4 (the paper plots every 100 steps)
    dpi : int, 1 to :data:`MAX_DPI` -- the figures are created, laid out and written at it; fmt : ``"png"``, ``"pdf"``
        or ``"svg"``

    Returns
    -------
    FigureSet -- ``{"fig1": Path, ..., "fig4": Path}`` (the files written) with ``.figures``,
    ``{"fig1": matplotlib.figure.Figure, ...}``; figures a system does not have are absent.

    References
    ----------
    Horikoshi, Sect. 5.5, Figs. 1-4.
    """
    if not isinstance(fmt, str) or fmt not in ("png", "pdf", "svg"):
        raise InvalidRunError(f"figure format must be png, pdf or svg, got {fmt!r}")
    system = as_system(system)
    x0, _ = initial_state(system, x0)
    h, t_short, t_long = finite_float(h, "h"), finite_float(t_short, "t_short"), finite_float(t_long, "t_long")
    for what, value in (("h", h), ("t_short", t_short), ("t_long", t_long)):
        if not value > 0:
            raise InvalidRunError(f"{what} must be a positive number, got {value!r}")
    every_long = check_count(every_long, "every_long", 1)
    dpi = check_count(dpi, "dpi", 1)
    if dpi > MAX_DPI:
        raise InvalidRunError(f"dpi must be between 1 and {MAX_DPI}, got {dpi}")
    # both runs' lengths from the request, before either starts (t / h can be astronomically many steps)
    for t in (t_short, t_long):
        check_work(int(min(t / h, 2.0 * MAX_RUN_STEPS)), x0)
    n_short = max(1, int(round(t_short / h)))
    n_long = max(every_long, int(round(t_long / h)) // every_long * every_long)
    x0 = check_inputs(system, h, max(n_short, n_long), every_long, x0, params)[3]  # before any title uses them
    if x0.ndim != 1:
        raise InvalidRunError(f"x0 must be one initial state of shape ({system.N},), got shape {x0.shape}")
    values = parameter_values(system, params)
    name = _plain(system.name)
    setting = ", ".join([f"$h = {h:g}$"] + [f"${_param_tex(p)} = {v:g}$" for p, v in values.items()] +
                        [rf"$x(0) = ({', '.join(f'{float(v):g}' for v in x0)})$"])
    scheme = rf"$\Phi^{{{_tex_word(word)}}}_h$"
    figures = {}

    env, _ = _stream(system, word, h, n_short, 1, x0, params, names=("H", "G", "H_c", "G_c"))
    for fig_name, (a, b) in {"fig1": ("H", "H_c"), "fig2": ("G", "G_c")}.items():
        if a not in env:
            continue
        fig, (ax,) = _figure(dpi)
        t, y = env[a].arrays()
        ax.plot(t, y, "-", lw=1.0, color="C0", label=f"${a}(t) - {a}(0)$")
        if b in env:
            sub = b.replace("_c", "_{c}")
            tb, yb = env[b].arrays()
            ax.plot(tb, yb, "--", lw=1.2, color="C3", label=f"${sub}(t) - {sub}(0)$")
        ax.set_xlabel("$t$")
        ax.set_ylabel("error")
        ax.set_title(f"{name}, {scheme}: {setting}", fontsize=9)
        ax.axhline(0, color="0.7", lw=0.5, zorder=0)
        _headroom(ax)
        ax.legend(loc="upper right", fontsize=9, ncol=2)
        ax.set_xlim(t[0], t[-1])
        figures[fig_name] = fig

    env, size = _stream(system, word, h, n_long, every_long, x0, params, kinds="ocs")
    last = system.coordinates[-1]
    tex = str(last).replace("x", "x_") if str(last).startswith("x") else str(last)
    run = rf"{tex}^{{{_tex_word(word)}}}(t)"
    drawn = f"every {every_long} steps" + (f", min/max of {size} samples" if size > 1 else "")
    if "o" in env:
        fig, (ax,) = _figure(dpi)
        t, y = env["o"].arrays()
        ax.plot(t, y, "-", lw=0.4, color="C0", label=f"${tex}^{{\\rm o}}(t) - {run}$ ({drawn})")
        ax.set_xlabel("$t$")
        ax.set_ylabel("difference")
        ax.set_title(f"the beat, {name}, {scheme}: {setting}", fontsize=9)
        _headroom(ax, 0.2)
        ax.legend(loc="upper right", fontsize=9)
        ax.set_xlim(t[0], t[-1])
        figures["fig3"] = fig
    if "c" in env and "s" in env:
        fig, (ax, zoom) = _figure(dpi, ncols=2)
        tc, yc = env["c"].arrays()
        ts, ys = env["s"].arrays()
        ax.plot(tc, yc, "-", lw=0.4, color="C0", label=f"${tex}^{{\\rm c}}(t) - {run}$")
        ax.plot(ts, ys, "--", lw=1.5, color="C3", label=f"${tex}^{{\\rm s}}(t) - {run}$")
        ax.set_xlabel("$t$")
        ax.set_ylabel("difference")
        ax.set_title(f"{name}, {scheme}: {setting}", fontsize=8)
        _headroom(ax, 0.3)
        ax.legend(loc="upper right", fontsize=8, ncol=2)
        ax.set_xlim(tc[0], tc[-1])
        zoom.plot(ts, ys, "-", lw=0.4, color="C3", label=f"${tex}^{{\\rm s}}(t) - {run}$ (magnified)")
        zoom.set_xlabel("$t$")
        zoom.set_title(f"magnified: max {env['s'].max_abs:.1e} (round-off)", fontsize=9)
        _headroom(zoom, 0.2)
        zoom.legend(loc="upper left", fontsize=8)
        zoom.set_xlim(ts[0], ts[-1])
        zoom.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))
        fig.tight_layout()  # the two panels' labels would overlap in a figure shown without being written
        figures["fig4"] = fig
    laid_out = {"fig4"}
    paths = _write_set(outdir, figures, fmt, dpi, laid_out) if outdir is not None else {}
    return FigureSet(paths, figures)


def _plain(text):
    """A name for a title: letters, digits, ``-`` and ``_`` only (never ``$`` or ``\\``: no mathtext or LaTeX)."""
    return "".join(ch for ch in str(text) if ch.isalnum() or ch in "-_")[:40] or "system"


def _param_tex(symbol):
    """A parameter for mathtext: sympy's LaTeX of a plain identifier (``omega`` -> ``\\omega``), else its letters."""
    text = str(symbol)
    if text.isidentifier() and text.isascii():
        return sympy.latex(sympy.Symbol(text))
    return r"\mathrm{" + _plain(text) + "}"


def _tex_word(word):
    """The word for a LaTeX superscript: digits and letters only, anything else dropped (never raw user text)."""
    text = "".join(ch for ch in str(word) if ch.isalnum() or ch in "-:")
    return text[:40] or "?"


def _headroom(ax, frac=0.35):
    """Extend the y-range upwards so the legend sits above the data."""
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + frac * (hi - lo))


def _render(fig, fmt, dpi, layout=True):
    """The file's bytes; ``layout``: ``tight_layout`` first (once per figure: a second pass only moves the
    axes by round-off, at the cost of measuring every text again)."""
    import io

    if layout:
        fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format=fmt, dpi=dpi, metadata={"Software": None} if fmt == "png" else None)
    return buffer.getvalue()


def _write_set(outdir, figures, fmt, dpi, laid_out=frozenset()) -> dict:
    """Write every figure or none.

    Render all; stage each in a temp file in ``outdir``; keep a hard-linked backup of every file
    about to be replaced; move the staged files into place; if any move fails, restore the
    backups and remove the files this call created.  One :class:`NambuBCHError` line on failure.
    """
    outdir = Path(outdir)
    data = {name: _render(fig, fmt, dpi, layout=name not in laid_out) for name, fig in figures.items()}
    staged, backups, done = {}, {}, []
    try:
        outdir.mkdir(parents=True, exist_ok=True)
        for name, blob in data.items():
            fd, tmp = tempfile.mkstemp(dir=outdir, prefix=f".tmp-{name}-")
            staged[name] = tmp
            with os.fdopen(fd, "wb") as fh:
                fh.write(blob)
                fh.flush()
                os.fsync(fh.fileno())
            os.chmod(tmp, 0o644)
        for name in staged:
            target = outdir / f"{name}.{fmt}"
            if os.path.lexists(target) and os.path.isfile(target) and not os.path.islink(target):
                backup = f"{staged[name]}.old"
                os.link(target, backup)
                backups[target] = backup
        for name, tmp in list(staged.items()):
            target = outdir / f"{name}.{fmt}"
            os.replace(tmp, target)
            done.append(target)
            del staged[name]
        return {path.stem: path for path in done}
    except OSError as exc:
        for target in done:  # roll back: the old file where there was one, else nothing
            try:
                if target in backups:
                    os.replace(backups.pop(target), target)
                else:
                    os.unlink(target)
            except OSError:
                pass
        where = exc.filename if isinstance(exc.filename, str) else outdir
        raise NambuBCHError(f"cannot write the figures to {outdir} ({exc.strerror or exc}: {where}); "
                            "no figure was written") from None
    finally:
        for tmp in [*staged.values(), *backups.values()]:
            try:
                os.unlink(tmp)
            except OSError:
                pass
