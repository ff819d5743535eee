"""Stability charts from Floquet theory: the parametric instability of a model's static state (or of its periodic
orbit) over a grid of two parameters, many points at once in the lanes, with the boundaries located and drawn.

:mod:`.linearised` (the model linearised about its static state, a system of its own; SymPy) -> :mod:`.recipe`
(what a chart runs on, as data) -> :mod:`.static_states` (the static state of every point) -> :mod:`.monodromies`
(one monodromy matrix per lane) -> :mod:`.kinds` (stable, fold, period doubling, Neimark-Sacker) ->
:mod:`.boundaries` (bisection on the grid lines, curves) -> :mod:`.chart` (:func:`static_chart`,
:func:`orbit_chart`) -> :mod:`.verb` (:func:`stability_chart`); :mod:`.orbits` (period-1 orbits of many points
by Newton) and :mod:`.phasing` (which tongues a planetary set's mesh phasing suppresses). See docs/stability.md.

Imported on first use (like :mod:`gearsym.sweep`'s runs): a chart of a cached model needs neither SymPy nor the
code generator, which :mod:`.linearised` and :mod:`.verb` load.
"""
from __future__ import annotations

import importlib

#: the names imported on first use, and their modules
_LAZY = {"ABOUT": "chart", "StabilityChart": "chart", "static_chart": "chart", "orbit_chart": "chart",
         "CompiledLinearisation": "recipe", "StaticRecipe": "recipe",
         "FOLD": "kinds", "KINDS": "kinds", "NEIMARK_SACKER": "kinds", "NO_ORBIT": "kinds",
         "NO_STATIC_STATE": "kinds", "PERIOD_DOUBLING": "kinds",
         "Linearised": "linearised", "compile_linearisation": "linearised", "linearise": "linearised",
         "static_recipe": "linearised", "stability_chart": "verb",
         "PhasingPrediction": "phasing", "phasing_prediction": "phasing"}

__all__ = sorted(_LAZY)


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
