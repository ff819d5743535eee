"""The backlash switching surfaces of a model, derived from the equations the engine integrates.

A low-level system with g(x, eta) written by hand is located too: the surfaces come from the expressions, not
from the declaration.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.backlash import G, g, g_slope
from ..errors import ModelError
from ..system import FirstOrderSystem
from .time_tables import SplitRHS


@dataclass(frozen=True)
class Switching:
    """The switching surfaces of a model's backlash, in the loop's symbols (states, tables, constants).

    Every application g(x, eta) (likewise g_slope, G) has two surfaces, s = x and s = -(x + eta), oriented
    so that the side [s >= 0] is the indicator of its branch: x >= 0 (one flank in contact) and x <= -eta
    (the other). ``rhs`` is ``split.rhs`` with each indicator replaced by a symbol of ``sides``: with the
    sides held fixed it is the smooth extension of one branch across its surfaces.
    """

    surfaces: tuple[sp.Expr, ...]
    sides: tuple[sp.Dummy, ...]
    rhs: tuple[sp.Expr, ...]


_OTHER_SWITCHES = (sp.Piecewise, sp.Heaviside, sp.Min, sp.Max, sp.Abs, sp.sign, sp.floor, sp.ceiling)


def _flank_of_backlash(e: sp.Expr):
    """The g(x, eta) of ``e`` if ``e`` is min(g, 0) (the coast flank: x + eta for x <= -eta) or max(g, 0)
    (the drive flank: x for x >= 0), else None."""
    if isinstance(e, (sp.Min, sp.Max)) and len(e.args) == 2 and sp.S.Zero in e.args:
        inner = next(a for a in e.args if a != 0)
        if isinstance(inner, g):
            return inner
    return None


def find_switching(system: FirstOrderSystem, split: SplitRHS) -> Switching:
    """The backlash switching surfaces of ``split.rhs``, derived from the expressions, in a fixed order
    (SymPy's canonical argument order) so that the same model always gives the same C."""
    states = set(system.states)
    surfaces: list[sp.Expr] = []
    sides: list[sp.Dummy] = []

    def side(s: sp.Expr) -> sp.Dummy:
        if s not in surfaces:
            surfaces.append(s)
            sides.append(sp.Dummy(f"side_{len(sides)}", real=True))
        return sides[surfaces.index(s)]

    def freeze(e: sp.Expr) -> sp.Expr:
        if isinstance(e, (g, g_slope, G)):
            x, eta = e.args
            if any(isinstance(a, (g, g_slope, G)) for arg in e.args for a in sp.preorder_traversal(arg)):
                raise ModelError(f"locate_crossings: nested backlash in {e} is not supported", system.name)
            on, off = side(x), side(-(x + eta))
            if isinstance(e, g):  # on x + off (x + eta), with one product on the path from x (~10 % per try)
                return (on + off) * x + off * eta
            if isinstance(e, g_slope):
                return on + off
            return on * x**2 / 2 + off * (x + eta) ** 2 / 2
        flank = _flank_of_backlash(e)
        if flank is not None:  # min(g, 0) or max(g, 0): one flank of g, switching on g's own surfaces
            x, eta = flank.args
            return side(x) * x if isinstance(e, sp.Max) else side(-(x + eta)) * (x + eta)
        if isinstance(e, _OTHER_SWITCHES) and e.free_symbols & states:
            raise ModelError(
                f"locating crossings handles the backlash g(x, eta) (and min/max(g, 0)) only; {e} switches on the "
                "state too and its crossings would not be located: use the paper's plain scheme "
                "(Integration.paper(), --plain)", system.name)
        if not e.args or isinstance(e, sp.Symbol):
            return e
        return e.func(*(freeze(a) for a in e.args))

    rhs = tuple(freeze(f) for f in split.rhs)
    return Switching(tuple(surfaces), tuple(sides), rhs)
