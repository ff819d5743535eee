"""Basin maps of a model with physical values, in its units: a grid in µm and mm/s, the speed in rpm.

A grid given in physical units is turned into the engine's nondimensional starts at each forcing frequency (a
rate's unit, L omega omega_n per second, moves with the speed); the results come back through the same
numbers (:class:`~gearsym.physical.point.PointUnits`: the length unit L, omega_n, the speed's ratio), so that
the tables, the JSON, the text and the figures say µm, mm/s and rpm.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..checks import json_safe
from ..errors import GearsymError
from ..figures.basins import Shown
from ..figures.poincare import parameter_text
from ..sweep.grid import Axis
from ..units import dimension_text, to_si, unit_dims
from .point import ANGLE, ANGULAR_VELOCITY, LENGTH, VELOCITY, PointUnits


def units_of(scaling) -> PointUnits:
    """The numbers that carry results of ``scaling`` (a full scaling, or the start-up cache's) to its units."""
    return scaling.units if hasattr(scaling, "units") and isinstance(scaling.units, PointUnits) \
        else scaling.point_units()


class PhysicalShown(Shown):
    """States in the length unit and mm/s, omega as the speed (in its unit), other parameters as they are."""

    def __init__(self, units: PointUnits):
        self.units = units

    def state(self, name: str, values, omega: float | None = None) -> tuple[np.ndarray, str]:
        if name not in self.units.kinds:
            return np.asarray(values, dtype=float), ""
        if self.units.kinds[name] != "length" and omega is None:
            raise GearsymError(f"{self.units.name}: {name} is a rate; its unit needs the forcing frequency")
        m = self.units.state(name, values, 1.0 if omega is None else omega)
        return np.asarray(m.magnitude, dtype=float), m.units.text

    def speed(self, omega) -> np.ndarray:
        """The operating speed (in its unit) at the engine's forcing frequency ``omega``."""
        u = self.units
        return np.asarray(omega, dtype=float) * u.omega_n / u.forcing_ratio * u.rad_s_to_speed

    def parameter(self, name: str, values) -> tuple[str, np.ndarray, str]:
        if name == "omega" and self.units.speed is not None:
            return self.units.speed.parameter, self.speed(values), self.units.speed_unit.text
        return name, np.asarray(values, dtype=float), ""

    def parameters(self, values: dict) -> str:
        parts = []
        for k, v in values.items():
            if k == "omega" and self.units.speed is not None:
                parts.append(f"{self.units.speed.parameter}={float(self.speed(v)):.6g} {self.units.speed_unit.text} "
                             f"(ω={v:.6g})")
            else:
                parts.append(parameter_text(k, v))
        return ", ".join(parts)


#: the dimension (exponents of mass, length, time) of each kind of state, and a grid of it in its unit
_DIMENSIONS = {LENGTH: ((0.0, 1.0, 0.0), "-20um:20um:1um"), VELOCITY: ((0.0, 1.0, -1.0), "-500mm/s:500mm/s:25mm/s"),
               ANGLE: ((0.0, 0.0, 0.0), "-0.01rad:0.01rad:0.001rad"),
               ANGULAR_VELOCITY: ((0.0, 0.0, -1.0), "-10rad/s:10rad/s:1rad/s")}


def check_grid_units(units: PointUnits, axes: Sequence[Axis]) -> None:
    """Every grid axis of a state with a physical kind has a unit of that kind's dimension (a length, a rate)."""
    for axis in axes:
        kind = units.kinds.get(axis.name)
        if kind is None:  # a state without a physical kind: the model's own numbers
            continue
        expected, grid = _DIMENSIONS[kind]
        example = f"{axis.name}={grid}"
        if not axis.unit:
            raise GearsymError(f"--grid {axis.spec!r}: {axis.name} is a {kind} of {units.name}, which has physical "
                               f"values: give the grid with its unit, e.g. {example}")
        got = unit_dims(axis.unit)
        if got != expected:
            raise GearsymError(f"--grid {axis.spec!r}: {axis.name} is a {kind} of {units.name} "
                               f"({dimension_text(expected)}), but {axis.unit} is {dimension_text(got)}; give it in "
                               f"a unit of a {kind}, e.g. {example}")


def engine_grid(units: PointUnits, axes: Sequence[Axis], omega: float) -> dict[str, np.ndarray]:
    """The engine's values of grid ``axes`` given in physical units, at the forcing frequency ``omega``."""
    check_grid_units(units, axes)
    grid = {}
    for axis in axes:
        kind = units.kinds.get(axis.name)
        if kind is None:  # a state without a physical kind: the model's own numbers
            grid[axis.name] = np.asarray(axis.values, dtype=float)
            continue
        per_engine_unit = float(units.state(axis.name, 1.0, omega, si=True))
        grid[axis.name] = to_si(np.asarray(axis.values, dtype=float), axis.unit) / per_engine_unit
    return grid


def physical_dict(result, shown: PhysicalShown, axes: Sequence[Axis]) -> dict:
    """A basin map's JSON in the model's units: the grid as given, amplitudes, points and the start in the
    length unit and mm/s, the speed beside omega."""
    data = result.as_dict(labels=True)
    omega = result.parameters.get("omega")

    def measured(name, values):
        v, unit = shown.state(name, values, omega)
        return {"value": json_safe(float(v) if np.ndim(v) == 0 else v), "unit": unit}

    data["grid"] = {**{a.name: {"values": list(a.values), "unit": a.unit} for a in axes},
                    "held": {k: measured(k, v) for k, v in result.held.items()}, "starts": result.starts}
    for a, out in zip(result.attractors, data["attractors"]):
        out["amplitude"] = {k: measured(k, v) for k, v in a.amplitude.items()}
        out["points"] = {n: measured(n, row) for n, row in zip(result.state_names, a.points)}
        out["representative"] = {k: measured(k, v) for k, v in a.representative.items()}
        out["exponents_per_second"] = json_safe(np.asarray(a.exponents) * omega * shown.units.omega_n)
    if shown.units.speed is not None and omega is not None:
        data["speed"] = {"value": float(shown.speed(omega)), "unit": shown.units.speed_unit.text}
    return data
