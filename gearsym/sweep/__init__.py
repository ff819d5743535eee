"""Parameter sweeps: Lyapunov spectra over grids of parameter values.

``run_sweep(model, {"omega": values}, ...)`` computes the Lyapunov spectrum,
amplitudes and regime at every point and, given ``out``, writes them as they
finish (resumable); ``read_sweep(path)`` reads a sweep back.

The running of sweeps (:mod:`.run` and :mod:`.workers`, with the Dask side, which loads the code generator and
SymPy) is imported when first asked for, so that a command that only reads grids or sweep files (``gearsym
basins`` on a cached model) starts without it.
"""
from __future__ import annotations

import importlib

from .grid import DIRECTIONS, MODES, Axis, parse_axis
from .result import SweepResult, read_sweep

#: the names imported on first use, and their modules
_LAZY = {"PARALLEL": "workers", "Workers": "workers", "POINCARE_SAMPLES": "run", "SweepInterrupted": "run",
         "run_sweep": "run"}

__all__ = ["Axis", "DIRECTIONS", "MODES", "PARALLEL", "POINCARE_SAMPLES", "SweepInterrupted", "SweepResult", "Workers",
           "parse_axis", "read_sweep", "run_sweep"]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
