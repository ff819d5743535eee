"""``export_fmu``: the face of the FMU export, from a model name or file, a drivetrain, a system or a compiled
model. A model with physical values (declared, or given in ``values``) gives an FMU in SI (:mod:`.physical`);
any other the engine's nondimensional variables."""
from __future__ import annotations

from pathlib import Path

from ..codegen.compiled import CompiledModel
from ..errors import GearsymError
from ..options import Integration
from ..loading import load, reduced
from ..reduction import NondimensionalModel
from ..registry import load_model
from ..system import FirstOrderSystem
from .build import ExportedFmu, build_fmu
from .frame import Frame
from .physical import physical_frame


def export_fmu(model, path, *, options: Integration | None = None, **values) -> ExportedFmu:
    """Write the FMI 2.0 FMU (co-simulation and model exchange, this platform's binary and the C sources) of
    ``model`` to ``path``.

    ``model``: a model name (``models/<name>.py``) or file, a Drivetrain or its reduction, a FirstOrderSystem or a
    CompiledModel; ``values``: parameter values, physical values with units or a new stiffness formula, as
    ``gearsym.load`` takes them (they become the FMU's start values, a formula its code). ``options``: the
    engine's step (its steps per period set the default experiment's step; with crossings located, the default,
    the co-simulation step splits at the backlash as every gearsym run does); a compiled model's own by default.
    """
    path = Path(path)
    if path.suffix.lower() != ".fmu":
        raise GearsymError(f"{path}: an FMU's file name ends in .fmu")
    if isinstance(model, CompiledModel):
        system = model.system.full  # (a model from the start-up cache: the system its summary stands for)
        return build_fmu(system.with_values(**values) if values else system, path, options or model.integration)
    options = options or Integration()
    if isinstance(model, FirstOrderSystem):
        return build_fmu(load(model, **values), path, options)
    teeth = values.pop("teeth", None)  # (tooth counts for a model that declares none)
    declared = model if isinstance(model, NondimensionalModel) else load_model(model)
    if isinstance(declared, FirstOrderSystem):
        return build_fmu(load(declared, teeth=teeth, **values), path, options)
    nd = reduced(declared, teeth)
    system = load(nd, **values)
    frame = physical_frame(nd, values, system)
    return build_fmu(system, path, options, frame or Frame())
