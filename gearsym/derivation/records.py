"""The structured derivation of a model: plain records, no printing.

Collecting (:mod:`gearsym.derivation.collect`) and rendering (text, LaTeX,
JSON, Markdown) are separate so that every format shows the same facts in the
same order, and so that a new format is a new renderer, not a new derivation.
Every record holds SymPy objects; renderers decide how to print them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import sympy as sp

from ..model.symbols import parameter_symbol, tau


@dataclass(frozen=True)
class BodyRecord:
    """A rotating body: the paper's I_i (and r_i for a gear), with its angle psi_i(t)."""

    name: str
    kind: str  # "Gear" | "Disk"
    inertia: sp.Expr
    radius: Optional[sp.Expr]
    angle: sp.Expr


@dataclass(frozen=True)
class CouplingRecord:
    """A mesh or a shaft as the reduction sees it."""

    name: str
    kind: str  # "mesh" | "shaft"
    ends: tuple[str, str]
    coordinate: str
    stiffness: sp.Expr  # mean mesh stiffness kZ or shaft stiffness kS
    damping: sp.Expr
    backlash: sp.Expr  # 0 for a shaft
    variation: sp.Expr  # k(phi), 1 for a shaft
    mesh_phase: sp.Expr  # phi(t), 0 for a shaft
    stiffness_in_time: Optional[sp.Eq]  # kZ(t) = kZ * k(phi(t)) for a mesh


@dataclass(frozen=True)
class TorqueRecord:
    """An external torque with the terms it contributes to its body's generalized force."""

    name: str
    on: str
    load: bool  # a resisting torque enters with a minus sign
    terms: tuple[sp.Expr, ...]

    @property
    def total(self) -> sp.Expr:
        return sp.Add(*self.terms)


@dataclass(frozen=True)
class CoordinateRecord:
    """A relative coordinate, its velocity state and its definition in the angles."""

    name: str
    velocity: str
    kind: str
    coupling: str
    definition: sp.Expr


@dataclass(frozen=True)
class ClosingRecord:
    """The deflection of a coupling that closes a kinematic loop: its definition in the angles and the
    combination of the relative coordinates it equals."""

    name: str
    coupling: str
    definition: sp.Expr
    combination: sp.Expr


@dataclass(frozen=True)
class GroupRecord:
    """A coefficient group; ``value`` is a derived group's value at the declared defaults."""

    name: str
    definition: sp.Expr
    kind: str  # "free" | "derived"
    description: str
    value: Optional[float]

    @property
    def symbol(self) -> sp.Symbol:
        return parameter_symbol(self.name)


@dataclass(frozen=True)
class ConditionRecord:
    equation: sp.Eq
    description: str


@dataclass(frozen=True)
class FunctionRecord:
    """A nondimensional mesh stiffness: its definition in the declared parameters and its formula in tau."""

    name: str
    mesh: str
    definition: sp.Expr
    expression: sp.Expr

    @property
    def applied(self) -> sp.Expr:
        return sp.Function(self.name, real=True)(tau)


@dataclass(frozen=True)
class ParameterRecord:
    name: str
    default: Optional[float]  # None: the model declares no default (the equations need none)
    description: str


@dataclass(frozen=True)
class Mechanics:
    """Everything between the declaration and the nondimensional form (drivetrains only)."""

    bodies: tuple[BodyRecord, ...]
    couplings: tuple[CouplingRecord, ...]
    torques: tuple[TorqueRecord, ...]
    kinetic_energy: sp.Expr
    potential_energy: sp.Expr
    dissipation: sp.Expr
    generalized_forces: tuple[sp.Expr, ...]
    equations_of_motion: tuple[sp.Eq, ...]
    rigid_modes: tuple[sp.Matrix, ...]
    rigid_body_equations: tuple[sp.Eq, ...]
    coordinates: tuple[CoordinateRecord, ...]
    transform: sp.Matrix
    reduced_equations: tuple[sp.Eq, ...]
    groups: tuple[GroupRecord, ...]
    conditions: tuple[ConditionRecord, ...]
    functions: tuple[FunctionRecord, ...]
    equations: tuple[sp.Eq, ...]  # nondimensional, second order in tau
    engine_rhs: tuple[sp.Expr, ...]  # the right-hand side as the engine receives it
    closing: tuple["ClosingRecord", ...] = ()  # deflections of couplings that close a kinematic loop
    fixed: tuple[str, ...] = ()  # bodies declared fixed (held): no angle
    geometry: tuple = ()  # (symbol, what it stands for): the numbers of the lines of action of gears on bearings

    @property
    def angles(self) -> tuple[sp.Expr, ...]:
        return tuple(b.angle for b in self.bodies)


@dataclass(frozen=True)
class ScalingRecord:
    """A model's physical values and the units that scale them to the nondimensional model."""

    inputs: tuple[tuple[str, str, str], ...]  # (parameter, value with its unit, what it is)
    omega_n_squared: sp.Expr  # the left side of the time-unit condition
    mass: sp.Expr  # the first mesh's stiffness: the mass unit is it over omega_n^2
    length: str  # how the length unit is chosen
    length_definition: Optional[sp.Expr]  # the group whose deflection it is (B0), for the static scale
    units: tuple[tuple[str, str], ...]  # (unit, its value)
    values: tuple[tuple[str, float], ...]  # the nondimensional values the scaling gives


@dataclass(frozen=True)
class Derivation:
    """A model's derivation: the first-order system always, the mechanics for a drivetrain.

    ``rhs`` keeps the coefficient groups and stiffness functions as symbols (the
    readable form); ``mechanics.engine_rhs`` has them substituted.
    """

    model: str
    title: str
    description: str
    time: sp.Symbol
    states: tuple[sp.Symbol, ...]
    rhs: tuple[sp.Expr, ...]
    parameters: tuple[ParameterRecord, ...]
    period: sp.Expr
    mechanics: Optional[Mechanics]
    notes: tuple[str, ...]
    scaling: Optional[ScalingRecord] = None  # a drivetrain with physical values
    cycles: int = 1  # forcing periods (mesh periods of the first mesh) in one period

    @property
    def forcing_period(self) -> sp.Expr:
        return self.period / self.cycles

    @property
    def is_drivetrain(self) -> bool:
        return self.mechanics is not None

    @property
    def bare_functions(self) -> frozenset[str]:
        """Names of the generalized coordinates, printed without their argument."""
        names = {s.name for s in self.states}
        if self.mechanics is not None:
            names |= {b.angle.func.__name__ for b in self.mechanics.bodies}
            names |= {c.name for c in self.mechanics.coordinates}
        return frozenset(names)

    @property
    def equations(self) -> tuple[sp.Eq, ...]:
        """The model's equations: nondimensional (drivetrain) or first-order (ODE) ones."""
        if self.mechanics is not None:
            return self.mechanics.equations
        return self.first_order_equations

    @property
    def first_order_equations(self) -> tuple[sp.Eq, ...]:
        """d(state)/d(time) = rhs, with the states written as functions of time."""
        as_functions = {s: sp.Function(s.name, real=True)(self.time) for s in self.states}
        return tuple(
            sp.Eq(sp.Derivative(as_functions[s], self.time), f.xreplace(as_functions))
            for s, f in zip(self.states, self.rhs)
        )
