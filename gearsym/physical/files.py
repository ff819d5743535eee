"""Results in physical units as files beside the engine's: a table (``FILE.physical.csv``, each column headed by
its name and unit) and, for a sweep, its record (``FILE.physical.json``: the scaling, the units and the
findings along the physical values); a basin map as shown (``FILE.csv``, ``FILE.json``) and basin fractions in
the model's units (``FILE.physical.csv``)."""
from __future__ import annotations

import csv
import io
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..analysis.basins import CLASSES, BasinMap
from ..checks import json_safe
from ..files.atomic import write_atomically
from ..sweep.store import sidecar
from .basins import ShownBasinMap, ShownFractions


def write_physical_table(result, path: Path) -> Path:
    """One row per point of a sweep in physical units (``speed [rpm]``, ``A_x [µm]``)."""
    names = list(result.columns)
    rows = ({n: result.columns[n][i] for n in names} for i in range(len(result)))
    return write_physical_rows(names, rows, result.units, path)


def write_physical_rows(names: Sequence[str], rows, units: Mapping[str, str], path: Path) -> Path:
    """Rows (dicts) as a table whose headers give each column's unit."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([f"{n} [{units[n]}]" if n in units else n for n in names])
    for row in rows:
        writer.writerow([_cell(row[n]) for n in names])
    return write_atomically(path, buffer.getvalue())


def write_physical_record(result, path: Path) -> Path:
    """A sweep's physical record (``result.record["physical"]``: the scaling, units, jumps and hysteresis)."""
    record = {"model": result.model, **result.record["physical"]}
    return write_atomically(path, json.dumps(json_safe(record), indent=1, allow_nan=False) + "\n")


def write_basin_map(shown: ShownBasinMap | BasinMap, path: str | Path) -> tuple[Path, Path]:
    """A basin map (as shown, or in the model's own numbers): ``path``, one row per start (the grid's two states,
    headed by their units, and the class it reached), and its record beside it (``.json``, without the labels
    the rows hold). Returns the two paths."""
    shown, path = ShownBasinMap.of(shown), Path(path)
    result = shown.result
    (x, xs), (y, ys) = result.axes
    sx, ux = shown.state(x, xs)
    sy, uy = shown.state(y, ys)
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow([f"{x} [{ux}]" if ux else x, f"{y} [{uy}]" if uy else y, "attractor"])
    for j, yv in enumerate(sy):
        for i, xv in enumerate(sx):
            label = int(result.labels[j, i])
            writer.writerow([repr(float(xv)), repr(float(yv)), CLASSES.get(label, label)])
    write_atomically(path, text.getvalue())
    data = shown.as_dict()
    data.pop("labels", None)
    record = sidecar(path, ".json")
    write_atomically(record, json.dumps(data, indent=2) + "\n")
    return path, record


def write_basin_fractions(shown: ShownFractions, path: str | Path) -> Path:
    """A basin continuation's rows as shown: the parameter (the speed, for a model with physical values) and the
    amplitudes in their units."""
    name, values, unit = shown.parameter()
    result = shown.result
    speed = dict(zip(result.values, values))
    coordinates = list(dict.fromkeys(k for r in result.rows for k in r.amplitude))
    units = {k: shown.unit(k) for k in coordinates}
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow([f"{name} [{unit}]" if unit else name, "class", "attractor", "fraction", "stderr", "period",
                     "regime", *(f"A_{k} [{units[k]}]" if units[k] else f"A_{k}" for k in coordinates)])
    for r in result.rows:
        amplitude = [repr(shown.amplitude(k, r.amplitude[k], r.value)[0]) if k in r.amplitude else ""
                     for k in coordinates]
        writer.writerow([repr(float(speed[r.value])), r.kind, "" if r.id is None else r.id, repr(r.fraction),
                         repr(r.stderr), "" if r.period is None else r.period, r.regime, *amplitude])
    return write_atomically(Path(path), text.getvalue())


def _cell(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value)).lower()
    if isinstance(value, (str, int, np.integer)):
        return str(value)
    return repr(float(value))
