"""Two gears in mesh: centre distance, working pressure angle, path of contact and contact ratios.

All in the transverse section (ISO 21771). With profile shifts x1, x2 and no backlash the working transverse
pressure angle alpha_wt solves inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2), and the
centre distance is a_w = (r_b1 + r_b2) / cos(alpha_wt); a larger centre distance (with backlash) may be given
instead, and then cos(alpha_wt) = (r_b1 + r_b2) / a_w. On the line of action, measured from T1 (where it
touches gear 1's base circle), contact runs from s_A = T1T2 - sqrt(r_a2^2 - r_b2^2) to s_E = sqrt(r_a1^2 - r_b1^2);
its length g_alpha = s_E - s_A over the transverse base pitch p_bt is the transverse contact ratio eps_alpha.
The overlap ratio is eps_beta = b sin|beta| / (pi m_n).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import GearsymError
from .gear import GearGeometry, involute

#: relative tolerance when two gears' rack data must agree
_SAME = 1e-9


def inverse_involute(value: float) -> float:
    """The angle alpha in [0, pi/2) with tan(alpha) - alpha = ``value`` (Newton from Cheng's cube-root start)."""
    if value < 0:
        raise GearsymError(f"the involute function has no angle for {value:g} < 0")
    alpha = (3.0 * value) ** (1.0 / 3.0)
    for _ in range(60):
        step = (math.tan(alpha) - alpha - value) / math.tan(alpha) ** 2 if alpha > 0 else 0.0
        alpha -= step
        if abs(step) < 1e-16:
            break
    return alpha


@dataclass(frozen=True)
class GearPair:
    """An external pair: ``gear1`` (the pinion, the driving gear) and ``gear2``, at ``centre_distance`` (m) or,
    if None, at the zero-backlash centre distance their profile shifts give."""

    gear1: GearGeometry
    gear2: GearGeometry
    centre_distance: float | None = None

    def __post_init__(self):
        g1, g2 = self.gear1, self.gear2
        for g in (g1, g2):
            if not isinstance(g, GearGeometry):
                raise GearsymError(f"gear pair: expected two GearGeometry, got {type(g).__name__}")
        if not math.isclose(g1.module, g2.module, rel_tol=_SAME):
            raise GearsymError(f"gear pair: the modules differ ({g1.module * 1e3:g} mm and {g2.module * 1e3:g} mm); "
                               "gears mesh only with the same module")
        if not math.isclose(g1.pressure_angle, g2.pressure_angle, rel_tol=_SAME):
            raise GearsymError(f"gear pair: the pressure angles differ ({math.degrees(g1.pressure_angle):g} and "
                               f"{math.degrees(g2.pressure_angle):g} deg); gears mesh only with the same basic rack")
        if not math.isclose(abs(g1.helix_angle), abs(g2.helix_angle), rel_tol=_SAME, abs_tol=1e-15):
            raise GearsymError(f"gear pair: the helix angles differ in size ({math.degrees(g1.helix_angle):g} and "
                               f"{math.degrees(g2.helix_angle):g} deg); an external pair has equal helix angles of "
                               "opposite hands")
        if g1.helix_angle and (g1.helix_angle > 0) == (g2.helix_angle > 0):
            raise GearsymError(f"gear pair: the helices have the same hand ({math.degrees(g1.helix_angle):g} and "
                               f"{math.degrees(g2.helix_angle):g} deg: the sign is the hand); an external pair meshes "
                               f"with opposite hands: give gear 2 {-math.degrees(g2.helix_angle):g} deg")
        zero_backlash = (g1.base_radius + g2.base_radius) / math.cos(self._tight_angle)
        if self.centre_distance is None:
            object.__setattr__(self, "centre_distance", zero_backlash)
        else:
            if isinstance(self.centre_distance, bool) or not isinstance(self.centre_distance, (int, float)) \
                    or not math.isfinite(self.centre_distance):
                raise GearsymError(f"gear pair: the centre distance must be a number (m), got {self.centre_distance!r}")
            object.__setattr__(self, "centre_distance", float(self.centre_distance))
            if self.centre_distance < zero_backlash * (1.0 - 1e-9):
                raise GearsymError(f"gear pair: a centre distance of {self.centre_distance * 1e3:.6g} mm is less than the "
                                   f"{zero_backlash * 1e3:.6g} mm at which the teeth mesh without backlash: they would "
                                   "jam; give at least that, or lower the profile shifts")
        a = self.centre_distance
        for tip, other in ((g1, g2), (g2, g1)):
            clearance = a - tip.tip_radius - other.root_radius
            if clearance < 0:
                raise GearsymError(f"gear pair: the tip of the {tip.teeth}-tooth gear reaches {-clearance * 1e3:.3g} mm "
                                   f"into the root of the {other.teeth}-tooth gear (no tip clearance); lower its "
                                   "addendum or profile shift, or widen the centre distance")
        if self.contact_ratio < 1.0:
            raise GearsymError(f"gear pair: the transverse contact ratio is {self.contact_ratio:.3f} < 1: the teeth "
                               "lose contact between one pair and the next; use more teeth, a larger addendum or a "
                               "smaller centre distance")
        for gear, position in ((g1, self.path_of_contact[0]), (g2, self.line_of_action - self.path_of_contact[1])):
            form = math.sqrt(max(gear.profile.form_radius ** 2 - gear.base_radius ** 2, 0.0))
            if position < form * (1.0 - 1e-9):
                other = g2 if gear is g1 else g1
                raise GearsymError(f"gear pair: the tip of the {other.teeth}-tooth gear meets the {gear.teeth}-tooth gear "
                                   f"below its involute (at the diameter {2e3 * math.hypot(gear.base_radius, position):.5g} mm, "
                                   f"the involute starts at {2e3 * gear.profile.form_radius:.5g} mm): tip interference; "
                                   "lower that tip or give the gears more profile shift")

    @property
    def _tight_angle(self) -> float:
        g1, g2 = self.gear1, self.gear2
        alpha_t = g1.transverse_pressure_angle
        target = involute(alpha_t) + 2.0 * math.tan(g1.pressure_angle) * (g1.profile_shift + g2.profile_shift) \
            / (g1.teeth + g2.teeth)
        return inverse_involute(target)

    @property
    def working_pressure_angle(self) -> float:
        """alpha_wt, the transverse pressure angle at the working pitch point (rad)."""
        return math.acos((self.gear1.base_radius + self.gear2.base_radius) / self.centre_distance)

    @property
    def line_of_action(self) -> float:
        """The length T1T2 of the line of action between the base circles' tangent points (m)."""
        return self.centre_distance * math.sin(self.working_pressure_angle)

    @property
    def path_of_contact(self) -> tuple[float, float]:
        """(s_A, s_E): where contact starts and ends on the line of action, measured from T1 (m)."""
        g1, g2 = self.gear1, self.gear2
        start = self.line_of_action - math.sqrt(g2.tip_radius ** 2 - g2.base_radius ** 2)
        end = math.sqrt(g1.tip_radius ** 2 - g1.base_radius ** 2)
        return start, end

    @property
    def base_pitch(self) -> float:
        """The transverse base pitch p_bt, the same for both gears (m)."""
        return self.gear1.base_pitch

    @property
    def contact_ratio(self) -> float:
        """The transverse contact ratio eps_alpha = g_alpha / p_bt."""
        start, end = self.path_of_contact
        return (end - start) / self.base_pitch

    @property
    def face_width(self) -> float:
        """The width both gears share, min(b1, b2) (m)."""
        return min(self.gear1.face_width, self.gear2.face_width)

    @property
    def overlap_ratio(self) -> float:
        """eps_beta = b sin|beta| / (pi m_n) = b tan(beta_b) / p_bt."""
        return self.face_width * math.sin(abs(self.gear1.helix_angle)) / (math.pi * self.gear1.module)

    @property
    def total_contact_ratio(self) -> float:
        """eps_gamma = eps_alpha + eps_beta."""
        return self.contact_ratio + self.overlap_ratio

    @property
    def ratio(self) -> float:
        """The gear ratio u = z2 / z1."""
        return self.gear2.teeth / self.gear1.teeth

    @property
    def teeth(self) -> int:
        """Mesh periods per revolution of gear 1: its tooth count (the mesh frequency is z1 times its speed)."""
        return self.gear1.teeth

    def mesh_frequency(self, speed: float) -> float:
        """The mesh frequency (Hz) at ``speed`` revolutions per second of gear 1: z1 n1."""
        return self.gear1.teeth * speed

    def describe(self) -> str:
        """'28/28 teeth, m_n 3.175 mm, alpha_n 20 deg, b 6.35 mm' (+ shifts, helix, bores)."""
        g1, g2 = self.gear1, self.gear2
        parts = [f"{g1.teeth}/{g2.teeth} teeth", f"m_n {g1.module * 1e3:.6g} mm",
                 f"alpha_n {math.degrees(g1.pressure_angle):.6g} deg", f"b {self.face_width * 1e3:.6g} mm"]
        if g1.profile_shift or g2.profile_shift:
            parts.append(f"x {g1.profile_shift:.6g}/{g2.profile_shift:.6g}")
        if g1.helix_angle:
            parts.append(f"beta {math.degrees(abs(g1.helix_angle)):.6g} deg")
        return ", ".join(parts)
