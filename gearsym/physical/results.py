"""Results of the nondimensional engine carried back to physical units by a :class:`~.scaling.Scaling`.

At a forcing frequency omega (the engine's), one unit of tau is ``1/(omega omega_n)`` seconds, one unit
of length is the scaling's L, a rate dx/dtau is ``L omega omega_n`` per second and an exponent per unit
tau is ``omega omega_n`` per second. A mesh's coordinate is its deflection (in the length unit); a shaft's
is its coordinate radius times its twist, so its twist is carried back as an angle (rad, its rate in rad/s).
Mesh forces are computed from the mesh's own law in physical units, ``kZ k(tau) g(x, eta) + cZ dx/dt``
(k(tau) the stiffness variation the run used: declared, or the formula that replaced it), and shaft torques
from the shaft's, ``kS twist + cS d(twist)/dt``, not through the scaled groups. Every conversion is
:class:`~.point.PointUnits`'s, which the start-up cache keeps.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
import sympy as sp

from ..codegen.on_arrays import numpy_program
from ..codegen.translate import to_casadi
from ..errors import GearsymError
from ..scales.dimensions import evaluate
from ..scales.map import Scaling
from ..sweep.grid import Axis
from ..model.symbols import parameter_symbol, phi, tau
from ..units import Quantity, conversion_factor, from_si, symbol
from .point import (ANGLE, ANGULAR_VELOCITY, LENGTH, LENGTH_UNIT, VELOCITY, VELOCITY_UNIT, Measured,
                    MeshUnits, PhysicalPoint, PointUnits, ShaftUnits, Unit, loads_trajectory)


def rate(scaling: Scaling, omega: float) -> float:
    """Radians per second of one unit of tau per unit time: omega * omega_n (tau = this * t)."""
    return float(omega) * scaling.omega_n_si


def kinds(scaling: Scaling) -> dict[str, str]:
    """state name -> what it is: a mesh's or a bearing's deflection (LENGTH), a shaft's twist (ANGLE), or their
    rates."""
    out = {}
    for c in scaling.model.coordinates:
        shaft = c.coupling.kind == "shaft"
        out[c.name], out[c.velocity_name] = (ANGLE, ANGULAR_VELOCITY) if shaft else (LENGTH, VELOCITY)
    return out


def _per_unit(scaling: Scaling) -> dict[str, float]:
    """state name -> the SI value of one engine unit of it: L (m) for a mesh, L over the coordinate radius (rad)
    for a shaft (a rate's is per unit tau)."""
    out = {}
    for c in scaling.model.coordinates:
        rc = c.coupling
        radius = 1.0 if rc.kind != "shaft" else evaluate(rc.scale, scaling.inputs,
                                                        f"{scaling.name}: shaft {rc.name!r} coordinate radius").si
        out[c.name] = out[c.velocity_name] = scaling.length_si / radius
    return out


def state_to_physical(scaling: Scaling, name: str, values, omega, length_unit: str = LENGTH_UNIT):
    """A state's values (numbers in the scaled units) as a quantity: a mesh's deflection in ``length_unit``, its
    rate in ``VELOCITY_UNIT``, a shaft's twist in rad and its rate in rad/s."""
    if name not in kinds(scaling):
        raise GearsymError(f"{scaling.name}: {name!r} is not a state of the model")
    return _quantity(point_units(scaling, length_unit).state(name, values, omega))


def point_to_physical(scaling: Scaling, result, length_unit: str = LENGTH_UNIT, trajectory=None,
                      model=None) -> PhysicalPoint:
    """A :class:`~gearsym.analysis.lyapunov.LyapunovSpectrum` in physical units, with the mesh forces and shaft torques
    of a trajectory at the same point: ``trajectory`` if given, else one run from the spectrum's final state on
    ``model`` (the compiled model the spectrum ran on; by default the scaling's :meth:`compiled_for` it)."""
    if trajectory is None:
        if model is None:
            model = scaling.compiled_for(result)
        _check_point(scaling, model, result)
        trajectory = loads_trajectory(model, result)
    point = point_units(scaling, length_unit).point(result, trajectory)
    return replace(point, **{f.name: _quantities(getattr(point, f.name)) for f in fields(point)})


def _check_point(scaling: Scaling, model, result) -> None:
    """The model a trajectory is run on must be the spectrum's: its parameters are the spectrum's."""
    theirs, ours = set(result.parameters), set(model.system.parameters)
    if theirs != ours:
        raise GearsymError(f"{scaling.name}: the spectrum's parameters ({', '.join(sorted(theirs))}) are not those "
                           f"of the model its mesh forces would be run on ({', '.join(sorted(ours))}): pass the "
                           "compiled model the spectrum ran on, to_physical(result, model=...)")


def _quantity(value: Measured):
    return Quantity(value.magnitude, value.units.name)


def _quantities(value):
    """:class:`~.point.Measured` values (in dicts) as pint Quantities, for a caller that converts them."""
    if isinstance(value, Measured):
        return _quantity(value)
    return {k: _quantities(v) for k, v in value.items()} if isinstance(value, dict) else value


def point_units(scaling: Scaling, length_unit: str = LENGTH_UNIT) -> PointUnits:
    """The numbers that carry a run of ``scaling`` to physical units (what the start-up cache keeps)."""
    def text(unit: str) -> Unit:
        return Unit(unit, symbol(unit))

    speed_unit = scaling.speed_unit
    return PointUnits(
        scaling.name, scaling.speed, text(speed_unit), conversion_factor("rad/s", speed_unit), scaling.omega_n_si,
        scaling.omega_n_si / (2 * np.pi), float(scaling.forcing_ratio) if scaling.speed else float("nan"),
        float(scaling.reference_mesh.order), conversion_factor("rad/s", "Hz"), scaling.length_si,
        float(from_si(scaling.length_si, length_unit)), length_unit, text(length_unit),
        conversion_factor("m", length_unit), text(VELOCITY_UNIT), conversion_factor("m/s", VELOCITY_UNIT), text("1/s"),
        text("N"), text("Hz"), text("rad"), text("rad/s"), text("N*m"), kinds(scaling), _per_unit(scaling),
        tuple(_mesh_units(scaling)), tuple(_shaft_units(scaling)), {n: q.text() for n, q in scaling.inputs.items()})


def _mesh_units(scaling: Scaling):
    """Each mesh's law in SI, with the stiffness variation k(tau) the engine integrates: the stiffness function
    of the system (declared or replaced by a formula) over the factor it carries besides the variation (1 for the
    first mesh, its relative mean stiffness K for another), at the scaling's values."""
    import casadi as ca

    nd, si = scaling.model, scaling.inputs
    values = {parameter_symbol(n): v for n, v in {**scaling.values, **scaling.formula_values}.items()}
    for f in nd.functions:
        rc = nd._mesh(f)
        where = f"{scaling.name}: mesh {rc.name!r}"
        declared = nd.stiffness_formula(f, nd.drivetrain.defaults[f.name]) if f.name in nd.drivetrain.defaults \
            else f.expression
        used = nd.stiffness_formula(f, scaling.functions[f.name]) if f.name in scaling.functions else declared
        varied = rc.variation.subs(phi, nd._mesh_phase(f))
        carried = sp.cancel(f.expression / varied)  # 1, or the relative mean stiffness K of a second mesh
        k_of_tau = (used / carried).xreplace(values)
        if k_of_tau.free_symbols - {tau}:
            missing = ", ".join(sorted(s.name for s in k_of_tau.free_symbols - {tau}))
            raise GearsymError(f"{where}: its stiffness needs a value for {missing}")
        angle = ca.SX.sym("tau")
        function = ca.Function("k", [angle], to_casadi([k_of_tau], {tau: angle}, where))
        coordinate = next(c for c in nd.coordinates if c.coupling.name == rc.name)
        yield MeshUnits(rc.name, coordinate.name, coordinate.velocity_name, evaluate(rc.stiffness, si, where).si,
                        evaluate(rc.damping, si, where).si, evaluate(rc.backlash, si, where).si, function.serialize(),
                        numpy_program(function))


def _shaft_units(scaling: Scaling):
    si = scaling.inputs
    for c in scaling.model.coordinates:
        rc = c.coupling
        if rc.kind == "mesh":
            continue
        where = f"{scaling.name}: {rc.kind} {rc.name!r}"
        yield ShaftUnits(rc.name, c.name, c.velocity_name, evaluate(rc.stiffness, si, where).si,
                         evaluate(rc.damping, si, where).si, rc.kind)


@dataclass(frozen=True)
class PhysicalTrajectory:
    """A trajectory in physical units: time in s, mesh deflections in the length unit (rates in mm/s), shaft
    twists in rad (rates in rad/s), mesh forces in N and shaft torques in N·m."""

    model: str
    time: object  # pint Quantities, for a Python user
    states: dict[str, object]
    mesh_force: dict[str, object]
    shaft_torque: dict[str, object]

    def __getitem__(self, name: str):
        return self.states[name]


def trajectory_to_physical(scaling: Scaling, trajectory, omega: float,
                           length_unit: str = LENGTH_UNIT) -> PhysicalTrajectory:
    """A :class:`~gearsym.analysis.poincare.Trajectory` (run at forcing frequency ``omega``) in physical units."""
    units = point_units(scaling, length_unit)
    seconds = np.asarray(trajectory.time, dtype=float) / rate(scaling, omega)
    states = {n: _quantity(units.state(n, trajectory[n], omega)) for n in trajectory.state_names}
    forces, torques = units.loads(trajectory, omega)
    return PhysicalTrajectory(scaling.name, Quantity(seconds, "s"), states,
                              {m: Quantity(f, "N") for m, f in forces.items()},
                              {s: Quantity(f, "N*m") for s, f in torques.items()})


def mesh_forces(scaling: Scaling, trajectory, omega: float) -> dict:
    """The force of every mesh along a trajectory, from its law in physical units (see the module's docstring)."""
    return {m: Quantity(f, "N") for m, f in point_units(scaling).mesh_forces(trajectory, omega).items()}


def speeds_of(units: PointUnits, omega) -> np.ndarray:
    """The operating speeds (in the speed's unit) of the engine's forcing frequencies ``omega``, as an array."""
    return np.atleast_1d(units.speed_of(omega))


def sweep_to_physical(scaling: Scaling, result, length_unit: str = LENGTH_UNIT, given=None):
    """A :class:`~gearsym.sweep.SweepResult` in physical units: along the physical values swept instead of the
    nondimensional parameters they moved (``given``: the physical axes, in the order of the result's, whose
    values come back as they were written; without them omega comes back as the speed, in the speed's unit),
    amplitudes and coordinates in ``length_unit`` (a shaft's twist in rad), rates in mm/s (rad/s) and exponents
    per second; ``units`` says which, and ``record["physical"]`` holds the scaling and the findings (jumps,
    hysteresis) in these units."""
    units = point_units(scaling, length_unit)
    renamed = _renamed_axes(scaling, units, result.axes, given)
    fixed_omega = float(result.record.get("parameters", {}).get("omega", scaling.values["omega"]))
    states = units.kinds

    def columns(table: dict) -> dict:
        out = {}
        w = np.asarray(table["omega"], dtype=float) if "omega" in table else fixed_omega
        for name, values in table.items():
            if name in renamed:
                physical_name, to_physical, _ = renamed[name]
                out[physical_name] = to_physical(values)
            elif name.startswith("A_"):
                out[name] = units.state(name[2:], values, 1.0).magnitude
            elif name.startswith(("lambda_", "stderr_")):
                out[name] = np.asarray(values, dtype=float) * w * units.omega_n
            elif name.startswith("final_") or name in states:
                state = name[len("final_"):] if name.startswith("final_") else name
                out[name] = units.state(state, values, w).magnitude
            else:
                out[name] = values
        return out

    axes = tuple(Axis(renamed[a.name][0], tuple(sorted(renamed[a.name][1](a.values))), a.spec,
                      renamed[a.name][2].name) if a.name in renamed else a for a in result.axes)
    shown_units = {physical_name: unit.text for physical_name, _, unit in renamed.values()}
    shown_units.update({f"A_{c}": units.unit(c).text for c in result.coordinates})
    shown_units.update({n: units.per_second.text for n in result.columns if n.startswith(("lambda_", "stderr_"))})
    for name in states:
        shown_units[name] = shown_units[f"final_{name}"] = units.unit(name).text
    findings = _findings(units, renamed, result.axes[0].name, result.findings())
    record = {**result.record, "physical": {**scaling.summary(), "units": shown_units, **findings}}
    return replace(result, axes=axes, columns=columns(result.columns), strobe=columns(result.strobe) if result.strobe
                   else result.strobe, record=record, units=shown_units)


def _renamed_axes(scaling: Scaling, units: PointUnits, axes, given) -> dict:
    """engine axis name -> (physical name, values -> physical values, Unit) for each axis that comes back as a
    physical value."""
    out = {}
    for i, axis in enumerate(axes):
        physical = given[i] if given is not None else None
        if physical is not None and physical.name != axis.name:
            back = dict(zip(axis.values, physical.values))

            def to_physical(values, back=back):
                return np.array([back[float(v)] for v in np.atleast_1d(values)], dtype=float)

            out[axis.name] = (physical.name, to_physical, Unit(physical.unit, symbol(physical.unit)))
        elif physical is None and axis.name == "omega" and scaling.speed:
            out[axis.name] = (scaling.speed.parameter, lambda values: speeds_of(units, values), units.speed_unit)
    return out


def _findings(units: PointUnits, renamed: dict, first: str, findings: dict) -> dict:
    """A sweep's jumps and hysteresis intervals (found along the engine's first parameter, amplitudes in L) along
    the physical values and in the coordinates' units."""
    def axis_values(item: dict) -> dict:
        out = {}
        for key, value in item.items():
            if key in renamed:
                out[renamed[key][0]] = float(renamed[key][1]([value])[0])
            elif key in ("from", "to") and first in renamed:
                out[key] = float(renamed[first][1]([value])[0])
            else:
                out[key] = value
        return out

    def amplitude(j: dict, key: str) -> float:
        return float(units.state(j["coordinate"], j[key], 1.0).magnitude)

    jumps = [{**axis_values(j), "A_before": amplitude(j, "A_before"), "A_after": amplitude(j, "A_after")}
             for j in findings["jumps"]]
    return {"axis": renamed[first][0] if first in renamed else first, "jumps": jumps,
            "hysteresis": [axis_values(h) for h in findings["hysteresis"]]}
