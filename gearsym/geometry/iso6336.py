"""ISO 6336-1 (method B): the single stiffness c' and the mesh stiffness c_gamma_alpha, c_gamma_beta of a pair.

In ISO's units, N/(mm um) per unit face width (ISO 6336-1:2006, clause 9):

* the theoretical single stiffness of solid steel spur gears on the basic rack, c'_th = 1 / q', with
  q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1^2 + C9 x2^2 (mm um / N),
  z_n the virtual numbers of teeth (Table 9 of the standard: :data:`Q_COEFFICIENTS`);
* the single stiffness c' = c'_th C_M C_R C_B cos(beta), with the correction factor C_M = 0.8 (theory against
  measurement), the gear blank factor C_R (1 for solid disc gears; 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n))) for a
  web of width b_s and a rim of thickness s_R, with 0.2 <= b_s/b <= 1.2 and s_R/m_n >= 1), the basic rack
  factor C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_n)] (the mean of the two gears'), and, for
  a line load F_t K_A / b below 100 N/mm, the factor (F_t K_A / b / 100)^0.25; for other materials than steel
  on steel c' scales with E = 2 E1 E2 / (E1 + E2) over E_steel = 206 000 N/mm^2;
* the mean mesh stiffness c_gamma_alpha = c' (0.75 eps_alpha + 0.25) (for eps_alpha >= 1.2; below, ISO says it
  may be up to 10 % less), c_gamma_beta = 0.85 c_gamma_alpha.

The equations for q' hold for x1 >= x2 and -0.5 <= x1 + x2 <= 2.0 (notes say when a pair is outside). The
worked example of ISO/TR 6336-30 is a test (tests/test_geometry_iso6336.py).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from .pair import GearPair

#: ISO 6336-1 Table 9: C1 ... C9 of q' (mm um / N)
Q_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
#: the correction factor C_M for solid disc gears
C_M = 0.8
#: Young's modulus of the steel the formulas are for, Pa
E_STEEL = 2.06e11
#: N/(mm um) -> N/m per metre of face width: c [N/(mm um)] * b [m] * 1e9 = k [N/m]
PER_WIDTH_TO_SI = 1e9


@dataclass(frozen=True)
class Iso6336Stiffness:
    """ISO 6336-1 method B for one pair; stiffnesses in N/(mm um), q' in mm um / N."""

    q_prime: float
    theoretical: float
    C_M: float
    C_R: float
    C_B: float
    load_factor: float
    material_factor: float
    single: float
    mesh_alpha: float
    mesh_beta: float
    face_width: float
    notes: tuple[str, ...] = ()

    @property
    def mean_stiffness(self) -> float:
        """c_gamma_alpha over the face width, in N/m."""
        return self.mesh_alpha * self.face_width * PER_WIDTH_TO_SI

    def as_dict(self) -> dict:
        """JSON-ready: the stiffnesses in N/(mm um) (keys c_th, c_prime, c_gamma_alpha, c_gamma_beta), the factors,
        and c_gamma_alpha times the face width in N/m."""
        d = asdict(self)
        return {"unit": "N/(mm um)", "q_prime": d["q_prime"], "c_th": d["theoretical"], "C_M": d["C_M"],
                "C_R": d["C_R"], "C_B": d["C_B"], "load_factor": d["load_factor"],
                "material_factor": d["material_factor"], "c_prime": d["single"], "c_gamma_alpha": d["mesh_alpha"],
                "c_gamma_beta": d["mesh_beta"], "mean_N_per_m": self.mean_stiffness, "notes": list(self.notes)}


def basic_rack_factor(dedendum_coefficient: float, pressure_angle: float) -> float:
    """C_B of one gear: [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 - alpha_n in degrees)]."""
    return (1.0 + 0.5 * (1.2 - dedendum_coefficient)) * (1.0 - 0.02 * (20.0 - math.degrees(pressure_angle)))


def blank_factor(web_ratio: float | None = None, rim_ratio: float | None = None) -> float:
    """C_R: 1 for a solid disc; with a web (``web_ratio`` = b_s / b) and a rim (``rim_ratio`` = s_R / m_n),
    1 + ln(b_s/b) / (5 exp(s_R / (5 m_n))), the ratios held to ISO's ranges (0.2-1.2 and >= 1)."""
    if web_ratio is None:
        return 1.0
    web = min(max(web_ratio, 0.2), 1.2)
    rim = max(1.0 if rim_ratio is None else rim_ratio, 1.0)
    return 1.0 + math.log(web) / (5.0 * math.exp(rim / 5.0))


def iso6336_stiffness(pair: GearPair, *, line_load: float | None = None, web_ratio: float | None = None,
                      rim_ratio: float | None = None) -> Iso6336Stiffness:
    """ISO 6336-1 method B for ``pair``. ``line_load``: F_t K_A / b in N/mm (None: at least 100 N/mm, no
    correction); ``web_ratio``, ``rim_ratio``: see :func:`blank_factor` (None: solid disc gears, C_R = 1)."""
    g1, g2 = pair.gear1, pair.gear2
    notes = []
    C = Q_COEFFICIENTS
    zn1, zn2, x1, x2 = g1.virtual_teeth, g2.virtual_teeth, g1.profile_shift, g2.profile_shift
    q = (C[0] + C[1] / zn1 + C[2] / zn2 + C[3] * x1 + C[4] * x1 / zn1 + C[5] * x2 + C[6] * x2 / zn2
         + C[7] * x1 ** 2 + C[8] * x2 ** 2)
    if x1 < x2 or not -0.5 <= x1 + x2 <= 2.0:
        notes.append(f"ISO 6336-1's q' holds for x1 >= x2 and -0.5 <= x1 + x2 <= 2; here x1 = {x1:g}, x2 = {x2:g}")
    theoretical = 1.0 / q
    C_R = blank_factor(web_ratio, rim_ratio)
    C_B = 0.5 * (basic_rack_factor(g1.dedendum_coefficient, g1.pressure_angle)
                 + basic_rack_factor(g2.dedendum_coefficient, g2.pressure_angle))
    load = 1.0 if line_load is None or line_load >= 100.0 else (line_load / 100.0) ** 0.25
    E1, E2 = g1.material.E, g2.material.E
    material = (2.0 * E1 * E2 / (E1 + E2)) / E_STEEL
    single = theoretical * C_M * C_R * C_B * math.cos(g1.helix_angle) * load * material
    eps = pair.contact_ratio
    if eps < 1.2:
        notes.append(f"eps_alpha = {eps:.3f} < 1.2: ISO 6336-1 says c_gamma_alpha may then be up to 10 % smaller")
    mesh_alpha = single * (0.75 * eps + 0.25)
    return Iso6336Stiffness(q, theoretical, C_M, C_R, C_B, load, material, single, mesh_alpha, 0.85 * mesh_alpha,
                            pair.face_width, tuple(notes))
