"""Coexisting attractors at one parameter point: many initial states, grouped by where they end up.

A single run from one initial state shows one attractor; a nonlinear gear pair
may have several at the same forcing frequency (the paper's Fig. 4: a regular
and a chaotic one at omega = 1.5), and which one a run finds depends on where it
starts. So :func:`find_attractors` starts ``ics`` runs from random initial
states, keeps each run's stroboscopic (Poincare) points after the transient,
and groups runs whose point sets coincide.

Grouping compares *sets*, not sequences: a period-2 orbit reached from two
initial states half a period apart visits the same two points in the other
order, and two runs on one chaotic attractor never share a point but fill the
same cloud. The distance between two clouds A and B is the larger of the two
directed mean nearest-neighbour distances (mean over a in A of the distance to
the nearest b in B, and the other way), in coordinates scaled by the spread of
all points together. Two runs are on the same attractor when that distance is
within ``merge_factor`` times the larger *self distance* of the two clouds (the
same measure between the first and the second half of one run: how finely a
finite sample resolves its own attractor), plus a fraction ``resolution`` (1 %)
of the larger cloud's extent, plus a tiny absolute floor (a converged periodic
orbit has self distance ~0, and a fixed point extent 0). The resolution term is
for quasi-periodic attractors: runs on one slowly turning invariant circle sit
at different phases of it for longer than any run. Runs are merged by single
linkage: A~B and B~C put all three together.
"""
from __future__ import annotations

import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import GearsymError, option, suggest
from ..checks import check_fits, json_safe, whole_number
from ..codegen import CompiledModel, engine_verb
from ..options import Integration
from .lane_spectra import lyapunov_spectra
from .lyapunov import LyapunovSpectrum
from .regime import classify_regime

#: the box initial states are drawn from, for every state the caller does not name
DEFAULT_BOX = (-5.0, 5.0)
#: two runs are one attractor if their cloud distance is within this many self distances ...
MERGE_FACTOR = 2.0
#: ... plus this fraction of the larger cloud's extent (the resolution of the comparison) ...
RESOLUTION = 1e-2
#: ... plus this absolute floor (in scaled coordinates: units of the pooled standard deviation)
MERGE_FLOOR = 1e-6
#: points of one cloud compared at most (evenly thinned beyond): keeps the pairwise distances small
MAX_POINTS = 400
#: distinct Poincare points of a periodic orbit: within this fraction of the attractor's extent is one point
PERIOD_TOLERANCE = 1e-2
#: the longest period (in forcing periods) reported; beyond it the period is None
MAX_PERIOD = 64

#: the run of each initial state when no options are given: a long transient before the runs are compared
RUN = {"periods": 500, "discard": 300}

#: the paper's labels in Fig. 4: '1' a regular attractor, '2' a chaotic one
PAPER_LABELS = {"periodic": "1", "quasi-periodic": "1", "equilibrium": "1", "undetermined": "1", "chaotic": "2",
                "hyperchaotic": "2"}


@dataclass(frozen=True)
class InitialConditionResult:
    """One run: where it started, what it measured, and which attractor (1-based number) it joined."""

    index: int
    initial_state: dict[str, float]
    attractor: int
    exponents: np.ndarray
    stderr: np.ndarray
    regime: str
    amplitude: dict[str, float]
    final_state: dict[str, float]
    strobe: np.ndarray  # (n, measured periods)

    def as_dict(self) -> dict:
        return {
            "index": self.index,
            "initial_state": self.initial_state,
            "attractor": self.attractor,
            "exponents": json_safe(self.exponents),
            "stderr": json_safe(self.stderr),
            "regime": self.regime,
            "amplitude": self.amplitude,
            "final_state": self.final_state,
        }


@dataclass(frozen=True)
class Attractor:
    """One attractor: the runs that reached it and what they measured together."""

    number: int  # 1-based, in the order of AttractorSet.attractors
    state_names: tuple[str, ...]
    members: tuple[int, ...]  # indices of the initial states that reached it
    initial_states: tuple[dict[str, float], ...]
    points: np.ndarray  # (n, all members' measured periods): the merged stroboscopic points
    exponents: np.ndarray  # mean over members, descending
    stderr: np.ndarray  # standard error of that mean (members' batch-means errors combined)
    regime: str  # periodic, quasi-periodic, chaotic, hyperchaotic (gearsym.analysis.regime)
    period: int | None  # periodic attractors: forcing periods per repetition (distinct Poincare points)
    amplitude: dict[str, float]  # mean over members of A = (max - min)/2
    centroid: dict[str, float]  # mean of the Poincare points

    @property
    def lambda1(self) -> float:
        return float(self.exponents[0])

    @property
    def lambda1_stderr(self) -> float:
        return float(self.stderr[0])

    @property
    def regular(self) -> bool:
        """Not chaotic: the paper's '1'."""
        return PAPER_LABELS.get(self.regime, "2") == "1"

    @property
    def paper_label(self) -> str:
        """'1' regular, '2' chaotic, as the paper marks its Fig. 4."""
        return PAPER_LABELS.get(self.regime, "2")

    @property
    def description(self) -> str:
        """'period 2', 'quasi-periodic', 'chaotic', ... in one short phrase."""
        if self.regime == "periodic":
            return f"period {self.period}" if self.period else f"periodic (period > {MAX_PERIOD} or unresolved)"
        return self.regime

    def as_dict(self, points: bool = False) -> dict:
        data = {
            "number": self.number,
            "members": list(self.members),
            "initial_states": list(self.initial_states),
            "regime": self.regime,
            "paper_label": self.paper_label,
            "period": self.period,
            "exponents": json_safe(self.exponents),
            "stderr": json_safe(self.stderr),
            "amplitude": self.amplitude,
            "centroid": self.centroid,
            "point_count": int(self.points.shape[1]),
        }
        if points:
            data["points"] = {n: row.tolist() for n, row in zip(self.state_names, self.points)}
        return data


@dataclass(frozen=True)
class AttractorSet:
    """Every attractor found at one parameter point, and every run that found them."""

    model: str
    parameters: dict[str, float]
    state_names: tuple[str, ...]
    attractors: tuple[Attractor, ...]  # most members first, then by centroid
    results: tuple[InitialConditionResult, ...]  # one per initial state, in the order they were given
    periods: int  # forcing periods per run, the transient included (as everywhere)
    discard: int
    steps_per_period: int
    period: float
    backend: str
    seed: int | None  # None when the initial states were given explicitly
    box: dict[str, tuple[float, float]] | None
    grouping: dict[str, float] = field(default_factory=dict)  # merge_factor, merge_floor, scale per state

    def __len__(self) -> int:
        return len(self.attractors)

    @property
    def measured(self) -> int:
        """Periods each run measures, after its transient."""
        return self.periods - self.discard

    def __iter__(self):
        return iter(self.attractors)

    @property
    def assignment(self) -> np.ndarray:
        """The attractor number of each initial state."""
        return np.array([r.attractor for r in self.results], dtype=int)

    def as_dict(self, points: bool = False) -> dict:
        """JSON-ready: the keys of ``gearsym poincare --format json`` (``points``: also every Poincare point)."""
        return {
            "model": self.model,
            "parameters": self.parameters,
            "states": list(self.state_names),
            "attractors": [a.as_dict(points) for a in self.attractors],
            "initial_conditions": [r.as_dict() for r in self.results],
            "periods": self.periods,
            "discard": self.discard,
            "steps_per_period": self.steps_per_period,
            "period": self.period,
            "backend": self.backend,
            "seed": self.seed,
            "box": None if self.box is None else {k: list(v) for k, v in self.box.items()},
            "grouping": self.grouping,
        }


# ------------------------------------------------------------------------------------------ entry point
@engine_verb(default=Integration(**RUN))
def find_attractors(
    model: CompiledModel,
    *,
    options: Integration | None = None,
    ics: int = 10,
    seed: int = 0,
    box: Mapping[str, tuple[float, float]] | None = None,
    initial_states=None,
    merge_factor: float = MERGE_FACTOR,
    resolution: float = RESOLUTION,
    merge_floor: float = MERGE_FLOOR,
    **values: float,
) -> AttractorSet:
    """Run from many initial states and group the runs into distinct attractors.

    ``model`` is a :class:`CompiledModel` (``values`` are parameter values) or a system, as for
    :func:`~gearsym.analysis.lyapunov.lyapunov_spectrum`. The ``ics`` initial states are
    drawn uniformly from ``box`` (state name -> (low, high); every state not named
    spans ``DEFAULT_BOX`` = [-5, 5]) with ``numpy.random.default_rng(seed)``, so a
    seed gives the same states every time; or ``initial_states`` (a sequence of
    mappings or of full state vectors) replaces the random draw, and then ``ics``,
    ``seed`` and ``box`` are not used. Each run discards ``options.discard`` periods and
    measures the rest (exponents and Poincare points); a system is compiled by default for ``RUN``
    (500 periods, 300 discarded: a long transient, so that a run has settled on its attractor before
    it is compared).

    Two runs are one attractor when their clouds of Poincare points are closer
    than ``merge_factor`` self distances plus ``resolution`` times the cloud's
    extent plus ``merge_floor`` (see the module's docstring). The resolution term
    keeps one quasi-periodic attractor whole: its runs sit at different phases of
    a slowly turning invariant circle and share no points within a short run.
    Attractors closer than that are not told apart.
    """
    options = model.run_options(options)
    periods, discard = options.measured, options.discard
    for what, value in (("merge_factor", merge_factor), ("resolution", resolution), ("merge_floor", merge_floor)):
        if not (isinstance(value, numbers.Real) and np.isfinite(value) and value >= 0):
            raise GearsymError(f"{what} must be a finite number >= 0, got {value!r}")
    compiled = model
    p = compiled.parameter_vector(values)  # checks the names and values once, before any run

    if initial_states is not None:
        if box is not None:
            raise GearsymError("give either initial_states or a box to draw them from, not both")
        starts = _explicit_states(compiled, initial_states)
        used_seed, used_box = None, None
    else:
        ics = check_ics(ics, compiled.dimension, options.periods)
        seed = whole_number(seed, "seed")
        used_box = _full_box(compiled.state_names, box)
        low, high = (np.array([used_box[s][i] for s in compiled.state_names]) for i in (0, 1))
        starts = np.random.default_rng(seed).uniform(low, high, size=(ics, compiled.dimension))
        used_seed = seed

    spectra = lyapunov_spectra(compiled, starts, options, p)  # many at once, in the lanes
    _diverged(compiled, starts, spectra)
    clouds = [s.strobe for s in spectra]
    scale = _scales(clouds)
    groups = _group(clouds, scale, merge_factor, resolution, merge_floor)
    grouping = {"merge_factor": float(merge_factor), "resolution": float(resolution),
                "merge_floor": float(merge_floor), **{f"scale_{n}": float(v) for n, v in zip(compiled.state_names, scale)}}
    return _assemble(compiled, p, starts, spectra, groups, scale, periods, discard, used_seed, used_box, grouping)


# ------------------------------------------------------------------------------------------ inputs
def check_ics(ics, dimension: int, periods: int) -> int:
    """``ics`` as a count of initial states whose runs fit in memory together: each keeps its stroboscopic states
    and its exponents' running estimates over its ``periods`` until the runs are grouped."""
    ics = whole_number(ics, "ics (the number of initial states)", 1)
    check_fits(ics, 8 * dimension * (2 * periods + 1), asked=option("ics", ics), item="initial state",
               what="each run's Poincare points and exponents kept for the grouping")
    return ics


def _full_box(states: Sequence[str], box: Mapping[str, tuple[float, float]] | None) -> dict[str, tuple[float, float]]:
    """Every state's (low, high): the caller's, or DEFAULT_BOX; names and bounds checked."""
    full = {s: DEFAULT_BOX for s in states}
    for name, bounds in (box or {}).items():
        if name not in full:
            raise GearsymError(f"the box names {name!r}, which is not a state.{suggest(name, states)} "
                               f"States are {', '.join(states)}")
        try:
            low, high = (float(b) for b in bounds)
        except (TypeError, ValueError):
            raise GearsymError(f"the box of {name} must be two numbers (low, high), got {bounds!r}") from None
        if not (np.isfinite(low) and np.isfinite(high)):
            raise GearsymError(f"the box of {name} must be finite, got ({low}, {high})")
        if low >= high:
            raise GearsymError(f"the box of {name} needs low < high, got ({low:g}, {high:g}); "
                               "to fix a state, give initial_states instead")
        full[name] = (low, high)
    return full


def _explicit_states(compiled: CompiledModel, initial_states) -> np.ndarray:
    """The caller's initial states as an (ics, n) array, each checked like a run's y0."""
    states = [] if isinstance(initial_states, Mapping) else list(initial_states)
    if isinstance(initial_states, Mapping) or any(np.ndim(y0) == 0 and not isinstance(y0, Mapping) for y0 in states):
        raise GearsymError("initial_states must be a sequence of initial states (mappings or vectors), "
                           "one per run; for a single run use lyapunov_spectrum(..., y0=...)")
    if not states:
        raise GearsymError("initial_states is empty: give at least one initial state")
    return np.array([compiled.initial_state(y0) for y0 in states])


def _diverged(compiled: CompiledModel, starts: np.ndarray, spectra: Sequence[LyapunovSpectrum]) -> None:
    """The error of the first run that diverged: it has no attractor to be grouped with."""
    for index, (y0, spectrum) in enumerate(zip(starts, spectra)):
        if spectrum.divergence is not None:
            start = ", ".join(f"{n}={v:g}" for n, v in zip(compiled.state_names, y0))
            raise GearsymError(f"initial state #{index} ({start}): the motion diverged: "
                               f"{spectrum.divergence.describe(spectrum.period)}; start from a smaller box")


# ------------------------------------------------------------------------------------------ grouping
def _scales(clouds: Sequence[np.ndarray]) -> np.ndarray:
    """Per-coordinate scale: the spread of all points together, so that x and v weigh alike.

    Floored at 1e-3 (1 + |mean|): when every run ends on the same fixed point the
    spread is rounding noise, and scaling by it would blow the noise up to O(1).
    """
    pooled = np.hstack(clouds)
    return np.maximum(pooled.std(axis=1), 1e-3 * (1.0 + np.abs(pooled.mean(axis=1))))


def _thin(points: np.ndarray, limit: int = MAX_POINTS) -> np.ndarray:
    """At most ``limit`` columns, evenly spaced (deterministic)."""
    if points.shape[1] <= limit:
        return points
    return points[:, np.linspace(0, points.shape[1] - 1, limit).round().astype(int)]


def _directed_mean_nn(a: np.ndarray, b: np.ndarray) -> float:
    """Mean over the columns of ``a`` of the distance to the nearest column of ``b``."""
    center = a.mean(axis=1, keepdims=True)  # |a|^2 + |b|^2 - 2 a.b cancels badly far from the origin
    a, b = a - center, b - center
    d2 = (a * a).sum(axis=0)[:, None] + (b * b).sum(axis=0)[None, :] - 2.0 * (a.T @ b)
    return float(np.sqrt(np.maximum(d2.min(axis=1), 0.0)).mean())


def cloud_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Symmetric set distance: the larger directed mean nearest-neighbour distance.

    The larger, not the average: a periodic orbit lying inside a chaotic cloud is
    near the cloud (small one way) but the cloud is far from its few points.
    """
    return max(_directed_mean_nn(a, b), _directed_mean_nn(b, a))


def self_distance(cloud: np.ndarray) -> float:
    """The cloud distance between the first and the second half of one run.

    Halves in time, not alternate points: the alternate points of a period-2
    orbit are its two different points. Zero (rounding) for a converged periodic
    orbit; the sampling resolution for a chaotic one; the drift for a slowly
    converging one.
    """
    half = cloud.shape[1] // 2
    if half == 0:
        return 0.0
    return cloud_distance(_thin(cloud[:, :half]), _thin(cloud[:, half:]))


def extent(cloud: np.ndarray) -> float:
    """The largest coordinate range of a cloud (0 for a fixed point)."""
    return float(np.max(cloud.max(axis=1) - cloud.min(axis=1))) if cloud.size else 0.0


def _group(clouds: Sequence[np.ndarray], scale: np.ndarray, merge_factor: float, resolution: float,
           merge_floor: float) -> list[list[int]]:
    """Single-linkage groups of run indices (union-find), each group sorted.

    Two runs are linked when ``cloud_distance <= merge_factor * larger self distance
    + resolution * larger extent + merge_floor``. The bounding boxes are compared
    first: a gap g between them puts every nearest neighbour at least g away, so
    far-apart clouds never need the pairwise distances.
    """
    scaled = [c / scale[:, None] for c in clouds]
    selfs = [self_distance(c) for c in scaled]
    extents = [extent(c) for c in scaled]
    thinned = [_thin(c) for c in scaled]
    lows, highs = np.array([c.min(axis=1) for c in scaled]), np.array([c.max(axis=1) for c in scaled])
    parent = list(range(len(clouds)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(len(clouds)):
        for j in range(i + 1, len(clouds)):
            ri, rj = root(i), root(j)
            if ri == rj:
                continue
            limit = merge_factor * max(selfs[i], selfs[j]) + resolution * max(extents[i], extents[j]) + merge_floor
            gap = np.max(np.maximum(lows[i] - highs[j], lows[j] - highs[i]))
            if gap <= limit and cloud_distance(thinned[i], thinned[j]) <= limit:
                parent[max(ri, rj)] = min(ri, rj)
    groups: dict[int, list[int]] = {}
    for i in range(len(clouds)):
        groups.setdefault(root(i), []).append(i)
    return list(groups.values())


def distinct_points(points: np.ndarray, tolerance: float) -> int:
    """How many distinct points a set holds: greedy clusters of radius ``tolerance`` (max-norm)."""
    left = points
    count = 0
    while left.shape[1]:
        count += 1
        near = np.abs(left - left[:, :1]).max(axis=0) <= tolerance
        left = left[:, ~near]
        if count > MAX_PERIOD:
            break
    return count


def orbit_period(strobes: Sequence[np.ndarray], scale: np.ndarray) -> int | None:
    """The period, in forcing periods, of a periodic attractor; None if it has none up to MAX_PERIOD.

    The number of distinct Poincare points of all its runs together (a tolerance of
    PERIOD_TOLERANCE times the attractor's extent, at least 1e-9 in scaled units),
    confirmed on each run: the sequence must repeat after that many periods.
    """
    scaled = [s / scale[:, None] for s in strobes]
    merged = np.hstack(scaled)
    extent = float(np.max(merged.max(axis=1) - merged.min(axis=1)))
    tolerance = max(PERIOD_TOLERANCE * extent, 1e-9)
    k = distinct_points(merged, tolerance)
    if k > MAX_PERIOD:
        return None
    for s in scaled:
        if s.shape[1] > k and np.abs(s[:, k:] - s[:, :-k]).max() > tolerance:
            return None
    return k


# ------------------------------------------------------------------------------------------ results
def _group_regime(regime: str, runs: Sequence[LyapunovSpectrum]) -> str:
    """The regime of the members' mean spectrum, where the exponents cannot decide (quasi-periodic) decided as
    each member's Poincare points did (gearsym.analysis.regime): a torus only if every member says so,
    periodic if every member settled on its orbit, undetermined otherwise."""
    if regime != "quasi-periodic" or any(r.settling is None for r in runs):
        return regime
    if all(r.regime == "periodic" for r in runs):
        return "periodic"
    return regime if all(r.settling.decides for r in runs) else "undetermined"


def _assemble(compiled, p, starts, spectra, groups, scale, periods, discard, seed, box, grouping) -> AttractorSet:
    names = compiled.state_names
    autonomous = bool(getattr(compiled.system, "autonomous", False))
    measured_time = periods * spectra[0].period

    def state(y) -> dict[str, float]:
        return dict(zip(names, map(float, y)))

    drafts = []
    for members in groups:
        runs = [spectra[i] for i in members]
        points = np.hstack([r.strobe for r in runs])
        exponents = np.mean([r.exponents for r in runs], axis=0)
        stderr = np.sqrt(np.sum([np.square(r.stderr) for r in runs], axis=0)) / len(runs)
        regime = _group_regime(classify_regime(exponents, stderr, measured_time, autonomous), runs)
        period = orbit_period([r.strobe for r in runs], scale) if regime == "periodic" else None
        amplitude = {k: float(np.mean([r.amplitude[k] for r in runs])) for k in runs[0].amplitude}
        drafts.append(dict(members=tuple(members), points=points, exponents=exponents, stderr=stderr,
                           regime=regime, period=period, amplitude=amplitude,
                           centroid=state(points.mean(axis=1))))
    drafts.sort(key=lambda d: (-len(d["members"]), tuple(d["centroid"].values())))
    attractors = tuple(
        Attractor(number=k, state_names=names, initial_states=tuple(state(starts[i]) for i in d["members"]), **d)
        for k, d in enumerate(drafts, 1))
    number = {i: a.number for a in attractors for i in a.members}
    results = tuple(
        InitialConditionResult(
            index=i, initial_state=state(y0), attractor=number[i], exponents=r.exponents, stderr=r.stderr,
            regime=r.regime, amplitude=r.amplitude,
            final_state=r.final_state, strobe=r.strobe)
        for i, (y0, r) in enumerate(zip(starts, spectra)))
    first = spectra[0]
    return AttractorSet(
        model=compiled.name, parameters=dict(zip(compiled.parameter_names, map(float, p))), state_names=names,
        attractors=attractors, results=results, periods=discard + periods, discard=discard,
        steps_per_period=compiled.steps_per_period, period=first.period, backend=compiled.backend, seed=seed,
        box=box, grouping=grouping)
