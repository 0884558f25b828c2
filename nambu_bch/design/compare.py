"""Work-precision comparison of integrators on one system: order, cost, error constants, measured error.

Per word:

* ``order`` and ``error_constant`` -- formal, from the exact Lyndon defects
  (:func:`~nambu_bch.design.error_analysis`; ``None`` if the word does not use every piece);
* ``cost`` -- sub-flow evaluations per step after merging equal neighbours, including
  across steps (first-same-as-last: a word that starts and ends with the same piece pays
  that piece once per step, plus once for the whole run);
* ``leading_power``, ``leading_size`` -- the system's own leading error term
  ``h^j Z_j`` of ``X_eff - X_{H,G}`` and ``max ||Z_j||`` on a box
  (:func:`~nambu_bch.design.leading_error`);
* the measured global error ``||x_N - x_ref(T)||_2`` at ``T = N h`` for several ``N``,
  against the evaluations ``N cost (+1)``, and the least-squares slope of
  ``log(error)`` against ``log(evaluations)`` over the points above round-off: ``-order``.

On a canonical ``T(p) + V(q)`` system with ``T`` a constant quadratic form, two-part rows also carry
``order_rkn`` and ``error_constant_rkn``: order and constant modulo the RKN relations (:mod:`.structure`), by which
RKN-optimised methods are designed and ranked.  Force-gradient compositions and processed kernels
(:mod:`nambu_bch.numeric.force_gradient`) have rows of their own (``family``, their cost counted as there).

Runge--Kutta and Kahan methods (a name of :data:`~nambu_bch.integrators.runge_kutta.TABLEAUX` or a
``ButcherTableau``; a partitioned pair of :data:`~nambu_bch.integrators.runge_kutta.PARTITIONED` on a canonical
system) are compared on the same runs: ``order`` is the tableau's, ``error_constant`` its principal error norm
``A^(p+1)`` (:func:`runge_kutta_error_constant`, exact in ``error_constant_exact``; not the LEM of a composition),
``leading_power`` / ``leading_size`` those of the first non-zero ``h^j Z_j`` of the modified field
(:func:`~nambu_bch.bseries.modified_equation`), and ``cost`` the *measured* field evaluations per step:
an explicit method pays its ``s`` stages; an implicit one pays ``s`` evaluations at the start of each step and
``s`` per Newton iteration, averaged over the runs (Jacobian evaluations and the linear solves are not counted);
Kahan's method, linearly implicit, pays one field and one Jacobian evaluation (counted 2) and one linear solve.

The reference ``x_ref(T)`` is the sixth-order Kahan-Li composition of the system's Strang
step (:mod:`nambu_bch.design.catalog`) with a step ``h_min / 8``; its error is checked
against the same run at ``h_min / 4`` and reported (``reference_error``).

References
----------
Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Sect. V.3.2 (work-precision
comparisons of composition methods, Fig. 3.3); Blanes & Casas, *A Concise Introduction to
Geometric Numerical Integration*, Sect. 3.7.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass, field

import numpy as np

from ..atomic import write_atomic
from ..checks import check_type, finite_float, is_int, show
from ..errors import InvalidCompositionError, InvalidRunError, NambuBCHError
from ..integrators.composition import Composition, composition as make_composition, composition_for
from ..integrators.runge_kutta import runge_kutta_method
from ..integrators.step import parameter_values
from ..numeric import iterate
from ..numeric.figures import MAX_DPI
from ..numeric.guards import check_count, initial_state
from ..numeric.iterate import as_system
from .conditions import error_analysis
from .system_error import MAX_SAMPLES, _box, leading_error

#: Errors below this are round-off and are not used in the slope fits.
FLOOR = 1e-11
#: Largest number of steps of one run.
MAX_STEPS = 10**7
#: Most integrators of one comparison (each costs its runs and an exact error analysis).
MAX_WORDS = 50


def cost(comp) -> tuple:
    """``(per_step, extra)``: sub-flow evaluations per step after merging equal neighbours, and the FSAL extra.

    >>> cost(make_composition("12321")), cost(make_composition("123"))
    ((4, 1), (3, 0))
    """
    check_type(comp, Composition, "comp")
    runs = [k for i, k in enumerate(comp.pieces) if i == 0 or comp.pieces[i - 1] != k]
    if len(runs) > 1 and runs[0] == runs[-1]:
        return len(runs) - 1, 1
    return len(runs), 0


def slope(x, y) -> float:
    """Least-squares slope of ``log y`` against ``log x`` (``nan`` with fewer than two points)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 2:
        return float("nan")
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


@dataclass
class Comparison:
    """The result of :func:`compare`: ``rows`` (one dict per word) and ``curves`` (word -> list of points)."""

    system: str
    t_end: float
    x0: tuple
    params: dict
    rows: list
    curves: dict
    reference: str
    reference_error: float
    meta: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"system": self.system, "t_end": self.t_end, "x0": list(self.x0), "params": self.params,
                "reference": self.reference, "reference_error": self.reference_error,
                "integrators": self.rows, "curves": self.curves}

    def to_json(self) -> str:
        """Strict JSON (non-finite numbers as strings, :func:`nambu_bch.render.to_json`)."""
        from ..render import to_json

        return to_json(self.to_dict())

    def table(self) -> str:
        """A plain-text table, one line per word."""
        head = f"{'integrator':<24} {'order':>5} {'cost':>5} {'LEM':>10} {'h^j':>4} {'|Z_j|max':>10} {'slope':>7} {'best error':>11}"
        lines = [f"{self.system}, T = {self.t_end:g}, x0 = {list(self.x0)}; reference {self.reference} (error ~{self.reference_error:.1e})", head]
        for r in self.rows:
            lem = "-" if r["error_constant"] is None else f"{r['error_constant']:.4g}"
            order = "-" if r["order"] is None else str(r["order"])
            power = "-" if r["leading_power"] is None else r["leading_power"]
            lines.append(f"{r['integrator']:<24} {order:>5} {r['cost']:>5} {lem:>10} {power:>4} "
                         f"{r['leading_size']:>10.3g} {r['slope']:>7.2f} {r['best_error']:>11.2e}")
        if any(r.get("error_constant_kind") == "A^(p+1)" for r in self.rows):
            lines.append("LEM of a Runge-Kutta method: its principal error norm A^(p+1) over the trees of order p+1 "
                         "(Kennedy-Carpenter-Lewis 2000), not comparable with a composition's LEM")
        return "\n".join(lines)

    def __str__(self):
        return self.table()

    def figure(self, path=None, dpi: int = 100):
        """The log-log work-precision plot (error vs sub-flow evaluations); written atomically to ``path`` if given."""
        if path is not None and not isinstance(path, (str, os.PathLike)):
            raise InvalidRunError(f"figure path must be a file name (str or path), got {show(path)}")
        dpi = check_count(dpi, "dpi", 1)
        if dpi > MAX_DPI:
            raise InvalidRunError(f"dpi must be between 1 and {MAX_DPI}, got {dpi}")
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        for r in self.rows:
            pts = self.curves[r["integrator"]]
            family = r.get("family")  # force-gradient and processed rows dashed, named by their family
            ax.loglog([p["evaluations"] for p in pts], [max(p["error"], 1e-17) for p in pts], "s--" if family else "o-",
                      label=f"{r['integrator']} (p={r['order']}, slope {r['slope']:.2f}"
                            + (f", {family})" if family else ")"))
        ax.set_xlabel("sub-flow evaluations")
        ax.set_ylabel(f"global error at T = {self.t_end:g}")
        ax.set_title(f"work-precision, {self.system}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        if path is not None:
            buffer = io.BytesIO()
            fmt = str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else "png"
            if fmt not in ("png", "pdf", "svg"):
                plt.close(fig)
                raise InvalidRunError(f"figure {path!r}: the file name must end in .png, .pdf or .svg")
            fig.savefig(buffer, format=fmt, dpi=dpi)
            plt.close(fig)
            write_atomic(path, buffer.getvalue())
            return path
        return fig


def _steps_list(steps):
    try:
        items = list(steps)
    except TypeError:
        items = None
    if items is None or isinstance(steps, (str, bytes)) or not all(is_int(s, numpy=True) for s in items):
        raise InvalidRunError(f"steps must be a list of positive integers, got {show(steps)}")
    out = sorted({int(s) for s in items})
    if len(out) < 2 or out[0] < 1 or out[-1] > MAX_STEPS:
        raise InvalidRunError(f"steps must hold at least two distinct integers in 1..{MAX_STEPS}, got {steps!r}")
    return out


def _words(words) -> list:
    """The integrators to compare as a non-empty list (a single word or Composition is a list of one)."""
    from ..integrators.composition import Composition

    from ..integrators.runge_kutta import ButcherTableau, PartitionedTableau

    from .generalized import GradientComposition

    methods = (str, Composition, ButcherTableau, PartitionedTableau, GradientComposition)
    if isinstance(words, methods):
        return [words]
    try:
        out = list(words)
    except TypeError:
        raise InvalidCompositionError(f"words must be a list of integrators such as ['121', 'forest-ruth'], "
                                      f"got {show(words)}") from None
    if not out:
        raise InvalidRunError("compare needs at least one integrator")
    if len(out) > MAX_WORDS:
        raise InvalidRunError(f"compare takes at most {MAX_WORDS} integrators, got {len(out)}")
    for w in out:
        if not isinstance(w, methods):
            raise InvalidCompositionError(f"each integrator must be a word, alias, Composition, Runge-Kutta method name, "
                                          f"ButcherTableau or PartitionedTableau, got {show(w)}")
    return out


def _final(system, comp, h, n, x0, params):
    """The state after ``n`` steps; complex for a complex map, whose error is the modulus of its difference to the
    (real) reference, the imaginary part included."""
    x = np.asarray(iterate(system, comp, h, n, x0, params=params, every=n, progress=False)[-1])
    return x if np.iscomplexobj(x) else x.astype(float)


def compare(system, words, t_end: float = 10.0, steps=(20, 40, 80, 160, 320, 640), x0=None, params=None,
            box=None, samples: int = 500) -> Comparison:
    """Compare integrators on ``system``: order, cost, error constants, measured error vs cost (module docstring).

    Parameters
    ----------
    system : System or model name
    words : sequence of words, aliases or Compositions (one word alone is taken as a list of one)
    t_end : float -- final time ``T``, ``0 < T < 1e6``
    steps : sequence of step counts ``N`` (``h = T/N``)
    x0 : initial state (default: the model's documented x0, :data:`nambu_bch.systems.catalog.DEFAULT_X0`)
    params : parameter values (default 1)
    box, samples : region and sample size of the leading-error size (default ``[-1, 1]^N``, 500 points)

    Examples
    --------
    >>> C = compare("ho", ["121", "forest-ruth"], t_end=2.0, steps=(10, 20, 40))
    >>> [r["order"] for r in C.rows], [round(r["slope"]) for r in C.rows]
    ([2, 4], [-2, -4])
    """
    system = as_system(system)
    n = len(system.splitting)
    words = _words(words)
    t_end = finite_float(t_end, "t_end")
    if not 0 < t_end < 1e6:
        raise InvalidRunError(f"t_end must be a positive number below 1e6, got {t_end!r}")
    steps = _steps_list(steps)
    x0, origin = initial_state(system, x0)
    try:
        items = list(np.asarray(x0, dtype=object)) if np.ndim(x0) == 1 else None
    except (TypeError, ValueError):  # ragged
        items = None
    if items is None or len(items) != system.N:
        raise InvalidRunError(f"x0 must be {system.N} real numbers (the coordinates "
                              f"{', '.join(str(c) for c in system.coordinates)} of {system.name}), got {show(x0)}")
    x0 = tuple(finite_float(v, "x0") for v in items)
    parameter_values(system, params)  # a dict of known names and finite values, before any run
    params = dict(params or {})
    _box(system, box)  # the leading-error arguments too, before the reference runs
    if not is_int(samples, 1, MAX_SAMPLES):
        raise InvalidRunError(f"samples must be an integer in 1..{MAX_SAMPLES:.0e}, got {show(samples)}")
    strang = "".join(str(k) for k in range(1, n + 1))
    strang = strang + strang[-2::-1] if n > 1 else "1"
    ref_name = f"kahan-li:{strang}" if n > 1 else strang
    ref = make_composition(ref_name, n)
    fine = max(8 * steps[-1], 64)
    if fine > MAX_STEPS:
        raise InvalidRunError(f"the reference run would need {fine} steps; use fewer steps (at most {MAX_STEPS // 8})")
    try:
        x_ref = _final(system, ref, t_end / fine, fine, x0, params)
        x_half = _final(system, ref, t_end / (fine // 2), fine // 2, x0, params)
    except NambuBCHError as exc:
        note = f"x0 = {list(x0)} is {origin.strip(' ()')}" if origin else "x0 as given"
        raise type(exc)(f"{exc} -- in the reference run of compare; {note}: choose an x0 whose orbit stays "
                        f"bounded up to t_end = {t_end:g}") from None
    ref_err = float(np.linalg.norm(x_ref - x_half)) / 63.0  # order 6: error(h) ~ (error(2h) - error(h)) / (2^6 - 1)
    rows, curves = [], {}
    rkn_system = _has_rkn_structure(system)
    for word in words:
        tableau = runge_kutta_method(word)
        if tableau is not None:
            label = word if isinstance(word, str) else tableau.name
            rows.append(_runge_kutta_row(system, tableau, label, t_end, steps, x0, params, x_ref, ref_err, box, samples))
            curves[label] = rows[-1].pop("points")
            continue
        if _is_gradient(word):
            rows.append(_gradient_row(system, word, t_end, steps, x0, params, x_ref, ref_err, box, samples))
            curves[rows[-1]["integrator"]] = rows[-1].pop("points")
            continue
        comp = composition_for(word, system.splitting)
        label = word if isinstance(word, str) else comp.name
        try:
            analysis = error_analysis(comp, n)
            order, lem = analysis.order, analysis.value
        except NambuBCHError:
            order, lem = None, None
        lead = leading_error(system, comp, box=box, samples=samples, params=params, hamiltonian=False)
        per_step, extra = cost(comp)
        rkn = _rkn_constant(system, comp) if rkn_system else {}
        pts = []
        for N in steps:
            h = t_end / N
            try:
                err = float(np.linalg.norm(_final(system, comp, h, N, x0, params) - x_ref))
            except NambuBCHError as exc:
                err = float("nan")
                pts.append({"steps": N, "h": h, "evaluations": N * per_step + extra, "error": err, "note": str(exc)})
                continue
            pts.append({"steps": N, "h": h, "evaluations": N * per_step + extra, "error": err})
        good = [p for p in pts if np.isfinite(p["error"]) and p["error"] > max(FLOOR, 100 * ref_err)]
        rows.append({
            "integrator": label, "name": comp.name, "order": order, "error_constant": lem,
            "cost": per_step, "fsal_extra": extra, "leading_power": lead.power, "leading_size": lead.size,
            "slope": slope([p["evaluations"] for p in good], [p["error"] for p in good]),
            "slope_points": len(good),
            "best_error": min((p["error"] for p in pts if np.isfinite(p["error"])), default=float("nan")),
            "citation": comp.citation, **rkn,
        })
        curves[label] = pts
    return Comparison(system.name, t_end, x0, params, rows, curves, ref_name, ref_err)


def _has_rkn_structure(system) -> bool:
    """Whether ``system`` is canonical ``T(p) + V(q)`` with ``T`` a constant quadratic form: there the RKN relations
    hold (:mod:`.structure`) and the rows carry ``error_constant_rkn`` too."""
    from ..errors import InvalidSystemError
    from .gradient_system import gradient_structure

    try:
        gradient_structure(system)
    except InvalidSystemError:
        return False
    return True


def _rkn_constant(system, comp) -> dict:
    """``{"order_rkn", "error_constant_rkn"}`` of a two-part composition on the RKN quotient (empty if it does not
    apply): the constants RKN-optimised methods (PEFRL, Blanes-Moan SRKN) are designed for."""
    try:
        analysis = error_analysis(comp, 2, structure="rkn")
    except NambuBCHError:
        return {}
    return {"order_rkn": analysis.order, "error_constant_rkn": analysis.value}


def _is_gradient(word) -> bool:
    from ..numeric.force_gradient import is_gradient_method

    return is_gradient_method(word)


def _gradient_row(system, word, t_end, steps, x0, params, x_ref, ref_err, box, samples) -> dict:
    """The row of a force-gradient composition or a processed kernel (:mod:`nambu_bch.numeric.force_gradient`).

    ``order`` and ``error_constant`` are the formal ones (:func:`~nambu_bch.design.generalized.gradient_analysis`), the
    effective order for a processed kernel (:func:`~nambu_bch.design.generalized.effective_order`); ``cost`` counts a
    force-gradient kick as :data:`~nambu_bch.numeric.force_gradient.GRADIENT_KICK_COST` evaluations and a processed run
    pays two processor applications of :data:`~nambu_bch.numeric.force_gradient.PROCESSOR_COST` each, once per run.
    ``leading_power`` is the first non-zero ``h^j Z_j`` of X_eff on the system (formal route), ``leading_size`` its
    largest norm on the default box.
    """
    from ..numeric.force_gradient import (PROCESSOR_COST, GradientStep, is_processed_kernel, iterate_gradient,
                                          iterate_processed)
    from .generalized import effective_order, gradient_analysis
    from .gradient_system import gradient_effective_field
    from .system_error import field_size

    step = GradientStep(system, word, params)  # refuses a system without the T(p) + V(q) structure, in one line
    label = word if isinstance(word, str) else str(step.composition)
    processed = is_processed_kernel(word)
    if processed:
        analysis = effective_order(word)
        order, lem = analysis.order, analysis.value
    else:
        analysis = gradient_analysis(word)
        order, lem = analysis.order, analysis.value
        rkn = gradient_analysis(word, structure="rkn")
    per_step, extra = step.cost()
    if processed:
        extra += 2 * PROCESSOR_COST
    try:
        X = gradient_effective_field(system, word, order=min(order + 1, 6))
        power = next((j for j in range(1, X.order + 1) if any(X[j])), None)
        size = float("nan") if power is None else field_size(X[power], system, box, samples, params, 0)
    except NambuBCHError:
        power, size = None, float("nan")
    run = iterate_processed if processed else iterate_gradient
    pts = []
    for N in steps:
        h = t_end / N
        try:
            final = np.asarray(run(system, word, h, N, x0, params, every=N)[-1], float)
            err = float(np.linalg.norm(final - x_ref))
        except NambuBCHError as exc:
            pts.append({"steps": N, "h": h, "evaluations": N * per_step + extra, "error": float("nan"), "note": str(exc)})
            continue
        pts.append({"steps": N, "h": h, "evaluations": N * per_step + extra, "error": err})
    good = [p for p in pts if np.isfinite(p["error"]) and p["error"] > max(FLOOR, 100 * ref_err)]
    return {
        "integrator": label, "name": str(step.composition), "order": order, "error_constant": lem,
        "cost": per_step, "fsal_extra": extra, "leading_power": power, "leading_size": size,
        "slope": slope([p["evaluations"] for p in good], [p["error"] for p in good]),
        "slope_points": len(good),
        "best_error": min((p["error"] for p in pts if np.isfinite(p["error"])), default=float("nan")),
        "citation": step.composition.citation, "family": "processed" if processed else "force-gradient",
        **({} if processed else {"order_rkn": rkn.order, "error_constant_rkn": rkn.value}),
        "points": pts,
    }


#: Most vertices of the trees searched for a non-vanishing error coefficient (the modified equation's limit, h^8;
#: for a partitioned pair the P-series' limit, :data:`nambu_bch.bseries.p_series.MAX_VERTICES`).
MAX_ERROR_TREES = 9


def runge_kutta_error_constant(method) -> tuple:
    """``(p, A)``: the order ``p`` at which the local error starts and its principal error norm ``A^(p+1)``, exact.

    ``A^(p+1) = ( sum_{|t| = p+1} tau(t)^2 )^(1/2)`` with ``tau(t) = (Phi(t) - 1/gamma(t)) / sigma(t)``, the
    coefficient of ``h^(p+1) F(t)`` in the local error (:func:`nambu_bch.bseries.rooted_trees.error_coefficients`),
    over the first tree order ``p + 1`` where some ``tau(t) != 0`` (decided exactly; ``p`` is the method's true
    order, at least the order its tableau states).  A partitioned pair sums over the bi-coloured trees
    (:func:`nambu_bch.bseries.p_series.error_coefficients`), a different, larger set: its value is not comparable
    with a plain tableau's.  Kahan's tableau is taken as a B-series on every field (on quadratic fields the trees
    with a vertex of three or more children do not contribute).

    Parameters
    ----------
    method : a name of :data:`~nambu_bch.integrators.runge_kutta.TABLEAUX` or
        :data:`~nambu_bch.integrators.runge_kutta.PARTITIONED`, a ButcherTableau or a PartitionedTableau

    References
    ----------
    C. A. Kennedy, M. H. Carpenter, R. M. Lewis, *Low-storage, explicit Runge--Kutta schemes for the compressible
    Navier--Stokes equations*, Appl. Numer. Math. 35 (2000) 177 (``A^(p+1)``, the 2-norm of the leading error
    coefficients); Hairer, Norsett, Wanner, *Solving ODEs I*, Sect. II.3 (the local error as a sum over trees).

    >>> runge_kutta_error_constant("rk4")      # Kennedy et al.'s A^(5) of the classical method (NodePy: the same)
    (4, sqrt(1745)/2880)
    """
    import sympy

    from ..bseries import p_series, rooted_trees
    from ..integrators.runge_kutta import PartitionedTableau, butcher_tableau

    tableau = runge_kutta_method(method) or butcher_tableau(method)  # the latter's message names what is accepted
    top = p_series.MAX_VERTICES if isinstance(tableau, PartitionedTableau) else MAX_ERROR_TREES
    for n in range(tableau.order + 1, top + 1):
        if isinstance(tableau, PartitionedTableau):
            tau = p_series.error_coefficients((tableau.q, tableau.p), n)
        else:
            tau = rooted_trees.error_coefficients(tableau, n)
        square = sympy.radsimp(sympy.expand(sum((v ** 2 for v in tau.values()), sympy.Integer(0))))
        if square != 0:
            return n - 1, sympy.sqrt(square)
    raise NambuBCHError(f"{tableau.name}: no non-vanishing error coefficient on the trees of at most {top} vertices "
                        "(the method agrees with the exact flow that far)")


def _runge_kutta_row(system, tableau, label, t_end, steps, x0, params, x_ref, ref_err, box, samples) -> dict:
    """The row of a Runge--Kutta method (module docstring): measured cost, error, and the modified field's leading term."""
    from ..bseries import modified_equation
    from ..bseries.modified import MAX_RK_ORDER
    from ..numeric.runge_kutta import is_linearly_implicit, iterate_runge_kutta
    from .system_error import field_size

    s = tableau.stages
    _, norm = runge_kutta_error_constant(tableau)
    top = min(tableau.order + 1, MAX_RK_ORDER)
    try:
        M = modified_equation(system, tableau, top)
    except NambuBCHError:  # no exact modified field (e.g. a non-polynomial field): the runs alone are compared
        M = None
    power = None if M is None else next((j for j in range(1, top + 1) if not M[j].is_zero()), None)
    size = float("nan") if power is None else field_size(M[power].to_sympy(), system, box, samples, params, 0)
    pts, per_steps = [], []
    for N in steps:
        h = t_end / N
        try:
            stats = {}
            final = iterate_runge_kutta(system, tableau, h, N, x0, params, every=N, stats=stats)[-1]
            err = float(np.linalg.norm(np.asarray(final, float) - x_ref))
        except NambuBCHError as exc:
            pts.append({"steps": N, "h": h, "evaluations": float("nan"), "error": float("nan"), "note": str(exc)})
            continue
        if is_linearly_implicit(tableau):
            per_step = 2.0
        elif tableau.is_explicit:
            per_step = float(s)
        else:
            per_step = s * (1.0 + stats["newton_iterations"] / max(N, 1))
        per_steps.append(per_step)
        pts.append({"steps": N, "h": h, "evaluations": N * per_step, "error": err})
    good = [p for p in pts if np.isfinite(p["error"]) and p["error"] > max(FLOOR, 100 * ref_err)]
    return {
        "integrator": label, "name": tableau.name, "order": tableau.order, "error_constant": float(norm),
        "error_constant_exact": str(norm), "error_constant_kind": "A^(p+1)",
        "cost": round(float(np.mean(per_steps)), 2) if per_steps else float("nan"), "fsal_extra": 0,
        "leading_power": power, "leading_size": size,
        "slope": slope([p["evaluations"] for p in good], [p["error"] for p in good]),
        "slope_points": len(good),
        "best_error": min((p["error"] for p in pts if np.isfinite(p["error"])), default=float("nan")),
        "citation": tableau.reference, "points": pts,
    }
