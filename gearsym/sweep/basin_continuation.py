"""Basin fractions along a parameter: the basin map at each value, its attractors matched with the last value's.

At each value of the parameter :func:`~gearsym.analysis.basins.basin_map` maps the grid; each attractor found is
matched with one of the previous value's by the distance between their Poincare sets (the symmetric mean
nearest-neighbour distance of :func:`~gearsym.analysis.attractors.cloud_distance`, in coordinates scaled by the
two maps' spreads): the closest pairs first, each attractor in at most one pair, and only within
``match_distance``. A matched attractor keeps its id (``continues``); a new one gets the next id (``appears``);
a previous one left without a partner ``vanishes``, unless it lies within ``match_distance`` of one of the
new attractors, into which it then ``merges`` (two basins became one). This is the global continuation of
Attractors.jl (matching by the distance of attractors' sets) on Poincare sets.

What happened (an attractor appeared, merged or vanished: :attr:`BasinContinuation.events`) is said once,
by :func:`track`, where each value's attractors are matched.

With ``out`` the files are written after each value (``FILE.attractors.csv``: every attractor's Poincare points;
``FILE.csv``: one row per class and value; ``FILE.json``: how it was made and what happened), whole files each
time and in that order: a value is finished once the record counts it. The same call again resumes after the
last value finished (its rows from the CSV, what happened from the record) and gives the same files as a run
that was never interrupted (nothing in them depends on when or how fast it ran); a finished continuation is read
and nothing is written.
"""
from __future__ import annotations

import csv
import io
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from itertools import takewhile
from pathlib import Path

import numpy as np

from ..analysis.attractors import cloud_distance
from ..analysis.basins import RUN, BasinMap, StartGrid, basin_map, method
from ..checks import json_safe
from ..codegen import CompiledModel, engine_verb
from ..errors import GearsymError, UnknownParameterError
from ..files.atomic import write_atomically
from ..options import Execution, Integration
from ..version import __version__
from ..files.lock import release_lock, take_lock
from .store import number, read_rows, sidecar

#: two attractors at neighbouring values are one when their Poincare sets are within this distance (in units of
#: the spread of all points, as the basin maps scale them)
MATCH_DISTANCE = 0.5
#: what happens to an attractor at a value
CONTINUES, APPEARS, MERGES, VANISHES = "continues", "appears", "merges", "vanishes"


@dataclass(frozen=True)
class Tracked:
    """One class of starts at one value: an attractor (with its id across the values), or diverged/undetermined."""

    value: float
    kind: str  # "attractor", "diverged" or "undetermined"
    id: int | None
    fraction: float
    stderr: float
    starts: int
    period: int | None
    regime: str
    amplitude: dict[str, float]
    exponents: tuple[float, ...]
    event: str  # continues, appears, "merges 3" (attractor 3 of the last value merged into it); "" otherwise
    points: np.ndarray  # (n, k): its Poincare points (none for diverged/undetermined)
    scale: tuple[float, ...]  # per state: the spread of the value's map (what its distances are in units of)


@dataclass(frozen=True)
class BasinContinuation:
    """The classes of every value, in order, and what happened to the attractors along the way."""

    model: str
    parameter: str
    values: tuple[float, ...]
    state_names: tuple[str, ...]
    rows: tuple[Tracked, ...]
    events: tuple[dict, ...]  # {"value", "event", "attractor", "into"}
    record: dict
    path: Path | None = None

    @property
    def ids(self) -> list[int]:
        return sorted({r.id for r in self.rows if r.id is not None})

    def at(self, value: float) -> list[Tracked]:
        return [r for r in self.rows if r.value == value]

    def fractions(self, key: int | str) -> np.ndarray:
        """The fraction of attractor ``key`` (an id), or of "diverged" or "undetermined", at every value (0 where
        it does not exist)."""
        out = np.zeros(len(self.values))
        where = {v: i for i, v in enumerate(self.values)}
        for r in self.rows:
            if (r.id == key) if isinstance(key, int) else (r.kind == key):
                out[where[r.value]] = r.fraction
        return out

    def as_dict(self) -> dict:
        return json_safe({"model": self.model, "parameter": self.parameter, "values": list(self.values),
                          "rows": [_row_dict(r, self.parameter) for r in self.rows], "events": list(self.events),
                          "record": self.record})


def _row_dict(r: Tracked, parameter: str) -> dict:
    return {parameter: r.value, "class": r.kind, "attractor": r.id, "fraction": r.fraction, "stderr": r.stderr,
            "starts": r.starts, "period": r.period, "regime": r.regime, "amplitude": r.amplitude,
            "exponents": list(r.exponents), "event": r.event}


@engine_verb(default=Integration(**RUN))
def continue_basins(model: CompiledModel, grid: Mapping[str, Sequence[float]] | StartGrid, parameter: str,
                    values: Sequence[float], *, options: Integration | None = None, y0=None,
                    out: str | Path | None = None, overwrite: bool | str = False, execution: Execution | None = None,
                    match_distance: float = MATCH_DISTANCE, on_value: Callable[[BasinMap], None] | None = None,
                    **fixed: float) -> BasinContinuation:
    """Basin maps of ``model`` on ``grid`` at each of ``values`` of ``parameter`` (ascending), their attractors
    matched from one value to the next (module docstring). ``grid``: {state: values} for two states, or a
    :class:`StartGrid` (one that moves with the parameter, or says how it was given). ``out``: write the files as
    values finish and resume them (``overwrite``: start again). ``execution``: the maps' threads and lanes, and
    with ``progress`` a line per value. ``on_value(map)`` is called after each value is stored."""
    options = model.run_options(options)
    execution = execution or Execution()
    grid = StartGrid.of(grid)
    if parameter not in model.parameter_names:
        raise UnknownParameterError(parameter, model.parameter_names, f"{model.name}: --param")
    if parameter in fixed:
        raise GearsymError(f"{parameter} is both continued (--param) and fixed (--set); drop one")
    values = tuple(sorted(float(v) for v in values))
    if not values or len(set(values)) != len(values):
        raise GearsymError(f"--param {parameter}: give distinct values, at least one")
    for v in values:
        model.parameter_vector(fixed, **{parameter: v})  # every value checked before any run
    if not (np.isfinite(match_distance) and match_distance > 0):
        raise GearsymError(f"match_distance must be a positive number, got {match_distance!r}")
    record = {"model": model.name, "model_hash": model.hash, "backend": model.backend, "parameter": parameter,
              "values": list(values), "settings": {k: float(v) for k, v in fixed.items()},
              "grid": grid.record, "initial_state": dict(zip(
                  model.state_names, map(float, model.initial_state(y0)))), "periods": options.periods,
              "discard": options.discard, "steps_per_period": model.steps_per_period,
              "locate_crossings": model.options.locate_crossings, "match_distance": float(match_distance),
              "method": method()}
    store = _Store(Path(out), model.state_names, model.observed, model.dimension, parameter) if out else None
    try:
        # the values finished (a prefix of values), their rows in order and what happened along them
        rows, done, happened = store.open(record, overwrite) if store else ([], [], [])
        previous = _last(rows, done)
        for value in values[len(done):]:
            execution.say(f"basins at {parameter}={value:g}")
            point = {**fixed, parameter: value}
            found = basin_map(model, grid, options=options, y0=y0,
                              execution=replace(execution, progress=False), **point)
            tracked, news = track(found, value, previous, match_distance, _next_id(rows))
            rows += tracked
            done.append(value)
            happened += news
            previous = (tracked, found.scale)
            if store:
                store.write(rows, done, happened, record)
            if on_value:
                on_value(found)
        return BasinContinuation(model.name, parameter, values, model.state_names, tuple(rows), tuple(happened),
                                 record, store.path if store else None)
    finally:
        if store:
            store.release()


def _next_id(rows: list[Tracked]) -> int:
    return 1 + max((r.id for r in rows if r.id is not None), default=0)


def _last(rows: list[Tracked], done: list[float]):
    """The last finished value's classes and scale, to match the next value's attractors with."""
    if not done:
        return None
    last = [r for r in rows if r.value == done[-1]]
    return last, np.array(last[0].scale)


def track(found: BasinMap, value: float, previous, match_distance: float,
          next_id: int) -> tuple[list[Tracked], list[dict]]:
    """The classes of ``found`` at ``value``, its attractors matched with ``previous`` (the last value's classes
    and scale, or None), and what happened there ({"value", "event", "attractor", "into"}: after a value with
    attractors, each that appears, each of the last value's that merges into one of these, then each that
    vanishes)."""
    attractors = sorted(found.attractors, key=lambda a: a.number)
    ids: dict[int, int] = {}  # the map's number of an attractor -> its id
    merged: dict[int, list[int]] = {}  # the map's number -> the ids of the last value's attractors merged into it
    before_ids: set[int] = set()  # the last value's attractors
    kept: set[int] = set()  # those that continue here, or merge into one here
    if previous is not None:
        before, scale_before = previous
        old = [r for r in before if r.kind == "attractor"]
        before_ids = {r.id for r in old}
        scale = (found.scale + scale_before) / 2 if scale_before is not None else found.scale
        pairs = sorted((cloud_distance(r.points / scale[:, None], a.points / scale[:, None]), r.id, a.number)
                       for r in old for a in attractors)
        used_new = set()
        for d, old_id, new in pairs:
            if d <= match_distance and old_id not in kept and new not in used_new:
                ids[new] = old_id
                kept.add(old_id)
                used_new.add(new)
        for d, old_id, new in pairs:  # an old attractor left alone, near a new one: their basins merged
            if old_id not in kept and d <= match_distance:
                merged.setdefault(new, []).append(old_id)
                kept.add(old_id)
    appeared = [a.number for a in attractors if a.number not in ids]  # new ids in the map's order
    ids.update({number: next_id + k for k, number in enumerate(appeared)})
    rows, news, scale_of = [], [], tuple(map(float, found.scale))
    for a in sorted(attractors, key=lambda a: ids[a.number]):
        aid, into_it = ids[a.number], merged.get(a.number, [])
        if a.number in appeared and before_ids:  # (an appearance is news after a value with attractors)
            news.append(_event(value, APPEARS, aid))
        news += [_event(value, MERGES, k, aid) for k in into_it]
        event = APPEARS if previous is None else " ".join(
            [APPEARS if a.number in appeared else CONTINUES, *(f"{MERGES} {k}" for k in into_it)])
        rows.append(Tracked(value, "attractor", aid, a.fraction, a.stderr, a.basin.starts, a.period, a.regime,
                            dict(a.amplitude), tuple(map(float, a.exponents)), event, a.points, scale_of))
    news += [_event(value, VANISHES, k) for k in sorted(before_ids - kept)]
    for kind, share in (("diverged", found.diverged), ("undetermined", found.undetermined)):
        rows.append(Tracked(value, kind, None, share.fraction, share.stderr, share.starts, None, kind, {}, (), "",
                            np.zeros((len(found.state_names), 0)), scale_of))
    return rows, news


def _event(value: float, event: str, attractor: int, into: int | None = None) -> dict:
    return {"value": value, "event": event, "attractor": attractor, "into": into}


class _Store:
    """``FILE.attractors.csv``, ``FILE.csv`` and ``FILE.json`` of one continuation, locked against a second writer
    and written whole after each value, in that order: a value is finished once the record counts it."""

    def __init__(self, path: Path, states: Sequence[str], observed: Sequence[str], n: int, parameter: str):
        if path.suffix.lower() != ".csv":
            raise GearsymError(f"--out {path}: the basin fractions are written as CSV; name the file *.csv")
        self.path, self.parameter = path, parameter
        self.points_path, self.meta_path = sidecar(path, ".attractors.csv"), sidecar(path, ".json")
        self.states, self.observed = list(states), list(observed)
        self.columns = [parameter, "class", "attractor", "fraction", "stderr", "starts", "period", "regime",
                        *(f"A_{c}" for c in observed), *(f"lambda_{i}" for i in range(1, n + 1)), "event",
                        *(f"scale_{s}" for s in states)]
        self.point_columns = [parameter, "attractor", "point", *states]
        self._lock: int | None = None

    def open(self, record: dict, overwrite: bool | str) -> tuple[list[Tracked], list[float], list[dict]]:
        """The rows of the values finished (those the record counts, from the first, whose rows are there), those
        values in order and what happened along them (none: a fresh start). ``overwrite="stale"``: start again
        files another continuation (or another model) wrote, resume this one's (how the reproduction keeps its
        data)."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = take_lock(self.path)
        said = self._said()
        if overwrite == "stale":
            overwrite = self.path.exists() and self._differs(record, said) is not None
        if overwrite:
            for p in (self.path, self.points_path, self.meta_path):
                p.unlink(missing_ok=True)
        if not self.path.exists():
            return [], [], []
        why = self._differs(record, said)
        if why:
            raise GearsymError(why)
        table = read_rows(self.path, self.columns)
        there = {float(row[self.parameter]) for row in table}
        done = list(takewhile(lambda v: v in there, record["values"][:said["values"]["done"]]))
        points: dict[tuple[float, int], list] = {}
        for row in read_rows(self.points_path, self.point_columns) if self.points_path.exists() else []:
            key = (float(row[self.parameter]), int(row["attractor"]))
            points.setdefault(key, []).append([float(row[s]) for s in self.states])
        rows = [self._tracked(row, points) for row in table if float(row[self.parameter]) in done]
        return rows, done, [e for e in said["events"] if e["value"] in done]

    def _said(self) -> dict | None:
        """The record in ``FILE.json``, or None: missing, or damaged (without how the continuation was made, how
        many values are finished or what happened along them)."""
        try:
            said = json.loads(self.meta_path.read_text())
            whole = (isinstance(said["basins"], dict) and isinstance(said["values"]["done"], int)
                     and said["values"]["done"] >= 0 and all(isinstance(e["value"], float) for e in said["events"]))
        except (OSError, ValueError, KeyError, TypeError):
            return None
        return said if whole else None

    def _differs(self, record: dict, said: dict | None) -> str | None:
        """Why the files cannot be resumed with ``record`` (another continuation's, or ``said``, their record,
        missing or damaged), or None."""
        if said is None:
            return (f"{self.path} exists but {self.meta_path.name} (the record of how it was made) is missing or "
                    "damaged, so it cannot be resumed: pass --overwrite or choose another --out")
        old, new = said["basins"], json.loads(json.dumps(record))
        differ = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k))
        if differ:
            return (f"{self.path} was written by another basin continuation ({', '.join(differ)} differ); repeat "
                    "the command it came from to resume it, or pass --overwrite")
        return None

    def _tracked(self, row: dict, points: dict) -> Tracked:
        value = float(row[self.parameter])
        aid = int(row["attractor"]) if row["attractor"] else None
        pts = np.array(points.get((value, aid), []), dtype=float).reshape(-1, len(self.states)).T
        if aid is not None and not pts.size:
            raise GearsymError(f"{self.points_path} lacks the points of attractor {aid} at {self.parameter}="
                               f"{value:g} (deleted or damaged?): pass --overwrite to start again")
        lambdas = [row[f"lambda_{i}"] for i in range(1, len(self.states) + 1)]
        return Tracked(value, row["class"], aid, float(row["fraction"]), float(row["stderr"]), int(row["starts"]),
                       int(row["period"]) if row["period"] else None, row["regime"],
                       {c: float(row[f"A_{c}"]) for c in self.observed if row[f"A_{c}"]},
                       tuple(float(x) for x in lambdas if x), row["event"], pts,
                       tuple(float(row[f"scale_{s}"]) for s in self.states))

    def write(self, rows: Sequence[Tracked], done: Sequence[float], happened: Sequence[dict], record: dict) -> None:
        """Every file whole, after a value: the points, the rows, then the record (that counts the value
        finished) with what happened."""
        text = io.StringIO()
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow(self.point_columns)
        for r in rows:
            for k, point in enumerate(r.points.T):
                writer.writerow([number(r.value), r.id, k, *map(number, point)])
        write_atomically(self.points_path, text.getvalue())
        text = io.StringIO()
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow(self.columns)
        for r in rows:
            amplitude = [number(r.amplitude[c]) if c in r.amplitude else "" for c in self.observed]
            lambdas = [number(x) for x in r.exponents] + [""] * (len(self.states) - len(r.exponents))
            writer.writerow([number(r.value), r.kind, "" if r.id is None else r.id, number(r.fraction),
                             number(r.stderr), r.starts, "" if r.period is None else r.period, r.regime, *amplitude,
                             *lambdas, r.event, *map(number, r.scale)])
        write_atomically(self.path, text.getvalue())
        planned = len(record["values"])
        meta = {"basins": record, "status": "complete" if len(done) == planned else "running",
                "values": {"planned": planned, "done": len(done)}, "events": json_safe(list(happened)),
                "gearsym": __version__}
        write_atomically(self.meta_path, json.dumps(meta, indent=2) + "\n")

    def release(self) -> None:
        if self._lock is not None:
            release_lock(self.path, self._lock)
            self._lock = None
