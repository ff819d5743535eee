"""Periodic orbits of forced models, their Floquet stability, and their branches over a parameter.

:mod:`.shooting` (the period-n map with its exact Jacobian, Newton, multiple shooting) ->
:mod:`.floquet` (multipliers, test functions, contact regimes) -> :mod:`.orbit` (one orbit:
:func:`periodic_orbit`) and :mod:`.continuation` (pseudo-arclength, located bifurcations) ->
:mod:`.branches` (:func:`continue_orbits`, branch switching) -> :mod:`.files` (CSV and JSON).
See docs/orbits.md for the method.
"""
from .branches import Bifurcation, Branch, Continuation, ContinuationInterrupted, continue_orbits
from .floquet import CONTACT_REGIMES, FOLD, GRAZING, NEIMARK_SACKER, PERIOD_DOUBLING
from .orbit import PeriodicOrbit, periodic_orbit
from .shooting import Shooting

__all__ = ["Bifurcation", "Branch", "CONTACT_REGIMES", "Continuation", "ContinuationInterrupted", "FOLD", "GRAZING", "NEIMARK_SACKER",
           "PERIOD_DOUBLING", "PeriodicOrbit", "Shooting", "continue_orbits", "periodic_orbit"]
