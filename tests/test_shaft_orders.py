"""Shaft-order terms of the symbolic model (tooth faults, spalls, eccentricity, spacing errors on a gear with its
tooth count) and the engine on the long periods they imply (a gear's revolution, the hunting period): the terms as
the equations, the derivation page and the C carry them, typed here independently; the revolution-period
Lyapunov spectrum against the mesh-period one; periodic orbits of a revolution and of a hunting period against
brute-force integration; order spectra."""
from __future__ import annotations

import json
import math
import random

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import conftest
import fault_rig
import gearsym
import gearsym.cli.spectrum
import gearsym.checks
import rig
from gearsym import Drivetrain, Gear, Harmonic, Integration, Mesh, Torque
from gearsym.cli import main
from gearsym.errors import GearsymError, ModelError
from gearsym.fit.effects import augment
from gearsym.model.faults import Eccentricity, Spall, SpacingErrors, ToothFault
from gearsym.model.shaft_orders import tooth_share
from gearsym.model.symbols import parameter_symbol, tau

TEETH = (9, 13)


def pair(name: str, *terms, teeth=TEETH, **defaults) -> Drivetrain:
    """The one-stage pair with tooth counts and shaft-order ``terms`` (functions of the two gears), typed here."""
    m = Drivetrain(name)
    g1 = m.add(Gear("gear1", inertia="I1", base_radius="r1", teeth=teeth[0]))
    g2 = m.add(Gear("gear2", inertia="I2", base_radius="r2", teeth=teeth[1]))
    m.add(Mesh("mesh", g1, g2, stiffness="kZ", damping="cZ", backlash="eta"))
    m.add(Torque("M1", on=g1, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    m.add(Torque("M2", on=g2, mean="M2", load=True))
    for term in terms:
        m.add(term(g1, g2))
    m.set_defaults(omega=1.5, zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.2, **defaults)
    m.set_initial_state(x=-2.0, v=-0.5)
    return m


def typed_window(phi, teeth, centre, length, edge=0.1):
    """The window of docs/data-loop.md, typed: (1 + tanh(kappa sin(a + h)))(1 + tanh(kappa sin(h - a)))/4, a the
    gear's angle from the centre, h = pi length/Z, kappa = Z/(pi edge)."""
    h, kappa = math.pi * length / teeth, teeth / (math.pi * edge)
    a = (phi - 2 * math.pi * centre) / teeth
    return (1 + math.tanh(kappa * math.sin(a + h))) * (1 + math.tanh(kappa * math.sin(h - a))) / 4


def typed_acceleration(t, x, v, p, teeth, crack=None, eccentric=None):
    """x'' of the pair with a tooth fault (gear, tooth, q) and an eccentricity (gear, A, psi), typed here."""
    k = 1 + p["k_a"] * sum(c * math.cos((n + 1) * t) for n, c in enumerate(rig.STIFFNESS))
    if crack:
        gear, tooth, q = crack
        z = teeth[gear - 1]
        before, here, after = (typed_window(t, z, tooth + k - 0.5, 1.6) for k in (-1, 0, 1))
        share = here / 2 + here * (1 - before) * (1 - after) / 2  # alone: in mesh, neither neighbour is
        k *= 1 - q * share
    e = 0.0
    if eccentric:
        gear, A, psi = eccentric
        e = A * math.cos(t / teeth[gear - 1] + psi)
    w = p["omega"]
    return (-2 * p["zeta"] * v / w + (p["B0"] + p["B1"] * math.cos(t + p["Theta"])) / w**2
            - k * rig.backlash(x - e, p["eta"]) / w**2)


@pytest.fixture(scope="module")
def faulty():
    """A tooth fault on the wheel and an eccentric pinion, declared on the drivetrain."""
    return pair("faulty_pair", lambda g1, g2: ToothFault("crack", g2, tooth=9, depth="q"),
                lambda g1, g2: Eccentricity("runout", g1, amplitude="A", phase="psi"), q=0.3, A=0.4, psi=0.7)


def test_shaft_order_terms_are_terms_of_the_model_its_page_and_its_c(faulty, tmp_path):
    nd = gearsym.reduce(faulty)
    system = nd.system()
    assert system.cycles == 9 * 13 and sp.simplify(system.period - 2 * sp.pi * 117) == 0  # the hunting period
    rng = random.Random(3)
    f = sp.lambdify([tau, *system.states], system.rhs[1].xreplace(
        {parameter_symbol(k): v for k, v in system.parameters.items()}).rewrite(sp.Piecewise), "math")
    for _ in range(40):
        t, x, v = rng.uniform(0, 2 * math.pi * 117), rng.uniform(-14, 4), rng.uniform(-3, 3)
        assert f(t, x, v) == pytest.approx(typed_acceleration(t, x, v, system.parameters, TEETH, (2, 9, 0.3),
                                                              (1, 0.4, 0.7)), rel=1e-10, abs=1e-10)
    page = gearsym.render(gearsym.derive(faulty), "markdown")
    assert r"\tanh" in page  # the fault's window in k(tau) ...
    assert r"A \cos{\left(\frac{\omega t}{9} + \psi \right)}" in page  # ... the runout in g's argument, in t
    generated = gearsym.compile_model(system, Integration(backend="in-process"))
    from gearsym.codegen.functions import build_functions
    from gearsym.codegen.generate import code_hash, write_code
    from gearsym.codegen.loops import LoopOptions

    loops = LoopOptions.of(Integration(), system.cycles)
    code = write_code(build_functions(system, loops), tmp_path, code_hash(system, loops)).source.read_text()
    assert "tanh(" in code and loops.steps_per_period == 200 * 117 and generated.steps_per_cycle == 200
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    assert any("tanh" in table for table in manifest["tables"].values())


def test_the_declared_terms_are_the_data_loops_effects(faulty):
    """The tooth fault and eccentricity the data loop adds are the declaration stage's terms."""
    declared = gearsym.load(faulty)
    effects = augment(gearsym.load("one_stage", teeth=TEETH), ["tooth_fault_gear2", "eccentricity_gear1"],
                      values={"q_gear2": 0.3, "tooth_gear2": 9, "e_c_gear1": 0.4 * math.cos(0.7),
                              "e_s_gear1": -0.4 * math.sin(0.7)})
    assert effects.cycles == declared.cycles == 117
    rng = random.Random(5)
    a, b = (sp.lambdify([tau, *s.states], s.rhs[1].xreplace({parameter_symbol(k): v for k, v in s.parameters.items()})
                        .rewrite(sp.Piecewise), "math") for s in (declared, effects))
    for _ in range(40):
        t, x, v = rng.uniform(0, 2 * math.pi * 117), rng.uniform(-14, 4), rng.uniform(-3, 3)
        assert a(t, x, v) == pytest.approx(b(t, x, v), rel=1e-12, abs=1e-12)


def test_a_pairs_share_of_the_mesh_stiffness_over_the_teeth_adds_up_to_one():
    phi = sp.Symbol("phi")
    shares = [sp.lambdify(phi, tooth_share(phi, 13, n, 1.6), "math") for n in range(1, 14)]
    for u in np.linspace(0, 13, 1301):
        total = sum(s(2 * math.pi * u) for s in shares)
        assert total == pytest.approx(1, abs=1e-7)  # (the windows' tails, 0.6 mesh periods from an edge)
    tooth = shares[4]  # tooth 5: single contact in mesh period 5 (u in [4, 5))
    # (its single contact, 0.4 mesh periods, is 4 edge widths: the neighbours' tails leave 3e-4 at its middle)
    assert tooth(2 * math.pi * 4.5) == pytest.approx(1, abs=1e-3)
    assert tooth(2 * math.pi * 4.0) == pytest.approx(0.5, abs=1e-5) == tooth(2 * math.pi * 5.0)
    assert tooth(2 * math.pi * 3.0) == pytest.approx(0, abs=1e-9) == tooth(2 * math.pi * 9.0)


@pytest.mark.slow
def test_a_spall_and_spacing_errors_are_declared_like_a_tooth_fault():
    m = pair("spalled", lambda g1, g2: Spall("pit", g1, tooth=2, width="w", start=0.25, end=1.0),
             lambda g1, g2: SpacingErrors("pitch", g2, errors=tuple(f"s{n}" for n in range(1, 14))),
             w=0.5, **{f"s{n}": 0.01 * n for n in range(1, 14)})
    system = gearsym.load(m)
    assert system.cycles == 117 and {"w", "s13"} <= set(system.parameters)
    loss = sp.lambdify(tau, next(iter(system.couplings)).stiffness.xreplace(
        {parameter_symbol(k): v for k, v in system.parameters.items()}), "math")
    k = lambda t: 1 + 0.2 * sum(c * math.cos((n + 1) * t) for n, c in enumerate(rig.STIFFNESS))  # noqa: E731
    # tooth 2 of the pinion: its path of contact runs over u in [0.7, 2.3] (alone in [1.3, 1.7]); the spall covers
    # the last three quarters, [1.1, 2.3], where the pair has lost half its width (edges 0.1 mesh periods wide)
    assert loss(2 * math.pi * 0.8) == pytest.approx(k(2 * math.pi * 0.8), rel=1e-4)  # before the spall: whole
    assert loss(2 * math.pi * 1.5) == pytest.approx(k(2 * math.pi * 1.5) * 0.5, rel=2e-3)  # alone: half
    assert loss(2 * math.pi * 2.0) == pytest.approx(k(2 * math.pi * 2.0) * 0.75, rel=2e-3)  # shared: a quarter
    with pytest.raises(ModelError, match="gives 3 spacing errors for a gear of 13 teeth"):
        gearsym.load(pair("bad", lambda g1, g2: SpacingErrors("pitch", g2, errors=(0, 0, 0))))


def test_tooth_counts_go_to_the_pinion_and_the_wheel_of_a_model_that_declares_none(capsys):
    system = gearsym.load("one_stage", teeth=(9, 13))
    assert [(g.gear, g.teeth) for g in system.coupling("x").gears] == [("gear1", 9), ("gear2", 13)]
    assert system.cycles == 1  # tooth counts alone add no term
    assert main(["derive", "one_stage", "--teeth", "9,13"]) == 0
    for argv, message in ((["lyap", "spur_pair", "--teeth", "9,13"], "declare their tooth counts already"),
                          (["lyap", "lorenz", "--teeth", "9,13"], "a first-order system has none"),
                          (["lyap", "one_stage", "--teeth", "9"], "two whole numbers of at least 3"),
                          (["lyap", "one_stage", "--set", "teeth=9"], "given with --teeth")):
        capsys.readouterr()
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1, err
    undeclared = Drivetrain("undeclared")
    g1 = undeclared.add(Gear("gear1", inertia="I1", base_radius="r1"))
    g2 = undeclared.add(Gear("gear2", inertia="I2", base_radius="r2"))
    undeclared.add(Mesh("mesh", g1, g2))
    undeclared.add(ToothFault("crack", g2, tooth=3))
    with pytest.raises(ModelError, match=r"needs the tooth count of 'gear2'.*--teeth Z1,Z2"):
        gearsym.reduce(undeclared)
    with pytest.raises(ModelError, match="tooth must be a whole number from 1 to the gear's 13 teeth"):
        gearsym.reduce(pair("wrong", lambda g1, g2: ToothFault("crack", g2, tooth=14)))


@pytest.mark.slow
def test_the_revolution_period_spectrum_is_the_mesh_period_spectrum_without_a_shaft_order_term():
    """A tooth fault of depth 0 makes the period a revolution of the pinion (9 mesh periods) and changes no
    equation's value: the same RK4 steps (steps per mesh period kept), Gram-Schmidt every 9 mesh periods instead of
    every one, the same exponents to rounding."""
    plain = conftest.compiled("one_stage", Integration(periods=900, discard=450))
    revolution = pair("revolution", lambda g1, g2: ToothFault("crack", g1, tooth=4, depth="q"), q=0.0)
    compiled = gearsym.compile_model(gearsym.load(revolution), Integration(periods=100, discard=50))
    assert compiled.cycles == 9 and compiled.steps_per_period == 9 * plain.steps_per_period
    a, b = gearsym.lyapunov_spectrum(plain), gearsym.lyapunov_spectrum(compiled)
    np.testing.assert_allclose(b.exponents, a.exponents, rtol=1e-9, atol=1e-12)
    assert b.amplitude["x"] == pytest.approx(a.amplitude["x"], rel=1e-12)
    faulty = gearsym.lyapunov_spectrum(compiled, q=0.3)  # and the fault does change them
    assert abs(faulty.exponents[0] - a.exponents[0]) > 1e-3


def eccentric(name: str, amplitude: float, phase: float, teeth=TEETH, both: bool = False) -> Drivetrain:
    terms = [lambda g1, g2: Eccentricity("runout1", g1, amplitude="A", phase="psi")]
    if both:
        terms.append(lambda g1, g2: Eccentricity("runout2", g2, amplitude="A2", phase="psi2"))
    extra = {"A2": 0.3, "psi2": -0.4} if both else {}
    return pair(name, *terms, teeth=teeth, A=amplitude, psi=phase, **extra)


@pytest.mark.slow
def test_a_periodic_orbit_of_a_revolution_agrees_with_brute_force_integration():
    """An eccentric pinion (9 teeth) at omega = 1.8: Newton on the revolution's map, shot once per mesh period, from
    the model's start; the orbit against SciPy's DOP853 of the equations typed in tests/fault_rig.py: it returns to
    itself over one revolution, its multipliers are those of the typed flow's monodromy matrix (central
    differences), and a run from rest converges to it."""
    model = eccentric("eccentric_pinion", 0.5, 0.3)
    compiled = gearsym.compile_model(gearsym.load(model, omega=1.8), Integration(periods=4, discard=0))
    orbit = gearsym.periodic_orbit(compiled)  # (Newton from where 4 revolutions from the model's start end)
    assert orbit.segments == 9 and orbit.residual < 1e-10 and orbit.iterations > 0
    assert orbit.period == pytest.approx(2 * math.pi * 9)
    typed = fault_rig.Pair(teeth=TEETH, eccentric=(1, 0.5, 0.3), omega=1.8)
    f = typed.rhs(1.8)

    def flow(y, tolerance=1e-11):
        s = solve_ivp(f, (0, orbit.period), y, method="DOP853", rtol=tolerance, atol=tolerance, max_step=0.2)
        return s.y[:, -1]

    np.testing.assert_allclose(flow(orbit.state), orbit.state, atol=1e-6)
    h = 1e-5
    M = np.column_stack([(flow(orbit.state + h * e) - flow(orbit.state - h * e)) / (2 * h) for e in np.eye(2)])
    typed_multipliers = np.abs(sorted(np.linalg.eigvals(M), key=lambda m: -abs(m)))
    np.testing.assert_allclose(np.abs(orbit.multipliers), typed_multipliers, rtol=0, atol=1e-3 * typed_multipliers[0])
    # and exactly: the flow's divergence is -2 zeta/omega, so det M = exp(-2 zeta T/omega) (Liouville)
    assert np.prod(np.abs(orbit.multipliers)) == pytest.approx(math.exp(-2 * 0.08 * orbit.period / 1.8), rel=1e-7)
    assert orbit.stable
    y = np.array([1.0, 0.0])
    for _ in range(20):  # brute force: revolution after revolution from rest (0.45 closer each: 1e-7 after 20)
        y = flow(y, 1e-9)
    np.testing.assert_allclose(y, orbit.state, atol=1e-5)


@pytest.mark.slow
def test_an_orbit_of_the_hunting_period_is_found_by_shooting_once_per_mesh_period():
    """Both gears eccentric (13 and 17 teeth): the period is the hunting period, 221 mesh periods, shot in 221
    segments (442 unknowns, a sparse Newton system); the orbit is where a long run of the engine ends, at every
    mesh period of the way."""
    model = eccentric("eccentric_pair", 0.5, 0.3, teeth=(13, 17), both=True)
    compiled = gearsym.compile_model(gearsym.load(model, omega=1.8), Integration(periods=2, discard=0))
    assert compiled.cycles == 221
    brute, _, _ = compiled.orbit_run(None, 30, compiled.prepare())  # 30 hunting periods from the model's start
    assert np.abs(brute[:, -1] - brute[:, -2]).max() < 1e-8  # (converged: a stable orbit)
    orbit = gearsym.periodic_orbit(compiled, y0=brute[:, -1] + [0.3, -0.2], trajectory=True)
    assert orbit.segments == 221 and orbit.residual < 1e-10 and orbit.iterations > 0
    np.testing.assert_allclose(orbit.state, brute[:, -1], atol=1e-8)
    run_on = compiled.trajectory(brute[:, -1], 1, compiled.prepare())[1]
    np.testing.assert_allclose(orbit.trajectory[:, ::200], run_on[:, ::200], atol=1e-8)


def test_order_spectrum_lines_are_fitted_at_their_exact_orders():
    from gearsym import order_spectrum

    gears = {"pinion": 9, "wheel": 13}
    tau = np.arange(0, 2 * math.pi * 41.3, 2 * math.pi / 37.3)  # no whole revolution of either, no whole sample
    u = tau / (2 * math.pi)
    x = (2.0 * np.cos(2 * math.pi * u + 0.3) + 0.1 * np.cos(2 * math.pi * (1 + 1 / 9) * u - 1.0)
         + 0.05 * np.sin(2 * math.pi * (2 - 2 / 13) * u) + 0.02 * np.cos(2 * math.pi * u / 13))
    s = order_spectrum(tau, x, gears)
    assert s.line("mesh x1").amplitude == pytest.approx(2.0, abs=1e-9)
    assert s.line("mesh x1 + pinion x1").amplitude == pytest.approx(0.1, abs=1e-9)
    assert s.line("mesh x2 - wheel x2").amplitude == pytest.approx(0.05, abs=1e-9)
    assert s.line("wheel x1").amplitude == pytest.approx(0.02, abs=1e-9)
    assert s.line("mesh x1 - pinion x1").amplitude == pytest.approx(0, abs=1e-9)
    assert s.sideband_energy("pinion") == pytest.approx(0.1, abs=1e-9)
    assert s.orders.size and s.orders[np.argmax(s.amplitude)] == pytest.approx(1.0, abs=0.03)


def test_the_spectrum_command_writes_the_lines_and_the_figure(tmp_path, capsys):
    runs = [(1.8, fault_rig.Pair(teeth=TEETH, eccentric=(1, 0.5, 0.3)).record(1.8, periods=27, transient=20))]
    data = fault_rig.write(tmp_path / "ecc.csv", runs, noise=0.0)
    out, plot = tmp_path / "spectrum.json", tmp_path / "spectrum.png"
    assert main(["spectrum", "one_stage", "--teeth", "9,13", "--data", str(data), "--out", str(out),
                 "--plot", str(plot)]) == 0
    spectrum = json.loads(out.read_text())["spectra"][0]
    energy = spectrum["sideband_energy"]
    assert energy["gear1"] > 10 * energy["gear2"]  # the pinion runs out: its sidebands, not the wheel's
    assert plot.stat().st_size > 10000
    assert main(["spectrum", "one_stage", "--data", str(data)]) == 2
    assert "tooth counts" in capsys.readouterr().err


@pytest.mark.slow
def test_a_sweep_and_a_continuation_of_an_eccentric_pinion_run_on_its_revolution():
    """The period the model implies, not the user's: a sweep's Poincaré samples of an eccentric pinion (9 teeth) are
    one revolution apart (SciPy's DOP853 of the equations typed in tests/fault_rig.py carries each sample to the
    next over 9 mesh periods, at omega = 1.7 a period-2 orbit of the revolution, at 1.8 a period-1 one), and every
    orbit of a continuation from omega = 1.8 to 1.7 returns to itself over one revolution of the typed flow."""
    model = eccentric("eccentric_pinion", 0.5, 0.3)
    compiled = gearsym.compile_model(gearsym.load(model), Integration(periods=30, discard=20))
    revolution = 2 * math.pi * TEETH[0]

    def flow(omega, y):
        f = fault_rig.Pair(teeth=TEETH, eccentric=(1, 0.5, 0.3), omega=omega).rhs(omega)
        return solve_ivp(f, (0, revolution), y, method="DOP853", rtol=1e-11, atol=1e-11, max_step=0.2).y[:, -1]

    sweep = gearsym.run_sweep(compiled, {"omega": [1.7, 1.8]}, mode="independent")
    strobe = sweep.strobe
    for omega in (1.7, 1.8):
        points = np.column_stack([strobe["x"], strobe["v"]])[strobe["omega"] == omega]
        assert len(points) == 10
        for a, b in zip(points[:3], points[1:4]):
            np.testing.assert_allclose(flow(omega, a), b, atol=1e-5)
    distinct = lambda omega: len({round(x, 4) for x in strobe["x"][strobe["omega"] == omega][-4:]})
    assert distinct(1.7) == 2 and distinct(1.8) == 1
    branch = gearsym.continue_orbits(compiled, "omega", 1.8, 1.7).branches[0]
    assert branch.values[-1] == pytest.approx(1.7) and len(branch) > 5
    for k in (0, len(branch) // 2, len(branch) - 1):
        np.testing.assert_allclose(flow(branch.values[k], branch.states[k]), branch.states[k], atol=1e-5)


# ------------------------------------------------------------------ issue 35: spectra of healthy gears, bad input
def _energy(capsys, *argv) -> dict:
    assert main(["spectrum", *argv, "--quiet"]) == 0
    out = capsys.readouterr().out
    said = out.split("sideband energy ")[1].split(";")[0]
    return {g: float(v) for g, v in (part.split() for part in said.split(", "))}


@pytest.mark.slow
def test_a_healthy_pair_shows_no_sidebands_and_a_cracked_one_does(capsys):
    """one_stage with 20/53 teeth at omega = 1.5 answers with period 2 (half orders, no shaft order): over the
    default 212 mesh periods (10.6 pinion revolutions) the unwindowed fit gave the pinion 0.034 of sidebands, the
    windowed one 1e-7 (its mesh line is 2.2); the cracked pinion of cracked_pair shows 0.18."""
    healthy = _energy(capsys, "one_stage", "--teeth", "20,53")
    assert max(healthy.values()) < 1e-5
    cracked = _energy(capsys, "cracked_pair")
    assert cracked["gear1"] > 0.1 and cracked["gear1"] > 1e4 * healthy["gear1"]
    tiny = _energy(capsys, "one_stage", "--teeth", "3,5")  # (k < Z/2 only: no line at a mesh harmonic, no NaN)
    assert all(math.isfinite(v) for v in tiny.values()) and max(tiny.values()) < 1e-4


@pytest.mark.parametrize("argv, said", [
    (["cracked_pair", "--periods", "1", "--discard", "0"],
     "the run of --periods 1 minus --discard 0 (20 mesh periods each) holds 20 mesh periods, less than the 2 "
     "revolutions of gear2 (53 teeth: 106 mesh periods) its sidebands need; give at least --periods 6"),
    (["cracked_pair", "--sidebands", "100000"], "--sidebands 100000: a gear of Z teeth has Z/2 sidebands of its own"),
    (["one_stage", "--teeth", "1000000000,3"], "the default run of gear1 1000000000 teeth, gear2 3 teeth (4 revolutions "
                                               "of the larger gear, 4000000000 mesh periods, after the transient) needs"),
])
def test_a_spectrum_that_cannot_show_sidebands_is_refused_before_the_run(capsys, monkeypatch, argv, said):
    monkeypatch.setattr(gearsym.checks, "available", lambda: 2**30)  # (a machine of 1 GiB: the same on any)
    monkeypatch.setattr(gearsym.cli.spectrum, "simulated_order_spectrum", lambda *a, **k: pytest.fail("ran"))
    assert main(["spectrum", *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearsym: error: ") and err.count("\n") == 1 and said in err, err
    assert "--periods" not in err or "--periods" in argv


def test_a_record_shorter_than_two_revolutions_is_refused(tmp_path, capsys):
    runs = [(1.8, fault_rig.Pair(teeth=TEETH, eccentric=(1, 0.5, 0.3)).record(1.8, periods=20, transient=20))]
    data = fault_rig.write(tmp_path / "short.csv", runs, noise=0.0)
    assert main(["spectrum", "one_stage", "--teeth", "9,13", "--data", str(data)]) == 2
    err = capsys.readouterr().err
    assert "less than the 2 revolutions of gear2 (13 teeth: 26 mesh periods) its sidebands need" in err


def test_numeric_spacing_errors_reduce_to_the_equations_of_the_same_errors_as_parameters():
    """The reduction's self-check compares 30 digits; a model file's 0.1 is a double, whose products the two sides
    round differently (equal to 18 digits): it refused every numeric SpacingErrors. Now they reduce, to the
    equations the same errors give as parameters."""
    errors = (0.1, -0.05, 0.0, 0.02, -0.07)
    numeric = pair("spacing_numeric", lambda g1, g2: SpacingErrors("pitch", g1, errors=errors), teeth=(5, 11))
    named = pair("spacing_named", lambda g1, g2: SpacingErrors("pitch", g1, errors=tuple(f"s{i}" for i in range(5))),
                 teeth=(5, 11), **{f"s{i}": e for i, e in enumerate(errors)})
    run = Integration(periods=2, discard=0, backend="in-process")
    a, b = (gearsym.compile_model(gearsym.load(m), run) for m in (numeric, named))
    rng = np.random.default_rng(3)
    for _ in range(5):
        t, y = rng.uniform(0, 60), rng.uniform(-12, 3, 2)  # (both flanks of the backlash and its gap)
        np.testing.assert_allclose(np.asarray(a.rhs(t, y, a.parameter_vector())).ravel(),
                                   np.asarray(b.rhs(t, y, b.parameter_vector())).ravel(), rtol=1e-13, atol=1e-13)
