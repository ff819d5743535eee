"""Results of the nondimensional engine carried back to physical units by a :class:`~.scaling.Scaling`.

At a forcing frequency omega (the engine's), one unit of tau is ``1/(omega omega_n)`` seconds, one unit
of length is the scaling's L, a rate dx/dtau is ``L omega omega_n`` per second and an exponent per unit
tau is ``omega omega_n`` per second. Mesh forces are computed from the mesh's own law in physical
units, ``kZ k(phi) g(x, eta) + cZ dx/dt``, not through the scaled groups.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pint
import sympy as sp

from ..errors import GearsymError
from ..symbols import omega as omega_symbol, phi, t
from .scaling import Scaling, evaluate
from .units import Quantity, shown

#: the default units results are shown in
LENGTH_UNIT = "um"
VELOCITY_UNIT = "mm/s"
SPEED_UNIT = "rpm"


def rate(scaling: Scaling, omega: float) -> float:
    """Radians per second of one unit of tau per unit time: omega * omega_n (tau = this * t)."""
    return float(omega) * scaling.omega_n.magnitude


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
    length = scaling.length.to("m").magnitude
    if kind == "length":
        return Quantity(np.asarray(values, dtype=float) * length, "m").to(length_unit)
    if kind == "velocity":
        return Quantity(np.asarray(values, dtype=float) * length * rate(scaling, omega), "m/s").to(VELOCITY_UNIT)
    raise GearsymError(f"{scaling.name}: {name!r} is not a state of the model")


@dataclass(frozen=True)
class PhysicalPoint:
    """One operating point of a spectrum run, in physical units."""

    model: str
    speed: pint.Quantity
    mesh_frequency: pint.Quantity  # Hz
    natural_frequency: pint.Quantity  # omega_n in Hz
    omega: float
    exponents: pint.Quantity  # 1/s
    stderr: pint.Quantity
    amplitude: dict[str, pint.Quantity]
    final_state: dict[str, pint.Quantity]
    length_unit: pint.Quantity  # the scaling's L
    mesh_force: dict = field(default_factory=dict)  # mesh -> {"mean", "min", "max", "dynamic"} in N

    def as_dict(self) -> dict:
        """JSON-ready: every value as a number with its unit beside it."""
        def q(x):
            return {"value": _number(x.magnitude), "unit": f"{x.units:~P}"}

        out = {"model": self.model, "speed": q(self.speed), "mesh_frequency": q(self.mesh_frequency),
               "natural_frequency": q(self.natural_frequency), "omega": self.omega,
               "exponents": q(self.exponents), "stderr": q(self.stderr),
               "amplitude": {k: q(v) for k, v in self.amplitude.items()},
               "final_state": {k: q(v) for k, v in self.final_state.items()}, "length_unit": q(self.length_unit)}
        if self.mesh_force:
            out["mesh_force"] = {m: {k: q(v) for k, v in f.items()} for m, f in self.mesh_force.items()}
        return out

    def lines(self) -> list[str]:
        """The text ``gearsym lyap`` prints for a model with physical values."""
        out = [f"operating point: {shown(self.speed)}, mesh frequency {shown(self.mesh_frequency)}, "
               f"omega_n = {shown(self.natural_frequency)} (omega = {self.omega:.6g})",
               "Lyapunov exponents per second: " + ", ".join(f"{v:+.6g}" for v in self.exponents.magnitude)]
        out += [f"amplitude A_{k} = {shown(v)}" for k, v in self.amplitude.items()]
        for mesh, f in self.mesh_force.items():
            out.append(f"mesh force {mesh}: mean {shown(f['mean'])}, {shown(f['min'])} to {shown(f['max'])} "
                       f"(dynamic amplitude {shown(f['dynamic'])})")
        return out


def _number(x):
    return x.tolist() if isinstance(x, np.ndarray) else float(x)


def point_to_physical(scaling: Scaling, result, length_unit: str = LENGTH_UNIT, trajectory=None) -> PhysicalPoint:
    """A :class:`~gearsym.analysis.LyapunovSpectrum` in physical units (with mesh forces from ``trajectory``,
    a :class:`~gearsym.analysis.orbits.Trajectory` at the same point, if given)."""
    w = float(result.parameters["omega"])
    per_second = rate(scaling, w)
    forces = mesh_forces(scaling, trajectory, w) if trajectory is not None else {}
    return PhysicalPoint(
        scaling.name, scaling.speed_at(w) if scaling.speed else Quantity(float("nan"), SPEED_UNIT),
        Quantity(w * scaling.omega_n.magnitude * float(scaling.reference_mesh.order), "rad/s").to("Hz"),
        scaling.omega_n.to("Hz"), w,
        Quantity(np.asarray(result.exponents, dtype=float) * per_second, "1/s"),
        Quantity(np.asarray(result.stderr, dtype=float) * per_second, "1/s"),
        {k: state_to_physical(scaling, k, v, w, length_unit) for k, v in result.amplitude.items()},
        {k: state_to_physical(scaling, k, v, w, length_unit) for k, v in result.final_state.items()},
        scaling.length.to(length_unit), {m: _force_summary(f) for m, f in forces.items()})


def _force_summary(force: pint.Quantity) -> dict:
    values = force.to("N").magnitude
    return {"mean": Quantity(float(np.mean(values)), "N"), "min": Quantity(float(values.min()), "N"),
            "max": Quantity(float(values.max()), "N"),
            "dynamic": Quantity(float(values.max() - values.min()) / 2, "N")}


@dataclass(frozen=True)
class PhysicalTrajectory:
    """A trajectory in physical units: time in s, coordinates in the length unit, rates in mm/s, forces in N."""

    model: str
    time: pint.Quantity
    states: dict[str, pint.Quantity]
    mesh_force: dict[str, pint.Quantity]

    def __getitem__(self, name: str) -> pint.Quantity:
        return self.states[name]


def trajectory_to_physical(scaling: Scaling, trajectory, omega: float,
                           length_unit: str = LENGTH_UNIT) -> PhysicalTrajectory:
    """A :class:`~gearsym.analysis.orbits.Trajectory` (run at forcing frequency ``omega``) in physical units."""
    seconds = np.asarray(trajectory.time, dtype=float) / rate(scaling, omega)
    states = {n: state_to_physical(scaling, n, trajectory[n], omega, length_unit) for n in trajectory.state_names}
    return PhysicalTrajectory(scaling.name, Quantity(seconds, "s"), states, mesh_forces(scaling, trajectory, omega))


def mesh_forces(scaling: Scaling, trajectory, omega: float) -> dict[str, pint.Quantity]:
    """The force of every mesh along a trajectory, from its law in physical units:
    ``kZ k(phi) g(x, eta) + cZ dx/dt`` with phi = order tau + phase."""
    out = {}
    tau = np.asarray(trajectory.time, dtype=float)
    for c in scaling.model.coordinates:
        rc = c.coupling
        if rc.kind != "mesh":
            continue
        where = f"{scaling.name}: mesh {rc.name!r}"
        si = {n: q.to_base_units() for n, q in scaling.inputs.items()}
        stiffness = evaluate(rc.stiffness, si, where).to("N/m").magnitude
        damping = evaluate(rc.damping, si, where).to("N*s/m").magnitude
        eta = evaluate(rc.backlash, si, where).to("m").magnitude
        variation = rc.variation.xreplace({sp.Symbol(n, real=True): float(q.to("").magnitude)
                                           for n, q in scaling.inputs.items() if q.dimensionless})
        phase = evaluate(rc.mesh_phase.xreplace({omega_symbol: 0, t: 0}), si, where).to("").magnitude
        k_of_phi = sp.lambdify(phi, variation, "numpy")
        x = state_to_physical(scaling, c.name, trajectory[c.name], omega, "m").magnitude
        v = state_to_physical(scaling, c.velocity_name, trajectory[c.velocity_name], omega).to("m/s").magnitude
        contact = np.where(x >= 0, x, np.where(x > -eta, 0.0, x + eta))  # g(x, eta), gearsym.backlash
        k = np.asarray(k_of_phi(float(rc.order) * tau + phase), dtype=float) * np.ones_like(tau)
        out[rc.name] = Quantity(stiffness * k * contact + damping * v, "N")
    return out


def sweep_to_physical(scaling: Scaling, result, length_unit: str = LENGTH_UNIT):
    """A :class:`~gearsym.sweep.SweepResult` over omega with a speed axis instead (in the speed's unit),
    amplitudes and coordinates in ``length_unit``, rates in mm/s and exponents per second; ``units`` says
    which."""
    from ..sweep.grid import Axis

    if result.axes[0].name != "omega":
        raise GearsymError(f"{scaling.name}: a sweep carried to physical units must run along omega first, "
                           f"not {result.axes[0].name}")
    unit = str(scaling.inputs[scaling.speed.parameter].units) if scaling.speed.parameter in scaling.inputs else SPEED_UNIT
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
                out[name] = np.asarray(values, dtype=float) * w * scaling.omega_n.magnitude
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
