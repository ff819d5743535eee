"""Analyses on one parameter point: a high-level call on a model, or a low-level
call on a prebuilt :class:`~gearsym.codegen.CompiledModel` reused across a sweep."""
from .attractors import Attractor, AttractorSet, find_attractors
from .basins import BasinAttractor, BasinMap, basin_map
from .jumps import Jump, find_jumps, hysteresis_intervals
from .lyapunov import LyapunovSpectrum, lyapunov_spectrum
from .poincare import Orbit, Trajectory, phase_trajectory, poincare_samples
from .order_run import simulated_order_spectrum
from .orders import OrderSpectrum, order_spectrum
from .regime import REGIMES, classify_regime
from .statistics import batch_means_stderr

__all__ = ["Attractor", "AttractorSet", "BasinAttractor", "BasinMap", "Jump", "LyapunovSpectrum", "Orbit",
           "OrderSpectrum", "REGIMES", "Trajectory", "basin_map", "batch_means_stderr", "classify_regime",
           "find_attractors", "find_jumps", "hysteresis_intervals", "lyapunov_spectrum", "order_spectrum",
           "phase_trajectory", "poincare_samples", "simulated_order_spectrum"]
