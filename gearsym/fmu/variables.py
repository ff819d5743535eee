"""The FMU's variables: names as in the model, value references, causality, units; one list that the model
description (:mod:`.description`) and the C wrapper's tables (:mod:`.wrapper`) are both written from.

In the order of ``ModelVariables``: the independent variable (the model's time, or ``time`` in s), the states
(outputs too, so that a co-simulation can connect them) and their derivatives, the parameters, ``substeps`` (RK4
steps per co-simulation communication step), then the computed outputs: per mesh its deflection
(``<mesh>.deflection``) and force (``<mesh>.force``), per shaft its twist (``<shaft>.twist``), the forcing phase
``tau`` of a physical model, and per mesh with backlash its contact state (``<mesh>.contact``: 1 on the drive
flank, x >= 0; 0 in the gap; -1 on the back flank, x <= -eta).
Real and Integer variables have value references of their own, each counted from 0.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import sympy as sp

from ..model.symbols import parameter_symbol
from ..system import Coupling, FirstOrderSystem
from .frame import Frame, PhysicalParameter, Term, Unit


@dataclass(frozen=True)
class Variable:
    """One ScalarVariable of the model description."""

    name: str
    type: str  # "Real" | "Integer"
    reference: int
    causality: str
    variability: str
    initial: str | None
    start: float | int | None
    description: str
    role: str  # time, state, derivative, parameter, substeps, deflection, force, twist, tau, contact
    unit: Unit | None = None
    display: str | None = None
    derivative: int | None = None  # the state's index (1-based) in ModelVariables
    minimum: float | None = None


#: the value of ``substeps`` before a user sets it: the fewest RK4 steps per communication step (more are taken
#: wherever the communication step is longer than the engine's step: the importer's step never sets the accuracy)
SUBSTEPS = 1


@dataclass(frozen=True)
class Layout:
    """Every variable of one FMU and what the wrapper needs to compute them."""

    system: FirstOrderSystem
    frame: Frame
    parameters: tuple[PhysicalParameter, ...]  # the FMU's Real parameters, in value-reference order
    engine_base: dict[str, float]
    meshes: tuple[Coupling, ...]
    shafts: tuple[Coupling, ...]
    indicators: tuple[sp.Expr, ...]  # two per mesh with backlash (its x and -(x + eta)) first, then any others
    variables: tuple[Variable, ...] = field(default=())

    @cached_property
    def contacts(self) -> tuple[Coupling, ...]:
        """The meshes with backlash: each has a contact state and the first pairs of event indicators."""
        return tuple(c for c in self.meshes if c.backlash != 0)

    def index(self, name: str) -> int:
        """A variable's index (1-based) in ModelVariables."""
        return next(i for i, v in enumerate(self.variables, 1) if v.name == name)

    def of_role(self, *roles: str) -> list[Variable]:
        return [v for v in self.variables if v.role in roles]

    @property
    def outputs(self) -> list[Variable]:
        return [v for v in self.variables if v.causality == "output"]


def layout(system: FirstOrderSystem, frame: Frame, indicators: tuple[sp.Expr, ...]) -> Layout:
    """The variables of the FMU of ``system`` in ``frame``, with its event ``indicators``."""
    meshes = tuple(c for c in system.couplings if c.kind == "mesh")
    shafts = tuple(c for c in system.couplings if c.kind == "shaft")
    if frame.physical:
        parameters, base = frame.parameters, dict(frame.engine_base)
    else:  # the engine's parameters themselves: engine = 1.0 x (value / 1.0), exact
        parameters = tuple(PhysicalParameter(name, float(value), None, None, _parameter_text(system, name),
                                             (Term(name, 1, 1.0),)) for name, value in system.parameters.items())
        base = {name: 1.0 for name in system.parameters}
    out = Layout(system, frame, parameters, base, meshes, shafts, indicators)
    object.__setattr__(out, "variables", tuple(_variables(out)))
    return out


def _variables(lay: Layout):
    system, frame = lay.system, lay.frame
    real, integer = _counter(), _counter()
    units = frame.units
    if frame.physical:
        yield Variable(frame.time_name, "Real", real(), "independent", "continuous", None, None,
                       f"time (the engine's forcing phase {system.time.name} = {frame.omega} {frame.time_name} / T, "
                       f"its time unit T = {frame.time_unit!r} s)", "time", units.get("time"))
    else:
        yield Variable(system.time.name, "Real", real(), "independent", "continuous", None, None,
                       f"the model's time {system.time.name} (one forcing period is {system.period})", "time")
    first_state = 2
    for name, value in zip(system.state_names, system.initial_vector):
        kind = frame.kinds.get(name)
        yield Variable(name, "Real", real(), "output", "continuous", "exact", _start(lay, name, kind, value),
                       _state_text(system, name, frame), "state", units.get(kind), frame.displays.get(kind))
    for i, name in enumerate(system.state_names):
        kind = frame.kinds.get(name)
        derivative_kind = {"length": "rate", "rate": "acceleration", "angle": "angular_rate",
                           "angular_rate": "angular_acceleration"}.get(kind)
        yield Variable(f"der({name})", "Real", real(), "local", "continuous", "calculated", None,
                       f"time derivative of {name}", "derivative", units.get(derivative_kind),
                       frame.displays.get(derivative_kind), derivative=first_state + i)
    for p in lay.parameters:
        constraint = system.constraints.get(p.name) if not frame.physical else None
        yield Variable(p.name, "Real", real(), "parameter", "tunable" if p.tunable else "fixed", "exact", p.value,
                       p.description if p.tunable else (p.description + "; " if p.description else "")
                       + "baked into the engine's values: export the FMU again with --set to change it",
                       "parameter", p.unit, p.display, minimum=0.0 if constraint else None)
    yield Variable("substeps", "Integer", integer(), "parameter", "tunable", "exact", SUBSTEPS,
                   "the fewest RK4 steps per co-simulation communication step: more are taken wherever needed to keep "
                   "each within the engine's own step (crossings of the backlash located in each)",
                   "substeps", minimum=1)
    for c in lay.meshes:
        yield Variable(f"{c.name}.deflection", "Real", real(), "output", "continuous", "calculated", None,
                       f"deflection of mesh {c.name!r} along its line of action ({c.contact})", "deflection",
                       units.get("length"), frame.displays.get("length"))
        yield Variable(f"{c.name}.force", "Real", real(), "output", "continuous", "calculated", None,
                       _force_text(lay, c), "force", units.get("force"), frame.displays.get("force"))
    for c in lay.shafts:
        yield Variable(f"{c.name}.twist", "Real", real(), "output", "continuous", "calculated", None,
                       f"twist of shaft {c.name!r} (its coordinate {c.contact} over its radius)" if frame.physical
                       else f"twist of shaft {c.name!r} ({c.contact})", "twist",
                       units.get("angle" if frame.physical else "length"),
                       None if frame.physical else frame.displays.get("length"))
    if frame.physical:
        yield Variable(system.time.name, "Real", real(), "output", "continuous", "calculated", None,
                       f"the forcing phase {system.time.name} of the engine (one forcing period is {system.period})",
                       "tau", units.get("angle"))
    for c in lay.contacts:
        yield Variable(f"{c.name}.contact", "Integer", integer(), "output", "discrete", "calculated", None,
                       f"contact state of mesh {c.name!r}: 1 drive flank ({c.contact} >= 0), 0 in the gap, "
                       f"-1 back flank ({c.contact} <= -{c.backlash})", "contact")


def _counter():
    count = iter(range(1 << 30))
    return lambda: next(count)


def _start(lay: Layout, name: str, kind: str | None, value: float) -> float:
    """A state's start value in the FMU's units."""
    frame = lay.frame
    scale = frame.scales.get(name, 1.0)
    if kind in ("length", "angle"):
        return value * frame.length_unit * scale
    if kind in ("rate", "angular_rate"):
        return value * frame.length_unit * scale * frame.engine_base[frame.omega] / frame.time_unit
    return value


def _parameter_text(system: FirstOrderSystem, name: str) -> str:
    return system.descriptions.get(name) or undescribed(system, name)


def undescribed(system: FirstOrderSystem, name: str) -> str:
    """The description of a parameter that neither the model nor its drivetrain's roles describe (a parameter of a
    stiffness formula given with --set, of an added effect): where it enters."""
    rows = [s.name for s, f in zip(system.states, system.rhs) if parameter_symbol(name) in f.free_symbols]
    where = f"the equations of {', '.join(rows)}" if rows else "the model's tables of time"
    return f"parameter {name} of {system.name}, in {where} (the model gives it no description)"


def _state_text(system: FirstOrderSystem, name: str, frame: Frame) -> str:
    time = frame.time_name if frame.physical else system.time.name
    for c in system.couplings:
        if c.coordinate == name:
            return f"relative coordinate of {c.kind} {c.name!r}"
        if c.velocity == name:
            return f"rate of the relative coordinate of {c.kind} {c.name!r} (d{c.coordinate}/d{time})"
    return f"state {name}"


def _force_text(lay: Layout, c: Coupling) -> str:
    if not lay.frame.physical:
        return (f"elastic force of mesh {c.name!r}: k(tau) g({c.contact}, {c.backlash}) in the model's units, "
                f"k(tau) = {c.stiffness if len(str(c.stiffness)) < 60 else 'its stiffness'} (the damping force is not "
                "included: the reduced model does not say which damping group is the mesh's)")
    damping = lay.frame.mesh_damping.get(c.name)
    return (f"dynamic force of mesh {c.name!r}: its stiffness k(tau) g(x, eta)"
            + (f" + {damping} dx/dt" if damping else " (its damping is not a physical value: not included)"))
