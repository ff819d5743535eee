"""The step, chosen from the model's fastest linearised mode: no --steps-per-period to tune.

A drivetrain's coupling and shaft modes can lie far above its mesh frequency. RK4 resolves a mode of rate
|lambda| (the modulus of an eigenvalue of the Jacobian) when h |lambda| is small (:data:`RK4_RESOLVED`: its
exponent is then within 1e-3 of the exact one) and is stable only up to h |lambda| = 2.78. So for an
``Integration(integrator="auto")`` (the default), when a model is compiled:

* rho, the largest |eigenvalue| of the Jacobian at the initial state and at the state at rest, at eight times over
  a forcing period (with the backlash closed where the state is in contact: the stiffest the model gets);
* RK4 with the steps asked (200 per forcing period) if they resolve rho; else RK4 with as many as resolve it
  (rounded up to a round number, so that a sweep's speeds share their code), if that is at most
  :data:`STIFF_COST` times as many: the cost of a stiff step in RK4 steps;
* else the stiff step (RODAS4, :mod:`.rosenbrock`) at the steps asked: stable whatever rho, resolving the modes
  up to its own :data:`~.rosenbrock.RESOLVED`; the faster ones are damped out, their exponents not resolved
  (the analyses report them as such, :mod:`gearsym.analysis.resolution`).

The choice and why are said in the result's ``choice`` (the commands print it). ``integrator="rk4"`` or
``"stiff"`` with ``steps_per_period`` is taken as given.
"""
from __future__ import annotations

import math
from dataclasses import replace


from ..options import Integration

#: h |lambda| up to which RK4 resolves a mode: the real part of ln R(h lambda)/h, the exponent the step gives a
#: linear mode, within 5e-4 of the mode's own for damping ratios from 0.02 to 1 (1.3e-3 at 0.01): its error
#: grows like (h|lambda|)^5 / zeta on a lightly damped mode (measured: 8e-3 at 0.5 for zeta = 0.02)
RK4_RESOLVED = 0.3
#: the same for the stiff RODAS4 (rosenbrock.py): within 4e-4 for every damping ratio at 0.6 (its stability
#: function is far closer to the exponential on the imaginary axis than RK4's)
STIFF_RESOLVED = 0.6
#: what one stiff step with its tangent map costs, in RK4 steps with theirs (measured on the two-stage box:
#: bench/stiff)
STIFF_COST = 4
#: the step counts RK4 is rounded up to (times powers of ten): a sweep's points share their code
_ROUND = (1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8)


def round_steps(steps: float) -> int:
    """The next round number of steps (200, 250, 300, 400, 500, 600, 800, 1000, ...) at or above ``steps``."""
    scale = 10 ** math.floor(math.log10(max(steps, 1)))
    return int(next(r * scale for r in (*_ROUND, 10) if r * scale >= steps - 1e-9))


def chosen(options: Integration, rho: float, cycle: float, unit: str = "") -> Integration:
    """``options`` with its integrator and steps chosen for a model whose fastest linearised mode has the rate
    ``rho`` (per unit time), its forcing period ``cycle``; ``unit`` names the time unit for the note."""
    if options.integrator != "auto":
        return options
    asked = options.steps_per_period
    z = rho * cycle / asked  # h rho at the steps asked
    mode = f"fastest linearised mode {rho:.4g}{unit}"
    if z <= RK4_RESOLVED:
        return replace(options, integrator="rk4", choice=f"RK4 ({mode}: h|lambda| = {z:.2g} at {asked} steps)")
    needed = round_steps(rho * cycle / RK4_RESOLVED)
    if needed <= STIFF_COST * asked:
        return replace(options, integrator="rk4", steps_per_period=needed,
                       choice=f"RK4 at {needed} steps per forcing period ({mode}: h|lambda| = "
                              f"{rho * cycle / needed:.2g}, resolved)")
    return replace(options, integrator="stiff",
                   choice=f"stiff RODAS4 at {asked} steps ({mode}: h|lambda| = {z:.3g}; RK4 would need "
                          f"{needed} steps per forcing period to resolve it)")


def choices_from(options: Integration, rho: float, cycle: float) -> list[Integration]:
    """Every choice :func:`chosen` makes for ``options`` at a rate of ``rho`` or more (a sweep's fastest point is
    at least as fast as the model's own values), the fewest steps first."""
    if options.integrator != "auto":
        return [options]
    first, asked = chosen(options, rho, cycle), options.steps_per_period
    if first.integrator == "stiff":
        return [first]
    steps, more = [first.steps_per_period], first.steps_per_period
    while (more := round_steps(more + 1)) <= STIFF_COST * asked:
        steps.append(more)
    return ([replace(options, integrator="rk4", steps_per_period=n) for n in steps]
            + [replace(options, integrator="stiff")])


def explicit(options: Integration, rho: float, cycle: float) -> Integration:
    """``options`` with RK4 at the steps that resolve ``rho`` (at least those asked): what a consumer with only the
    explicit step takes (an FMU's co-simulation step)."""
    if options.integrator == "rk4":
        return options
    steps = max(options.steps_per_period, round_steps(rho * cycle / RK4_RESOLVED))
    return replace(options, integrator="rk4", steps_per_period=steps,
                   choice=f"RK4 at {steps} steps per forcing period (fastest linearised mode {rho:.4g})")
