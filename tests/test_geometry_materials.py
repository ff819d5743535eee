"""Gear pairs of two materials and of two racks, and a mesh opened by its centre distance, against the formulas
typed here: ISO 6336-1's q' (Table 9's coefficients), its basic rack factor C_B per gear, its material factor
E = 2 E1 E2 / (E1 + E2) over steel's; the Hertzian compliance of two cylinders of different materials; ISO 21771's
transverse contact ratio at a given centre distance.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize

from gearsym import Gear, Mesh
from gearsym.errors import GearsymWarning
from gearsym.geometry import GearGeometry, GearPair, Material, iso6336_stiffness
from gearsym.geometry.tooth_pair import pair_compliances

DEG = math.pi / 180
E_STEEL = 206e9
BRONZE = Material(E=110e9, nu=0.34, rho=8800.0)
ALUMINIUM = Material(E=70e9, nu=0.33, rho=2700.0)
STEEL = Material(E=206e9, nu=0.3)
#: ISO 6336-1:2006 Table 9, C1 ... C9
C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)


def q_prime(zn1, zn2, x1, x2):
    return (C[0] + C[1] / zn1 + C[2] / zn2 + C[3] * x1 + C[4] * x1 / zn1 + C[5] * x2 + C[6] * x2 / zn2
            + C[7] * x1 ** 2 + C[8] * x2 ** 2)


def rack_factor(dedendum, alpha_deg):
    return (1 + 0.5 * (1.2 - dedendum)) * (1 - 0.02 * (20 - alpha_deg))


def pinion(material=STEEL, **kw):
    return GearGeometry(23, 3e-3, 20 * DEG, 25e-3, **{"profile_shift": 0.35, "dedendum_coefficient": 1.25,
                                                      "material": material, **kw})


def wheel(material=STEEL, **kw):
    return GearGeometry(57, 3e-3, 20 * DEG, 25e-3, **{"profile_shift": 0.15, "dedendum_coefficient": 1.4,
                                                      "fillet_coefficient": 0.39, "material": material, **kw})


def test_iso6336_of_a_steel_pinion_on_a_bronze_wheel_with_both_gears_shifted():
    pair = GearPair(pinion(STEEL), wheel(BRONZE))
    iso = iso6336_stiffness(pair)
    q = q_prime(23, 57, 0.35, 0.15)  # (spur: the virtual numbers of teeth are the numbers of teeth)
    assert iso.q_prime == pytest.approx(q, rel=1e-13)
    assert iso.theoretical == pytest.approx(1 / q, rel=1e-13)
    assert iso.C_B == pytest.approx((rack_factor(1.25, 20) + rack_factor(1.4, 20)) / 2, rel=1e-13)  # 0.9375
    E = 2 * 206e9 * 110e9 / (206e9 + 110e9)
    assert iso.material_factor == pytest.approx(E / E_STEEL, rel=1e-13)  # 0.696
    single = (1 / q) * 0.8 * 1.0 * iso.C_B * E / E_STEEL
    assert iso.single == pytest.approx(single, rel=1e-13)
    assert iso.mesh_alpha == pytest.approx(single * (0.75 * pair.contact_ratio + 0.25), rel=1e-13)
    assert iso.as_dict()["mean_N_per_m"] == pytest.approx(iso.mesh_alpha * 25e-3 * 1e9, rel=1e-13)


def test_the_material_factor_is_the_same_whichever_gear_is_of_which_material():
    ab = iso6336_stiffness(GearPair(pinion(ALUMINIUM), wheel(BRONZE)))
    ba = iso6336_stiffness(GearPair(pinion(BRONZE), wheel(ALUMINIUM)))
    expected = 2 * 70e9 * 110e9 / (70e9 + 110e9) / E_STEEL
    assert ab.material_factor == pytest.approx(expected, rel=1e-13)
    assert ba.material_factor == pytest.approx(expected, rel=1e-13)
    steel = iso6336_stiffness(GearPair(pinion(), wheel()))
    assert steel.material_factor == pytest.approx(1.0, rel=1e-13)
    assert ab.single / steel.single == pytest.approx(expected, rel=1e-12)


def test_the_hertzian_compliance_of_two_materials_is_the_sum_of_each_ones_share():
    """1/k_h = 2/(pi b) [(1 - nu1^2)/E1 + (1 - nu2^2)/E2], whichever gear is of which material."""
    b = 25e-3
    expected = 2 / (math.pi * b) * ((1 - 0.33 ** 2) / 70e9 + (1 - 0.34 ** 2) / 110e9)
    s = np.linspace(1e-3, 5e-3, 3)
    for pair in (GearPair(pinion(ALUMINIUM), wheel(BRONZE)), GearPair(pinion(BRONZE), wheel(ALUMINIUM))):
        hertz = pair_compliances(pair, s, terms="hertz")["hertz"]
        assert hertz == pytest.approx(np.full(3, expected), rel=1e-13)
        slice_ = pair_compliances(pair, s, width=b / 5, terms="hertz")["hertz"]  # (a slice of a fifth of the face)
        assert slice_ == pytest.approx(np.full(3, 5 * expected), rel=1e-13)
    steel = pair_compliances(GearPair(pinion(), wheel()), s, terms="hertz")["hertz"]
    assert steel == pytest.approx(np.full(3, 4 / (math.pi * b) * (1 - 0.09) / 206e9), rel=1e-13)


def contact_ratio_at(z1, z2, m, alpha, x1, x2, a):
    """ISO 21771's transverse contact ratio of a spur pair at the centre distance a (full-height teeth)."""
    d1, d2 = z1 * m, z2 * m
    db1, db2 = d1 * math.cos(alpha), d2 * math.cos(alpha)
    da1, da2 = d1 + 2 * m * (1 + x1), d2 + 2 * m * (1 + x2)
    aw = math.acos((db1 + db2) / (2 * a))
    g = 0.5 * (math.sqrt(da1 ** 2 - db1 ** 2) + math.sqrt(da2 ** 2 - db2 ** 2)) - a * math.sin(aw)
    return g / (math.pi * m * math.cos(alpha))


def tight_centre_distance(z1, z2, m, alpha, x1, x2):
    inv = lambda t: math.tan(t) - t  # noqa: E731
    target = inv(alpha) + 2 * (x1 + x2) / (z1 + z2) * math.tan(alpha)
    aw = optimize.brentq(lambda t: inv(t) - target, 1e-6, 1.5, xtol=1e-15)
    return (z1 + z2) * m / 2 * math.cos(alpha) / math.cos(aw)


def test_a_mesh_from_gears_at_a_wider_centre_distance_has_the_shorter_path_of_contact():
    """Mesh.from_gears(centre_distance=...) computes the stiffness of the pair at that distance: its contact ratio
    is ISO 21771's there, below the tight pair's."""
    dims = dict(module="3 mm", pressure_angle="20 deg", face_width="25 mm", bore_diameter="25 mm")
    a = Gear.from_geometry("pinion", teeth=23, profile_shift=0.35, **dims)
    b = Gear.from_geometry("wheel", teeth=57, profile_shift=0.15, **dims)
    tight = tight_centre_distance(23, 57, 3e-3, 20 * DEG, 0.35, 0.15)
    wide = tight + 0.2e-3
    with pytest.warns(GearsymWarning, match="root angle"):  # (a 23-tooth pinion: Sainsot's fit extrapolated)
        curve = Mesh.from_gears("mesh", a, b, centre_distance=f"{wide * 1e3!r} mm", harmonics=3).computed.curve
        closed = Mesh.from_gears("mesh", a, b, harmonics=3).computed.curve
    assert curve.pair.centre_distance == pytest.approx(wide, rel=1e-12)
    assert curve.contact_ratio == pytest.approx(contact_ratio_at(23, 57, 3e-3, 20 * DEG, 0.35, 0.15, wide),
                                                rel=1e-10)
    assert closed.pair.centre_distance == pytest.approx(tight, rel=1e-12)
    assert closed.contact_ratio == pytest.approx(contact_ratio_at(23, 57, 3e-3, 20 * DEG, 0.35, 0.15, tight),
                                                 rel=1e-10)
    assert curve.contact_ratio < closed.contact_ratio - 0.05
