"""Sweeps over physical values: each physical axis becomes the axis of the one nondimensional parameter it
moves (``speed`` -> omega, ``cZ`` -> zeta, ...), so the engine sweeps as before. The axes come from
``--param`` (``speed=500rpm:6000rpm:25rpm``) or, in Python, from a mapping whose values carry their unit
(``{"speed": ["1000 rpm", "2000 rpm"]}`` or pint Quantities)."""
from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import GearsymError
from ..sweep.grid import Axis, axes_from, axis_fields, parse_axis
from ..units import Measure, as_quantity, is_quantity, measure_in, symbol

if TYPE_CHECKING:  # (the type only: a sweep of a cached model reads this module without SymPy)
    from ..scales.map import Scaling

#: a unit written straight after a number (rpm, um, mm): no space needed, nor quotes on a command line
_PLAIN_UNIT = re.compile(r"[A-Za-zµμ]+")


@dataclass(frozen=True)
class MeasuredAxis(Axis):
    """An axis whose values carry a unit, read once (:meth:`of`; :meth:`read` for a ``--param`` as written): each
    value as a :class:`~gearsym.units.Measure` (in SI, its dimension, as given), or why they cannot be read
    (``refused``: said where they are used, after the checks that come before it)."""

    measures: tuple[Measure, ...] = ()
    refused: str = ""

    @classmethod
    def of(cls, axis: Axis, where: str | None = None) -> "MeasuredAxis":
        """``axis`` with its values read in its unit (none without one); ``where`` names it in errors (default the
        ``--param`` it was written as)."""
        if isinstance(axis, cls):
            return axis
        plain = axis_fields(axis)
        if not axis.unit:
            return cls(**plain)
        where = where or f"--param {axis.spec!r}"
        try:
            return cls(**plain, measures=tuple(measure_in(v, axis.unit, where) for v in axis.values))
        except GearsymError as exc:
            return cls(**plain, refused=str(exc))

    @classmethod
    def read(cls, text: str) -> "MeasuredAxis":
        """A ``--param`` axis (``NAME=START:STOP:STEP``, a list or one value, with or without a unit)."""
        return cls.of(parse_axis(text))

    @property
    def plain(self) -> Axis:
        """The axis as it was given (its values in their unit)."""
        return Axis(**axis_fields(self))


def nondimensional_axis(scaling: Scaling, axis: Axis, where: str | None = None) -> Axis:
    """The engine's axis for ``axis``: a physical value swept (with a unit) becomes the one nondimensional
    parameter it changes; other axes pass as they are. ``where`` names the entry in errors (default the
    ``--param`` it was written as)."""
    return engine_axis(scaling, MeasuredAxis.of(axis, where), where)


def engine_axis(scaling: Scaling, axis: MeasuredAxis, where: str | None = None) -> Axis:
    """:func:`nondimensional_axis` of an axis whose values were read in their unit already."""
    where = where or f"--param {axis.spec!r}"
    name = axis.name
    if name not in scaling.inputs and not (scaling.speed and name == scaling.speed.parameter):
        if axis.unit:
            raise GearsymError(f"{where}: {name} is not a physical value of {scaling.name}, so it takes no unit; "
                               f"physical values: {', '.join(scaling.roles)}")
        return axis.plain
    if not axis.unit:
        unit = scaling.unit_needed(name)
        if unit:
            raise GearsymError(f"{where}: {name}: "
                               f"{scaling.unitless(name, axis.values[0], _spelled(axis, unit, where))}")
    if axis.refused:
        raise GearsymError(axis.refused)
    base = scaling.values
    columns = [scaling.values_at(**{name: value}) for value in axis.measures]
    moved = sorted({k for row in columns for k in row if row[k] != base[k]} or {scaling.parameter_moved_by(name)})
    if len(moved) != 1:
        raise GearsymError(f"{where}: {name} moves {', '.join(moved)} of the nondimensional model "
                           "together (it changes the units themselves); sweep a value that moves one of them, or "
                           "fix the length scale with --set length_scale='1 um'")
    target = moved[0]
    values = tuple(row[target] for row in columns)
    if len(set(values)) != len(values):
        raise GearsymError(f"{where}: two values of {name} give the same {target}")
    return Axis(target, values, axis.spec)


def _spelled(axis: Axis, unit: str, where: str) -> str:
    """The axis written with its unit, as the entry takes it: ``speed=2000rpm:16000rpm:7000rpm`` on the command
    line, ``{'speed': ['2000 rpm', ...]}`` in Python."""
    shown = symbol(unit)
    if not where.startswith("--param"):
        values = ", ".join(f"'{v:g} {shown}'" for v in axis.values[:2]) + (", ..." if len(axis.values) > 2 else "")
        return f"{{{axis.name!r}: [{values}]}}"
    body = axis.spec.partition("=")[2]
    separator = ":" if ":" in body else ","
    parts = [p.strip() for p in body.split(separator)]
    if _PLAIN_UNIT.fullmatch(shown):
        return f"{axis.name}=" + separator.join(f"{p}{shown}" for p in parts)
    return f"\"{axis.name}={separator.join(parts)} {shown}\""


def nondimensional_axes(scaling: Scaling, axes: Sequence[Axis], where: str | None = None) -> tuple[Axis, ...]:
    return tuple(nondimensional_axis(scaling, a, where) for a in axes)


def axes_with_units(spec: Mapping[str, Sequence] | Sequence[Axis | str]) -> tuple[Axis, ...]:
    """Axes from a mapping whose values may carry a unit (quantity strings or pint Quantities; an axis's values
    in the unit of its first), from Axis objects or from ``--param`` strings."""
    if not isinstance(spec, Mapping):
        return axes_from(spec)
    plain, axes = {}, {}
    for name, values in spec.items():
        values = list(values)
        if not any(is_quantity(v) for v in values):
            plain[name] = values
            continue
        quantities = [as_quantity(v, f"run_sweep: {name}") for v in values]
        bare = next((v for v, q in zip(values, quantities) if str(q.units) == "dimensionless"), None)
        if bare is not None:
            given = next(v for v in values if is_quantity(v))
            raise GearsymError(f"run_sweep: {name}: {bare!r} has no unit while {given!r} has one: give every value "
                               "its unit")
        unit = str(quantities[0].units)
        try:
            numbers = sorted(float(q.to(unit).magnitude) for q in quantities)
        except Exception:
            raise GearsymError(f"run_sweep: {name}: the values {values[:3]!r} cannot all be converted to "
                               f"{symbol(unit)}") from None
        axes[name] = Axis(name, tuple(numbers), f"{name}={','.join(map(str, values))}", unit)
    made = dict(zip(plain, axes_from(plain))) if plain else {}
    return axes_from([made.get(name) or axes[name] for name in spec])
