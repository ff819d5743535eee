"""The fastest linearised mode of a system: what the step is chosen from (:mod:`.step_choice`)."""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..options import Integration
from ..system import FirstOrderSystem
from .casadi_symbols import SystemSymbols
from .mode_rates import fastest_of, largest_rate
from .step_choice import chosen


def fastest_rate(system: FirstOrderSystem, values=None) -> float:
    """rho: the largest |eigenvalue| of the Jacobian per unit of the system's time, over a forcing period, at the
    initial state and at rest (zero state)."""
    symbols = SystemSymbols.of(system)
    jacobian = ca.Function("J", [symbols.t, symbols.y, symbols.p], [ca.densify(ca.jacobian(symbols.rhs(system),
                                                                                          symbols.y))])
    merged = system.parameter_values(values)
    p = [merged[name] for name in system.parameters]
    return largest_rate(lambda t, y: np.array(jacobian(t, y, p), dtype=float), system, system.cycle_at(values))


def chosen_for(options: Integration, system: FirstOrderSystem) -> Integration:
    """``options`` with the integrator and steps chosen for ``system`` at its values (:func:`.step_choice.chosen`)."""
    if options.integrator != "auto":
        return options
    return chosen(options, fastest_rate(system), system.cycle_at())


def chosen_integration(options: Integration, system: FirstOrderSystem, points=()) -> Integration:
    """``options`` with the integrator and steps chosen for ``system`` at its values and at each of ``points``
    (mappings of parameter values: the ends of a sweep's axes), the fastest of them deciding: one library runs
    every point at a step that resolves its fastest mode."""
    if options.integrator != "auto":
        return options
    rates = [fastest_rate(system)] + [fastest_rate(system, values) for values in points]
    return fastest_of(options, rates, system, system.cycle_at(), points)
