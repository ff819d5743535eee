"""gearsym: symbolic drivetrain models, reduced and nondimensionalised automatically.

Pipeline: ``gearsym.model`` (declare) -> ``gearsym.reduce`` (relative coordinates,
groups, tau-form) -> ``gearsym.system`` (first-order ODE for the engine);
``gearsym.derivation`` renders the derivation as text, LaTeX, JSON or Markdown.
"""
from .errors import GearsymError, ModelError, UnknownParameterError
from .model import Disk, Drivetrain, Gear, Harmonic, Mesh, Shaft, Torque, rectangular_mesh_stiffness
from .reduce import NondimensionalModel, reduce
from .registry import available_models, load_model
from .system import FirstOrderSystem

__version__ = "0.1.0"

__all__ = [
    "Disk", "Drivetrain", "FirstOrderSystem", "Gear", "GearsymError", "Harmonic", "Mesh", "ModelError",
    "NondimensionalModel", "Shaft", "Torque", "UnknownParameterError", "available_models", "load_model",
    "rectangular_mesh_stiffness", "reduce",
]
