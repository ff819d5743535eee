"""Declaring drivetrains: components, parameters and the Lagrangian (pipeline step 1)."""
from .components import Body, Disk, Gear, Harmonic, Mesh, Planet, Shaft, Torque
from .drivetrain import Drivetrain
from .stiffness import rectangular_mesh_stiffness

__all__ = ["Body", "Disk", "Drivetrain", "Gear", "Harmonic", "Mesh", "Planet", "Shaft", "Torque",
           "rectangular_mesh_stiffness"]
