"""Mesh orders from tooth counts (issue 38): a multi-stage box declared without an order, a function or a group
typed by hand; its period is the meshes' common one and its steps count per mesh period of the first stage."""
from __future__ import annotations

import pytest
import sympy as sp

import gearsym
from conftest import reduced
from gearsym import Disk, Drivetrain, Gear, Mesh, ModelError, Shaft, Torque
from gearsym.model import symbols


def gearbox(order2=None, teeth=(23, 61, 19, 47)) -> Drivetrain:
    """The issue's gearbox with parameters instead of geometry (cheap): motor, coupling, 23/61, shaft, 19/47."""
    z1, z2, z3, z4 = teeth
    m = Drivetrain("box")
    motor = m.add(Disk("motor", inertia="Im", speed="speed"))
    g = [m.add(Gear(f"g{i + 1}", inertia=f"I{i + 1}", base_radius=f"r{i + 1}", teeth=z)) for i, z in enumerate(teeth)]
    m.add(Shaft("coupling", motor, g[0], stiffness="kc"))
    m.add(Mesh("stage1", g[0], g[1]))
    m.add(Shaft("intermediate", g[1], g[2], stiffness="ki"))
    mesh = {} if order2 is None else {"order": order2}
    m.add(Mesh("stage2", g[2], g[3], stiffness="kZ2", damping="cZ2", backlash="eta2", **mesh))
    m.add(Torque("M1", on=motor, mean="M1"))
    m.add(Torque("M4", on=g[3], mean="M4", load=True))
    return m


def test_a_second_stage_gets_its_order_from_the_tooth_counts():
    stage1, stage2 = (rc for rc in gearbox().resolved.couplings if rc.kind == "mesh")
    assert stage1.order == 1 and stage2.order == sp.Rational(19, 61)  # 19 x (23/61) over 23
    assert stage2.mesh_phase == sp.Rational(19, 61) * symbols.omega * symbols.t


def test_the_first_mesh_may_be_any_of_the_stages_and_a_planet_carrier_counts_relative_speeds():
    # the same box with the stages declared the other way round: the first mesh is the forcing
    m = gearbox(teeth=(20, 40, 30, 45))
    orders = [rc.order for rc in m.resolved.couplings if rc.kind == "mesh"]
    assert orders == [1, sp.Rational(30 * 20, 40 * 20)]  # 30 x 20/40 over 20
    # a planetary set driving a parallel pair: the pinion on the carrier turns at the carrier's speed
    (planetary_mesh, *_), parallel = ([rc for rc in reduced("planetary_two_stage").reduction.resolved.couplings
                                       if rc.kind == "mesh"][i] for i in (slice(None), -1))
    assert parallel.order == sp.Rational(47, 94)


def test_an_order_the_teeth_contradict_is_refused_with_the_order_to_write():
    with pytest.raises(ModelError) as err:
        gearbox(order2=1).resolved
    text = str(err.value)
    assert "order=sp.Rational(19, 61)" in text and "leave order= out" in text and "'stage2'" in text
    gearbox(order2=sp.Rational(19, 61)).resolved  # the right one, written out, is taken


def test_a_mesh_without_tooth_counts_keeps_order_one_unless_declared():
    assert [rc.order for rc in reduced("two_stage").reduction.resolved.couplings if rc.kind == "mesh"] == [
        1, sp.Rational(1, 2)]
    assert reduced("two_stage").cycles == 2  # the second mesh's period is two of the first's


def test_the_gearbox_repeats_on_61_mesh_periods_and_names_its_second_mesh_itself():
    nd = reduced("two_stage_gearbox")
    assert nd.forcing_period == 2 * sp.pi and nd.period == 122 * sp.pi and nd.cycles == 61
    names = {gr.name for gr in nd.groups}
    second = {f.name for f in nd.functions} - {"k"}
    assert second and {"zeta", "B0"} <= names and any(n.startswith("K_") for n in names)
    assert any(n.startswith("zeta_") for n in names)
    scaling = gearsym.scaling(nd)
    system = scaling.system()
    assert system.cycles == 61 and float(system.period) == pytest.approx(122 * 3.141592653589793)
    # it starts at rest under its torques, its shafts' twists declared in rad: the first mesh at its static
    # deflection (the length unit), the coupling's twist -150 N m / 5e4 N m/rad as radius x twist
    assert system.initial["x2"] == pytest.approx(1.0, rel=1e-9)
    radius = scaling.si_values["r_gear1"]
    assert system.initial["x1"] * scaling.length_si / radius == pytest.approx(-150 / 5e4, rel=1e-12)


def test_an_order_spectrum_labels_every_meshs_lines_at_their_orders_of_the_first():
    from gearsym.analysis.orders import order_lines, order_spectrum

    import numpy as np

    others = {"stage2": (19 / 61, {"gear3": 19, "gear4": 47})}
    lines = {ln.label: ln.order for ln in order_lines({"gear1": 23, "gear2": 61}, 2, 1, others)}
    assert lines["stage2 x1"] == pytest.approx(19 / 61) and lines["stage2 x2"] == pytest.approx(38 / 61)
    assert lines["stage2 x1 + gear4 x1"] == pytest.approx(19 / 61 * (1 + 1 / 47))
    tau = np.linspace(0, 2 * np.pi * 61, 61 * 50, endpoint=False)  # one period of the box, 50 samples a mesh period
    signal = 2.0 * np.cos(tau) + 0.5 * np.cos(19 / 61 * tau)  # the first mesh's harmonic and the second's
    s = order_spectrum(tau, signal, {"gear1": 23, "gear2": 61}, meshes=others, unit="µm")
    assert s.line("mesh x1").amplitude == pytest.approx(2.0, rel=1e-3)
    assert s.line("stage2 x1").amplitude == pytest.approx(0.5, rel=1e-3) and s.unit == "µm"
