"""The static solution where the shipped models do not go: a stiffness variation whose mean is not 1, a load that
presses the teeth onto their back flank, a harmonic torque beside the mean ones.

A gear pair under balanced mean torques (M2 = M1 r2 / r1) carries the mesh force F = M1 / r1, so at rest
k_mean g(d) = F with k_mean the stiffness times the variation's mean over a mesh period: on the drive flank
d = F / k_mean, on the back flank (F < 0) g(d) = d + eta gives d = F / k_mean - eta. The mean is integrated
here by SciPy's quad, not sampled.
"""
from __future__ import annotations

import math

import pytest
from scipy.integrate import quad

import gearsym
from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque
from gearsym.reduction.statics import static_state, torque_imbalance

VARIATION = "1.3 + 0.2*cos(phi) + 0.1*cos(phi)**2 + kw*sin(3*phi)"
VALUES = dict(I1=1e-3, I2=4e-3, r1=0.03, r2=0.06, kZ=2e8, cZ=500.0, eta=5e-5, kw=0.05)


def variation(phi: float) -> float:
    return 1.3 + 0.2 * math.cos(phi) + 0.1 * math.cos(phi) ** 2 + VALUES["kw"] * math.sin(3 * phi)


#: 1.35: the mean of the variation over a mesh period, by quadrature
MEAN = quad(variation, 0.0, 2 * math.pi, epsabs=1e-13, epsrel=1e-13, limit=200)[0] / (2 * math.pi)


@pytest.fixture(scope="module")
def pair():
    m = Drivetrain("flanks")
    a = m.add(Gear("pinion", inertia="I1", base_radius="r1"))
    b = m.add(Gear("wheel", inertia="I2", base_radius="r2"))
    m.add(Mesh("mesh", a, b, stiffness="kZ", damping="cZ", backlash="eta", variation=VARIATION, coordinate="x"))
    m.add(Torque("M1", on=a, mean="M1", harmonics=(Harmonic("M1a", phase="Theta"),)))
    m.add(Torque("M2", on=b, mean="M2", load=True))
    return gearsym.reduce(m).reduction


def loaded(M1: float, **extra) -> dict:
    """The values with a mean torque M1 on the pinion, balanced by the wheel's load, and a harmonic beside it."""
    return {**VALUES, "M1": M1, "M2": M1 * VALUES["r2"] / VALUES["r1"], "M1a": 0.7 * abs(M1), "Theta": 0.3, **extra}


def test_the_mean_of_the_variation_is_the_stiffness_at_rest_on_the_drive_flank(pair):
    assert MEAN == pytest.approx(1.35, abs=1e-12)
    values = loaded(60.0)
    assert not torque_imbalance(pair, values)
    rest = static_state(pair, values)
    force = 60.0 / VALUES["r1"]
    d = force / (VALUES["kZ"] * MEAN)
    assert rest.contact == {"mesh": "drive"}
    assert rest.deflections["mesh"] == pytest.approx(d, rel=1e-10)
    assert rest.coordinates["x"] == pytest.approx(d, rel=1e-10)
    assert rest.mesh_forces["mesh"] == pytest.approx(force, rel=1e-10)  # the harmonic M1a adds nothing at rest


@pytest.mark.parametrize("M1", [-60.0, -2000.0])
def test_a_reversed_load_rests_on_the_back_flank_one_backlash_further(pair, M1):
    """A small load (its deflection F/k within the backlash) and a large one (beyond it)."""
    values = loaded(M1)
    rest = static_state(pair, values)
    force = M1 / VALUES["r1"]
    d = force / (VALUES["kZ"] * MEAN) - VALUES["eta"]
    assert rest.contact == {"mesh": "back"}
    assert rest.deflections["mesh"] == pytest.approx(d, rel=1e-10)
    assert rest.deflections["mesh"] < -VALUES["eta"]
    assert rest.mesh_forces["mesh"] == pytest.approx(force, rel=1e-10)


def test_a_term_of_mean_zero_leaves_the_rest_where_it_was_on_either_flank(pair):
    """Another amplitude of the variation's sin(3 phi) term leaves the mean, and so the rest, where it was; the
    back flank's rest is the drive flank's mirrored, one backlash further."""
    base = static_state(pair, loaded(60.0)).deflections["mesh"]
    assert static_state(pair, loaded(60.0, kw=0.4)).deflections["mesh"] == pytest.approx(base, rel=1e-12)
    back = static_state(pair, loaded(-60.0, kw=0.4)).deflections["mesh"]
    assert back + VALUES["eta"] == pytest.approx(-base, rel=1e-12)


@pytest.fixture(scope="module")
def idler():
    """Three gears in a chain: the idler passes the mesh force on (F2 = F1: one radius for both meshes)."""
    m = Drivetrain("idler_flanks")
    a = m.add(Gear("g1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("g2", inertia="I2", base_radius="r2"))
    c = m.add(Gear("g3", inertia="I3", base_radius="r3"))
    m.add(Mesh("m1", a, b, stiffness="kZ", damping="cZ", backlash="eta", variation=VARIATION, coordinate="x1"))
    m.add(Mesh("m2", b, c, stiffness="kZ2", damping="cZ2", backlash="eta2", variation="0.8 + 0.3*sin(phi)",
               coordinate="x2"))
    m.add(Torque("M1", on=a, mean="M1"))
    m.add(Torque("M3", on=c, mean="M3", load=True))
    return gearsym.reduce(m).reduction


@pytest.mark.parametrize("M1", [45.0, -45.0])
def test_both_meshes_of_a_chain_rest_on_the_flank_their_load_presses(idler, M1):
    """Both meshes carry F = M1 / r1; a reversed load puts both on their back flank, each one backlash (its own)
    further than the drive flank's rest mirrored."""
    values = {**VALUES, "I3": 2e-3, "r3": 0.045, "kZ2": 3e8, "cZ2": 400.0, "eta2": 8e-5, "M1": M1,
              "M3": M1 * 0.045 / VALUES["r1"]}
    assert not torque_imbalance(idler, values)
    rest = static_state(idler, values)
    force = M1 / VALUES["r1"]
    flank, shift = ("drive", (0.0, 0.0)) if M1 > 0 else ("back", (VALUES["eta"], 8e-5))
    assert rest.contact == {"m1": flank, "m2": flank}
    assert rest.deflections["m1"] == pytest.approx(force / (VALUES["kZ"] * MEAN) - shift[0], rel=1e-10)
    assert rest.deflections["m2"] == pytest.approx(force / (3e8 * 0.8) - shift[1], rel=1e-10)
    assert rest.mesh_forces == pytest.approx({"m1": force, "m2": force}, rel=1e-10)
