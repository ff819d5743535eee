"""A tooth root crack through the gear geometry (issue 28): the cracked tooth's compliances by the potential-energy
method (Chen & Shao 2011's sections: the loaded side cut at the crack tip's distance from the centre line) against
SciPy's adaptive quadrature of the same integrals typed here; no crack, no change; a deeper crack takes more; a
crack past the centre line is refused; and the loss it implies is the depth of a ToothFault in the model."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import gearsym
from gearsym import Drivetrain, Gear, Harmonic, Mesh, ToothFault, Torque
from gearsym.errors import GearsymError
from gearsym.geometry import Crack, crack_stiffness_loss, gear_geometry, gear_pair, pair_compliances
from gearsym.geometry.crack import crack_stiffness_loss as loss_in_si
from gearsym.geometry.crack import cracked_pair_stiffness, cracked_tooth_compliances
from gearsym.geometry.tooth_energy import tooth_compliances

WIDTH = 20e-3


@pytest.fixture(scope="module")
def pair():
    pinion = gear_geometry(teeth=20, module=3e-3, pressure_angle=math.radians(20), face_width=WIDTH)
    wheel = gear_geometry(teeth=53, module=3e-3, pressure_angle=math.radians(20), face_width=WIDTH)
    return gear_pair(pinion, wheel)


def typed_compliances(profile, material, tau_c: float, h: float) -> dict[str, float]:
    """The cracked tooth's compliances at one load angle, by SciPy's quad over the fillet (in its normal angle
    gamma) and the involute (in tau), the section's thickness x + min(x, h) typed here from Chen & Shao."""
    x_c, y_c, _ = profile.involute(np.array(tau_c))
    c, s = math.cos(tau_c), math.sin(tau_c)

    def integrand(piece, kind):
        def f(u):
            x, y, dy = (float(v) for v in piece(np.array(u)))
            t = x + min(x, h)  # the loaded thickness
            if kind == "bending":
                arm = c * (y_c - y) - x_c * s
                return 12 * arm * arm / t ** 3 * dy
            return dy / t
        return f

    out = {}
    for kind in ("bending", "direct"):
        fillet = -quad(integrand(profile.fillet, kind), profile.junction, math.pi / 2, limit=400, epsabs=0,
                       epsrel=1e-12)[0]
        involute = quad(integrand(profile.involute, kind), profile.form_parameter, tau_c, limit=400, epsabs=0,
                        epsrel=1e-12)[0]
        out[kind] = fillet + involute
    E, G = material.E, material.shear_modulus
    return {"bending": out["bending"] / (E * WIDTH), "shear": 1.2 * c * c * out["direct"] / (G * WIDTH),
            "axial": s * s * out["direct"] / (E * WIDTH)}


@pytest.mark.parametrize("depth_mm,angle_deg", [(1.0, 70), (2.5, 45), (3.5, 70)])
def test_a_cracked_tooths_compliances_are_those_of_an_independent_quadrature(pair, depth_mm, angle_deg):
    g = pair.gear1
    crack = Crack(depth_mm * 1e-3, math.radians(angle_deg))
    h = crack.tip(g.profile)
    root = float(g.profile.fillet(np.array(math.pi / 2))[0])
    assert h == pytest.approx(root - depth_mm * 1e-3 * math.sin(math.radians(angle_deg)), rel=1e-15)
    taus = np.linspace(g.profile.form_parameter + 0.02, g.profile.tip_parameter, 4)
    ours = cracked_tooth_compliances(g.profile, g.material, WIDTH, taus, 24, crack)
    healthy = tooth_compliances(g.profile, g.material, WIDTH, taus, 24)
    for k, tau in enumerate(taus):
        typed = typed_compliances(g.profile, g.material, float(tau), h)
        for name in ("bending", "shear", "axial"):
            assert ours[name][k] == pytest.approx(typed[name], rel=1e-7), (name, tau)
            assert ours[name][k] > healthy[name][k]  # a crack only softens


def test_no_crack_changes_nothing_and_a_deeper_crack_takes_more(pair):
    taus = np.linspace(pair.gear2.profile.form_parameter + 0.01, pair.gear2.profile.tip_parameter, 5)
    zero = cracked_tooth_compliances(pair.gear2.profile, pair.gear2.material, WIDTH, taus, 24, Crack(0.0, 1.2))
    healthy = tooth_compliances(pair.gear2.profile, pair.gear2.material, WIDTH, taus, 24)
    for name in healthy:
        np.testing.assert_allclose(zero[name], healthy[name], rtol=1e-13)
    s = np.linspace(*pair.path_of_contact, 7)
    np.testing.assert_allclose(cracked_pair_stiffness(pair, s, 1, Crack(0.0, 1.2)),
                               1 / sum(pair_compliances(pair, s).values()), rtol=1e-13)
    losses = [crack_stiffness_loss(pair, 1, q * 1e-3, math.radians(70)) for q in (0.0, 1.0, 2.0, 3.0, 4.0)]
    assert abs(losses[0]) < 1e-15 and all(0 < a < b < 1 for a, b in zip(losses[1:], losses[2:]))
    # the same crack takes less from the wheel's thicker tooth than from the pinion's
    assert 0 < crack_stiffness_loss(pair, 2, 3e-3, math.radians(70)) < losses[3]


def test_a_crack_past_the_centre_line_or_a_wrong_angle_is_refused(pair):
    with pytest.raises(GearsymError, match="reaches past the tooth's centre line"):
        crack_stiffness_loss(pair, 1, 6e-3, math.radians(80))
    with pytest.raises(GearsymError, match=r"angle 70 rad must lie in \(0, pi/2\]"):
        Crack(1e-3, 70)
    with pytest.raises(GearsymError, match="gear must be 1 or 2"):
        crack_stiffness_loss(pair, 3, 1e-3, 1.0)


def test_the_cracks_loss_is_the_depth_of_a_tooth_fault_in_the_model(pair):
    """Through the face, in the user's units: the loss of a 3 mm crack at 70 degrees on the wheel's tooth becomes the
    ToothFault's depth, so the model's mesh stiffness while that pair alone is in mesh is k (1 - loss)."""
    import pint

    units = pint.UnitRegistry()
    loss = gearsym.crack_stiffness_loss(pair, 2, 3 * units.mm, 70 * units.deg)
    assert loss == loss_in_si(pair, 2, 3e-3, math.radians(70)) and 0 < loss < 0.2
    m = Drivetrain("cracked_by_geometry")
    g1 = m.add(Gear("gear1", inertia="I1", base_radius="r1", teeth=20))
    g2 = m.add(Gear("gear2", inertia="I2", base_radius="r2", teeth=53))
    m.add(Mesh("mesh", g1, g2, stiffness="kZ", damping="cZ", backlash="eta"))
    m.add(Torque("M1", on=g1, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    m.add(Torque("M2", on=g2, mean="M2", load=True))
    m.add(ToothFault("crack", g2, tooth=7, depth=loss))
    m.set_defaults(omega=1.5, zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.0)
    system = gearsym.load(m)
    (mesh,) = system.meshes
    k = mesh.stiffness.xreplace({p: system.parameters[p.name] for p in mesh.stiffness.free_symbols
                                 if p.name in system.parameters})
    t = system.time
    assert k.free_symbols == {t}
    single = 2 * math.pi * 6.5  # the middle of tooth 7's mesh period: its pair alone in mesh
    assert float(k.subs(t, single)) == pytest.approx(1 - loss, rel=1e-4)  # (the windows' tanh edges: 1 - 2e-5)
    assert float(k.subs(t, single + 2 * math.pi * 3)) == pytest.approx(1.0, rel=1e-4)  # three teeth on: healthy
