"""Shaft-order terms the shipped tests leave out: eccentricity (run-out) at shaft orders above 1 with a phase, on
both gears, on a mesh whose phase runs at twice the model's time (mesh order 2), and a spall over part of a tooth's
path of contact: the model's equation of motion against the terms typed here, at random instants and states over
the whole hunting period.

Typed: x'' = -2 zeta x'/omega + (B0 + B1 cos(tau + Theta))/omega^2 - k(phi) (1 - loss(phi)) g(x - e(phi))/omega^2
with phi = order tau the mesh phase, k the default rectangular stiffness (tests/rig.py), e = sum A_i cos(N_i phi/Z_i
+ psi_i), and a spall's loss w s_n(phi) W(phi): the pair's share s_n times the window of its part of the path.
"""
from __future__ import annotations

import math
import random

import pytest
import sympy as sp

import gearsym
import rig
from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque
from gearsym.model.faults import Eccentricity, SpacingErrors, Spall
from gearsym.model.symbols import parameter_symbol, tau

TEETH = (9, 13)
VALUES = dict(omega=1.5, zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.2)


def pair(name: str, *terms, order=1, **defaults) -> Drivetrain:
    m = Drivetrain(name)
    g1 = m.add(Gear("gear1", inertia="I1", base_radius="r1", teeth=TEETH[0]))
    g2 = m.add(Gear("gear2", inertia="I2", base_radius="r2", teeth=TEETH[1]))
    m.add(Mesh("mesh", g1, g2, stiffness="kZ", damping="cZ", backlash="eta", order=order))
    m.add(Torque("M1", on=g1, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    m.add(Torque("M2", on=g2, mean="M2", load=True))
    for term in terms:
        m.add(term(g1, g2))
    m.set_defaults(**VALUES, **defaults)
    return m


def window(phi, teeth, centre, length, edge=0.1):
    """(1 + tanh(kappa sin(a + h)))(1 + tanh(kappa sin(h - a)))/4: a the gear's angle from the centre (in mesh
    periods from phi = 0), h = pi length/Z, kappa = Z/(pi edge)."""
    h, kappa = math.pi * length / teeth, teeth / (math.pi * edge)
    a = (phi - 2 * math.pi * centre) / teeth
    return (1 + math.tanh(kappa * math.sin(a + h))) * (1 + math.tanh(kappa * math.sin(h - a))) / 4


def share(phi, teeth, tooth, e=1.6):
    before, here, after = (window(phi, teeth, tooth + k - 0.5, e) for k in (-1, 0, 1))
    return here / 2 + here * (1 - before) * (1 - after) / 2


def typed(t, x, v, order=1, runout=(), spall=None, spacing=None):
    """x'' typed: ``runout`` [(gear, N, A, psi)], ``spall`` (gear, tooth, w, start, end), ``spacing`` (gear,
    errors): e_n while tooth n carries the load, each over one mesh period with edges over the double contact."""
    phi = order * t
    k = 1 + VALUES["k_a"] * sum(c * math.cos((n + 1) * phi) for n, c in enumerate(rig.STIFFNESS))
    if spall:
        gear, tooth, w, a, b = spall
        z, e = TEETH[gear - 1], 1.6
        part = window(phi, z, tooth - 0.5 - e / 2 + e * (a + b) / 2, e * (b - a))
        k *= 1 - w * share(phi, z, tooth) * part
    error = sum(A * math.cos(N * phi / TEETH[gear - 1] + psi) for gear, N, A, psi in runout)
    if spacing:
        gear, errors = spacing
        error += sum(e * window(phi, TEETH[gear - 1], n - 0.5, 1, edge=(1.6 - 1) / 2) for n, e in enumerate(errors, 1))
    w = VALUES["omega"]
    return (-2 * VALUES["zeta"] * v / w + (VALUES["B0"] + VALUES["B1"] * math.cos(t + VALUES["Theta"])) / w ** 2
            - k * rig.backlash(x - error, VALUES["eta"]) / w ** 2)


def acceleration(model: Drivetrain):
    system = gearsym.load(model)
    f = sp.lambdify([tau, *system.states], system.rhs[1].xreplace(
        {parameter_symbol(k): v for k, v in system.parameters.items()}).rewrite(sp.Piecewise), "math")
    return system, f


def compare(f, span: float, **terms) -> None:
    rng = random.Random(37)
    for _ in range(60):
        t, x, v = rng.uniform(0, span), rng.uniform(-14, 4), rng.uniform(-3, 3)
        assert f(t, x, v) == pytest.approx(typed(t, x, v, **terms), rel=1e-10, abs=1e-10), (t, x, v)


def test_run_out_at_shaft_orders_2_and_3_with_phases_on_both_gears():
    model = pair("runout", lambda g1, g2: Eccentricity("e1", g1, amplitude="A1", phase="psi1", order=2),
                 lambda g1, g2: Eccentricity("e2", g2, amplitude="A2", phase="psi2", order=3),
                 A1=0.4, psi1=0.7, A2=0.25, psi2=-1.1)
    system, f = acceleration(model)
    assert system.cycles == 9 * 13  # (the hunting period, in mesh periods)
    compare(f, 2 * math.pi * 117, runout=[(1, 2, 0.4, 0.7), (2, 3, 0.25, -1.1)])


def test_run_out_on_a_mesh_of_order_2_turns_with_the_mesh_phase():
    """The mesh phase is 2 tau: k(2 tau), and the gear of Z teeth turns once in Z mesh periods, pi Z in tau."""
    model = pair("runout_order2", lambda g1, g2: Eccentricity("e2", g2, amplitude="A2", phase="psi2", order=3),
                 order=2, A2=0.25, psi2=0.4)
    system, f = acceleration(model)
    compare(f, 2 * math.pi * 117, order=2, runout=[(2, 3, 0.25, 0.4)])


def test_a_spall_over_part_of_the_path_of_contact_takes_its_width_there():
    model = pair("spall", lambda g1, g2: Spall("pit", g2, tooth=5, width="w", start=0.2, end=0.55), w=0.6)
    system, f = acceleration(model)
    compare(f, 2 * math.pi * 117, spall=(2, 5, 0.6, 0.2, 0.55))


def test_spacing_errors_are_each_tooths_error_while_it_carries_the_load():
    errors = [0.3, -0.2, 0.5, 0.0, 0.1, -0.4, 0.25, 0.05, -0.1]
    model = pair("spacing", lambda g1, g2: SpacingErrors("pitch", g1, errors=tuple(f"s{n}" for n in range(1, 10))),
                 **{f"s{n}": e for n, e in enumerate(errors, 1)})
    system, f = acceleration(model)
    compare(f, 2 * math.pi * 117, spacing=(1, errors))
