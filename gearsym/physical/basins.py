"""Basin maps and basin fractions as they are shown: in a model's units when it has physical values (a grid in
µm and mm/s, the speed in rpm), else in its own numbers.

A grid given in physical units is read into SI units once, when it is parsed (:class:`GridAxis`), checked against
the model's states once (:class:`GivenGrid`), and turned into the engine's nondimensional starts at each forcing
frequency (a rate's unit, L omega omega_n per second, moves with the speed: :func:`engine_grid`); the results come
back through the same numbers (:class:`~gearsym.physical.point.PointUnits`: the length unit L, omega_n, the speed's
ratio). :class:`ShownBasinMap` and :class:`ShownFractions` are the results in those units, which say themselves
as text and as a record (``text``, ``as_dict``: the command's output), and which the files (:mod:`.files`) and
the figures (:mod:`gearsym.figures.basins`) take.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..analysis.basins import BasinMap, StartGrid
from ..checks import json_safe
from ..errors import GearsymError
from ..sweep.basin_continuation import BasinContinuation
from ..sweep.grid import Axis, parse_axis
from ..units import dimension_text
from .point import ANGLE, ANGULAR_VELOCITY, LENGTH, VELOCITY, PointUnits
from .sweeps import MeasuredAxis
from .text import parameter_text


class OwnNumbers:
    """How a model without physical values shows its values: its own numbers, no unit."""

    def state(self, name: str, values, omega: float | None = None) -> tuple[np.ndarray, str]:
        """A state's values as shown, and their unit ('' for the model's own)."""
        return np.asarray(values, dtype=float), ""

    def parameter(self, name: str, values) -> tuple[str, np.ndarray, str]:
        """A parameter's values as shown: (name, values, unit)."""
        return name, np.asarray(values, dtype=float), ""

    def parameters(self, values: dict) -> str:
        """The parameter values of a run, as a title shows them."""
        return ", ".join(parameter_text(k, v) for k, v in values.items())

    def run_parameters(self, values: dict) -> str:
        """The parameter values of one run, as its title shows them."""
        return self.parameters(values)

    def exponent(self, value: float, omega: float | None) -> str:
        """An exponent (per unit of the model's time) as shown."""
        return f"{value:+.4f}"


class PhysicalUnits(OwnNumbers):
    """States in the length unit and mm/s, omega as the speed (in its unit); of the other parameters (the engine's
    groups, numbers nobody gave) a title shows only the values the user gave (``given``: --set's, as given), the
    rest being the model's declared physical values (every engine number is in the files)."""

    def __init__(self, units: PointUnits, given: dict | None = None):
        self.units = units
        self.given = {k: v for k, v in (given or {}).items() if k != "teeth"}

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

    def run_parameters(self, values: dict) -> str:
        """The speed and the values the user gave, in their units (not the engine's groups, which nobody gave:
        the files hold them)."""
        speed = self.units.speed.parameter if self.units.speed is not None else None
        parts = [self.parameters({"omega": values["omega"]})] if "omega" in values and speed else []
        parts += [f"{k}={v}" for k, v in self.given.items() if k != speed]
        return ", ".join(parts + ["the rest as the model declares them"])

    def exponent(self, value: float, omega: float | None) -> str:
        """An exponent (per unit tau at ``omega``) as shown: per second."""
        if omega is None:
            return super().exponent(value, omega)
        return f"{value * omega * self.units.omega_n:+.4g} {self.units.per_second}"


#: the dimension (exponents of mass, length, time) of each kind of state, and a grid of it in its unit
_DIMENSIONS = {LENGTH: ((0.0, 1.0, 0.0), "-20um:20um:1um"), VELOCITY: ((0.0, 1.0, -1.0), "-500mm/s:500mm/s:25mm/s"),
               ANGLE: ((0.0, 0.0, 0.0), "-0.01rad:0.01rad:0.001rad"),
               ANGULAR_VELOCITY: ((0.0, 0.0, -1.0), "-10rad/s:10rad/s:1rad/s")}


@dataclass(frozen=True)
class GridAxis(MeasuredAxis):
    """One ``--grid`` axis as given, its unit read once when it is parsed (:meth:`read`), as any axis with a unit
    is (:class:`~gearsym.physical.sweeps.MeasuredAxis`): its values in SI units and the unit's dimension
    (exponents of mass, length and time), or why the unit is no drivetrain's (``refused``: a model with physical
    values says it, one without says that it takes no unit)."""

    @classmethod
    def read(cls, text: str) -> "GridAxis":
        """``STATE=START:STOP:STEP`` (or a list, or one value), with or without a unit (its errors name --grid)."""
        axis = parse_axis(text, "--grid")
        return cls.of(axis, f"--grid {axis.spec!r}")

    @property
    def si_values(self) -> tuple[float, ...]:
        """The values in SI units (none without a unit, or with one refused)."""
        return tuple(m.si for m in self.measures)

    @property
    def dims(self) -> tuple[float, float, float] | None:
        """The unit's dimension (None without a unit, or with one refused)."""
        return self.measures[0].dims if self.measures else None


def grid_in_si(units: PointUnits, axes: Sequence[GridAxis]) -> dict[str, np.ndarray]:
    """The values of grid ``axes`` in SI units (an axis of a state without a physical kind: the model's own
    numbers), each axis of a state with a physical kind checked to have a unit of that kind's dimension (a
    length, a rate)."""
    grid = {}
    for axis in axes:
        values = np.asarray(axis.values, dtype=float)
        kind = units.kinds.get(axis.name)
        if kind is None:  # a state without a physical kind: the model's own numbers
            grid[axis.name] = values
            continue
        expected, example = _DIMENSIONS[kind]
        example = f"{axis.name}={example}"
        if not axis.unit:
            raise GearsymError(f"--grid {axis.spec!r}: {axis.name} is a {kind} of {units.name}, which has physical "
                               f"values: give the grid with its unit, e.g. {example}")
        if axis.dims is None:
            raise GearsymError(axis.refused)
        if axis.dims != expected:
            raise GearsymError(f"--grid {axis.spec!r}: {axis.name} is a {kind} of {units.name} "
                               f"({dimension_text(expected)}), but {axis.unit} is {dimension_text(axis.dims)}; give it "
                               f"in a unit of a {kind}, e.g. {example}")
        grid[axis.name] = np.asarray(axis.si_values, dtype=float)
    return grid


def shown_in(units: PointUnits | None, given: dict | None = None) -> OwnNumbers:
    """How results are shown for a model with these ``units`` (None: a model without physical values), the values
    the user gave being ``given``."""
    return OwnNumbers() if units is None else PhysicalUnits(units, given)


@dataclass(frozen=True)
class ShownBasinMap:
    """A :class:`~gearsym.analysis.basins.BasinMap` with the units it is shown in, and its grid as given."""

    result: BasinMap
    units: OwnNumbers = OwnNumbers()
    axes: tuple[Axis, ...] = ()  # the grid as the caller gave it (with its units), if it was given so

    @classmethod
    def of(cls, result: "BasinMap | ShownBasinMap") -> "ShownBasinMap":
        return result if isinstance(result, cls) else cls(result)

    @property
    def omega(self) -> float | None:
        return self.result.parameters.get("omega")

    def state(self, name: str, values) -> tuple[np.ndarray, str]:
        """A state's values (at the map's forcing frequency) as shown, and their unit."""
        return self.units.state(name, values, self.omega)

    def number(self, name: str, value: float) -> tuple[float, str]:
        """One value of a state as shown, and its unit."""
        values, unit = self.state(name, [value])
        return float(values[0]), unit

    def parameters_text(self) -> str:
        return self.units.run_parameters(self.result.parameters)

    def exponent(self, value: float) -> str:
        """An exponent of the map's run as shown (per second for a model with physical values)."""
        return self.units.exponent(value, self.omega)

    def as_dict(self) -> dict:
        """The map's record: in the model's units when it has physical values (the grid as given, amplitudes,
        points and the start in the length unit and mm/s, the speed beside omega), else the engine's."""
        result, units = self.result, self.units
        if not isinstance(units, PhysicalUnits):
            return result.as_dict()
        data = result.as_dict(labels=True)

        def measured(name, values):
            v, unit = self.state(name, values)
            return {"value": json_safe(float(v) if np.ndim(v) == 0 else v), "unit": unit}

        data["grid"] = {**{a.name: {"values": list(a.values), "unit": a.unit} for a in self.axes},
                        "held": {k: measured(k, v) for k, v in result.held.items()}, "starts": result.starts}
        for a, out in zip(result.attractors, data["attractors"]):
            out["amplitude"] = {k: measured(k, v) for k, v in a.amplitude.items()}
            out["points"] = {n: measured(n, row) for n, row in zip(result.state_names, a.points)}
            out["representative"] = {k: measured(k, v) for k, v in a.representative.items()}
            out["exponents_per_second"] = json_safe(np.asarray(a.exponents) * self.omega * units.units.omega_n)
        if units.units.speed is not None and self.omega is not None:
            data["speed"] = {"value": float(units.speed(self.omega)), "unit": units.units.speed_unit.text}
        return data

    def text(self) -> str:
        """The map as the command's text says it: the run, each attractor, the other classes."""
        result = self.result
        (x, xs), (y, ys) = result.axes
        sx, ux = self.state(x, xs)
        sy, uy = self.state(y, ys)
        held = ", ".join("{}={:g}{}".format(k, *self.number(k, v)) for k, v in result.held.items())
        lines = [
            f"{result.model}: {result.starts} starts, {x} in [{sx.min():g}, {sx.max():g}]{ux} ({xs.size}) x {y} in "
            f"[{sy.min():g}, {sy.max():g}]{uy} ({ys.size})" + (f", held {held}" if held else ""),
            f"parameters: {self.parameters_text().replace('$', '')}",  # (no figure mathtext in text)
            f"{result.periods} periods per start ({result.discard} discarded), {result.steps_per_period} RK4 "
            f"steps/period, {'crossings located' if result.locate_crossings else 'plain RK4'}, {result.backend}, "
            f"{result.lanes} trajectories per call",
            f"{len(result.attractors)} attractor{'s' if len(result.attractors) != 1 else ''} (fraction of starts ± "
            "binomial standard error; exponents from one tangent run on each):",
        ]
        for a in result.attractors:
            amplitude = ", ".join("A_{} = {:.6g}{}".format(k, *_spaced(self.number(k, v)))
                                  for k, v in a.amplitude.items())
            lines += [f"  {a.number}: {a.description}: {a.fraction:.4f} ± {a.stderr:.4f} ({a.basin.starts} starts)",
                      f"     {amplitude}; lambda = " + ", ".join(f"{v:+.5f}" for v in a.exponents)]
        for name, share in (("diverged", result.diverged), ("undetermined", result.undetermined)):
            lines.append(f"  {name}: {share.fraction:.4f} ± {share.stderr:.4f} ({share.starts} starts)")
        return "\n".join(lines)


def _spaced(number: tuple[float, str]) -> tuple[float, str]:
    value, unit = number
    return value, f" {unit}" if unit else ""


@dataclass(frozen=True)
class ShownFractions:
    """A :class:`~gearsym.sweep.basin_continuation.BasinContinuation` with the units it is shown in."""

    result: BasinContinuation
    units: OwnNumbers = OwnNumbers()

    @classmethod
    def of(cls, result: "BasinContinuation | ShownFractions") -> "ShownFractions":
        return result if isinstance(result, cls) else cls(result)

    def parameter(self) -> tuple[str, np.ndarray, str]:
        """The parameter as shown: (name, values, unit) (omega as the speed for a model with physical values)."""
        return self.units.parameter(self.result.parameter, self.result.values)

    def amplitude(self, name: str, value: float, at: float) -> tuple[float, str]:
        """An amplitude of state ``name`` at the parameter's value ``at`` as shown, and its unit."""
        omega = at if self.result.parameter == "omega" else self.result.record.get("settings", {}).get("omega")
        values, unit = self.units.state(name, [value], omega)
        return float(values[0]), unit

    def unit(self, name: str) -> str:
        """The unit a state's amplitudes are shown in."""
        return self.units.state(name, [0.0], 1.0)[1]

    def parameters_text(self, values: dict) -> str:
        return self.units.parameters(values)

    def as_dict(self) -> dict:
        """The continuation's record, in the engine's numbers as its own files hold them (the fractions in the
        model's units: :func:`~gearsym.physical.files.write_basin_fractions`)."""
        return self.result.as_dict()

    def text(self) -> str:
        """The fractions as the command's text says them: at each value of the parameter (the speed for a model
        with physical values), each attractor's share and what it is, then where attractors appear, vanish or
        merge."""
        result = self.result
        name, values, unit = self.parameter()
        lines = [f"{result.model}: basin fractions at {len(values)} values of {name} ({values[0]:g} to "
                 f"{values[-1]:g}{' ' + unit if unit else ''}) -> {result.path}"]
        where = dict(zip(result.values, values))
        for v in result.values:
            parts = [f"{r.id}: {r.fraction:.3f} ({r.period and f'period {r.period}' or r.regime})"
                     for r in result.at(v) if r.kind == "attractor"]
            other = [f"{r.kind} {r.fraction:.3f}" for r in result.at(v) if r.kind != "attractor" and r.starts]
            lines.append(f"  {name}={where[v]:g}: " + "; ".join(parts + other))
        for e in result.events:
            what = f"attractor {e['attractor']} {e['event']}" + (f" into {e['into']}" if e["into"] else "")
            lines.append(f"  at {name}={where[e['value']]:g}: {what}")
        return "\n".join(lines)


def engine_grid(units: PointUnits, si_grid: Mapping[str, np.ndarray], omega: float) -> dict[str, np.ndarray]:
    """The engine's values of a grid in SI units (:func:`grid_in_si`) at the forcing frequency ``omega`` (a rate's
    engine unit moves with the speed)."""
    return {name: values if units.kinds.get(name) is None else values / float(units.state(name, 1.0, omega, si=True))
            for name, values in si_grid.items()}


class GivenGrid(StartGrid):
    """The starts of a grid as given (``axes``: :class:`GridAxis`, with the record's specs): in the model's own
    numbers (``units`` None: a model without physical values), or in physical units, checked and in SI units
    when it is made (:func:`grid_in_si`), its engine values at each forcing frequency (a rate's unit moves with
    the speed)."""

    def __init__(self, units: PointUnits | None, axes: Sequence[GridAxis]):
        super().__init__({a.name: a.values for a in axes}, [a.spec for a in axes])
        self.units, self.axes = units, tuple(axes)
        self.si_grid = grid_in_si(units, axes) if units is not None else None

    def at(self, point):
        if self.units is None:  # (the model's own numbers: the same at every point)
            return super().at(point)
        return engine_grid(self.units, self.si_grid, point.get("omega", 1.0))
