"""The types of the data loop's effects: where one acts (:class:`Site`), what it changes there (:class:`Change`),
and the effect itself (:class:`Effect`), with :func:`site`, which finds the site in a system.

The library (:mod:`.effects`) and the shaft-order effects (:mod:`.shaft_effects`) are made of them.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import sympy as sp

from ..model.backlash import g
from ..errors import ModelError
from ..model.symbols import parameter_symbol
from ..parameters import Constraint
from ..system import Coupling, FirstOrderSystem


@dataclass(frozen=True)
class Site:
    """Where an effect acts: a coupling (its coordinate x, rate v and the rows its law enters with their
    factors), or the driving torque (the rows where the mean torque enters, with df/dB0)."""

    system: FirstOrderSystem
    kind: str  # "mesh" | "shaft" | "torque"
    coupling: Coupling | None
    rows: tuple[tuple[int, sp.Expr], ...]
    omega: sp.Expr

    @property
    def time(self) -> sp.Symbol:
        return self.system.time

    @property
    def x(self) -> sp.Symbol:
        return self.system.states[self.system.state_names.index(self.coupling.coordinate)]

    @property
    def v(self) -> sp.Symbol:
        return self.system.states[self.system.state_names.index(self.coupling.velocity)]

    @property
    def own_row(self) -> int:
        return self.system.state_names.index(self.coupling.velocity)

    @property
    def backlash(self) -> sp.Expr:
        """g(contact, eta) of a mesh (the contact itself for a mesh without backlash)."""
        return g(self.coupling.contact, self.coupling.backlash)

    @property
    def stiffness(self) -> sp.Expr:
        return self.coupling.stiffness

    @property
    def phase(self) -> sp.Expr:
        """The mesh phase phi: the mesh order (mesh over forcing frequency) times tau."""
        return (self.coupling.order or sp.S.One) * self.time

    @staticmethod
    def parameter(name: str) -> sp.Symbol:
        return parameter_symbol(name)


@dataclass(frozen=True)
class Change:
    """What an effect does at its site: a term added to the coupling's law (-factor * law in each of its
    rows), a new contact (the argument of g), a term added to the driving torque (df/dB0 * torque in each
    row), or a term added to dv/dtau of the coupling's own velocity only."""

    law: sp.Expr = sp.S.Zero
    contact: sp.Expr | None = None
    torque: sp.Expr = sp.S.Zero
    own: sp.Expr = sp.S.Zero


@dataclass(frozen=True)
class Effect:
    """One candidate effect: its parameters (0 = off; ``fixed`` ones it needs but does not fit), where it acts,
    its change there, the physical bounds of its parameters (name -> (low, high, why)) and its (cos, sin)
    pairs, reported as amplitude and phase."""

    name: str
    description: str
    fitted: tuple[str, ...]
    fixed: Mapping[str, float]
    build: Callable[[Site], Change]
    acts_on: str = "mesh"
    bounds: Mapping[str, tuple[float, float, str]] = field(default_factory=dict)
    pairs: tuple[tuple[str, str], ...] = ()
    order: int = 0  # a harmonic's order (0: none)
    term: sp.Expr | None = None  # a term added by hand or proposed: the expression its coefficient multiplies
    coordinate: str | None = None  # the mesh it acts in (None: the first with backlash)
    gear: str = ""  # a shaft-order effect's gear (:mod:`.shaft_effects`) and its tooth count
    teeth: int = 0
    scan: str = ""  # a fixed parameter found by a scan over the gear's teeth (the faulty tooth)
    gears: tuple[tuple[str, int], ...] = ()  # a tooth-by-tooth form's gears and tooth counts (both gears of a mesh)
    prior: float = 0.0  # a tooth-by-tooth form's prior spread of each parameter (regularised: 0 for none) ...
    prior_unit: str = ""  # ... in the parameter's units ("") or times the mesh coordinate's spread ("displacement")
    constraints: Mapping[str, Constraint] = field(default_factory=dict)  # what its parameters may be, physically

    @property
    def parameters(self) -> dict[str, float]:
        return {**{p: 0.0 for p in self.fitted}, **self.fixed}

    @property
    def shaft_order(self) -> bool:
        """An effect that repeats once per revolution of its gear (a tooth fault, an eccentricity) or of each of its
        gears (a tooth-by-tooth form)."""
        return bool(self.teeth or self.gears)

    @property
    def revolutions(self) -> tuple[tuple[str, int], ...]:
        """(gear, teeth) of every gear whose revolution the effect repeats on."""
        return self.gears or (((self.gear, self.teeth),) if self.teeth else ())

    @property
    def family(self) -> str:
        """The name without its order (mesh_stiffness_harmonic for mesh_stiffness_harmonic_3)."""
        return self.name[: -len(f"_{self.order}")] if self.order else self.name


def site(system: FirstOrderSystem, acts_on: str, coordinate: str | None = None) -> Site:
    """Where an effect acting on ``acts_on`` goes in ``system``: a mesh (``coordinate``, default the first with
    backlash), a shaft, or the driving torque."""
    omega = parameter_symbol("omega")
    if acts_on == "torque":
        _tau_form(system)
        return _torque_site(system, omega)
    # a mesh that closes a kinematic loop has no coordinate (no row) of its own to add an effect to
    couplings = [c for c in system.couplings if c.kind == acts_on and not c.closes_loop]
    if acts_on == "mesh":  # the backlash meshes first
        couplings.sort(key=lambda c: c.backlash == 0)
    chosen = [c for c in couplings if coordinate in (None, c.coordinate)]
    if not chosen:
        where = f"coordinate {coordinate!r}" if coordinate else "any coordinate"
        known = f" ({acts_on}es act on {', '.join(c.coordinate for c in couplings)})" if couplings else ""
        force = "mesh force g(x, eta)" if acts_on == "mesh" else f"{acts_on} force"
        raise ModelError(f"no {force} acting on {where}{known}; these effects act on the {acts_on} of a reduced "
                         "drivetrain", system.name)
    _tau_form(system)
    c = chosen[0]
    rows = c.rows or ((system.state_names.index(c.velocity), sp.S.One),)
    return Site(system, acts_on, c, tuple(rows), omega)


def _tau_form(system: FirstOrderSystem) -> None:
    if "omega" not in system.parameters:
        raise ModelError("the effects library needs the paper's tau-form (a parameter omega)", system.name)


def _torque_site(system: FirstOrderSystem, omega: sp.Expr) -> Site:
    if "B0" not in system.parameters:
        raise ModelError("a torque harmonic enters where the mean torque B0 does; the model has no B0", system.name)
    B0 = parameter_symbol("B0")
    rows = tuple((i, sp.diff(f, B0)) for i, f in enumerate(system.rhs) if f.has(B0))
    mesh = next((c for c in system.couplings if c.kind == "mesh"), None)
    return Site(system, "torque", mesh, rows, omega)
