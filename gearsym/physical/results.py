"""Results of the nondimensional engine carried back to physical units by a :class:`~.scaling.Scaling`.

At a forcing frequency omega (the engine's), one unit of tau is ``1/(omega omega_n)`` seconds, one unit
of length is the scaling's L, a rate dx/dtau is ``L omega omega_n`` per second and an exponent per unit
tau is ``omega omega_n`` per second. Mesh forces are computed from the mesh's own law in physical
units, ``kZ k(phi) g(x, eta) + cZ dx/dt``, not through the scaled groups.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
import sympy as sp

from ..codegen.translate import to_casadi
from ..errors import GearsymError
from ..scales.dimensions import evaluate
from ..scales.map import Scaling
from ..sweep.grid import Axis
from ..symbols import omega as omega_symbol, phi, t
from ..units import Quantity, from_si, symbol
from .point import LENGTH_UNIT, VELOCITY_UNIT, Measured, MeshUnits, PhysicalPoint, PointUnits, Unit, contact

def rate(scaling: Scaling, omega: float) -> float:
    """Radians per second of one unit of tau per unit time: omega * omega_n (tau = this * t)."""
    return float(omega) * scaling.omega_n_si


def kinds(scaling: Scaling) -> dict[str, str]:
    """state name -> "length" (a relative coordinate) or "velocity" (its rate)."""
    out = {}
    for c in scaling.model.coordinates:
        out[c.name], out[c.velocity_name] = "length", "velocity"
    return out


def state_to_physical(scaling: Scaling, name: str, values, omega: float, length_unit: str = LENGTH_UNIT):
    """A state's values (numbers in the scaled units) as a quantity: a coordinate in ``length_unit``, a rate in
    ``VELOCITY_UNIT``."""
    kind = kinds(scaling).get(name)
    length = scaling.length_si
    if kind == "length":
        return Quantity(np.asarray(values, dtype=float) * length, "m").to(length_unit)
    if kind == "velocity":
        return Quantity(np.asarray(values, dtype=float) * length * rate(scaling, omega), "m/s").to(VELOCITY_UNIT)
    raise GearsymError(f"{scaling.name}: {name!r} is not a state of the model")


def point_to_physical(scaling: Scaling, result, length_unit: str = LENGTH_UNIT, trajectory=None) -> PhysicalPoint:
    """A :class:`~gearsym.analysis.LyapunovSpectrum` in physical units (with mesh forces from ``trajectory``,
    a :class:`~gearsym.analysis.orbits.Trajectory` at the same point, if given)."""
    point = point_units(scaling, length_unit).point(result, trajectory)
    return replace(point, **{f.name: _quantities(getattr(point, f.name)) for f in fields(point)})


def _quantities(value):
    """:class:`~.point.Measured` values (in dicts) as pint Quantities, for a caller that converts them."""
    if isinstance(value, Measured):
        return Quantity(value.magnitude, value.units.name)
    return {k: _quantities(v) for k, v in value.items()} if isinstance(value, dict) else value


def point_units(scaling: Scaling, length_unit: str = LENGTH_UNIT) -> PointUnits:
    """The numbers that carry a spectrum run of ``scaling`` to physical units (what the start-up cache keeps)."""
    def factor(source: str, target: str) -> float:
        return float(Quantity(1.0, source).to(target).magnitude)

    def text(unit: str) -> Unit:
        return Unit(unit, symbol(unit))

    speed_unit = scaling.speed_unit
    return PointUnits(
        scaling.name, scaling.speed, text(speed_unit), factor("rad/s", speed_unit), scaling.omega_n_si,
        scaling.omega_n_si / (2 * np.pi), float(scaling.forcing_ratio) if scaling.speed else float("nan"),
        float(scaling.reference_mesh.order), factor("rad/s", "Hz"), scaling.length_si,
        float(from_si(scaling.length_si, length_unit)), length_unit, text(length_unit), factor("m", length_unit),
        text(VELOCITY_UNIT), factor("m/s", VELOCITY_UNIT), factor(VELOCITY_UNIT, "m/s"), text("1/s"), text("N"), text("Hz"),
        kinds(scaling), tuple(_mesh_units(scaling)))


def _mesh_units(scaling: Scaling):
    import casadi as ca

    si = scaling.inputs
    for c in scaling.model.coordinates:
        rc = c.coupling
        if rc.kind != "mesh":
            continue
        where = f"{scaling.name}: mesh {rc.name!r}"
        variation = rc.variation.xreplace({sp.Symbol(n, real=True): q.si
                                           for n, q in scaling.inputs.items() if q.dimensionless})
        angle = ca.SX.sym("phi")
        k_of_phi = ca.Function("k", [angle], to_casadi([variation], {phi: angle}, where))
        yield MeshUnits(rc.name, c.name, c.velocity_name, evaluate(rc.stiffness, si, where).si,
                        evaluate(rc.damping, si, where).si, evaluate(rc.backlash, si, where).si,
                        evaluate(rc.mesh_phase.xreplace({omega_symbol: 0, t: 0}), si, where).si,
                        float(rc.order), k_of_phi.serialize())


@dataclass(frozen=True)
class PhysicalTrajectory:
    """A trajectory in physical units: time in s, coordinates in the length unit, rates in mm/s, forces in N."""

    model: str
    time: object  # pint Quantities, for a Python user
    states: dict[str, object]
    mesh_force: dict[str, object]

    def __getitem__(self, name: str):
        return self.states[name]


def trajectory_to_physical(scaling: Scaling, trajectory, omega: float,
                           length_unit: str = LENGTH_UNIT) -> PhysicalTrajectory:
    """A :class:`~gearsym.analysis.orbits.Trajectory` (run at forcing frequency ``omega``) in physical units."""
    seconds = np.asarray(trajectory.time, dtype=float) / rate(scaling, omega)
    states = {n: state_to_physical(scaling, n, trajectory[n], omega, length_unit) for n in trajectory.state_names}
    return PhysicalTrajectory(scaling.name, Quantity(seconds, "s"), states, mesh_forces(scaling, trajectory, omega))


def mesh_forces(scaling: Scaling, trajectory, omega: float) -> dict:
    """The force of every mesh along a trajectory, from its law in physical units:
    ``kZ k(phi) g(x, eta) + cZ dx/dt`` with phi = order tau + phase."""
    out = {}
    tau = np.asarray(trajectory.time, dtype=float)
    for c in scaling.model.coordinates:
        rc = c.coupling
        if rc.kind != "mesh":
            continue
        where = f"{scaling.name}: mesh {rc.name!r}"
        si = scaling.inputs
        stiffness = evaluate(rc.stiffness, si, where).si
        damping = evaluate(rc.damping, si, where).si
        eta = evaluate(rc.backlash, si, where).si
        variation = rc.variation.xreplace({sp.Symbol(n, real=True): q.si
                                           for n, q in scaling.inputs.items() if q.dimensionless})
        phase = evaluate(rc.mesh_phase.xreplace({omega_symbol: 0, t: 0}), si, where).si
        k_of_phi = sp.lambdify(phi, variation, "numpy")
        x = state_to_physical(scaling, c.name, trajectory[c.name], omega, "m").magnitude
        v = state_to_physical(scaling, c.velocity_name, trajectory[c.velocity_name], omega).to("m/s").magnitude
        k = np.asarray(k_of_phi(float(rc.order) * tau + phase), dtype=float) * np.ones_like(tau)
        out[rc.name] = Quantity(stiffness * k * contact(x, eta) + damping * v, "N")
    return out


def sweep_to_physical(scaling: Scaling, result, length_unit: str = LENGTH_UNIT):
    """A :class:`~gearsym.sweep.SweepResult` over omega with a speed axis instead (in the speed's unit),
    amplitudes and coordinates in ``length_unit``, rates in mm/s and exponents per second; ``units`` says
    which."""
    if result.axes[0].name != "omega":
        raise GearsymError(f"{scaling.name}: a sweep carried to physical units must run along omega first, "
                           f"not {result.axes[0].name}")
    unit = scaling.speed_unit
    speed_name = scaling.speed.parameter

    def speeds(w):
        return np.array([scaling.speed_at(v, unit).magnitude for v in np.asarray(w, dtype=float)])

    def columns(table: dict) -> dict:
        out = {}
        w = np.asarray(table["omega"], dtype=float) if "omega" in table else None
        for name, values in table.items():
            if name == "omega":
                out[speed_name] = speeds(values)
            elif name.startswith("A_"):
                out[name] = state_to_physical(scaling, name[2:], values, 1.0, length_unit).magnitude
            elif name.startswith(("lambda_", "stderr_")):
                out[name] = np.asarray(values, dtype=float) * w * scaling.omega_n_si
            elif name.startswith("final_") or name in kinds(scaling):
                state = name[len("final_"):] if name.startswith("final_") else name
                out[name] = np.asarray([state_to_physical(scaling, state, x, wi, length_unit).magnitude
                                        for x, wi in zip(values, w)], dtype=float)
            else:
                out[name] = values
        return out

    first = result.axes[0]
    axes = (Axis(speed_name, tuple(sorted(speeds(first.values))), first.spec), *result.axes[1:])
    units = {speed_name: f"{Quantity(1, unit).units:~P}"}
    units.update({f"A_{c}": f"{Quantity(1, length_unit).units:~P}" for c in result.coordinates})
    units.update({n: "1/s" for n in result.columns if n.startswith(("lambda_", "stderr_"))})
    for name, kind in kinds(scaling).items():
        units[name] = units[f"final_{name}"] = (f"{Quantity(1, length_unit).units:~P}" if kind == "length"
                                                else VELOCITY_UNIT)
    record = {**result.record, "physical": scaling.summary()}
    return replace(result, axes=axes, columns=columns(result.columns), strobe=columns(result.strobe) if result.strobe
                   else result.strobe, record=record, units=units)
