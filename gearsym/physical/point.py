"""One operating point of a spectrum run in physical units, from numbers alone (no pint, no SymPy).

:func:`gearsym.physical.results.point_units` reads once, with pint, what carrying a
:class:`~gearsym.analysis.LyapunovSpectrum` back to physical units takes (the time unit, the length unit,
the unit conversions, each mesh's stiffness, damping, backlash and its variation k(phi) as a CasADi
function); :class:`PointUnits` keeps those numbers and does the carrying. The start-up cache
(gearsym/cached.py) stores them, so that ``gearsym lyap`` on a cached model with physical values imports
neither pint (most of a second with its registry) nor SymPy.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from ..scales.speeds import Speed
from ..units import shown

#: the default units results are shown in
LENGTH_UNIT = "um"
VELOCITY_UNIT = "mm/s"
SPEED_UNIT = "rpm"


@dataclass(frozen=True)
class Unit:
    """A unit by its name for pint (``um``) and its short symbol (``µm``, what ``f"{quantity.units:~P}"`` prints)."""

    name: str
    text: str

    def __format__(self, spec: str) -> str:
        return self.text

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class Measured:
    """A number (or array) with its unit, shown as a pint Quantity is (:func:`~gearsym.physical.text.shown`)."""

    magnitude: object
    units: Unit
    dimensionless = False


@dataclass(frozen=True)
class PhysicalPoint:
    """One operating point of a spectrum run, in physical units (pint Quantities or :class:`Measured`)."""

    model: str
    speed: object
    mesh_frequency: object  # Hz
    natural_frequency: object  # omega_n in Hz
    omega: float
    exponents: object  # 1/s
    stderr: object
    amplitude: dict
    final_state: dict
    length_unit: object  # the scaling's L
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


@dataclass(frozen=True)
class MeshUnits:
    """A mesh's law in SI: force = stiffness k(order tau + phase) g(x, eta) + damping dx/dt."""

    name: str
    coordinate: str
    velocity: str
    stiffness: float  # N/m
    damping: float  # N s/m
    eta: float  # m
    phase: float
    order: float
    variation: str  # k(phi), a serialized CasADi function

    def force(self, tau, x, v) -> np.ndarray:
        """The force in N along a trajectory (x in m, v in m/s)."""
        import casadi as ca

        phases = np.atleast_1d(self.order * tau + self.phase)
        k_of_phi = ca.Function.deserialize(self.variation).map(phases.size)
        k = np.asarray(k_of_phi(phases.reshape(1, -1)), dtype=float).reshape(phases.shape) * np.ones_like(tau)
        return self.stiffness * k * contact(x, self.eta) + self.damping * v


def contact(x, eta):
    """g(x, eta) of gearsym.backlash, on arrays."""
    return np.where(x >= 0, x, np.where(x > -eta, 0.0, x + eta))


@dataclass(frozen=True)
class PointUnits:
    """The numbers that carry a spectrum run of one scaling to physical units (see the module's docstring);
    factors are pint's own (``rad_s_to_hz``: 1 rad/s in Hz), applied as pint applies them."""

    name: str
    speed: Speed | None  # (None: no body declares the operating speed)
    speed_unit: Unit
    rad_s_to_speed: float
    omega_n: float  # rad/s
    natural_frequency: float  # Hz
    forcing_ratio: float
    order: float  # of the reference mesh
    rad_s_to_hz: float
    length: float  # L in m
    length_shown: float  # L in the length unit
    length_unit: str
    length_text: Unit
    m_to_length: float
    velocity_text: Unit
    m_s_to_velocity: float
    velocity_to_m_s: float
    per_second: Unit
    newton: Unit
    hertz: Unit
    kinds: dict  # state -> "length" or "velocity"
    meshes: tuple[MeshUnits, ...]

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "PointUnits":
        units = {k: Unit(str(d[k]["name"]), str(d[k]["text"])) for k in ("speed_unit", "length_text", "velocity_text", "per_second",
                                                        "newton", "hertz")}
        meshes = tuple(MeshUnits(**m) for m in d["meshes"])
        speed = Speed(**d["speed"]) if d["speed"] else None
        return cls(**{**d, **units, "meshes": meshes, "speed": speed, "kinds": {str(k): str(v) for k, v in d["kinds"].items()}})

    def state(self, name: str, values, omega: float, *, si: bool = False) -> Measured:
        """A state's values as a coordinate in the length unit or a rate in mm/s (``si``: numbers in m, m/s)."""
        kind = self.kinds[name]
        if kind == "length":
            metres = np.asarray(values, dtype=float) * self.length
            return metres if si else Measured(metres * self.m_to_length, self.length_text)
        rate = np.asarray(values, dtype=float) * self.length * (float(omega) * self.omega_n)
        return rate * self.m_s_to_velocity * self.velocity_to_m_s if si else Measured(rate * self.m_s_to_velocity,
                                                                                     self.velocity_text)

    def point(self, result, trajectory=None) -> PhysicalPoint:
        """A :class:`~gearsym.analysis.LyapunovSpectrum` in physical units (with the mesh forces of
        ``trajectory``, a :class:`~gearsym.analysis.orbits.Trajectory` at the same point, if given)."""
        w = float(result.parameters["omega"])
        per_second = w * self.omega_n
        speed = (w * self.omega_n / self.forcing_ratio * self.rad_s_to_speed) if self.speed else float("nan")
        forces = self.mesh_forces(trajectory, w) if trajectory is not None else {}
        return PhysicalPoint(
            self.name, Measured(speed, self.speed_unit),
            Measured(w * self.omega_n * self.order * self.rad_s_to_hz, self.hertz),
            Measured(self.natural_frequency, self.hertz), w,
            Measured(np.asarray(result.exponents, dtype=float) * per_second, self.per_second),
            Measured(np.asarray(result.stderr, dtype=float) * per_second, self.per_second),
            {k: self.state(k, v, w) for k, v in result.amplitude.items()},
            {k: self.state(k, v, w) for k, v in result.final_state.items()},
            Measured(self.length_shown, self.length_text), {m: self._force_summary(f) for m, f in forces.items()})

    def mesh_forces(self, trajectory, omega: float) -> dict[str, np.ndarray]:
        """The force of every mesh along a trajectory, in N."""
        tau = np.asarray(trajectory.time, dtype=float)
        return {m.name: m.force(tau, self.state(m.coordinate, trajectory[m.coordinate], omega, si=True),
                                self.state(m.velocity, trajectory[m.velocity], omega, si=True))
                for m in self.meshes}

    def _force_summary(self, values: np.ndarray) -> dict:
        return {"mean": Measured(float(np.mean(values)), self.newton),
                "min": Measured(float(values.min()), self.newton), "max": Measured(float(values.max()), self.newton),
                "dynamic": Measured(float(values.max() - values.min()) / 2, self.newton)}


class CachedScaling:
    """A :class:`~gearsym.scales.map.Scaling` as far as a spectrum run needs it, from cached :class:`PointUnits`;
    anything else comes from the full scaling, made on first use (the model reduced: seconds)."""

    def __init__(self, units: PointUnits, load: Callable[[], object]):
        self.units, self._load, self.name, self.speed = units, load, units.name, units.speed

    @property
    def full(self):
        if "_full" not in self.__dict__:
            self.__dict__["_full"] = self._load()
        return self.__dict__["_full"]

    def to_physical(self, result, length_unit: str = LENGTH_UNIT, *, omega: float | None = None, trajectory=None):
        if hasattr(result, "exponents") and length_unit == self.units.length_unit:
            return self.units.point(result, trajectory)
        return self.full.to_physical(result, length_unit, omega=omega, trajectory=trajectory)

    def __getattr__(self, name: str):
        if name.startswith("__") or name in ("_full", "_load", "units"):
            raise AttributeError(name)
        return getattr(self.full, name)
