"""Analyses on one parameter point: a high-level call on a model, or a low-level
call on a prebuilt :class:`~gearsym.codegen.CompiledModel` reused across a sweep."""
from .lyapunov import LyapunovSpectrum, lyapunov_spectrum
from .orbits import Orbit, Trajectory, phase_trajectory, poincare_samples
from .statistics import batch_means_stderr

__all__ = ["LyapunovSpectrum", "Orbit", "Trajectory", "batch_means_stderr", "lyapunov_spectrum",
           "phase_trajectory", "poincare_samples"]
