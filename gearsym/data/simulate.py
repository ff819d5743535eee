"""Synthetic measurements: a model run by the compiled engine, sampled evenly and given noise.

Each record is one run at its operating conditions: ``discard`` forcing periods of transient
from ``y0`` (the model's start by default), then the other ``periods - discard`` periods
sampled ``samples_per_period`` times per period (the end point included, so a record has
``(periods - discard) * samples_per_period + 1`` rows). The samples are RK4 steps of the engine itself
(:func:`~gearsym.analysis.poincare.phase_trajectory`), so the engine's steps per period is a multiple
of ``samples_per_period``: by default the smallest multiple of at least 200.

``tau`` starts at 0 in every record. The transient is a whole number of forcing periods, so
the forcing phase at tau is the model's: the file can be fitted with tau as the model's time.

Noise is Gaussian, independent per sample, with a standard deviation of ``noise`` times the
standard deviation of the clean signal, per record and per state column (``noise=0.01``: 1 %
of the signal's spread). The table keeps the clean signal and the standard deviations used.

Which parameters appear in the file: only the operating conditions given per record
(``records=[{"omega": 1.2}, ...]``, the ``--record`` option), as columns. Other parameter values
are the simulated ("true") model, which a fit has to find: they are not written.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.poincare import phase_trajectory
from ..errors import GearsymError, option, option_name as caller_name
from ..checks import MAX_STEPS_PER_PERIOD, check_fits, whole_number
from ..codegen import CompiledModel, engine_verb
from ..options import STEPS_PER_PERIOD, Integration
from ..files.atomic import write_atomically
from .columns import RECORD

#: the run of each record when no options are given: 40 periods recorded after a transient of 100
RUN = {"periods": 140, "discard": 100}


@dataclass(frozen=True, eq=False)
class MeasurementTable:
    """A tidy table of simulated measurements, one row per sample, records one after another.

    ``data`` maps every column to its values (``record`` holds integers 1, 2, ...); ``clean``
    the state columns before noise; per record, ``noise_std`` the noise's standard deviation per
    state column and ``parameters`` every parameter value it was simulated with.
    """

    model: str
    columns: tuple[str, ...]
    data: Mapping[str, np.ndarray]
    clean: Mapping[str, np.ndarray]
    noise_std: tuple[Mapping[str, float], ...]
    parameters: tuple[Mapping[str, float], ...]
    samples_per_period: int
    steps_per_period: int

    def __getitem__(self, column: str) -> np.ndarray:
        return self.data[column]

    @property
    def rows(self) -> int:
        return int(self.data[RECORD].size)

    @property
    def records(self) -> int:
        return len(self.parameters)

    @property
    def states(self) -> tuple[str, ...]:
        return tuple(self.clean)

    @property
    def conditions(self) -> tuple[str, ...]:
        return tuple(c for c in self.columns if c not in ("tau", RECORD) and c not in self.clean)

    def rows_of(self, record: int) -> np.ndarray:
        """The row indices of record ``record`` (1-based, as in the ``record`` column)."""
        return np.nonzero(self.data[RECORD] == record)[0]


def _default_options(*, samples_per_period: int = 50, **_) -> Integration:
    """How a system is compiled for this verb: for ``RUN``, with steps per period that the samples divide."""
    return Integration(**RUN, steps_per_period=steps_for(samples_per_period))


@engine_verb(default=_default_options)
def simulate_measurements(
    model: CompiledModel,
    *,
    options: Integration | None = None,
    samples_per_period: int = 50,
    noise: float = 0.0,
    seed: int = 0,
    records: Sequence[Mapping[str, float]] | None = None,
    y0=None,
    velocities: bool = False,
    out: str | Path | None = None,
    **values: float,
) -> MeasurementTable:
    """Simulate measurements of ``model`` (a CompiledModel, or a FirstOrderSystem compiled first).

    Each record discards ``options.discard`` periods and records the remaining ``periods - discard``
    (a system is compiled by default for ``RUN``: 40 periods after 100). The engine's steps per period
    must be a multiple of ``samples_per_period`` (the samples are RK4 steps); a system is compiled with
    the smallest multiple of at least 200 unless the options say otherwise.
    ``records``: the operating conditions of each record (parameter values, written as columns);
    default one record without conditions. ``velocities``: also the states that are not
    coordinates (``v``, ``v1``, ...). ``out``: also write the table there (:func:`write_measurements`).
    """
    options = model.run_options(options)
    m = whole_number(samples_per_period, "samples_per_period", 1)
    seed = whole_number(seed, "seed")
    if not (np.isfinite(noise) and noise >= 0):
        raise GearsymError(f"noise must be a relative size of 0 or more (0.01 = 1 % of the signal), got {noise!r}")
    steps_for(m, model.steps_per_cycle)
    runs = [dict(r) for r in records] if records else [{}]
    columns = 2 + len(model.parameter_names) + 2 * len(model.state_names)  # at most: tau, record, conditions, states
    check_fits(options.measured, 8 * (model.steps_per_period * (model.dimension + 1) + len(runs) * m * columns),
               asked=f"{option('samples_per_period', m)} over {option('periods', options.periods)}", item="period",
               what="a record's run at every RK4 step and the table's rows")
    condition_names = tuple(p for p in model.parameter_names if any(p in r for r in runs))
    for run in runs:
        model.parameter_vector({**values, **run})  # unknown names and bad values, before any run
    states = model.observed + (tuple(s for s in model.state_names if s not in model.observed)
                               if velocities else ())
    rng = np.random.default_rng(seed)
    pieces = [_simulate_record(model, options, i, {**values, **run}, condition_names, states, m, y0, noise, rng)
              for i, run in enumerate(runs, 1)]
    columns = ("tau", RECORD, *condition_names, *states)
    table = MeasurementTable(
        model.name, columns,
        {c: np.concatenate([p.data[c] for p in pieces]) for c in columns},
        {s: np.concatenate([p.clean[s] for p in pieces]) for s in states},
        tuple(p.noise_std for p in pieces), tuple(p.parameters for p in pieces), m, model.steps_per_cycle)
    if out is not None:
        write_measurements(table, out)
    return table


def steps_for(samples_per_period: int, steps_per_period: int | None = None) -> int:
    """The engine's steps per period for sampling ``samples_per_period`` times a period: ``steps_per_period``
    if given (checked to be a multiple), else the smallest multiple of at least the default steps."""
    samples = whole_number(samples_per_period, caller_name("samples_per_period"), 1)
    if samples > MAX_STEPS_PER_PERIOD:
        raise GearsymError(f"{option('samples_per_period', samples)}: the samples are RK4 steps of the engine, and "
                           f"a forcing period has at most {MAX_STEPS_PER_PERIOD} "
                           f"(see {caller_name('steps_per_period')})")
    if steps_per_period is None:
        return samples * -(-STEPS_PER_PERIOD // samples)
    steps = whole_number(steps_per_period, caller_name("steps_per_period"), 1)
    if steps % samples:
        raise GearsymError(f"samples_per_period={samples} must divide the engine's {steps} steps per period (the "
                           f"samples are RK4 steps): choose a divisor, or steps_per_period="
                           f"{samples * -(-steps // samples)}")
    return steps


@dataclass(frozen=True)
class _Piece:
    data: dict[str, np.ndarray]
    clean: dict[str, np.ndarray]
    noise_std: dict[str, float]
    parameters: dict[str, float]


def _simulate_record(compiled: CompiledModel, options: Integration, record: int, parameters: dict, condition_names,
                     states, samples: int, y0, noise: float, rng: np.random.Generator) -> _Piece:
    trajectory = phase_trajectory(compiled, options=options, y0=y0, **parameters)
    stride = compiled.steps_per_cycle // samples  # (samples per forcing period; a period may hold several)
    sampled = trajectory.states[:, ::stride]
    period = compiled.prepare(compiled.parameter_vector(parameters)).period
    tau = (period / compiled.steps_per_period) * stride * np.arange(sampled.shape[1])
    used = dict(zip(compiled.parameter_names, map(float, compiled.parameter_vector(parameters))))
    data = {"tau": tau, RECORD: np.full(tau.size, record, dtype=np.int64)}
    data.update({c: np.full(tau.size, used[c]) for c in condition_names})
    clean, std = {}, {}
    for name in states:
        clean[name] = sampled[compiled.state_names.index(name)]
        std[name] = float(noise * np.std(clean[name]))
        data[name] = clean[name] + rng.normal(0.0, std[name], clean[name].size)
    return _Piece(data, clean, std, used)


def write_measurements(table: MeasurementTable, path: str | Path) -> Path:
    """Write the table as CSV: a header, then one line per row; floats as ``repr`` (read back exactly),
    record ids as integers. The same table always gives the same bytes."""
    path = Path(path)
    if path.suffix.lower() != ".csv":
        raise GearsymError(f"{path}: measurements are written as CSV; name the file *.csv")
    columns = [table.data[c] for c in table.columns]
    text = [",".join(table.columns)]
    for i in range(table.rows):
        text.append(",".join(str(int(col[i])) if name == RECORD else repr(float(col[i]))
                             for name, col in zip(table.columns, columns)))
    return write_atomically(path, "\n".join(text) + "\n")  # (whole or not at all; a symlink is not written through)
