"""The built-in models, by the names the CLI and :func:`model` share (DESIGN.md)."""

from __future__ import annotations

from ..errors import UnknownModelError
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
        # with t -> -t.  DESIGN.md fixes this order; reversing time maps h -> -h and changes no
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


_MODELS = {
    "ho": _ho,
    "ho3": _ho3,
    "rigid-body": _rigid_body,
    "lotka-volterra": _lotka_volterra,
    "ho3-composite": _ho3_composite,
}
_CACHE: dict = {}


def model_names() -> tuple:
    return tuple(_MODELS)


def model(name: str) -> System:
    """A built-in system by name: ``ho``, ``ho3``, ``rigid-body``, ``lotka-volterra``, ``ho3-composite``.

    Examples
    --------
    >>> model("ho3").hamiltonians
    (m*omega**2*x3/2 + x2**2/(2*m), -x1**2 + x3)
    """
    if not isinstance(name, str) or name not in _MODELS:
        raise UnknownModelError(f"unknown model {name!r}; built-in models are {', '.join(_MODELS)}")
    if name not in _CACHE:
        _CACHE[name] = _MODELS[name]()
    return _CACHE[name]
