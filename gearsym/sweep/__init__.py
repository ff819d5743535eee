"""Sweeps over declared parameters: continuation (the paper's procedure) or independent points.

``run_sweep(model, {"omega": values}, ...)`` computes the Lyapunov spectrum,
amplitudes and regime at every point and, given ``out``, writes them as they
finish (resumable); ``read_sweep(path)`` reads a sweep back.
"""
from .grid import DIRECTIONS, MODES, Axis, parse_axis
from .result import SweepResult, read_sweep
from .run import POINCARE_SAMPLES, SweepInterrupted, run_sweep
from .workers import PARALLEL, Workers

__all__ = ["Axis", "DIRECTIONS", "MODES", "PARALLEL", "POINCARE_SAMPLES", "SweepInterrupted", "SweepResult", "Workers",
           "parse_axis", "read_sweep", "run_sweep"]
