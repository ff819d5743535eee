"""A stability chart of a model with physical values, in its units: the axes as the user gave them (the speed in
rpm, a damping in N s/m), the boundaries carried along.

The engine charts the nondimensional parameter each physical axis moves (speed -> omega: proportional); every
value of the chart (grid, crossings, boundary curves) is taken back through the map between the axis's values
as given and as the engine ran them, piecewise linear between the grid's values (exact for the speed, which
omega is proportional to)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..sweep.grid import Axis
from ..stability.boundaries import Boundary
from ..stability.chart import StabilityChart


def _axis_map(given: Axis, engine: Axis):
    """engine value -> the value as given (identity for an axis that was not converted)."""
    if given.name == engine.name and not given.unit:
        return lambda v: np.asarray(v, dtype=float)
    xp, fp = np.array(engine.values, dtype=float), np.array(given.values, dtype=float)
    order = np.argsort(xp)
    xp, fp = xp[order], fp[order]
    if len(xp) == 1:  # (one value: proportional, the speed's rule; no crossing lies along such an axis)
        return lambda v: np.asarray(v, dtype=float) * (fp[0] / xp[0]) if xp[0] else np.full(np.shape(v), fp[0])
    slope_lo, slope_hi = (fp[1] - fp[0]) / (xp[1] - xp[0]), (fp[-1] - fp[-2]) / (xp[-1] - xp[-2])

    def to_given(v):
        v = np.asarray(v, dtype=float)
        out = np.interp(v, xp, fp)
        out = np.where(v < xp[0], fp[0] + (v - xp[0]) * slope_lo, out)
        return np.where(v > xp[-1], fp[-1] + (v - xp[-1]) * slope_hi, out)

    return to_given


def chart_in_units(chart: StabilityChart, given: tuple[Axis, Axis], engine: tuple[Axis, Axis]) -> StabilityChart:
    """``chart`` (run on the ``engine`` axes) along the axes as ``given``, in their units."""
    maps = [_axis_map(g, e) for g, e in zip(given, engine)]
    values = tuple(maps[k](chart.values[k]) for k in range(2))
    crossings = []
    for c in chart.crossings:
        f = maps[c.axis]
        value = float(f(c.value))
        error = float(abs(f(c.value + c.error) - value)) if c.error else 0.0
        crossings.append(c._replace(value=value, error=error))
    boundaries = [Boundary(np.column_stack([maps[0](b.points[:, 0]), maps[1](b.points[:, 1])]), b.closed, b.kind,
                           b.kinds) for b in chart.boundaries]
    tolerance = tuple(float(abs(maps[k](chart.values[k][0] + chart.tolerance[k]) - maps[k](chart.values[k][0])))
                      for k in range(2))
    engine_note = [f"charted in the engine's {e.name} ({min(e.values):.6g} to {max(e.values):.6g}), shown as "
                   f"{g.name} in {g.unit}" for g, e in zip(given, engine) if g.name != e.name or g.unit]
    return replace(chart, names=(given[0].name, given[1].name), values=values, crossings=tuple(crossings),
                   boundaries=tuple(boundaries), tolerance=tolerance, units=(given[0].unit, given[1].unit),
                   engine=(engine[0].name, engine[1].name),
                   notes=chart.notes + tuple(engine_note))
