"""Reduction to relative coordinates and the nondimensional form (pipeline step 2)."""
from .coordinates import Coordinate, relative_coordinates, rigid_body_modes
from .nondimensional import Condition, Group, NondimensionalModel, StiffnessFunction, nondimensionalize, reduce
from .reduction import Reduction, ReductionError, reduce_drivetrain

__all__ = [
    "Condition", "Coordinate", "Group", "NondimensionalModel", "Reduction", "ReductionError",
    "StiffnessFunction", "nondimensionalize", "reduce", "reduce_drivetrain", "relative_coordinates",
    "rigid_body_modes",
]
