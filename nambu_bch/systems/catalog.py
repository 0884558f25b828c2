"""The built-in models, by the names the CLI and :func:`model` share (symbols: docs/conventions.md; list: docs/systems.md)."""

from __future__ import annotations

from ..checks import show
from ..errors import UnknownModelError, did_you_mean
from .system import System

_PAPER = "Horikoshi, Shadow Hamiltonians of structure-preserving integrators for Nambu mechanics"


def _ho():
    return System(
        "x1 x2", ["x2**2/(2*m) + m*omega**2*x1**2/2"], "m omega", name="ho",
        description="harmonic oscillator, (x1, x2) = (q, p); pieces 1 = T, 2 = V",
        citation=f"{_PAPER}, Eq. (HO1)",
    )


def _ho3():
    return System(
        "x1 x2 x3", ["x2**2/(2*m) + m*omega**2*x3/2", "x3 - x1**2"], "m omega", name="ho3",
        description="N = 3 oscillator (q, p, q^2); pieces 1, 2, 3 = X_{A,C}, X_{B,D}, X_{A,D}",
        citation=f"{_PAPER}, Eqs. (Ex1), (H), (G), (AB), (CD)",
    )


def _rigid_body():
    return System(
        "x1 x2 x3", ["x1**2/(2*I1) + x2**2/(2*I2) + x3**2/(2*I3)", "x1**2/2 + x2**2/2 + x3**2/2"],
        "I1 I2 I3", name="rigid-body",
        # With H (energy) before G (|L|^2/2), {f, H, G} gives dL/dt = omega x L: Euler's equations
        # with t -> -t.  This order is part of the model's definition; reversing time maps h -> -h and changes no
        # existence result, so the model keeps it and says so.
        description="free rigid body (Euler equations with t -> -t for this order of H, G), full split; piece i moves x_i",
        citation="Nambu (1973); Modin (2010)",
    )


def _lotka_volterra():
    return System(
        "x1 x2 x3", ["x1 + x2 + x3", "x1*x2*x3"], (), name="lotka-volterra", split="single",
        description="cyclic Lotka-Volterra; only H is split, piece i = X_{x_i, G}",
        citation=f"Frachebourg, Krapivsky, Ben-Naim (1996); {_PAPER}, Sect. 6",
    )


def _ho3_composite():
    return System(
        "x1 x2 x3", ["x2/(2*m) + m*omega**2*x1/2", "2*x3**2 - 2*x1*x2"], "m omega", name="ho3-composite",
        split="single",
        description="oscillator in (q^2, p^2, qp); only H is split",
        citation=f"Horikoshi (2013); {_PAPER}, Sect. 6",
    )


_HLW = "Hairer, Lubich, Wanner, Geometric Numerical Integration (2nd ed.)"


def _pendulum():
    return System(
        "x1 x2", ["x2**2/2 - cos(x1)"], (), name="pendulum",
        description="mathematical pendulum, canonical (x1, x2) = (q, p); pieces 1 = T, 2 = V (121 = position Verlet)",
        citation=f"{_HLW}, Sect. I.1.4",
    )


def _henon_heiles():
    return System(
        "q1 q2 p1 p2", ["p1**2/2 + p2**2/2 + q1**2/2 + q2**2/2 + q1**2*q2 - q2**3/3"], (), name="henon-heiles",
        description="Henon-Heiles, canonical d = 2 (q1, q2, p1, p2); pieces 1 = T, 2 = V",
        citation=f"Henon, Heiles (1964); {_HLW}, Sect. I.3",
    )


def _fpu_beta():
    q = ["0", "q1", "q2", "q3", "0"]
    springs = [f"({q[i + 1]} - {q[i]})" for i in range(4)]
    V = " + ".join(f"{s}**2/2 + beta*{s}**4/4" for s in springs)
    return System(
        "q1 q2 q3 p1 p2 p3", [f"p1**2/2 + p2**2/2 + p3**2/2 + {V}"], "beta", name="fpu-beta",
        description="FPU-beta chain, 3 moving particles, fixed ends, canonical d = 3; pieces 1 = T, 2 = V",
        citation="Fermi, Pasta, Ulam (1955); Gallavotti (ed.), The Fermi-Pasta-Ulam Problem (2008)",
    )


def _toda():
    return System(
        "q1 q2 q3 p1 p2 p3", ["p1**2/2 + p2**2/2 + p3**2/2 + exp(q1 - q2) + exp(q2 - q3) + exp(q3 - q1)"], (), name="toda",
        description="periodic Toda lattice, 3 particles, canonical d = 3, exponential potential; pieces 1 = T, 2 = V",
        citation="Toda (1967); Henon (1974); Flaschka (1974)",
    )


def _exp_well():
    return System(
        "x1 x2", ["x2**2/2 + exp(x1) - x1"], (), name="exp-well",
        description="1-DOF Toda-type exponential well V = e^q - q, canonical (q, p); pieces 1 = T, 2 = V",
        citation="Toda (1967), the two-particle reduction",
    )


def _rational():
    return System(
        "x1 x2", ["x2**2/2 - 1/(1 + x1**2)"], (), name="rational",
        description="rational (Lorentzian) well V = -1/(1 + q^2), canonical (q, p); pieces 1 = T, 2 = V",
        citation=f"{_HLW}, Sect. IX.3 (any smooth separable H)",
    )


def _kepler():
    return System(
        "q1 q2 p1 p2", ["(p1**2 + p2**2)/2 - mu/sqrt(q1**2 + q2**2)"], "mu", name="kepler",
        description="Kepler problem (central force -mu/|q|) in the plane, canonical d = 2 (q1, q2, p1, p2); "
                    "pieces 1 = T, 2 = V (212 = velocity Verlet)",
        citation=f"{_HLW}, Sect. I.2",
    )


def _kepler_3d():
    return System(
        "q1 q2 q3 p1 p2 p3", ["(p1**2 + p2**2 + p3**2)/2 - mu/sqrt(q1**2 + q2**2 + q3**2)"], "mu", name="kepler-3d",
        description="Kepler problem (central force -mu/|q|) in space, canonical d = 3; pieces 1 = T, 2 = V",
        citation=f"{_HLW}, Sect. I.2",
    )


def _morse():
    return System(
        "x1 x2", ["x2**2/2 + (1 - exp(-x1))**2"], (), name="morse",
        description="Morse oscillator V = (1 - e^(-q))^2 (well depth 1, unit width and mass), canonical (q, p); "
                    "pieces 1 = T, 2 = V",
        citation="Morse, Phys. Rev. 34 (1929) 57",
    )


def _lennard_jones():
    return System(
        "x1 x2", ["x2**2/2 + 4/x1**12 - 4/x1**6"], (), name="lennard-jones",
        description="Lennard-Jones dimer in its relative coordinate r = x1 > 0 (epsilon = sigma = 1, reduced mass 1), "
                    "canonical (r, p); pieces 1 = T, 2 = V",
        citation="Lennard-Jones, Proc. R. Soc. A 106 (1924) 463",
    )


def _rigid_body_lp():
    return System(
        "x1 x2 x3", ["x1**2/(2*I1) + x2**2/(2*I2) + x3**2/(2*I3)"], "I1 I2 I3", name="rigid-body-lp",
        bracket="lie-poisson",
        description="free rigid body as a Lie-Poisson system (G = |x|^2/2 the Casimir); only H is split, "
                    "piece i = X_{x_i^2/(2 I_i), G} is a rotation about axis i",
        citation="McLachlan (1993) Phys. Rev. Lett. 71, 3043; Touma, Wisdom (1994); Modin (2010)",
    )


def _ho3_pair():
    return System(
        "x1 x2 x3 x4 x5 x6", ["x2**2/2 + x3/2 + x5**2/2 + x6/2 + kappa*x1*x4", "x3 - x1**2 + x6 - x4**2"], "kappa",
        name="ho3-pair",
        description="two (q, p, q^2) oscillators on Nambu's canonical triplets, coupled by kappa q1 q2; "
                    "pieces are shears (each term of H paired with each term of G, merged)",
        citation=f"Nambu (1973), Sect. III; {_PAPER}, Sect. 6",
    )


_MODELS = {
    "ho": _ho,
    "ho3": _ho3,
    "rigid-body": _rigid_body,
    "lotka-volterra": _lotka_volterra,
    "ho3-composite": _ho3_composite,
    "pendulum": _pendulum,
    "henon-heiles": _henon_heiles,
    "fpu-beta": _fpu_beta,
    "toda": _toda,
    "exp-well": _exp_well,
    "rational": _rational,
    "kepler": _kepler,
    "kepler-3d": _kepler_3d,
    "morse": _morse,
    "lennard-jones": _lennard_jones,
    "rigid-body-lp": _rigid_body_lp,
    "ho3-pair": _ho3_pair,
}
_CACHE: dict = {}

#: The documented initial state of each model: what ``check``, ``compare``, ``iterate``, ``plot`` (and the CLI)
#: use when ``x0`` is omitted.  ``(1, ..., 1)`` where that is a bounded, non-trivial orbit (the paper's
#: ``x(0) = (1, 1, 1)`` for ho3).  Henon-Heiles at (1, 1, 1, 1) has energy 8/3, far above the escape energy
#: 1/6, and leaves to infinity, so its default is an orbit of energy 0.13 inside the bounded well.  Toda at
#: (1, ..., 1) drifts with total momentum 3 until the step's exponentials overflow float64 (q near 700); its
#: default has total momentum 0.  Kepler (mu = 1) starts on an ellipse of energy -0.28 (eccentricity 0.44; in
#: space -0.235, inclined); Morse at energy 0.2 below the dissociation energy 1; the Lennard-Jones dimer at
#: energy -0.85 near the minimum r = 2^(1/6) of the well of depth 1.
DEFAULT_X0 = {
    "ho": (1.0, 1.0),
    "ho3": (1.0, 1.0, 1.0),
    "rigid-body": (1.0, 1.0, 1.0),
    "lotka-volterra": (1.0, 1.0, 1.0),
    "ho3-composite": (1.0, 1.0, 1.0),
    "pendulum": (1.0, 1.0),
    "henon-heiles": (0.0, 0.1, 0.5, 0.0),
    "fpu-beta": (1.0, 1.0, 1.0, 1.0, 1.0, 1.0),
    "toda": (1.0, 0.0, -1.0, 0.5, 0.0, -0.5),
    "exp-well": (1.0, 1.0),
    "rational": (1.0, 1.0),
    "kepler": (1.0, 0.0, 0.0, 1.2),
    "kepler-3d": (1.0, 0.0, 0.0, 0.0, 1.2, 0.3),
    "morse": (0.5, 0.3),
    "lennard-jones": (1.2, 0.3),
    "rigid-body-lp": (1.0, 1.0, 1.0),
    "ho3-pair": (1.0, 1.0, 1.0, 1.0, 1.0, 1.0),
}


def default_x0(system) -> tuple:
    """``(x0, where)``: the initial state used when none is given, and where it comes from.

    A built-in model (the same coordinates and Hamiltonians as :func:`model` of its name) has its
    documented :data:`DEFAULT_X0`, ``where = "the default x0 of <name>"``; any other system starts
    at ``(1, ..., 1)``, ``where = "the default x0 (1, ..., 1)"``.  ``where`` goes into the messages
    of a run that fails from it, so a default that escapes is named as the default.
    """
    name = getattr(system, "name", None)
    if name in _MODELS:
        builtin = model(name)
        if builtin is system or (builtin.coordinates == system.coordinates
                                 and builtin.hamiltonians == system.hamiltonians):
            return DEFAULT_X0[name], f"the default x0 of {name}"
    return (1.0,) * system.N, "the default x0 (1, ..., 1)"


def model_names() -> tuple:
    return tuple(_MODELS)


def model(name: str) -> System:
    """A built-in system by name (:func:`model_names`): the paper's ``ho``, ``ho3``, ``rigid-body``,
    ``lotka-volterra``, ``ho3-composite``; canonical ``pendulum``, ``henon-heiles``, ``fpu-beta``,
    ``toda``, ``exp-well``, ``rational``, ``kepler``, ``kepler-3d``, ``morse``, ``lennard-jones``; Lie-Poisson ``rigid-body-lp``; canonical triplets ``ho3-pair``.

    Examples
    --------
    >>> model("ho3").hamiltonians
    (m*omega**2*x3/2 + x2**2/(2*m), -x1**2 + x3)
    """
    if not isinstance(name, str) or name not in _MODELS:
        raise UnknownModelError(
            f"unknown model {show(name)}{did_you_mean(name, _MODELS)}; built-in models are {', '.join(_MODELS)}"
        )
    if name not in _CACHE:
        _CACHE[name] = _MODELS[name]()
    return _CACHE[name]
