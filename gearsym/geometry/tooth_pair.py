"""The stiffness of one pair of teeth in contact, as a function of where the contact is on the line of action.

The pair's compliances add in series (Yang & Lin 1987; Tian 2004):

    1/k = 1/k_h + sum over the two gears (1/k_b + 1/k_s + 1/k_a + 1/k_f),

the Hertzian contact's, then each tooth's bending, shear and axial compression (:mod:`.tooth_energy`) and its
body's (:mod:`.foundation`). A contact at distance s from T1 on the line of action touches gear 1 at the roll
angle s / r_b1 and gear 2 at (T1T2 - s) / r_b2; the load angle of each is its roll angle minus psi_b.
"""
from __future__ import annotations

import numpy as np

from ..errors import GearsymError
from .foundation import body_ratio, foundation_compliance
from .pair import GearPair
from .tooth_energy import hertz_compliance, tooth_compliances

#: the compliances a pair of teeth is made of (any subset can be asked for, e.g. for the limits in the tests)
TERMS = ("hertz", "bending", "shear", "axial", "foundation")
#: Gauss–Legendre nodes per piece of the profile (fillet, involute): converged to ~1e-10 (tests/test_geometry_energy.py)
QUADRATURE_POINTS = 24


def check_terms(terms) -> tuple[str, ...]:
    """``terms`` as a tuple of names from :data:`TERMS`, or a one-line error."""
    if isinstance(terms, str):
        terms = (terms,)
    terms = tuple(terms)
    unknown = [t for t in terms if t not in TERMS]
    if unknown or not terms:
        raise GearsymError(f"unknown stiffness terms {', '.join(map(repr, unknown)) or '(none given)'}; "
                           f"choose from {', '.join(TERMS)}")
    return terms


def pair_compliances(pair: GearPair, positions, *, width: float | None = None, points: int = QUADRATURE_POINTS,
                     terms=TERMS) -> dict[str, np.ndarray]:
    """Each compliance (m/N) of one pair of teeth of face width ``width`` (default: the pair's) in contact at
    ``positions`` (m from T1 on the line of action, array): keys 'hertz' and 'bending1', ..., 'foundation2'."""
    terms = check_terms(terms)
    s = np.asarray(positions, dtype=float)
    w = pair.face_width if width is None else width
    out: dict[str, np.ndarray] = {}
    if "hertz" in terms:
        out["hertz"] = np.full_like(s, hertz_compliance(pair.gear1.material, pair.gear2.material, w))
    for index, gear, along in ((1, pair.gear1, s), (2, pair.gear2, pair.line_of_action - s)):
        tau = along / gear.base_radius - gear.half_base_angle
        if {"bending", "shear", "axial"} & set(terms):
            parts = tooth_compliances(gear.profile, gear.material, w, tau, points)
            for name in ("bending", "shear", "axial"):
                if name in terms:
                    out[f"{name}{index}"] = parts[name]
        if "foundation" in terms:
            out[f"foundation{index}"] = foundation_compliance(gear, w, tau, body_ratio(gear)[0])
    return out


def pair_stiffness(pair: GearPair, positions, *, width: float | None = None, points: int = QUADRATURE_POINTS,
                   terms=TERMS) -> np.ndarray:
    """The stiffness (N/m) of one pair of teeth in contact at ``positions`` (see :func:`pair_compliances`)."""
    parts = pair_compliances(pair, positions, width=width, points=points, terms=terms)
    return 1.0 / sum(parts.values())
