"""A drivetrain declared from components; its Lagrangian and equations of motion.

Like ``sympy.physics.mechanics.System``: declare bodies, couplings and torques,
then call :meth:`Drivetrain.form_eoms`. Declarations are checked when the
drivetrain is resolved (at the first derivation, :mod:`.resolved`), so a model file can add
components in any order; every error names the component to fix.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from functools import cached_property

import sympy as sp

from .declared import Model
from ..errors import ModelError
from ..units import Measure, measure
from .components import Bearing, Body, Coupling, Mesh, Shaft, Torque
from .expressions import ExprLike
from .faults import ShaftOrderTerm
from .length_scale import check_length_scale
from .resolved import ResolvedDrivetrain


class Drivetrain(Model):
    """A torsional drivetrain: bodies, meshes, shafts and external torques."""

    @property
    def is_drivetrain(self) -> bool:
        return True

    def __init__(self, name: str, title: str = "", description: str = ""):
        if not name.isidentifier():
            raise ModelError("a model name must be a Python identifier, e.g. 'flexible_shaft'", repr(name))
        self.name = name
        self.title = title or name
        self.description = description
        self.bodies: list[Body] = []
        self.couplings: list[Coupling] = []
        self.torques: list[Torque] = []
        self.shaft_terms: list[ShaftOrderTerm] = []  # eccentricity, tooth faults, ... (:mod:`.faults`)
        self.bearings: list[Bearing] = []  # bodies whose centres translate (:class:`Bearing`)
        self.joints: list = []  # meshes, shafts and bearings in the order declared (their coordinates' order)
        self._frame_terms = True  # the rotating frame's Coriolis and centripetal terms (planets that translate)
        self._defaults: dict[str, ExprLike] = {}
        self._descriptions: dict[str, str] = {}
        self._initial: dict[str, float | Measure] = {}
        self._physical: dict[str, Measure] = {}  # name -> value in SI, read (and checked) when set
        self._from_geometry: dict[str, tuple[str, Measure]] = {}  # name -> (the component, its value)
        self._length_scale: str | Measure = "static"
        self.version = 0  # bumped by every change, so derived results can be cached safely

    def _changed(self) -> None:
        self.version += 1
        self.__dict__.pop("resolved", None)

    # ----------------------------------------------------------------- declaring
    def add(self, component):
        """Add a component; returns it, so ``g1 = model.add(Gear(...))`` reads naturally."""
        self._changed()
        names = {c.name for c in (*self.bodies, *self.couplings, *self.torques, *self.shaft_terms, *self.bearings)}
        if not getattr(component, "name", None) or not isinstance(component.name, str):
            raise ModelError("every component needs a name (a non-empty string)", repr(component))
        if component.name in names:
            raise ModelError("a component with this name was already added; names must be unique", component.name)
        self._add_physical_values(component)
        if isinstance(component, Body):
            self.bodies.append(component)
        elif isinstance(component, (Mesh, Shaft)):
            self.couplings.append(component)
            self.joints.append(component)
        elif isinstance(component, Torque):
            self.torques.append(component)
        elif isinstance(component, ShaftOrderTerm):
            self.shaft_terms.append(component)
        elif isinstance(component, Bearing):
            self.bearings.append(component)
            self.joints.append(component)
        else:
            raise ModelError(
                f"cannot add a {type(component).__name__}; add Gear, Disk, Mesh, Shaft, Bearing, Torque or a shaft-order term "
                "(ToothFault, Spall, Eccentricity, SpacingErrors)",
                getattr(component, "name", None),
            )
        return component

    def _add_physical_values(self, component) -> None:
        """The physical values a component declared from its geometry gives (a gear's inertia and base radius, a
        mesh's mean stiffness); a value set later with :meth:`set_physical` replaces them."""
        values = getattr(component, "physical_values", dict)()
        for name, value in values.items():
            given = self._from_geometry.get(name)
            if given is not None and given[1].si != value.si:
                raise ModelError(f"gives {name} = {value}, but {given[0]!r} gave it {given[1]}: name the parameters "
                                 f"of the two apart (e.g. inertia='I1' and inertia='I2')", component.name)
            self._from_geometry[name] = (component.name, value)
            self._physical[name] = value

    def set_defaults(self, **values: ExprLike) -> "Drivetrain":
        """Default values of the model's parameters (checked against the reduced model's parameters)."""
        self._changed()
        self._defaults.update(values)
        return self

    def set_physical(self, **values) -> "Drivetrain":
        """Physical values of the component parameters, with their units: ``I1="2.1e-3 kg*m^2"``,
        ``kZ="2e8 N/m"``, ``speed="3000 rpm"`` (strings read by the safe quantity parser, or pint Quantities;
        a plain number is dimensionless: for a value that has a unit it is refused when the model is scaled). They are turned into SI numbers here (:func:`gearsym.units.measure`);
        the engine's nondimensional values are derived from them (:class:`gearsym.scales.Scaling`), and its
        results carried back to the units given."""
        self._changed()
        for name, value in values.items():
            self._physical[name] = measure(value, f"{self.name}: set_physical {name}")
        return self

    def set_frame_terms(self, included: bool) -> "Drivetrain":
        """Whether the equations of bodies that translate in a turning carrier's frame (the planets and, with them,
        the central members, as Lin & Parker write them) keep the frame's Coriolis and centripetal terms,
        ``2 m Omega_c (-y', x')`` and ``-m Omega_c^2 (x, y)``, with the carrier's speed Omega_c from the
        forcing frequency and the tooth counts (default True). ``False`` is Lin & Parker's stationary model."""
        if not isinstance(included, bool):
            raise ModelError(f"set_frame_terms takes True or False, got {included!r}", self.name)
        self._changed()
        self._frame_terms = included
        return self

    @property
    def frame_terms(self) -> bool:
        return self._frame_terms

    def set_length_scale(self, scale) -> "Drivetrain":
        """The length unit of the nondimensional model: ``"static"`` (the static deflection of the first mesh
        under the mean load: B0 = 1, the paper's convention), ``"backlash"`` (half the first mesh's backlash)
        or a length (``"1 um"``). It is the unit the engine computes in and the unit of an initial state given
        as plain numbers; the physical answers do not depend on it."""
        self._changed()
        self._length_scale = check_length_scale(scale, f"{self.name}: set_length_scale")
        return self

    @property
    def physical(self) -> dict[str, Measure]:
        """The declared physical values (name -> :class:`~gearsym.units.Measure`, in SI)."""
        return dict(self._physical)

    @property
    def length_scale(self):
        return self._length_scale

    def set_initial_state(self, **values) -> "Drivetrain":
        """Default initial state of the reduced model (e.g. the paper's x=-2, v=-0.5); others start at 0.

        Numbers are in the model's units (for a model with physical values: lengths in the length unit of
        :meth:`set_length_scale`, rates in that unit per unit tau); a model with physical values may give
        quantities instead (``x="13.5 um"``, ``v="0 m/s"``), the same start whatever unit the engine uses."""
        self._changed()
        for name, value in values.items():
            where = f"{self.name}: set_initial_state {name}"
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                number = float(value)
                if number != number or number in (float("inf"), float("-inf")):
                    raise ModelError(f"the initial state must be finite, got {value!r}", where)
                self._initial[name] = number
            else:
                self._initial[name] = measure(value, where)
        return self

    @property
    def initial_state(self) -> dict[str, float | Measure]:
        """The declared initial state: numbers in the model's units, or physical values."""
        return dict(self._initial)

    def describe(self, **descriptions: str) -> "Drivetrain":
        """One-line descriptions of parameters, shown in the derivation docs."""
        self._changed()
        self._descriptions.update(descriptions)
        return self

    @property
    def defaults(self) -> dict[str, ExprLike]:
        return dict(self._defaults)

    @property
    def descriptions(self) -> dict[str, str]:
        return dict(self._descriptions)

    def with_bodies(self, bodies: Mapping[str, Body]) -> "Drivetrain":
        """A new drivetrain with the same components and values, the bodies named in ``bodies`` replaced by those
        given (every component that refers to one refers to its replacement)."""
        out = Drivetrain(self.name, self.title, self.description)
        new = {body.name: bodies.get(body.name, body) for body in self.bodies}
        swapped = {id(old): new[old.name] for old in self.bodies}

        def rewired(component):
            changes = {f.name: swapped[id(v)] for f in dataclasses.fields(component)
                       if isinstance(v := getattr(component, f.name), Body) and id(v) in swapped}
            return dataclasses.replace(component, **changes) if changes else component

        for body in self.bodies:
            out.add(rewired(new[body.name]))
        for component in (*self.joints, *self.torques, *self.shaft_terms):  # (joints: meshes, shafts, bearings)
            out.add(rewired(component))
        out._frame_terms = self._frame_terms
        out._defaults.update(self._defaults)
        out._descriptions.update(self._descriptions)
        out._physical.update(self._physical)  # (SI values already read and checked)
        out._initial.update(self._initial)
        out._length_scale = self._length_scale
        out._changed()
        return out

    # ----------------------------------------------------------------- resolving
    @cached_property
    def resolved(self) -> "ResolvedDrivetrain":
        return ResolvedDrivetrain(self)

    def form_lagrangian(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """Kinetic energy T, potential energy V and Rayleigh dissipation R."""
        r = self.resolved
        return r.kinetic_energy, r.potential_energy, r.dissipation

    def form_eoms(self) -> list[sp.Eq]:
        """Lagrange's equations d/dt dL/dpsi' - dL/dpsi + dR/dpsi' = Q, one per body."""
        return self.resolved.equations_of_motion

    def __repr__(self) -> str:
        faults = f", {len(self.shaft_terms)} shaft-order terms" if self.shaft_terms else ""
        faults += f", {len(self.bearings)} bearings" if self.bearings else ""
        return (
            f"Drivetrain({self.name!r}: {len(self.bodies)} bodies, "
            f"{len(self.couplings)} couplings, {len(self.torques)} torques{faults})"
        )
