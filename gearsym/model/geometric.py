"""Gears and meshes declared from their geometry: what a :class:`~gearsym.geometry.GearGeometry` gives the model.

A gear declared from its geometry (``Gear.from_geometry``) gives its inertia (the disk with its bore,
:attr:`GearGeometry.polar_inertia`), its base radius and its tooth count; a mesh between two such gears
(``Mesh.from_gears``) computes the pair's stiffness over one mesh period by the potential-energy method
(:func:`gearsym.geometry.mesh_stiffness`) and enters it as its mean (the physical value of the mesh's stiffness
parameter, N/m) times a Fourier series of the mesh phase (the mesh's variation, of mean 1). The series is the
stiffness's own exact Fourier coefficients to a declared order, with Lanczos's sigma factors (as gearsym's
default rectangular wave has them): see :data:`GEOMETRY_HARMONICS` for the order and why.

Quantities with units are read here, at the edge (``module="3.175 mm"``, ``pressure_angle="20 deg"``, or pint
Quantities); the geometry below works in SI floats.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

from ..errors import GearsymError, ModelError
from ..geometry import GearGeometry, MeshStiffness, StiffnessOptions, gear_pair, mesh_stiffness
from .symbols import phi
from ..units import Measure, measure

#: harmonics of the computed stiffness a mesh from geometry keeps unless told. Seven, as gearsym's default
#: rectangular wave: (1) smooth in time and resolved by the integrator: at the default 200 RK4 steps per forcing
#: period the 7th mesh harmonic gets 28 steps per cycle (RK4's error per step ~ (2 pi/28)^5 / 120, 5e-6),
#: the 15th would get 13; (2) with Lanczos's sigma factors the series has no Gibbs overshoot: for the NASA
#: rig pair it stays inside the curve's own minimum and maximum (0.658-1.207 of the mean), where the plain
#: truncated series over- and undershoots by up to 4 % of the mean at the jumps between single and double contact;
#: (3) the harmonics above the 7th carry under 1 % of the variation's power each (5 % together for the NASA pair),
#: and they excite resonances only at speeds below 1/8 of the main one.
GEOMETRY_HARMONICS = 7
#: significant digits of the computed mean and Fourier coefficients written into the model: the generated code
#: must be the same on every machine, and the last bits of a numpy sum are not (1e-10 is far below the
#: method's own accuracy, tens of per cent in the mean)
DIGITS = 10


@dataclass(frozen=True)
class _Kind:
    """The kind of a dimensional value of a gear's geometry: its exponents of mass, length, time and an example."""

    what: str
    dims: tuple[float, float, float]
    example: str

    def si(self, value, name: str, where: str) -> float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            if value == 0:  # zero is zero in every unit: a solid gear, a spur gear
                return 0.0
            raise ModelError(f"{name}={value!r} has no unit, and {self.what} needs one: write "
                             f"{name}='{value:g} {self.example.split()[1]}' (or pass a GearGeometry in SI)", where)
        try:
            m = measure(value, f"{where}: {name}")
        except GearsymError as exc:
            raise ModelError(str(exc)) from None
        if m.dims != self.dims or not m.unit:
            raise ModelError(f"{name}={m.text()} is not {self.what}; write e.g. {name}='{self.example}'", where)
        return m.si


_LENGTH = _Kind("a length", (0.0, 1.0, 0.0), "3.175 mm")
_ANGLE = _Kind("an angle", (0.0, 0.0, 0.0), "20 deg")
#: the dimensional arguments of a gear's geometry; the others (teeth, profile_shift, the rack's coefficients,
#: material) are plain numbers or a Material, passed on as they are
KINDS = {"module": _LENGTH, "face_width": _LENGTH, "bore_diameter": _LENGTH, "pressure_angle": _ANGLE,
         "helix_angle": _ANGLE}
PLAIN = ("teeth", "profile_shift", "addendum_coefficient", "dedendum_coefficient", "fillet_coefficient", "material")


def geometry_from(where: str, geometry: GearGeometry | None, dimensions: dict) -> GearGeometry:
    """The :class:`GearGeometry` given, or the one ``dimensions`` (quantities with units) describe."""
    if geometry is not None:
        if dimensions:
            raise ModelError(f"give a GearGeometry or its dimensions ({', '.join(dimensions)}), not both", where)
        if not isinstance(geometry, GearGeometry):
            raise ModelError(f"expected a GearGeometry, got {type(geometry).__name__}; or give its dimensions "
                             "(teeth=28, module='3.175 mm', pressure_angle='20 deg', face_width='6.35 mm')", where)
        return geometry
    unknown = sorted(set(dimensions) - set(KINDS) - set(PLAIN))
    if unknown:
        raise ModelError(f"unknown gear dimension {', '.join(unknown)}; a gear takes {', '.join((*KINDS, *PLAIN))}",
                         where)
    missing = [name for name in ("teeth", "module", "pressure_angle", "face_width") if name not in dimensions]
    if missing:
        raise ModelError(f"a gear from its geometry needs {', '.join(missing)} (e.g. teeth=28, module='3.175 mm', "
                         "pressure_angle='20 deg', face_width='6.35 mm')", where)
    values = {name: KINDS[name].si(value, name, where) if name in KINDS else value for name, value in dimensions.items()}
    try:
        return GearGeometry(**values)
    except GearsymError as exc:
        raise ModelError(str(exc), where) from None


def body_values(geometry: GearGeometry, inertia: str, base_radius: str, mass: str | None = None) -> dict[str, Measure]:
    """The physical values a gear from its geometry gives: its inertia (kg m^2) and base radius (mm), and its mass
    (kg) when it has a mass parameter (a gear on a bearing)."""
    out = {inertia: measure(f"{geometry.polar_inertia:.{DIGITS}g} kg*m^2", inertia),
           base_radius: measure(f"{geometry.base_radius * 1e3:.{DIGITS}g} mm", base_radius)}
    if mass is not None:
        out[mass] = measure(f"{geometry.mass:.{DIGITS}g} kg", mass)
    return out


def check_harmonics(harmonics, where: str | None) -> None:
    if isinstance(harmonics, bool) or not isinstance(harmonics, int) or not 1 <= harmonics <= 100:
        raise ModelError(f"harmonics must be a whole number from 1 to 100, got {harmonics!r} (the default "
                         f"{GEOMETRY_HARMONICS} keeps the series smooth; see docs/geometry.md)", where)


def sigma_factors(harmonics: int) -> list[float]:
    """Lanczos's sigma factors sinc(n / (N + 1)), n = 1 ... N: the smoothing of the truncated series."""
    return [math.sin(math.pi * n / (harmonics + 1)) / (math.pi * n / (harmonics + 1)) for n in range(1, harmonics + 1)]


@dataclass(frozen=True)
class ComputedStiffness:
    """A mesh's stiffness computed from its gears' geometry, as the model takes it: ``curve`` (the pair's
    :class:`~gearsym.geometry.MeshStiffness`, N/m over one mesh period), kept to ``harmonics`` Fourier terms,
    with Lanczos's sigma factors if ``smoothed``."""

    curve: MeshStiffness
    harmonics: int = GEOMETRY_HARMONICS
    smoothed: bool = True

    def __post_init__(self):
        check_harmonics(self.harmonics, None)

    @property
    def mean(self) -> float:
        """The mean stiffness the model takes, N/m (to :data:`DIGITS` digits)."""
        return float(f"{self.curve.mean:.{DIGITS}g}")

    def coefficients(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The model's cosine and sine coefficients of k / mean, n = 1 ... harmonics: the curve's exact Fourier
        coefficients times the sigma factors (if smoothed), to :data:`DIGITS` digits."""
        series = self.curve.fourier(self.harmonics)
        factors = sigma_factors(self.harmonics) if self.smoothed else [1.0] * self.harmonics
        return (tuple(float(f"{a * s:.{DIGITS}g}") for a, s in zip(series.cos, factors)),
                tuple(float(f"{b * s:.{DIGITS}g}") for b, s in zip(series.sin, factors)))

    def variation(self, variable: sp.Symbol = phi) -> sp.Expr:
        """``1 + sum_n a_n cos(n phi) + b_n sin(n phi)``, the mesh's variation of mean 1."""
        wave = sp.S.One
        for n, (a, b) in enumerate(zip(*self.coefficients()), start=1):
            for coefficient, term in ((a, sp.cos(n * variable)), (b, sp.sin(n * variable))):
                if abs(coefficient) >= 1e-12:  # a term the symmetry of the pair cancels (to rounding)
                    wave += sp.Float(repr(coefficient)) * term
        return wave

    def values(self, name: str) -> dict[str, Measure]:
        """The physical value of the mesh stiffness parameter ``name``: the mean in N/m."""
        return {name: measure(f"{self.mean!r} N/m", name)}

    def describe(self) -> str:
        """One line: the pair, its contact ratio, the mean and extremes, the series."""
        c = self.curve
        smoothing = " with Lanczos factors" if self.smoothed else " (plain truncation)"
        return (f"{c.pair.describe()}: contact ratio {c.contact_ratio:.4f}, mean {self.mean:.6g} N/m "
                f"(min {c.min / c.mean:.3f}, max {c.max / c.mean:.3f} of it), {self.harmonics} Fourier "
                f"harmonics{smoothing}")


def computed_stiffness(where: str, geometry_a: GearGeometry | None, geometry_b: GearGeometry | None,
                       names: tuple[str, str], options: StiffnessOptions | None, centre_distance, harmonics: int,
                       smoothed: bool) -> ComputedStiffness:
    """The pair's stiffness (gear a drives) as the model takes it; one line if either gear has no geometry."""
    for geometry, name in zip((geometry_a, geometry_b), names):
        if geometry is None:
            raise ModelError(f"meshes with {name!r}, which was not declared from its geometry: declare it with "
                             "Gear.from_geometry(...), or give this Mesh its stiffness and variation", where)
    check_harmonics(harmonics, where)
    distance = None if centre_distance is None else KINDS["module"].si(centre_distance, "centre_distance", where)
    try:
        curve = mesh_stiffness(gear_pair(geometry_a, geometry_b, distance), options)
    except GearsymError as exc:
        raise ModelError(str(exc), where) from None
    return ComputedStiffness(curve, harmonics, smoothed)
