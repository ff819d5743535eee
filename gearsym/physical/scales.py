"""Physical values in, nondimensional values for the engine, physical results out: the scaling stage.

The reduction writes the equations in a unit system of its own: time in 1/omega_n, where
omega_n^2 is the left-hand side of its time-unit condition (``m kZ`` of the first mesh). A
:class:`Scaling` completes that unit system from physical values:

* time unit ``T = 1/omega_n``, from the condition itself;
* mass unit ``M = kZ / omega_n^2`` (the first mesh's effective mass ``1/m``), so its stiffness is 1
  and its damping is ``2 zeta``, as in the paper's Eqs. 3-4;
* length unit ``L``: the static deflection of the first mesh under the mean load (``B0/omega_n^2``,
  so that B0 = 1 as in the paper), half its backlash, or a given length.

Every parameter is then a number in these units (``value / (M^a L^b T^c)`` for a value of
dimension ``[mass]^a [length]^b [time]^c``), the free groups (zeta, B0, B1, K ...) are their own
definitions evaluated at those numbers, and omega is the forcing frequency times T. Nothing is
retyped from the paper: change the drivetrain and the same code scales it. The way back multiplies
by the same units: a length by L, a time (in tau) by ``1/(omega omega_n)``, an exponent per unit
tau by ``omega omega_n``.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from functools import cached_property

import pint
import sympy as sp

from ..errors import GearsymError, ModelError, UnknownParameterError
from ..model.drivetrain import Drivetrain, ResolvedCoupling
from ..symbols import parameter_symbol
from .point import Speed
from .roles import SPEED, fields, parameter_roles, physical_parameters
from .units import Quantity, as_quantity, dimension_text, shown, ureg

LENGTH_SCALES = ("static", "backlash")
#: the dimensions a drivetrain's values are made of (angles are dimensionless)
BASE = ("[mass]", "[length]", "[time]")
#: how closely a gear pair's radii must follow its tooth counts (both set the same speed ratio)
RATIO_TOLERANCE = 1e-3


def check_length_scale(scale, where: str):
    """``"static"``, ``"backlash"`` or a positive length (a pint Quantity)."""
    if isinstance(scale, str) and scale.strip() in LENGTH_SCALES:
        return scale.strip()
    q = as_quantity(scale, where)
    if q.dimensionality != ureg.meter.dimensionality or not q.magnitude > 0:
        raise GearsymError(f"{where}: the length scale is 'static' (the static deflection), 'backlash' (half "
                           f"the backlash) or a positive length such as '1 um', got {scale!r}")
    return q


def evaluate(expr: sp.Expr, values: Mapping[str, pint.Quantity], where: str) -> pint.Quantity:
    """``expr`` with every parameter a quantity: dimensions are checked by pint at every + and every function."""
    if expr.is_Number or isinstance(expr, sp.NumberSymbol):
        return Quantity(float(expr))
    if isinstance(expr, sp.Symbol):
        if expr.name not in values:
            raise GearsymError(f"{where}: no physical value for {expr.name}")
        return values[expr.name]
    args = [evaluate(a, values, where) for a in expr.args]
    try:
        if expr.is_Add:
            total = args[0]
            for a in args[1:]:
                total = total + a
            return total
        if expr.is_Mul:
            return math.prod(args[1:], start=args[0])
        if expr.is_Pow and expr.exp.is_Number:
            return args[0] ** float(expr.exp)
        if isinstance(expr, sp.Function) and all(a.dimensionless for a in args):
            return Quantity(float(expr.func(*(sp.Float(a.to("").magnitude) for a in args))))
    except pint.DimensionalityError as exc:
        raise GearsymError(f"{where}: inconsistent dimensions in {expr} ({exc})") from None
    raise GearsymError(f"{where}: cannot evaluate {expr} with units (a function of a dimensional value?)")


def _exponents(q: pint.Quantity, name: str) -> tuple[float, float, float]:
    dims = dict(q.dimensionality)
    other = sorted(set(dims) - set(BASE))
    if other:
        raise GearsymError(f"{name}: a drivetrain value is made of mass, length and time, but {shown(q)} has "
                           f"the dimension {dimension_text(q.dimensionality)}")
    return tuple(float(dims.get(d, 0)) for d in BASE)


class Scaling:
    """A reduced drivetrain with physical values: its units, its nondimensional values, and the way back.

    Made by :func:`scaling`; ``values`` are what :meth:`NondimensionalModel.system` takes,
    :meth:`values_at` those at another operating point (``speed="3000 rpm"``), and ``to_physical``
    (:mod:`gearsym.physical.results`) carries results back.
    """

    def __init__(self, nd, physical: Mapping[str, object], length_scale="static"):
        from ..reduce import NondimensionalModel

        if not isinstance(nd, NondimensionalModel):
            raise GearsymError(f"{getattr(nd, 'name', nd)}: physical values need a drivetrain model "
                               "(a FirstOrderSystem has no components to give them units)")
        self.model = nd
        self.name = nd.name
        rd = nd.reduction.resolved
        self.length_scale = check_length_scale(length_scale, f"{self.name}: length scale")
        self.speed = _declared_speed(nd.drivetrain)
        self.roles = parameter_roles(rd)
        if self.speed:
            self.roles[self.speed.parameter] = (SPEED, self.speed.where)
        self.inputs = self._inputs(physical)  # name -> Quantity, in the units given
        self._check_dimensions()
        self._check_conditions()

    # ------------------------------------------------------------------ inputs
    def _inputs(self, given: Mapping[str, object]) -> dict[str, pint.Quantity]:
        names = physical_parameters(self.model.reduction.resolved)
        known = names + ([self.speed.parameter] if self.speed else [])
        out: dict[str, pint.Quantity] = {}
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
            out[name] = as_quantity(value, f"{self.name}: {name}")
        defaults = self.model.drivetrain.defaults
        missing = []
        for name in names:
            if name in out:
                continue
            role = self.roles.get(name, (None, ""))[0]
            if name in defaults and (role is None or not role.example):  # a dimensionless default (k_a, Theta)
                out[name] = Quantity(self.model.check_value(name, defaults[name]))
            else:
                missing.append(name)
        if missing:
            wanted = "; ".join(f"{n} ({self.roles[n][0].describe()})" if n in self.roles else n for n in missing)
            raise ModelError(f"no physical value for {wanted}. Add them to model.set_physical(...) or give them "
                             f"(--set {missing[0]}='...')", self.name)
        return out

    def _check_dimensions(self) -> None:
        for name, q in self.inputs.items():
            role, where = self.roles.get(name, (None, ""))
            if role is not None and q.dimensionality != role.dimensionality:
                raise ModelError(f"{shown(q)} is not {role.describe()} (it is {dimension_text(q.dimensionality)}; "
                                 f"{where})", f"{self.name}: {name}")
        for field in fields(self.model.reduction.resolved):
            if isinstance(field.expression, sp.Symbol) or field.expression.is_Number:
                continue
            value = evaluate(field.expression, self.inputs, f"{self.name}: {field.where}")
            if value.dimensionality != field.role.dimensionality:
                raise ModelError(f"{field.expression} = {shown(value)} is not {field.role.describe()}",
                                 f"{self.name}: {field.where}")
        for name, q in self.inputs.items():
            _exponents(q, f"{self.name}: {name}")

    def _check_conditions(self) -> None:
        """The reduction's assumptions (a torque balance, Eq. 10) must hold at the physical values."""
        for c in self.model.conditions:
            if c.kind == "time_unit":
                continue
            where = f"{self.name}: {c.description.split(':')[0]}"
            terms = [evaluate(a, self.inputs, where).to_base_units()
                     for a in sp.Add.make_args(sp.expand(c.equation.lhs - c.equation.rhs))]
            off = sum(terms[1:], terms[0])
            if abs(off.magnitude) > 1e-9 * max(abs(t.magnitude) for t in terms):
                raise ModelError(f"the physical values break a condition of the reduction: {c.equation.lhs} = "
                                 f"{c.equation.rhs} is {shown(off)} off ({c.description})", self.name)

    def with_values(self, **physical) -> "Scaling":
        """The same drivetrain with some physical values changed (``speed="3000 rpm"``)."""
        return Scaling(self.model, {**self.inputs, **physical}, self.length_scale)

    # ------------------------------------------------------------------ units
    @cached_property
    def omega_n(self) -> pint.Quantity:
        """The natural frequency that is the time unit: omega_n^2 = the left side of the time-unit condition."""
        condition = next(c for c in self.model.conditions if c.kind == "time_unit")
        square = evaluate(condition.equation.lhs, self.inputs, f"{self.name}: time unit")
        try:
            per_second = square.to("1/s**2").magnitude
        except pint.DimensionalityError:
            raise GearsymError(f"{self.name}: the time-unit condition {condition.equation.lhs} is "
                               f"{shown(square)}, not a frequency squared") from None
        if not per_second > 0:
            raise GearsymError(f"{self.name}: omega_n^2 = {condition.equation.lhs} = {shown(square)} must be positive")
        return Quantity(math.sqrt(per_second), "rad/s")

    @property
    def time(self) -> pint.Quantity:
        """The time unit 1/omega_n, in seconds."""
        return Quantity(1.0 / self.omega_n.magnitude, "s")

    @cached_property
    def reference_mesh(self) -> ResolvedCoupling:
        return self.model._mesh(self.model.functions[0])

    @cached_property
    def mass(self) -> pint.Quantity:
        """The mass unit kZ/omega_n^2 (the first mesh's effective mass): its stiffness is 1 in these units."""
        stiffness = evaluate(self.reference_mesh.stiffness, self.inputs, f"{self.name}: mesh stiffness")
        return (stiffness / Quantity(self.omega_n.magnitude, "1/s") ** 2).to("kg")

    @cached_property
    def static_group(self) -> str | None:
        """The constant forcing group of the first coordinate (B0), whose deflection is the static scale."""
        for term in sp.Add.make_args(self.model.row_rhs[0]):
            if isinstance(term, sp.Symbol) and any(gr.symbol == term for gr in self.model.groups):
                return term.name
        return None

    @cached_property
    def length(self) -> pint.Quantity:
        """The length unit L (see the module's docstring), in metres."""
        if isinstance(self.length_scale, pint.Quantity):
            return self.length_scale.to("m")
        if self.length_scale == "backlash":
            eta = evaluate(self.reference_mesh.backlash, self.inputs, f"{self.name}: backlash").to("m")
            if not eta.magnitude > 0:
                raise GearsymError(f"{self.name}: the mesh has no backlash to scale lengths by; use the length "
                                   "scale 'static' or a length such as '1 um'")
            return eta / 2
        group = self.static_group
        force = self.group_quantity(group) if group else None
        deflection = (force / Quantity(self.omega_n.magnitude, "1/s") ** 2).to("m") if force is not None else None
        if deflection is None or not deflection.magnitude > 0:
            raise GearsymError(f"{self.name}: the static deflection under the mean load is "
                               f"{'zero' if deflection is None else shown(deflection.to('um'))}, so it cannot be the "
                               "length unit; use the length scale 'backlash' or a length such as '1 um'")
        return deflection

    def unit_of(self, q: pint.Quantity, name: str = "value") -> float:
        """The scaled unit M^a L^b T^c a quantity of this dimension is measured in, in SI."""
        a, b, c = _exponents(q, f"{self.name}: {name}")
        return self.mass.magnitude ** a * self.length.magnitude ** b * self.time.magnitude ** c

    # ------------------------------------------------------------------ both ways
    def scaled(self, name: str, q: pint.Quantity | None = None) -> float:
        """Parameter ``name`` (its value, or ``q``) as a number in the scaled units."""
        q = self.inputs[name] if q is None else as_quantity(q, f"{self.name}: {name}")
        return float(q.to_base_units().magnitude / self.unit_of(q, name))

    def physical(self, name: str, number: float) -> pint.Quantity:
        """The inverse of :meth:`scaled`: a number in the scaled units back in the unit ``name`` was given in."""
        given = self.inputs[name]
        si = Quantity(number * self.unit_of(given, name), given.to_base_units().units)
        return si.to(given.units)

    @cached_property
    def scaled_values(self) -> dict[str, float]:
        return {name: self.scaled(name) for name in self.inputs if not self.speed or name != self.speed.parameter}

    def group_quantity(self, name: str) -> pint.Quantity:
        """A free group's definition evaluated in physical units (zeta in 1/s, B0 in m/s^2, ...)."""
        return evaluate(self.model.group(name).definition, self.inputs, f"{self.name}: group {name}")

    def group_value(self, name: str) -> float:
        """A free group's nondimensional value: its definition at the scaled values."""
        gr = self.model.group(name)
        subs = {parameter_symbol(n): v for n, v in self.scaled_values.items()}
        return float(gr.definition.xreplace(subs))

    # ------------------------------------------------------------------ speed and frequencies
    def _speed_quantity(self, speed=None) -> pint.Quantity:
        if not self.speed:
            raise GearsymError(f"{self.name}: no body declares the operating speed; declare it on one, e.g. "
                               "Gear(..., teeth=20, speed='speed')")
        if speed is None:
            if self.speed.parameter not in self.inputs:
                raise GearsymError(f"{self.name}: no value for the speed; give it (--set {self.speed.parameter}="
                                   "'3000 rpm')")
            return self.inputs[self.speed.parameter]
        q = as_quantity(speed, f"{self.name}: {self.speed.parameter}")
        if q.dimensionality != SPEED.dimensionality:
            raise ModelError(f"{shown(q)} is not {SPEED.describe()}", f"{self.name}: {self.speed.parameter}")
        return q

    def body_speed_ratio(self, body: str) -> float:
        """Speed of ``body`` over the speed of the body that declares the operating speed (from the rigid modes)."""
        rd = self.model.reduction.resolved
        index = {rb.body.name: rb.index for rb in rd.bodies}
        ref = index[self.speed.body]
        subs = {parameter_symbol(n): v for n, v in self.scaled_values.items()}
        for mode in self.model.reduction.rigid_modes:
            u = [float(e.xreplace(subs)) for e in mode]
            if u[ref] != 0 and u[index[body]] != 0:
                return abs(u[index[body]] / u[ref])
        raise GearsymError(f"{self.name}: {body!r} does not turn with {self.speed.body!r} (no rigid-body mode joins "
                           "them), so its speed is not set by the declared speed")

    def mesh_frequency_ratio(self, rc: ResolvedCoupling) -> float:
        """A mesh's tooth-passing frequency per unit operating speed: teeth x speed of its gear (radians per
        radian of the driving body); its gears' tooth counts and radii must agree."""
        rates = []
        for end in (rc.a, rc.b):
            teeth = end.body.tooth_count
            if teeth is not None:
                if not (isinstance(teeth, int) and not isinstance(teeth, bool) and teeth > 0):
                    raise ModelError(f"teeth must be a positive whole number, got {teeth!r}",
                                     f"{type(end.body).__name__} {end.body.name!r}")
                rates.append((end.body.name, teeth * self.body_speed_ratio(end.body.name)))
        if not rates:
            raise GearsymError(f"{self.name}: mesh {rc.name!r} needs tooth counts to turn the speed into a mesh "
                               f"frequency: declare Gear(..., teeth=N) on {rc.a.body.name!r} and {rc.b.body.name!r}")
        if len(rates) == 2 and not math.isclose(rates[0][1], rates[1][1], rel_tol=RATIO_TOLERANCE):
            raise GearsymError(f"{self.name}: mesh {rc.name!r}: the radii make {rates[0][0]!r} and {rates[1][0]!r} "
                               f"turn in a ratio their tooth counts do not (mesh frequencies {rates[0][1]:.6g} and "
                               f"{rates[1][1]:.6g} per unit speed); base radii must be in the ratio of the teeth")
        return rates[0][1]

    @cached_property
    def forcing_ratio(self) -> float:
        """The forcing frequency (omega's) per unit operating speed; every mesh's order is checked against it."""
        ref = self.reference_mesh
        ratio = self.mesh_frequency_ratio(ref) / float(ref.order)
        for rc in self.model.reduction.resolved.couplings:
            if rc.kind != "mesh" or rc is ref or not any(e.body.tooth_count for e in (rc.a, rc.b)):
                continue
            got = self.mesh_frequency_ratio(rc) / ratio
            if not math.isclose(got, float(rc.order), rel_tol=RATIO_TOLERANCE):
                raise GearsymError(f"{self.name}: mesh {rc.name!r} is declared with order {rc.order} of the forcing "
                                   f"frequency, but its tooth counts give {got:.6g}")
        return ratio

    def forcing_frequency(self, speed=None) -> pint.Quantity:
        """The forcing frequency (the first mesh's frequency over its order) at a speed, in rad/s."""
        q = self._speed_quantity(speed)
        return Quantity(q.to("rad/s").magnitude * self.forcing_ratio, "rad/s")

    def mesh_frequency(self, speed=None, mesh: str | None = None) -> pint.Quantity:
        """The tooth-passing frequency of a mesh (default the first) at a speed, in Hz."""
        rc = self.reference_mesh if mesh is None else self.model._mesh(
            next(f for f in self.model.functions if f.mesh == mesh))
        q = self._speed_quantity(speed)
        return Quantity(q.to("rad/s").magnitude * self.mesh_frequency_ratio(rc), "rad/s").to("Hz")

    def omega(self, speed=None) -> float:
        """The nondimensional forcing frequency at a speed: forcing frequency / omega_n."""
        return float(self.forcing_frequency(speed).magnitude / self.omega_n.magnitude)

    def speed_at(self, omega: float, unit: str | None = None) -> pint.Quantity:
        """The operating speed at which the nondimensional forcing frequency is ``omega`` (in the speed's unit)."""
        unit = unit or (str(self.inputs[self.speed.parameter].units) if self.speed and self.speed.parameter in
                        self.inputs else "rpm")
        self._speed_quantity(Quantity(1.0, unit))  # checks that a speed is declared
        return Quantity(omega * self.omega_n.magnitude / self.forcing_ratio, "rad/s").to(unit)

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
                    self._speed_quantity()  # says what is missing
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

    def system(self, **settings):
        """The engine's first-order system at these values (``settings``: physical values, or a new stiffness
        function as a formula in tau)."""
        functions = {f.name for f in self.model.functions}
        formulas = {k: v for k, v in settings.items() if k in functions}
        physical = {k: v for k, v in settings.items() if k not in functions}
        return self.model.system(**self.values_at(**physical), **formulas)

    def to_physical(self, result, length_unit: str = "um", *, omega: float | None = None, trajectory=None):
        """A result of the engine in physical units: a LyapunovSpectrum (optionally with the mesh forces of a
        ``trajectory`` at the same point), a Trajectory (run at ``omega``, default this scaling's) or a
        SweepResult along omega (see :mod:`gearsym.physical.results`)."""
        from . import results

        if hasattr(result, "exponents"):
            return results.point_to_physical(self, result, length_unit, trajectory)
        if hasattr(result, "columns"):
            return results.sweep_to_physical(self, result, length_unit)
        if hasattr(result, "states") and hasattr(result, "time"):
            return results.trajectory_to_physical(self, result, self.values["omega"] if omega is None else omega,
                                                  length_unit)
        raise GearsymError(f"cannot carry a {type(result).__name__} to physical units")

    # ------------------------------------------------------------------ the record
    def summary(self) -> dict:
        """JSON-ready: the inputs, the units and the nondimensional values (``gearsym derive`` and the docs)."""
        out = {
            "inputs": {n: shown(q) for n, q in self.inputs.items()},
            "length_scale": self.length_scale if isinstance(self.length_scale, str) else shown(self.length_scale),
            "omega_n": shown(self.omega_n), "natural_frequency": shown(self.omega_n.to("Hz")),
            "time_unit": shown(self.time), "mass_unit": shown(self.mass), "length_unit": shown(self.length.to("um")),
            "values": self.values,
        }
        if self.speed and self.speed.parameter in self.inputs:
            out["mesh_frequency"] = shown(self.mesh_frequency())
        return out


def _declared_speed(model: Drivetrain) -> Speed | None:
    declared = [(b.name, b.speed_parameter) for b in model.bodies if b.speed_parameter]
    if len(declared) > 1:
        raise ModelError(f"bodies {', '.join(repr(b) for b, _ in declared)} all declare a speed; declare the "
                         "operating speed on one body (the others follow from the rigid-body mode)", model.name)
    if not declared:
        return None
    body, name = declared[0]
    if not (isinstance(name, str) and name.isidentifier()):
        raise ModelError(f"speed must name a parameter (e.g. speed='speed'), got {name!r}", body)
    return Speed(name, body, f"the speed of {body!r}")


def scaling(model, length_scale=None, **physical) -> Scaling:
    """The :class:`Scaling` of a model (a name, a file, a Drivetrain or its reduction) at its declared physical
    values, with ``physical`` overriding them (``kZ="3e8 N/m"``, ``speed="3000 rpm"``)."""
    from ..reduce import NondimensionalModel, reduce
    from ..registry import load_model

    declared = model if isinstance(model, NondimensionalModel) else load_model(model)
    if not isinstance(declared, (Drivetrain, NondimensionalModel)):
        raise GearsymError(f"{declared.name}: physical values need a drivetrain model (a FirstOrderSystem has no "
                           "components to give them units)")
    nd = declared if isinstance(declared, NondimensionalModel) else reduce(declared)
    scale = nd.drivetrain.length_scale if length_scale is None else length_scale
    return Scaling(nd, {**nd.drivetrain.physical, **physical}, scale)


def is_physical(model, values: Mapping[str, object]) -> bool:
    """True if ``model`` declares physical values or ``values`` give one (a quantity string or a pint Quantity)."""
    from .text import looks_like_quantity

    declared = getattr(getattr(model, "drivetrain", model), "physical", None)
    if declared:
        return True
    return any(isinstance(v, pint.Quantity) or (isinstance(v, str) and looks_like_quantity(v)) for v in values.values())


__all__ = ["LENGTH_SCALES", "Scaling", "check_length_scale", "evaluate", "is_physical", "scaling"]
