"""Physical values in, nondimensional values for the engine: the map the reduction defines.

The reduction writes the equations in a unit system of its own: time in 1/omega_n, where omega_n^2 is
the left-hand side of its time-unit condition (``m kZ`` of the first mesh). A :class:`Scaling` completes
that unit system from physical values (SI numbers, :class:`~gearsym.units.Measure`, converted at the edge):

* time unit ``T = 1/omega_n``, from the condition itself;
* mass unit ``M = kZ / omega_n^2`` (the first mesh's effective mass ``1/m``), so its stiffness is 1 and
  its damping is ``2 zeta``, as in the paper's Eqs. 3-4;
* length unit ``L``: the static deflection of the first mesh under the mean load (the static solution of
  the reduced equations, :mod:`gearsym.reduction.statics`: chains, trees and loops alike), half its
  backlash, or a given length.

Every parameter is then a number in these units (``value / (M^a L^b T^c)`` for a value of dimension
``[mass]^a [length]^b [time]^c``), the free groups (zeta, B0, B1, K ...) are their own definitions
evaluated at those numbers, and omega is the forcing frequency times T. Nothing is retyped from the paper:
change the drivetrain and the same code scales it. The length unit is the engine's, not the answer's: an
initial state is kept physically the same whatever it is, and results carried back (:mod:`gearsym.physical`)
do not depend on it.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from functools import cached_property

import sympy as sp

from ..errors import GearsymError, ModelError, UnknownParameterError
from ..model.expressions import parameter_names
from ..model.length_scale import check_length_scale
from ..model.resolved_components import ResolvedCoupling
from ..reduction import NondimensionalModel
from ..reduction.statics import StaticState, static_state, torque_imbalance
from ..model.symbols import parameter_symbol
from ..units import Measure, Quantity, conversion_factor, dimension_text, measure, symbol
from .dimensions import evaluate, same_dimension
from .roles import SPEED, fields, parameter_roles, physical_parameters
from .settings import maybe_number
from .speeds import SpeedRatios, declared_speed

#: how closely the mean torques must balance (a fraction of the largest): see Scaling._check_balance
BALANCE = 1e-3
#: units a speed may be given in: an angle per time (a bare 1/s is no speed: revolutions or radians?)
_ANGLES = ("radian", "revolution", "hertz", "degree", "turn", "cycle", "rpm")


class Scaling:
    """A reduced drivetrain with physical values: its units, its nondimensional values, and the numbers that
    carry results back.

    ``values`` are what :meth:`NondimensionalModel.system` takes, :meth:`values_at` those at another operating
    point (``speed="3000 rpm"``). The units (``omega_n``, ``time``, ``mass``, ``length``) are pint Quantities
    for a Python user; the numbers inside are SI (``si_values``).
    """

    def __init__(self, nd: NondimensionalModel, physical: Mapping[str, object], length_scale="static"):
        if not isinstance(nd, NondimensionalModel):
            raise GearsymError(f"{getattr(nd, 'name', nd)}: physical values need a drivetrain model "
                               "(a FirstOrderSystem has no components to give them units)")
        self.model = nd
        self.name = nd.name
        rd = nd.reduction.resolved
        self.length_scale = check_length_scale(length_scale, f"{self.name}: length scale")
        self.speed = declared_speed(nd.drivetrain)
        self.roles = parameter_roles(rd)
        if self.speed:
            self.roles[self.speed.parameter] = (SPEED, self.speed.where)
        physical = dict(physical)
        #: stiffness functions replaced by a formula (``k="1+0.2*cos(tau)"``), and the values of the new
        #: (dimensionless) parameters such a formula brings (``a=0.3`` for ``k="1+a*cos(tau)"``)
        self.functions: dict[str, object] = {f.name: physical.pop(f.name) for f in nd.functions if f.name in physical}
        self.formula_values: dict[str, float] = self._formula_values(physical)
        self.inputs: dict[str, Measure] = self._inputs(physical)  # name -> SI value, as the user gave it
        self._check_dimensions()
        self._check_signs()
        self._check_conditions()
        self._check_balance()

    # ------------------------------------------------------------------ inputs
    def _formula_values(self, given: dict[str, object]) -> dict[str, float]:
        """The values of the parameters the stiffness formulas bring (removed from ``given``): plain numbers, since
        a stiffness formula is nondimensional."""
        new = set()
        for f in self.model.functions:
            if f.name in self.functions:
                new |= parameter_names(self.model.stiffness_formula(f, self.functions[f.name]))
        new -= set(self.model.parameter_names) | set(physical_parameters(self.model.reduction.resolved))
        out = {}
        for name in sorted(new & set(given)):
            value = maybe_number(given.pop(name))
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ModelError(f"{value!r} is not a number: a parameter of a stiffness formula is dimensionless",
                                 f"{self.name}: {name}")
            out[name] = float(value)
        return out

    def _inputs(self, given: Mapping[str, object]) -> dict[str, Measure]:
        names = physical_parameters(self.model.reduction.resolved)
        known = names + ([self.speed.parameter] if self.speed else [])
        out: dict[str, Measure] = {}
        derived = {gr.name: gr for gr in self.model.groups if gr.kind == "free"}
        for name, value in given.items():
            if name == "omega" and self.speed:
                raise ModelError(f"omega follows from the speed when the model has physical values: give "
                                 f"{self.speed.parameter}='3000 rpm' instead", self.name)
            if name in derived:
                behind = ", ".join(sorted(str(s) for s in derived[name].definition.free_symbols))
                raise ModelError(f"{name} is derived from the physical values ({name} = {derived[name].definition}): "
                                 f"set {behind} instead", self.name)
            if name not in known:
                raise UnknownParameterError(name, known, f"{self.name}: physical values")
            out[name] = self._input(name, value)
        defaults = self.model.drivetrain.defaults
        missing = []
        for name in names:
            if name in out:
                continue
            role = self.roles.get(name, (None, ""))[0]
            if name in defaults and (role is None or not role.example):  # a dimensionless default (k_a, Theta)
                number = self.model.check_value(name, defaults[name])
                out[name] = Measure(number, (0.0, 0.0, 0.0), number)
            else:
                missing.append(name)
        if missing:
            wanted = "; ".join(f"{n} ({self.roles[n][0].describe()})" if n in self.roles else n for n in missing)
            raise ModelError(f"no physical value for {wanted}. Add them to model.set_physical(...) or give them "
                             f"(--set {missing[0]}='...')", self.name)
        return out

    def _input(self, name: str, value) -> Measure:
        """One physical value in SI; a plain number (or text that reads as one) for a value that has a unit is
        refused (one rule everywhere: a number is never silently read in some unit)."""
        where = f"{self.name}: {name}"
        out = measure(maybe_number(value), where)
        if out.dimensionless and not out.unit:  # a number, text that reads as one, a declared plain number
            unit = self.unit_needed(name)
            if unit:
                raise ModelError(self.unitless(name, out.given, f"{name}='{out.given:g} {symbol(unit)}'"), where)
        role = self.roles.get(name, (None, ""))[0]
        if role is SPEED and same_dimension(out.dims, SPEED.dims) and out.unit \
                and not any(a in out.unit for a in _ANGLES):
            raise ModelError(f"{out.text()} is a frequency without an angle: write '{out.given:g} rev/s' "
                             f"(revolutions) or '{out.given:g} rad/s'", where)
        return out

    def unit_needed(self, name: str) -> str:
        """The unit a value of ``name`` is shown in (its declared one, else its role's), or "" for a dimensionless
        value (a plain number is then fine)."""
        role = self.roles.get(name, (None, ""))[0]
        if role is None or not role.example:
            return ""
        declared = self.model.drivetrain.physical.get(name)
        if name in getattr(self, "inputs", {}) and self.inputs[name].unit:
            declared = self.inputs[name]
        return declared.unit if declared is not None and declared.unit else role.example

    def unitless(self, name: str, number: float, spelled: str) -> str:
        """The one message for a plain number given to a value that has a unit (``--set``, ``--param``, a keyword,
        a sweep axis): what is missing and ``spelled``, the value written with its unit as the entry takes it."""
        role = self.roles[name][0]
        return f"{number:g} has no unit, and {role.meaning} needs one: write {spelled}"

    def _check_dimensions(self) -> None:
        for name, q in self.inputs.items():
            role, where = self.roles.get(name, (None, ""))
            if role is not None and not same_dimension(q.dims, role.dims):
                raise ModelError(f"{q.text()} is not {role.describe()} (it is {dimension_text(q.dims)}; {where})",
                                 f"{self.name}: {name}")
        for field in fields(self.model.reduction.resolved):
            if isinstance(field.expression, sp.Symbol) or field.expression.is_Number:
                continue
            value = evaluate(field.expression, self.inputs, f"{self.name}: {field.where}")
            if not same_dimension(value.dims, field.role.dims):
                raise ModelError(f"{field.expression} is {dimension_text(value.dims)}, not {field.role.describe()}",
                                 f"{self.name}: {field.where}")

    def _check_signs(self) -> None:
        """What must be positive (inertias, radii) or not negative (stiffness, damping, backlash), in the user's
        units, before anything is divided by it."""
        constraints = self.model._constraints
        for name, q in self.inputs.items():
            constraint = constraints.get(name)
            if constraint is None or name == "omega":
                continue
            must = constraint.violation(q.si)
            if must:
                raise ModelError(f"{q.text()} is {constraint.meaning} and {must}", f"{self.name}: {name}")
        if self.speed and self.speed.parameter in self.inputs and not self.inputs[self.speed.parameter].si > 0:
            raise ModelError(f"{self.inputs[self.speed.parameter].text()} is the operating speed and must be "
                             "positive", f"{self.name}: {self.speed.parameter}")

    def _check_conditions(self) -> None:
        """The reduction's assumptions (a torque balance, Eq. 10) must hold at the physical values."""
        for c in self.model.conditions:
            if c.kind == "time_unit":
                continue
            where = f"{self.name}: {c.description.split(':')[0]}"
            terms = [evaluate(a, self.inputs, where).si for a in sp.Add.make_args(sp.expand(c.equation.lhs - c.equation.rhs))]
            off = math.fsum(terms)
            if abs(off) > 1e-9 * max(abs(t) for t in terms):
                dims = evaluate(c.equation.rhs if c.equation.lhs == 0 else c.equation.lhs, self.inputs, where).dims
                raise ModelError(f"the physical values break a condition of the reduction: {c.equation.lhs} = "
                                 f"{c.equation.rhs} is {off:.6g} {dimension_text(dims)} (SI) off ({c.description})",
                                 self.name)

    def _check_balance(self) -> None:
        """A steady operating point needs the mean torques to balance in every rigid-body rotation: to
        ``BALANCE`` of the largest (values given to four digits, 100 N·m against 265.2 N·m through 23/61 teeth,
        balance to 6e-5: the speed such a train drifts by over a run is far below anything the run resolves);
        worse is refused, with the torque that would balance it."""
        reference = self.speed.body if self.speed else None
        for gap in torque_imbalance(self.model.reduction, self.si_values, reference, BALANCE):
            options = [f"{t} = {_torque(v)} on {b!r}" for t, b, v in gap.balancing if v > 0] or \
                      [f"{t} = {_torque(v)} on {b!r}" for t, b, v in gap.balancing]
            raise ModelError(
                f"the mean torques do not balance: they leave {_torque(gap.net)} (on the axis of {gap.reference!r}) "
                f"to accelerate the whole train, so there is no steady operating point. "
                f"{' or '.join(options[:2])} balances them", self.name)

    @classmethod
    def of(cls, nd: NondimensionalModel, length_scale=None, **physical) -> "Scaling":
        """The scaling of ``nd`` at its declared physical values, ``physical`` overriding them, in its declared
        length unit unless ``length_scale`` is given."""
        scale = nd.drivetrain.length_scale if length_scale is None else length_scale
        return cls(nd, {**nd.drivetrain.physical, **physical}, scale)

    @property
    def full(self) -> "Scaling":
        """The scaling itself (the start-up cache's stand-in, :class:`~gearsym.physical.point.CachedScaling`, makes
        its full scaling here: whatever a caller needs beyond a spectrum's units)."""
        return self

    def with_values(self, **physical) -> "Scaling":
        """The same drivetrain with some physical values changed (``speed="3000 rpm"``)."""
        return type(self)(self.model, {**self.inputs, **self.functions, **self.formula_values, **physical},
                          self.length_scale)

    # ------------------------------------------------------------------ SI numbers
    @cached_property
    def si_values(self) -> dict[str, float]:
        """Every physical value as an SI number."""
        return {name: q.si for name, q in self.inputs.items()}

    @cached_property
    def statics(self) -> StaticState:
        """The drivetrain at rest under its mean loads, in SI (m, N)."""
        return static_state(self.model.reduction, self.si_values)

    @cached_property
    def omega_n_si(self) -> float:
        """The natural frequency that is the time unit, in rad/s: omega_n^2 = the time-unit condition's left side."""
        condition = next(c for c in self.model.conditions if c.kind == "time_unit")
        square = evaluate(condition.equation.lhs, self.inputs, f"{self.name}: time unit")
        if not same_dimension(square.dims, (0.0, 0.0, -2.0)):
            raise GearsymError(f"{self.name}: the time-unit condition {condition.equation.lhs} is "
                               f"{dimension_text(square.dims)}, not a frequency squared")
        if not square.si > 0:
            raise GearsymError(f"{self.name}: omega_n^2 = {condition.equation.lhs} = {square.si:.6g} 1/s² must be "
                               "positive")
        return math.sqrt(square.si)

    @cached_property
    def reference_mesh(self) -> ResolvedCoupling:
        return self.model._mesh(self.model.functions[0])

    @cached_property
    def mass_si(self) -> float:
        """The mass unit kZ/omega_n^2 (the first mesh's effective mass) in kg: its stiffness is 1 in these units."""
        stiffness = evaluate(self.reference_mesh.stiffness, self.inputs, f"{self.name}: mesh stiffness").si
        return stiffness / self.omega_n_si ** 2

    @cached_property
    def static_deflection_si(self) -> float:
        """The first mesh's deflection at rest under the mean loads, in m (negative on the back flank)."""
        return self.statics.deflections[self.reference_mesh.name]

    @cached_property
    def length_si(self) -> float:
        """The length unit L in m (see the module's docstring)."""
        return self._length_of(self.length_scale)

    def _length_of(self, scale) -> float:
        if isinstance(scale, Measure):
            return scale.si
        if scale == "backlash":
            eta = evaluate(self.reference_mesh.backlash, self.inputs, f"{self.name}: backlash").si
            if not eta > 0:
                raise GearsymError(f"{self.name}: the mesh has no backlash to scale lengths by; use the length "
                                   "scale 'static' or a length such as '1 um'")
            return eta / 2
        deflection = self.static_deflection_si
        if not deflection > 0:
            flank = self.statics.contact[self.reference_mesh.name]
            why = ("the mean load presses the back flanks" if flank == "back" else "the mesh carries no mean load")
            raise GearsymError(f"{self.name}: the static deflection of mesh {self.reference_mesh.name!r} under the "
                               f"mean load is {deflection * 1e6:.6g} µm ({why}), so it cannot be the length unit; use "
                               "the length scale 'backlash' or a length such as '1 um'")
        return deflection

    @property
    def time_si(self) -> float:
        return 1.0 / self.omega_n_si

    def unit_of(self, dims: tuple[float, float, float]) -> float:
        """The scaled unit M^a L^b T^c of a value of these dimensions, in SI."""
        a, b, c = dims
        return self.mass_si ** a * self.length_si ** b * self.time_si ** c

    # ------------------------------------------------------------------ the units, for a Python user
    @property
    def omega_n(self):
        """omega_n in rad/s (a pint Quantity)."""
        return Quantity(self.omega_n_si, "rad/s")

    @property
    def time(self):
        """The time unit 1/omega_n, in s."""
        return Quantity(self.time_si, "s")

    @property
    def mass(self):
        return Quantity(self.mass_si, "kg")

    @property
    def length(self):
        """The length unit L, in m."""
        return Quantity(self.length_si, "m")

    @property
    def static_deflection(self):
        """The first mesh's static deflection under the mean load, in m."""
        return Quantity(self.static_deflection_si, "m")

    # ------------------------------------------------------------------ both ways
    def scaled(self, name: str, value=None) -> float:
        """Parameter ``name`` (its value, or ``value``) as a number in the scaled units."""
        q = self.inputs[name] if value is None else measure(value, f"{self.name}: {name}")
        return q.si / self.unit_of(q.dims)

    def physical(self, name: str, number: float) -> Measure:
        """The inverse of :meth:`scaled`: a number in the scaled units back as a value of ``name``'s kind."""
        given = self.inputs[name]
        return given.with_si(number * self.unit_of(given.dims))

    @cached_property
    def scaled_values(self) -> dict[str, float]:
        return {name: self.scaled(name) for name in self.inputs if not self.speed or name != self.speed.parameter}

    def group_si(self, name: str) -> Measure:
        """A free group's definition evaluated in SI (zeta in 1/s, B0 in m/s^2, ...)."""
        return evaluate(self.model.group(name).definition, self.inputs, f"{self.name}: group {name}")

    def group_value(self, name: str) -> float:
        """A free group's nondimensional value: its definition at the scaled values."""
        gr = self.model.group(name)
        subs = {parameter_symbol(n): v for n, v in self.scaled_values.items()}
        return float(gr.definition.xreplace(subs))

    # ------------------------------------------------------------------ speed and frequencies
    @cached_property
    def ratios(self) -> SpeedRatios:
        return SpeedRatios(self.model, self.speed, {parameter_symbol(n): v for n, v in self.si_values.items()})

    def speed_si(self, speed=None) -> float:
        """The operating speed in rad/s (``speed``, or this scaling's)."""
        if not self.speed:
            raise GearsymError(f"{self.name}: no body declares the operating speed; declare it on one, e.g. "
                               "Gear(..., teeth=20, speed='speed')")
        if speed is None:
            if self.speed.parameter not in self.inputs:
                raise GearsymError(f"{self.name}: no value for the speed; give it (--set {self.speed.parameter}="
                                   "'3000 rpm')")
            return self.inputs[self.speed.parameter].si
        q = self._input(self.speed.parameter, speed)
        if not same_dimension(q.dims, SPEED.dims):
            raise ModelError(f"{q.text()} is not {SPEED.describe()}", f"{self.name}: {self.speed.parameter}")
        return q.si

    @property
    def speed_unit(self) -> str:
        """The unit the speed is given in (rpm if none is)."""
        if self.speed and self.speed.parameter in self.inputs and self.inputs[self.speed.parameter].unit:
            return self.inputs[self.speed.parameter].unit
        return "rpm"

    def body_speed_ratio(self, body: str) -> float:
        return self.ratios.body(body)

    def mesh_frequency_ratio(self, rc: ResolvedCoupling) -> float:
        return self.ratios.mesh(rc)

    @cached_property
    def forcing_ratio(self) -> float:
        """The forcing frequency (omega's) per unit operating speed."""
        return self.ratios.forcing(self.reference_mesh)

    def forcing_frequency(self, speed=None):
        """The forcing frequency (the first mesh's frequency over its order) at a speed, in rad/s."""
        return Quantity(self.speed_si(speed) * self.forcing_ratio, "rad/s")

    def mesh_frequency(self, speed=None, mesh: str | None = None):
        """The tooth-passing frequency of a mesh (default the first) at a speed, in Hz."""
        return Quantity(self._mesh_frequency_hz(speed, mesh), "Hz")

    def _mesh_frequency_hz(self, speed=None, mesh: str | None = None) -> float:
        """:meth:`mesh_frequency`'s number (pint's conversion from rad/s, without pint when it is kept)."""
        rc = self.reference_mesh if mesh is None else self.model._mesh(
            next(f for f in self.model.functions if f.mesh == mesh))
        return self.speed_si(speed) * self.mesh_frequency_ratio(rc) * conversion_factor("rad/s", "Hz")

    def omega(self, speed=None) -> float:
        """The nondimensional forcing frequency at a speed: forcing frequency / omega_n."""
        return self.speed_si(speed) * self.forcing_ratio / self.omega_n_si

    def speed_si_at(self, omega: float) -> float:
        """The operating speed (rad/s) at which the nondimensional forcing frequency is ``omega``."""
        self.speed_si(Quantity(1.0, "rad/s"))  # checks that a speed is declared
        return omega * self.omega_n_si / self.forcing_ratio

    def speed_at(self, omega: float, unit: str | None = None):
        """The operating speed at which the nondimensional forcing frequency is ``omega`` (in the speed's unit)."""
        return Quantity(self.speed_si_at(omega), "rad/s").to(unit or self.speed_unit)

    # ------------------------------------------------------------------ the engine's values
    @cached_property
    def values(self) -> dict[str, float]:
        """Every parameter of the nondimensional model, as :meth:`NondimensionalModel.system` takes them."""
        free = {gr.name for gr in self.model.groups if gr.kind == "free"}
        out = {}
        for name in self.model.parameter_names:
            if name == "omega":
                if self.speed and self.speed.parameter in self.inputs:
                    out[name] = self.omega()
                elif "omega" in self.model.drivetrain.defaults:
                    out[name] = self.model.check_value("omega", self.model.drivetrain.defaults["omega"])
                else:
                    self.speed_si()  # says what is missing
            elif name in free:
                out[name] = self.group_value(name)
            elif name in self.scaled_values:
                out[name] = self.scaled_values[name]
            else:
                raise GearsymError(f"{self.name}: parameter {name} has no physical value")
        return out

    def values_at(self, **physical) -> dict[str, float]:
        """The nondimensional values with some physical values changed (``speed="3000 rpm"``)."""
        return self.with_values(**physical).values if physical else dict(self.values)

    def parameter_moved_by(self, name: str) -> str:
        """The nondimensional parameter that the physical value ``name`` moves, found by a small step away from it
        (the one a one-point axis of ``name`` sweeps; several, comma-separated, where it moves more than one)."""
        q = self.inputs.get(name)
        shifted = self.values_at(**{name: q.with_si(q.si * 1.01) if q is not None
                                    else Quantity(self.speed_si() * 1.01, "rad/s")})
        moved = [k for k, v in shifted.items() if v != self.values[k]]
        return moved[0] if len(moved) == 1 else ",".join(moved)

    @cached_property
    def initial(self) -> dict[str, float]:
        """The declared initial state in the engine's units: plain numbers are in the model's declared length unit
        (so another length scale starts from the same physical state), physical values are converted."""
        declared = self.model.drivetrain.length_scale
        ratio = 1.0 if declared == self.length_scale else self._declared_length() / self.length_si
        kinds, radius = {}, {}
        for c in self.model.coordinates:
            kinds[c.name], kinds[c.velocity_name] = "length", "rate"
            if c.coupling.kind != "mesh":  # a shaft's coordinate is its radius times its twist
                radius[c.name] = radius[c.velocity_name] = c.coupling.scale
        out = {}
        for name, value in self.model.drivetrain.initial_state.items():
            if name not in kinds:
                raise UnknownParameterError(name, kinds, f"{self.name}: initial state")
            if isinstance(value, Measure):
                rate = kinds[name] == "rate"
                per = self.length_si * (self.omega_n_si * self.values["omega"] if rate else 1.0)
                if name in radius and same_dimension(value.dims, (0.0, 0.0, -1.0 if rate else 0.0)):
                    # a shaft's twist (rate) in rad (rad/s), as gearsym gives it back
                    r = evaluate(radius[name], self.inputs, f"{self.name}: shaft coordinate radius").si
                    out[name] = value.si * r / per
                    continue
                wanted = (0.0, 1.0, -1.0) if rate else (0.0, 1.0, 0.0)
                if not same_dimension(value.dims, wanted):
                    what = ("a twist rate (rad/s) or a velocity" if rate else "a twist (rad) or a length") \
                        if name in radius else ("a velocity" if rate else "a length")
                    raise ModelError(f"{value.text()} is not {what}", f"{self.name}: initial state {name}")
                out[name] = value.si / per
            else:
                out[name] = value * ratio
        return out

    def _declared_length(self) -> float:
        declared = self.model.drivetrain.length_scale
        try:
            return self._length_of(declared)
        except GearsymError as exc:
            raise GearsymError(f"{exc} (the initial state is declared in that length unit; declare it with units, "
                               "e.g. set_initial_state(x='10 um'))") from None

    def system(self, **settings):
        """The engine's first-order system at these values (``settings``: physical values, or a new stiffness
        function as a formula in tau or phi, and its new parameters' values)."""
        at = self.with_values(**settings) if settings else self
        return self.model.system(**at.values, **at.functions, **at.formula_values, initial=at.initial)

    # ------------------------------------------------------------------ the record
    def summary(self) -> dict:
        """JSON-ready: the inputs, the units and the nondimensional values (``gearsym derive`` and the docs)."""
        out = {
            "inputs": {n: q.text() for n, q in self.inputs.items()},
            "length_scale": self.length_scale if isinstance(self.length_scale, str) else self.length_scale.text(),
            "omega_n": f"{self.omega_n_si:.6g} rad/s", "natural_frequency": f"{self.omega_n_si / (2 * math.pi):.6g} Hz",
            "time_unit": f"{self.time_si:.6g} s", "mass_unit": f"{self.mass_si:.6g} kg",
            "length_unit": f"{self.length_si * 1e6:.6g} {symbol('um')}",
            "static_deflection": f"{self.static_deflection_si * 1e6:.6g} {symbol('um')}",
            "values": self.values,
        }
        if self.speed and self.speed.parameter in self.inputs:
            out["mesh_frequency"] = f"{self._mesh_frequency_hz():.6g} Hz"
        return out


def _torque(newton_metres: float) -> str:
    return f"{newton_metres:.6g} N·m"
