"""The backlash switching surfaces of a system, in its own terms: what the located loops split their steps at.

The loops find the surfaces in the split right-hand side (:func:`.switching.find_switching`: every g(x, eta) gives
s = x and s = -(x + eta)), written in the loop's symbols (tables of time and constants). An exporter that
evaluates them elsewhere (the event indicators of an FMU, :mod:`gearsym.fmu`) needs them as expressions of the
system's time, states and parameters: here they are, the tables and constants put back, in the loops' order.
"""
from __future__ import annotations

import sympy as sp

from ..system import FirstOrderSystem
from .switching import find_switching
from .time_tables import split_rhs


def switching_surfaces(system: FirstOrderSystem) -> tuple[sp.Expr, ...]:
    """Every surface s (the side s >= 0 is the indicator of its branch) the located loops of ``system`` split
    their steps at, as expressions of its time, states and parameters. A model whose right-hand side switches
    on the state otherwise than through the backlash raises the loops' ModelError."""
    split = split_rhs(system, factored=True)
    back = dict(split.tables) | dict(split.constants)
    return tuple(s.xreplace(back) for s in find_switching(system, split).surfaces)
