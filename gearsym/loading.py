"""Names and files to systems, scalings and modes: the face's verbs that take a model by name.

The registry turns a name or a file into the declared model; this module takes it down the pipeline with the
caller's values: reduced (:func:`reduced`), scaled when it has physical values (:func:`scaling`), made the
engine's first-order system (:func:`load`), or its natural modes (:func:`natural_modes`). Every stage below
takes the typed object these make; nothing below resolves a name.
"""
from __future__ import annotations

import os

from .analysis.modes import Modes, drivetrain_modes, nondimensional_modes, physical_modes
from .codegen.build import compile_model
from .errors import GearsymError
from .options import Integration
from .model.teeth import with_teeth
from .model.tooth_counts import ToothCounts
from .physical.answers import PhysicalScaling
from .reduction import NondimensionalModel, reduce
from .registry import load_model, model_options
from .scales.settings import maybe_number, physical_settings
from .scales.si_values import si_values
from .system import FirstOrderSystem
from .units import is_quantity


def declared(ref, teeth=None, options=None):
    """The declared model of a name, a file or a model, with ``teeth`` = (pinion, wheel) tooth counts given to a
    drivetrain that declares none (:func:`gearsym.model.teeth.with_teeth`; read here, where they enter) and
    ``options`` given to its file's ``build`` (model options such as ``planets=4``)."""
    return with_teeth(load_model(ref, options), ToothCounts.of(teeth))


def split_options(ref, values: dict) -> tuple[dict, dict]:
    """``values`` split into the model options its file declares (``planets=4``) and the rest."""
    if not isinstance(ref, (str, os.PathLike)) or not values:
        return {}, dict(values)
    names = model_options(ref)
    return ({k: v for k, v in values.items() if k in names}, {k: v for k, v in values.items() if k not in names})


def reduced(ref, teeth=None, options=None) -> NondimensionalModel:
    """The reduction of a model (a name, a file, a Drivetrain or its reduction)."""
    if isinstance(ref, NondimensionalModel):
        if teeth is not None:
            return reduced(ref.drivetrain, teeth)
        return ref
    model = declared(ref, teeth, options)
    if not model.is_drivetrain:
        raise GearsymError(f"{model.name}: a first-order system has no components to reduce (it is one already)")
    return reduce(model)


class ModelScaling(PhysicalScaling):
    """The face's scaling: a spectrum carried to physical units without the compiled model it ran on has its mesh
    forces run on this scaling's system, compiled here (the units stage below compiles nothing)."""

    def compiled_for(self, result):
        system = self.system()
        return compile_model(system, result.info.get("integration") or Integration(
            steps_per_period=result.steps_per_period // system.cycles))


def scaling(model, length_scale=None, *, teeth=None, **physical) -> PhysicalScaling:
    """The scaling of a model (a name, a file, a Drivetrain or its reduction) at its declared physical values,
    with ``physical`` overriding them (``kZ="3e8 N/m"``, ``speed="3000 rpm"``) or replacing a stiffness function
    by a formula in tau or phi (``k="1+0.2*cos(tau)"``, with the values of its new parameters); ``teeth``: tooth
    counts for a model that declares none."""
    if not isinstance(model, NondimensionalModel):
        options, physical = split_options(model, physical)
        model, teeth = declared(model, teeth, options), None
        if not model.is_drivetrain:
            raise GearsymError(f"{model.name}: physical values need a drivetrain model (a FirstOrderSystem has no "
                               "components to give them units)")
    return ModelScaling.of(reduced(model, teeth), length_scale, **physical)


def load(ref, *, teeth=None, **values) -> FirstOrderSystem:
    """The first-order system of a model, ready for the engine: the one place names and files are resolved.

    ``ref`` is a model name (``models/<name>.py``), the path of a model file, a Drivetrain, a reduced
    NondimensionalModel or a FirstOrderSystem. ``values`` give parameter values (``omega=1.5``) or, for a
    drivetrain, a new mesh stiffness as a formula in tau (``k="1 + 0.2*cos(tau)"``). Strings that read as
    numbers are numbers. A drivetrain with physical values (``model.set_physical``), or given one here
    (``kZ="2e8 N/m"``, ``speed="3000 rpm"``, a pint Quantity; ``length_scale="backlash"``), is scaled to its
    nondimensional values by :class:`gearsym.scales.map.Scaling`. ``teeth`` = (Z1, Z2): the tooth counts of the
    first mesh's pinion (its driving gear) and wheel, for a model that declares none (``--teeth Z1,Z2``).
    """
    options, values = split_options(ref, values)
    model = reduced(ref, teeth) if isinstance(ref, NondimensionalModel) else declared(ref, teeth, options)
    values = {k: maybe_number(v) for k, v in values.items()}
    if isinstance(model, FirstOrderSystem):
        for key, value in values.items():
            if not isinstance(value, (int, float)):
                raise GearsymError(
                    f"{model.name}: {key}={value!r} is not a number; only drivetrain models accept a formula "
                    "(a new mesh stiffness function) or a physical value"
                )
        return model.with_values(**values)
    nd = reduced(model)
    split = physical_settings(nd, values)
    if split is not None:
        length_scale, physical, formulas = split
        return scaling(nd, length_scale, **physical, **formulas).system()
    return nd.system(**values)


def natural_modes(model, *, teeth=None, **settings) -> Modes:
    """The natural modes of ``model`` (a name, a file, a Drivetrain or its reduction). ``settings`` are physical
    values (``kZ="2e8 N/m"``: frequencies in Hz; also for a model that declares physical values) or, for a
    model without, nondimensional parameter values (``kS=0.5``); a stiffness formula (``k="1+0.2*cos(tau)"``)
    enters through its mean."""
    options, settings = split_options(model, settings)
    found = declared(model, teeth, options) if not isinstance(model, NondimensionalModel) else model.drivetrain
    plain = all(is_quantity(v) or isinstance(maybe_number(v), (int, float)) for v in settings.values())
    if getattr(found, "is_drivetrain", False) and getattr(found, "bearings", None) and found.physical \
            and "length_scale" not in settings and plain:
        # (a drivetrain on bearings: its modes from its kinematics, without the long reduction)
        return drivetrain_modes(found, si_values(found, settings))
    nd = reduced(model, teeth, options)
    split = physical_settings(nd, dict(settings))
    if split is not None:
        length_scale, physical, formulas = split
        return physical_modes(scaling(nd, length_scale, **physical, **formulas))
    return nondimensional_modes(nd, settings)


def is_physical(model, *, teeth=None, **values) -> bool:
    """Whether ``model`` (a name, a file or a model) with ``values`` runs in physical units (it declares
    physical values, or ``values`` give one or a length scale). Nothing is reduced to tell."""
    options, values = split_options(model, values)
    found = model if isinstance(model, NondimensionalModel) else load_model(model, options)
    drivetrain = found.drivetrain if isinstance(found, NondimensionalModel) else found
    if not drivetrain.is_drivetrain:
        return False
    return bool(drivetrain.physical) or "length_scale" in values or any(is_quantity(v) for v in values.values())
