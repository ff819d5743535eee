"""Basins of attraction: which attractor each start of a grid reaches, identified by what it is.

A grid over two states (the others held) gives the starts. Each runs ``discard`` periods of transient and
``measured`` more, L at a time in the lanes (:mod:`gearsym.codegen.lane_runs`; no tangent vectors), recording
its Poincare points (the state at t0 + kT) and every period's extremes. Then, start by start:

* **diverged**: a record that is not finite (the verdict ``diverged`` of :mod:`gearsym.analysis.regime`). Its own
  class.
* **periodic**: the last ``TAIL`` Poincare points repeat with a period k <= ``MAX_PERIOD`` forcing periods to
  ``PERIOD_TOLERANCE`` (in coordinates scaled by the spread of every start's points, as
  :func:`~gearsym.analysis.attractors.find_attractors` scales them, or by the spread of the starts where that
  is larger: every start may end on one orbit). Two periodic starts are one attractor when
  their period is the same and their k points coincide as sets (Hausdorff distance within ``MATCH_TOLERANCE``):
  an orbit reached at another phase visits the same points in another order.
* **undetermined**: neither periodic nor settled: the recurrence of its best period still shrinks along the tail
  (``CONVERGING``: a periodic orbit not yet reached), or the first and the second half of its measured points
  are not one cloud by :func:`~gearsym.analysis.attractors.find_attractors`' rule (a transient still moving).
  Its own class, the verdict ``undetermined`` of :mod:`gearsym.analysis.regime` (a transient, or too few periods
  to say): more periods (``--periods``) decide it.
* **aperiodic** (chaotic, quasi-periodic, or periodic beyond ``MAX_PERIOD``): its points are a cloud; two
  starts are one attractor by :func:`~gearsym.analysis.attractors.find_attractors`' rule (cloud distance within
  twice the larger self distance, plus 1 % of the extent), compared with each attractor's first member.

So attractors are matched across starts by their Poincare sets, not by where a run happens to end. Each
attractor's exponents are computed once, from the final state of its first member (on the attractor): a
tangent run of the same length (:func:`~gearsym.analysis.lyapunov.lyapunov_spectrum`), which gives its regime;
its period is the one its Poincare points show; its amplitude the mean of its members'. A fraction's standard
error is the binomial sqrt(f (1 - f) / N), as for N starts drawn at random in the grid's box: a fine grid
resolves the boundaries better than that.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..checks import json_safe
from ..codegen import CompiledModel, engine_verb
from ..codegen.lane_runs import CHUNK, LaneRunner, chunked, finite_rows, threaded
from ..errors import GearsymError, suggest
from ..options import Execution, Integration
from .attractors import MERGE_FACTOR, MERGE_FLOOR, RESOLUTION
from .lyapunov import lyapunov_spectrum
from .regime import DIVERGED as DIVERGED_VERDICT, UNDETERMINED as UNDETERMINED_VERDICT

#: the run of each start when no options are given (the paper's run)
RUN = {"periods": 400, "discard": 100}
#: the longest period (in forcing periods) told from the Poincare points; longer ones are clouds
MAX_PERIOD = 16
#: the last Poincare points of a start compared for its period
TAIL = 2 * MAX_PERIOD
#: Poincare points of a start kept for comparing clouds (evenly over its measured periods)
CLOUD = 64
#: a start is periodic when its tail repeats to this (scaled coordinates: units of the spread of all points)
PERIOD_TOLERANCE = 1e-3
#: two periodic starts are one attractor when their points coincide to this
MATCH_TOLERANCE = 1e-2
#: two periodic groups whose point sets are within this of each other are one attractor (one orbit, approached
#: along a slowly decaying spiral, looks periodic with a multiple of its period first)
ORBIT_MERGE = 5e-2
#: a start whose best recurrence error over the second half of its tail is below this fraction of the first
#: half's still converges: undetermined
CONVERGING = 0.1
#: starts at most (each keeps ~1-2 KB of records until it is classified)
MAX_STARTS = 1_000_000
#: the labels of the two classes that are not attractors
DIVERGED, UNDETERMINED = -1, 0
CLASSES = {DIVERGED: DIVERGED_VERDICT, UNDETERMINED: UNDETERMINED_VERDICT}


@dataclass(frozen=True)
class Fraction:
    """How many starts of the grid went one way, as a fraction with its standard error."""

    starts: int
    total: int

    @property
    def fraction(self) -> float:
        return self.starts / self.total if self.total else 0.0

    @property
    def stderr(self) -> float:
        f = self.fraction
        return math.sqrt(f * (1 - f) / self.total) if self.total else 0.0

    def as_dict(self) -> dict:
        return {"fraction": self.fraction, "stderr": self.stderr, "starts": self.starts}


@dataclass(frozen=True)
class BasinAttractor:
    """One attractor of a basin map: its basin's share of the grid and what it is."""

    number: int  # 1-based: most starts first
    basin: Fraction
    period: int | None  # forcing periods per repetition, from its Poincare points (None: not periodic up to MAX_PERIOD)
    regime: str  # from its exponents (gearsym.analysis.regime)
    amplitude: dict[str, float]  # mean over its starts of A = (max - min)/2 over the measured periods
    exponents: np.ndarray  # from one tangent run on it, descending
    exponents_stderr: np.ndarray
    points: np.ndarray  # (n, k): its Poincare points (periodic: the orbit's; else up to CLOUD of a few members')
    representative: dict[str, float]  # the first start that reached it (its final state started the exponents)

    @property
    def fraction(self) -> float:
        return self.basin.fraction

    @property
    def stderr(self) -> float:
        return self.basin.stderr

    @property
    def description(self) -> str:
        """'period 2', 'chaotic', ... in a few words."""
        if self.period:
            return f"period {self.period}" + ("" if self.regime == "periodic" else f", {self.regime}")
        return self.regime if self.regime != "periodic" else f"periodic (period > {MAX_PERIOD})"

    def as_dict(self, state_names: Sequence[str]) -> dict:
        return {"number": self.number, **self.basin.as_dict(), "period": self.period, "regime": self.regime,
                "amplitude": self.amplitude, "exponents": json_safe(self.exponents),
                "exponents_stderr": json_safe(self.exponents_stderr), "representative": self.representative,
                "points": {n: json_safe(row) for n, row in zip(state_names, self.points)}}


@dataclass(frozen=True)
class BasinMap:
    """The attractor each start of a grid reaches (``labels``), and the attractors with their basins' shares."""

    model: str
    parameters: dict[str, float]
    state_names: tuple[str, ...]
    axes: tuple[tuple[str, np.ndarray], ...]  # ((x, values), (y, values)): the grid's two states
    held: dict[str, float]  # the other states' start
    labels: np.ndarray  # (len(y values), len(x values)): attractor number, 0 undetermined, -1 diverged
    attractors: tuple[BasinAttractor, ...]
    diverged: Fraction
    undetermined: Fraction
    scale: np.ndarray  # per state: the spread the tolerances are in units of
    periods: int
    discard: int
    steps_per_period: int
    period: float
    backend: str
    locate_crossings: bool
    lanes: int  # trajectories per native call (1: the scalar loops)
    method: dict = field(default_factory=dict)

    @property
    def starts(self) -> int:
        return int(self.labels.size)

    @property
    def fractions(self) -> dict[str, float]:
        """Every class's share: the attractors by number, then diverged and undetermined (they sum to 1)."""
        return {**{str(a.number): a.fraction for a in self.attractors}, "diverged": self.diverged.fraction,
                "undetermined": self.undetermined.fraction}

    def as_dict(self, labels: bool = True) -> dict:
        (x, xs), (y, ys) = self.axes
        data = {
            "model": self.model, "parameters": self.parameters, "states": list(self.state_names),
            "grid": {x: json_safe(xs), y: json_safe(ys), "held": self.held, "starts": self.starts},
            "attractors": [a.as_dict(self.state_names) for a in self.attractors],
            "diverged": self.diverged.as_dict(), "undetermined": self.undetermined.as_dict(),
            "periods": self.periods, "discard": self.discard, "steps_per_period": self.steps_per_period,
            "period": self.period, "backend": self.backend, "locate_crossings": self.locate_crossings,
            "lanes": self.lanes, "scale": dict(zip(self.state_names, map(float, self.scale))), "method": self.method,
        }
        if labels:
            data["labels"] = self.labels.tolist()  # rows: the values of the second state; columns: the first's
        return data

    @classmethod
    def from_dict(cls, data: dict) -> "BasinMap":
        """The map :meth:`as_dict` wrote (with its labels), read back: JSON's floats give the same bits."""
        states = tuple(data["states"])
        grid = data["grid"]
        names = [k for k in grid if k not in ("held", "starts")]

        def array(values):
            return np.array([np.nan if v is None else v for v in values], dtype=float)

        attractors = tuple(BasinAttractor(
            number=a["number"], basin=Fraction(a["starts"], grid["starts"]), period=a["period"], regime=a["regime"],
            amplitude=dict(a["amplitude"]), exponents=array(a["exponents"]),
            exponents_stderr=array(a["exponents_stderr"]),
            points=np.array([array(a["points"][s]) for s in states]).reshape(len(states), -1),
            representative=dict(a["representative"])) for a in data["attractors"])
        return cls(data["model"], dict(data["parameters"]), states,
                   tuple((n, np.array(grid[n], dtype=float)) for n in names), dict(grid["held"]),
                   np.array(data["labels"], dtype=int), attractors,
                   Fraction(data["diverged"]["starts"], grid["starts"]),
                   Fraction(data["undetermined"]["starts"], grid["starts"]),
                   np.array([data["scale"][s] for s in states]), data["periods"], data["discard"],
                   data["steps_per_period"], data["period"], data["backend"], data["locate_crossings"], data["lanes"],
                   dict(data["method"]))


class StartGrid:
    """The starts of basin maps: ``values`` ({state: values} for two states) at any parameter values, and how they
    were ``given`` (for the record: e.g. the command line's ``x=-5:5:0.1``; by default the values themselves). A
    grid whose engine values move with the parameters (a grid in physical units, whose rates' unit moves with the
    speed: :class:`~gearsym.physical.basins.GivenGrid`) is a subclass that overrides :meth:`at`, which
    :func:`basin_map` asks where it makes the starts, at the parameter values of its run."""

    def __init__(self, values: Mapping[str, Sequence[float]], given: Sequence[str] = ()):
        self.values, self.given = values, tuple(given)

    @classmethod
    def of(cls, grid: "Mapping[str, Sequence[float]] | StartGrid") -> "StartGrid":
        """``grid`` as a :class:`StartGrid` (a mapping of values: the same at every point, given as those values)."""
        return grid if isinstance(grid, StartGrid) else cls(grid)

    def at(self, point: Mapping[str, float]) -> Mapping[str, Sequence[float]]:
        """The grid at the parameter values ``point``."""
        return self.values

    @property
    def record(self) -> list | dict:
        """How the grid stands in a record (a continuation's): as it was given, else its values."""
        if self.given:
            return list(self.given)
        return {k: np.asarray(v, dtype=float).tolist() for k, v in self.values.items()}


# ------------------------------------------------------------------------------------------ entry point
@engine_verb(default=Integration(**RUN))
def basin_map(model: CompiledModel, grid: Mapping[str, Sequence[float]] | StartGrid, *,
              options: Integration | None = None, y0=None, execution: Execution | None = None,
              **values: float) -> BasinMap:
    """The basin map of ``model`` on ``grid`` ({state: values} for two states, e.g. ``{"x": xs, "v": vs}``, or a
    :class:`StartGrid`, whose values are taken at this run's parameters; the other states start where ``y0`` says,
    default the model's initial state) at the parameter ``values``.

    Every start runs ``options.discard`` periods and is classified from the ``options.measured`` after them
    (module docstring); ``execution``: its ``jobs`` threads run the lanes (0: one per core); ``lanes=False`` runs
    the scalar loops start by start (the same numbers, slower); with ``progress`` a first compile of the lanes is
    said."""
    options = model.run_options(options)
    execution = execution or Execution()
    p = model.parameter_vector(values)  # names and values checked before any run
    point = dict(zip(model.parameter_names, map(float, p)))
    axes, held, starts = grid_starts(model, StartGrid.of(grid).at(point), y0)
    inputs = model.prepare(p)
    runner = LaneRunner(model, options.discard, options.measured, lanes=execution.with_lanes(True),
                        verbose=execution.verbose)
    chunks = chunked(len(starts), CHUNK * runner.width)
    summary = Summary.join(list(threaded(lambda rows: Summary.of(runner.orbits(starts[rows], inputs)), chunks,
                                         execution.jobs)))
    labels, groups, scale = classify(summary, starts)
    attractors = _attractors(model, options, point, summary, starts, labels, groups)
    shape = (len(axes[1][1]), len(axes[0][1]))
    counts = {k: int(np.sum(labels == k)) for k in (DIVERGED, UNDETERMINED)}
    return BasinMap(
        model=model.name, parameters=point, state_names=model.state_names, axes=axes, held=held,
        labels=_renumbered(labels, attractors).reshape(shape), attractors=tuple(a for a, _ in attractors),
        diverged=Fraction(counts[DIVERGED], len(starts)), undetermined=Fraction(counts[UNDETERMINED], len(starts)),
        scale=scale, periods=options.periods, discard=options.discard, steps_per_period=model.steps_per_period,
        period=inputs.period, backend=model.backend, locate_crossings=model.options.locate_crossings,
        lanes=runner.width, method=method())


#: bump when the classification changes for the same constants (records of maps and continuations carry it)
CLASSIFIER = 4  # 4: the class "undecided" is the verdict "undetermined" of gearsym.analysis.regime


def method() -> dict:
    """The classification's constants, for the record."""
    return {"classifier": CLASSIFIER, "max_period": MAX_PERIOD, "tail": TAIL, "cloud": CLOUD, "period_tolerance": PERIOD_TOLERANCE,
            "match_tolerance": MATCH_TOLERANCE, "orbit_merge": ORBIT_MERGE, "converging": CONVERGING, "merge_factor": MERGE_FACTOR,
            "resolution": RESOLUTION, "merge_floor": MERGE_FLOOR}


def grid_starts(model: CompiledModel, grid: Mapping[str, Sequence[float]], y0=None):
    """((x, values), (y, values)), the held states and the starts (rows: y slowest, x fastest)."""
    if not isinstance(grid, Mapping) or len(grid) != 2:
        raise GearsymError(f"a basin map needs a grid over two states (e.g. {{'x': xs, 'v': vs}}), got "
                           f"{list(grid) if isinstance(grid, Mapping) else type(grid).__name__}")
    names = list(grid)
    for name in names:
        if name not in model.state_names:
            raise GearsymError(f"--grid {name}: not a state of {model.name}.{suggest(name, model.state_names)} "
                               f"States are {', '.join(model.state_names)}")
    axes = []
    for name in names:
        values = np.asarray(grid[name], dtype=float).reshape(-1)
        if values.size == 0 or not np.isfinite(values).all():
            raise GearsymError(f"--grid {name}: the values must be finite numbers, at least one")
        axes.append((name, values))
    count = axes[0][1].size * axes[1][1].size
    if count > MAX_STARTS:
        raise GearsymError(f"the grid has {count} starts ({axes[0][1].size} x {axes[1][1].size}); at most "
                           f"{MAX_STARTS} are kept in memory: use a coarser step")
    base = model.initial_state(y0)
    held = {s: float(v) for s, v in zip(model.state_names, base) if s not in names}
    (x, xs), (y, ys) = axes
    starts = np.tile(base, (count, 1))
    starts[:, model.state_names.index(x)] = np.tile(xs, ys.size)
    starts[:, model.state_names.index(y)] = np.repeat(ys, xs.size)
    return tuple(axes), held, starts


# ------------------------------------------------------------------------------------------ per start
@dataclass(frozen=True)
class Summary:
    """What the classification keeps of each start's records (a few KB, whatever the run length)."""

    finite: np.ndarray  # (starts,)
    tail: np.ndarray  # (starts, TAIL, n): the last Poincare points
    cloud: np.ndarray  # (starts, CLOUD, n): Poincare points evenly over the measured periods
    amplitude: np.ndarray  # (starts, observed)
    final: np.ndarray  # (starts, n)

    @classmethod
    def of(cls, records) -> "Summary":
        strobe = records.strobe
        measured = strobe.shape[1]
        cloud = strobe[:, np.linspace(0, measured - 1, min(CLOUD, measured)).round().astype(int)]
        amplitude = (records.high.max(axis=1) - records.low.min(axis=1)) / 2
        return cls(finite_rows(records), strobe[:, -min(TAIL, measured):].copy(), cloud, amplitude,
                   records.final.copy())

    @classmethod
    def join(cls, parts: list["Summary"]) -> "Summary":
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.__dataclass_fields__))


def scales(summary: Summary, starts: np.ndarray) -> np.ndarray:
    """Per state: the spread of every finite start's points, or of the starts if that is larger (every start
    may end on one orbit), floored as find_attractors floors it."""
    pooled = summary.cloud[summary.finite].reshape(-1, summary.cloud.shape[2])
    spread = starts.std(axis=0)
    if pooled.size == 0:
        return np.maximum(spread, 1.0)
    return np.maximum(np.maximum(pooled.std(axis=0), spread), 1e-3 * (1.0 + np.abs(pooled.mean(axis=0))))


def recurrence(tail: np.ndarray, k: int) -> np.ndarray:
    """Per start, the largest |point - point k periods before| along the tail (max over states)."""
    return np.abs(tail[:, k:] - tail[:, :-k]).max(axis=(1, 2))


def periods_of(tail: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per start (scaled tails), its period (0: none up to MAX_PERIOD) and whether its best recurrence still
    shrinks along the tail (``CONVERGING``)."""
    count, length = tail.shape[:2]
    period, converging = np.zeros(count, dtype=int), np.zeros(count, dtype=bool)
    best, best_k = np.full(count, np.inf), np.ones(count, dtype=int)
    for k in range(1, min(MAX_PERIOD, length // 2) + 1):
        error = recurrence(tail, k)
        found = (period == 0) & (error <= PERIOD_TOLERANCE)
        period[found] = k
        better = error < best
        best[better], best_k[better] = error[better], k
    half = length // 2
    for k in sorted(set(best_k[period == 0].tolist())):  # (not np.unique: it imports numpy.ma, 0.1 s)
        rows = (period == 0) & (best_k == k)
        if half >= 2 * k:  # (each half compares at least half its points: a maximum over a few is chance)
            first = recurrence(tail[rows, :half], k)
            second = recurrence(tail[rows, half:], k)
            converging[rows] = second < CONVERGING * first
    return period, converging


def directed_mean_nn(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per cloud of ``a`` (count, n, p), the mean over its points of the distance to the nearest point of the
    cloud of ``b`` (count or 1, n, q): :func:`~gearsym.analysis.attractors.cloud_distance`'s measure, for many
    clouds at once."""
    center = a.mean(axis=2, keepdims=True)
    a, b = a - center, b - center
    d2 = (a * a).sum(axis=1)[:, :, None] + (b * b).sum(axis=1)[:, None, :] - 2.0 * (a.transpose(0, 2, 1) @ b)
    return np.sqrt(np.maximum(d2.min(axis=2), 0.0)).mean(axis=1)


def distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`~gearsym.analysis.attractors.cloud_distance` of each cloud of ``a`` to its own of ``b`` (or to the
    one cloud of ``b``)."""
    if len(b) != len(a):
        b = np.broadcast_to(b, (len(a), *b.shape[1:]))
    return np.maximum(directed_mean_nn(a, b), directed_mean_nn(b, a))


def self_distances(clouds: np.ndarray) -> np.ndarray:
    """:func:`~gearsym.analysis.attractors.self_distance` of each cloud (count, n, p): first half against second."""
    half = clouds.shape[2] // 2
    if half == 0:
        return np.zeros(len(clouds))
    return distances(clouds[:, :, :half], clouds[:, :, half:])


def extents(clouds: np.ndarray) -> np.ndarray:
    """:func:`~gearsym.analysis.attractors.extent` of each cloud (count, n, p)."""
    return (clouds.max(axis=2) - clouds.min(axis=2)).max(axis=1)


def settled(clouds: np.ndarray) -> np.ndarray:
    """Per start (scaled points in time order, (count, n, p)), whether the first and the second half of its
    points are one cloud by find_attractors' rule: not a transient still moving."""
    half = clouds.shape[2] // 2
    if half < 4:
        return np.ones(len(clouds), dtype=bool)
    a, b = clouds[:, :, :half], clouds[:, :, half:]
    limit = MERGE_FACTOR * np.maximum(self_distances(a), self_distances(b)) + RESOLUTION * extents(clouds) \
        + MERGE_FLOOR
    return distances(a, b) <= limit


def hausdorff(sets: np.ndarray, one: np.ndarray) -> np.ndarray:
    """Per set of ``sets`` (count, k, n), its Hausdorff distance (max-norm) to the set ``one`` (k, n)."""
    d = np.abs(sets[:, :, None, :] - one[None, None, :, :]).max(axis=3)  # (count, k, k)
    return np.maximum(d.min(axis=2).max(axis=1), d.min(axis=1).max(axis=1))


def classify(summary: Summary, starts: np.ndarray) -> tuple[np.ndarray, list[tuple[list[int], int]], np.ndarray]:
    """Per start a label (DIVERGED, UNDETERMINED, or a provisional attractor number from 1), the attractors' members
    (in start order, first member first) with their period (0: a cloud), and the scale the tolerances are in
    units of."""
    scale = scales(summary, starts)
    count = summary.finite.size
    labels = np.full(count, UNDETERMINED, dtype=int)
    labels[~summary.finite] = DIVERGED
    finite = np.flatnonzero(summary.finite)
    tail = summary.tail[finite] / scale
    period, converging = periods_of(tail)
    groups: list[tuple[list[int], int]] = []
    # periodic starts: the same period and the same points (as sets)
    for k in sorted(set(period[period > 0].tolist())):
        rows = np.flatnonzero(period == k)
        sets = tail[rows, -k:]
        left = np.ones(rows.size, dtype=bool)
        while left.any():
            first = int(np.argmax(left))
            same = left & (hausdorff(sets, sets[first]) <= MATCH_TOLERANCE)
            groups.append((list(finite[rows[same]]), int(k)))
            left &= ~same
    groups = _merged_orbits(groups, tail, finite)
    # a start still converging whose last points are already on a periodic attractor's (to MATCH_TOLERANCE) joins it
    slow = np.flatnonzero((period == 0) & converging)
    for members, k in list(groups):
        if slow.size and tail.shape[1] >= k:
            near = hausdorff(tail[slow, -k:], tail[np.searchsorted(finite, members[0]), -k:]) <= MATCH_TOLERANCE
            members += list(finite[slow[near]])
            slow = slow[~near]
    # the rest: clouds; those settled compared with each cloud attractor's first member; one not settled joins
    # the attractor it is one cloud with, else it is undetermined (a transient still moving)
    rest = np.flatnonzero((period == 0) & ~converging)
    clouds = _batched_clouds(summary, finite[rest], scale)
    still = np.concatenate([settled(clouds[at:at + BATCH]) for at in range(0, rest.size, BATCH)]) \
        if rest.size else np.zeros(0, dtype=bool)
    selfs, sizes = _batched(self_distances, clouds), extents(clouds)
    lows, highs = clouds.min(axis=2), clouds.max(axis=2)
    left = still.copy()
    cloud_groups = []
    while left.any():  # the attractors, from the settled clouds
        first = int(np.argmax(left))
        same = _same_cloud(clouds, selfs, sizes, lows, highs, first, left)
        cloud_groups.append(list(same))
        left[same] = False
    left = ~still
    for members in cloud_groups:  # a cloud not settled joins the attractor it is one cloud with
        same = _same_cloud(clouds, selfs, sizes, lows, highs, members[0], left)
        members += list(same)
        left[same] = False
    cloud_groups = [list(finite[rest[members]]) for members in cloud_groups]
    groups += [(members, 0) for members in cloud_groups]
    groups.sort(key=lambda g: g[0][0])
    for number, (members, _) in enumerate(groups, 1):
        labels[members] = number
    return labels, groups, scale


def set_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The Hausdorff distance (max-norm) between two sets of points, (k1, n) and (k2, n)."""
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def _merged_orbits(groups: list[tuple[list[int], int]], tail: np.ndarray, finite: np.ndarray):
    """Periodic groups whose point sets lie within ``ORBIT_MERGE`` of each other are one attractor: a weakly
    stable orbit approached along a slowly decaying spiral looks periodic with a multiple of its period (its k
    points ring the orbit's) before it has converged. The merged group is the shortest period's: its first member
    first (whose points and final state stand for the attractor), then the others in start order."""
    if len(groups) < 2:
        return groups
    sets = [tail[np.searchsorted(finite, members[0]), -k:] for members, k in groups]
    parent = list(range(len(groups)))

    def root(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(groups)):
        for j in range(i + 1, len(groups)):
            if root(i) != root(j) and set_distance(sets[i], sets[j]) <= ORBIT_MERGE:
                parent[max(root(i), root(j))] = min(root(i), root(j))
    merged: dict[int, list[int]] = {}
    for i in range(len(groups)):
        merged.setdefault(root(i), []).append(i)
    out = []
    for parts in merged.values():
        shortest = min(parts, key=lambda i: (groups[i][1], groups[i][0][0]))
        first = groups[shortest][0][0]
        out.append(([first, *sorted(m for i in parts for m in groups[i][0] if m != first)], groups[shortest][1]))
    return out


#: clouds compared at once (a few MB of distances)
BATCH = 512


def _batched_clouds(summary: Summary, rows: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """The scaled clouds of ``rows``, (count, n, points)."""
    if not rows.size:
        return np.zeros((0, scale.size, max(1, summary.cloud.shape[1])))
    return np.concatenate([_scaled_clouds(summary, rows[at:at + BATCH], scale) for at in range(0, rows.size, BATCH)])


def _same_cloud(clouds, selfs, sizes, lows, highs, first: int, among: np.ndarray) -> np.ndarray:
    """The clouds of ``among`` (a mask) that are one with cloud ``first`` by find_attractors' rule."""
    limit = MERGE_FACTOR * np.maximum(selfs, selfs[first]) + RESOLUTION * np.maximum(sizes, sizes[first]) + MERGE_FLOOR
    gap = np.max(np.maximum(lows - highs[first], lows[first] - highs), axis=1)
    near = np.flatnonzero(among & (gap <= limit))
    return near[_batched(lambda c: distances(c, clouds[first:first + 1]), clouds[near]) <= limit[near]]


def _scaled_clouds(summary: Summary, rows: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """The clouds of ``rows`` in scaled coordinates, (count, n, points)."""
    return (summary.cloud[rows] / scale).transpose(0, 2, 1).astype(float)


def _batched(f, clouds: np.ndarray) -> np.ndarray:
    """``f`` of ``clouds`` in batches of ``BATCH``."""
    if not len(clouds):
        return np.zeros(0)
    return np.concatenate([f(clouds[at:at + BATCH]) for at in range(0, len(clouds), BATCH)])


# ------------------------------------------------------------------------------------------ attractors
def _attractors(model: CompiledModel, options: Integration, values: dict, summary: Summary, starts: np.ndarray,
                labels: np.ndarray, groups: list[tuple[list[int], int]]) -> list[tuple[BasinAttractor, int]]:
    """Each group as an attractor (with its provisional label), its exponents from its first member's final
    state, numbered by basin size (then by its points)."""
    names = model.state_names
    drafts = []
    for label, (members, period) in enumerate(groups, 1):
        first = members[0]
        points = summary.tail[first, -period:].T if period else _cloud_points(summary, members)
        spectrum = lyapunov_spectrum(model, options=options, y0=summary.final[first], **values)
        amplitude = summary.amplitude[members].mean(axis=0)
        drafts.append((label, dict(
            basin=Fraction(len(members), labels.size), period=period or None, regime=spectrum.regime,
            amplitude=dict(zip(model.observed, map(float, amplitude))), exponents=spectrum.exponents,
            exponents_stderr=spectrum.stderr, points=points,
            representative=dict(zip(names, map(float, starts[first]))))))
    drafts.sort(key=lambda d: (-d[1]["basin"].starts, tuple(d[1]["points"].mean(axis=1))))
    return [(BasinAttractor(number=k, **d), label) for k, (label, d) in enumerate(drafts, 1)]


def _cloud_points(summary: Summary, members: list[int], limit: int = 4) -> np.ndarray:
    """A cloud attractor's points: those of its first few members, (n, points)."""
    return np.hstack([summary.cloud[i].T for i in members[:limit]]).astype(float)


def _renumbered(labels: np.ndarray, attractors: list[tuple[BasinAttractor, int]]) -> np.ndarray:
    """The provisional labels as the attractors' final numbers."""
    out = labels.copy()
    for a, label in attractors:
        out[labels == label] = a.number
    return out
