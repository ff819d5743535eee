"""One cylindrical involute gear from its geometry: module, teeth, pressure angle, face width and the rest.

Everything is in SI units (m, rad, kg); conversions from a user's units happen at the edge (the command line,
the face functions). Names and formulas follow ISO 21771 (cylindrical involute gears: geometry) and ISO 53
(the basic rack): the normal module m_n and pressure angle alpha_n are the basic rack's, the transverse
section (the plane the torsional model lives in) has m_t = m_n / cos(beta) and
tan(alpha_t) = tan(alpha_n) / cos(beta).

The gear body, for its mass and polar moment of inertia, is the disk ISO 6336-1 takes for the reduced mass of
a gear pair (its clause on the resonance speed, m_red): a cylinder of the mean diameter
d_m = (d_a + d_f) / 2 with the bore d_i removed, over the face width.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

from ..checks import whole_number
from ..errors import GearsymError, warn
from .material import STEEL, Material
from .profile import ToothProfile

#: fewer teeth than this make no working involute gear (undercut removes most of the flank)
MIN_TEETH = 6
#: more teeth than this are a rack in all but name (and the sizes of the arrays grow with them)
MAX_TEETH = 10000
#: the pressure angles of the basic racks in use (ISO 53: 20 deg; older 14.5 deg; high 25-30 deg)
PRESSURE_ANGLE_RANGE = (math.radians(10.0), math.radians(35.0))
#: the thinnest rim under the teeth, in tooth heights: ISO 6336-3's rim thickness factor Y_B covers s_R / h_t >= 0.5
MIN_RIM = 0.5
#: helix angles beyond this are not cylindrical gears for power transmission
MAX_HELIX_ANGLE = math.radians(45.0)
#: a tip thinner than this (in modules) is warned about: ISO 21771 / common practice ask s_a >= 0.2-0.4 m_n
THIN_TIP = 0.2
#: ISO 53 profile A's tool tip rounding rho_fP / m_n: the default wherever it fits (a 20 deg rack; not above ~22.6 deg)
ISO53_FILLET = 0.38


def involute(angle):
    """inv(alpha) = tan(alpha) - alpha."""
    return math.tan(angle) - angle


def largest_fillet_coefficient(pressure_angle: float, dedendum_coefficient: float) -> float:
    """The largest rho_fP / m_n whose two roundings fit on the tool's tip, of width pi/2 - 2 h_fP tan(alpha) (in
    modules), where they meet at its middle (a full-round tip)."""
    alpha = pressure_angle
    return (0.25 * math.pi - dedendum_coefficient * math.tan(alpha)) * math.cos(alpha) / (1.0 - math.sin(alpha))


def largest_dedendum(pressure_angle: float) -> float:
    """The dedendum coefficient h_fP / m_n at which the tool's flanks meet at its tip: pi / (4 tan(alpha))."""
    return 0.25 * math.pi / math.tan(pressure_angle)


def default_fillet_coefficient(pressure_angle: float, dedendum_coefficient: float) -> float:
    """The tool tip's rounding of the default rack: ISO 53 profile A's 0.38 where it fits, else the largest that
    fits (a full-round tip; ISO 53 has no rack of 25 deg, whose largest rounding is 0.318)."""
    return min(ISO53_FILLET, largest_fillet_coefficient(pressure_angle, dedendum_coefficient))


def _finite(value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise GearsymError(f"{what} must be a finite number, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class GearGeometry:
    """A cylindrical involute gear cut by a rack (ISO 53 basic rack with a rounded tip).

    * ``teeth``: the number of teeth z.
    * ``module``: the normal module m_n (m).
    * ``pressure_angle``: the normal pressure angle alpha_n of the basic rack (rad).
    * ``face_width``: b (m).
    * ``profile_shift``: the profile shift coefficient x (in modules, positive away from the centre).
    * ``helix_angle``: beta at the reference cylinder (rad; its sign is the hand, its size counts here).
    * ``addendum_coefficient``: h_aP / m_n of the basic rack, the gear's addendum (1.0).
    * ``dedendum_coefficient``: h_fP / m_n, the gear's dedendum and the tool's addendum (1.25).
    * ``fillet_coefficient``: rho_fP / m_n, the radius of the tool tip's rounding, which cuts the root
      fillet (0.38: ISO 53 profile A; B has 0.30, C 0.25, D 0.39 with a dedendum of 1.4). By default ISO 53's
      0.38 where it fits on the tool's tip, else the largest that fits (a full-round tip: 0.318 on a 25 deg
      rack, which ISO 53 does not cover): :func:`default_fillet_coefficient`.
    * ``bore_diameter``: d_i (m); 0 for a solid gear.
    * ``material``: :class:`Material` (steel by default).
    """

    teeth: int
    module: float
    pressure_angle: float
    face_width: float
    profile_shift: float = 0.0
    helix_angle: float = 0.0
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25
    fillet_coefficient: float | None = None
    bore_diameter: float = 0.0
    material: Material = field(default=STEEL)

    def __post_init__(self):
        z = whole_number(self.teeth, "gear: teeth", MIN_TEETH)
        if z > MAX_TEETH:
            raise GearsymError(f"gear: {z} teeth is more than the {MAX_TEETH} this model takes (a rack, in effect)")
        object.__setattr__(self, "teeth", z)
        for name, what in (("module", "gear: module (m)"), ("pressure_angle", "gear: pressure angle (rad)"),
                           ("face_width", "gear: face width (m)"), ("profile_shift", "gear: profile shift coefficient"),
                           ("helix_angle", "gear: helix angle (rad)"),
                           ("addendum_coefficient", "gear: addendum coefficient"),
                           ("dedendum_coefficient", "gear: dedendum coefficient"),
                           ("fillet_coefficient", "gear: fillet radius coefficient"),
                           ("bore_diameter", "gear: bore diameter (m)")):
            if getattr(self, name) is not None or name != "fillet_coefficient":
                object.__setattr__(self, name, _finite(getattr(self, name), what))
        if not isinstance(self.material, Material):
            raise GearsymError(f"gear: material must be a Material(E, nu, rho), got {type(self.material).__name__}")
        if self.module <= 0:
            raise GearsymError(f"gear: the module must be positive (in m), got {self.module:g}")
        if self.module > 1.0:
            raise GearsymError(f"gear: a module of {self.module:g} m is not a gear's; the module is in metres here "
                               f"(3 mm is 0.003)")
        if self.face_width <= 0:
            raise GearsymError(f"gear: the face width must be positive (in m), got {self.face_width:g}")
        low, high = PRESSURE_ANGLE_RANGE
        if not low <= self.pressure_angle <= high:
            raise GearsymError(f"gear: pressure angle {self.pressure_angle:g} rad ({math.degrees(self.pressure_angle):.4g} "
                               f"deg) is outside {math.degrees(low):g}-{math.degrees(high):g} deg; angles are in "
                               f"radians here (20 deg is 0.349)")
        if abs(self.helix_angle) >= MAX_HELIX_ANGLE:
            raise GearsymError(f"gear: helix angle {math.degrees(self.helix_angle):.4g} deg must be less than "
                               f"{math.degrees(MAX_HELIX_ANGLE):g} deg in size; angles are in radians here")
        if not 0.5 <= self.addendum_coefficient <= 2.0:
            raise GearsymError(f"gear: addendum coefficient {self.addendum_coefficient:g} must lie in 0.5-2 "
                               "(1.0 for ISO 53's basic rack)")
        if not self.addendum_coefficient < self.dedendum_coefficient <= 2.5:
            raise GearsymError(f"gear: dedendum coefficient {self.dedendum_coefficient:g} must exceed the addendum "
                               f"coefficient {self.addendum_coefficient:g} (a tip clearance) and be at most 2.5 "
                               "(1.25 for ISO 53's basic rack)")
        deepest = largest_dedendum(self.pressure_angle)
        if self.dedendum_coefficient >= deepest:
            raise GearsymError(f"gear: dedendum coefficient {self.dedendum_coefficient:g} is too deep for a "
                               f"{math.degrees(self.pressure_angle):.4g} deg rack: the tool's flanks meet before its "
                               f"tip (keep it below {deepest:.3g}, or take a smaller pressure angle)")
        if self.fillet_coefficient is None:
            object.__setattr__(self, "fillet_coefficient",
                               default_fillet_coefficient(self.pressure_angle, self.dedendum_coefficient))
        if self.root_radius <= 0:
            raise GearsymError(f"gear: the root circle has no radius ({self.root_radius:g} m): {self.teeth} teeth are "
                               "too few for this dedendum and profile shift")
        fillet_max = self.largest_fillet_coefficient
        if not 0.0 <= self.fillet_coefficient <= fillet_max:
            raise GearsymError(f"gear: fillet radius coefficient {self.fillet_coefficient:g} must lie in 0-{fillet_max:.3f} "
                               f"on a {math.degrees(self.pressure_angle):.4g} deg rack of dedendum "
                               f"{self.dedendum_coefficient:g}: the tool tip's roundings must fit on its tip "
                               f"({ISO53_FILLET} is ISO 53's profile A, a 20 deg rack; leave it out for the default)")
        if self.dedendum_coefficient - self.profile_shift - self.fillet_coefficient < 0:
            raise GearsymError(f"gear: profile shift {self.profile_shift:g} is too large for this basic rack: the tool "
                               "tip's rounding would lie above the generating line (keep x below "
                               f"{self.dedendum_coefficient - self.fillet_coefficient:.3g})")
        if self.bore_diameter < 0:
            raise GearsymError(f"gear: the bore diameter must be 0 (solid) or positive, got {self.bore_diameter:g}")
        if self.bore_diameter >= 2.0 * self.root_radius:
            raise GearsymError(f"gear: the bore ({self.bore_diameter * 1e3:.4g} mm) is not smaller than the root "
                               f"circle ({2e3 * self.root_radius:.4g} mm): nothing would carry the teeth")
        rim, height = self.root_radius - self.bore_diameter / 2, self.tip_radius - self.root_radius
        if self.bore_diameter and rim < MIN_RIM * height:
            raise GearsymError(f"gear ({self.teeth} teeth): the bore ({self.bore_diameter * 1e3:.4g} mm) leaves a rim "
                               f"of {rim * 1e3:.3g} mm under the teeth, less than {MIN_RIM:g} of their height "
                               f"({height * 1e3:.3g} mm; ISO 6336-3's rim factor ends there): such a rim bends as a "
                               f"ring, which no formula here holds; give a bore of at most "
                               f"{2e3 * (self.root_radius - MIN_RIM * height):.4g} mm")
        if self.tip_thickness <= 0:
            raise GearsymError(f"gear: the teeth come to a point below the tip circle ({self.teeth} teeth, profile shift "
                               f"{self.profile_shift:g}): lower the profile shift or the addendum")
        if self.tip_thickness < THIN_TIP * self.module:
            warn(f"gear ({self.teeth} teeth, x = {self.profile_shift:g}): the tip is {self.tip_thickness / self.module:.2f} "
                 f"modules thick, less than the {THIN_TIP} ISO 21771 asks; lower the profile shift or the addendum")
        if self.profile.undercut:
            warn(f"gear ({self.teeth} teeth, x = {self.profile_shift:g}): the tooth is undercut (the involute starts at "
                 f"the diameter {self.profile.form_radius * 2e3:.4g} mm, the base circle is {self.base_radius * 2e3:.4g} mm); a profile shift of at least "
                 f"{self.undercut_free_shift:.3g} avoids it. The stiffness is computed on the undercut tooth")

    # -- the transverse section -------------------------------------------------------------------------

    @property
    def transverse_module(self) -> float:
        """m_t = m_n / cos(beta) (m)."""
        return self.module / math.cos(self.helix_angle)

    @property
    def transverse_pressure_angle(self) -> float:
        """alpha_t, with tan(alpha_t) = tan(alpha_n) / cos(beta) (rad)."""
        return math.atan(math.tan(self.pressure_angle) / math.cos(self.helix_angle))

    @property
    def base_helix_angle(self) -> float:
        """beta_b, with tan(beta_b) = tan(beta) cos(alpha_t) (rad, its size)."""
        return math.atan(math.tan(abs(self.helix_angle)) * math.cos(self.transverse_pressure_angle))

    @property
    def reference_radius(self) -> float:
        """r = m_t z / 2, the pitch radius of the generating rack (m)."""
        return 0.5 * self.transverse_module * self.teeth

    @property
    def base_radius(self) -> float:
        """r_b = r cos(alpha_t) (m)."""
        return self.reference_radius * math.cos(self.transverse_pressure_angle)

    @property
    def tip_radius(self) -> float:
        """r_a = r + m_n (h_aP* + x) (m)."""
        return self.reference_radius + self.module * (self.addendum_coefficient + self.profile_shift)

    @property
    def root_radius(self) -> float:
        """r_f = r - m_n (h_fP* - x) (m)."""
        return self.reference_radius - self.module * (self.dedendum_coefficient - self.profile_shift)

    @property
    def base_pitch(self) -> float:
        """The transverse base pitch p_bt = 2 pi r_b / z = pi m_t cos(alpha_t) (m)."""
        return 2.0 * math.pi * self.base_radius / self.teeth

    @property
    def normal_base_pitch(self) -> float:
        """p_bn = pi m_n cos(alpha_n) (m)."""
        return math.pi * self.module * math.cos(self.pressure_angle)

    @property
    def virtual_teeth(self) -> float:
        """The virtual number of teeth z_n = z / (cos^2(beta_b) cos(beta)) of ISO 6336-1."""
        return self.teeth / (math.cos(self.base_helix_angle) ** 2 * math.cos(self.helix_angle))

    @property
    def half_base_angle(self) -> float:
        """psi_b: half the tooth's angular thickness at the base circle, (pi/2 + 2 x tan(alpha_n)) / z + inv(alpha_t)."""
        return ((0.5 * math.pi + 2.0 * self.profile_shift * math.tan(self.pressure_angle)) / self.teeth
                + involute(self.transverse_pressure_angle))

    @property
    def tip_thickness(self) -> float:
        """The tooth's normal thickness on the tip circle (arc length, m): 2 r_a (psi_b - inv(alpha_a)) cos(beta_a)."""
        alpha_a = math.acos(self.base_radius / self.tip_radius)
        transverse = 2.0 * self.tip_radius * (self.half_base_angle - involute(alpha_a))
        beta_a = math.atan(math.tan(abs(self.helix_angle)) * self.tip_radius / self.reference_radius)
        return transverse * math.cos(beta_a)

    @property
    def largest_fillet_coefficient(self) -> float:
        """The largest rho_fP / m_n whose roundings fit on the tool's tip (they meet at its middle)."""
        return largest_fillet_coefficient(self.pressure_angle, self.dedendum_coefficient)

    @property
    def rack(self) -> str:
        """The basic rack in words: ISO 53's profile A, a full-round tip (the largest rounding that fits), or its
        numbers."""
        ha, hf, rho = self.addendum_coefficient, self.dedendum_coefficient, self.fillet_coefficient
        numbers = f"addendum {ha:g}, dedendum {hf:g}, tip rounding {rho:.3g} (in modules)"
        if (ha, hf, rho) == (1.0, 1.25, ISO53_FILLET):
            return f"ISO 53 profile A: {numbers}"
        if math.isclose(rho, self.largest_fillet_coefficient, rel_tol=1e-9):
            too_large = f"; ISO 53's {ISO53_FILLET} does not fit it" if rho < ISO53_FILLET else ""
            return (f"{numbers}: a full-round tip, the largest rounding that fits this "
                    f"{math.degrees(self.pressure_angle):.4g} deg rack{too_large}")
        return numbers

    @property
    def undercut_free_shift(self) -> float:
        """The smallest profile shift that avoids undercut (the tool's straight flank ends above the interference
        point): x_min = (h_fP - rho_fP (1 - sin(alpha_t))) / m_n - z sin^2(alpha_t) / (2 cos(beta))."""
        alpha_t = self.transverse_pressure_angle
        flank_end = self.dedendum_coefficient - self.fillet_coefficient * (1.0 - math.sin(alpha_t))
        return flank_end - self.teeth * math.sin(alpha_t) ** 2 / (2.0 * math.cos(self.helix_angle))

    @cached_property
    def profile(self) -> ToothProfile:
        """The tooth's form in the transverse section: the generated root fillet and the involute."""
        return ToothProfile.generated(
            teeth=self.teeth, reference_radius=self.reference_radius,
            pressure_angle=self.transverse_pressure_angle, half_base_angle=self.half_base_angle,
            tooth_thickness=2.0 * self.reference_radius * (self.half_base_angle - involute(self.transverse_pressure_angle)),
            tool_addendum=self.module * (self.dedendum_coefficient - self.profile_shift),
            fillet_radius=self.module * self.fillet_coefficient, tip_radius=self.tip_radius)

    # -- the gear body ----------------------------------------------------------------------------------

    @property
    def body_diameter(self) -> float:
        """d_m = (d_a + d_f) / 2, the disk ISO 6336-1 takes for a gear's inertia (m)."""
        return self.tip_radius + self.root_radius

    @property
    def mass(self) -> float:
        """The body's mass: rho pi (d_m^2 - d_i^2) b / 4 (kg)."""
        return self.material.rho * math.pi * (self.body_diameter ** 2 - self.bore_diameter ** 2) * self.face_width / 4.0

    @property
    def polar_inertia(self) -> float:
        """The body's moment of inertia about its axis: m (d_m^2 + d_i^2) / 8 (kg m^2)."""
        return self.mass * (self.body_diameter ** 2 + self.bore_diameter ** 2) / 8.0

    def describe(self) -> str:
        """One line: '28 teeth, m_n 3.175 mm, alpha_n 20 deg, b 6.35 mm' (+ x, beta, bore where not 0)."""
        parts = [f"{self.teeth} teeth", f"m_n {self.module * 1e3:.6g} mm",
                 f"alpha_n {math.degrees(self.pressure_angle):.6g} deg", f"b {self.face_width * 1e3:.6g} mm"]
        if self.profile_shift:
            parts.append(f"x {self.profile_shift:.6g}")
        if self.helix_angle:
            parts.append(f"beta {math.degrees(self.helix_angle):.6g} deg")
        if self.bore_diameter:
            parts.append(f"bore {self.bore_diameter * 1e3:.6g} mm")
        return ", ".join(parts)
