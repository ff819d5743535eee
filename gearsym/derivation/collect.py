"""Collecting the derivation of a model into a :class:`~gearsym.derivation.records.Derivation`.

This is the one place that walks the pipeline (declaration -> Lagrangian ->
equations of motion -> reduction -> groups -> tau-form -> first-order
system) and keeps what each step produced. Every expression comes from the
core API, so the docs cannot drift from the code; the only things computed
here are the derived groups' values at the defaults and, for parameters the
model does not describe, a description of their role in the components.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from pathlib import Path

import sympy as sp

from ..errors import GearsymError
from ..model.drivetrain import Drivetrain
from ..model.resolved import ResolvedDrivetrain
from ..model.roles import parameter_roles
from ..reduction.nondimensional import NondimensionalModel, reduce
from ..scales.map import Scaling
from ..model.symbols import parameter_symbol, tau
from ..system import FirstOrderSystem
from ..units import from_si
from .notes import paper_notes
from .records import (
    BodyRecord, ClosingRecord, ConditionRecord, CoordinateRecord, CouplingRecord, Derivation, FunctionRecord, GroupRecord,
    Mechanics, ParameterRecord, ScalingRecord, TorqueRecord,
)

@functools.singledispatch
def derive(model) -> Derivation:
    """The structured derivation of a declared model (``gearsym.load_model(name)``: a Drivetrain or a
    FirstOrderSystem) or of a reduced one (a :class:`NondimensionalModel`, which saves reducing again)."""
    hint = f"; for a name or file use derive(gearsym.load_model({model!r}))" if isinstance(model, (str, Path)) else ""
    raise GearsymError(f"derive takes a Drivetrain, a NondimensionalModel or a FirstOrderSystem, got "
                       f"{type(model).__name__}{hint}")


@derive.register
def _derive_drivetrain(model: Drivetrain) -> Derivation:
    return _derive_reduced(reduce(model))


def _parameters(names, values: Mapping[str, float], descriptions: Mapping[str, str],
                roles: Mapping[str, str] | None = None) -> tuple[ParameterRecord, ...]:
    """Parameters in the system's order with their defaults (None: no default); a description the model
    does not give is its role, if known."""
    roles = roles or {}
    return tuple(
        ParameterRecord(name, float(values[name]) if name in values else None,
                        descriptions.get(name) or roles.get(name, ""))
        for name in names
    )


@derive.register
def _derive_first_order(system: FirstOrderSystem) -> Derivation:
    return Derivation(
        model=system.name, title=system.title or system.name, description="", time=system.time, states=tuple(system.states),
        rhs=tuple(system.rhs), parameters=_parameters(system.parameters, system.parameters, system.descriptions),
        period=system.period, mechanics=None, notes=(),
    )


def _value(expr: sp.Expr, values: dict[str, float]) -> float | None:
    """``expr`` at the parameter values, or None if it does not evaluate to a number."""
    result = expr.xreplace({parameter_symbol(n): sp.Float(v) for n, v in values.items()})
    return float(result) if result.is_number else None


def _components(
    rd: ResolvedDrivetrain, coordinates: Mapping[str, str]
) -> tuple[tuple[BodyRecord, ...], tuple[CouplingRecord, ...], tuple[TorqueRecord, ...]]:
    """The component tables; ``coordinates`` maps a coupling's name to its coordinate's."""
    bodies = tuple(
        BodyRecord(rb.body.name, type(rb.body).__name__, rb.inertia, rb.radius, rb.angle) for rb in rd.bodies
    ) + tuple(BodyRecord(rb.label, f"{type(rb.body).__name__} centre ({rb.motion})", rb.inertia, None, rb.angle)
              for rb in rd.translations)
    couplings = []
    for rc in rd.couplings:
        in_time = sp.Eq(rd.stiffness_at(rc), rd.stiffness_definition(rc)) if rc.kind == "mesh" else None
        couplings.append(CouplingRecord(
            rc.name, rc.kind, (rc.a.body.name, rc.b.body.name), coordinates[rc.name], rc.stiffness, rc.damping,
            rc.backlash, rc.variation, rc.mesh_phase, in_time,
        ))
    torques = []
    for tq in rd.model.torques:
        terms = tuple(f.amplitude * f.time_function for f in rd.forcing if f.torque is tq)
        on = tq.on if isinstance(tq.on, str) else tq.on.name
        torques.append(TorqueRecord(tq.name, on, tq.load, terms))
    return bodies, tuple(couplings), tuple(torques)


@derive.register
def _derive_reduced(nd: NondimensionalModel) -> Derivation:
    red, rd, model = nd.reduction, nd.reduction.resolved, nd.drivetrain
    engine_rhs, names = nd.engine_equations()  # symbolic: no parameter needs a default
    scaling = _scaling(nd)
    scaled = _scaled_values(scaling)
    values = {n: v for n, v in {**nd.declared_defaults, **scaled}.items() if n in names}
    descriptions = {gr.name: gr.description for gr in nd.groups} | dict(model.descriptions)
    groups = tuple(
        GroupRecord(gr.name, gr.definition, gr.kind, gr.description,
                    _value(gr.definition, values) if gr.kind == "derived" else values.get(gr.name))
        for gr in nd.groups
    )
    bodies, couplings, torques = _components(rd, {c.coupling.name: c.name for c in red.deflections})
    kinetic, potential, dissipation = model.form_lagrangian()
    mechanics = Mechanics(
        bodies=bodies, couplings=couplings, torques=torques,
        kinetic_energy=kinetic, potential_energy=potential, dissipation=dissipation,
        generalized_forces=tuple(rd.generalized_forces),
        equations_of_motion=tuple(model.form_eoms()),
        rigid_modes=tuple(red.rigid_modes),
        rigid_body_equations=tuple(red.rigid_body_equations),
        coordinates=tuple(
            CoordinateRecord(c.name, c.velocity_name, c.kind, c.coupling.name, c.definition) for c in red.coordinates
        ),
        transform=red.transform,
        reduced_equations=tuple(red.equations),
        groups=groups,
        conditions=tuple(ConditionRecord(c.equation, c.description) for c in nd.conditions),
        functions=tuple(FunctionRecord(f.name, f.mesh, f.definition, f.expression) for f in nd.functions),
        equations=tuple(nd.equations),
        engine_rhs=engine_rhs,
        closing=tuple(ClosingRecord(c.name, c.coupling.name, c.definition, c.in_states()[0]) for c in red.dependent),
        fixed=tuple(rb.body.name for rb in rd.fixed),
        geometry=tuple(sorted(rd.geometry.items(), key=lambda kv: kv[0].name)),
    )
    return Derivation(
        model=model.name, title=model.title, description=model.description, time=tau,
        states=tuple(nd.states), rhs=tuple(nd.rhs), parameters=_parameters(names, values, descriptions, parameter_roles(rd)),
        period=nd.period, cycles=nd.cycles,
        mechanics=mechanics, notes=paper_notes(nd, groups, values),
        scaling=_scaling_record(scaling) if scaling is not None else None,
    )


def _scaling(nd: NondimensionalModel):
    """The model's :class:`~gearsym.scales.map.Scaling` at its declared physical values, or None."""
    if not nd.drivetrain.physical:
        return None
    return Scaling(nd, nd.drivetrain.physical, nd.drivetrain.length_scale)


def _scaled_values(scaling) -> dict[str, float]:
    """The nondimensional values a scaling gives, or none where its length unit cannot be had (no mean load):
    the equations, the groups and the page do not depend on it."""
    if scaling is None:
        return {}
    try:
        return scaling.values
    except GearsymError:
        return {}


def _scaling_record(s) -> ScalingRecord:
    """What the docs show of a scaling: every number in a fixed unit, so the page is the same everywhere; a
    length unit the values cannot give (no mean load) is said, not fatal: the equations do not depend on it."""
    def value(name: str) -> str:
        role = s.roles.get(name, (None, ""))[0]
        q = s.inputs[name]
        return (f"{from_si(q.si, role.example):.6g} {role.example}" if role is not None and role.example
                else f"{q.si:.6g}")

    condition = next(c for c in s.model.conditions if c.kind == "time_unit").equation
    rule = {"static": "the static deflection of the first mesh under the mean load (the static solution of the "
                      "reduced equations)",
            "backlash": "half the backlash of the first mesh"}.get(s.length_scale) \
        if isinstance(s.length_scale, str) else "a given length"
    units = [("omega_n", f"{s.omega_n_si:.6g} rad/s ({s.omega_n_si / (2 * math.pi):.6g} Hz)"),
             ("T", f"{s.time_si:.6g} s"), ("M", f"{s.mass_si:.6g} kg")]
    try:
        units.append(("L", f"{s.length_si * 1e6:.6g} um"))
        values = tuple(s.values.items())
    except GearsymError as exc:
        units.append(("L", f"none: {str(exc).split(': ', 1)[-1]}"))
        values = ()
    if s.speed and s.speed.parameter in s.inputs:
        units.append(("mesh frequency", f"{s.mesh_frequency().magnitude:.6g} Hz at {value(s.speed.parameter)}"))
    return ScalingRecord(
        inputs=tuple((n, value(n), s.roles[n][0].meaning if n in s.roles else "") for n in s.inputs),
        omega_n_squared=condition.lhs, mass=s.reference_mesh.stiffness, length=rule,
        length_definition=None, units=tuple(units), values=values)
