"""gearsym: symbolic drivetrain models, reduced and nondimensionalised automatically.

One flat public face; the stages behind it, each handing one type to the next:

* declare: :class:`Drivetrain` from components (:class:`Gear`, :class:`Mesh`, ...), or a plain ODE as a
  :class:`FirstOrderSystem`; ``load_model(name)`` reads one from ``models/`` or a file (``model_module(name)``:
  the whole file, its builders too);
* reduce: :func:`reduce` (Drivetrain -> :class:`NondimensionalModel`), whose ``.system(**values)`` is the
  :class:`FirstOrderSystem` the engine takes; :func:`load` does name -> system in one call;
* compile: :func:`compile_model` (FirstOrderSystem, :class:`Integration` -> :class:`CompiledModel`); how the
  verbs that run many things run them: :class:`Execution` (threads or workers, the lanes, progress);
* analyse: :func:`lyapunov_spectrum`, :func:`poincare_samples`, :func:`phase_trajectory`,
  :func:`simulated_order_spectrum` (and :func:`order_spectrum` of any signal: mesh orders, shaft-order sidebands),
  :func:`find_attractors`, :func:`basin_map` (basins of attraction, many starts at once in the lanes),
  :func:`continue_basins` (basin fractions along a parameter), :func:`run_sweep` (on a CompiledModel, or on a
  system, compiled first);
  periodic orbits and their branches: :func:`periodic_orbit`, :func:`continue_orbits`; parametric
  instability: :func:`stability_chart` (Floquet multipliers over a grid of two parameters, the tongues' kinds and
  boundaries);
* data: :func:`simulate_measurements`, :func:`load_measurements`, :func:`explain`;
* FMUs: :func:`export_fmu` (a model as an FMI 2.0 FMU, co-simulation and model exchange, for other tools);
* physical units: :func:`scaling` (a drivetrain with values in units -> its nondimensional values, and results
  back to rpm, um, N, 1/s), :func:`is_physical`, :func:`natural_modes`, :func:`campbell`;
* document: :func:`derive` and :func:`render`.

The verbs are imported on first use, so ``import gearsym`` stays cheap for a command that needs few of them.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from .errors import GearsymError, ModelError, UnknownParameterError
from .version import __version__


#: the engine's verbs: each face name -> the module of its low-level verb (on a CompiledModel, ``@engine_verb``);
#: the face's verb (:mod:`gearsym.verbs`) is made from it, for a CompiledModel or a system. A new analysis is
#: its module, a line here, and its command (a module of :mod:`gearsym.cli`)
VERBS = {
    "lyapunov_spectrum": "gearsym.analysis.lyapunov",
    "poincare_samples": "gearsym.analysis.poincare",
    "phase_trajectory": "gearsym.analysis.poincare",
    "find_attractors": "gearsym.analysis.attractors",
    "basin_map": "gearsym.analysis.basins",
    "continue_basins": "gearsym.sweep.basin_continuation",
    "run_sweep": "gearsym.sweep.run",
    "periodic_orbit": "gearsym.periodic.orbit",
    "continue_orbits": "gearsym.periodic.branches",
    "simulate_measurements": "gearsym.data.simulate",
    "simulated_order_spectrum": "gearsym.analysis.order_run",
    "stability_chart": "gearsym.stability.verb",
}

#: public name -> the module that defines it (imported when the name is first used: the declaring and
#: reducing stages import SymPy, which a command on a cached model never needs)
_LAZY = {
    "Execution": "gearsym.options",
    "Integration": "gearsym.options",
    "Bearing": "gearsym.model.components",
    "Disk": "gearsym.model.components",
    "Drivetrain": "gearsym.model.drivetrain",
    "Gear": "gearsym.model.components",
    "Harmonic": "gearsym.model.components",
    "Mesh": "gearsym.model.components",
    "Planet": "gearsym.model.components",
    "Shaft": "gearsym.model.components",
    "Torque": "gearsym.model.components",
    "ToothFault": "gearsym.model.faults",
    "Spall": "gearsym.model.faults",
    "Eccentricity": "gearsym.model.faults",
    "SpacingErrors": "gearsym.model.faults",
    "cracked_tooth": "gearsym.model.faults",
    "rectangular_mesh_stiffness": "gearsym.model.stiffness",
    "parse_formula": "gearsym.model.formula",
    "NondimensionalModel": "gearsym.reduction",
    "reduce": "gearsym.reduction",
    "FirstOrderSystem": "gearsym.system",
    "available_models": "gearsym.registry",
    "load": "gearsym.loading",
    "load_model": "gearsym.registry",
    "model_module": "gearsym.registry",
    "CompiledModel": "gearsym.codegen",
    "compile_model": "gearsym.codegen.build",
    "chosen_integration": "gearsym.codegen.fastest_mode",
    "LyapunovSpectrum": "gearsym.analysis.lyapunov",
    "classify_regime": "gearsym.analysis.regime",
    "StabilityChart": "gearsym.stability",
    "read_sweep": "gearsym.sweep",
    "SweepInterrupted": "gearsym.sweep",
    "order_spectrum": "gearsym.analysis.orders",
    "load_measurements": "gearsym.data",
    "explain": "gearsym.fit",
    "EFFECTS": "gearsym.fit",
    "scaling": "gearsym.loading",
    "Scaling": "gearsym.scales.map",
    "natural_modes": "gearsym.loading",
    "campbell": "gearsym.physical.campbell",
    "is_physical": "gearsym.loading",
    "export_fmu": "gearsym.fmu.export",
    "derive": "gearsym.derivation",
    "render": "gearsym.derivation",
    "GearGeometry": "gearsym.geometry",
    "GearPair": "gearsym.geometry",
    "Material": "gearsym.geometry",
    "MeshStiffness": "gearsym.geometry",
    "StiffnessOptions": "gearsym.geometry",
    "gear_geometry": "gearsym.geometry",
    "Crack": "gearsym.geometry",
    "crack_stiffness_loss": "gearsym.geometry",
    "crack_loss_along_path": "gearsym.geometry",
    "gear_pair": "gearsym.geometry",
    "mesh_stiffness": "gearsym.geometry",
    "iso6336_stiffness": "gearsym.geometry",
    **dict.fromkeys(VERBS, "gearsym.verbs"),
}

__all__ = ["GearsymError", "ModelError", "UnknownParameterError", *_LAZY]


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
    from .analysis.lyapunov import LyapunovSpectrum
    from .options import Execution, Integration
    from .analysis.orders import order_spectrum
    from .analysis.regime import classify_regime
    from .codegen import CompiledModel
    from .codegen.build import compile_model
    from .data import load_measurements
    from .derivation import derive, render
    from .fit import EFFECTS, explain
    from .fmu.export import export_fmu
    from .loading import is_physical, load, natural_modes, scaling
    from .model.components import Bearing, Disk, Gear, Harmonic, Mesh, Planet, Shaft, Torque
    from .model.drivetrain import Drivetrain
    from .model.faults import Eccentricity, Spall, SpacingErrors, ToothFault, cracked_tooth
    from .model.stiffness import rectangular_mesh_stiffness
    from .physical.campbell import campbell
    from .reduction import NondimensionalModel, reduce
    from .registry import available_models, load_model
    from .scales.map import Scaling
    from .system import FirstOrderSystem
    from .sweep import SweepInterrupted, read_sweep
    from .stability import StabilityChart
