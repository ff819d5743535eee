"""The two jobs of ``gearsym basins``, for Python as for the command line: a map of basins on a grid of starts
(:class:`BasinMapJob`), and the basin fractions along a parameter (:class:`BasinFractionsJob`), on one base
(:class:`BasinsJob`: the grid as given, where the other states start, how the run runs, the picture).

A job runs on a model opened for it (:class:`~gearsym.opening.OpenModel`): first what it was given is checked
against the model, before the model is compiled (:func:`checked_starts`: units for a model with physical
values, none for one without); then the job compiles the model, runs on it, writes its files and returns what it
found as shown, with what it wrote (:class:`Done`)::

    job = BasinMapJob(grid=(GridAxis.read("x=-2:2:0.1"), GridAxis.read("v=-2:2:0.1")), out="map.csv")
    done = job.run(open_model(ModelRequest("duffing", options=Integration(periods=60, discard=20))))
    print(done.report())
"""
from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..analysis.basins import basin_map
from ..errors import GearsymError
from ..figures.basins import save_basin_fractions, save_basin_map
from ..opening import OpenModel
from ..options import Execution
from ..physical.basins import GivenGrid, GridAxis, OwnNumbers, ShownBasinMap, ShownFractions, shown_in
from ..physical.sweeps import MeasuredAxis, engine_axis
from ..sweep.basin_continuation import MATCH_DISTANCE, continue_basins
from ..sweep.grid import Axis
from ..sweep.store import sidecar


@dataclass(frozen=True)
class Done:
    """What a job found, as shown (:class:`~gearsym.physical.basins.ShownBasinMap` or
    :class:`~gearsym.physical.basins.ShownFractions`: in the model's units when it has physical values), and what
    it wrote (``written``: a line for each file, or table with its record)."""

    shown: ShownBasinMap | ShownFractions
    written: tuple[str, ...] = ()

    def report(self, format: str = "text") -> str:
        """What was found, as text or (``"json"``) as its record."""
        return json.dumps(self.shown.as_dict(), indent=2) if format == "json" else self.shown.text()


def checked_starts(model: OpenModel, grid: Sequence[GridAxis],
                   others: Sequence[Axis] = ()) -> tuple[OwnNumbers, GivenGrid]:
    """How the results of a run on ``model`` are shown, and its ``grid`` of starts, checked before the model is
    compiled: a model with physical values takes the grid in units (each axis in a unit of its state's kind), one
    without takes no unit, on the grid nor on the ``others`` given (a parameter's axis)."""
    scaling = model.scaling
    units = scaling.point_units() if scaling is not None else None
    if units is None:
        unit = next((a for a in [*grid, *others] if a.unit), None)
        if unit:
            raise GearsymError(f"{unit.spec!r} has a unit, but the model has no physical values; give the model's own "
                               "numbers")
    return shown_in(units, model.request.settings), GivenGrid(units, grid)


@dataclass(frozen=True, kw_only=True)
class BasinsJob:
    """What both jobs are given: the ``grid`` of starts as given (two :class:`~gearsym.physical.basins.GridAxis`,
    in physical units for a model with physical values), where the other states start (``y0``: the model's
    initial state by default), the runs' threads, lanes and progress (``execution``) and the picture (``plot``)."""

    grid: Sequence[GridAxis]
    y0: Mapping[str, float] | None = None
    execution: Execution = field(default_factory=Execution)
    plot: str | Path | None = None

    def run(self, model: OpenModel) -> Done:  # pragma: no cover (each job has its own)
        """The job on ``model`` (an :class:`~gearsym.opening.OpenModel`): what it was given checked against the
        model, the model compiled, the job run and its files written; what it found, as shown, and what it
        wrote."""
        raise NotImplementedError

    def plotted(self) -> tuple[str, ...]:
        """The line that says the picture was written (none without a picture)."""
        return (f"wrote {self.plot}",) if self.plot else ()


@dataclass(frozen=True, kw_only=True)
class BasinMapJob(BasinsJob):
    """A map of basins (:func:`~gearsym.analysis.basins.basin_map`): which attractor each start of the grid
    reaches; its table ``out`` (one row per start, and its record) and its picture, each written whole
    (:func:`~gearsym.figures.basins.save_basin_map`)."""

    out: str | Path | None = None

    def run(self, model: OpenModel) -> Done:
        """The map on ``model`` (compiled here, after the grid is checked), its files written."""
        shown_as, grid = checked_starts(model, self.grid)
        compiled = model.compiled()
        found = basin_map(compiled, grid, y0=self.y0, execution=self.execution)
        shown = ShownBasinMap(found, shown_as, grid.axes)
        written = save_basin_map(shown, self.out, self.plot)
        tables = [f"wrote {written[0]} and {written[1]}"] if self.out else []
        return Done(shown, (*tables, *self.plotted()))


@dataclass(frozen=True, kw_only=True)
class BasinFractionsJob(BasinsJob):
    """The basin fractions along a ``parameter`` (a :class:`~gearsym.physical.sweeps.MeasuredAxis`, in its unit
    for a model with physical values), each attractor followed from one value to the next by its Poincare set
    (:func:`~gearsym.sweep.basin_continuation.continue_basins`): its files ``out`` written as the values finish
    and resumed (``overwrite``: start again), then the fractions in the model's units and the picture
    (:func:`~gearsym.figures.basins.save_basin_fractions`)."""

    parameter: MeasuredAxis
    out: str | Path | None = None
    overwrite: bool = False
    match_distance: float = MATCH_DISTANCE

    def run(self, model: OpenModel) -> Done:
        """The fractions on ``model`` (compiled here, after the grid and the parameter are checked and the
        parameter is in the engine's numbers), their files written. Ctrl-C during the values:
        :class:`FractionsInterrupted`."""
        shown_as, grid = checked_starts(model, self.grid, [self.parameter])
        physical = grid.units is not None
        axis = engine_axis(model.scaling.full, self.parameter) if physical else self.parameter
        compiled = model.compiled()
        try:
            result = continue_basins(compiled, grid, axis.name, axis.values, y0=self.y0, out=self.out,
                                     overwrite=self.overwrite, execution=self.execution,
                                     match_distance=self.match_distance)
        except KeyboardInterrupt as exc:
            raise FractionsInterrupted from exc
        shown = ShownFractions(result, shown_as)
        table = sidecar(self.out, ".physical.csv") if physical and self.out else None
        save_basin_fractions(shown, table, self.plot)
        tables = [f"wrote {table} (the fractions in the model's units)"] if table else []
        return Done(shown, (*tables, *self.plotted()))


class FractionsInterrupted(KeyboardInterrupt):
    """Ctrl-C while a job's basin fractions were being made: the values finished are in its files (``out``), from
    which the same job resumes."""
