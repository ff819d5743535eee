"""What a root crack (:mod:`.crack`) takes from its pair's stiffness, along the path of contact and through the mesh.

The cracked tooth's pair has the compliances of :func:`.tooth_pair.pair_compliances` with the cracked tooth's
bending, shear and axial ones (:func:`.crack.cracked_tooth_compliances`); its loss at a point of the path is
1 - k_cracked / k_healthy there. A crack softens its pair most where the load acts high on the cracked tooth (near its
tip: late in the path on the driving gear, early on the driven one), so the loss runs along the path, from under 1 %
to over 10 % for a 3 mm crack; :class:`CrackLoss` holds it as a function of the fraction u of the path (0 where the
pair comes into contact, at s_A; 1 where it leaves, at s_E), its mean, and the polynomial by which a model's
:class:`~gearsym.model.faults.ToothFault` carries it through the mesh phase (:meth:`CrackLoss.shape`).

:func:`cracked_mesh_stiffness` is the pair's mesh stiffness while the cracked tooth passes, the pairs in contact
summed at each mesh phase as in :mod:`.meshing`: the healthy curve with the cracked pair's share lowered.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import GearsymError
from .crack import Crack, cracked_tooth_compliances
from .gear import GearGeometry
from .pair import GearPair
from .quadrature import gauss_legendre
from .tooth_pair import QUADRATURE_POINTS, pair_compliances

#: Gauss-Legendre nodes along the path of contact for a crack's mean loss (the loss is smooth along the path but
#: for kinks where the contact passes a kink of the cracked sections: converged to 1e-5 of the mean)
PATH_POINTS = 96
#: samples of the loss along the path kept in a CrackLoss (for its figure and its polynomial)
PATH_SAMPLES = 121
#: the highest degree of the polynomial a ToothFault carries the loss with, and how closely it must follow
MAX_DEGREE = 10
SHAPE_TOLERANCE = 0.005


def _check(pair: GearPair, gear: int) -> GearGeometry:
    if gear not in (1, 2):
        raise GearsymError(f"crack: gear must be 1 or 2 (the pair's driving or driven gear), got {gear!r}")
    if pair.gear1.helix_angle != 0.0:
        raise GearsymError("crack: the root crack model is for spur pairs (Tian; Chen & Shao), this pair is helical")
    return pair.gear1 if gear == 1 else pair.gear2


def cracked_pair_stiffness(pair: GearPair, positions, gear: int, crack: Crack, *,
                           points: int = QUADRATURE_POINTS) -> np.ndarray:
    """The stiffness (N/m) of one pair of teeth in contact at ``positions`` (m from T1 on the line of action) when
    the tooth of gear ``gear`` (1 or 2) has ``crack``; the other compliances are those of :func:`.pair_compliances`."""
    g = _check(pair, gear)
    s = np.asarray(positions, dtype=float)
    parts = pair_compliances(pair, s, points=points)
    along = s if gear == 1 else pair.line_of_action - s
    tau = along / g.base_radius - g.half_base_angle
    cracked = cracked_tooth_compliances(g.profile, g.material, pair.face_width, tau, points, crack)
    for name in ("bending", "shear", "axial"):
        parts[f"{name}{gear}"] = cracked[name]
    return 1.0 / sum(parts.values())


def pair_loss(pair: GearPair, gear: int, crack: Crack, fraction, *, points: int = QUADRATURE_POINTS) -> np.ndarray:
    """1 - k_cracked / k_healthy of the cracked tooth's pair at the fractions ``fraction`` of the path of contact
    (0: where the pair comes into contact, 1: where it leaves)."""
    start, end = pair.path_of_contact
    s = start + np.asarray(fraction, dtype=float) * (end - start)
    healthy = 1.0 / sum(pair_compliances(pair, s, points=points).values())
    return 1.0 - cracked_pair_stiffness(pair, s, gear, crack, points=points) / healthy


@dataclass(frozen=True)
class CrackLoss:
    """A crack's loss of its pair's stiffness along the path of contact: ``fraction`` (0 ... 1 along the path),
    ``loss`` there, its ``mean`` over the path (Gauss-Legendre, not the samples'), and the ``contact_ratio``
    over which the pair is in mesh."""

    pair: GearPair
    gear: int
    crack: Crack
    fraction: np.ndarray
    loss: np.ndarray
    mean: float
    contact_ratio: float
    _shape: dict = field(default_factory=dict, compare=False, repr=False)

    def shape(self, degree: int | None = None) -> tuple[float, ...]:
        """The loss over its mean as a polynomial sum_k c_k w^k, w = sin(a) / sin(h) in [-1, 1] along the path, a
        the gear's angle from the middle of the pair's time in mesh and h half its length (pi eps / Z): the form a
        model's tooth fault takes it in (:func:`gearsym.model.shaft_orders.path_coordinate`), periodic over the
        revolution. ``degree`` None: the lowest (up to :data:`MAX_DEGREE`) that follows the loss within
        :data:`SHAPE_TOLERANCE` of its largest value. Coefficients are rounded to 12 digits (the same C everywhere)."""
        if degree not in self._shape:
            teeth = (self.pair.gear1 if self.gear == 1 else self.pair.gear2).teeth
            half = math.pi * self.contact_ratio / teeth
            w = np.sin((2 * self.fraction - 1) * half) / math.sin(half)
            target = self.loss / self.mean if self.mean > 0 else np.ones_like(self.loss)
            degrees = range(MAX_DEGREE + 1) if degree is None else [degree]
            for d in degrees:
                coef = np.polynomial.polynomial.polyfit(w, target, d)
                fitted = np.polynomial.polynomial.polyval(w, coef)
                if np.max(np.abs(fitted - target)) <= SHAPE_TOLERANCE * np.max(np.abs(target)):
                    break
            self._shape[degree] = tuple(float(f"{c:.12g}") for c in coef)
        return self._shape[degree]


def crack_loss_along_path(pair: GearPair, gear: int, crack: Crack, *, points: int = QUADRATURE_POINTS,
                          samples: int = PATH_SAMPLES) -> CrackLoss:
    """The :class:`CrackLoss` of ``crack`` on a tooth of gear ``gear`` (1 or 2) of ``pair``."""
    _check(pair, gear)
    fraction = np.linspace(0.0, 1.0, samples)
    u, w = gauss_legendre(0.0, 1.0, PATH_POINTS)
    mean = float((pair_loss(pair, gear, crack, u, points=points) * w).sum())
    return CrackLoss(pair, gear, crack, fraction, pair_loss(pair, gear, crack, fraction, points=points), mean,
                     pair.contact_ratio)


def crack_stiffness_loss(pair: GearPair, gear: int, depth: float, angle: float, *,
                         points: int = QUADRATURE_POINTS, **where) -> float:
    """The fraction of its pair's stiffness that a root crack (``depth`` m at ``angle`` rad to the tooth's centre
    line; ``origin=``, ``limit_line=`` as :class:`Crack`'s) on a tooth of gear ``gear`` (1 or 2) takes away, averaged
    over the pair's path of contact: the depth q of a constant :class:`~gearsym.model.faults.ToothFault`."""
    crack = Crack(float(depth), float(angle), **where)
    _check(pair, gear)
    u, w = gauss_legendre(0.0, 1.0, PATH_POINTS)
    return float((pair_loss(pair, gear, crack, u, points=points) * w).sum())


def cracked_mesh_stiffness(pair: GearPair, gear: int, crack: Crack, phase, *,
                           points: int = QUADRATURE_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """(healthy, cracked) mesh stiffness (N/m) of a spur ``pair`` at the mesh phases ``phase`` (rad; 0 where the
    cracked tooth's pair comes into contact, 2 pi eps where it leaves): the pairs in contact at each phase summed, the
    cracked pair with ``crack`` on its tooth of gear ``gear``."""
    _check(pair, gear)
    phase = np.asarray(phase, dtype=float)
    start, end = pair.path_of_contact
    healthy, cracked = np.zeros_like(phase), np.zeros_like(phase)
    periods = phase / (2 * math.pi)
    for j in range(math.floor(-np.max(periods, initial=0.0)) - 1,
                   math.ceil(pair.contact_ratio - np.min(periods, initial=0.0)) + 2):
        s = start + (phase / (2 * math.pi) + j) * pair.base_pitch
        inside = (s >= start) & (s <= end)
        if not inside.any():
            continue
        k = np.zeros_like(phase)
        k[inside] = 1.0 / sum(pair_compliances(pair, s[inside], points=points).values())
        healthy += k
        if j == 0:
            k = np.zeros_like(phase)
            k[inside] = cracked_pair_stiffness(pair, s[inside], gear, crack, points=points)
        cracked += k
    return healthy, cracked


def loss_against_depth(pair: GearPair, gear: int, crack: Crack, count: int = 25
                       ) -> tuple[np.ndarray, np.ndarray, float]:
    """(depths, mean losses, depth at which the crack reaches the centre line): ``count`` cracks like ``crack`` (its
    angle, origin, limit line) from no depth to 97 % of the deepest that stays short of the other flank (or
    ``crack``'s own depth, if deeper)."""
    profile = _check(pair, gear).profile
    deepest, step = crack.depth, 0.02 * pair.gear1.module
    while True:  # the deepest crack the tooth holds, to a step of 2 % of a module
        try:
            replace(crack, depth=deepest + step).path(profile)
        except GearsymError:
            break
        deepest += step
    depths = np.linspace(0.0, 0.97 * deepest, count)
    means = np.array([crack_stiffness_loss(pair, gear, float(q), crack.angle, origin=crack.origin,
                                           limit_line=crack.limit_line) for q in depths])
    return depths, means, crack.path(profile).origin[0] / math.sin(crack.angle)
