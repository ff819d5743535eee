"""FMUs: a model's generated C as an FMI 2.0 Functional Mock-up Unit (model exchange and co-simulation).

``frame`` (how the FMU's variables stand to the engine's: SI for a physical model) -> ``variables`` (the
variables, named as in the model) -> ``functions`` (the FMU's own CasADi functions: tables at one time, event
indicators, outputs) -> ``wrapper`` (the one C wrapper and the model's header) and ``description``
(modelDescription.xml) -> ``build`` (the binary and the archive, ``archive``); ``physical`` makes the frame of a
model with physical values from its scaling, and ``export`` is the face: :func:`export_fmu`.
"""
from __future__ import annotations

from .build import ExportedFmu, build_fmu
from .frame import Frame

__all__ = ["ExportedFmu", "Frame", "build_fmu"]
