"""What the fit sees of one window (:class:`Segment`), the RK4 steps between its samples, and the model run at its
sample times."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..codegen.windows import compile_windows
from ..options import Integration
from ..system import FirstOrderSystem


@dataclass(frozen=True)
class Segment:
    """What the fit sees of one window: sample times, measured channels and the record's parameters.
    ``channels``: what each observed name measures (states and derivative placeholders); default the
    names are states."""

    tau: np.ndarray  # (S,)
    observed: dict[str, np.ndarray]  # channel name -> (S,)
    parameters: dict[str, float]  # every parameter value of the window's record
    label: str = ""
    channels: Mapping[str, sp.Expr] | None = None
    key: tuple | None = None  # (record, window index): which windows follow each other

    def channel(self, name: str) -> sp.Expr:
        return (self.channels or {}).get(name, sp.Symbol(name, real=True))


def substeps_for(step: float, period: float, options: Integration) -> int:
    """RK4 steps per sample interval: at least the options' steps per forcing period."""
    return max(1, int(np.ceil(options.steps_per_period * step / period - 1e-9)))


def simulate_segment(system: FirstOrderSystem, seg: Segment, start, estimates: Mapping[str, float] | None = None,
                     period: float = 2 * np.pi, samples: int | None = None,
                     options: Integration = Integration()) -> np.ndarray:
    """The states at ``seg``'s sample times (or ``samples`` of them) from ``start`` (n x samples)."""
    values = {**seg.parameters, **(estimates or {})}
    dt = float(np.median(np.diff(seg.tau)))
    engine = compile_windows(system, [], options.backend)
    run = engine.run(np.asarray(start, float)[:, None], [float(seg.tau[0])], [dt], [samples or len(seg.tau)],
                     [substeps_for(dt, period, options)],
                     np.array([[values[n] for n in system.parameters]]).T, tangent=False)
    return run.states
