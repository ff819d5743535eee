"""A tooth root crack by the potential-energy method: where it starts, where it ends, and the cracked tooth's
compliances.

**The literature's crack.** The potential-energy crack models (Tian 2004, MSc thesis, Univ. of Alberta; Wu, Zuo &
Parey 2008, J. Sound Vib. 317; Chen & Shao 2011, Eng. Fail. Anal. 18; Mohammed, Rantatalo & Aidanpaeae 2013, Eng.
Fail. Anal. 34) draw the crack as a straight line of length q (``depth``) from a point of the loaded flank into the
tooth, at the angle nu (``angle``) to the tooth's centre line, running towards the root; its tip lies at

    h_q = h_c - q sin(nu)    from the centre line (negative: past it, on the other side),
    y_q = y_c - q cos(nu)    in height (y along the centre line, from the gear's centre),

with (h_c, y_c) where it starts (``origin``):

* ``"critical_section"`` (the default): where a tangent at 30 deg to the centre line touches the root fillet, the
  critical section of ISO 6336-3 (its s_Fn = 2 h_c), where root cracks start. On the generated fillet of
  :mod:`.profile` the tangent makes the angle gamma - phi(gamma) with the centre line, so the point solves
  gamma - phi(gamma) = 30 deg.
* ``"base_circle"``: the section Tian and Chen & Shao start it from, h_c = r_b sin(psi_b) (their R_b sin(alpha_2),
  psi_b half the tooth's angular thickness on the base circle) at the height r_b cos(psi_b).

On the 53-tooth wheel of a 20/53, m 3 mm pair these are 3.27 and 3.33 mm from the centre line, against 4.30 mm where
the fillet meets the root circle (where gearsym started it before).

**The sections.** As in those papers, the part of the tooth beyond a *limit line* through the crack tip carries no
load: a section at height y >= y_q of half thickness x keeps its unloaded half and, of its loaded half, the part up
to the limit line's distance l(y) from the centre line, so its thickness is ``x + min(x, l(y))`` instead of 2x, and

    I_y = (x + min(x, l))^3 w / 12,    A_y = (x + min(x, l)) w

enter the bending, shear and axial energies of :mod:`.tooth_energy` (the neutral axis' shift is neglected, as
there). Sections below the tip are intact. The limit line (``limit_line``):

* ``"parallel"`` (Tian; Chen & Shao's first case): through the tip, parallel to the centre line, l = h_q; it leaves
  the tooth where the profile's half thickness falls to h_q, and the sections above are intact.
* ``"to_top"``: from the tip to the top of the tooth's centre line (on the tip circle),
  l(y) = h_q (r_a - y) / (r_a - y_q), after Mohammed et al. 2013's limit line running from the crack tip to the
  tooth's top.

A crack **past the centre line** (h_q < 0; Chen & Shao's second case, whose second segment carries the crack on
into the unloaded half) always takes the ``"to_top"`` line: a parallel line there would leave the upper sections a
ligament x - |h_q| that closes where the tooth is |h_q| thick, and the bending integral, 1/thickness^3, diverges
there. At h_q = 0 both lines are the centre line, so the loss runs on continuously through the crossing. A crack
that reaches the unloaded flank is refused.

The integrals are split where a section's thickness has a kink (at the tip's height, and where x = l(y)), so each
piece stays smooth for Gauss-Legendre; tests/test_geometry_crack.py checks them against SciPy's adaptive quadrature
of the sections typed from the papers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GearsymError
from .profile import ToothProfile
from .quadrature import gauss_legendre

#: where a crack may start
ORIGINS = ("critical_section", "base_circle")
#: the limit lines beyond which a cracked section carries no load
LIMIT_LINES = ("parallel", "to_top")
#: the angle (rad) of ISO 6336-3's tangent to the fillet at the critical section
CRITICAL_TANGENT = math.pi / 6
#: samples of a profile piece searched for the kinks of a cracked section's thickness
_SEARCH = 65


@dataclass(frozen=True)
class Crack:
    """A root crack: ``depth`` (m) along the crack, ``angle`` (rad) between the crack and the tooth's centre line,
    starting at ``origin`` (one of :data:`ORIGINS`), with the limit line ``limit_line`` (:data:`LIMIT_LINES`)."""

    depth: float
    angle: float
    origin: str = "critical_section"
    limit_line: str = "parallel"

    def __post_init__(self):
        if not (math.isfinite(self.depth) and self.depth >= 0):
            raise GearsymError(f"crack: depth {self.depth!r} m must be a finite length of 0 or more")
        if not (math.isfinite(self.angle) and 0 < self.angle <= math.pi / 2):
            raise GearsymError(f"crack: angle {self.angle!r} rad must lie in (0, pi/2] (radians, from the tooth's "
                               "centre line; math.radians(70) for 70 degrees)")
        if self.origin not in ORIGINS:
            raise GearsymError(f"crack: origin {self.origin!r} is not one of {', '.join(ORIGINS)}")
        if self.limit_line not in LIMIT_LINES:
            raise GearsymError(f"crack: limit line {self.limit_line!r} is not one of {', '.join(LIMIT_LINES)}")

    def path(self, profile: ToothProfile) -> "CrackPath":
        """Where this crack starts and ends on ``profile``'s tooth, and its limit line; a one-line error for a crack
        that reaches through the tooth."""
        h_c, y_c = crack_origin(profile, self.origin)
        h_q = h_c - self.depth * math.sin(self.angle)
        y_q = y_c - self.depth * math.cos(self.angle)
        path = CrackPath((h_c, y_c), (h_q, y_q), profile.tip_radius,
                         sloped=self.limit_line == "to_top" or h_q < 0)
        if h_q < 0:
            other = half_thickness(profile, y_q)
            if -h_q >= other:
                raise GearsymError(f"crack: {self.depth * 1e3:.4g} mm at {math.degrees(self.angle):.4g} deg from "
                                   f"{self.origin.replace('_', ' ')} ({h_c * 1e3:.4g} mm from the centre line) reaches "
                                   f"the other flank of the tooth ({other * 1e3:.4g} mm beyond the centre line at the "
                                   "tip's height): the tooth is broken off, which this model does not describe")
        return path


@dataclass(frozen=True)
class CrackPath:
    """A crack on a tooth (m): ``origin`` (h_c, y_c) and ``tip`` (h_q, y_q), the distance from the centre line
    (positive on the loaded flank's side) and the height; ``top`` the tooth's top on its centre line (the tip radius);
    ``sloped``: the limit line runs from the tip to the top, else parallel to the centre line."""

    origin: tuple[float, float]
    tip: tuple[float, float]
    top: float
    sloped: bool

    @property
    def crosses_centre_line(self) -> bool:
        return self.tip[0] < 0

    def limit(self, y):
        """l(y): the limit line's distance from the centre line at the heights ``y`` (where y >= y_q)."""
        h_q, y_q = self.tip
        y = np.asarray(y, dtype=float)
        if not self.sloped:
            return np.full_like(y, h_q)
        return h_q * (self.top - y) / (self.top - y_q)

    def thickness(self, x, y):
        """The load-carrying thickness of the sections of half thickness ``x`` at heights ``y`` (arrays)."""
        x = np.asarray(x, dtype=float)
        cut = np.asarray(y) >= self.tip[1]
        return x + np.where(cut, np.minimum(x, self.limit(y)), x)


def crack_origin(profile: ToothProfile, origin: str) -> tuple[float, float]:
    """(h_c, y_c): where a crack starting at ``origin`` (:data:`ORIGINS`) leaves the loaded flank (m)."""
    if origin == "base_circle":
        psi = profile.half_base_angle
        return profile.base_radius * math.sin(psi), profile.base_radius * math.cos(psi)
    # the fillet's tangent makes gamma - phi(gamma) with the centre line: 0 at the involute's end (gamma = alpha),
    # growing to pi/2 - phi at the root circle
    r, a = profile.reference_radius, profile.centre_depth

    def tangent_angle(gamma: float) -> float:
        return gamma - (a * math.cos(gamma) / math.sin(gamma) + profile.centre_offset) / r

    low, high = profile.junction, 0.5 * math.pi
    if not tangent_angle(low) < CRITICAL_TANGENT < tangent_angle(high):
        raise GearsymError("crack: no tangent at 30 deg to the centre line touches this tooth's fillet (a fillet "
                           "radius of 0?); start the crack at origin='base_circle'")
    gamma = _bisect(tangent_angle, low, high, CRITICAL_TANGENT)
    x, y, _ = profile.fillet(np.array(gamma))
    return float(x), float(y)


def half_thickness(profile: ToothProfile, height: float) -> float:
    """The tooth's half thickness (m) at ``height`` along its centre line (the root's below the root circle, the
    tip's above the tip circle)."""
    fillet_y = lambda g: float(profile.fillet(np.array(g))[1])  # noqa: E731 (falls from the junction to the root)
    involute_y = lambda t: float(profile.involute(np.array(t))[1])  # noqa: E731 (rises to the tip)
    if height <= fillet_y(0.5 * math.pi):
        return float(profile.fillet(np.array(0.5 * math.pi))[0])
    if height <= fillet_y(profile.junction):
        return float(profile.fillet(np.array(_bisect(fillet_y, profile.junction, 0.5 * math.pi, height)))[0])
    top = profile.tip_parameter
    if height >= involute_y(top):
        return float(profile.involute(np.array(top))[0])
    return float(profile.involute(np.array(_bisect(involute_y, profile.form_parameter, top, height)))[0])


def _bisect(f, low: float, high: float, target: float) -> float:
    """Where the continuous ``f`` crosses ``target`` in [low, high] (f - target changes sign there)."""
    f_low = f(low) - target
    for _ in range(100):
        mid = 0.5 * (low + high)
        if (f(mid) - target) * f_low > 0:
            low, f_low = mid, f(mid) - target
        else:
            high = mid
    return 0.5 * (low + high)


def _kinks(piece, low: float, high: float, path: CrackPath) -> list[float]:
    """The parameters in (low, high) of a profile piece where a cracked section's thickness has a kink: the tip's
    height, and where the half thickness meets the limit line above it."""
    grid = np.linspace(low, high, _SEARCH)
    out = []
    height = lambda u: float(piece(np.array(u))[1])  # noqa: E731
    gap = lambda u: float(piece(np.array(u))[0] - path.limit(height(u)))  # noqa: E731
    for f, target in ((height, path.tip[1]), (gap, 0.0)):
        values = np.array([f(u) for u in grid]) - target
        for k in np.nonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)[0]:
            u = _bisect(f, float(grid[k]), float(grid[k + 1]), target)
            if f is height or height(u) >= path.tip[1]:
                out.append(u)
    return sorted(out)


def cracked_tooth_compliances(profile: ToothProfile, material, width: float, load_angle, points: int,
                              crack: Crack) -> dict[str, np.ndarray]:
    """Bending, shear and axial compliances (m/N) of one tooth with ``crack``, loaded on its involute at the load
    angles ``load_angle`` (array): :func:`.tooth_energy.tooth_compliances` with the cracked sections' thickness."""
    tau = np.asarray(load_angle, dtype=float)
    path = crack.path(profile)
    x_c, y_c, _ = profile.involute(tau)
    c, s = np.cos(tau), np.sin(tau)
    bending = np.zeros_like(tau)
    direct = np.zeros_like(tau)

    def add(x, y, dy, weights):  # one piece's nodes (..., points) with dy the signed height step
        nonlocal bending, direct
        thick = 0.5 * path.thickness(x, y)  # half of the section's load-carrying thickness
        if np.any(thick <= 0):
            raise GearsymError("crack: a section of the cracked tooth keeps no material (the limit line crosses the "
                               "unloaded flank); a shallower crack or another angle")
        arm = c[..., None] * (y_c[..., None] - y) - (x_c * s)[..., None]
        bending = bending + (arm * arm / thick ** 3 * dy * weights).sum(-1)
        direct = direct + (dy / thick * weights).sum(-1)

    # the fillet, from the root circle (gamma = pi/2) up to the involute
    edges = [profile.junction, *_kinks(profile.fillet, profile.junction, 0.5 * math.pi, path), 0.5 * math.pi]
    for low, high in zip(edges, edges[1:]):
        gamma, weights = gauss_legendre(low, high, points)
        x, y, dy = profile.fillet(gamma)
        add(x, y, -dy, weights)  # (y falls as gamma rises)
    # the involute, from the form point up to each contact
    start = profile.form_parameter
    inner = _kinks(profile.involute, start, profile.tip_parameter, path)
    edges = [start, *(np.minimum(k, tau) for k in inner), tau]
    for low, high in zip(edges, edges[1:]):
        nodes, weights = gauss_legendre(low, high, points)
        x, y, dy = profile.involute(nodes)
        add(x, y, dy, weights)
    E, G = material.E, material.shear_modulus
    return {
        "bending": 1.5 / (E * width) * bending,
        "shear": 0.6 * c * c / (G * width) * direct,
        "axial": 0.5 * s * s / (E * width) * direct,
    }
