"""gearsym: symbolic drivetrain models, reduced and nondimensionalised automatically.

One flat public face; the stages behind it, each handing one type to the next:

* declare: :class:`Drivetrain` from components (:class:`Gear`, :class:`Mesh`, ...), or a plain ODE as a
  :class:`FirstOrderSystem`; ``load_model(name)`` reads one from ``models/`` or a file;
* reduce: :func:`reduce` (Drivetrain -> :class:`NondimensionalModel`), whose ``.system(**values)`` is the
  :class:`FirstOrderSystem` the engine takes; :func:`load` does name -> system in one call;
* compile: :func:`compile_model` (FirstOrderSystem, :class:`Integration` -> :class:`CompiledModel`);
* analyse: :func:`lyapunov_spectrum`, :func:`poincare_samples`, :func:`phase_trajectory`,
  :func:`find_attractors`, :func:`run_sweep` (on a CompiledModel, or on a system, compiled first);
  periodic orbits and their branches: :func:`periodic_orbit`, :func:`continue_orbits`;
* data: :func:`simulate_measurements`, :func:`load_measurements`, :func:`explain`;
* physical units: :func:`scaling` (a drivetrain with values in units -> its nondimensional values, and results
  back to rpm, um, N, 1/s), :func:`natural_modes`, :func:`campbell`;
* document: :func:`derive` and :func:`render`.

The verbs are imported on first use, so ``import gearsym`` stays cheap for a command that needs few of them.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

import sys
import types

from .errors import GearsymError, ModelError, UnknownParameterError
from .options import Integration
from .version import __version__


#: public name -> the module that defines it (imported when the name is first used: the declaring and
#: reducing stages import SymPy, which a command on a cached model never needs)
_LAZY = {
    "Disk": "gearsym.model",
    "Drivetrain": "gearsym.model",
    "Gear": "gearsym.model",
    "Harmonic": "gearsym.model",
    "Mesh": "gearsym.model",
    "Planet": "gearsym.model",
    "Shaft": "gearsym.model",
    "Torque": "gearsym.model",
    "rectangular_mesh_stiffness": "gearsym.model",
    "NondimensionalModel": "gearsym.reduce",
    "reduce": "gearsym.reduce",
    "FirstOrderSystem": "gearsym.system",
    "available_models": "gearsym.registry",
    "load": "gearsym.registry",
    "load_model": "gearsym.registry",
    "CompiledModel": "gearsym.codegen",
    "compile_model": "gearsym.codegen",
    "LyapunovSpectrum": "gearsym.analysis",
    "lyapunov_spectrum": "gearsym.analysis",
    "poincare_samples": "gearsym.analysis",
    "phase_trajectory": "gearsym.analysis",
    "find_attractors": "gearsym.analysis",
    "classify_regime": "gearsym.analysis",
    "periodic_orbit": "gearsym.periodic",
    "continue_orbits": "gearsym.periodic",
    "run_sweep": "gearsym.sweep",
    "read_sweep": "gearsym.sweep",
    "Workers": "gearsym.sweep",
    "SweepInterrupted": "gearsym.sweep",
    "simulate_measurements": "gearsym.data",
    "load_measurements": "gearsym.data",
    "explain": "gearsym.fit",
    "EFFECTS": "gearsym.fit",
    "scaling": "gearsym.physical.scales",
    "Scaling": "gearsym.physical.scales",
    "natural_modes": "gearsym.analysis.modes",
    "campbell": "gearsym.physical.campbell",
    "derive": "gearsym.derivation",
    "render": "gearsym.derivation",
    "GearGeometry": "gearsym.geometry",
    "GearPair": "gearsym.geometry",
    "Material": "gearsym.geometry",
    "MeshStiffness": "gearsym.geometry",
    "StiffnessOptions": "gearsym.geometry",
    "gear_geometry": "gearsym.geometry",
    "gear_pair": "gearsym.geometry",
    "mesh_stiffness": "gearsym.geometry",
    "iso6336_stiffness": "gearsym.geometry",
}

__all__ = ["GearsymError", "Integration", "ModelError", "UnknownParameterError", *_LAZY]


class _Package(types.ModuleType):
    """gearsym.reduce is both a function of the face and a subpackage: importing the subpackage (gearsym.load
    does) must not rebind the name to the package, or gearsym.reduce(drivetrain) would call the module."""

    def __setattr__(self, name, value):
        if not (name == "reduce" and isinstance(value, types.ModuleType)):
            super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'gearsym' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # once: later lookups do not come here
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


if TYPE_CHECKING:  # for editors and type checkers, which do not run __getattr__
    from .analysis import (LyapunovSpectrum, classify_regime, find_attractors, lyapunov_spectrum,
                           phase_trajectory, poincare_samples)
    from .codegen import CompiledModel, compile_model
    from .data import load_measurements, simulate_measurements
    from .derivation import derive, render
    from .analysis.modes import natural_modes
    from .fit import EFFECTS, explain
    from .periodic import continue_orbits, periodic_orbit
    from .physical import Scaling, scaling
    from .physical.campbell import campbell
    from .model import Disk, Drivetrain, Gear, Harmonic, Mesh, Shaft, Torque, rectangular_mesh_stiffness
    from .reduce import NondimensionalModel, reduce
    from .registry import available_models, load, load_model
    from .system import FirstOrderSystem
    from .sweep import SweepInterrupted, Workers, read_sweep, run_sweep
