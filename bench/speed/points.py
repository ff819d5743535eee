"""Full Lyapunov spectra at single points, in every tool: the per-point task of the comparison.

Fast tools (fixed-step: gearsym, the C builds, Numba) are repeated and
interleaved (every tool at a point, then the next point, then the next
repetition), so that all of them see the same machine load; slow tools
(JiTCODE, SciPy) run once per tolerance. Each entry keeps every repetition's
time (the tool's own clock around the computation, setup excluded) and the
exponents of the first repetition, in Gram-Schmidt order and sorted.
"""
from __future__ import annotations

import sys
from collections.abc import Callable, Mapping

import numpy as np


def _entry(res) -> dict:
    gs = np.asarray(res.exponents, dtype=float)
    return {"seconds": [res.seconds], "exponents": np.sort(gs)[::-1].tolist(), "sum": float(gs.sum()),
            "final_state": np.asarray(res.final_state, dtype=float).tolist()}


def _tool_record(tool) -> dict:
    return {"name": tool.name, "setup_seconds": tool.setup_seconds, "setup_note": tool.setup_note,
            "accuracy": dict(tool.accuracy), "points": {}}


def time_interleaved(tools: Mapping[str, object], omegas, y0, periods: int, discard: int, repeats: int,
                     log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    out = {label: _tool_record(tool) for label, tool in tools.items()}
    for rep in range(repeats):
        for omega in omegas:
            key = repr(float(omega))
            for label, tool in tools.items():
                res = tool.spectrum(omega, y0, periods, discard)
                points = out[label]["points"]
                if key in points:
                    points[key]["seconds"].append(res.seconds)
                else:
                    points[key] = _entry(res)
        log(f"    repetition {rep + 1}/{repeats}: " + ", ".join(
            f"{label} {sum(p['seconds'][-1] for p in out[label]['points'].values()) * 1e3:.1f} ms"
            for label in tools))
    return out


def time_once(tool, omegas, y0, periods: int, discard: int) -> dict:
    out = _tool_record(tool)
    for omega in omegas:
        out["points"][repr(float(omega))] = _entry(tool.spectrum(omega, y0, periods, discard))
    return out
