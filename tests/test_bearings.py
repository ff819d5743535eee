"""Gears on bearings (issue 39): Lin & Parker's translational planetary model against its mass and stiffness
matrices typed from the paper in NumPy (tests/lin_parker.py), the lateral-torsional pair against its equations
typed here in SciPy, and the torsional limit (very stiff bearings) against spur_pair.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import gearsym
from gearsym import Integration
from gearsym.analysis.modes import drivetrain_modes
from gearsym.cli import main
from gearsym.registry import load_model
from gearsym.scales.si_values import si_values
from lin_parker import matrices, natural_frequencies

CENTRAL = ("sun", "ring", "carrier")


def lin_parker_parameters(values: dict) -> dict:
    """The paper's parameters (masses, I/r^2, stiffnesses on u = r theta) from the model's SI values."""
    r = {k: values[f"r_{k}"] for k in "sprc"}
    return dict(m_s=values["m_s"], m_r=values["m_r"], m_c=values["m_c"], m_p=values["m_p"],
                j_s=values["I_s"] / r["s"] ** 2, j_r=values["I_r"] / r["r"] ** 2, j_c=values["I_c"] / r["c"] ** 2,
                j_p=values["I_p"] / r["p"] ** 2, k_s=values["k_s"], k_r=values["k_r"], k_c=values["k_c"],
                k_su=0.0, k_cu=0.0, k_ru=values["k_ru"] / r["r"] ** 2, k_p=values["k_p"], k_sp=values["k_sp"],
                k_rp=values["k_rp"], alpha_s=values["alpha_s"], alpha_r=values["alpha_r"])


@pytest.fixture(scope="module", params=[3, 4, pytest.param(5, marks=pytest.mark.slow)], ids=lambda n: f"N={n}")
def planetary(request):
    """gearsym's modes of the translational planetary set with N planets and the paper's matrices' frequencies."""
    planets = request.param
    model = load_model("planetary_translational", {"planets": planets, "stationary": 1})
    values = si_values(model, {})
    mass, stiffness, _, _ = matrices(lin_parker_parameters(values), planets)
    frequencies, _ = natural_frequencies(mass, stiffness)
    return planets, drivetrain_modes(model, values), frequencies


@pytest.mark.slow
def test_the_translational_planetary_set_has_the_frequencies_of_lin_and_parkers_matrices(planetary):
    planets, modes, expected = planetary
    got = np.array(modes.frequencies)
    assert len(got) == len(expected) == 3 * (planets + 3)
    assert got[0] == 0.0 and expected[0] < 1e-3  # the rigid-body mode (the ring held, sun and carrier free)
    assert np.max(np.abs(got[1:] - expected[1:]) / expected[1:]) < 1e-9


@pytest.mark.slow
def test_its_modes_fall_into_lin_and_parkers_three_classes_with_their_multiplicities(planetary):
    planets, modes, _ = planetary
    elastic = [m for m in modes.modes if m.kind != "rigid"]
    by_kind = {kind: [m for m in elastic if m.kind == kind] for kind in ("rotational", "translational", "planet")}
    assert len(elastic) == sum(len(v) for v in by_kind.values())  # nothing else ("mixed")
    assert len(by_kind["rotational"]) == 5 and all(m.multiplicity == 1 for m in by_kind["rotational"])
    assert len(by_kind["translational"]) == 12 and all(m.multiplicity == 2 for m in by_kind["translational"])
    assert len(by_kind["planet"]) == 3 * (planets - 3)
    assert all(m.multiplicity == planets - 3 for m in by_kind["planet"])
    # a multiplicity is the number of modes at that frequency
    for m in elastic:
        assert sum(1 for o in elastic if abs(o.frequency - m.frequency) < 1e-6 * m.frequency) == m.multiplicity


def test_its_mode_shapes_have_lin_and_parkers_properties(planetary):
    """Rotational modes: the central members only turn and every planet moves alike; translational modes: the
    central members only translate; planet modes: the central members do not move and the planets' motions sum to
    zero, as do their first harmonics in the planet positions (Lin & Parker 1999, Sections 3-5)."""
    planets, modes, _ = planetary
    positions = [2 * math.pi * n / planets for n in range(planets)]
    for m in modes.modes:
        shape = m.shape
        moves = [f"{b}.{d}" for b in CENTRAL for d in "xy" if f"{b}.{d}" in shape]
        planet = {what: np.array([shape[f"planet{n + 1}{what}"] for n in range(planets)])
                  for what in ("", ".radial", ".tangential")}
        if m.kind == "rotational":
            assert max(abs(shape[k]) for k in moves) < 1e-9
            assert all(np.ptp(v) < 1e-9 for v in planet.values())
        elif m.kind == "translational":
            assert max(abs(shape[b]) for b in CENTRAL) < 1e-9
            assert max(abs(shape[k]) for k in moves) > 1e-3
        elif m.kind == "planet":
            assert max(abs(shape[k]) for k in (*CENTRAL, *moves)) < 1e-9
            for v in planet.values():
                assert abs(v.sum()) < 1e-9
                assert abs(v @ np.cos(positions)) < 1e-9 and abs(v @ np.sin(positions)) < 1e-9


def test_gearsym_modes_gives_the_planetary_sets_modes_as_json_with_kind_and_multiplicity(capsys):
    assert main(["modes", "planetary_translational", "--set", "planets=4", "--set", "stationary=1",
                 "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["modes"]) == 21
    first = out["modes"][1]
    assert set(first) >= {"frequency", "multiplicity", "kind", "shape"}
    assert first["frequency"]["unit"] == "Hz" and first["frequency"]["value"] > 0
    assert {m["kind"] for m in out["modes"]} == {"rigid", "rotational", "translational", "planet"}
    assert [m["multiplicity"] for m in out["modes"] if m["kind"] == "planet"] == [1, 1, 1]
    assert "planet3.radial" in first["shape"] and "sun.x" in first["shape"]


# ----------------------------------------------------------------------------- the lateral-torsional pair

#: a periodic point with tooth separations (single-sided impacts): near the pair's mesh resonance, light load
PAIR = dict(k="1+0.3*cos(tau)", M1="20 N*m", M2="20 N*m", M1a="10 N*m", speed="4700 rpm")
PAIR_RUN = Integration(steps_per_period=1024, periods=300, discard=250)


@pytest.fixture(scope="module")
def pair():
    """The 4-degree-of-freedom pair at PAIR, compiled, and its periodic orbit with every RK4 step."""
    scaling = gearsym.scaling("spur_pair_bearings", **PAIR)
    model = gearsym.compile_model(scaling.system(), PAIR_RUN)
    return scaling, gearsym.periodic_orbit(model, options=PAIR_RUN, trajectory=True)


def kahraman_singh(p: dict, forcing: float):
    """Kahraman & Singh's lateral-torsional pair, typed here in SI (y along the line of action):
    m1 y1'' + c_b1 y1' + k_b1 y1 + F = 0, m2 y2'' + c_b2 y2' + k_b2 y2 - F = 0,
    I1 th1'' + r1 F = M1 + M1a cos(w t + Theta), I2 th2'' - r2 F = -M2,
    F = kZ (1 + 0.3 cos w t) g(d, eta) + cZ d', d = r1 th1 - r2 th2 + y1 - y2."""
    eta = p["eta"]

    def g(d):
        return d if d >= 0 else (d + eta if d <= -eta else 0.0)

    def rhs(t, s):
        th1, th2, y1, y2, w1, w2, v1, v2 = s
        d = p["r1"] * th1 - p["r2"] * th2 + y1 - y2
        dd = p["r1"] * w1 - p["r2"] * w2 + v1 - v2
        force = p["kZ"] * (1 + 0.3 * math.cos(forcing * t)) * g(d) + p["cZ"] * dd
        return [w1, w2, v1, v2,
                (p["M1"] + p["M1a"] * math.cos(forcing * t + p["Theta"]) - p["r1"] * force) / p["I1"],
                (-p["M2"] + p["r2"] * force) / p["I2"],
                (-p["c_b1"] * v1 - p["k_b1"] * y1 - force) / p["m1"],
                (-p["c_b2"] * v2 - p["k_b2"] * y2 + force) / p["m2"]]

    return rhs


@pytest.mark.slow
def test_the_pair_on_bearings_follows_its_typed_equations_at_a_periodic_point_with_tooth_separations(pair):
    from scipy.integrate import solve_ivp

    scaling, orbit = pair
    assert orbit.stable and orbit.contact["mesh"] == "single-sided impact"
    p = dict(scaling.si_values)
    length, forcing = scaling.length_si, orbit.parameters["omega"] * scaling.omega_n_si
    names = list(orbit.state_names)
    states = dict(zip(names, orbit.trajectory))
    tau = np.linspace(0.0, orbit.forcing_period, orbit.trajectory.shape[1])
    x, y1, y2 = (states[n] * length for n in ("x", "y_pinion", "y_wheel"))
    v, v1, v2 = (states[n] * length * forcing for n in ("v", "dy_pinion", "dy_wheel"))
    # the absolute angles from the deflection (the rigid rotation is free: the pinion starts at 0)
    start = [0.0, (y1[0] - y2[0] - x[0]) / p["r2"], y1[0], y2[0], 0.0, (v1[0] - v2[0] - v[0]) / p["r2"], v1[0], v2[0]]
    t = tau / forcing
    sol = solve_ivp(kahraman_singh(p, forcing), (0.0, t[-1]), start, method="DOP853", t_eval=t, rtol=1e-12,
                    atol=1e-18, max_step=t[-1] / 400)
    th1, th2, sy1, sy2 = sol.y[:4]
    typed = {"x": p["r1"] * th1 - p["r2"] * th2 + sy1 - sy2, "y_pinion": sy1, "y_wheel": sy2}
    for name, got in (("x", x), ("y_pinion", y1), ("y_wheel", y2)):
        size = np.ptp(got)
        assert np.max(np.abs(typed[name] - got)) < 1e-6 * size, name
        assert abs(typed[name][-1] - typed[name][0]) < 1e-6 * size, name  # periodic in the typed equations too


def test_the_pair_on_stiff_bearings_has_the_torsional_pairs_frequency():
    torsional = gearsym.natural_modes("spur_pair").elastic[0].frequency
    model = load_model("spur_pair_bearings")
    stiff = drivetrain_modes(model, si_values(model, dict(k_b1="1e14 N/m", k_b2="1e14 N/m")))
    nearest = min(stiff.elastic, key=lambda m: abs(m.frequency - torsional))
    assert nearest.frequency == pytest.approx(torsional, rel=1e-5)
    soft = drivetrain_modes(model, si_values(model, {}))  # on its real bearings the mesh mode moves away
    assert min(abs(m.frequency - torsional) for m in soft.elastic) > 1e-3 * torsional


@pytest.mark.slow
def test_the_pair_on_stiff_bearings_responds_as_the_torsional_pair(pair):
    """With bearings 1e4 times stiffer than the mesh the periodic orbit's mesh deflection is spur_pair's.
    In-process, from 60 periods of transient: two libraries of their own cost 5 s of compiling, 300 periods
    in-process 3.5 s, this 0.5 s, for the same orbits (their extremes alike to 1e-14 of their range)."""
    run = Integration(steps_per_period=2048, periods=60, discard=10, backend="in-process")
    answers = {}
    for name, extra in (("spur_pair", {}), ("spur_pair_bearings", dict(k_b1="1e12 N/m", k_b2="1e12 N/m"))):
        scaling = gearsym.scaling(name, **PAIR, **extra)
        orbit = gearsym.periodic_orbit(gearsym.compile_model(scaling.system(), run), options=run)
        answers[name] = np.array(orbit.extremes["x"]) * scaling.length_si
    torsional, lateral = answers["spur_pair"], answers["spur_pair_bearings"]
    assert np.max(np.abs(lateral - torsional)) < 2e-3 * np.ptp(torsional)


# ----------------------------------------------------------------------------- a bearing's accelerometer


@pytest.mark.slow
def test_a_bearing_accelerometer_is_a_channel_and_its_record_gives_the_mesh_damping_back(pair, tmp_path):
    """A record of the pinion centre's acceleration (the channel a_pinion_y, what an accelerometer on its
    bearing housing reads) is a channel of the pair on bearings, and fitting the mesh's damping ratio to it
    from a start 30 % off gives the value the record was made with."""
    import sympy as sp

    from gearsym.data import load_measurements
    from gearsym.fit.selection import explain

    scaling, _ = pair
    system = scaling.system()
    assert {k: str(v) for k, v in system.translations.items()} == {"pinion_y": "y_pinion", "wheel_y": "y_wheel"}
    run = Integration(steps_per_period=PAIR_RUN.steps_per_period, periods=40, discard=20)  # (the pair's library)
    model = gearsym.compile_model(system, run)
    trajectory = gearsym.phase_trajectory(model, options=run)
    states = list(system.states)
    backlash = {"g": lambda x, eta: np.where(x >= 0, x, np.where(x <= -eta, x + eta, 0.0))}
    acceleration = sp.lambdify([system.time, *states, *system.parameter_symbols],
                               system.rhs[states.index(sp.Symbol("dy_pinion", real=True))], [backlash, "numpy"])
    p = [system.parameters[s.name] for s in system.parameter_symbols]
    every = 16  # 64 samples per period
    tau = trajectory.time[::every]
    a = acceleration(tau, *trajectory.states[:, ::every], *p)
    path = tmp_path / "housing.csv"
    path.write_text("tau,a_pinion_y\n" + "".join(f"{float(t)!r},{float(v)!r}\n" for t, v in zip(tau, a)))
    measurements = load_measurements(path, system)
    truth = system.parameters["zeta"]
    ex = explain(system.with_values(zeta=1.3 * truth), measurements, ["zeta"], candidates=(), propose=False,
                 options=run)
    assert ex.final.fit.estimates["zeta"] == pytest.approx(truth, rel=1e-3)


def test_the_carrier_frames_coriolis_and_centripetal_terms_are_lin_and_parkers():
    """With the frame's terms kept, each translating body's generalized forces are Lin & Parker's
    -(Omega_c G q' - Omega_c^2 K_Omega q) with G = [[0, -2m], [2m, 0]] and K_Omega = diag(m, m) on its (x, y) or
    (radial, tangential); the carrier turns at 1/94 of the mesh frequency (26/34/94 teeth, the ring held)."""
    import sympy as sp

    from gearsym.model.translations import CARRIER_SPEED
    from gearsym.model.symbols import t

    rd = load_model("planetary_translational").resolved
    assert rd.frame_turns and rd.carrier_speed_ratio() == sp.Rational(1, 94)
    speed = sp.Symbol(CARRIER_SPEED, real=True)
    forces = rd.frame_forces
    for centre in rd.centres.values():
        (i, u), (j, v) = [(d.index, d.angle) for d in centre.translations]
        m = centre.translations[0].inertia
        gyroscopic = sp.Matrix([[0, -2 * m], [2 * m, 0]])
        for row, k in enumerate((i, j)):
            for col, q in enumerate((u, v)):
                assert sp.expand(forces[k].diff(sp.diff(q, t)) + speed * gyroscopic[row, col]) == 0
                assert sp.expand(forces[k].diff(q) - speed**2 * (m if row == col else 0)) == 0
    stationary = load_model("planetary_translational", {"stationary": 1}).resolved
    assert not stationary.frame_turns and all(f == 0 for f in stationary.frame_forces)


@pytest.mark.parametrize("dof", [4, 6])
def test_the_pair_at_rest_loads_each_bearing_with_the_mesh_force_along_the_line_of_action(dof):
    """At rest under the mean torques each bearing carries the mesh force, in the line of action's direction:
    along y for 4 degrees of freedom, split into F sin(alpha), F cos(alpha) in x and y for 6 (line of centres
    along x); the mesh force is the torque over the base radius."""
    scaling = gearsym.scaling(load_model("spur_pair_bearings", {"dof": dof}))
    statics, si = scaling.statics, scaling.si_values
    force = statics.mesh_forces["mesh"]
    assert force == pytest.approx(si["M1"] / si["r1"], rel=1e-9)
    alpha = si["alpha"]
    expected = {"y": force} if dof == 4 else {"x": force * math.sin(alpha), "y": force * math.cos(alpha)}
    for direction, value in expected.items():
        assert statics.bearing_forces[f"bearing1_{direction}"] == pytest.approx(-value, rel=1e-9)
        assert statics.bearing_forces[f"bearing2_{direction}"] == pytest.approx(value, rel=1e-9)


def test_the_translational_sets_mesh_phases_are_the_rotational_sets():
    """Parker & Lin's phases follow from the teeth and the planet positions whether the planets translate or not."""
    translational = {rc.name: rc.planet_phase for rc in load_model("planetary_translational").resolved.couplings
                     if rc.kind == "mesh"}
    rotational = {rc.name: rc.planet_phase for rc in load_model("planetary").resolved.couplings}
    assert translational == rotational
    assert len(set(translational.values())) == 3  # 26/94 teeth, three planets: 0, 2 pi/3, 4 pi/3


@pytest.mark.slow
def test_gearsym_lyap_answers_bearing_deflections_in_um_and_bearing_forces_in_newtons(capsys):
    assert main(["lyap", "spur_pair_bearings", "--periods", "16", "--discard", "6"]) == 0
    out = capsys.readouterr().out
    assert "amplitude A_y_pinion" in out and "rad" not in out.split("amplitude A_y_pinion")[1].splitlines()[0]
    forces = [line for line in out.splitlines() if line.startswith("bearing force bearing1_y")]
    assert forces and forces[0].split("mean ")[1].split()[1] == "N,"


# ------------------------------------------------------------------ the values a run was made at, in the user's units
#: the pinion bearing's stiffness as the model declares it, and as the engine's number it becomes (k_b1 / kZ)
K_B1 = "k_b1=1e+08 N/m"


@pytest.mark.slow
def test_gearsym_lyap_says_the_values_it_ran_at_in_the_users_units_not_the_engines_numbers(capsys):
    """The engine's numbers carry the physical values' names (k_b1 = 0.996842 is k_b1 / kZ): printed as
    'parameters:' they would read as those values in other units."""
    assert main(["lyap", "spur_pair_bearings", "--periods", "16", "--discard", "6"]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("parameters: "))
    assert K_B1 in line and "speed=6000 rpm" in line and "eta=100 µm" in line and "omega=" not in line
    assert main(["lyap", "spur_pair_bearings", "--periods", "16", "--discard", "6", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["physical"]["parameters"]["k_b1"] == "1e+08 N/m" and "omega" in data["parameters"]


def test_gearsym_orbits_says_the_orbits_values_in_the_users_units_and_writes_them_to_its_record(capsys, tmp_path):
    out = tmp_path / "orbit.json"
    assert main(["orbits", "spur_pair_bearings", "--transient", "50", "--out", str(out)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("parameters: "))
    assert K_B1 in line and "omega=" not in line
    assert json.loads(out.read_text())["physical"]["parameters"]["k_b1"] == "1e+08 N/m"


def test_a_spectrums_record_carries_the_values_it_ran_at_in_the_users_units(capsys, tmp_path):
    out = tmp_path / "spectrum.json"
    assert main(["spectrum", "spur_pair_bearings", "--periods", "160", "--discard", "100", "--out", str(out)]) == 0
    spectrum = json.loads(out.read_text())["spectra"][0]
    assert spectrum["parameters"]["k_b1"] == "1e+08 N/m" and spectrum["parameters"]["speed"] == "6000 rpm"


def test_a_charts_held_values_are_the_users_but_its_axes_and_what_an_engine_axis_stands_for():
    """'fixed:' of `gearsym stability` on a physical model: every physical value but the axes (the speed, here
    charted as given), and an axis in the engine's numbers (zeta) with the values it is made of."""
    from gearsym.cli.stability import held_values
    from gearsym.sweep.grid import axes_from

    held = held_values(gearsym.scaling("spur_pair_bearings"), axes_from(["speed=4000rpm,6000rpm", "zeta=0.05,0.1"]))
    values, engine = held.split("; ")
    assert K_B1 in values and "eta=100 µm" in values and "speed=" not in values and "zeta" not in values
    assert engine.startswith("zeta charted in the engine's numbers") and "cZ" in engine
    from types import SimpleNamespace

    from gearsym.figures.stability import chart_title
    from gearsym.physical.basins import shown_in

    units = gearsym.scaling("spur_pair_bearings").point_units()  # the chart's title holds the same values
    engine_values = {"k_b1": 0.996842, "eta": 1.0}
    chart = SimpleNamespace(about="static", steps_per_period=200, model="spur_pair_bearings", fixed=engine_values)
    title = chart_title(chart, shown_in(units), fixed=held)
    assert held in title and "k_b1=0.996842" not in title
