"""A tooth root crack by the potential-energy method: the cracked tooth's compliances and the fraction of its pair's
stiffness the crack takes away (what a :class:`~gearsym.model.faults.ToothFault` needs as its depth).

The crack starts where the fillet meets the root circle, on the loaded flank, and runs straight into the tooth for
``depth`` (m) at ``angle`` (rad) to the tooth's centre line (Chen & Shao 2011, Mech. Mach. Theory 46: their crack
depth q and angle nu). Its tip lies at h_q = h_c - q sin(nu) from the centre line, h_c the tooth's half thickness at
the root circle. As in Chen & Shao (and Tian 2004), the part of a section beyond the line through the tip parallel to
the centre line carries no load: a section of half thickness x has its loaded side cut to min(x, h_q), so its
thickness is x + min(x, h_q) instead of 2x; the energies of :mod:`.tooth_energy` then use

    I_y = (x + min(x, h_q))^3 w / 12,    A_y = (x + min(x, h_q)) w

up to the height where the profile's half thickness falls to h_q, and the intact tooth's above it (the shift of the
neutral axis is neglected, as there). Only a crack that stays on its side of the centre line (h_q > 0, Chen &
Shao's first case) is taken. The integrals are split where the profile's half thickness is h_q, so each piece
stays smooth for Gauss-Legendre.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GearsymError
from .gear import GearGeometry
from .pair import GearPair
from .profile import ToothProfile
from .quadrature import gauss_legendre
from .tooth_pair import QUADRATURE_POINTS, pair_compliances

#: positions on the path of contact over which a crack's loss of stiffness is averaged
PATH_POSITIONS = 201


@dataclass(frozen=True)
class Crack:
    """A root crack: ``depth`` (m) along the crack, ``angle`` (rad) between the crack and the tooth's centre line."""

    depth: float
    angle: float

    def __post_init__(self):
        if not (math.isfinite(self.depth) and self.depth >= 0):
            raise GearsymError(f"crack: depth {self.depth!r} m must be a finite length of 0 or more")
        if not (math.isfinite(self.angle) and 0 < self.angle <= math.pi / 2):
            raise GearsymError(f"crack: angle {self.angle!r} rad must lie in (0, pi/2] (radians, from the tooth's "
                               "centre line; math.radians(70) for 70 degrees)")

    def tip(self, profile: ToothProfile) -> float:
        """h_q: the crack tip's distance from the tooth's centre line (m), or a one-line error past it."""
        root = float(profile.fillet(np.array(0.5 * math.pi))[0])
        h = root - self.depth * math.sin(self.angle)
        if h <= 0:
            raise GearsymError(f"crack: depth {self.depth * 1e3:.4g} mm at {math.degrees(self.angle):.4g} deg "
                               f"reaches past the tooth's centre line (half thickness {root * 1e3:.4g} mm at the root): "
                               "only a crack that stays on its side of the centre line is modelled")
        return h


def _crossing(f, low: float, high: float, target: float) -> float:
    """Where the monotone ``f`` takes ``target`` in [low, high] (bisection)."""
    f_low = f(low) - target
    for _ in range(100):
        mid = 0.5 * (low + high)
        if (f(mid) - target) * f_low > 0:
            low = mid
        else:
            high = mid
    return 0.5 * (low + high)


def cracked_tooth_compliances(profile: ToothProfile, material, width: float, load_angle, points: int,
                              crack: Crack) -> dict[str, np.ndarray]:
    """Bending, shear and axial compliances (m/N) of one tooth with ``crack``, loaded on its involute at the load
    angles ``load_angle`` (array): :func:`.tooth_energy.tooth_compliances` with the cracked sections' thickness."""
    tau = np.asarray(load_angle, dtype=float)
    h = crack.tip(profile)
    x_c, y_c, _ = profile.involute(tau)
    c, s = np.cos(tau), np.sin(tau)
    bending = np.zeros_like(tau)
    direct = np.zeros_like(tau)

    def add(x, y, dy, weights):  # one piece's nodes (..., points) with dy the signed height step
        nonlocal bending, direct
        thick = 0.5 * (x + np.minimum(x, h))  # half of the section's loaded thickness
        arm = c[..., None] * (y_c[..., None] - y) - (x_c * s)[..., None]
        bending = bending + (arm * arm / thick ** 3 * dy * weights).sum(-1)
        direct = direct + (dy / thick * weights).sum(-1)

    # the fillet, from the root circle (gamma = pi/2) up to the involute, split where its half thickness is h
    fillet_x = lambda g: float(profile.fillet(np.array(g))[0])  # noqa: E731 (falls from the root up)
    pieces = [profile.junction, 0.5 * math.pi]
    if fillet_x(profile.junction) < h < fillet_x(0.5 * math.pi):
        pieces.insert(1, _crossing(fillet_x, profile.junction, 0.5 * math.pi, h))
    for low, high in zip(pieces, pieces[1:]):
        gamma, weights = gauss_legendre(low, high, points)
        x, y, dy = profile.fillet(gamma)
        add(x, y, -dy, weights)  # (y falls as gamma rises)
    # the involute, from the form point up to each contact, split where its half thickness is h
    start = profile.form_parameter
    involute_x = lambda t: float(profile.involute(np.array(t))[0])  # noqa: E731
    split = start
    if involute_x(start) > h:
        split = _crossing(involute_x, start, profile.tip_parameter, h) if involute_x(profile.tip_parameter) < h \
            else profile.tip_parameter
    edges = [start, np.minimum(split, tau), tau]
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


def cracked_pair_stiffness(pair: GearPair, positions, gear: int, crack: Crack, *,
                           points: int = QUADRATURE_POINTS) -> np.ndarray:
    """The stiffness (N/m) of one pair of teeth in contact at ``positions`` (m from T1 on the line of action) when
    the tooth of gear ``gear`` (1 or 2) has ``crack``; the other compliances are those of :func:`.pair_compliances`."""
    if gear not in (1, 2):
        raise GearsymError(f"crack: gear must be 1 or 2 (the pair's driving or driven gear), got {gear!r}")
    s = np.asarray(positions, dtype=float)
    parts = pair_compliances(pair, s, points=points)
    g: GearGeometry = pair.gear1 if gear == 1 else pair.gear2
    along = s if gear == 1 else pair.line_of_action - s
    tau = along / g.base_radius - g.half_base_angle
    cracked = cracked_tooth_compliances(g.profile, g.material, pair.face_width, tau, points, crack)
    for name in ("bending", "shear", "axial"):
        parts[f"{name}{gear}"] = cracked[name]
    return 1.0 / sum(parts.values())


def crack_stiffness_loss(pair: GearPair, gear: int, depth: float, angle: float, *,
                         points: int = QUADRATURE_POINTS) -> float:
    """The fraction of its pair's stiffness that a root crack (``depth`` m at ``angle`` rad to the tooth's centre
    line) on a tooth of gear ``gear`` (1 or 2) takes away, averaged over the pair's path of contact: the depth q of
    a :class:`~gearsym.model.faults.ToothFault` (k(phi)(1 - q s_n(phi)))."""
    crack = Crack(float(depth), float(angle))
    start, end = pair.path_of_contact
    s = np.linspace(start, end, PATH_POSITIONS)
    healthy = 1.0 / sum(pair_compliances(pair, s, points=points).values())
    cracked = cracked_pair_stiffness(pair, s, gear, crack, points=points)
    return float(np.mean(1.0 - cracked / healthy))
