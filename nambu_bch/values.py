"""Value equality of results: a result equals its copy from ``pickle`` or from a worker process.

A result compares by the exact data that determine it, never by its printing: ring elements (which compare
as exact sparse polynomials), rationals, ints and strings as they are; sympy expressions through their
expanded form (a canonical sum of monomials for the polynomial and rational data results hold); numpy arrays
by dtype, shape and bytes.  A :class:`~nambu_bch.systems.System` compares by identity (it is a key of
per-system caches), so results compare the systems they hold by their defining data (:func:`system_key`).
"""

from __future__ import annotations

import math


class _NaN:
    """The one stand-in for a float ``nan`` in a key, so that two runs that both found ``nan`` agree."""

    def __repr__(self):
        return "nan"


NAN = _NaN()


def system_key(system) -> tuple:
    """The data that define ``system``: coordinates, Hamiltonians, parameters, name, split, bracket, texts.

    >>> from nambu_bch import model
    >>> system_key(model("ho")) == system_key(model("ho"))
    True
    """
    if system is None:
        return None
    return ("System", tuple(system.coordinates), tuple(freeze(H) for H in system.hamiltonians), tuple(system.parameters),
            system.name, system.split, system.bracket, system.description, system.citation, tuple(system.piece_labels))


def freeze(value):
    """A hashable, canonical key of ``value``: nested dicts, lists, tuples, sympy expressions, numpy data.

    Values that define their own value equality (ring elements, compositions, results) stay themselves;
    sympy expressions become their expanded forms; a float ``nan`` becomes :data:`NAN`.
    """
    import sympy

    from .systems.system import System

    if value is None or isinstance(value, (bool, int, str, bytes)):
        return value
    if isinstance(value, float):
        return NAN if math.isnan(value) else value
    if isinstance(value, System):
        return system_key(value)
    if isinstance(value, sympy.Basic):
        return sympy.expand(value) if isinstance(value, sympy.Expr) else value
    if isinstance(value, dict):
        items = [(freeze(k), freeze(v)) for k, v in value.items()]
        return ("dict", tuple(sorted(items, key=lambda kv: repr(kv[0]))))
    if isinstance(value, (list, tuple)):
        return tuple(freeze(v) for v in value)
    if isinstance(value, (set, frozenset)):
        return frozenset(freeze(v) for v in value)
    if type(value).__module__ == "numpy" or type(value).__module__.startswith("numpy."):
        import numpy as np

        if isinstance(value, np.ndarray):
            return ("ndarray", str(value.dtype), value.shape, value.tobytes())
        return freeze(value.item())
    if isinstance(value, ValueEquality):
        return value
    from .algebra.vector_field import VectorField

    if isinstance(value, VectorField):  # compares by its exact components; has no hash of its own
        return ("VectorField", value.algebra, tuple(freeze(c) for c in value.components))
    import dataclasses  # here: a result served without sympy (the BCH table) does not import it

    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (type(value).__qualname__,
                tuple(freeze(getattr(value, f.name)) for f in dataclasses.fields(value) if f.compare))
    return value


class ValueEquality:
    """Mixin: ``==`` and ``hash`` on :meth:`_value`, the exact data of a result (a tuple :func:`freeze` accepts).

    Results are immutable, so the key is computed once and kept (it is not part of the pickle).
    """

    #: attributes derived from the exact data on demand, left out of the pickle
    _TRANSIENT = ("_value_cache",)

    def _value(self) -> tuple:  # pragma: no cover - each result type defines its own
        raise NotImplementedError

    def _value_key(self):
        key = self.__dict__.get("_value_cache")
        if key is None:
            key = self.__dict__["_value_cache"] = freeze(self._value())
        return key

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self is other or self._value_key() == other._value_key()

    def __hash__(self):
        return hash((type(self).__qualname__, self._value_key()))

    def __getstate__(self):
        state = dict(self.__dict__)
        for name in self._TRANSIENT:
            state.pop(name, None)
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
