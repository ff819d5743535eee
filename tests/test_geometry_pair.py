"""Gear and pair geometry against the closed forms of ISO 21771, written here; and the one-line refusals."""
from __future__ import annotations

import math
import warnings

import pytest
from scipy import optimize

import gearsym
from gearsym.errors import GearsymError, GearsymWarning
from gearsym.geometry import GearGeometry, GearPair, gear_geometry, gear_pair

DEG = math.pi / 180


def closed_form(z1, z2, m, alpha_n, b, x1=0.0, x2=0.0, beta=0.0, a=None, ha=1.0):
    """eps_alpha, eps_beta and a_w from ISO 21771's formulas (the involute inverted by SciPy's brentq)."""
    inv = lambda t: math.tan(t) - t  # noqa: E731
    at = math.atan(math.tan(alpha_n) / math.cos(beta))
    d1, d2 = z1 * m / math.cos(beta), z2 * m / math.cos(beta)
    db1, db2 = d1 * math.cos(at), d2 * math.cos(at)
    da1, da2 = d1 + 2 * m * (ha + x1), d2 + 2 * m * (ha + x2)
    if a is None:
        target = inv(at) + 2 * (x1 + x2) / (z1 + z2) * math.tan(alpha_n)
        awt = optimize.brentq(lambda t: inv(t) - target, 1e-6, 1.5, xtol=1e-15)
        a = (d1 + d2) / 2 * math.cos(at) / math.cos(awt)
    else:
        awt = math.acos((db1 + db2) / (2 * a))
    g = 0.5 * (math.sqrt(da1 ** 2 - db1 ** 2) + math.sqrt(da2 ** 2 - db2 ** 2)) - a * math.sin(awt)
    eps_a = g / (math.pi * m / math.cos(beta) * math.cos(at))
    eps_b = b * math.sin(beta) / (math.pi * m)
    return eps_a, eps_b, a


PAIRS = [  # z1, z2, m, alpha_n, b, x1, x2, beta
    (28, 28, 3.175e-3, 20 * DEG, 6.35e-3, 0.0, 0.0, 0.0),
    (19, 48, 3.2e-3, 20 * DEG, 16e-3, 0.25, -0.1, 0.0),
    (25, 83, 2.5e-3, 25 * DEG, 30e-3, 0.2, 0.1, 0.0),
    (26, 61, 3e-3, 20 * DEG, 40e-3, 0.1, 0.3, 15 * DEG),
    (31, 45, 5e-3, 20 * DEG, 60e-3, 0.0, 0.0, 30 * DEG),
]


@pytest.mark.parametrize("case", PAIRS, ids=lambda c: f"{c[0]}-{c[1]}-beta{round(c[7] / DEG)}")
def test_contact_ratios_and_centre_distance_are_the_closed_forms(case):
    z1, z2, m, alpha, b, x1, x2, beta = case
    rho = 0.25 if alpha > 21 * DEG else 0.38
    pair = GearPair(GearGeometry(z1, m, alpha, b, x1, beta, fillet_coefficient=rho),
                    GearGeometry(z2, m, alpha, b, x2, -beta, fillet_coefficient=rho))
    eps_a, eps_b, a = closed_form(z1, z2, m, alpha, b, x1, x2, beta)
    assert pair.centre_distance == pytest.approx(a, rel=1e-13, abs=0)
    assert pair.contact_ratio == pytest.approx(eps_a, rel=1e-12, abs=0)
    assert pair.overlap_ratio == pytest.approx(eps_b, rel=1e-13, abs=1e-15)
    assert pair.total_contact_ratio == pytest.approx(eps_a + eps_b, rel=1e-12, abs=0)
    # a wider centre distance (backlash) shortens the path of contact
    wide = GearPair(pair.gear1, pair.gear2, a + 0.1 * m)
    assert wide.contact_ratio == pytest.approx(closed_form(z1, z2, m, alpha, b, x1, x2, beta, a=a + 0.1 * m)[0],
                                               rel=1e-12, abs=0)
    assert wide.contact_ratio < pair.contact_ratio


def test_a_gear_body_is_isos_disk_of_the_mean_diameter_less_its_bore():
    gear = GearGeometry(40, 2e-3, 20 * DEG, 25e-3, profile_shift=0.2, bore_diameter=30e-3)
    d, d_a, d_f = 80e-3, 80e-3 + 2 * 2e-3 * 1.2, 80e-3 - 2 * 2e-3 * 1.05
    d_m = (d_a + d_f) / 2
    mass = 7850 * math.pi / 4 * (d_m ** 2 - 0.03 ** 2) * 25e-3
    assert gear.mass == pytest.approx(mass, rel=1e-13, abs=0)
    assert gear.polar_inertia == pytest.approx(mass * (d_m ** 2 + 0.03 ** 2) / 8, rel=1e-13, abs=0)
    assert (2 * gear.tip_radius, 2 * gear.root_radius, 2 * gear.reference_radius) == pytest.approx((d_a, d_f, d),
                                                                                                 rel=1e-14, abs=0)
    assert gear.base_radius == pytest.approx(0.04 * math.cos(20 * DEG), rel=1e-15, abs=0)


def test_the_mesh_frequency_is_the_tooth_count_times_the_speed():
    g = GearGeometry(28, 3.175e-3, 20 * DEG, 6.35e-3)
    pair = GearPair(g, GearGeometry(35, 3.175e-3, 20 * DEG, 6.35e-3))
    assert pair.teeth == 28 and pair.mesh_frequency(6000 / 60) == pytest.approx(2800.0)
    assert pair.ratio == pytest.approx(35 / 28)


def test_the_face_takes_pint_quantities_and_refuses_text():
    from gearsym.units import Quantity

    g = gear_geometry(teeth=28, module=Quantity(3.175, "mm"), pressure_angle=Quantity(20, "deg"),
                      face_width=Quantity(0.25, "inch"))
    assert g.module == pytest.approx(3.175e-3, rel=1e-14, abs=0)
    assert g.pressure_angle == pytest.approx(20 * DEG, rel=1e-14, abs=0)
    assert g.face_width == pytest.approx(6.35e-3, rel=1e-14, abs=0)
    assert gear_pair(g, g, Quantity(88.9, "mm")).centre_distance == pytest.approx(0.0889, rel=1e-14, abs=0)
    with pytest.raises(GearsymError, match="text"):
        gear_geometry(teeth=28, module="3 mm", pressure_angle=0.3, face_width=0.01)
    with pytest.raises(GearsymError, match="not in m"):
        gear_geometry(teeth=28, module=Quantity(3, "s"), pressure_angle=0.3, face_width=0.01)
    assert gearsym.GearGeometry is GearGeometry and gearsym.mesh_stiffness is not None


def _error(**changes) -> str:
    base = dict(teeth=28, module=3e-3, pressure_angle=20 * DEG, face_width=10e-3)
    with pytest.raises(GearsymError) as info:
        GearGeometry(**{**base, **changes})
    message = str(info.value)
    assert "\n" not in message
    return message


def test_a_gear_that_cannot_be_made_is_refused_with_one_line():
    assert "at least 6" in _error(teeth=4)
    assert "whole number" in _error(teeth=2.5)
    assert "metres" in _error(module=3.0)
    assert "radians" in _error(pressure_angle=20.0)
    assert "positive" in _error(face_width=0.0)
    assert "root circle" in _error(bore_diameter=0.1)
    assert "point" in _error(profile_shift=0.8, teeth=8)
    assert "fit on its tip" in _error(fillet_coefficient=0.6)
    assert "finite" in _error(module=float("nan"))


def test_undercut_and_a_thin_tip_are_warned_about():
    with pytest.warns(GearsymWarning, match="undercut.*profile shift of at least 0.298"):
        GearGeometry(12, 3e-3, 20 * DEG, 10e-3)
    with pytest.warns(GearsymWarning, match="tip"):
        GearGeometry(10, 3e-3, 20 * DEG, 10e-3, profile_shift=0.6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        GearGeometry(17, 3e-3, 20 * DEG, 10e-3, profile_shift=0.01)  # just above z_min


def _pair_error(g1, g2, a=None) -> str:
    with pytest.raises(GearsymError) as info:
        GearPair(g1, g2, a)
    assert "\n" not in str(info.value)
    return str(info.value)


def test_a_pair_that_cannot_mesh_is_refused_with_one_line():
    g = GearGeometry(28, 3e-3, 20 * DEG, 10e-3)
    assert "modules differ" in _pair_error(g, GearGeometry(28, 2e-3, 20 * DEG, 10e-3))
    assert "pressure angles differ" in _pair_error(g, GearGeometry(28, 3e-3, 25 * DEG, 10e-3, fillet_coefficient=0.25))
    assert "helix angles differ" in _pair_error(g, GearGeometry(28, 3e-3, 20 * DEG, 10e-3, helix_angle=0.2))
    assert "jam" in _pair_error(g, g, 0.083)
    stub = GearGeometry(7, 3e-3, 20 * DEG, 10e-3, addendum_coefficient=0.6, dedendum_coefficient=0.85,
                        profile_shift=0.4, fillet_coefficient=0.2)
    assert "contact ratio" in _pair_error(stub, stub)
    with pytest.warns(GearsymWarning, match="undercut"):
        small = GearGeometry(9, 3e-3, 20 * DEG, 10e-3)
    assert "below its involute" in _pair_error(small, GearGeometry(90, 3e-3, 20 * DEG, 10e-3))


def test_helices_of_the_same_hand_do_not_mesh_externally():
    right = GearGeometry(28, 3e-3, 20 * DEG, 20e-3, helix_angle=15 * DEG)
    error = _pair_error(right, GearGeometry(40, 3e-3, 20 * DEG, 20e-3, helix_angle=15 * DEG))
    assert error == ("gear pair: the helices have the same hand (15 and 15 deg: the sign is the hand); an external "
                     "pair meshes with opposite hands: give gear 2 -15 deg")
    GearPair(right, GearGeometry(40, 3e-3, 20 * DEG, 20e-3, helix_angle=-15 * DEG))  # (opposite hands: a pair)


def test_a_bore_that_leaves_no_rim_is_refused_and_a_pinhole_bore_is_a_solid_body():
    """A rim under half the tooth height is refused (ISO 6336-3's rim factor ends there); a bore so small that
    Sainsot's root-to-bore ratio passes the fit's 7 is taken at 7, as a solid gear is (the fit's h^2 terms made a
    1e-9 mm bore's mesh stiffness 1.6e-31 N/m, and 1 mm's a 178 Hz mode where the solid pair has 5174 Hz)."""
    from gearsym.geometry import mesh_stiffness

    nasa = dict(teeth=28, module=3.175e-3, pressure_angle=20 * DEG, face_width=6.35e-3)
    with pytest.raises(GearsymError, match=r"the bore \(75 mm\) leaves a rim of 2.98 mm under the teeth, less than "
                                           r"0.5 of their height \(7.14 mm; .*give a bore of at most 73.82 mm"):
        GearGeometry(**nasa, bore_diameter=75e-3)

    def mean(bore):
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            gear = GearGeometry(**nasa, bore_diameter=bore)
            value = mesh_stiffness(GearPair(gear, gear)).mean
        return value, " ".join(str(w.message) for w in said)

    solid, _ = mean(0.0)
    for bore, ratio in ((1e-12, "8.1e+10"), (1e-3, "81")):
        value, said = mean(bore)
        assert value == pytest.approx(solid, rel=1e-12)
        assert f"root radius / bore radius = {ratio}, beyond the 1.4-7 of Sainsot's body formula" in said
    within, said = mean(20e-3)
    assert "Sainsot" not in said and within > solid  # (h = 4: a body held nearer the teeth is stiffer)
