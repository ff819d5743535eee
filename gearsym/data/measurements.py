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

import csv
import math
from functools import lru_cache
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Union

import numpy as np

import sympy as sp

from ..checks import whole_number
from ..errors import GearsymError, suggest
from ..model.expressions import to_expr
from ..system import FirstOrderSystem

RECORD = "record"
PHYSICAL_TIME = "t"
#: default minimum number of samples per forcing period
MIN_SAMPLES_PER_PERIOD = 20
#: default minimum number of whole forcing periods per record
MIN_PERIODS = 3
#: default relative tolerance on the sample step (0.1 % of the median step)
SPACING_TOLERANCE = 1e-3
#: rounding allowance at window edges, as a fraction of a sample step
_EDGE = 1e-6
#: the suffixes of a state's time derivatives as channel names, and their order
DERIVATIVES = {"_dot": 1, "_ddot": 2}
CHANNELS_HELP = ("a state (x), its time derivative (x_dot) or second derivative (x_ddot, an accelerometer), or a "
                 "combination declared with channels={name: formula} (--channel NAME=FORMULA)")

PathLike = Union[str, Path]


class DataError(GearsymError):
    """A measured-data file that cannot be used; says where: ``source``, ``line`` and ``column``."""

    def __init__(self, message: str, source: PathLike, line: int | None = None, column: str | None = None):
        self.source, self.line, self.column = Path(source), line, column
        where = str(source) + (f", line {line}" if line else "") + (f", column {column!r}" if column else "")
        super().__init__(f"{where}: {message}")


# --------------------------------------------------------------------------- the result
@dataclass(frozen=True, eq=False)
class Record:
    """One run at fixed operating conditions: evenly spaced samples of some of the model's states.

    ``tau`` is the model's time; ``observed`` maps channel names to arrays like ``tau``, and
    ``channels`` each channel name to what it measures (:func:`channel_symbols`: states, the
    placeholders of their tau-derivatives, already scaled to the file's time unit);
    ``conditions`` the parameter values this record sets (the rest are the model's);
    ``period`` the forcing period in tau; ``step`` the sample step (the median, in tau);
    ``line_numbers`` the line of each sample in its file; ``origin`` the time at which
    forcing-period windows start (the first sample, kept by the parts of a split so that their
    windows stay those of the whole record); ``time_scale`` the factor from the file's ``t`` to
    tau (1 for a file in tau).
    """

    source: Path
    record: str
    tau: np.ndarray
    observed: Mapping[str, np.ndarray]
    conditions: Mapping[str, float]
    period: float
    step: float
    line_numbers: np.ndarray
    origin: float
    time_scale: float = 1.0
    channels: Mapping[str, sp.Expr] | None = None

    def __post_init__(self):
        if self.channels is None:  # a record of states only
            object.__setattr__(self, "channels", {k: sp.Symbol(k, real=True) for k in self.observed})

    @property
    def label(self) -> str:
        return f"{self.source.name} record {self.record}"

    @property
    def lines(self) -> tuple[int, int]:
        """The first and last line of the record in its file."""
        return int(self.line_numbers[0]), int(self.line_numbers[-1])

    @property
    def samples(self) -> int:
        return int(self.tau.size)

    @property
    def samples_per_period(self) -> float:
        return self.period / self.step

    @property
    def periods(self) -> float:
        """The length covered, in forcing periods (each sample counts one step)."""
        return self.samples * self.step / self.period

    def __getitem__(self, state: str) -> np.ndarray:
        return self.observed[state]

    def windows(self) -> tuple["Window", ...]:
        """The whole forcing periods [origin + k T, origin + (k+1) T) the record covers, in order.

        Each sample belongs to at most one window; a window holds every sample in its period
        (so with an integer number of samples per period, windows are blocks of that many).
        Samples after the last whole period belong to none.
        """
        h, T, tol = self.step, self.period, _EDGE * self.step
        first = math.floor((self.tau[0] - h + tol - self.origin) / T) + 1
        last = math.floor((self.tau[-1] + h + tol - self.origin) / T) - 1
        out = []
        for k in range(first, last + 1):
            start = self.origin + k * T
            lo, hi = np.searchsorted(self.tau, [start - tol, start + T - tol], side="left")
            out.append(Window(self, k, start, slice(int(lo), int(hi))))
        return tuple(out)

    def part(self, start: float = -math.inf, stop: float = math.inf) -> "Record":
        """The samples with start <= tau < stop (same origin, so the same windows)."""
        lo, hi = (int(i) for i in np.searchsorted(self.tau, [start, stop], side="left"))
        if hi <= lo:
            raise GearsymError(f"{self.label}: no samples with {start:g} <= tau < {stop:g}")
        return replace(self, tau=self.tau[lo:hi], observed={k: v[lo:hi] for k, v in self.observed.items()},
                       line_numbers=self.line_numbers[lo:hi])

    def split(self, held_out: float = 0.25) -> tuple["Record", "Record"]:
        """(train, held-out) by time: the last ``held_out`` of the record's whole forcing periods
        (rounded, at least one) and anything after them are held out; the rest is for training."""
        if not 0 < held_out < 1:
            raise GearsymError(f"held_out must be a fraction between 0 and 1, got {held_out!r}")
        windows = self.windows()
        if len(windows) < 2:
            raise GearsymError(f"{self.label}: {len(windows)} whole forcing period(s); at least 2 are needed to "
                               "hold one out")
        kept = len(windows) - min(len(windows) - 1, max(1, round(held_out * len(windows))))
        cut = windows[kept].start - _EDGE * self.step
        return self.part(stop=cut), self.part(start=cut)


@dataclass(frozen=True, eq=False)
class Window:
    """The samples of one forcing period [start, start + period) of a record: one multiple-shooting
    interval (``start`` is the node's time, the record's origin plus ``index`` periods)."""

    record: Record
    index: int
    start: float
    rows: slice

    @property
    def stop(self) -> float:
        return self.start + self.record.period

    @property
    def tau(self) -> np.ndarray:
        return self.record.tau[self.rows]

    @property
    def observed(self) -> dict[str, np.ndarray]:
        return {k: v[self.rows] for k, v in self.record.observed.items()}

    @property
    def conditions(self) -> Mapping[str, float]:
        return self.record.conditions


@dataclass(frozen=True, eq=False)
class Measurements:
    """Records of one model, from one or more files.

    ``defaults`` are the model's parameter values (with any settings given when loading),
    which each record's ``conditions`` override: :meth:`parameters`.
    """

    model: str
    states: tuple[str, ...]
    defaults: Mapping[str, float]
    records: tuple[Record, ...]

    def __len__(self) -> int:
        return len(self.records)

    def __iter__(self) -> Iterator[Record]:
        return iter(self.records)

    def __getitem__(self, index: int) -> Record:
        return self.records[index]

    @property
    def observed(self) -> tuple[str, ...]:
        """The channels measured in at least one record: states in the model's order, then the others."""
        seen = list(dict.fromkeys(name for r in self.records for name in r.observed))
        return tuple(s for s in self.states if s in seen) + tuple(c for c in seen if c not in self.states)

    @property
    def sources(self) -> tuple[Path, ...]:
        return tuple(dict.fromkeys(r.source for r in self.records))

    def find(self, record: str, source: PathLike | None = None) -> Record:
        """The record with this id (in ``source``, needed when several files use the id)."""
        hits = [r for r in self.records if r.record == str(record)
                and (source is None or r.source == Path(source) or r.source.name == str(source))]
        if len(hits) != 1:
            ids = ", ".join(f"{r.source.name}:{r.record}" for r in self.records)
            what = "no" if not hits else "more than one"
            raise GearsymError(f"{what} record {record!r}{'' if source is None else f' in {source}'}; records: {ids}")
        return hits[0]

    def parameters(self, record: Record) -> dict[str, float]:
        """Every parameter value of a record: the defaults, overridden by its conditions."""
        return {**self.defaults, **record.conditions}

    def windows(self) -> tuple[Window, ...]:
        """The one-forcing-period windows of every record, record after record."""
        return tuple(w for r in self.records for w in r.windows())

    def split(self, held_out: float = 0.25) -> tuple["Measurements", "Measurements"]:
        """(train, held-out): every record split by time (:meth:`Record.split`)."""
        parts = [r.split(held_out) for r in self.records]
        return (replace(self, records=tuple(p[0] for p in parts)),
                replace(self, records=tuple(p[1] for p in parts)))


# --------------------------------------------------------------------------- reading
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
    rules = _Rules(_positive(min_samples_per_period, "min_samples_per_period"),
                   whole_number(min_periods, "min_periods", 1), _positive(spacing_tolerance, "spacing_tolerance"))
    if time_scale is not None:
        time_scale = _positive(time_scale, "time_scale (tau = time_scale * t)")
    files = [paths] if isinstance(paths, (str, Path)) else list(paths)
    if not files:
        raise GearsymError("no measurement files given")
    twice = [p for i, p in enumerate(files) if Path(p).resolve() in {Path(q).resolve() for q in files[:i]}]
    if twice:
        raise GearsymError(f"{twice[0]} is given twice")
    declared = _declared_channels(system, channels or {})
    records = tuple(r for path in files for r in _read_file(Path(path), system, defaults, time_scale, rules,
                                                            declared))
    unused = [name for name in declared if not any(name in r.observed for r in records)]
    if unused:
        raise GearsymError(f"channel {unused[0]} is declared but no file has a column {unused[0]}")
    return Measurements(system.name, system.state_names, defaults, records)


def channel_symbols(system: FirstOrderSystem) -> dict[str, sp.Symbol]:
    """The names a channel may use: every state, and the placeholder of each state's derivatives
    (``x_dot``, ``x_ddot``: dx/dtau, d2x/dtau2), which :func:`channel_expression` resolves."""
    out = {s.name: s for s in system.states}
    for s in system.states:
        out.update({s.name + suffix: sp.Symbol(s.name + suffix, real=True) for suffix in DERIVATIVES})
    return out


def channel_expression(channel: sp.Expr, system: FirstOrderSystem) -> sp.Expr:
    """What ``channel`` (states and derivative placeholders) is as h(tau, y, p) of ``system``:
    x_dot = f_x, x_ddot = df_x/dtau along the flow (= f_v for x' = v)."""
    return _channel_expression(channel, system.time, system.states, system.rhs)


@lru_cache(maxsize=256)
def _channel_expression(channel: sp.Expr, time: sp.Symbol, states: tuple, rhs: tuple) -> sp.Expr:
    rates = dict(zip(states, rhs))

    def derivative(expr: sp.Expr, order: int) -> sp.Expr:
        for _ in range(order):
            expr = sp.diff(expr, time) + sum(sp.diff(expr, s) * rates[s] for s in states)
        return expr

    by_name = {s.name: s for s in states}
    used = {s.name for s in channel.free_symbols}
    for s in states:
        for suffix, order in DERIVATIVES.items():
            if s.name + suffix in used:
                by_name[s.name + suffix] = derivative(s, order)
    return channel.xreplace({s: by_name[s.name] for s in channel.free_symbols if s.name in by_name})


def _declared_channels(system: FirstOrderSystem, channels: Mapping[str, str]) -> dict[str, sp.Expr]:
    """Each declared combination as an expression of states and derivative placeholders (tau units)."""
    names = channel_symbols(system)
    out = {}
    for name, formula in channels.items():
        where = f"channel {name}"
        if not str(name).isidentifier():
            raise GearsymError(f"{where}: a channel name must be a column name like acc or a1 (letters, digits, _)")
        if name in names or name in system.parameters or name in (RECORD, PHYSICAL_TIME, system.time.name):
            raise GearsymError(f"{where}: the name is already a state, derivative, parameter or time column; "
                               "name the combination otherwise")
        expr = to_expr(formula, where, {**names, system.time.name: system.time})
        unknown = sorted(s.name for s in expr.free_symbols
                         if s not in names.values() and s != system.time and s.name not in system.parameters)
        if unknown:
            known = ", ".join(names)
            raise GearsymError(f"{where}: unknown name {unknown[0]}.{suggest(unknown[0], list(names))} A channel "
                               f"combines {known}, the time {system.time.name} and the parameters")
        out[name] = expr
    return out


def _in_file_units(expr: sp.Expr, system: FirstOrderSystem, scale: float) -> sp.Expr:
    """A channel of a file whose time is t (tau = scale t): derivatives per unit t, d^k/dt^k = scale^k d^k/dtau^k."""
    if scale == 1.0:
        return expr
    mapping = {}
    for s in system.states:
        for suffix, order in DERIVATIVES.items():
            mapping[sp.Symbol(s.name + suffix, real=True)] = sp.Float(scale) ** order * sp.Symbol(s.name + suffix,
                                                                                                     real=True)
    return expr.xreplace(mapping)


def _positive(value, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number > 0):
        raise GearsymError(f"{what} must be a positive number, got {value!r}")
    return number


@dataclass(frozen=True)
class _Rules:
    min_samples_per_period: float
    min_periods: int
    spacing_tolerance: float


@dataclass(frozen=True)
class _Layout:
    """What each column of a file is."""

    time: str
    scale: float
    record: str | None
    states: tuple[str, ...]  # the measured channels (states, derivatives, combinations)
    conditions: tuple[str, ...]
    channels: Mapping[str, sp.Expr] = None  # what each measures, in the file's time unit


@dataclass(frozen=True)
class _Rows:
    """The data rows of one record: their line numbers, record id and numeric cells by column."""

    record: str
    lines: np.ndarray
    values: dict[str, np.ndarray]


def _read_file(path: Path, system: FirstOrderSystem, defaults: dict, time_scale, rules: _Rules,
               declared: Mapping[str, sp.Expr]) -> list[Record]:
    header_line, header, rows = _read_csv(path)
    layout = _layout(path, header_line, header, system, time_scale, declared)
    return [_record(path, group, layout, system, defaults, rules) for group in _group(path, header, rows, layout)]


def _read_csv(path: Path) -> tuple[int, list[str], list[tuple[int, list[str]]]]:
    """The header (its line number and names) and the non-blank rows with their line numbers."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise DataError("no such file", path) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read it as UTF-8 text ({exc})", path) from None
    reader = csv.reader(text.splitlines())
    header_line, header, rows = 0, None, []
    for cells in reader:
        if not any(c.strip() for c in cells):
            continue
        if header is None:
            header_line, header = reader.line_num, [c.strip() for c in cells]
            continue
        if len(cells) != len(header):
            raise DataError(f"{len(cells)} cells, but the header (line {header_line}) names {len(header)} columns",
                            path, reader.line_num)
        rows.append((reader.line_num, cells))
    if header is None:
        raise DataError("the file is empty; expected a header line naming the columns, e.g. tau,x", path)
    return header_line, header, rows


def _layout(path: Path, line: int, header: list[str], system: FirstOrderSystem, time_scale,
            declared: Mapping[str, sp.Expr]) -> _Layout:
    states, parameters = system.state_names, tuple(system.parameters)
    symbols = channel_symbols(system)
    channel_names = [*symbols, *declared]
    own_time = system.time.name
    times = [own_time] + ([PHYSICAL_TIME] if own_time != PHYSICAL_TIME else [])
    for i, name in enumerate(header):
        if not name:
            raise DataError(f"column {i + 1} has no name", path, line)
        if header.index(name) != i:
            raise DataError("the column appears twice", path, line, name)
    known = [*times, RECORD, *channel_names, *parameters]
    for name in header:
        if name not in known:
            raise DataError(
                f"unknown column.{suggest(name, known)} A column is the time ({' or '.join(times)}), "
                f"{RECORD}, a channel: {CHANNELS_HELP} (states of {system.name}: {', '.join(states)}), or one of "
                f"its parameters as an operating condition ({', '.join(parameters)})", path, line, name)
    given = [t for t in times if t in header]
    if not given:
        raise DataError(f"no time column: name it {own_time} (the model's time)"
                        + (f" or {PHYSICAL_TIME} (physical time, with a time scale)" if len(times) > 1 else ""),
                        path, line)
    if len(given) > 1:
        raise DataError(f"both {own_time} and {PHYSICAL_TIME} columns; keep one", path, line, PHYSICAL_TIME)
    scale = 1.0
    if given[0] == PHYSICAL_TIME and own_time != PHYSICAL_TIME:
        if time_scale is None:
            raise DataError(
                f"the time is t (physical time) but no time scale was given: pass time_scale=... "
                f"({own_time} = time_scale * t; `gearsym derive {system.name}` shows the time unit), or give "
                f"the model's time as a {own_time} column", path, line, PHYSICAL_TIME)
        scale = float(time_scale)
    measured = tuple(c for c in channel_names if c in header)
    if not measured:
        raise DataError(f"no measured state: name at least one column as a channel of {system.name}: {CHANNELS_HELP} "
                        f"(states: {', '.join(states)})", path, line)
    conditions = tuple(p for p in parameters if p in header)
    channels = {c: _in_file_units(declared[c] if c in declared else symbols[c], system, scale) for c in measured}
    return _Layout(given[0], scale, RECORD if RECORD in header else None, measured, conditions, channels)


def _group(path: Path, header: list[str], rows, layout: _Layout) -> list[_Rows]:
    """Numbers parsed (every bad cell reported where it is) and rows grouped by record."""
    numeric = [layout.time, *layout.states, *layout.conditions]
    index = {name: header.index(name) for name in header}
    ids, lines, table = [], [], np.empty((len(rows), len(numeric)))
    for r, (line, cells) in enumerate(rows):
        if layout.record:
            ids.append(cells[index[RECORD]].strip())
            if not ids[-1]:
                raise DataError("empty record id", path, line, RECORD)
        lines.append(line)
        for c, name in enumerate(numeric):
            table[r, c] = _number(cells[index[name]], path, line, name)
    groups, order = {}, []
    for r, rid in enumerate(ids or ["1"] * len(rows)):
        if rid not in groups:
            groups[rid] = [r]
            order.append(rid)
        elif groups[rid][-1] != r - 1:
            raise DataError(f"record {rid} appears again after other records (it started on line "
                            f"{lines[groups[rid][0]]}); the rows of a record must be together, or give the second "
                            "run another record id", path, lines[r], RECORD)
        else:
            groups[rid].append(r)
    if not order:
        raise DataError("no data rows below the header", path)
    return [_Rows(rid, np.array(lines)[groups[rid]], {name: table[groups[rid], c] for c, name in enumerate(numeric)})
            for rid in order]


def _number(text: str, path: Path, line: int, column: str) -> float:
    cell = text.strip()
    if not cell:
        raise DataError("empty cell; every sample needs a value (drop the row or fill the gap, keeping the "
                        "time evenly spaced)", path, line, column)
    try:
        value = float(cell)
    except ValueError:
        raise DataError(f"{cell!r} is not a number", path, line, column) from None
    if not math.isfinite(value):
        raise DataError(f"{cell!r}: every value must be a finite number", path, line, column)
    return value


def _record(path: Path, rows: _Rows, layout: _Layout, system: FirstOrderSystem, defaults: dict,
            rules: _Rules) -> Record:
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


def _condition(path: Path, rows: _Rows, name: str, system: FirstOrderSystem) -> float:
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


def _check_time(path: Path, time: np.ndarray, lines: np.ndarray, column: str, where: str, rules: _Rules) -> float:
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


def _check_length(record: Record, layout: _Layout, rules: _Rules) -> None:
    where = f"record {record.record} (lines {record.lines[0]}-{record.lines[1]})"
    scaled = f" with time_scale={layout.scale:g}" if layout.time == PHYSICAL_TIME and layout.scale != 1 else ""
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
