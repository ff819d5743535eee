"""A finished sweep as arrays, with what the paper looks for in it: jumps and hysteresis."""
from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..analysis.jumps import find_jumps, hysteresis_intervals
from ..errors import GearsymError
from ..files.kinds import what_is_at
from .grid import INDEPENDENT, Axis
from .store import PoincareRows, read_poincare, read_rows, sidecar


@dataclass(frozen=True)
class SweepResult:
    """Columns of the sweep table (numbers as float arrays, ``direction``/``regime`` as str arrays),
    plus the Poincare samples (``strobe``: the same columns, one row per sample)."""

    model: str
    axes: tuple[Axis, ...]
    mode: str
    columns: dict[str, np.ndarray]
    strobe: dict[str, np.ndarray]
    record: dict
    path: Path | None = None
    units: dict[str, str] = field(default_factory=dict)  # column -> unit, for a sweep carried to physical units

    TEXT = ("direction", "regime")

    @classmethod
    def from_rows(cls, model, axes, mode, names: Sequence[str], rows: Sequence[dict],
                  strobes: Sequence[PoincareRows], record: dict, path: Path | None = None,
                  strobe_columns: Sequence[str] = ()) -> "SweepResult":
        """``rows``: one dict per point; ``strobes``: their Poincare rows, in ``strobe_columns``."""
        return cls(model, tuple(axes), mode, _columns(names, rows), _strobe_columns(strobe_columns, strobes),
                   record, path)

    def __len__(self) -> int:
        return len(self.columns["direction"])

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.columns[name]
        except KeyError:
            raise GearsymError(f"the sweep has no column {name!r}; it has {', '.join(self.columns)}") from None

    @property
    def coordinates(self) -> list[str]:
        return [c[2:] for c in self.columns if c.startswith("A_")]

    @property
    def exponent_count(self) -> int:
        return sum(c.startswith("lambda_") for c in self.columns)

    def lines(self) -> list[tuple[str, dict[str, float], np.ndarray]]:
        """(direction, values of the other axes, row indices in run order) for each run along the first axis."""
        others = [a.name for a in self.axes[1:]]
        groups: dict[tuple, list[int]] = {}
        for i in range(len(self)):
            key = (str(self["direction"][i]), tuple(float(self[n][i]) for n in others))
            groups.setdefault(key, []).append(i)
        return [(d, dict(zip(others, vals)), np.array(idx)) for (d, vals), idx in groups.items()]

    def findings(self) -> dict:
        """Jumps of every amplitude along every continuation run, and hysteresis where up and down both ran."""
        first = self.axes[0].name
        jumps, hysteresis = [], []
        if self.mode == INDEPENDENT:
            return {"jumps": jumps, "hysteresis": hysteresis}
        runs = [(d, fixed, idx[self["regime"][idx] != "diverged"]) if "regime" in self.columns else (d, fixed, idx)
                for d, fixed, idx in self.lines()]  # (a run that grew without bound has no amplitude to jump)
        for direction, fixed, idx in runs:
            for c in self.coordinates:
                for j in find_jumps(self[first][idx], self[f"A_{c}"][idx]):
                    jumps.append({"coordinate": c, "direction": direction, **fixed, **j.as_dict()})
        by_fixed: dict[tuple, dict[str, np.ndarray]] = {}
        for direction, fixed, idx in runs:
            by_fixed.setdefault(tuple(fixed.items()), {})[direction] = idx
        for fixed, pair in by_fixed.items():
            if {"up", "down"} <= set(pair):
                common = np.intersect1d(self[first][pair["up"]], self[first][pair["down"]])  # all, unless interrupted
                up, down = (_ascending_on(self[first], pair[d], common) for d in ("up", "down"))
                for c in self.coordinates:
                    for lo, hi in hysteresis_intervals(self[first][up], self[f"A_{c}"][up], self[f"A_{c}"][down]):
                        hysteresis.append({"coordinate": c, **dict(fixed), "from": lo, "to": hi})
        return {"jumps": jumps, "hysteresis": hysteresis}


def _ascending_on(values: np.ndarray, idx: np.ndarray, common: np.ndarray) -> np.ndarray:
    """The rows of ``idx`` whose first-axis value is in ``common``, in ascending order of it."""
    keep = idx[np.isin(values[idx], common)]
    return keep[np.argsort(values[keep], kind="stable")]


def _columns(names: Sequence[str], rows: Sequence[dict]) -> dict[str, np.ndarray]:
    return {name: _typed(name, [r[name] for r in rows]) for name in names}


def _strobe_columns(names: Sequence[str], strobes: Sequence[PoincareRows]) -> dict[str, np.ndarray]:
    """The Poincare table as columns (none without a sample)."""
    strobes = [s for s in strobes if len(s.samples)]
    if not strobes:
        return {}
    keys = len(strobes[0].where)
    counts = [len(s.samples) for s in strobes]
    columns = {name: np.repeat(_typed(name, [s.where[i] for s in strobes]), counts)  # (each point's keys read once)
               for i, name in enumerate(names[:keys])}
    columns[names[keys]] = np.concatenate([np.arange(c, dtype=float) for c in counts])
    states = np.concatenate([s.samples for s in strobes])
    columns.update({name: states[:, i].copy() for i, name in enumerate(names[keys + 1:])})
    return columns


def _typed(name: str, values: list[str]) -> np.ndarray:
    return np.array(values, dtype=str) if name in SweepResult.TEXT else np.array(values, dtype=float)


def read_sweep(path: str | Path) -> SweepResult:
    """A sweep written by :func:`~gearsym.sweep.run_sweep` (complete or not), from its CSV and JSON record."""
    path = Path(path)
    meta = sidecar(path, ".json")
    for p in (path, meta):
        if not p.is_file():
            said = "no such file" if not p.exists() and not p.is_symlink() else what_is_at(p, "a sweep is a CSV file")
            raise GearsymError(f"{p}: {said}; a sweep is written by `gearsym sweep ... --out {path.name}`")
    try:
        record = json.loads(meta.read_text())["sweep"]
        axes = tuple(Axis(n, tuple(v), f"{n}=...") for n, v in record["axes"].items())
    except (json.JSONDecodeError, KeyError, TypeError, AttributeError) as exc:
        raise GearsymError(f"{meta}: not a gearsym sweep record ({exc})") from None

    rows = read_rows(path)
    names = list(rows[0]) if rows else next(csv.reader(path.read_text().splitlines()), [])
    strobe_path = sidecar(path, ".poincare.csv")
    try:  # (the Poincare rows' keys: the swept values and the direction)
        strobe_columns, strobes = read_poincare(strobe_path, len(axes) + 1) if strobe_path.is_file() else ([], [])
        return SweepResult.from_rows(record["model"], axes, record["mode"], names, rows, strobes, record, path,
                                     strobe_columns)
    except (ValueError, TypeError) as exc:
        raise GearsymError(f"{path}: a value is not a number ({exc})") from None
