"""The printer hooks of every result (:class:`Printable`), in a module that imports nothing.

A result class defines ``to_latex()`` and ``to_text()``; the mixin turns them into sympy's printer hooks,
``str(result)`` and Jupyter's ``_repr_latex_``.  It lives apart from :mod:`nambu_bch.printing` (which imports
sympy to lay out series) so that a result that can be served without sympy,
:class:`~nambu_bch.bch.formal.FormalBCH` read from the BCH table, defines its class without importing it;
:mod:`nambu_bch.printing` re-exports it.
"""

from __future__ import annotations


class Printable:
    """Mixin: ``to_latex()`` (an ``aligned`` block) and ``to_text()`` give the printer hooks.

    ``sympy.latex(obj)`` -> ``obj.to_latex()``; ``sympy.sstr(obj)``, ``str(obj)`` and
    ``print(obj)`` -> ``obj.to_text()``; ``obj._repr_latex_()`` -> ``$$`` + block + ``$$``.
    """

    def _latex(self, printer=None):
        return self.to_latex()

    def _sympystr(self, printer=None):
        return self.to_text()

    def __str__(self):
        return self.to_text()

    def _repr_latex_(self):
        return "$$" + self.to_latex() + "$$"
