"""One operating point of a spectrum run in physical units, from numbers alone (no pint, no SymPy).

:func:`gearsym.physical.results.point_units` reads once, with pint, what carrying a
:class:`~gearsym.analysis.lyapunov.LyapunovSpectrum` back to physical units takes (the time unit, the length unit,
the unit conversions, each mesh's stiffness, damping, backlash and its variation k(tau) as a CasADi
function and as NumPy's instructions, each shaft's stiffness and damping); :class:`PointUnits` keeps those numbers
and does the carrying.
The mesh forces and shaft torques of a point come from a trajectory at that point (:func:`loads_trajectory`:
``FORCE_PERIODS`` forcing periods from the run's final state), whoever asks (the command line or Python). The start-up cache
(gearsym/cached.py) stores them, so that ``gearsym lyap`` on a cached model with physical values imports
neither pint (most of a second with its registry) nor SymPy.
"""
from __future__ import annotations

import math
import textwrap
from collections.abc import Callable, Mapping
from dataclasses import asdict, field, replace

import numpy as np

from ..records import record_class
from ..analysis.lyapunov import LyapunovSpectrum
from ..analysis.poincare import phase_trajectory
from ..codegen.on_arrays import evaluate_on_samples, evaluate_program, stored_program
from ..errors import GearsymError
from ..scales.speeds import Speed
from ..units import shown

#: the default units results are shown in
LENGTH_UNIT = "um"
VELOCITY_UNIT = "mm/s"
SPEED_UNIT = "rpm"
#: significant digits of a speed (or a mesh frequency) carried back from omega
SPEED_DIGITS = 12
#: forcing periods of the trajectory a point's mesh forces and shaft torques are read from (after the run's end)
FORCE_PERIODS = 20


@record_class
class Unit:
    """A unit by its name for pint (``um``) and its short symbol (``µm``, what ``f"{quantity.units:~P}"`` prints)."""

    name: str
    text: str

    def __format__(self, spec: str) -> str:
        return self.text

    def __str__(self) -> str:
        return self.text


@record_class
class Measured:
    """A number (or array) with its unit, shown as a pint Quantity is (:func:`~gearsym.units.shown`)."""

    magnitude: object
    units: Unit
    dimensionless = False


@record_class
class PhysicalPoint:
    """One operating point of a spectrum run, in physical units (pint Quantities or :class:`Measured`)."""

    model: str
    speed: object
    mesh_frequency: object  # Hz
    natural_frequency: object  # omega_n in Hz
    omega: float
    exponents: object  # 1/s
    stderr: object
    amplitude: dict  # a mesh's deflection in the length unit, a shaft's twist in rad
    final_state: dict
    length_unit: object  # the scaling's L
    mesh_force: dict = field(default_factory=dict)  # mesh -> {"mean", "min", "max", "dynamic"} in N
    shaft_torque: dict = field(default_factory=dict)  # shaft -> {"mean", "min", "max", "dynamic"} in N·m
    #: per exponent: "" (resolved) or what is known of one the run did not resolve (never its value)
    unresolved: tuple[str, ...] = ()
    bearing_force: dict = field(default_factory=dict)  # bearing direction -> {"mean", ...} in N

    def exponent_texts(self) -> list[str]:
        """Each exponent as text: its value, or what is known of it where the run did not resolve it."""
        notes = self.unresolved or ("",) * len(self.exponents.magnitude)
        return [f"{v:+.6g}" if not note else f"λ{_subscript(i + 1)} {note}"
                for i, (v, note) in enumerate(zip(self.exponents.magnitude, notes))]

    def as_dict(self) -> dict:
        """JSON-ready: every value as a number with its unit beside it."""
        def q(x):
            return {"value": _number(x.magnitude), "unit": f"{x.units:~P}"}

        out = {"model": self.model, "speed": q(self.speed), "mesh_frequency": q(self.mesh_frequency),
               "natural_frequency": q(self.natural_frequency), "omega": self.omega,
               "exponents": q(self.exponents), "stderr": q(self.stderr),
               "amplitude": {k: q(v) for k, v in self.amplitude.items()},
               "final_state": {k: q(v) for k, v in self.final_state.items()}, "length_unit": q(self.length_unit)}
        if any(self.unresolved):
            out["unresolved"] = {str(i + 1): note for i, note in enumerate(self.unresolved) if note}
        if self.mesh_force:
            out["mesh_force"] = {m: {k: q(v) for k, v in f.items()} for m, f in self.mesh_force.items()}
        if self.shaft_torque:
            out["shaft_torque"] = {m: {k: q(v) for k, v in f.items()} for m, f in self.shaft_torque.items()}
        if self.bearing_force:
            out["bearing_force"] = {m: {k: q(v) for k, v in f.items()} for m, f in self.bearing_force.items()}
        return out

    def lines(self) -> list[str]:
        """The text ``gearsym lyap`` prints for a model with physical values."""
        speed = f"{shown(self.speed)}, " if math.isfinite(float(np.asarray(self.speed.magnitude))) else ""
        out = [f"operating point: {speed}mesh frequency {shown(self.mesh_frequency)}, "
               f"omega_n = {shown(self.natural_frequency)} (omega = {self.omega:.6g})",
               "Lyapunov exponents per second: " + ", ".join(self.exponent_texts())]
        out += [f"amplitude A_{k} = {shown(v)}" for k, v in self.amplitude.items()]
        for what, table in (("mesh force", self.mesh_force), ("shaft torque", self.shaft_torque),
                            ("bearing force", self.bearing_force)):
            for name, f in table.items():
                out.append(f"{what} {name}: mean {shown(f['mean'])}, {shown(f['min'])} to {shown(f['max'])} "
                           f"(dynamic amplitude {shown(f['dynamic'])})")
        return out


def _subscript(k: int) -> str:
    """k in subscript digits (λ₁₀, not λ₁0)."""
    return str(k).translate(str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉"))


def _number(x):
    return x.tolist() if isinstance(x, np.ndarray) else float(x)


def _significant(x):
    """``x`` (a number or array) to ``SPEED_DIGITS`` significant digits."""
    values = np.asarray(x, dtype=float)
    rounded = np.array([float(f"{v:.{SPEED_DIGITS}g}") for v in values.ravel()]).reshape(values.shape)
    return rounded if values.ndim else float(rounded)


def whole_period_mean(time, values, period: float) -> float:
    """The mean of a sampled signal over the whole periods from its first sample: the trapezoidal rule, so a
    sample that ends one period and starts the next (the same phase) counts once, and for samples evenly spaced
    over a periodic signal the mean is that of one sample per phase (exact for a Fourier series of lower degree
    than the samples per period). Samples after the last whole period are left out."""
    time, values = np.asarray(time, dtype=float), np.asarray(values, dtype=float)
    span = time[-1] - time[0]
    whole = math.floor(span / period * (1 + 1e-12)) if period > 0 else 0
    if whole < 1:  # less than a period: the mean of what there is
        return float(np.trapezoid(values, time) / span) if span > 0 else float(values[0])
    end = time[0] + whole * period
    keep = time <= end + 1e-9 * period
    return float(np.trapezoid(values[keep], time[keep]) / (time[keep][-1] - time[0]))


@record_class
class MeshUnits:
    """A mesh's law in SI: force = stiffness k(tau) g(x, eta) + damping dx/dt, where k(tau) is the mesh's
    stiffness variation (declared, or the formula that replaced it) at the engine's time tau."""

    name: str
    coordinate: str
    velocity: str
    stiffness: float  # N/m
    damping: float  # N s/m
    eta: float  # m
    variation: str  # k(tau), a serialized CasADi function
    program: tuple | None  # k(tau) as NumPy's instructions (codegen.on_arrays.numpy_program); None: one has none

    @classmethod
    def from_dict(cls, d: dict) -> "MeshUnits":
        return cls(**{**d, "program": None if d["program"] is None else stored_program(d["program"])})

    def variation_at(self, tau) -> np.ndarray:
        """k(tau) at every sample of ``tau`` (all at once: :mod:`gearsym.codegen.on_arrays`; without CasADi when
        NumPy has each of its instructions)."""
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        if self.program is not None:
            return evaluate_program(self.program, tau)
        import casadi as ca

        return evaluate_on_samples(ca.Function.deserialize(self.variation), tau)

    def force(self, tau, x, v, k=None) -> np.ndarray:
        """The force in N along a trajectory (x in m, v in m/s; ``k``: :meth:`variation_at` ``tau``, if known)."""
        k = self.variation_at(tau) if k is None else k
        return self.stiffness * k * contact(x, self.eta) + self.damping * v


@record_class
class ShaftUnits:
    """A shaft's law in SI: torque = stiffness twist + damping d(twist)/dt; a bearing's (``kind`` "bearing"): its
    force = stiffness deflection + damping d(deflection)/dt (N/m and N s/m, a deflection in m)."""

    name: str
    coordinate: str
    velocity: str
    stiffness: float  # N m/rad (a bearing's N/m)
    damping: float  # N m s/rad (a bearing's N s/m)
    kind: str = "shaft"

    def torque(self, twist, rate) -> np.ndarray:
        """The torque in N·m along a trajectory (twist in rad, its rate in rad/s)."""
        return self.stiffness * np.asarray(twist, dtype=float) + self.damping * np.asarray(rate, dtype=float)


def contact(x, eta):
    """g(x, eta) of gearsym.model.backlash, on arrays."""
    return np.where(x >= 0, x, np.where(x > -eta, 0.0, x + eta))


#: what a state is physically: a mesh's deflection (a length) or a shaft's twist (an angle), or their rates
LENGTH, VELOCITY, ANGLE, ANGULAR_VELOCITY = "length", "velocity", "angle", "angular velocity"
RATES = (VELOCITY, ANGULAR_VELOCITY)


@record_class
class PointUnits:
    """The numbers that carry a run of one scaling to physical units (see the module's docstring);
    factors are pint's own (``rad_s_to_hz``: 1 rad/s in Hz), applied as pint applies them.

    A state of the engine is a number in the scaled units: a mesh's deflection in L, a shaft's coordinate
    (its coordinate radius times its twist) in L too, their rates per unit tau. ``per_unit`` gives the SI value
    of one such unit of each state (L in m for a mesh, L / radius in rad for a shaft), ``kinds`` what it is;
    a rate is then further times omega omega_n per second."""

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
    per_second: Unit
    newton: Unit
    hertz: Unit
    radian: Unit
    radian_per_second: Unit
    newton_metre: Unit
    kinds: dict  # state -> LENGTH, VELOCITY, ANGLE or ANGULAR_VELOCITY
    per_unit: dict  # state -> SI value (m or rad) of one engine unit of it (of its rate: per unit tau)
    meshes: tuple[MeshUnits, ...]
    shafts: tuple[ShaftUnits, ...] = ()
    values: dict = field(default_factory=dict)  # every physical value as the user gave it ('1.27e+08 N/m')

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "PointUnits":
        units = {k: Unit(str(d[k]["name"]), str(d[k]["text"]))
                 for k in ("speed_unit", "length_text", "velocity_text", "per_second", "newton", "hertz", "radian",
                           "radian_per_second", "newton_metre")}
        meshes = tuple(MeshUnits.from_dict(m) for m in d["meshes"])
        shafts = tuple(ShaftUnits(**m) for m in d["shafts"])
        speed = Speed(**d["speed"]) if d["speed"] else None
        return cls(**{**d, **units, "meshes": meshes, "shafts": shafts, "speed": speed,
                      "kinds": {str(k): str(v) for k, v in d["kinds"].items()},
                      "per_unit": {str(k): float(v) for k, v in d["per_unit"].items()},
                      "values": {str(k): str(v) for k, v in d["values"].items()}})

    def unit(self, name: str) -> Unit:
        """The unit a state is shown in."""
        return {LENGTH: self.length_text, VELOCITY: self.velocity_text, ANGLE: self.radian,
                ANGULAR_VELOCITY: self.radian_per_second}[self.kinds[name]]

    def state(self, name: str, values, omega, *, si: bool = False) -> Measured:
        """A state's values as a mesh deflection in the length unit (its rate in mm/s) or a shaft's twist in rad
        (its rate in rad/s); ``si``: numbers in m, m/s, rad, rad/s. ``omega`` (a number, or one per value) is
        the forcing frequency the values were run at (a rate depends on it)."""
        kind = self.kinds[name]
        value = np.asarray(values, dtype=float) * self.per_unit[name]
        if kind in RATES:
            value = value * (np.asarray(omega, dtype=float) * self.omega_n)
        if si:
            return value
        factor = {LENGTH: self.m_to_length, VELOCITY: self.m_s_to_velocity}.get(kind, 1.0)
        return Measured(value * factor, self.unit(name))

    def speed_of(self, omega) -> np.ndarray:
        """The operating speed (in its unit) at which the engine's forcing frequency is ``omega``, to
        ``SPEED_DIGITS`` significant digits: the digits of a speed the user gave survive the round trip through
        omega, its last bits (6000.000000000001 rpm) do not."""
        return _significant(np.asarray(omega, dtype=float) * self.omega_n / self.forcing_ratio * self.rad_s_to_speed)

    def point(self, result, trajectory=None) -> PhysicalPoint:
        """A :class:`~gearsym.analysis.lyapunov.LyapunovSpectrum` in physical units (with the mesh forces and shaft
        torques of ``trajectory``, a :class:`~gearsym.analysis.poincare.Trajectory` at the same point, if given)."""
        w = float(result.parameters["omega"])
        per_second = w * self.omega_n
        speed = float(self.speed_of(w)) if self.speed else float("nan")
        forces, torques = self.loads(trajectory, w) if trajectory is not None else ({}, {})
        period = float(result.period)
        time = trajectory.time if trajectory is not None else None
        return PhysicalPoint(
            self.name, Measured(speed, self.speed_unit),
            Measured(float(_significant(w * self.omega_n * self.order * self.rad_s_to_hz)), self.hertz),
            Measured(self.natural_frequency, self.hertz), w,
            Measured(np.asarray(result.exponents, dtype=float) * per_second, self.per_second),
            Measured(np.asarray(result.stderr, dtype=float) * per_second, self.per_second),
            {k: self.state(k, v, w) for k, v in result.amplitude.items()},
            {k: self.state(k, v, w) for k, v in result.final_state.items()},
            Measured(self.length_shown, self.length_text),
            {m: self._summary(time, f, period, self.newton) for m, f in forces.items()},
            {s: self._summary(time, f, period, self.newton_metre) for s, f in torques.items() if s in self._shafts},
            self._unresolved(result, per_second),
            {s: self._summary(time, f, period, self.newton) for s, f in torques.items() if s not in self._shafts})

    @property
    def _shafts(self) -> set[str]:
        return {s.name for s in self.shafts if s.kind == "shaft"}

    def _unresolved(self, result, per_second: float) -> tuple[str, ...]:
        known = getattr(result, "resolution", None)
        if known is None or known.all_resolved:
            return ()
        return tuple(known.note(i, per_second, f" {self.per_second.text}") for i in range(len(result.exponents)))

    def figure(self, result, trajectory, given: Mapping[str, str] | None = None) -> tuple:
        """A spectrum run and a trajectory at its point as a figure shows them in physical units
        (:func:`gearsym.figures.point.plot_point`): the spectrum with its exponents, their running estimates and
        its Poincaré points converted, the trajectory's states converted, the unit of each, and a title with the
        physical values as the user gave them: those of ``given`` (the values a command set) if given, else every
        one (a model's own values then go in the figure's caption file, :meth:`caption`)."""
        w = float(result.parameters["omega"])
        per_second = w * self.omega_n

        def states(names, matrix):
            return np.vstack([self.state(n, matrix[i], w).magnitude for i, n in enumerate(names)])

        spectrum = replace(result, exponents=np.asarray(result.exponents) * per_second,
                           stderr=np.asarray(result.stderr) * per_second,
                           history=np.asarray(result.history) * per_second,
                           strobe=states(tuple(result.final_state), result.strobe))  # (its keys: the states)
        converted = states(trajectory.state_names, trajectory.states)
        every = max(1, (converted.shape[1] - 1) // max(1, trajectory.strobe.shape[1] - 1))
        shown_trajectory = replace(trajectory, states=converted, strobe=converted[:, ::every])
        units = {n: self.unit(n).text for n in trajectory.state_names} | {"exponents": self.per_second.text}
        speed = self.speed.parameter if self.speed else None
        head = f"{shown(Measured(float(self.speed_of(w)), self.speed_unit))}; " if self.speed else ""
        chosen = self.values if given is None else {k: v for k, v in given.items()}
        values = ", ".join(f"{k}={v}" for k, v in chosen.items() if k != speed)
        if given is not None:
            values = (values + "; " if values else "") + "the model's other values in the caption file"
        title = (textwrap.fill(f"{self.name}: {head}{values}", 140)
                 + f"\n{result.regime}, λ₁ = {spectrum.exponents[0]:+.5g} {self.per_second.text}")
        return spectrum, shown_trajectory, units, title

    def parameters_text(self, leave_out=()) -> str:
        """Every physical value as the model or the user gave it, in one line ('speed=6000 rpm, kZ=1.27e+08 N/m'),
        but those named in ``leave_out`` (a chart's axes): how a command's text says where it ran."""
        return ", ".join(f"{k}={v}" for k, v in self.values.items() if k not in leave_out)

    def caption(self) -> str:
        """Every physical value of the point as the model or the user gave it, one a line: what a figure's title
        leaves to its caption file."""
        return "".join(f"{k} = {v}\n" for k, v in self.values.items())

    def loads(self, trajectory, omega: float) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """The force of every mesh (N) and the torque of every shaft (N·m) along a trajectory."""
        tau = np.asarray(trajectory.time, dtype=float)

        def si(name):
            return self.state(name, trajectory[name], omega, si=True)

        k = {}  # k(tau) once per variation (a planetary set's sun and ring meshes of one planet share theirs)
        for m in self.meshes:
            k[m.variation] = k[m.variation] if m.variation in k else m.variation_at(tau)
        forces = {m.name: m.force(tau, si(m.coordinate), si(m.velocity), k[m.variation]) for m in self.meshes}
        torques = {s.name: s.torque(si(s.coordinate), si(s.velocity)) for s in self.shafts}
        return forces, torques

    def mesh_forces(self, trajectory, omega: float) -> dict[str, np.ndarray]:
        """The force of every mesh along a trajectory, in N."""
        return self.loads(trajectory, omega)[0]

    @staticmethod
    def _summary(time, values: np.ndarray, period: float, unit: Unit) -> dict:
        """Mean (over whole periods), least, greatest and half the swing of a force or torque."""
        return {"mean": Measured(whole_period_mean(time, values, period), unit),
                "min": Measured(float(values.min()), unit), "max": Measured(float(values.max()), unit),
                "dynamic": Measured(float(values.max() - values.min()) / 2, unit)}


class CachedScaling:
    """A :class:`~gearsym.scales.map.Scaling` as far as a spectrum run needs it, from cached :class:`PointUnits`
    (its name, speed, units and :meth:`to_physical` of a spectrum); what else a caller needs is the full scaling's
    (:attr:`full`, made on first use: the model reduced, seconds)."""

    def __init__(self, units: PointUnits, load: Callable[[], object]):
        self.units, self._load, self.name, self.speed = units, load, units.name, units.speed

    @property
    def full(self):
        if "_full" not in self.__dict__:
            self.__dict__["_full"] = self._load()
        return self.__dict__["_full"]

    def to_physical(self, result, length_unit: str = LENGTH_UNIT, *, trajectory=None, model=None, **options):
        """A spectrum run from the cached numbers (its loads from ``trajectory``, or one run on ``model``);
        anything else by the full scaling's ``to_physical``."""
        if isinstance(result, LyapunovSpectrum) and length_unit == self.units.length_unit and not options:
            if trajectory is None and model is not None:
                trajectory = loads_trajectory(model, result)
            return self.units.point(result, trajectory)
        given = {k: v for k, v in (("trajectory", trajectory), ("model", model)) if v is not None}
        return self.full.to_physical(result, length_unit, **given, **options)

    def point_units(self, length_unit: str = LENGTH_UNIT) -> PointUnits:
        return self.units if length_unit == self.units.length_unit else self.full.point_units(length_unit)


def loads_trajectory(model, result):
    """The trajectory a spectrum run's mesh forces and shaft torques are read from: ``FORCE_PERIODS`` periods of
    ``model`` (the compiled model the run was made on) from the run's final state, at the run's parameters."""
    if result.steps_per_period != model.steps_per_period:
        raise GearsymError(f"{model.name}: the spectrum ran with {result.steps_per_period} steps per period, the "
                           f"model given integrates with {model.steps_per_period}: give the compiled "
                           "model the spectrum ran on")
    options = model.integration.run(periods=FORCE_PERIODS, discard=0)
    return phase_trajectory(model, options=options, y0=result.final_state, **result.parameters)
