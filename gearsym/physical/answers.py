"""A scaling that also carries the engine's answers back to the user's units (the face's ``gearsym.scaling``)."""
from __future__ import annotations

from ..errors import GearsymError
from ..scales.map import Scaling
from . import results
from .point import LENGTH_UNIT


class PhysicalScaling(Scaling):
    """A :class:`~gearsym.scales.map.Scaling` with :meth:`to_physical`: this stage sits above the analyses whose
    results it converts, the map below them."""

    def to_physical(self, result, length_unit: str = LENGTH_UNIT, *, omega: float | None = None, trajectory=None):
        """A result of the engine in physical units: a LyapunovSpectrum (optionally with the mesh forces of a
        ``trajectory`` at the same point), a Trajectory (run at ``omega``, default this scaling's) or a
        SweepResult along omega (see :mod:`gearsym.physical.results`)."""
        if hasattr(result, "exponents"):
            return results.point_to_physical(self, result, length_unit, trajectory)
        if hasattr(result, "columns"):
            return results.sweep_to_physical(self, result, length_unit)
        if hasattr(result, "states") and hasattr(result, "time"):
            return results.trajectory_to_physical(self, result, self.values["omega"] if omega is None else omega,
                                                  length_unit)
        raise GearsymError(f"cannot carry a {type(result).__name__} to physical units")

    def point_units(self, length_unit: str = LENGTH_UNIT):
        """The numbers that carry a spectrum run back (what the start-up cache keeps: no pint, no SymPy)."""
        return results.point_units(self, length_unit)
