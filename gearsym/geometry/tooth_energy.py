"""One tooth's compliance along the line of action by the potential-energy method, and the Hertzian contact's.

The tooth is a cantilever of variable thickness 2x(y) on the body, from the root circle to the tip, loaded at
the contact point (x_c, y_c) by a unit force along the line of action, at the load angle tau_c to the x axis
(Yang & Lin 1987; Tian 2004; Chaari, Fakhfakh & Haddar 2009; with the fillet of Ma et al. 2014). The force's
components F cos(tau_c) (across the tooth) and F sin(tau_c) (along it) store the energies of bending, shear and
axial compression in the sections below the contact; each compliance 1/k = 2 U / F^2 is

    1/k_b = integral [cos(tau_c) (y_c - y) - x_c sin(tau_c)]^2 / (E I_y) dy,   I_y = (2x)^3 w / 12
    1/k_s = integral 1.2 cos^2(tau_c) / (G A_y) dy,                          A_y = 2 x w
    1/k_a = integral sin^2(tau_c) / (E A_y) dy

from the root circle (where the body's own deflection, :mod:`.foundation`, takes over) up to the contact,
over the fillet (load-independent moments, :meth:`ToothProfile.fillet_moments`) and the involute (a
Gauss–Legendre rule on [tau_form, tau_c], vectorised over all contacts at once). w is the face width of the
tooth (or of one slice of it). The contact's Hertzian compliance, independent of where along the profile,
is 1/k_h = 4 (1 - nu^2) / (pi E w) for two equal materials (Yang & Lin 1987), and in general
1/k_h = (2 / (pi w)) ((1 - nu_1^2) / E_1 + (1 - nu_2^2) / E_2).

E is the plane-stress Young's modulus, as in Yang & Lin and Tian; G = E / (2 (1 + nu)).
"""
from __future__ import annotations

import math

import numpy as np

from .material import Material
from .profile import ToothProfile
from .quadrature import gauss_legendre


def tooth_compliances(profile: ToothProfile, material: Material, width: float, load_angle,
                      points: int) -> dict[str, np.ndarray]:
    """Bending, shear and axial compliances (m/N) of one tooth of face width ``width`` loaded on its involute at
    the load angles ``load_angle`` (array), each integral with ``points`` Gauss–Legendre nodes per piece."""
    tau = np.asarray(load_angle, dtype=float)
    x_c, y_c, _ = profile.involute(tau)
    c, s = np.cos(tau), np.sin(tau)
    fillet = profile.fillet_moments(points)
    # fillet: the moment arm c (y_c - y) - x_c s = (c Y - d) - c eta, with Y = y_c - y_root and eta = y - y_root
    lead = c * (y_c - fillet.y_root) - x_c * s
    f0, f1, f2 = fillet.bending
    bending = lead * lead * f0 - 2.0 * lead * c * f1 + c * c * f2
    direct = np.full_like(tau, fillet.direct)
    # involute: from the form point up to the contact
    nodes, weights = gauss_legendre(profile.form_parameter, tau, points)
    x, y, dy = profile.involute(nodes)
    arm = c[..., None] * (y_c[..., None] - y) - (x_c * s)[..., None]
    bending = bending + (arm * arm / x ** 3 * dy * weights).sum(-1)
    direct = direct + (dy / x * weights).sum(-1)
    E, G = material.E, material.shear_modulus
    return {
        "bending": 1.5 / (E * width) * bending,  # 12 / (E (2x)^3 w) = 1.5 / (E w x^3)
        "shear": 0.6 * c * c / (G * width) * direct,  # 1.2 / (G 2 x w)
        "axial": 0.5 * s * s / (E * width) * direct,  # 1 / (E 2 x w)
    }


def hertz_compliance(material1: Material, material2: Material, width: float) -> float:
    """1/k_h (m/N) of the line contact of two teeth of face width ``width``."""
    return 2.0 / (math.pi * width) * ((1.0 - material1.nu ** 2) / material1.E + (1.0 - material2.nu ** 2) / material2.E)
