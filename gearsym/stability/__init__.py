"""Stability charts from Floquet theory: the parametric instability of a model's static state (or of its periodic
orbit) over a grid of two parameters, many points at once in the lanes, with the boundaries located and drawn.

:mod:`.linearised` (the model linearised about its static state, a system of its own) -> :mod:`.static_states`
(the static state of every point) -> :mod:`.monodromies` (one monodromy matrix per lane) -> :mod:`.kinds`
(stable, fold, period doubling, Neimark-Sacker) -> :mod:`.boundaries` (bisection on the grid lines, curves) ->
:mod:`.chart` (:func:`stability_chart`); :mod:`.orbits` (period-1 orbits of many points by Newton) and
:mod:`.phasing` (which tongues a planetary set's mesh phasing suppresses). See docs/stability.md.
"""
from .chart import (ABOUT, CompiledLinearisation, StabilityChart, compile_linearisation, orbit_chart, stability_chart,
                    static_chart)
from .kinds import FOLD, KINDS, NEIMARK_SACKER, NO_ORBIT, NO_STATIC_STATE, PERIOD_DOUBLING
from .linearised import Linearised, StaticRecipe, linearise

__all__ = ["ABOUT", "CompiledLinearisation", "FOLD", "KINDS", "Linearised", "NEIMARK_SACKER", "NO_ORBIT",
           "NO_STATIC_STATE", "PERIOD_DOUBLING", "StabilityChart", "StaticRecipe", "compile_linearisation",
           "linearise", "orbit_chart", "stability_chart", "static_chart"]
