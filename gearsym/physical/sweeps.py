"""Sweeps over physical values: each physical axis becomes the axis of the one nondimensional parameter it
moves (``speed`` -> omega, ``cZ`` -> zeta, ...), so the engine sweeps as before."""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..errors import GearsymError
from ..sweep.grid import Axis
from ..units import Quantity

if TYPE_CHECKING:  # (the type only: a sweep of a cached model reads this module without SymPy)
    from ..scales.map import Scaling


def nondimensional_axis(scaling: Scaling, axis: Axis) -> Axis:
    """The engine's axis for ``axis``: a physical value swept (with or without a unit: the unit of its declared
    value then) becomes the one nondimensional parameter it changes; other axes pass as they are."""
    name = axis.name
    if name not in scaling.inputs and not (scaling.speed and name == scaling.speed.parameter):
        if axis.unit:
            raise GearsymError(f"--param {axis.spec!r}: {name} is not a physical value of {scaling.name}, so it "
                               f"takes no unit; physical values: {', '.join(scaling.roles)}")
        return axis
    declared = scaling.inputs.get(name)
    if not axis.unit and (declared is None or not declared.dimensionless):
        unit = declared.unit if declared is not None else scaling.speed_unit
        raise GearsymError(f"--param {axis.spec!r}: {name} has a unit, so its values need one: write them with it, "
                           f"e.g. {name}={axis.values[0]:g}{unit}:{axis.values[-1]:g}{unit}:...")
    unit = axis.unit
    base = scaling.values
    columns = [scaling.values_at(**{name: Quantity(v, unit)}) for v in axis.values]
    moved = sorted({k for row in columns for k in row if row[k] != base[k]} or {_first_moved(scaling, name)})
    if len(moved) != 1:
        raise GearsymError(f"--param {axis.spec!r}: {name} moves {', '.join(moved)} of the nondimensional model "
                           "together (it changes the units themselves); sweep a value that moves one of them, or "
                           "fix the length scale with --set length_scale='1 um'")
    target = moved[0]
    values = tuple(row[target] for row in columns)
    if len(set(values)) != len(values):
        raise GearsymError(f"--param {axis.spec!r}: two values of {name} give the same {target}")
    return Axis(target, values, axis.spec)


def _first_moved(scaling: Scaling, name: str) -> str:
    """The parameter a one-point axis moves: found by a small step away from it."""
    q = scaling.inputs.get(name)
    shifted = scaling.values_at(**{name: q.with_si(q.si * 1.01) if q is not None
                                   else Quantity(scaling.speed_si() * 1.01, "rad/s")})
    moved = [k for k, v in shifted.items() if v != scaling.values[k]]
    return moved[0] if len(moved) == 1 else ",".join(moved)


def nondimensional_axes(scaling: Scaling, axes: Sequence[Axis]) -> tuple[Axis, ...]:
    return tuple(nondimensional_axis(scaling, a) for a in axes)
