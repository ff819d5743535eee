"""What each parameter of a drivetrain is physically, read from the component field it fills.

A body's ``inertia`` is a moment of inertia, a mesh's ``stiffness`` a force per length, a torque's
``mean`` a torque, and so on: the role gives the dimension a physical value must have and the unit
an error message suggests. Parameters inside a formula (``inertia="2*I0"``) get no role of their
own; the formula as a whole is checked against the field's role instead.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.resolved import ResolvedDrivetrain
from ..model.expressions import parameter_names, to_expr
from ..model.symbols import omega, phi, t
from ..units import dimension_text, unit_dims


@dataclass(frozen=True)
class Role:
    """What a value is ('a mesh stiffness') and a unit it may be given in ('N/m')."""

    meaning: str
    example: str  # a unit for messages and for showing values

    @property
    def dims(self) -> tuple[float, float, float]:
        """The exponents of mass, length and time a value of this role has."""
        return unit_dims(self.example)

    def describe(self) -> str:
        dims = dimension_text(self.dims)
        return f"{self.meaning} in {self.example} ({dims})" if self.example else f"{self.meaning} (dimensionless)"


INERTIA = Role("a moment of inertia", "kg*m^2")
LENGTH = Role("a base radius", "mm")
MESH_STIFFNESS = Role("a mesh stiffness", "N/m")
MESH_DAMPING = Role("a mesh damping", "N*s/m")
BACKLASH = Role("a backlash", "um")
SHAFT_STIFFNESS = Role("a torsional stiffness", "N*m/rad")
SHAFT_DAMPING = Role("a torsional damping", "N*m*s/rad")
SHAFT_RADIUS = Role("a shaft coordinate radius", "mm")
TORQUE = Role("a torque", "N*m")
PHASE = Role("a phase angle", "")
RATIO = Role("a dimensionless ratio", "")
SPEED = Role("a rotational speed", "rpm")
MASS = Role("a mass", "kg")
BEARING_STIFFNESS = Role("a bearing stiffness", "N/m")
BEARING_DAMPING = Role("a bearing damping", "N*s/m")
ANGLE = Role("an angle", "")
ORBIT = Role("a carrier radius", "mm")
TRANSMISSION_ERROR = Role("a transmission error", "um")


@dataclass(frozen=True)
class Field:
    """One component field: its expression, its role and where it is declared."""

    expression: sp.Expr
    role: Role
    where: str


def fields(rd: ResolvedDrivetrain) -> list[Field]:
    """Every field of the drivetrain that holds a physical value."""
    out = []
    for rb in rd.bodies:
        where = f"{type(rb.body).__name__} {rb.body.name!r}"
        out.append(Field(rb.inertia, INERTIA, f"{where} inertia"))
        if rb.radius is not None:
            out.append(Field(rb.radius, LENGTH, f"{where} base radius"))
    for rb in rd.translations:
        where = f"{type(rb.body).__name__} {rb.body.name!r}"
        out.append(Field(rb.inertia, MASS, f"{where} mass"))
        orbit = getattr(rb.body, "orbit", None)
        if orbit is not None and rb.motion == "tangential":
            out.append(Field(to_expr(orbit, where), ORBIT, f"{where} orbit radius"))
    for rc in rd.couplings:
        where = f"{type(rc.component).__name__} {rc.name!r}"
        if rc.kind == "bearing":
            out += [Field(rc.stiffness, BEARING_STIFFNESS, f"{where} stiffness"),
                    Field(rc.damping, BEARING_DAMPING, f"{where} damping")]
            continue
        if rc.kind == "mesh" and rd.translations:
            out += [Field(to_expr(rc.component.pressure_angle, where), ANGLE, f"{where} pressure angle")]
            if rc.component.centres is not None:
                out += [Field(to_expr(rc.component.centres, where), ANGLE, f"{where} line of centres")]
        if rc.kind == "mesh":
            out += [Field(rc.stiffness, MESH_STIFFNESS, f"{where} stiffness"),
                    Field(rc.damping, MESH_DAMPING, f"{where} damping"),
                    Field(rc.backlash, BACKLASH, f"{where} backlash"),
                    Field(rc.mesh_phase.xreplace({omega: 0, t: 0}), PHASE, f"{where} phase")]
            out += [Field(sp.Symbol(name, real=True), RATIO, f"{where} stiffness variation")
                    for name in sorted(parameter_names(rc.variation) - {phi.name})]
            # shaft-order terms (a tooth fault's depth, its tooth; an eccentricity's amplitudes and phase): the
            # fraction of stiffness lost is dimensionless, a transmission error a length where it enters linearly
            out += [Field(sp.Symbol(name, real=True), RATIO, f"{where} shaft-order term (stiffness lost)")
                    for name in sorted(parameter_names(rc.loss) - {phi.name})]
            for name in sorted(parameter_names(rc.error) - {phi.name}):
                s = sp.Symbol(name, real=True)
                linear = s not in sp.diff(rc.error.xreplace({x: sp.Symbol(x.name, real=True)
                                                             for x in rc.error.free_symbols}), s).free_symbols
                out.append(Field(s, TRANSMISSION_ERROR if linear else PHASE, f"{where} shaft-order term"))
        else:
            out += [Field(rc.stiffness, SHAFT_STIFFNESS, f"{where} stiffness"),
                    Field(rc.damping, SHAFT_DAMPING, f"{where} damping"),
                    Field(rc.scale, SHAFT_RADIUS, f"{where} coordinate radius")]
    for f in rd.forcing:
        where = f"Torque {f.torque.name!r}"
        out.append(Field(f.amplitude, TORQUE, f"{where} {'mean' if f.order == 0 else 'harmonic amplitude'}"))
        if f.order:
            out.append(Field(f.phase, PHASE, f"{where} harmonic phase"))
    return out


def parameter_roles(rd: ResolvedDrivetrain) -> dict[str, tuple[Role, str]]:
    """name -> (role, where) for each parameter that fills a field on its own (a plain name, or minus one)."""
    out: dict[str, tuple[Role, str]] = {}
    for field in fields(rd):
        expr = -field.expression if field.expression.could_extract_minus_sign() else field.expression
        if isinstance(expr, sp.Symbol):
            out.setdefault(expr.name, (field.role, field.where))
    return out


def physical_parameters(rd: ResolvedDrivetrain) -> list[str]:
    """Every parameter name the drivetrain's fields use, in declaration order."""
    seen: dict[str, None] = {}
    for field in fields(rd):
        for s in sorted(field.expression.free_symbols, key=lambda s: s.name):
            if s.name not in ("t", "tau", "phi", "omega"):
                seen.setdefault(s.name)
    return list(seen)
