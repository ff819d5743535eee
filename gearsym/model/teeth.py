"""Tooth counts for a model that declares none: ``--teeth Z1,Z2`` (``teeth=(Z1, Z2)`` in Python).

The counts go to the gears of the model's first mesh: Z1 to its *pinion*, the driving gear (the one a driving
torque acts on, else the one whose speed is the operating point, else the mesh's first gear), Z2 to its *wheel*.
The model is not changed: :func:`with_teeth` returns a copy with those two gears declared with their teeth
(every component that refers to them refers to the copies), made once per model, version and counts.
"""
from __future__ import annotations

import dataclasses
import weakref

from .declared import Model
from ..errors import GearsymError, ModelError
from .components import Body, Gear, Mesh
from .drivetrain import Drivetrain
from .shaft_orders import teeth_of
from .tooth_counts import ToothCounts


#: model -> counts -> (the model's version, its copy with those counts), for as long as the model lives
_WITH_TEETH: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def first_mesh_gears(model: Drivetrain) -> tuple[Gear, Gear]:
    """The pinion (driving gear) and the wheel of the model's first mesh."""
    meshes = [c for c in model.couplings if isinstance(c, Mesh)]
    if not meshes:
        raise ModelError("has no mesh, so there are no gears to give tooth counts to", model.name)
    mesh = meshes[0]
    by_name = {b.name: b for b in model.bodies}
    ends = [end if isinstance(end, Body) else by_name.get(end) for end in mesh.ends]
    if not all(isinstance(end, Gear) for end in ends):
        raise ModelError(f"the first mesh {mesh.name!r} does not join two gears of the model", model.name)
    driven = {t.on.name if isinstance(t.on, Body) else t.on for t in model.torques if not t.load}
    for rule in (lambda b: b.name in driven, lambda b: bool(b.speed_parameter)):
        chosen = [end for end in ends if rule(end)]
        if len(chosen) == 1:
            pinion = chosen[0]
            return pinion, ends[1] if pinion is ends[0] else ends[0]
    return ends[0], ends[1]


def with_teeth(model: Model, counts: ToothCounts | None) -> Model:
    """``model`` with the tooth ``counts`` on its first mesh's gears (a copy; the same copy for the same model,
    version and counts). None: the model itself."""
    if counts is None:
        return model
    if not model.is_drivetrain:
        raise GearsymError(f"{model.name}: --teeth gives tooth counts to the gears of a drivetrain; a first-order "
                           "system has none")
    kept = _WITH_TEETH.setdefault(model, {})
    if counts in kept and kept[counts][0] == model.version:
        return kept[counts][1]
    pinion, wheel = first_mesh_gears(model)
    declared = [b.name for b in (pinion, wheel) if b.tooth_count is not None]
    if declared:
        told = "declare their tooth counts" if len(declared) > 1 else "declares its tooth count"
        raise GearsymError(f"{model.name}: {' and '.join(declared)} {told} already (Gear(..., teeth=)); --teeth is "
                           "for a model that declares none")
    for z, gear in zip(counts, (pinion, wheel)):
        teeth_of(z, f"--teeth for {gear.name!r}")
    copy = model.with_bodies({gear.name: dataclasses.replace(gear, teeth=z)
                              for gear, z in zip((pinion, wheel), counts)})
    kept[counts] = (model.version, copy)
    return copy
