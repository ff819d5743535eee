"""Stability charts: the Floquet multipliers of a model linearised about its static state (or its periodic orbit)
at every point of a grid of two parameters, the kind of instability where it is unstable, and the boundaries
located to a stated tolerance and joined into curves.

The cost is one period of the linearised system per point (its monodromy matrix, many points per native call
in the lanes: :mod:`.monodromies`), and log2(step / tolerance) periods per boundary point (:mod:`.boundaries`).
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..checks import json_safe
from ..codegen.compiled import CompiledModel
from ..errors import GearsymError
from ..options import Execution
from ..sweep.grid import Axis, axes_from
from .boundaries import Boundary, Crossing, curves, grid_crossings, midpoints, refine
from .kinds import MARGIN, NO_ORBIT, NO_STATIC_STATE, classify, multipliers
from .monodromies import MonodromyRunner
from .orbits import periodic_orbits
from .recipe import STATIC_SUFFIX, CompiledLinearisation, StaticRecipe, anchor_parameter
from .static_states import DRIVE, EDGE, GAP, solve_static

ABOUT = ("static", "orbit")
#: the default tolerance of a boundary: this fraction of the axis's range
RELATIVE_TOLERANCE = 1e-7


@dataclass(frozen=True)
class StabilityChart:
    """A stability chart over the axes ``names`` (first: columns, second: rows of every grid array).

    ``multipliers`` (rows x columns x n, largest modulus first; NaN where the point has none), ``max_modulus``,
    ``stable`` (True, False, or None where there is no result), ``kind`` (None where stable: ``fold``,
    ``period doubling``, ``Neimark-Sacker``; or why there is no result), the ``boundaries`` (curves) from the
    ``crossings`` located on the grid lines to ``tolerance``; ``notes``: what was linearised and how."""

    model: str
    about: str
    names: tuple[str, str]
    values: tuple[np.ndarray, np.ndarray]
    parameters: dict[str, float]
    multipliers: np.ndarray
    max_modulus: np.ndarray
    stable: np.ndarray
    kind: np.ndarray
    crossings: tuple[Crossing, ...]
    boundaries: tuple[Boundary, ...]
    tolerance: tuple[float, float]
    steps_per_period: int
    notes: tuple[str, ...] = ()
    timings: dict = field(default_factory=dict)
    units: tuple[str, str] = ("", "")
    engine: tuple[str, str] = ()  # the engine's parameters the axes move, where they are shown as others (speed)

    @property
    def shape(self) -> tuple[int, int]:
        return self.max_modulus.shape

    @property
    def fixed(self) -> dict[str, float]:
        """The parameters held over the chart."""
        return {k: v for k, v in self.parameters.items() if k not in (*self.names, *self.engine)}

    def points(self) -> list[dict]:
        a, b = self.values
        out = []
        for i in range(len(b)):
            for j in range(len(a)):
                out.append({self.names[0]: float(a[j]), self.names[1]: float(b[i]),
                            "max_modulus": self.max_modulus[i, j], "stable": self.stable[i, j],
                            "kind": self.kind[i, j]})
        return out

    def as_dict(self) -> dict:
        return json_safe({
            "model": self.model, "about": self.about,
            "grid": {name: values for name, values in zip(self.names, self.values)},
            "units": {name: unit for name, unit in zip(self.names, self.units) if unit},
            "parameters": self.fixed, "steps_per_period": self.steps_per_period,
            "unstable_above": 1.0 + MARGIN,
            "tolerance": dict(zip(self.names, self.tolerance)),
            "points": self.points(),
            "boundaries": [b.as_dict(self.names) for b in self.boundaries],
            "crossings": [{"axis": self.names[c.axis], "at": {self.names[1 - c.axis]: float(
                self.values[1][c.i] if c.axis == 0 else self.values[0][c.j])}, "value": c.value, "error": c.error,
                "kind": c.kind, "located": c.located} for c in self.crossings],
            "counts": self.counts(), "notes": list(self.notes), "timings": self.timings,
        })

    def counts(self) -> dict[str, int]:
        """Points by verdict: stable, each kind of instability, and those without a result."""
        out = {"stable": int(np.sum(self.stable == True))}  # noqa: E712 (an object array of True/False/None)
        for k in self.kind.reshape(-1):
            if k is not None:
                out[k] = out.get(k, 0) + 1
        return out


class _Grid:
    """The chart's points: axis values, the model's parameter vector at each."""

    def __init__(self, names: tuple[str, ...], base: np.ndarray, axes: tuple[Axis, ...]):
        self.names, self.base = names, base
        self.axes = axes
        self.a = np.array(axes[0].values, dtype=float)
        self.b = np.array(axes[1].values, dtype=float)
        self.columns = [names.index(ax.name) for ax in axes]

    def vectors(self, points: np.ndarray, base: np.ndarray | None = None,
                columns: Sequence[int] | None = None) -> np.ndarray:
        """The parameter vectors of ``points``: ``base`` (default: the grid's) with the axes' values in
        ``columns`` (default: the axes' columns in the grid's names)."""
        base = self.base if base is None else base
        p = np.empty((len(points), len(base)))
        p[:] = base
        for k, column in enumerate(self.columns if columns is None else columns):
            p[:, column] = points[:, k]
        return p

    def all_points(self) -> np.ndarray:
        """Every point of the grid, row by row (the first axis fastest)."""
        points = np.empty((len(self.a) * len(self.b), 2))
        points.reshape(len(self.b), len(self.a), 2)[:, :, 0] = self.a
        points.reshape(len(self.b), len(self.a), 2)[:, :, 1] = self.b[:, None]
        return points


class _Static:
    """Monodromy matrices of the linearisation about the static state (:func:`compile_linearisation`)."""

    about = "static"

    def __init__(self, lin: CompiledLinearisation, grid: _Grid, lanes: bool, jobs: int, verbose: bool):
        self.lin, self.grid = lin, grid
        self.runner = MonodromyRunner(lin.model, lanes=lanes, jobs=jobs, verbose=verbose, linear=True)
        self.names = names = lin.model.parameter_names  # (the model's parameters, then the anchors)
        self.base = np.zeros(len(names))
        self.base[[names.index(n) for n in grid.names]] = grid.base
        self.axis_columns = [names.index(n) for n in (grid.axes[0].name, grid.axes[1].name)]
        self.anchor_columns = [names.index(anchor_parameter(s)) for s in lin.anchors]
        self.anchor_states = [lin.recipe.states.index(s) for s in lin.anchors]
        self.flanks: dict[str, dict[str, int]] = {}
        self.missing = 0

    def evaluate(self, points: np.ndarray, near=None, progress=None) -> tuple[np.ndarray, np.ndarray]:
        p = self.grid.vectors(points, self.base, self.axis_columns)
        static = solve_static(self.lin.recipe, self.names, p)
        if self.anchor_states:  # (one static state for every point where it depends on none of the axes)
            anchors = static.distinct_states[:, self.anchor_states]
            p[:, self.anchor_columns] = anchors[0] if len(anchors) == 1 else anchors[static.index]
        ok = static.found
        if ok.all():
            mu = multipliers(self.runner.run(p, None, progress=progress)[1])
        else:
            mu = np.full((len(points), self.lin.model.dimension), np.nan + 0j)
            if ok.any():
                rows = np.nonzero(ok)[0]
                mu[rows] = multipliers(self.runner.run(p[rows], None, progress=progress)[1])
        if near is None:  # the grid itself: what the notes say
            self.missing = int((~ok).sum())
            self.flanks = static.flank_counts
        return mu, ok

    def notes(self) -> list[str]:
        out = ["linearised about the static state: the equations averaged over a period (k(tau) and every "
               "harmonic term by its mean), at rest; the monodromy matrix of the variational equation there, "
               "over one period"]
        meaning = {DRIVE: "drive flank in contact: g' = 1", GAP: "in the gap: g' = 0, no mesh stiffness",
                   "back flank": "back flank in contact: g' = 1",
                   EDGE: "at the edge of contact (x = 0 or x = -eta): linearised with the contact side's g' = 1"}
        for mesh, counts in self.flanks.items():
            parts = [f"{meaning.get(k, k)} at {v} point(s)" for k, v in counts.items()]
            out.append(f"backlash of mesh {mesh!r} linearised at the static mesh deflection: " + "; ".join(parts))
        if self.missing:
            out.append(f"{self.missing} point(s) have no static state (Newton on the averaged equations did not "
                       f"converge): marked '{NO_STATIC_STATE}'")
        return out

    missing_kind = NO_STATIC_STATE


class _Orbit:
    """Monodromy matrices of the period-1 orbits (found by shooting from the static state) of the model."""

    about = "orbit"

    def __init__(self, model: CompiledModel, recipe: StaticRecipe, grid: _Grid, lanes: bool, jobs: int,
                 verbose: bool):
        self.model, self.recipe, self.grid = model, recipe, grid
        self.runner = MonodromyRunner(model, lanes=lanes, jobs=jobs, verbose=verbose)
        self.orbits: np.ndarray | None = None
        self.missing, self.from_neighbour = 0, 0

    def evaluate(self, points: np.ndarray, near=None, progress=None) -> tuple[np.ndarray, np.ndarray]:
        p = self.grid.vectors(points)
        if near is None:
            starts = solve_static(self.recipe, self.grid.names, p).states
        else:
            starts = self.orbits[near]
        z, M, ok = periodic_orbits(self.runner, p, starts)
        if near is None:
            z, M, ok = self._from_neighbours(p, z, M, ok)
            self.orbits = z
            self.missing = int((~ok).sum())
        mu = np.full((len(points), self.model.dimension), np.nan + 0j)
        if ok.any():
            mu[ok] = multipliers(M[ok])
        return mu, ok

    def _from_neighbours(self, p, z, M, ok):
        """Points whose Newton did not converge from the static state, again from a neighbour's orbit."""
        rows, cols = len(self.grid.b), len(self.grid.a)
        for _ in range(3):
            if ok.all() or not ok.any():
                break
            grid_ok = ok.reshape(rows, cols)
            start = np.full_like(z, np.nan)
            todo = []
            for k in np.nonzero(~ok)[0]:
                i, j = divmod(int(k), cols)
                for di, dj in ((0, -1), (0, 1), (-1, 0), (1, 0)):
                    ni, nj = i + di, j + dj
                    if 0 <= ni < rows and 0 <= nj < cols and grid_ok[ni, nj]:
                        start[k] = z[ni * cols + nj]
                        todo.append(k)
                        break
            if not todo:
                break
            todo = np.array(todo)
            z2, M2, ok2 = periodic_orbits(self.runner, p[todo], start[todo])
            z[todo[ok2]], M[todo[ok2]], ok[todo[ok2]] = z2[ok2], M2[ok2], True
            self.from_neighbour += int(ok2.sum())
        return z, M, ok

    def notes(self) -> list[str]:
        out = ["linearised about the period-1 orbit: found by Newton (shooting, the exact monodromy matrix) from "
               "the static state, the monodromy matrix at the orbit over one period"
               + (" (crossings of the backlash located)" if self.model.options.locate_crossings else "")]
        if self.from_neighbour:
            out.append(f"{self.from_neighbour} point(s) converged only from a neighbouring point's orbit")
        if self.missing:
            out.append(f"{self.missing} point(s): no periodic orbit found from the static state or a neighbour's "
                       f"(Newton did not converge): marked '{NO_ORBIT}'")
        return out

    missing_kind = NO_ORBIT


def chart_of(problem, grid: _Grid, *, model: str, steps: int, parameters: dict, refine_boundaries: bool = True,
             tolerance: Sequence[float] | None = None,
             progress: Callable[[str, int, int], None] | None = None) -> StabilityChart:
    """The chart of ``problem`` (:class:`_Static` or :class:`_Orbit`) over ``grid``."""
    start = time.perf_counter()
    na, nb = len(grid.a), len(grid.b)
    points = grid.all_points()
    mu, ok = problem.evaluate(points, progress=(lambda d, t: progress("grid", d, t)) if progress else None)
    everywhere = ok.all()
    largest, unstable, kind = classify(mu if everywhere else np.where(ok[:, None], mu, 0))
    if not everywhere:
        kind[~ok] = problem.missing_kind
    stable = _VERDICTS[np.where(ok, ~unstable, 2) if not everywhere else ~unstable + 0]
    shape = (nb, na)
    grid_seconds = time.perf_counter() - start
    tol = _tolerances(grid, tolerance)
    valid = ok.reshape(shape)
    un = unstable.reshape(shape)
    largest = (largest if everywhere else np.where(ok, largest, np.nan)).reshape(shape)
    kinds = kind.reshape(shape)
    t = time.perf_counter()
    edges = grid_crossings(un, valid)
    evaluations = [0]

    def evaluate(at: np.ndarray, near: np.ndarray):
        evaluations[0] += len(at)
        m, good = problem.evaluate(at, near)
        big, bad, k = classify(np.where(good[:, None], m, 0))
        return bad, k, good

    if refine_boundaries:
        found = refine(edges, grid.a, grid.b, un, kinds, evaluate, tol,
                       (lambda d, t_: progress("boundaries", d, t_)) if progress else None)
    else:
        found = midpoints(edges, grid.a, grid.b, un, kinds)
    refine_seconds = time.perf_counter() - t
    boundaries = curves(found, grid.a, grid.b, un, valid, largest)
    timings = {"grid_seconds": grid_seconds, "grid_points": int(na * nb), "boundary_points": len(found),
               "refinement_seconds": refine_seconds, "refinement_periods": evaluations[0],
               "periods_per_boundary_point": evaluations[0] / len(found) if found else 0.0}
    return StabilityChart(
        model=model, about=problem.about, names=(grid.axes[0].name, grid.axes[1].name), values=(grid.a, grid.b),
        parameters=parameters,
        multipliers=mu.reshape(nb, na, -1), max_modulus=largest, stable=stable.reshape(shape), kind=kinds,
        crossings=tuple(found), boundaries=tuple(boundaries), tolerance=tol, steps_per_period=steps,
        notes=tuple(problem.notes()), timings=timings)


#: a point's verdict (``stable``) by its code: unstable, stable, no result
_VERDICTS = np.array([False, True, None], dtype=object)


def _tolerances(grid: _Grid, tolerance) -> tuple[float, float]:
    """Absolute tolerances per axis: given, or :data:`RELATIVE_TOLERANCE` of the axis's range (of its value where
    it has one value)."""
    if tolerance is not None:
        values = tuple(float(t) for t in (tolerance if isinstance(tolerance, Sequence) else (tolerance,) * 2))
        if len(values) != 2 or not all(np.isfinite(v) and v > 0 for v in values):
            raise GearsymError(f"tolerance must be one or two positive numbers (per axis), got {tolerance!r}")
        return values
    out = []
    for values in (grid.a, grid.b):
        span = float(values.max() - values.min())
        out.append(RELATIVE_TOLERANCE * (span or max(1.0, float(np.abs(values).max()))))
    return tuple(out)


def chart_axes(model_parameters: Sequence[str], grid) -> tuple[Axis, ...]:
    """The chart's two axes, checked against the model's parameters."""
    axes = axes_from(grid)
    if len(axes) != 2:
        raise GearsymError(f"a stability chart has two axes, got {len(axes)} ({', '.join(a.name for a in axes)}); "
                           "for a line give the second one value (--param k_a=0.2, {'k_a': [0.2]})")
    for ax in axes:
        if ax.name not in model_parameters:
            raise GearsymError(f"{ax.name} is not a parameter of the model (parameters: {', '.join(model_parameters)})")
        if ax.name.endswith(STATIC_SUFFIX):
            raise GearsymError(f"{ax.name} is where the linearisation is taken, not a parameter to chart")
    return axes


def static_chart(lin: CompiledLinearisation, grid, *, refine: bool = True, tolerance=None,
                 execution: Execution | None = None, **values: float) -> StabilityChart:
    """The chart of a compiled linearisation (:func:`compile_linearisation`) over ``grid`` (two axes of the
    model's parameters), the other parameters at ``values`` or the model's. ``execution``: threads, the lanes (on
    by default) and progress (each stage's points done)."""
    execution = execution or Execution()
    names = tuple(lin.base_parameters)
    axes = chart_axes(names, grid)
    merged = _values(lin.base_parameters, values, lin.base)
    base = np.array([merged[n] for n in names], dtype=float)
    g = _Grid(names, base, axes)
    problem = _Static(lin, g, execution.with_lanes(True), execution.jobs, execution.verbose)
    return chart_of(problem, g, model=lin.base, steps=lin.model.steps_per_cycle, parameters=merged,
                    refine_boundaries=refine, tolerance=tolerance, progress=stage_progress(execution))


def orbit_chart(model: CompiledModel, recipe: StaticRecipe, grid, *, refine: bool = True, tolerance=None,
                execution: Execution | None = None, **values: float) -> StabilityChart:
    """The chart of ``model``'s period-1 orbits over ``grid`` (see :func:`static_chart`)."""
    execution = execution or Execution()
    names = tuple(model.parameter_names)
    axes = chart_axes(names, grid)
    merged = dict(zip(names, model.parameter_vector(values).tolist()))
    g = _Grid(names, np.array([merged[n] for n in names]), axes)
    problem = _Orbit(model, recipe, g, execution.with_lanes(True), execution.jobs, execution.verbose)
    return chart_of(problem, g, model=model.name, steps=model.steps_per_cycle, parameters=merged,
                    refine_boundaries=refine, tolerance=tolerance, progress=stage_progress(execution))


#: at most one progress line this often (seconds), and the last of each stage
PROGRESS_EVERY = 0.5


def stage_progress(execution: Execution) -> Callable[[str, int, int], None] | None:
    """``progress(stage, done, total)`` for :func:`chart_of`: a line ``'<stage>: <done>/<total>'`` said through
    ``execution`` at most every PROGRESS_EVERY seconds (and when a stage ends); None without progress."""
    if not execution.progress:
        return None
    say, last = execution.say, [-PROGRESS_EVERY]

    def progress(stage: str, done: int, total: int) -> None:
        now = time.perf_counter()
        if now - last[0] >= PROGRESS_EVERY or done >= total:
            last[0] = now
            say(f"{stage}: {done}/{total}")

    return progress


def _values(parameters: Mapping[str, float], values: Mapping[str, float], model: str) -> dict[str, float]:
    unknown = [k for k in values if k not in parameters]
    if unknown:
        raise GearsymError(f"{model}: no parameter {', '.join(unknown)} (parameters: {', '.join(parameters)})")
    return {**{k: float(v) for k, v in parameters.items()}, **{k: float(v) for k, v in values.items()}}
