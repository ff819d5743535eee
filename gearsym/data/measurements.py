"""Measured time series: the tidy CSV files of issue 5, read and checked against a model.

One row per sample. The columns, in any order:

* the time: ``tau``, the model's own (nondimensional) time, or ``t``, physical time, with a
  time scale given to :func:`load_measurements` (tau = time_scale * t; ``gearsym derive MODEL``
  shows the model's time unit). A model whose own time is ``t`` (Lorenz) reads ``t`` as is.
* one column per observation *channel*, at least one (:data:`CHANNELS_HELP`):

  - a state, named as in the model: ``x`` for ``one_stage``, ``x1`` and ``x2`` for
    ``flexible_shaft``, velocities ``v``, ``v1``;
  - its first or second time derivative, ``x_dot`` or ``x_ddot`` (an accelerometer on the
    mesh coordinate: ``x_ddot`` = dv/dtau). A derivative is per unit of the file's time: per
    unit tau in a ``tau`` file, per unit of ``t`` (a second) in a ``t`` file, where with
    tau = s t the model's output is scaled to it: dx/dt = s dx/dtau, d2x/dt2 = s^2 d2x/dtau2;
  - a combination declared when loading (``channels={"a": "x1_ddot + 0.5*x2_ddot"}``,
    ``--channel a=...``): a formula of states, their derivatives, the time and parameters,
    read by the safe formula parser.

  Any state may be unmeasured.
* optionally ``record``: a label (any text) that separates several runs in one file. The rows of
  a record are together and in time order. Without the column the file is one record, ``1``.
* any number of operating conditions: columns named as model parameters (``omega``, ``B1``),
  constant within a record. They override the model's defaults for that record.

Every sample of a record must be finite, the time strictly increasing and evenly spaced (within
``spacing_tolerance`` of the record's median step), with at least ``min_samples_per_period``
samples per forcing period and at least ``min_periods`` whole forcing periods. The forcing
period is the model's, at the record's parameter values (2*pi in tau for the gear
models). A file that breaks a rule gets a :class:`DataError` naming the file, the line (as a
text editor numbers it: the header is line 1) and the column.

The forcing phase of a measurement is the model's tau: data whose clock does not start at a
known phase of the excitation need the phase (``Theta``) fitted, which is the fitting layer's job.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import sympy as sp

from ..checks import whole_number
from ..errors import GearsymError
from ..system import FirstOrderSystem
# the names this module defined before the reading was split into one file per step (kept importable from here)
from .channels import CHANNELS_HELP, DERIVATIVES, channel_expression, channel_symbols, declared_channels
from .columns import PHYSICAL_TIME, RECORD
from .csvtext import csv_rows
from .dataset import Measurements
from .errors import DataError, PathLike
from .grouping import group_rows
from .layout import layout_of
from .record import Record, Window
from .rules import MIN_PERIODS, MIN_SAMPLES_PER_PERIOD, SPACING_TOLERANCE, Rules, checked_record

__all__ = ["CHANNELS_HELP", "DERIVATIVES", "DataError", "MIN_PERIODS", "MIN_SAMPLES_PER_PERIOD", "Measurements",
           "PHYSICAL_TIME", "RECORD", "Record", "SPACING_TOLERANCE", "Window", "channel_expression", "channel_symbols",
           "load_measurements"]


def load_measurements(
    paths: PathLike | Sequence[PathLike],
    system: FirstOrderSystem,
    *,
    time_scale: float | None = None,
    min_samples_per_period: float = MIN_SAMPLES_PER_PERIOD,
    min_periods: int = MIN_PERIODS,
    spacing_tolerance: float = SPACING_TOLERANCE,
    channels: Mapping[str, str] | None = None,
    **values: float,
) -> Measurements:
    """Read and check measured-data files (one path or several) for a model.

    ``system`` is the model's :class:`~gearsym.system.FirstOrderSystem` (``values``: parameter values that
    hold for every record unless a record's conditions set them). Records
    are identified per file (two files may both have a record ``1``). ``time_scale`` converts a
    ``t`` column: tau = time_scale * t; files with a ``tau`` column ignore it. ``channels``:
    combinations of states and derivatives measured as one column, by column name (see the module
    docstring).
    """
    if not isinstance(system, FirstOrderSystem):
        raise GearsymError(f"load_measurements takes the model's FirstOrderSystem, got {type(system).__name__}"
                           + ("; resolve a name with gearsym.load(...)" if isinstance(system, str) else ""))
    defaults = system.parameter_values(values)
    rules = Rules(_positive(min_samples_per_period, "min_samples_per_period"),
                  whole_number(min_periods, "min_periods", 1), _positive(spacing_tolerance, "spacing_tolerance"))
    if time_scale is not None:
        time_scale = _positive(time_scale, "time_scale (tau = time_scale * t)")
    files = [paths] if isinstance(paths, (str, Path)) else list(paths)
    if not files:
        raise GearsymError("no measurement files given")
    twice = [p for i, p in enumerate(files) if Path(p).resolve() in {Path(q).resolve() for q in files[:i]}]
    if twice:
        raise GearsymError(f"{twice[0]} is given twice")
    declared = declared_channels(system, channels or {})
    records = tuple(r for path in files for r in _read_file(Path(path), system, defaults, time_scale, rules,
                                                            declared))
    unused = [name for name in declared if not any(name in r.observed for r in records)]
    if unused:
        raise GearsymError(f"channel {unused[0]} is declared but no file has a column {unused[0]}")
    return Measurements(system.name, system.state_names, defaults, records)


def _read_file(path: Path, system: FirstOrderSystem, defaults: dict, time_scale, rules: Rules,
               declared: Mapping[str, sp.Expr]) -> list[Record]:
    with csv_rows(path) as (header_line, header, rows):
        layout = layout_of(path, header_line, header, system, time_scale, declared)
        groups = group_rows(path, header, rows, layout)
    return [checked_record(path, group, layout, system, defaults, rules) for group in groups]


def _positive(value, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number > 0):
        raise GearsymError(f"{what} must be a positive number, got {value!r}")
    return number

