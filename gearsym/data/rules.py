"""What makes a record usable for a fit, checked: constant operating conditions, a time that increases evenly,
enough samples per forcing period and enough whole periods; a group of rows that passes becomes a :class:`Record`."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GearsymError, option
from ..system import FirstOrderSystem
from .columns import PHYSICAL_TIME, RECORD
from .errors import DataError
from .grouping import Rows
from .layout import Layout
from .record import Record

#: default minimum number of samples per forcing period
MIN_SAMPLES_PER_PERIOD = 20
#: default minimum number of whole forcing periods per record
MIN_PERIODS = 3
#: default relative tolerance on the sample step (0.1 % of the median step)
SPACING_TOLERANCE = 1e-3


@dataclass(frozen=True)
class Rules:
    min_samples_per_period: float
    min_periods: int
    spacing_tolerance: float



def checked_record(path: Path, rows: Rows, layout: Layout, system: FirstOrderSystem, defaults: dict,
            rules: Rules) -> Record:
    lines, where = rows.lines, f"record {rows.record}"
    conditions = {name: _condition(path, rows, name, system) for name in layout.conditions}
    try:
        period = system.cycle_at({**defaults, **conditions})  # (a forcing period, if the system's spans several)
    except GearsymError as exc:
        raise DataError(f"{where}: at its conditions: {exc}", path, int(lines[0])) from None
    step = _check_time(path, rows.values[layout.time], lines, layout.time, where, rules)
    tau = rows.values[layout.time] * layout.scale
    record = Record(path, rows.record, tau, {s: rows.values[s] for s in layout.states}, conditions, period,
                    step * layout.scale, lines, float(tau[0]), layout.scale, dict(layout.channels))
    _check_length(record, layout, rules)
    return record


def _condition(path: Path, rows: Rows, name: str, system: FirstOrderSystem) -> float:
    """The value of an operating condition in a record: constant, and valid for the model."""
    column, lines = rows.values[name], rows.lines
    changed = np.nonzero(column != column[0])[0]
    if changed.size:
        i = int(changed[0])
        raise DataError(f"{name} varies within record {rows.record} ({float(column[0])!r} on line {lines[0]}, "
                        f"{float(column[i])!r} here); an operating condition is constant within a record: start a "
                        "new record where it changes", path, int(lines[i]), name)
    try:
        return system.parameter_values({name: float(column[0])})[name]
    except GearsymError as exc:
        raise DataError(f"record {rows.record}: {exc}", path, int(lines[0]), name) from None


def _check_time(path: Path, time: np.ndarray, lines: np.ndarray, column: str, where: str, rules: Rules) -> float:
    """The record's median step, after checking that time increases strictly and evenly."""
    if time.size < 2:
        raise DataError(f"{where} has a single sample; a fit needs at least {rules.min_periods} forcing periods "
                        f"of {rules.min_samples_per_period:g} samples or more", path, int(lines[0]), column)
    steps = np.diff(time)
    back = np.nonzero(steps <= 0)[0]
    if back.size:
        i = int(back[0]) + 1
        raise DataError(f"the time does not increase within {where}: {float(time[i])!r} after "
                        f"{float(time[i - 1])!r} on line {lines[i - 1]}; sort the rows by time, or start a new "
                        f"record with the {RECORD} column", path, int(lines[i]), column)
    step = float(np.median(steps))
    uneven = np.nonzero(np.abs(steps - step) > rules.spacing_tolerance * step)[0]
    if uneven.size:
        i = int(uneven[0]) + 1
        raise DataError(f"the samples of {where} are not evenly spaced: the step from line {lines[i - 1]} is "
                        f"{float(steps[i - 1])!r}, the median step {step!r} (tolerance "
                        f"{rules.spacing_tolerance:.3g} of the step); resample the record to a uniform time grid "
                        "or split it where samples are missing", path, int(lines[i]), column)
    return step


def _check_length(record: Record, layout: Layout, rules: Rules) -> None:
    where = f"record {record.record} (lines {record.lines[0]}-{record.lines[1]})"
    scaled = f" with {option('time_scale', layout.scale)}" if layout.time == PHYSICAL_TIME and layout.scale != 1 else ""
    if record.samples_per_period < rules.min_samples_per_period * (1 - 1e-9):
        raise DataError(
            f"{where} has {record.samples_per_period:.3g} samples per forcing period (period {record.period:.6g} "
            f"in the model's time, step {record.step:.6g}{scaled}); at least {rules.min_samples_per_period:g} are "
            "needed: sample faster" + (", or check the time scale" if scaled else ""),
            record.source, record.lines[0], layout.time)
    whole = len(record.windows())
    if whole < rules.min_periods:
        raise DataError(
            f"{where} is too short to fit: it covers {record.periods:.3g} forcing periods ({whole} whole), at "
            f"least {rules.min_periods} whole periods are needed: record a longer run",
            record.source, record.lines[0], layout.time)
