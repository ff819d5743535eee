"""Physical units (issue 16): values with units in, the reduction's own scaling, results carried back.

The independent checks are typed here: a simulation of the Lagrange equations in physical units with
SciPy, the natural frequencies of two- and three-inertia chains by hand, and ISO 6336-1's resonance
speed formula for the worked example.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gearsym
from conftest import reduced
from gearsym import Disk, Drivetrain, Gear, GearsymError, Harmonic, Integration, Mesh, ModelError, Shaft, Torque
from gearsym import natural_modes
from gearsym.cli import main
from gearsym import scaling
from gearsym.physical.campbell import campbell
from gearsym.physical.sweeps import nondimensional_axis
from gearsym.units import Quantity, parse_quantity, ureg
from gearsym.sweep.grid import parse_axis

#: physical values for the paper's flexible-shaft model (which declares none): M3 keeps its torque balance
#: balanced: the pinion's 160 N m turns the wheel's axis with 160 x 45/30 = 240 = 90 + 150 N m of load, and
#: r2 M2/I2 = r2 M3/I3 (the torque balance the model assumes for its shaft, Eq. 10)
FLEX = dict(I1="2e-3 kg*m^2", I2="3e-3 kg*m^2", I3="5e-3 kg*m^2", r1="30 mm", r2="45 mm", kZ="2e8 N/m",
            cZ="400 N*s/m", eta="60 um", kS="2e4 N*m/rad", M1="160 N*m", M2="90 N*m", M3="150 N*m",
            M1a="5 N*m", Theta=0.3, k_a=0.2)


def spur(**values):
    return scaling(reduced("spur_pair"), **values)


# ------------------------------------------------------------------ physical -> nondimensional -> physical
@pytest.mark.parametrize("model, values, length_scale", [
    ("spur_pair", {}, None),
    ("flexible_shaft", FLEX, "static"),
    ("flexible_shaft", FLEX, "backlash"),
    ("flexible_shaft", FLEX, "2 um"),
])
def test_every_physical_value_comes_back_from_the_nondimensional_model(model, values, length_scale):
    s = scaling(reduced(model), length_scale, **values)
    for name, q in s.inputs.items():
        if s.speed and name == s.speed.parameter:
            back = s.speed_at(s.values["omega"])
            assert back.to(q.unit).magnitude == pytest.approx(q.given, rel=1e-12), name
        else:
            back = s.physical(name, s.scaled(name))
            assert back.unit == q.unit and back.given == pytest.approx(q.given, rel=1e-12, abs=1e-300), name
    for gr in s.model.groups:  # each free group: its scaled value in its own unit is its definition in SI
        if gr.kind == "free":
            dimensional = s.group_si(gr.name)
            assert s.group_value(gr.name) * s.unit_of(dimensional.dims) == pytest.approx(dimensional.si, rel=1e-12)
    assert gearsym.load(reduced(model), length_scale=length_scale or "static", **values).parameters == \
        pytest.approx(s.values, rel=1e-15)


def test_the_scaling_follows_the_paper_conventions():
    s = scaling(reduced("flexible_shaft"), "static", **FLEX)
    m = 0.030**2 / 2e-3 + 0.045**2 / 3e-3  # r1^2/I1 + r2^2/I2, typed here
    assert s.omega_n.to("rad/s").magnitude == pytest.approx(math.sqrt(2e8 * m), rel=1e-12)
    assert s.values["zeta"] == pytest.approx(400 * m / (2 * math.sqrt(2e8 * m)), rel=1e-12)  # c/(2 m_e omega_n)
    assert s.scaled("kZ") == pytest.approx(1.0, rel=1e-12)  # the mass unit makes the first mesh's stiffness 1 ...
    assert s.scaled("cZ") == pytest.approx(2 * s.values["zeta"], rel=1e-12)  # ... and its damping 2 zeta (Eq. 3)
    static = 160 / 0.030 / 2e8  # at rest the pinion's torque over its base radius is the mesh force: M1/(r1 kZ)
    assert s.length.to("m").magnitude == pytest.approx(static, rel=1e-12)
    # B0 is the mesh row's forcing, r1 M1/I1 + r2 M2/I2 over omega_n^2 L: with the shaft it is not the deflection
    assert s.values["B0"] == pytest.approx((0.030 * 160 / 2e-3 + 0.045 * 90 / 3e-3) / (2e8 * m) / static, rel=1e-12)
    assert s.values["eta"] == pytest.approx(60e-6 / static, rel=1e-12)
    assert scaling(reduced("flexible_shaft"), "backlash", **FLEX).values["eta"] == pytest.approx(2.0, rel=1e-12)
    # beta_1 kS, what the engine multiplies x2 by, is kS/I2 in units of omega_n^2
    assert s.values["kS"] / s.values["I2"] == pytest.approx(2e4 / 3e-3 / (2e8 * m), rel=1e-12)


def test_speed_gives_omega_through_the_tooth_count():
    s = spur(speed="3000 rpm")
    mesh_hz = 28 * 3000 / 60
    assert s.mesh_frequency().to("Hz").magnitude == pytest.approx(mesh_hz, rel=1e-12)
    assert s.values["omega"] == pytest.approx(2 * math.pi * mesh_hz / s.omega_n.to("rad/s").magnitude, rel=1e-12)
    assert spur(speed="50 Hz").values["omega"] == pytest.approx(s.values["omega"], rel=1e-12)  # Hz is rev/s here


# ------------------------------------------------------------------ an independent simulation in physical units
def pair_model() -> Drivetrain:
    m = Drivetrain("pair_si")
    a = m.add(Gear("pinion", inertia="I1", base_radius="r1", teeth=20, speed="speed"))
    b = m.add(Gear("wheel", inertia="I2", base_radius="r2", teeth=30))
    m.add(Mesh("mesh", a, b, variation="1 + 0.3*cos(phi)"))
    m.add(Torque("M1", on=a, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    m.add(Torque("M2", on=b, mean="M2", load=True))
    m.set_physical(I1="1.5e-3 kg*m^2", I2="4e-3 kg*m^2", r1="20 mm", r2="30 mm", kZ="1.5e8 N/m",
                   cZ="300 N*s/m", eta="40 um", M1="40 N*m", M2="60 N*m", M1a="8 N*m", Theta=0.2,
                   speed="7000 rpm")
    return m


@pytest.mark.slow
def test_a_simulation_of_the_physical_lagrange_equations_agrees_with_gearsym_carried_back():
    from scipy.integrate import solve_ivp

    s = scaling(pair_model())
    periods = 40
    x0 = 30e-6  # m
    trajectory = gearsym.phase_trajectory(s.system(), options=Integration(periods=periods, discard=0,
                                                                           steps_per_period=400),
                                          y0={"x": x0 / s.length.to("m").magnitude, "v": 0.0})
    ours = s.to_physical(trajectory)
    # the Lagrange equations of the two gears, in SI, typed here
    I1, I2, r1, r2, kZ, cZ, eta, M1, M2, M1a, theta = 1.5e-3, 4e-3, 0.020, 0.030, 1.5e8, 300.0, 40e-6, 40.0, 60.0, 8.0, 0.2
    mesh = 20 * 7000 / 60 * 2 * math.pi  # rad/s: teeth x speed

    def force(t, x, xdot):
        contact = x if x >= 0 else (0.0 if x > -eta else x + eta)
        return kZ * (1 + 0.3 * math.cos(mesh * t)) * contact + cZ * xdot

    def rhs(t, y):
        p1, p2, w1, w2 = y
        f = force(t, r1 * p1 - r2 * p2, r1 * w1 - r2 * w2)
        return [w1, w2, (M1 + M1a * math.cos(mesh * t + theta) - r1 * f) / I1, (-M2 + r2 * f) / I2]

    t = ours.time.to("s").magnitude
    sol = solve_ivp(rhs, (0.0, t[-1]), [x0 / r1, 0.0, 0.0, 0.0], method="DOP853", t_eval=t, rtol=1e-11,
                    atol=1e-15, max_step=0.05 * 2 * math.pi / mesh)
    x = 0.020 * sol.y[0] - 0.030 * sol.y[1]
    xdot = 0.020 * sol.y[2] - 0.030 * sol.y[3]
    ours_x = ours["x"].to("m").magnitude
    scale = np.max(np.abs(x))
    assert np.max(np.abs(ours_x - x)) < 1e-5 * scale
    assert np.max(np.abs(ours["v"].to("m/s").magnitude - xdot)) < 1e-5 * np.max(np.abs(xdot))
    last = t > t[-1] - 10 * 2 * math.pi / mesh
    assert (np.ptp(ours_x[last]) / 2) == pytest.approx(np.ptp(x[last]) / 2, rel=1e-5)  # amplitude, last 10 periods
    expected_force = np.array([force(ti, xi, vi) for ti, xi, vi in zip(t, x, xdot)])
    got = ours.mesh_force["mesh"].to("N").magnitude
    assert np.max(np.abs(got - expected_force)) < 1e-4 * np.max(np.abs(expected_force))


@pytest.mark.slow
def test_a_spectrum_is_carried_back_per_second_and_in_micrometres():
    s = scaling(pair_model())
    result = gearsym.lyapunov_spectrum(s.system(), options=Integration(periods=60, discard=40))
    point = s.to_physical(result)
    forcing = s.values["omega"] * s.omega_n.to("rad/s").magnitude
    assert point.exponents.to("1/s").magnitude == pytest.approx(np.asarray(result.exponents) * forcing, rel=1e-12)
    assert point.amplitude["x"].to("m").magnitude == pytest.approx(result.amplitude["x"] * s.length.to("m").magnitude,
                                                                  rel=1e-12)
    assert point.speed.to("rpm").magnitude == pytest.approx(7000, rel=1e-12)
    assert point.as_dict()["amplitude"]["x"]["unit"] == "µm"


# ------------------------------------------------------------------ natural frequencies
def chain(inertias: list[float], stiffnesses: list[float]) -> Drivetrain:
    m = Drivetrain(f"chain{len(inertias)}")
    disks = [m.add(Disk(f"d{i + 1}", inertia=f"J{i + 1}")) for i in range(len(inertias))]
    for i, (a, b) in enumerate(zip(disks, disks[1:])):
        m.add(Shaft(f"s{i + 1}", a, b, stiffness=f"k{i + 1}", radius=1, coordinate=f"x{i + 1}"))
    m.set_defaults(**{f"J{i + 1}": v for i, v in enumerate(inertias)},
                   **{f"k{i + 1}": v for i, v in enumerate(stiffnesses)})
    return m


def test_two_inertias_on_a_shaft_have_the_frequency_of_the_textbook():
    modes = natural_modes(chain([2.0, 3.0], [5.0]))
    assert modes.frequencies == pytest.approx([0.0, math.sqrt(5.0 * (1 / 2.0 + 1 / 3.0))], abs=1e-12)
    assert [m.kind for m in modes.modes] == ["rigid", "elastic"]
    assert modes.modes[0].angles == pytest.approx({"d1": 1.0, "d2": 1.0})
    elastic = modes.modes[1].angles  # the inertias swing against each other, 3:2
    assert elastic["d1"] / elastic["d2"] == pytest.approx(-3.0 / 2.0)


def test_two_separate_trains_have_one_rigid_body_mode_each():
    m = chain([1.0, 2.0], [3.0])
    c = m.add(Disk("d3", inertia="J3"))
    d = m.add(Disk("d4", inertia="J4"))
    m.add(Shaft("s2", c, d, stiffness="k2", radius=1, coordinate="x2"))
    m.set_defaults(J3=1.0, J4=1.0, k2=2.0)
    modes = natural_modes(m)
    rigid = [mode.angles for mode in modes.modes if mode.kind == "rigid"]
    assert rigid == [{"d1": 1.0, "d2": 1.0, "d3": 0.0, "d4": 0.0}, {"d1": 0.0, "d2": 0.0, "d3": 1.0, "d4": 1.0}]
    assert modes.frequencies == pytest.approx([0.0, 0.0, 2.0, math.sqrt(3.0 * 1.5)])


def test_three_inertias_in_a_chain_match_the_hand_computed_frequencies():
    modes = natural_modes(chain([1.0, 2.0, 1.0], [4.0, 4.0]))  # J, 2J, J with k, k: w^2 = k/J and 2k/J
    assert modes.frequencies == pytest.approx([0.0, 2.0, math.sqrt(8.0)], abs=1e-12)
    antisymmetric = modes.modes[1]
    assert antisymmetric.angles == pytest.approx({"d1": 1.0, "d2": 0.0, "d3": -1.0}, abs=1e-12)
    assert antisymmetric.coordinates == pytest.approx({"x1": -1.0, "x2": -1.0}, abs=1e-12)


def test_the_flexible_shaft_frequencies_solve_its_reduced_equations():
    # x1'' = -m kZ x1 - kS x2/I2, x2'' = -r2^2 kZ x1/I2 - kS (1/I2 + 1/I3) x2, typed from the paper's Eq. 9
    modes = natural_modes(reduced("flexible_shaft"), **FLEX)
    I1, I2, I3, r1, r2, kZ, kS = 2e-3, 3e-3, 5e-3, 0.030, 0.045, 2e8, 2e4
    a = np.array([[kZ * (r1**2 / I1 + r2**2 / I2), kS / I2], [r2**2 * kZ / I2, kS * (1 / I2 + 1 / I3)]])
    expected = np.sqrt(np.sort(np.linalg.eigvals(a).real)) / (2 * math.pi)
    assert modes.unit == "Hz"
    assert modes.frequencies == pytest.approx([0.0, *expected], rel=1e-10)
    nondimensional = natural_modes("flexible_shaft")  # unit inertias and radii, kS = 0.1, m kZ = 1
    a = np.array([[1.0, 0.1], [0.5, 0.2]])
    assert nondimensional.frequencies == pytest.approx([0.0, *np.sqrt(np.sort(np.linalg.eigvals(a)))], rel=1e-10)


def test_repeated_frequencies_are_reported_with_their_multiplicity():
    m = Drivetrain("star")  # a hub with three equal arms: the arms' modes share w^2 = k/J twice
    hub = m.add(Disk("hub", inertia="J0"))
    for i in range(3):
        arm = m.add(Disk(f"arm{i}", inertia="J"))
        m.add(Shaft(f"s{i}", hub, arm, stiffness="k", radius=1, coordinate=f"x{i}"))
    m.set_defaults(J0=2.0, J=1.0, k=3.0)
    modes = natural_modes(m)
    assert modes.frequencies == pytest.approx([0.0, math.sqrt(3.0), math.sqrt(3.0), math.sqrt(3.0 * (1 + 3 / 2))])
    assert [mode.multiplicity for mode in modes.modes] == [1, 2, 2, 1]


def test_the_worked_example_resonates_at_iso_6336s_resonance_speed():
    modes = natural_modes("spur_pair")
    # ISO 6336-1: n_E1 = 30000/(pi z1) sqrt(c_gamma / m_red), m* = J/(r_b^2 b) in kg/mm, typed here, with the
    # gears' bodies as ISO takes them (disks of the mean of tip and root diameters, less the 20 mm bore) and
    # c_gamma the mean of the stiffness the model computes from the geometry (per unit face width, N/(mm um))
    z, module, b, bore = 28, 3.175, 6.35, 20.0  # mm
    r_base = z * module / 2 * math.cos(math.radians(20))
    d_m = ((z + 2) * module + (z - 2.5) * module) / 2
    inertia = 7850e-9 * math.pi * b * (d_m**4 - bore**4) / 32 * 1e-6  # kg m^2 (kg/mm^3 x mm^5 = kg mm^2)
    m_star = inertia * 1e6 / (r_base**2 * b)
    mesh = gearsym.load_model("spur_pair").couplings[0]
    c_gamma = mesh.computed.curve.mean / 1e6 / b  # N/m = 1e-6 N/(mm um) x mm of face width
    n_e1 = 30000 / (math.pi * z) * math.sqrt(c_gamma / (m_star / 2))  # rpm
    assert modes.elastic[0].frequency == pytest.approx(n_e1 * z / 60, rel=1e-6)
    assert modes.frequencies[0] == 0.0 and modes.modes[0].kind == "rigid"
    assert scaling(reduced("spur_pair")).omega_n.to("Hz").magnitude == pytest.approx(modes.elastic[0].frequency,
                                                                                      rel=1e-12)


def test_gearsym_modes_prints_json_by_coordinate(capsys):
    assert main(["modes", "flexible_shaft", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["unit"] == "omega_n" and out["frequencies"] == sorted(out["frequencies"])
    assert [m["kind"] for m in out["modes"]] == ["rigid", "elastic", "elastic"]
    assert set(out["modes"][1]["shape"]) == {"gear1", "gear2", "disk3"}
    assert set(out["modes"][1]["coordinates"]) == {"x1", "x2"}


# ------------------------------------------------------------------ sweeps and the Campbell diagram
def test_a_physical_range_is_counted_in_its_unit():
    axis = parse_axis("speed=500rpm:6000rpm:25rpm")
    assert axis.unit == "rpm" and len(axis.values) == 221 and axis.values[:2] == (500.0, 525.0)
    assert parse_axis("speed=3000rpm,100Hz").values == pytest.approx((3000.0, 6000.0), rel=1e-12)  # in rpm
    assert parse_axis("cZ=200,500 N*s/m").unit == "N*s/m"
    assert parse_axis("omega=0.1:0.3:0.1").unit == ""


def test_a_speed_axis_becomes_omega_and_comes_back_in_rpm(tmp_path):
    s = spur()
    axis = nondimensional_axis(s, parse_axis("speed=8000rpm:12000rpm:2000rpm"))
    assert axis.name == "omega"
    assert axis.values == tuple(s.omega(Quantity(v, "rpm")) for v in (8000.0, 10000.0, 12000.0))
    result = gearsym.run_sweep(s.system(), [axis], options=Integration(periods=30, discard=20), execution=gearsym.Execution(1, "threads"))
    physical = s.to_physical(result)
    assert physical["speed"] == pytest.approx([8000.0, 10000.0, 12000.0], rel=1e-12)
    assert physical["A_x"] == pytest.approx(result["A_x"] * s.length.to("um").magnitude, rel=1e-12)
    assert physical.units["A_x"] == "µm" and physical.units["speed"] == "rpm"


def test_a_sweep_axis_that_moves_the_units_themselves_is_refused():
    with pytest.raises(GearsymError, match="moves .* together"):
        nondimensional_axis(spur(), parse_axis("kZ=1e8,2e8 N/m"))


def test_the_campbell_crossings_are_where_the_orders_meet_the_natural_frequency():
    s = spur()
    modes = natural_modes("spur_pair")
    diagram = campbell(s, np.arange(1000.0, 16000.0, 500.0), "rpm", modes, mesh_orders=3)
    fn = modes.elastic[0].frequency
    mesh = [c for c in diagram.crossings if "mesh" in c.order]
    assert [c.speed for c in mesh] == pytest.approx([60 * fn / (k * 28) for k in (3, 2, 1)], rel=1e-12)
    assert [c.order for c in mesh] == ["3x mesh", "2x mesh", "1x mesh"]
    assert any(c.order == "torque 1x" for c in diagram.crossings)


def test_gearsym_campbell_draws_the_diagram_beside_the_sweep(tmp_path, capsys):
    out, plot = tmp_path / "c.csv", tmp_path / "c.png"
    assert main(["campbell", "spur_pair", "--param", "speed=6000rpm:14000rpm:4000rpm", "--periods", "30",
                 "--discard", "20", "--out", str(out), "--plot", str(plot), "--quiet", "--jobs", "1"]) == 0
    text = capsys.readouterr().out
    fn = natural_modes("spur_pair").elastic[0].frequency
    assert f"crossing: 1x mesh meets {fn:g} Hz at {60 * fn / 28:g} rpm" in text
    assert plot.stat().st_size > 10_000 and out.is_file()
    assert json.loads((tmp_path / "c.campbell.json").read_text())["natural_frequencies_Hz"] == pytest.approx([fn],
                                                                                                            rel=1e-9)


def test_gearsym_sweep_writes_a_table_in_physical_units(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "spur_pair", "--param", "speed=9000rpm:11000rpm:1000rpm", "--periods", "30",
                 "--discard", "20", "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    header, first = (tmp_path / "s.physical.csv").read_text().splitlines()[:2]
    assert header.startswith("speed [rpm],direction,A_x [µm],lambda_1 [1/s]")
    assert first.startswith("9000.0,up,")


# ------------------------------------------------------------------ errors before any work
@pytest.mark.parametrize("values, message", [
    ({"kZ": "2e8 N*m"}, r"spur_pair: kZ: 2e\+08 .* is not a mesh stiffness in N/m"),
    ({"kZ": "2e8"}, r"kZ: 2e\+08 has no unit, and a mesh stiffness needs one: write kZ='2e\+08 N/m'"),
    ({"speed": "3000 N"}, r"speed: .* is not a rotational speed in rpm"),
    ({"kZ": "2e8 N/blorp"}, r"unknown unit 'blorp'"),
    ({"zeta": 0.1}, r"zeta is derived from the physical values .* set I1, I2, cZ, r1, r2 instead"),
    ({"omega": 1.2}, r"omega follows from the speed .* speed='3000 rpm'"),
    ({"kX": "1 N/m"}, r"unknown parameter 'kX'"),
])
def test_bad_physical_values_get_one_clear_line(values, message):
    with pytest.raises(GearsymError, match=message):
        gearsym.load(reduced("spur_pair"), **values)


def test_missing_physical_values_are_named_with_the_units_they_need():
    with pytest.raises(ModelError) as err:
        gearsym.load(reduced("one_stage"), kZ="2e8 N/m")
    text = str(err.value)
    assert "no physical value for I1 (a moment of inertia in kg*m^2" in text and "cZ (a mesh damping in N*s/m" in text
    assert "\n" not in text


def test_a_broken_torque_balance_is_refused():
    with pytest.raises(ModelError, match="break a condition of the reduction"):
        scaling(reduced("flexible_shaft"), **{**FLEX, "M3": "100 N*m"})


def test_the_cli_prints_one_line_for_bad_units(capsys):
    assert main(["lyap", "spur_pair", "--set", "kZ=2e8 N*m"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearsym: error: spur_pair: kZ:") and "N/m" in err and err.count("\n") == 1
    assert main(["sweep", "one_stage", "--param", "omega=1rpm:2rpm:1rpm", "--out", "x.csv"]) == 2
    assert "has a unit, but the model has no physical values" in capsys.readouterr().err
    assert main(["modes", "lorenz", "--set", "sigma=10 N"]) == 2


# ------------------------------------------------------------------ a quantity string is never run
TOUCH = "__import__('os').system('touch PWNED')"


@pytest.fixture
def sandbox(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    assert not (tmp_path / "PWNED").exists(), "a quantity string was run as Python"


@pytest.mark.parametrize("argv", [
    ["lyap", "spur_pair", "--set", f"kZ=2e8 {TOUCH}"],
    ["lyap", "spur_pair", "--set", f"kZ=2e8 N/m*{TOUCH}"],
    ["lyap", "spur_pair", "--set", f"speed=3000 rpm; {TOUCH}"],
    ["lyap", "spur_pair", "--set", f"length_scale=1 um {TOUCH}"],
    ["modes", "spur_pair", "--set", f"kZ=1e{TOUCH}"],
    ["sweep", "spur_pair", "--param", f"speed=500rpm:{TOUCH}:1rpm", "--out", "o.csv"],
    ["sweep", "spur_pair", "--param", f"speed=500 rpm*{TOUCH}", "--out", "o.csv"],
])
def test_quantity_injections_stop_with_one_line_and_run_nothing(argv, sandbox, capfd):
    assert main(argv) == 2
    out, err = capfd.readouterr()
    assert err.startswith("gearsym: error: ") and err.count("\n") == 1 and "PWNED" not in out


@pytest.mark.parametrize("text", [
    TOUCH, f"1 {TOUCH}", "1 m.__class__", "1 m[0]", "1 m; import os", "1 lambda: 0", "1 m**10**10", "1 m**2.5",
    "1 (m", "1 'm'", "1 m" + "*m" * 80,
])
def test_pint_never_sees_text_outside_the_quantity_grammar(text, monkeypatch):
    seen = []
    original = ureg.parse_units
    monkeypatch.setattr(ureg, "parse_units", lambda t, *a, **k: (seen.append(t), original(t, *a, **k))[1])
    from gearsym import units

    units._units.cache_clear()
    with pytest.raises(GearsymError):
        parse_quantity(text, "test")
    assert all("(" not in t or t.count("(") == t.count(")") for t in seen)
    assert not any(bad in t for t in seen for bad in ("__", ".", "[", ";", "'", "lambda", "**10"))


def test_no_module_shadows_a_name_of_the_face_whatever_was_imported_first():
    """(A submodule named like a function handed on by its package would replace it there once imported; so no
    package hands a name on that a module of it bears, and no function of the face shares a subpackage's name.)"""
    import subprocess
    import sys

    code = ("import importlib, pkgutil, types, gearsym\n"
            "names = [m.name for m in pkgutil.walk_packages(gearsym.__path__, 'gearsym.')\n"
            "         if not m.name.endswith('__main__')]\n"
            "for n in names: importlib.import_module(n)\n"
            "bad = [n for n in gearsym.__all__ if isinstance(getattr(gearsym, n), types.ModuleType)]\n"
            "for n in names:\n"
            "    m = importlib.import_module(n)\n"
            "    bad += [f'{n}.{a}' for a in getattr(m, '__all__', []) if isinstance(getattr(m, a), types.ModuleType)]\n"
            "tops = {n.split('.')[1] for n in names}\n"
            "bad += sorted(tops & set(gearsym.__all__))\n"
            "assert not bad, bad\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
