"""A scaling that also carries the engine's answers back to the user's units (the face's ``gearsym.scaling``)."""
from __future__ import annotations

from functools import singledispatchmethod

from ..analysis.lyapunov import LyapunovSpectrum
from ..analysis.poincare import Trajectory
from ..errors import GearsymError
from ..periodic.branches import Continuation
from ..scales.map import Scaling
from ..sweep.result import SweepResult
from . import results
from .orbits import continuation_to_physical
from .point import LENGTH_UNIT


class PhysicalScaling(Scaling):
    """A :class:`~gearsym.scales.map.Scaling` with :meth:`to_physical`: this stage sits above the analyses whose
    results it converts, the map below them."""

    @singledispatchmethod
    def to_physical(self, result, length_unit: str = LENGTH_UNIT, **options):
        """A result of the engine in physical units (see :mod:`gearsym.physical.results`):

        * a LyapunovSpectrum: a :class:`~gearsym.physical.point.PhysicalPoint` with the mesh forces and shaft
          torques of ``trajectory`` (a Trajectory at the same point) or, without one, of a trajectory run from the
          spectrum's final state on ``model`` (the compiled model it ran on; default this scaling's system);
        * a Trajectory (run at ``omega``, default this scaling's): a PhysicalTrajectory;
        * a SweepResult: along the physical values ``given`` (the axes swept before they became the engine's) or
          the speed for omega, with ``units``;
        * a Continuation: along the speed (if it ran along omega), with ``units``."""
        raise GearsymError(f"cannot carry a {type(result).__name__} to physical units")

    @to_physical.register
    def _(self, result: LyapunovSpectrum, length_unit: str = LENGTH_UNIT, *, trajectory=None, model=None):
        return results.point_to_physical(self, result, length_unit, trajectory, model)

    @to_physical.register
    def _(self, result: SweepResult, length_unit: str = LENGTH_UNIT, *, given=None):
        return results.sweep_to_physical(self, result, length_unit, given)

    @to_physical.register
    def _(self, result: Trajectory, length_unit: str = LENGTH_UNIT, *, omega: float | None = None):
        return results.trajectory_to_physical(self, result, self.values["omega"] if omega is None else omega,
                                              length_unit)

    @to_physical.register
    def _(self, result: Continuation, length_unit: str = LENGTH_UNIT):
        return continuation_to_physical(self, result, length_unit)

    def compiled_for(self, result):
        """The compiled model the spectrum ``result``'s mesh forces are run on when the caller gives none (its
        integration, as it ran): the face's scaling
        (:func:`gearsym.scaling`) compiles this scaling's system; this stage compiles nothing."""
        raise GearsymError(f"{self.name}: give the compiled model the spectrum ran on, to_physical(result, "
                           "model=...), or its trajectory (trajectory=...)")

    def point_units(self, length_unit: str = LENGTH_UNIT):
        """The numbers that carry a spectrum run back (what the start-up cache keeps: no pint, no SymPy)."""
        return results.point_units(self, length_unit)
