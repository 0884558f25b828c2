r"""The numerical shadow Hamiltonian of Skeel and Hardy: the modified Hamiltonian from a trajectory alone.

A symplectic splitting scheme ``Phi_h`` for a canonical Hamiltonian ``H(q, p)`` is, as a formal series, the
time-``h`` flow of a modified Hamiltonian ``H~ = H + h^2 H_2 + ...`` (odd powers too for a non-symmetric
word); the samples ``y_n = (q_n, p_n)`` lie on one solution ``y~(t)`` of its equations, ``y~(n h) = y_n``.
Skeel and Hardy (2001) estimate ``H~`` at the samples from the samples alone, without the series, to any
even order; this module computes that estimate.

The mathematics (derived here; the references state the construction, their equation numbers are not
cited because their text was not at hand when this was written):

1. **An identity for any Hamiltonian.**  Let ``E = q.d/dq + p.d/dp`` be the scaling (Euler) field.  Along a
   solution of ``q' = H_p``, ``p' = -H_q``::

       (1/2) (p . q' - q . p') = (1/2) (p . H_p + q . H_q) = (1/2) E(H),

   so with a scalar ``beta`` carried along by ``beta' = E(H) - 2 H``::

       H = (1/2) (p . q' - q . p' - beta').                                            (SH)

2. **beta is computed by the scheme itself** (the extended system of Skeel and Hardy).  Add the pair
   ``(lambda, beta)`` (conjugate) and the Hamiltonian ``Hbar(q, p, lambda) = lambda^{-2} H(lambda q,
   lambda p)``.  At ``lambda = 1`` its flow is that of ``H`` on ``(q, p)``, keeps ``lambda = 1``
   (``lambda' = -dHbar/dbeta = 0``), and moves ``beta' = dHbar/dlambda = E(H) - 2 H``.  Scaling
   ``y -> lambda y`` multiplies the canonical bracket by ``lambda^2``: ``{A_bar, B_bar} = lambda^{-2}
   {A, B}(lambda y)`` for ``A_bar = lambda^{-2} A(lambda y)`` (no function depends on ``beta``, so the
   ``(lambda, beta)`` part of the bracket vanishes).  Every term of the BCH series of a composition of the
   pieces ``Hbar_i`` is therefore the scaled term of the pieces ``H_i``, and the modified Hamiltonian of
   the extended scheme is ``lambda^{-2} H~(lambda y)``: the scheme applied to the extended system moves
   ``beta`` exactly as the flow of ``H~`` does, ``beta~' = E(H~) - 2 H~``.  Identity (SH) holds for ``H~``
   along ``y~``, with the ``beta_n`` of the extended scheme.
   For the canonical pieces of this package (each depends only on ``q`` or only on ``p`` and moves the
   other half) ``w_i = E(H_i) - 2 H_i`` is constant along the sub-flow ``exp(tau X_{H_i})``, so that
   sub-flow adds exactly ``tau w_i(y)``: one step adds ``beta_{n+1} - beta_n = sum_s c_s h w_{i_s}(y^{(s)})``
   over its stages ``y^{(s)}``.  For velocity Verlet (word ``212``: kick, drift, kick) with a kinetic
   energy quadratic in ``p`` (``E(T) = 2 T``, drifts add nothing) and ``w_V = q . V_q - 2 V = -q . F - 2 V``::

       beta_{n+1} - beta_n = (h/2) (w_V(q_n) + w_V(q_{n+1})).                           (beta)

3. **The derivatives at the samples** are the centred differences of order ``2k`` on ``2k + 1`` samples
   (Fornberg, Math. Comp. 51 (1988) 699, Table 1)::

       h y~'(n h) = sum_{j=1}^{k} a_j (y_{n+j} - y_{n-j}) + O(h^{2k+1}),
       a_j = (-1)^{j+1} (k!)^2 / (j (k-j)! (k+j)!)      (k = 2: a = 2/3, -1/12),

   and the estimate of order ``2k`` at sample ``n`` is (SH) with them::

       H~_{2k}(n) = 1/(2h) sum_j a_j [p_n . (q_{n+j} - q_{n-j}) - q_n . (p_{n+j} - p_{n-j})
                                       - (beta_{n+j} - beta_{n-j})]
                  = H~(y_n) + O(h^{2k}).

   The ``beta`` differences are summed from the step increments (no running sum, whose rounding would
   grow along a long run).  Values exist at the interior samples ``n = k, ..., n_samples - 1 - k``.

Two properties follow and are tested: along a run ``H~_{2k}`` fluctuates by ``O(h^{2k})`` (while ``H``
fluctuates by ``O(h^2)``); and for a quadratic ``H`` it is conserved exactly (to rounding) -- the samples are
``y_n = M^n y_0`` with ``M`` symplectic, the difference operator is a matrix ``B`` commuting with ``M``,
``beta`` is constant (``E(H) = 2 H``), and ``y^T J B y`` is invariant under ``M`` -- the "bonus" Skeel and
Hardy state for their construction.  ``H~_{2k}`` agrees with the package's symbolic shadow Hamiltonian
truncated after ``h^{2k-2}`` (:func:`~nambu_bch.shadow.shadow_hamiltonians`, order ``2k - 2``) up to
``O(h^{2k})``.

Engle, Skeel and Drees (2005) write the same kind of estimate as combinations of antisymmetric products
``A_ij`` of differences of ``q``, ``p`` and ``beta``; this module uses the centred form above (its
coefficients are those of the standard centred derivative, not copied from their tables).

Only the canonical bracket has (SH): for a Nambu splitting see docs/trajectories_and_sweeps.md.

References
----------
R. D. Skeel, D. J. Hardy, *Practical construction of modified Hamiltonians*, SIAM J. Sci. Comput. 23 (2001)
1172-1188.
R. D. Engle, R. D. Skeel, M. Drees, *Monitoring energy drift with shadow Hamiltonians*, J. Comput. Phys. 206
(2005) 432-452.
B. Fornberg, *Generation of finite difference formulas on arbitrarily spaced grids*, Math. Comp. 51 (1988) 699.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from ..checks import finite_float, show
from ..errors import InvalidOrderError, InvalidRunError, InvalidSystemError, NumericalRangeError
from .diagnostics import _json_float, drift_rate
from .guards import finite_array

#: Orders ``2k`` of the estimate (``2k + 1`` samples per value).
ORDERS = (2, 4, 6, 8)
#: Largest ``|Phi_h(y_n) - y_{n+1}|``, relative to ``max(1, max |y|)``, accepted as one step of the scheme.
STEP_RTOL = 1e-8


def stencil(k: int) -> tuple:
    """The exact weights ``a_1..a_k`` of the centred first derivative of order ``2k``.

    ``h f'(0) = sum_j a_j (f(j h) - f(-j h)) + O(h^{2k+1})`` with ``a_j = (-1)^{j+1} (k!)^2 / (j (k-j)! (k+j)!)``
    (Fornberg, Math. Comp. 51 (1988) 699, Table 1).

    >>> [str(a) for a in stencil(2)]
    ['2/3', '-1/12']
    """
    f = math.factorial
    return tuple(Fraction((-1) ** (j + 1) * f(k) ** 2, j * f(k - j) * f(k + j)) for j in range(1, k + 1))


@dataclass
class NumericalShadow:
    """The numerical shadow Hamiltonian ``H~_{2k}`` at the interior samples of one trajectory.

    Attributes
    ----------
    model, integrator : str -- the system (``"arrays"`` when forces were given) and the scheme
    h : float; order : int -- ``2k``
    indices : numpy.ndarray -- the sample indices ``k .. n_samples - 1 - k`` of the values
    t : numpy.ndarray -- their times ``|h| * indices``
    values : numpy.ndarray -- ``H~_{2k}`` at those samples
    H : numpy.ndarray or None -- ``H`` at the same samples (when the system is known)
    max_abs_error : dict -- ``max_n |Q_n - Q_k|`` of ``H~`` (and of ``H``), from the first value, sample ``k``
    drift : dict -- ``{name: DriftFit}``, the straight line through ``(t, Q_n - Q_k)``
    """

    model: str
    integrator: str
    h: float
    order: int
    indices: np.ndarray
    t: np.ndarray
    values: np.ndarray
    H: np.ndarray | None = None
    max_abs_error: dict = field(default_factory=dict)
    drift: dict = field(default_factory=dict)

    def to_dict(self, values: bool = False) -> dict:
        """JSON-ready summary (``values=True`` adds ``indices``, ``t``, ``values`` and ``H``)."""
        out = {
            "model": self.model, "integrator": self.integrator, "h": float(self.h), "order": int(self.order),
            "first_index": int(self.indices[0]), "last_index": int(self.indices[-1]), "n_values": int(self.indices.size),
            "max_abs_error": {k: _json_float(v) for k, v in self.max_abs_error.items()},
            "drift_rate": {k: _json_float(fit.rate) for k, fit in self.drift.items()},
            "drift": {k: {key: _json_float(v) for key, v in fit.to_dict().items()} for k, fit in self.drift.items()},
        }
        if values:
            out["indices"] = [int(i) for i in self.indices]
            out["t"] = [float(v) for v in self.t]
            out["values"] = [float(v) for v in self.values]
            if self.H is not None:
                out["H"] = [float(v) for v in self.H]
        return out

    def __str__(self):
        lines = [f"{self.model} {self.integrator}: numerical shadow Hamiltonian of order {self.order} (Skeel-Hardy), "
                 f"h = {self.h}, samples {int(self.indices[0])}..{int(self.indices[-1])}"]
        first = int(self.indices[0])
        lines += [f"  max |{k}_n - {k}_{first}| = {v:.3e}, drift rate {self.drift[k].rate:.3e} "
                  f"+- {self.drift[k].stderr:.1e}" for k, v in self.max_abs_error.items()]
        return "\n".join(lines)


def numerical_shadow(q, p, forces_or_system, h, *, order=4, word="212", potential=None, params=None,
                     check_steps=True) -> NumericalShadow:
    r"""``H~_{2k}``, the numerical shadow Hamiltonian of Skeel and Hardy, along a trajectory; and its drift.

    See the module docstring for the mathematics: ``H~_{2k}(n) = 1/(2h) sum_j a_j [p_n . (q_{n+j} - q_{n-j})
    - q_n . (p_{n+j} - p_{n-j}) - (beta_{n+j} - beta_{n-j})]``, ``beta`` the work variable of the
    extended system, ``a_j`` the centred-difference weights (:func:`stencil`).

    Parameters
    ----------
    q, p : arrays of shape ``(n_samples, d)`` (or ``(n_samples,)`` for ``d = 1``) -- positions and momenta
        after every step of the scheme (from :func:`~nambu_bch.numeric.iterate`, columns ``:d`` and ``d:``, or
        from any other code), at least ``2k + 3`` samples
    forces_or_system : a canonical System or model name, or an array of forces ``F = -dV/dq`` of the shape of
        ``q``.  With a system, ``beta`` is computed by replaying each step's stages of ``word`` (any word of
        its pieces); with forces, the scheme is velocity Verlet (``word`` ``212``), the kinetic energy
        quadratic in ``p``, and ``potential`` is required
    h : float -- the step (non-zero)
    order : int -- ``2k``, one of 2, 4, 6, 8
    word : str or Composition -- the scheme that made the trajectory (default ``212``, velocity Verlet)
    potential : array of shape ``(n_samples,)`` -- ``V(q_n)``, with forces only
    params : dict, optional -- parameter values of the system (missing ones are 1)
    check_steps : bool -- verify that each sample is one step of the scheme from the one before (with a
        system: the replayed step; with forces: ``p_{n+1} = p_n + h (F_n + F_{n+1}) / 2``), to
        ``STEP_RTOL`` relative to ``max(1, max |y|)``

    Returns
    -------
    NumericalShadow -- values at the samples ``k .. n_samples - 1 - k``, ``max_abs_error`` and ``drift``
    (:func:`~nambu_bch.numeric.drift_rate`) of ``H~`` and, with a system, of ``H``

    Raises
    ------
    InvalidSystemError -- a system that is not canonical (a Nambu pair has no identity (SH))
    InvalidOrderError -- ``order`` not in 2, 4, 6, 8
    InvalidRunError -- arrays of the wrong shapes, too few samples, a word other than velocity Verlet with
        forces, samples that are not consecutive steps of the scheme
    NumericalRangeError -- non-finite inputs or values

    Examples
    --------
    >>> from nambu_bch.numeric import iterate
    >>> x = iterate("henon-heiles", "212", 0.1, 400, [0.1, -0.2, 0.3, 0.25])
    >>> r = numerical_shadow(x[:, :2], x[:, 2:], "henon-heiles", 0.1, order=4)
    >>> int(r.indices[0]), bool(r.max_abs_error["H~"] < 1e-2 * r.max_abs_error["H"])
    (2, True)
    """
    h = finite_float(h, "h")
    if h == 0:
        raise InvalidRunError("h must be non-zero: the numerical shadow Hamiltonian divides by the step")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or int(order) not in ORDERS:
        raise InvalidOrderError(f"order must be one of {', '.join(map(str, ORDERS))} (the 2k of H~_2k), got {show(order)}")
    order = int(order)
    k = order // 2
    Q, P = _phase_arrays(q, p, 2 * k + 3)
    check_steps = _flag(check_steps, "check_steps")
    from ..systems.spec import SystemSpec
    from ..systems.system import System

    if isinstance(forces_or_system, (str, System, SystemSpec)):
        if potential is not None:
            raise InvalidRunError("potential is read only with an array of forces; with a system V comes from H")
        model, name, H, dbeta = _from_system(forces_or_system, word, Q, P, h, params, check_steps)
    else:
        if params is not None:
            raise InvalidRunError("params is read only with a system; with arrays of forces nothing is parametrised")
        model, name, H, dbeta = "arrays", *_from_forces(forces_or_system, potential, word, Q, P, h, check_steps)
    values = _centred(Q, P, dbeta, h, k)
    idx = np.arange(k, Q.shape[0] - k)
    t = abs(h) * idx.astype(np.float64)
    series = {"H~": values, **({"H": H[idx]} if H is not None else {})}
    bad = [n for n, v in series.items() if not np.all(np.isfinite(v))]
    if bad or not math.isfinite(t[-1]):
        raise NumericalRangeError(f"{', '.join(bad) or 't'} not finite along the trajectory (float64 overflow at "
                                  f"h = {h:g}); rescale the states")
    result = NumericalShadow(model, name, h, order, idx, t, values, series.get("H"))
    for n, v in series.items():
        result.max_abs_error[n] = float(np.max(np.abs(v - v[0])))
        result.drift[n] = drift_rate(t, v)
    return result


def _flag(value, what) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidRunError(f"{what} must be True or False, got {show(value)}")
    return bool(value)


def _phase_arrays(q, p, minimum):
    """``q``, ``p`` as float64 arrays ``(n, d)`` of equal shape with ``n >= minimum``, else one line."""
    Q, P = finite_array(q, "q"), finite_array(p, "p")
    Q, P = (Q[:, None] if Q.ndim == 1 else Q), (P[:, None] if P.ndim == 1 else P)
    if Q.ndim != 2 or Q.shape != P.shape or Q.shape[1] == 0:
        raise InvalidRunError(f"q and p must be arrays of the same shape (n_samples, d), one state per row, "
                              f"got shapes {np.shape(q)} and {np.shape(p)}")
    if Q.shape[0] < minimum:
        raise InvalidRunError(f"this order needs at least {minimum} samples (2k + 1 per value, 3 values for the drift "
                              f"fit), got {Q.shape[0]}")
    return Q, P


def _centred(Q, P, dbeta, h, k) -> np.ndarray:
    """``H~_{2k}`` at the samples ``k .. n - 1 - k`` from the centred differences of ``q``, ``p`` and ``beta``."""
    n = Q.shape[0]
    m = n - 2 * k
    Qn, Pn = Q[k:k + m], P[k:k + m]
    acc = np.zeros(m)
    window = np.zeros(m)
    with np.errstate(all="ignore"):
        for j, a in enumerate(stencil(k), start=1):
            # beta_{n+j} - beta_{n-j}: the 2j step increments in between, grown by one on each side
            window = window + dbeta[k - j:k - j + m] + dbeta[k + j - 1:k + j - 1 + m]
            dq = Q[k + j:k + j + m] - Q[k - j:k - j + m]
            dp = P[k + j:k + j + m] - P[k - j:k - j + m]
            acc += float(a) * (np.einsum("ij,ij->i", Pn, dq) - np.einsum("ij,ij->i", Qn, dp) - window)
        return acc / (2.0 * h)


def _from_forces(forces, potential, word, Q, P, h, check_steps):
    """``(name, None, beta increments)`` of velocity Verlet from forces and potential energies (Eq. (beta))."""
    from ..integrators.composition import composition

    comp = composition(word, 2)
    if comp.pieces != (2, 1, 2) or [str(c) for c in comp.coefficients] != ["1/2", "1", "1/2"]:
        raise InvalidRunError(f"with arrays of forces the scheme must be velocity Verlet (word 212: kick, drift, kick), "
                              f"got {show(word)}; for another word pass the system")
    F = finite_array(forces, "forces")
    F = F[:, None] if F.ndim == 1 else F
    if F.shape != Q.shape:
        raise InvalidRunError(f"forces must have the shape of q, {Q.shape}, got {np.shape(forces)}")
    if potential is None:
        raise InvalidRunError("potential (V(q_n), one per sample) is required with arrays of forces: beta needs "
                              "q . F + 2 V")
    U = finite_array(potential, "potential")
    if U.shape != (Q.shape[0],):
        raise InvalidRunError(f"potential must be an array of shape ({Q.shape[0]},), one V(q_n) per sample, "
                              f"got shape {U.shape}")
    if check_steps:
        _check_steps(P[1:], P[:-1] + (h / 2) * (F[:-1] + F[1:]), P,
                     "velocity Verlet (p_{n+1} = p_n + h (F_n + F_{n+1})/2)")
    w = -np.einsum("ij,ij->i", Q, F) - 2.0 * U
    return "212", None, (h / 2) * (w[:-1] + w[1:])


def _from_system(system, word, Q, P, h, params, check_steps):
    """``(model, word, H along the samples, beta increments)``, replaying each step's stages of ``word``."""
    import sympy

    from ..integrators.composition import composition_for
    from ..integrators.step import parameter_values, subflow_functions
    from .diagnostics import numpy_function
    from .iterate import as_system

    system = as_system(system)
    if system.bracket != "canonical":
        raise InvalidSystemError(
            f"the numerical shadow Hamiltonian needs a canonical system (q, p halves); {system.name} has the "
            f"{system.bracket} bracket, and the Skeel-Hardy identity H = (p.q' - q.p' - beta')/2 uses the symplectic "
            "form; for a Nambu pair evaluate the symbolic H_S, G_S along the trajectory with shadow_along")
    d = system.N // 2
    if Q.shape[1] != d:
        raise InvalidRunError(f"q and p must have d = {d} columns for {system.name}, got {Q.shape[1]}")
    splitting = system.splitting
    comp = composition_for(word, splitting)
    name = word if isinstance(word, str) else str(comp)
    values = parameter_values(system, params)
    coords = system.coordinates
    pieces_h = []
    for piece in splitting.pieces:
        Hk = sympy.Add(*(sympy.sympify(term[0], strict=True) for term in piece.terms))
        # (beta) needs w_k constant along piece k's flow: true when H_k does not involve what the piece moves
        if any(Hk.has(coords[i]) for i in piece.moving):
            raise InvalidSystemError(f"piece {piece.number} of {system.name} moves a coordinate its Hamiltonian depends "
                                     "on; the work variable beta needs kicks and drifts")
        pieces_h.append(Hk)
    rest = sympy.expand(system.H - sympy.Add(*pieces_h))  # the constant the splitting leaves out
    if rest.free_symbols & set(coords):  # canonical_split keeps every non-constant term: a guard, not a branch
        raise InvalidSystemError(f"the pieces of {system.name} do not add up to H")
    # a constant c in H is a piece with no flow whose work is E(c) - 2c = -2c per unit time
    constant_work = -2.0 * h * float(rest.subs(values))
    w = [sympy.expand(sum(x * sympy.diff(Hk, x) for x in coords) - 2 * Hk).subs(values) for Hk in pieces_h]
    w_fn = [numpy_function(e, coords) for e in w]
    H_fn = numpy_function(sympy.sympify(system.H, strict=True).subs(values), coords)
    Y = np.hstack([Q, P])
    flows = subflow_functions(splitting, comp, params)
    state = Y[:-1]
    dbeta = np.zeros(Y.shape[0] - 1)
    with np.errstate(all="ignore"):
        for (f, c), piece in zip(flows, comp.pieces):
            dbeta += (c * h) * w_fn[piece - 1](state)
            cols = [state[:, i] for i in range(system.N)]
            state = np.column_stack([np.asarray(v, dtype=np.float64) + 0.0 * cols[0] for v in f(*cols, c * h)])
        if check_steps:
            _check_steps(Y[1:], state, Y, f"{name} at h = {h:g}")
        H = H_fn(Y)
    return system.name, name, H, dbeta + constant_work


def _check_steps(got, want, Y, what):
    """Refuse samples that are not consecutive steps of the scheme (another word, h, or every > 1)."""
    with np.errstate(all="ignore"):
        diff = np.max(np.abs(got - want), axis=1)
    scale = max(1.0, float(np.max(np.abs(Y))))
    bad = np.flatnonzero(~(diff <= STEP_RTOL * scale))
    if bad.size:
        n = int(bad[0])
        raise InvalidRunError(f"sample {n + 1} is not one step of {what} from sample {n} (difference {diff[n]:.1e}); "
                              "the numerical shadow Hamiltonian needs every step of the scheme that made the "
                              "trajectory (the same word and h, every = 1)")
