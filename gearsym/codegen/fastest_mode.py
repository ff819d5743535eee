"""The fastest linearised mode of a system: what the step is chosen from (:mod:`.step_choice`)."""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..options import Integration
from ..system import FirstOrderSystem
from .casadi_symbols import SystemSymbols
from .step_choice import chosen


def fastest_rate(system: FirstOrderSystem, values=None) -> float:
    """rho: the largest |eigenvalue| of the Jacobian per unit of the system's time, over a forcing period, at the
    initial state and at rest (zero state)."""
    symbols = SystemSymbols.of(system)
    jacobian = ca.Function("J", [symbols.t, symbols.y, symbols.p], [ca.densify(ca.jacobian(symbols.rhs(system),
                                                                                          symbols.y))])
    merged = system.parameter_values(values)
    p = [merged[name] for name in system.parameters]
    cycle = system.cycle_at(values)
    rho = 0.0
    for y in (system.initial_vector, [0.0] * system.dimension):
        for k in range(8):
            J = np.array(jacobian(cycle * k / 8, y, p), dtype=float)
            if np.all(np.isfinite(J)):
                rho = max(rho, float(np.max(np.abs(np.linalg.eigvals(J)))))
    return rho


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
    own = system.parameters.get("omega")
    rates = [(fastest_rate(system), own)] + [(fastest_rate(system, values), values.get("omega", own))
                                             for values in points]
    rho, omega = max(rates, key=lambda r: r[0])
    # (a rate per unit time is per unit of tau: where omega differs from the model's, the note says at which, so
    # that its frequency is converted there)
    where = f" at omega={omega!r}" if omega is not None and omega != own else ""
    return chosen(options, rho, system.cycle_at(), where)
