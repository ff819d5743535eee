"""The form of one tooth in the transverse section: the root fillet a rack cutter generates, then the involute.

Coordinates are those of the potential-energy method: the tooth's centre line is the y axis (y measured from the
gear's centre), x is half the tooth's thickness at height y. Both pieces are parametrised so that the energy
integrals run over smooth functions:

* the **involute** by the load angle tau (the angle between the normal to the flank, i.e. the line of action
  through that point, and the x axis; Ma et al. 2014, ROSS's ``GearElementTVMS``):
  x = r_b ((tau + psi_b) cos tau - sin tau), y = r_b ((tau + psi_b) sin tau + cos tau), dy/dtau = r_b (tau + psi_b) cos tau,
  where psi_b is half the tooth's angular thickness at the base circle and tau + psi_b = tan(alpha) is the roll
  angle of the point;
* the **fillet** (the trochoid's parallel curve cut by the tool tip's rounding of radius rho) by the angle gamma of
  its normal with the generating line: the normal at the cutting point passes through the rounding's centre and
  through the pitch point of the rolling rack, so with a = (depth of the rounding's centre below the generating
  line), b = (its distance from the tooth's centre line along the generating line) and phi = (a cot gamma + b)/r,
  x = r sin phi - (a / sin gamma + rho) cos(gamma - phi), y = r cos phi - (a / sin gamma + rho) sin(gamma - phi),
  gamma from pi/2 (the root circle) down to alpha_t (where the rounding meets the tool's straight flank, which
  generates the involute). The same curve as Ma et al. 2014 and the transition-curve equations of the
  "improved potential energy method" literature; written here from the rolling of the rack.

Helical gears use the transverse section (m_t, alpha_t) and take the tool rounding's radius as rho_fP (its
transverse section is an ellipse of semi-axes rho_fP and rho_fP / cos(beta); the difference is neglected).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .quadrature import gauss_legendre

#: a tolerance on the undercut condition (relative to the reference radius): standard gears at z_min are not undercut
_UNDERCUT_TOLERANCE = 1e-12


@dataclass(frozen=True)
class FilletMoments:
    """Integrals over the fillet (root circle to the start of the involute) that do not depend on the load:
    with eta = y - y_root, ``bending[k]`` = integral of eta^k / x^3 dy (k = 0, 1, 2) and ``direct`` = integral of
    dy / x (m^-2, m^-1, 1 and 1)."""

    y_root: float
    bending: tuple[float, float, float]
    direct: float


@dataclass(frozen=True)
class ToothProfile:
    """The generated tooth form (see the module's docstring). Lengths in m, angles in rad."""

    teeth: int
    reference_radius: float
    pressure_angle: float
    half_base_angle: float
    fillet_radius: float
    centre_depth: float
    centre_offset: float
    tip_radius: float
    junction: float
    undercut: bool
    _moments: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def generated(cls, *, teeth: int, reference_radius: float, pressure_angle: float, half_base_angle: float,
                  tooth_thickness: float, tool_addendum: float, fillet_radius: float,
                  tip_radius: float) -> "ToothProfile":
        """The tooth a rack cuts: ``tooth_thickness`` at the reference circle (arc, = the rack's space on the
        generating line), ``tool_addendum`` the depth of the tool's tip below the generating line
        (h_fP - x m_n), ``fillet_radius`` the tool tip's rounding rho_fP."""
        rho = fillet_radius
        a = tool_addendum - rho
        alpha = pressure_angle
        b = 0.5 * tooth_thickness + rho / math.cos(alpha) + a * math.tan(alpha)
        # undercut: the tool's straight flank reaches deeper than the interference point, r sin^2(alpha) below
        # the generating line
        undercut = a + rho * math.sin(alpha) > reference_radius * math.sin(alpha) ** 2 * (1.0 + _UNDERCUT_TOLERANCE)
        profile = cls(teeth, reference_radius, alpha, half_base_angle, rho, a, b, tip_radius, alpha, undercut)
        if undercut:
            object.__setattr__(profile, "junction", profile._undercut_junction())
        return profile

    # -- radii and angles ---------------------------------------------------------------------------------

    @property
    def base_radius(self) -> float:
        return self.reference_radius * math.cos(self.pressure_angle)

    @property
    def root_radius(self) -> float:
        """Where the fillet meets the root circle: r - a - rho."""
        return self.reference_radius - self.centre_depth - self.fillet_radius

    @property
    def root_angle(self) -> float:
        """theta_f: the angle between the tooth's centre line and the point where the fillet meets the root circle."""
        return self.centre_offset / self.reference_radius

    @property
    def form_radius(self) -> float:
        """The radius where the involute starts (the fillet's end)."""
        x, y, _ = self.fillet(np.array(self.junction))
        return float(math.hypot(x, y))

    @property
    def form_parameter(self) -> float:
        """The involute's load angle tau at the form radius."""
        return self.parameter(self.form_radius)

    @property
    def tip_parameter(self) -> float:
        """The involute's load angle tau at the tip circle."""
        return self.parameter(self.tip_radius)

    def parameter(self, radius):
        """The load angle tau of the involute's point at ``radius`` (scalar or array): tan(alpha) - psi_b."""
        roll = np.sqrt(np.maximum(np.square(np.asarray(radius, dtype=float) / self.base_radius) - 1.0, 0.0))
        return roll - self.half_base_angle

    # -- the two pieces -------------------------------------------------------------------------------------

    def involute(self, tau):
        """(x, y, dy/dtau) of the involute at load angle ``tau`` (array)."""
        tau = np.asarray(tau, dtype=float)
        roll = tau + self.half_base_angle
        c, s = np.cos(tau), np.sin(tau)
        rb = self.base_radius
        return rb * (roll * c - s), rb * (roll * s + c), rb * roll * c

    def fillet(self, gamma):
        """(x, y, dy/dgamma) of the root fillet at normal angle ``gamma`` (array; pi/2 is the root circle)."""
        gamma = np.asarray(gamma, dtype=float)
        r, a, rho = self.reference_radius, self.centre_depth, self.fillet_radius
        sg, cg = np.sin(gamma), np.cos(gamma)
        phi = (a * cg / sg + self.centre_offset) / r
        dphi = -a / (r * sg * sg)
        lever = a / sg + rho
        dlever = -a * cg / (sg * sg)
        sp, cp = np.sin(phi), np.cos(phi)
        s_gp, c_gp = np.sin(gamma - phi), np.cos(gamma - phi)
        x = r * sp - lever * c_gp
        y = r * cp - lever * s_gp
        dy = -r * sp * dphi - dlever * s_gp - lever * c_gp * (1.0 - dphi)
        return x, y, dy

    def _undercut_junction(self) -> float:
        """The normal angle gamma at which the fillet crosses the involute of an undercut tooth: below it the
        fillet is the thinner of the two (the tool removed the involute there), above it the involute."""
        rb = self.base_radius

        def excess(gamma: float) -> float:  # the fillet's polar half-angle minus the involute's at the same radius
            x, y, _ = self.fillet(np.array(gamma))
            radius = float(math.hypot(x, y))
            alpha = math.acos(min(1.0, rb / radius))
            return math.atan2(float(x), float(y)) - (self.half_base_angle - (math.tan(alpha) - alpha))

        grid = np.linspace(0.5 * math.pi, self.pressure_angle, 401)
        previous = None
        for gamma in grid:
            x, y, _ = self.fillet(np.array(gamma))
            if math.hypot(x, y) < rb:
                continue
            value = excess(float(gamma))
            if value >= 0.0 and previous is not None:
                low, high = previous, float(gamma)  # excess < 0 at low (root side), >= 0 at high
                for _ in range(80):
                    mid = 0.5 * (low + high)
                    if excess(mid) < 0.0:
                        low = mid
                    else:
                        high = mid
                return 0.5 * (low + high)
            previous = float(gamma) if value < 0.0 else None
        return self.pressure_angle

    # -- what the energy integrals need ------------------------------------------------------------------

    def fillet_moments(self, points: int) -> FilletMoments:
        """The load-independent integrals over the fillet with a ``points``-point Gauss–Legendre rule in gamma."""
        cached = self._moments.get(points)
        if cached is None:
            gamma, weight = gauss_legendre(self.junction, 0.5 * math.pi, points)
            x, y, dy = self.fillet(gamma)
            y_root = float(self.fillet(np.array(0.5 * math.pi))[1])
            eta = y - y_root
            w = -dy * weight  # dy = y'(gamma) dgamma, and y falls as gamma rises
            cube = w / x ** 3
            cached = FilletMoments(y_root, (float(cube.sum()), float((cube * eta).sum()), float((cube * eta * eta).sum())),
                                   float((w / x).sum()))
            self._moments[points] = cached
        return cached
