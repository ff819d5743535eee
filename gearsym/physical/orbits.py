"""Branches of periodic orbits carried to physical units: along the speed instead of omega, amplitudes and
states in the units of :class:`~.point.PointUnits` (a mesh's deflection in um, a shaft's twist in rad)."""
from __future__ import annotations

import re
from dataclasses import replace

import numpy as np

from ..periodic.branches import Continuation
from ..scales.map import Scaling
from .point import LENGTH_UNIT
from .results import point_units, speeds_of

#: "omega=0.924099" in the text of why a branch ended
_OMEGA = re.compile(r"\bomega=([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def continuation_to_physical(scaling: Scaling, result: Continuation, length_unit: str = LENGTH_UNIT) -> Continuation:
    """``result`` with its amplitudes, extremes and states at the section in physical units and, for a
    continuation along omega, the speed as its parameter; ``units`` says which (the parameter of a continuation
    along another value keeps the engine's numbers), ``settings["physical"]`` the scaling."""
    units = point_units(scaling, length_unit)
    along_speed = result.parameter == "omega" and bool(scaling.speed)
    parameter = scaling.speed.parameter if along_speed else result.parameter

    def omegas(values):
        values = np.asarray(values, dtype=float)
        return values if result.parameter == "omega" else np.full_like(values, result.parameters["omega"])

    def axis(values):
        return speeds_of(units, values) if along_speed else np.asarray(values, dtype=float)

    def states(matrix, w):
        return np.column_stack([units.state(n, matrix[:, j], w).magnitude for j, n in enumerate(result.state_names)])

    def observed(matrix):
        return np.column_stack([units.state(c, matrix[:, j], 1.0).magnitude for j, c in enumerate(result.observed)])

    def ended(text: str) -> str:
        if not along_speed:
            return text
        return _OMEGA.sub(lambda m: f"{parameter}={speeds_of(units, float(m[1]))[0]:.6g} {units.speed_unit}", text)

    branches = tuple(replace(br, values=axis(br.values), states=states(br.states, omegas(br.values)),
                             low=observed(br.low), high=observed(br.high), end=ended(br.end))
                     for br in result.branches)
    bifurcations = tuple(replace(b, value=float(axis([b.value])[0]),
                                 state=states(np.atleast_2d(b.state), omegas([b.value]))[0])
                         for b in result.bifurcations)
    shown = {c: units.unit(c).text for c in result.observed}
    table = {**({parameter: units.speed_unit.text} if along_speed else {}),
             **{f"{what}_{c}": shown[c] for c in result.observed for what in ("A", "min", "max")},
             **{f"state_{n}": units.unit(n).text for n in result.state_names}}
    start, stop = axis([result.start, result.stop])
    return replace(result, parameter=parameter, start=float(start), stop=float(stop), branches=branches,
                   bifurcations=bifurcations, units=table,
                   settings={**result.settings, "physical": scaling.summary()})
