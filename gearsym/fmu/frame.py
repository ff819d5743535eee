"""How an FMU's variables stand to the engine's: plain numbers, no units library.

An FMU of a nondimensional model shows the engine as it is: its time, states and parameters. An FMU of a
model with physical values shows SI (time in s, coordinates in m, rates in m/s, forces in N); its
:class:`Frame` says how: the time unit T and length unit L of the scaling, which engine parameter is omega
(the forcing phase runs at d tau/dt = omega / T), the kind of each state, and the physical parameters with
how each one that may change at run time enters the engine's parameters. It is made at the edge, from the
model's :class:`~gearsym.physical.Scaling` (:mod:`.physical`); nothing here knows about units.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

#: the SI base units an FMI unit is made of (FMI 2.0 BaseUnit attributes)
BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


@dataclass(frozen=True)
class Unit:
    """An FMI unit: its name, its exponents of the SI base units, and display units (name, factor: a value
    shown in the display unit is factor x the value in this unit)."""

    name: str
    base: tuple[tuple[str, int], ...]
    displays: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class Term:
    """A physical parameter's part in an engine parameter: engine = base x (value / reference) ** exponent
    (times the other terms of the same engine parameter)."""

    engine: str
    exponent: int
    reference: float  # SI


@dataclass(frozen=True)
class PhysicalParameter:
    """A physical value as the FMU shows it (in SI) and how it reaches the engine: ``terms`` for one the
    FMU may change at run time, none for one baked into the engine's values (fixed)."""

    name: str
    value: float  # SI
    unit: Unit | None
    display: str | None  # the unit it was given in (a display unit of ``unit``)
    description: str
    terms: tuple[Term, ...] = ()

    @property
    def tunable(self) -> bool:
        return bool(self.terms)


@dataclass(frozen=True)
class Frame:
    """The FMU's variables in the engine's terms (see the module's docstring). ``Frame()``: nondimensional."""

    physical: bool = False
    time_unit: float = 1.0  # s per unit of the engine's time t (1/omega_n)
    length_unit: float = 1.0  # m per unit of length
    omega: str | None = None  # the engine parameter omega (tau = omega t: d tau/d seconds = omega / time_unit)
    parameters: tuple[PhysicalParameter, ...] = ()
    engine_base: Mapping[str, float] = field(default_factory=dict)  # engine values at the terms' references
    kinds: Mapping[str, str] = field(default_factory=dict)  # state -> "length" | "rate" | "angle" | "angular_rate"
    #: per mesh: N/m of one unit of its stiffness in the engine (its own mean stiffness over its relative mean
    #: there, K2 for a second mesh: each mesh's force from its own stiffness); a mesh not named: 1
    mesh_stiffness: Mapping[str, float] = field(default_factory=dict)
    mesh_damping: Mapping[str, str] = field(default_factory=dict)  # mesh -> the physical parameter of its damping
    time_name: str = "time"
    units: Mapping[str, Unit] = field(default_factory=dict)  # "time", "length", "rate", "force" -> their SI unit
    displays: Mapping[str, str] = field(default_factory=dict)  # the same -> the display unit shown by default
    #: per state: its SI value per unit of the length unit (1 for a mesh's deflection and rate, 1/radius for a
    #: shaft's coordinate, which is its radius times its twist: the twist in rad); a state not named: 1
    scales: Mapping[str, float] = field(default_factory=dict)
