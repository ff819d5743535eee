"""The 191-point continuation sweep (omega = 0.1 ... 2.0, step 0.01) in every tool.

Each point starts from the previous point's final state (the paper's
procedure). Fast tools repeat it, interleaved; slow tools run it once, and a
tool too slow for all 191 points (SciPy) runs every ``every``-th point as its
own, coarser continuation, which gives its time per point (the quantity
compared) without an hour of waiting. Continuations of different tools drift
apart after chaotic windows (last-bit differences grow), so the exponents are
compared point by point only to count agreement, not as an error.
"""
from __future__ import annotations

import sys
from collections.abc import Callable, Mapping

import numpy as np

OMEGA_START, OMEGA_STEP, POINTS = 0.1, 0.01, 191


def omegas(every: int = 1) -> list[float]:
    """The C program's own expression for the grid, so every tool visits the same floats."""
    return [OMEGA_START + OMEGA_STEP * i for i in range(0, POINTS, every)]


def _record(tool, results, every: int) -> dict:
    return {"name": tool.name, "accuracy": dict(tool.accuracy), "every": every,
            "seconds": [float(sum(r.seconds for r in results))], "points": len(results),
            "exponents": [np.sort(np.asarray(r.exponents))[::-1].tolist() for r in results]}


def time_sweeps(tools: Mapping[str, object], y0, periods: int, discard: int, repeats: int, every: int = 1,
                log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    out: dict[str, dict] = {}
    grid = omegas(every)
    for rep in range(repeats):
        for label, tool in tools.items():
            results = tool.sweep(grid, y0, periods, discard)
            if label in out:
                out[label]["seconds"].append(float(sum(r.seconds for r in results)))
            else:
                out[label] = _record(tool, results, every)
        log(f"    repetition {rep + 1}/{repeats}: "
            + ", ".join(f"{label} {out[label]['seconds'][-1]:.3f} s" for label in tools))
    return out


def time_sweep_once(tool, y0, periods: int, discard: int, every: int = 1) -> dict:
    return _record(tool, tool.sweep(omegas(every), y0, periods, discard), every)
