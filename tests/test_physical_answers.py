"""A physical model answers in the user's units everywhere (issue 25: "Physical units end to end", and item 7,
the mean mesh force over whole periods).

The references are independent of the scaling: Lagrange's equations of a motor-coupling-gear train typed here in
SI and integrated by SciPy (shaft twists in rad, shaft torques in N·m, the mesh force in N); the exact mean of a
periodic mesh force (a pinion on a periodic orbit does not accelerate on average, so the mean mesh force is the
mean torque over the base radius, M1 / r1); the textbook frequency of two gears on a mesh; a sampled signal of
known mean. Every entry of a unitless speed is tried (the command line's --set and --param, Python's keywords and
sweep axes) for the one message.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gearsym
from conftest import reduced
from gearsym import Disk, Drivetrain, Gear, GearsymError, Integration, Mesh, Shaft, Torque
from gearsym.analysis.poincare import Trajectory
from gearsym.cli import main
from gearsym.physical.point import whole_period_mean

@pytest.fixture(scope="module")
def spur():
    return gearsym.scaling(reduced("spur_pair"))


def declared(name: str) -> float:
    """A value spur_pair declares (models/spur_pair.py), in SI: what the exact answers below are made of."""
    return reduced("spur_pair").drivetrain.physical[name].si


# ------------------------------------------------------------------ shafts: twists in rad, torques in N·m
def motor_coupling_gear() -> Drivetrain:
    """Motor disk -> damped coupling -> pinion 23 T -> mesh -> wheel 61 T -> damped shaft -> load disk."""
    m = Drivetrain("motor_coupling_gear_si")
    motor = m.add(Disk("motor", inertia="Im"))
    pinion = m.add(Gear("pinion", inertia="I1", base_radius="r1", teeth=23, speed="speed"))
    wheel = m.add(Gear("wheel", inertia="I2", base_radius="r2", teeth=61))
    load = m.add(Disk("load", inertia="IL"))
    m.add(Shaft("coupling", motor, pinion, stiffness="kc", damping="cc", coordinate="xc"))
    m.add(Mesh("mesh", pinion, wheel, variation="1 + 0.3*cos(phi)", coordinate="x"))
    m.add(Shaft("output", wheel, load, stiffness="ko", damping="co", coordinate="xo"))
    m.add(Torque("M1", on=motor, mean="M1"))
    m.add(Torque("M3", on=load, mean="M3", load=True))
    m.set_physical(Im="0.05 kg*m^2", I1="4e-4 kg*m^2", I2="2e-2 kg*m^2", IL="0.3 kg*m^2", r1="32.42 mm",
                   r2=f"{32.42 * 61 / 23!r} mm", kc="1e5 N*m/rad", cc="20 N*m*s/rad", ko="4e5 N*m/rad",
                   co="50 N*m*s/rad", kZ="2e8 N/m", cZ="600 N*s/m", eta="50 um", M1="100 N*m",
                   M3=f"{100 * 61 / 23!r} N*m", speed="3000 rpm")
    return m


@pytest.mark.slow
def test_shaft_twists_come_back_in_radians_and_their_torques_in_newton_metres():
    from scipy.integrate import solve_ivp

    s = gearsym.scaling(motor_coupling_gear())
    si = s.si_values
    Im, I1, I2, IL, r1, r2 = (si[k] for k in ("Im", "I1", "I2", "IL", "r1", "r2"))
    kc, cc, ko, co, kZ, cZ, eta, M1, M3 = (si[k] for k in ("kc", "cc", "ko", "co", "kZ", "cZ", "eta", "M1", "M3"))
    mesh = 23 * si["speed"]  # rad/s of the mesh phase: teeth x the pinion's speed
    twist_c, x0, twist_o = -0.9 * M1 / kc, 10e-6, -1.1 * M3 / ko  # near rest, so that it moves
    L = s.length_si
    y0 = {"xc": r1 * twist_c / L, "x": x0 / L, "xo": r2 * twist_o / L}  # a shaft's coordinate: radius x twist
    trajectory = gearsym.phase_trajectory(s.system(), options=Integration(periods=10, discard=0,
                                                                           steps_per_period=400), y0=y0)
    ours = s.to_physical(trajectory)

    def force(t, x, xdot):  # the mesh's law, typed here
        contact = x if x >= 0 else (0.0 if x > -eta else x + eta)
        return kZ * (1 + 0.3 * math.cos(mesh * t)) * contact + cZ * xdot

    def rhs(t, y):  # Lagrange's equations of the four bodies, in SI
        pm, pp, pw, pl, wm, wp, ww, wl = y
        tc, to = kc * (pp - pm) + cc * (wp - wm), ko * (pl - pw) + co * (wl - ww)
        f = force(t, r1 * pp - r2 * pw, r1 * wp - r2 * ww)
        return [wm, wp, ww, wl, (M1 + tc) / Im, (-tc - r1 * f) / I1, (r2 * f + to) / I2, (-to - M3) / IL]

    t = ours.time.to("s").magnitude
    start = [0.0, twist_c, (r1 * twist_c - x0) / r2, (r1 * twist_c - x0) / r2 + twist_o, 0, 0, 0, 0]
    sol = solve_ivp(rhs, (0.0, t[-1]), start, method="DOP853", t_eval=t, rtol=1e-11, atol=1e-14,
                    max_step=0.02 * 2 * math.pi / mesh)
    pm, pp, pw, pl, wm, wp, ww, wl = sol.y
    expected = {"xc": (pp - pm, "rad"), "vc": (wp - wm, "rad/s"), "xo": (pl - pw, "rad"), "vo": (wl - ww, "rad/s"),
                "x": (r1 * pp - r2 * pw, "m"), "v": (r1 * wp - r2 * ww, "m/s")}
    for name, (theirs, unit) in expected.items():
        got = ours[name].to(unit).magnitude
        assert np.max(np.abs(got - theirs)) < 1e-5 * np.max(np.abs(theirs)), name
    assert str(ours["xc"].units) == "radian" and str(ours["vo"].units) == "radian / second"
    torques = {"coupling": kc * (pp - pm) + cc * (wp - wm), "output": ko * (pl - pw) + co * (wl - ww)}
    for name, theirs in torques.items():
        got = ours.shaft_torque[name].to("N*m").magnitude
        assert np.max(np.abs(got - theirs)) < 1e-5 * np.max(np.abs(theirs)), name
    theirs = np.array([force(ti, xi, vi) for ti, xi, vi in zip(t, r1 * pp - r2 * pw, r1 * wp - r2 * ww)])
    assert np.max(np.abs(ours.mesh_force["mesh"].to("N").magnitude - theirs)) < 1e-5 * np.max(np.abs(theirs))


@pytest.mark.slow
def test_a_spectrum_of_a_train_with_shafts_gives_twists_in_rad_and_shaft_torques_in_newton_metres():
    s = gearsym.scaling(motor_coupling_gear())
    result = gearsym.lyapunov_spectrum(s.system(), options=Integration(periods=120, discard=60))
    point = s.to_physical(result)
    lines = "\n".join(point.lines())
    assert "amplitude A_xc = " in lines and lines.split("amplitude A_xc = ")[1].split("\n")[0].endswith(" rad")
    # at a steady state the coupling passes the motor's torque on: its mean torque is -M1 (twist = pinion - motor)
    assert point.shaft_torque["coupling"]["mean"].to("N*m").magnitude == pytest.approx(-100.0, rel=1e-4)
    assert point.shaft_torque["output"]["mean"].to("N*m").magnitude == pytest.approx(-100 * 61 / 23, rel=1e-4)
    assert point.as_dict()["shaft_torque"]["coupling"]["mean"]["unit"] == "N·m"
    assert point.as_dict()["amplitude"]["xo"]["unit"] == "rad"


# ------------------------------------------------------------------ the mean over whole periods (item 7)
def test_a_mean_over_a_sampled_periodic_signal_counts_each_phase_once():
    period, per = 2 * math.pi, 200
    time = np.linspace(0.0, 20 * period, 20 * per + 1)  # both ends: 4001 samples, as a trajectory gives them
    signal = 3.0 + 2.0 * np.cos(time) + 0.5 * np.sin(3 * time)  # mean 3, exactly
    assert whole_period_mean(time, signal, period) == pytest.approx(3.0, rel=1e-14)
    assert abs(np.mean(signal) - 3.0) > 1e-4  # the plain mean counts the phase at both ends twice
    # samples beyond the last whole period are left out, as the phase they would weigh twice
    longer = np.linspace(0.0, 20.5 * period, 20 * per + per // 2 + 1)
    assert whole_period_mean(longer, 3.0 + 2.0 * np.cos(longer), period) == pytest.approx(3.0, rel=1e-14)


def test_the_mean_mesh_force_of_a_point_is_the_mean_over_whole_periods():
    """The point's summary takes its mean over the trajectory's whole periods: a fake trajectory of known mean."""
    s = gearsym.scaling(reduced("spur_pair"))
    units = s.point_units()
    period, per = 2 * math.pi, 200
    tau = np.linspace(0.0, 20 * period, 20 * per + 1)
    x = (2.0 + np.cos(tau)) * 1e-6 / s.length_si  # in contact throughout: force = kZ k(tau) x + cZ x'
    trajectory = Trajectory("spur_pair", ("x", "v"), tau, np.vstack([x, np.zeros_like(x)]), np.zeros((2, 21)))
    samples = units.mesh_forces(trajectory, 1.0)["mesh"]
    spectrum = gearsym.LyapunovSpectrum("spur_pair", {"omega": 1.0}, np.zeros(2), np.zeros(2),
                                        np.zeros((1, 2)), {}, {}, np.zeros((2, 1)), 21, 1, per, period, "")
    mean = units.point(spectrum, trajectory).mesh_force["mesh"]["mean"].magnitude
    exact = np.mean(samples[:-1])  # one sample per phase (the last repeats the first)
    assert mean == pytest.approx(exact, rel=1e-13)
    assert abs(np.mean(samples) - exact) > 1e-5 * exact


@pytest.mark.slow
def test_python_and_the_command_line_give_the_mean_mesh_force_of_a_periodic_orbit_exactly(spur, capsys):
    """On a periodic orbit the pinion does not accelerate on average, so the mean mesh force is M1 / r1 (the
    torque harmonic and the damping average out); ``to_physical`` runs the trajectory itself when not given
    one (Python), as the command line does. At 5000 rpm the teeth stay in contact, so the force is smooth and its
    mean over the RK4 steps exact (at the default 6000 rpm, on the second harmonic's resonance, they separate)."""
    exact = declared("M1") / declared("r1")
    spur = gearsym.scaling(reduced("spur_pair"), speed="5000 rpm")
    result = gearsym.lyapunov_spectrum(spur.system(), options=Integration(periods=200, discard=150))
    point = spur.to_physical(result)
    assert point.mesh_force["mesh"]["mean"].to("N").magnitude == pytest.approx(exact, rel=1e-7)
    stiffer = gearsym.scaling(reduced("spur_pair"), k="2", speed="5000 rpm")  # a formula replaces the stiffness
    result = gearsym.lyapunov_spectrum(stiffer.system(), options=Integration(periods=200, discard=150))
    assert stiffer.to_physical(result).mesh_force["mesh"]["mean"].to("N").magnitude == pytest.approx(exact, rel=1e-7)
    assert main(["lyap", "spur_pair", "--set", "k=2", "--set", "speed=5000 rpm", "--periods", "200", "--discard",
                 "150", "--format", "json"]) == 0
    force = json.loads(capsys.readouterr().out)["physical"]["mesh_force"]["mesh"]["mean"]
    assert force["unit"] == "N" and force["value"] == pytest.approx(exact, rel=1e-7)


# ------------------------------------------------------------------ a speed sweep in Python
def test_a_speed_sweep_in_python_runs_along_the_speeds_given_and_answers_in_their_units(spur):
    speeds = ["9000 rpm", "10000 rpm", "1.2e4 rpm"]
    options = Integration(periods=30, discard=20)
    result = gearsym.run_sweep(spur, {"speed": speeds}, options=options, execution=gearsym.Execution(1, "threads"))
    assert result.axes[0].name == "speed" and list(result["speed"]) == [9000.0, 10000.0, 12000.0]
    assert result.units["speed"] == "rpm" and result.units["A_x"] == "µm" and result.units["lambda_1"] == "1/s"
    engine = gearsym.run_sweep(spur.system(), {"omega": [spur.omega(v) for v in speeds]}, options=options,
                               execution=gearsym.Execution(1, "threads"))
    assert result["A_x"] == pytest.approx(engine["A_x"] * spur.length.to("um").magnitude, rel=1e-12)
    back = spur.to_physical(engine)  # (an omega sweep alone: the speeds to their significant digits)
    assert list(back["speed"]) == [9000.0, 10000.0, 12000.0] and back.units["speed"] == "rpm"
    omega = np.asarray(engine["omega"])
    assert result["lambda_1"] == pytest.approx(engine["lambda_1"] * omega * spur.omega_n.to("rad/s").magnitude,
                                               rel=1e-12)


def test_a_speed_sweep_of_the_engines_model_says_how_to_sweep_speeds(spur):
    with pytest.raises(GearsymError, match=r"run_sweep: speed='1000 rpm' is a physical value.*"
                                           r"gearsym\.run_sweep\(gearsym\.scaling\('spur_pair'\)"):
        gearsym.run_sweep(spur.system(), {"speed": ["1000 rpm", "2000 rpm"]})


# ------------------------------------------------------------------ one rule for a unitless speed
UNITLESS = r"9000 has no unit, and a rotational speed needs one: write "


@pytest.mark.parametrize("argv, fix", [
    (["lyap", "spur_pair", "--set", "speed=9000"], "speed='9000 rpm'"),
    (["modes", "spur_pair", "--set", "speed=9000"], "speed='9000 rpm'"),
    (["simulate", "spur_pair", "--set", "speed=9000", "--out", "m.csv"], "speed='9000 rpm'"),
    (["sweep", "spur_pair", "--param", "speed=9000:16000:7000", "--out", "s.csv"],
     "speed=9000rpm:16000rpm:7000rpm"),
    (["campbell", "spur_pair", "--param", "speed=9000:16000:7000", "--out", "c.csv", "--plot", "c.png"],
     "speed=9000rpm:16000rpm:7000rpm"),
    (["orbits", "spur_pair", "--param", "speed=9000:12000"], "speed=9000rpm:12000rpm"),
])
def test_a_unitless_speed_on_the_command_line_is_refused_with_one_message(argv, fix, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert UNITLESS + fix in err and err.count("\n") == 1, err


@pytest.mark.parametrize("call, fix", [
    (lambda s: gearsym.load(reduced("spur_pair"), speed=9000), "speed='9000 rpm'"),
    (lambda s: gearsym.scaling(reduced("spur_pair"), speed="9000"), "speed='9000 rpm'"),
    (lambda s: gearsym.natural_modes(reduced("spur_pair"), speed=9000.0), "speed='9000 rpm'"),
    (lambda s: s.omega(9000), "speed='9000 rpm'"),
    (lambda s: s.with_values(speed=9000), "speed='9000 rpm'"),
    (lambda s: gearsym.run_sweep(s, {"speed": [9000, 12000]}), "{'speed': ['9000 rpm', '12000 rpm']}"),
])
def test_a_unitless_speed_in_python_is_refused_with_the_same_message(spur, call, fix):
    with pytest.raises(GearsymError) as err:
        call(spur)
    assert UNITLESS + fix in str(err.value)


def test_a_model_that_declares_a_plain_number_for_a_stiffness_gets_the_same_message():
    model = motor_coupling_gear()
    model.set_physical(kZ=2e8)
    with pytest.raises(GearsymError, match=r"motor_coupling_gear_si: kZ: 2e\+08 has no unit, and a mesh stiffness "
                                           r"needs one: write kZ='2e\+08 N/m'"):
        gearsym.scaling(model)
    model.set_physical(kZ=gearsym.units.Quantity(2e8))  # (a dimensionless pint Quantity alike)
    with pytest.raises(GearsymError, match=r"kZ: 2e\+08 has no unit"):
        gearsym.scaling(model)


def test_a_unitless_backlash_gets_the_same_message_in_its_unit(capsys):
    assert main(["lyap", "spur_pair", "--set", "eta=50"]) == 2
    assert "spur_pair: eta: 50 has no unit, and a backlash needs one: write eta='50 µm'" in capsys.readouterr().err


# ------------------------------------------------------------------ errors in the user's units
@pytest.mark.parametrize("value, message", [
    ({"eta": "-50 um"}, r"spur_pair: eta: -50 µm is a backlash and must not be negative"),
    ({"kZ": "-2e8 N/m"}, r"spur_pair: kZ: -2e\+08 N/m is a stiffness and must not be negative"),
    ({"I1": "0 kg*m^2"}, r"spur_pair: I1: 0 kg·m² is an inertia and must be positive"),
    ({"speed": "150 1/s"}, r"150 1/s is a frequency without an angle: write '150 rev/s' \(revolutions\) or '150 rad/s'"),
    ({"speed": "9000 rpms"}, r"unknown unit 'rpms' in '9000 rpms'; did you mean 'rpm'\?"),
    ({"speed": "3000 rpm**-1e9"}, r"'3000 rpm\*\*-1e9' is inf in SI units, out of the range of a number"),
])
def test_bad_values_are_reported_in_the_units_they_were_given_in(value, message, capsys):
    name, text = next(iter(value.items()))
    with pytest.raises(GearsymError, match=message):
        gearsym.scaling(reduced("spur_pair"), **value)
    assert main(["lyap", "spur_pair", "--set", f"{name}={text}"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "mm²" not in err and "/kg" not in err


@pytest.mark.parametrize("written", ["9000 1/min", "9000 rev/min", "9000 min^-1", "150 rev/s", "150 Hz",
                                     "942.477796076938 rad/s"])
def test_the_ways_people_write_a_speed_are_that_speed(spur, written):
    assert spur.omega(written) == pytest.approx(spur.omega("9000 rpm"), rel=1e-12)


# ------------------------------------------------------------------ stiffness formulas: modes, phi and t
def test_the_modes_of_a_stiffness_formula_have_its_mean_stiffness(capsys):
    """Two gears on a mesh: f = sqrt(k (r1^2/I1 + r2^2/I2)) / 2 pi with k the mean of the formula."""
    assert main(["modes", "one_stage", "--set", "k=2+0.2*cos(tau)", "--format", "json"]) == 0
    frequencies = json.loads(capsys.readouterr().out)["frequencies"]
    assert frequencies == pytest.approx([0.0, math.sqrt(2.0)], abs=1e-12)  # in the model's time unit 1/omega_n
    assert main(["modes", "spur_pair", "--set", "k=2", "--format", "json"]) == 0
    frequencies = json.loads(capsys.readouterr().out)["frequencies"]
    m = declared("r1") ** 2 / declared("I1") + declared("r2") ** 2 / declared("I2")
    textbook = math.sqrt(2 * declared("kZ") * m) / (2 * math.pi)
    assert frequencies == pytest.approx([0.0, textbook], rel=1e-12)


def test_a_stiffness_formula_may_be_written_in_the_mesh_phase_phi():
    """phi is the mesh's phase: its order times tau plus its phase (the idler's second mesh has a phase ph2)."""
    nd = reduced("idler")
    f = next(f for f in nd.functions if f.mesh == "m2")
    import sympy as sp
    from gearsym.model.symbols import omega, parameter_symbol, tau

    rc = nd._mesh(f)
    expected = sp.cos(sp.expand(rc.mesh_phase.subs(sp.Symbol("t", real=True), tau / omega)))
    assert nd.stiffness_formula(f, "cos(phi)") == expected
    assert parameter_symbol("ph2") in expected.free_symbols  # (the phase is in it: not the same as cos(tau))
    one = gearsym.load(reduced("one_stage"), k="1+0.2*cos(phi)")  # order 1, no phase: the same as in tau
    assert one.rhs == gearsym.load(reduced("one_stage"), k="1+0.2*cos(tau)").rhs


def test_a_stiffness_formula_in_t_names_the_function_and_the_variables_it_takes(capsys):
    assert main(["lyap", "one_stage", "--set", "k=1+0.2*cos(t)"]) == 2
    err = capsys.readouterr().err
    assert "k='1+0.2*cos(t)' uses t, but a mesh stiffness is a function of tau" in err and "phi" in err
    assert "dv/dtau" not in err and "eta" not in err and err.count("\n") == 1


# ------------------------------------------------------------------ the commands' outputs in the user's units
def test_a_physical_sweep_reports_its_jumps_and_tables_in_rpm_and_micrometres(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "spur_pair", "--param", "speed=9000rpm:13000rpm:500rpm", "--direction", "both",
                 "--periods", "60", "--discard", "40", "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    text = capsys.readouterr().out
    engine = json.loads((tmp_path / "s.json").read_text())
    physical = json.loads((tmp_path / "s.physical.json").read_text())
    assert engine["jumps"] or engine["hysteresis"], "the run should show the resonance's hysteresis"
    s = gearsym.scaling(reduced("spur_pair"))
    for found, theirs in zip(engine["jumps"], physical["jumps"]):
        assert theirs["from"] == pytest.approx(s.speed_at(found["from"]).to("rpm").magnitude, rel=1e-12)
        assert theirs["A_before"] == pytest.approx(found["A_before"] * s.length.to("um").magnitude, rel=1e-12)
        assert f"speed {theirs['from']:g} -> {theirs['to']:g} rpm" in text
    for h in physical["hysteresis"]:
        assert f"up and down differ for speed in [{h['from']:g}, {h['to']:g}] rpm" in text
    assert "omega" not in text.split("regimes:")[1]
    rows = (tmp_path / "s.physical.csv").read_text().splitlines()
    assert [r.split(",")[0] for r in rows[1:6]] == ["9000.0", "9500.0", "10000.0", "10500.0", "11000.0"]


def test_gearsym_orbits_of_a_physical_model_answers_in_rpm_and_micrometres(tmp_path, capsys):
    out, plot = tmp_path / "o.csv", tmp_path / "o.png"
    assert main(["orbits", "spur_pair", "--param", "speed=7000rpm:8000rpm", "--transient", "100",
                 "--out", str(out), "--plot", str(plot)]) == 0  # below the main resonance's fold (9353 rpm)
    text = capsys.readouterr().out
    assert "speed 7000 -> 8000 rpm" in text and "reached speed=8000 rpm" in text
    engine = out.read_text().splitlines()
    physical = (tmp_path / "o.physical.csv").read_text().splitlines()
    header = physical[0].split(",")
    assert header[2:4] == ["speed [rpm]", "A_x [µm]"] and "state_v [mm/s]" in header
    s = gearsym.scaling(reduced("spur_pair"))
    for ours, theirs in zip(physical[1:], engine[1:]):
        speed, a = map(float, ours.split(",")[2:4])
        omega, a_engine = map(float, theirs.split(",")[2:4])
        assert speed == pytest.approx(s.speed_at(omega).to("rpm").magnitude, rel=1e-11)
        assert a == pytest.approx(a_engine * s.length.to("um").magnitude, rel=1e-12)
    record = json.loads((tmp_path / "o.json").read_text())
    assert record["physical"]["parameter"] == "speed" and record["physical"]["units"]["A_x"] == "µm"
    assert plot.stat().st_size > 10_000


def test_the_figures_of_a_physical_model_are_titled_and_labelled_in_its_units(spur):
    from gearsym.figures.orbits import orbits_title
    from gearsym.figures.point import plot_point
    from gearsym.figures.sweep import sweep_title

    options = Integration(periods=30, discard=20)
    result = gearsym.run_sweep(spur, {"speed": ["9000 rpm", "9500 rpm"]}, options=options, execution=gearsym.Execution(1, "threads"))
    title = sweep_title(result, 1000)
    kZ = reduced("spur_pair").drivetrain.physical["kZ"].text()  # the mean of the computed stiffness
    assert "speed = 9000..9500 rpm" in title and f"kZ={kZ}" in title and "M1=71.8 N·m" in title
    assert "omega" not in title and "eta=7.38" not in title
    compiled = gearsym.compile_model(spur.system(), options)
    orbits = spur.to_physical(gearsym.continue_orbits(compiled, "omega", spur.omega("9000 rpm"),
                                                      spur.omega("9300 rpm"), max_points=4))
    title = orbits_title(orbits, 1000)
    cZ = reduced("spur_pair").drivetrain.physical["cZ"].text()
    assert "over speed = 9000..9300 rpm" in title and f"cZ={cZ}" in title and "zeta" not in title
    spectrum = gearsym.lyapunov_spectrum(compiled)
    trajectory = gearsym.phase_trajectory(compiled, options=options.run(periods=3, discard=0),
                                          y0=spectrum.final_state)
    shown, shown_trajectory, units, title = spur.point_units().figure(spectrum, trajectory)
    fig = plot_point(shown, shown_trajectory, units=units, title=title)
    left, right = fig.axes[:2]
    assert left.get_ylabel().endswith("[1/s]") and right.get_xlabel() == "x [µm]" and right.get_ylabel() == "v [mm/s]"
    assert "6000 rpm" in fig._suptitle.get_text() and f"kZ={kZ}" in fig._suptitle.get_text()
    assert shown.exponents == pytest.approx(spectrum.exponents * spur.values["omega"]
                                            * spur.omega_n.to("rad/s").magnitude, rel=1e-12)


def test_gearsym_campbell_writes_a_physical_table_and_the_orders_units(tmp_path, capsys):
    out, plot = tmp_path / "c.csv", tmp_path / "c.png"
    assert main(["campbell", "spur_pair", "--param", "speed=6000rpm:14000rpm:4000rpm", "--periods", "30",
                 "--discard", "20", "--out", str(out), "--plot", str(plot), "--quiet", "--jobs", "1"]) == 0
    rows = (tmp_path / "c.physical.csv").read_text().splitlines()
    assert rows[0].startswith("speed [rpm],direction,A_x [µm],lambda_1 [1/s]")
    assert [r.split(",")[0] for r in rows[1:]] == ["6000.0", "10000.0", "14000.0"]
    diagram = json.loads((tmp_path / "c.campbell.json").read_text())
    assert diagram["orders"][0] == {"label": "1x mesh", "kind": "mesh", "cycles_per_revolution": 28.0}
    assert diagram["speed"] == "the speed of 'pinion'"


def test_a_physical_model_without_a_declared_speed_still_answers_in_its_units(capsys):
    """The paper's flexible shaft given physical values (no body declares a speed; omega stays the engine's):
    the mesh in µm and N, the shaft's twist in rad and its torque in N·m."""
    values = dict(I1="2e-3 kg*m^2", I2="3e-3 kg*m^2", I3="5e-3 kg*m^2", r1="30 mm", r2="45 mm", kZ="2e8 N/m",
                  cZ="400 N*s/m", eta="60 um", kS="2e4 N*m/rad", M1="160 N*m", M2="90 N*m", M3="150 N*m",
                  M1a="5 N*m", Theta="0.3", k_a="0.2")
    argv = ["lyap", "flexible_shaft", "--periods", "60", "--discard", "40"]
    for name, value in values.items():
        argv += ["--set", f"{name}={value}"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "operating point: mesh frequency" in text and "nan" not in text
    assert text.split("amplitude A_x2 = ")[-1].split("\n")[0].endswith(" rad")
    assert text.split("amplitude A_x1 = ")[-1].split("\n")[0].endswith(" µm")
    assert "shaft torque shaft: mean " in text and " N·m" in text.split("shaft torque shaft:")[1]


def test_a_two_dimensional_physical_sweep_is_drawn_in_its_units(spur):
    from gearsym.figures.sweep import plot_sweep

    result = gearsym.run_sweep(spur, {"speed": ["9000 rpm", "9500 rpm"], "cZ": ["200 N*s/m", "500 N*s/m"]},
                               options=Integration(periods=30, discard=20), execution=gearsym.Execution(1, "threads"))
    assert sorted(set(result["cZ"])) == [200.0, 500.0] and result.units["cZ"] == "N·s/m"
    labels = [a.get_ylabel() for a in plot_sweep(result).axes] + [a.get_xlabel() for a in plot_sweep(result).axes]
    assert "speed [rpm]" in labels and "cZ [N·s/m]" in labels
    assert r"$\lambda_1$ [1/s]" in labels and "A (x) [µm]" in labels  # (the colour bars)
