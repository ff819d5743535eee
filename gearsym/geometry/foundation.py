"""The deflection of the gear body under a tooth: Sainsot, Velex & Duverger's fillet-foundation formula.

P. Sainsot, P. Velex, O. Duverger, *Contribution of gear body to tooth deflections — a new bidimensional
analytical formula*, Journal of Mechanical Design 126 (2004) 748–752, doi:10.1115/1.1758252. From
finite-element results on a ring (the body between the root circle and the bore, held at the bore) they fit

    1/k_f = cos^2(tau_c) / (E w) [ L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2(tau_c)) ]

with X* = A / theta_f^2 + B h_fi^2 + C h_fi / theta_f + D / theta_f + E h_fi + F for X* in (L*, M*, P*, Q*) and
the coefficients of :data:`COEFFICIENTS` (as in Chaari et al. 2009 and ROSS's ``GearElementTVMS``), where

* h_fi = r_f / r_int: the root radius over the body's inner radius (the bore);
* theta_f: the angle between the tooth's centre line and where the fillet meets the root circle;
* S_f = 2 r_f sin(theta_f): the tooth's thickness at the root circle;
* u_f: the distance, along the centre line, from the root circle to where the line of action crosses it,
  u_f = r_b / cos(tau_c) - r_f (the lever arm of the force about the root, so that the L* term is the body's
  rotation under the tooth's moment; some implementations take the contact point's height instead).

**Validity.** The finite-element cases behind the fit span h_fi in [1.4, 7] and theta_f in [0.01, 0.12] rad
(:data:`BODY_RATIO_RANGE`, :data:`ROOT_ANGLE_RANGE`; the bounds ROSS's implementation checks). theta_f is about
3.0 / z for an ISO 53 rack, so gears of fewer than 25 teeth lie outside; a gear with a large bore (a thin rim,
h_fi < 1.4) too; there the polynomial is extrapolated and a warning says so (a rim thinner than half the tooth
height is refused by :class:`~.gear.GearGeometry`). A solid gear has no inner radius (h_fi infinite, where the
fit has no value): it is evaluated at h_fi = 7, the edge of the fitted range, and a warning names that
assumption (give the bore, or the shaft's diameter, for the gear's own value). So is a bore small enough to put
h_fi beyond 7: the fit's h_fi^2 terms grow without bound (at a bore of 1 um the body alone would make the mesh
stiffness 1e-30 N/m), while a body held at a smaller bore is only closer to a solid one.
"""
from __future__ import annotations

import math

import numpy as np

from .gear import GearGeometry

#: Sainsot et al. 2004: (A, B, C, D, E, F) of L*, M*, P*, Q*
COEFFICIENTS = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}
#: the range of h_fi = r_f / r_int and of theta_f (rad) the fit was made on
BODY_RATIO_RANGE = (1.4, 7.0)
ROOT_ANGLE_RANGE = (0.01, 0.12)


def coefficients(body_ratio: float, root_angle: float) -> tuple[float, float, float, float]:
    """(L*, M*, P*, Q*) at h_fi = ``body_ratio`` and theta_f = ``root_angle``."""
    h, t = body_ratio, root_angle
    return tuple(A / t ** 2 + B * h ** 2 + C * h / t + D / t + E * h + F
                 for A, B, C, D, E, F in (COEFFICIENTS[k] for k in "LMPQ"))


def body_ratio(gear: GearGeometry) -> tuple[float, list[str]]:
    """h_fi for ``gear``, and what is outside the fit's range (as sentences for a warning)."""
    notes = []
    low, high = BODY_RATIO_RANGE
    if gear.bore_diameter == 0.0:
        ratio = high
        notes.append(f"the {gear.teeth}-tooth gear is solid: Sainsot's body formula needs a bore, so the body is taken "
                     f"as the thickest the fit covers (root radius / bore radius = {high:g}); give its bore for its own")
    else:
        ratio = gear.root_radius / (0.5 * gear.bore_diameter)
        if ratio > high:  # (the fit's h^2 terms grow without bound: a body held at a pinhole bore is not that soft)
            notes.append(f"the {gear.teeth}-tooth gear's bore ({gear.bore_diameter * 1e3:.3g} mm) gives root radius / "
                         f"bore radius = {ratio:.3g}, beyond the {low:g}-{high:g} of Sainsot's body formula, whose "
                         f"terms grow without bound there: the body is taken as the thickest the fit covers "
                         f"({high:g}, as for a solid gear)")
            ratio = high
        elif ratio < low:
            notes.append(f"the {gear.teeth}-tooth gear's root radius / bore radius = {ratio:.3g} is below the "
                         f"{low:g}-{high:g} of Sainsot's body formula (a thin rim): its deflection is extrapolated")
    theta = gear.profile.root_angle
    lo, hi = ROOT_ANGLE_RANGE
    if not lo <= theta <= hi:
        notes.append(f"the {gear.teeth}-tooth gear's root angle theta_f = {theta:.3g} rad is outside the {lo:g}-{hi:g} "
                     "of Sainsot's body formula: its deflection is extrapolated")
    return ratio, notes


def foundation_compliance(gear: GearGeometry, width: float, load_angle, ratio: float) -> np.ndarray:
    """1/k_f (m/N) of the body under a tooth of face width ``width`` loaded at the load angles ``load_angle``,
    at h_fi = ``ratio`` (from :func:`body_ratio`)."""
    profile = gear.profile
    tau = np.asarray(load_angle, dtype=float)
    L, M, P, Q = coefficients(ratio, profile.root_angle)
    r_f = profile.root_radius
    s_f = 2.0 * r_f * math.sin(profile.root_angle)
    u = (profile.base_radius / np.cos(tau) - r_f) / s_f
    c = np.cos(tau)
    return c * c / (gear.material.E * width) * (L * u * u + M * u + P * (1.0 + Q * np.tan(tau) ** 2))
