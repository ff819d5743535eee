"""One record (a run at fixed operating conditions, evenly sampled) and its forcing-period windows."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import sympy as sp

from ..errors import GearsymError

#: rounding allowance at window edges, as a fraction of a sample step
_EDGE = 1e-6


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

