"""Amplitude jumps along a continuation, and hysteresis between the up and down runs.

A jump is a step in A between neighbouring points of a continuation that
stands out from how A changes around it: |dA| is larger than ``ratio`` times the
median |dA| over ``window`` neighbouring steps on either side, and larger than
``min_fraction`` of the amplitude there (the larger of the two). The first rule
keeps a steep but smooth slope (or a noisy chaotic window) from counting; the
second keeps numerical wobble on a flat curve from counting. A cliff that
takes a few grid steps is one jump, and it must be steep beside its own
neighbours too (the steps just before and after it at most a third of its
own): a slope that goes on, as the smooth decay from a sweep's first point,
is no jump however it compares with the flat curve further on. This is what one sees by eye in the
paper's Fig. 3a (jumps near omega = 1.36 and 1.70 for D = 2); the scale is
local because a jump of 1 next to a resonance peak of 40 is still a jump.

Hysteresis: where a run up and a run down over the same grid settle on
different attractors, their amplitudes differ. The intervals are the maximal
runs of grid points where |A_up - A_down| exceeds ``min_fraction`` of the larger.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

RATIO = 5.0
WINDOW = 5
MIN_FRACTION = 0.05
#: a jump's steps over the steps just beside it, at least
SIDE_RATIO = 3.0


@dataclass(frozen=True)
class Jump:
    """A step in the amplitude between two neighbouring points of one continuation."""

    start: float  # parameter value before the jump (in the order the run went)
    end: float  # ... and after it
    before: float  # A at start
    after: float  # A at end

    @property
    def size(self) -> float:
        return self.after - self.before

    def as_dict(self) -> dict:
        return {"from": self.start, "to": self.end, "A_before": self.before, "A_after": self.after}


def find_jumps(values: Sequence[float], amplitude: Sequence[float], *, ratio: float = RATIO,
               window: int = WINDOW, min_fraction: float = MIN_FRACTION) -> list[Jump]:
    """Jumps of ``amplitude`` along ``values`` (both in the order the continuation went)."""
    x, a = np.asarray(values, dtype=float), np.asarray(amplitude, dtype=float)
    if x.shape != a.shape or x.ndim != 1:
        raise ValueError(f"values and amplitudes must be 1-D and of one length, got {x.shape} and {a.shape}")
    if a.size < 3 or not np.isfinite(a).all():
        return []
    signed = np.diff(a)
    step = np.abs(signed)
    level = np.maximum(np.abs(a[:-1]), np.abs(a[1:]))
    cliffs: list[list[int]] = []  # runs of neighbouring steps that stand out, of one sign
    for i, d in enumerate(step):
        around = np.concatenate([step[max(0, i - window):i], step[i + 1:i + 1 + window]])
        if not (d > min_fraction * level[i] and d > ratio * float(np.median(around))):
            continue
        if cliffs and cliffs[-1][-1] == i - 1 and np.sign(signed[i]) == np.sign(signed[i - 1]):
            cliffs[-1].append(i)  # the same cliff
        else:
            cliffs.append([i])
    jumps = []
    for run in cliffs:
        first, last = run[0], run[-1]
        # a jump is steep next to both of its sides: the step just before and the step just after it (those that
        # exist) are small beside its own; a slope that goes on (a smooth decay from the sweep's first point,
        # 7.956, 7.559, 7.307 um) does not
        beside = [step[k] for k in (first - 1, last + 1) if 0 <= k < step.size]
        if any(b > min(step[first], step[last]) / SIDE_RATIO for b in beside):
            continue
        jumps.append(Jump(float(x[first]), float(x[last + 1]), float(a[first]), float(a[last + 1])))
    return jumps


def hysteresis_intervals(values: Sequence[float], up: Sequence[float], down: Sequence[float], *,
                         min_fraction: float = MIN_FRACTION) -> list[tuple[float, float]]:
    """[low, high] intervals of ``values`` (ascending) where the amplitudes of the two runs differ."""
    x, a, b = (np.asarray(v, dtype=float) for v in (values, up, down))
    if not (x.shape == a.shape == b.shape) or x.ndim != 1:
        raise ValueError("values, up and down amplitudes must be 1-D and of one length")
    if x.size == 0:
        return []
    differ = np.abs(a - b) > min_fraction * np.maximum(np.abs(a), np.abs(b))
    intervals, start = [], None
    for i, d in enumerate(differ):
        if d and start is None:
            start = i
        if start is not None and (not d or i == len(differ) - 1):
            last = i if d else i - 1
            intervals.append((float(x[start]), float(x[last])))
            start = None
    return intervals
