"""What each column of a measurement file is: the time (and its scale), the record label, the channels and the
operating conditions, from the header and the model."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import sympy as sp

from ..errors import option, suggest
from ..system import FirstOrderSystem
from .channels import CHANNELS_HELP, channel_symbols, in_file_units
from .columns import PHYSICAL_TIME, RECORD
from .errors import DataError


@dataclass(frozen=True)
class Layout:
    """What each column of a file is."""

    time: str
    scale: float
    record: str | None
    states: tuple[str, ...]  # the measured channels (states, derivatives, combinations)
    conditions: tuple[str, ...]
    channels: Mapping[str, sp.Expr] = None  # what each measures, in the file's time unit



def layout_of(path: Path, line: int, header: list[str], system: FirstOrderSystem, time_scale,
            declared: Mapping[str, sp.Expr]) -> Layout:
    states, parameters = system.state_names, tuple(system.parameters)
    symbols = channel_symbols(system)
    channel_names = [*symbols, *declared]
    own_time = system.time.name
    times = [own_time] + ([PHYSICAL_TIME] if own_time != PHYSICAL_TIME else [])
    known = [*times, RECORD, *channel_names, *parameters]
    if not set(header) & set(known):  # (perhaps no measurement at all, e.g. a system file: none of it is quoted)
        raise DataError(
            f"none of the {len(header)} column(s) of its header is one gearsym knows: is it a measurement file? Its "
            f"first line names the columns: the time ({' or '.join(times)}), {RECORD}, channels: {CHANNELS_HELP} "
            f"(states of {system.name}: {', '.join(states)}), or parameters as operating conditions "
            f"({', '.join(parameters)})", path, line)
    for i, name in enumerate(header):
        if not name:
            raise DataError(f"column {i + 1} has no name", path, line)
        if header.index(name) != i:
            raise DataError("the column appears twice", path, line, name)
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
                f"the time is t (physical time) but no time scale was given: pass {option('time_scale')} "
                f"({own_time} = time_scale * t; `gearsym derive {system.name}` shows the time unit), or give "
                f"the model's time as a {own_time} column", path, line, PHYSICAL_TIME)
        scale = float(time_scale)
    measured = tuple(c for c in channel_names if c in header)
    if not measured:
        raise DataError(f"no measured state: name at least one column as a channel of {system.name}: {CHANNELS_HELP} "
                        f"(states: {', '.join(states)})", path, line)
    conditions = tuple(p for p in parameters if p in header)
    channels = {c: in_file_units(declared[c] if c in declared else symbols[c], system, scale) for c in measured}
    return Layout(given[0], scale, RECORD if RECORD in header else None, measured, conditions, channels)

