"""Models as FMUs (issue 29): what FMPy, an FMI tool nobody on this project wrote, makes of them.

The references are independent: the one-stage equations and the spur pair's Lagrange equations in SI are typed
here and solved with SciPy; the planetary set's equations are SymPy's (lambdified: no CasADi, no generated C).
gearsym's own trajectory at the same step is the reference the co-simulation must meet to rounding. Each FMU
is built once per module (building compiles C).
"""
from __future__ import annotations

import io
import math
import shutil
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

fmpy = pytest.importorskip("fmpy")
from fmpy import read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import gearsym  # noqa: E402
from gearsym import Integration  # noqa: E402
from gearsym.cli import main  # noqa: E402
from gearsym.codegen.code_files import code_directory  # noqa: E402
from gearsym.codegen.generate import code_hash  # noqa: E402
from gearsym.codegen.loops import LoopOptions  # noqa: E402
from gearsym.codegen.surfaces import switching_surfaces  # noqa: E402
from gearsym.fmu.functions import indicators  # noqa: E402
from gearsym.files.paths import REPO_ROOT  # noqa: E402
from conftest import slow_models_group, system  # noqa: E402

K = "1+0.2*cos(tau)"  # the issue's stiffness formula
PERIODS, STEPS = 40, 200
TWO_PI = 2 * math.pi
#: gearsym's own runs here: CasADi's evaluation of the same step (the same bits as its compiled C without fused
#: multiply-add, as the FMU's binary is built; and nothing more to compile)
ENGINE = "in-process"


def contact_of(x, eta):
    return np.where(x >= 0, x, np.where(x > -eta, 0.0, x + eta))


# ------------------------------------------------------------------ the FMUs, built once
@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return tmp_path_factory.mktemp("fmu")


@pytest.fixture(scope="module")
def one_stage(built):
    """The issue's command: gearsym fmu one_stage --set "k=1+0.2*cos(tau)" --out one_stage.fmu."""
    path = built / "one_stage.fmu"
    assert main(["fmu", "one_stage", "--set", f"k={K}", "--out", str(path)]) == 0
    return path


@pytest.fixture(scope="module")
def spur(built):
    path = built / "spur_pair.fmu"
    assert main(["fmu", "spur_pair", "--set", f"k={K}", "--out", str(path)]) == 0
    return path


@pytest.fixture(scope="module")
def planetary(built):
    path = built / "planetary.fmu"
    gearsym.export_fmu(system("planetary"), path)  # (the session's reduction of it: a system exports as well)
    return path


def cs(path, periods=PERIODS, step=TWO_PI / STEPS, output=("x",), **start):
    """Co-simulation over ``periods`` forcing periods, one communication step per RK4 step of the engine."""
    return simulate_fmu(str(path), fmi_type="CoSimulation", stop_time=periods * STEPS * step, output_interval=step,
                        output=list(output), start_values=start)


def me(path, stop, step, output=("x",), rtol=1e-10, events=False, **start):
    return simulate_fmu(str(path), fmi_type="ModelExchange", stop_time=stop, output_interval=step,
                        relative_tolerance=rtol, output=list(output), record_events=events, start_values=start)


# ------------------------------------------------------------------ the one-stage model (nondimensional)
def one_stage_reference(omega=1.5, zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, periods=PERIODS):
    """The paper's Eq. 2 with k = 1 + 0.2 cos(tau), typed here, solved by SciPy's DOP853."""
    from scipy.integrate import solve_ivp

    def g(x):
        return x if x >= 0 else (0.0 if x > -eta else x + eta)

    def rhs(tau, y):
        x, v = y
        return [v, -2 * zeta * v / omega + (B0 + B1 * math.cos(tau + Theta)) / omega**2
                - (1 + 0.2 * math.cos(tau)) * g(x) / omega**2]

    tau = np.arange(periods * STEPS + 1) * TWO_PI / STEPS
    sol = solve_ivp(rhs, (0, tau[-1]), [-2.0, -0.5], method="DOP853", t_eval=tau, rtol=1e-12, atol=1e-12)
    return tau, sol.y[0], sol.y[1]


@pytest.fixture(scope="module")
def reference():
    return one_stage_reference()


def test_the_issues_command_writes_an_fmu_that_fmpy_validates(one_stage):
    assert validate_fmu(str(one_stage)) == []
    md = read_model_description(str(one_stage))
    assert md.fmiVersion == "2.0" and md.coSimulation and md.modelExchange
    assert md.numberOfEventIndicators == 2
    names = {v.name: v for v in md.modelVariables}
    assert {"tau", "x", "v", "der(x)", "der(v)", "omega", "zeta", "B0", "B1", "Theta", "eta", "substeps",
            "mesh.deflection", "mesh.force", "mesh.contact"} == set(names)
    assert "k_a" not in names  # the formula replaced the default stiffness, and its amplitude with it
    assert all(names[p].variability == "tunable" for p in ("omega", "zeta", "B0", "B1", "Theta", "eta"))
    assert names["der(x)"].derivative is names["x"] and names["x"].start == "-2.0"
    assert names["zeta"].description == "damping ratio of mesh 'mesh'"  # the model's own descriptions
    with zipfile.ZipFile(one_stage) as zf:
        files = set(zf.namelist())
    assert {"modelDescription.xml", "binaries/linux64/one_stage.so", "sources/buildDescription.xml",
            "sources/gearsym_fmu.c", "sources/gearsym_model.h", "sources/one_stage.c",
            "sources/gearsym_fmu_functions.c", "sources/fmi2Functions.h", "sources/fmi2FunctionTypes.h",
            "sources/fmi2TypesPlatform.h"} == files


def test_co_simulation_is_gearsyms_own_step_to_rounding(one_stage):
    """Same step, same located RK4: the co-simulation and gearsym's phase trajectory agree to rounding, also with
    several substeps in a communication step."""
    ours = gearsym.phase_trajectory(system("one_stage", k=K),
                                    options=Integration(periods=PERIODS, discard=0, backend=ENGINE))
    x = ours["x"][:PERIODS * STEPS + 1]
    span = np.ptp(x)
    fmu = cs(one_stage)
    assert np.allclose(fmu["time"], ours.time[:len(x)], rtol=0, atol=1e-9)
    assert np.max(np.abs(fmu["x"] - x)) < 1e-10 * span
    four = simulate_fmu(str(one_stage), fmi_type="CoSimulation", stop_time=PERIODS * TWO_PI,
                        output_interval=4 * TWO_PI / STEPS, output=["x"], start_values={"substeps": 4})
    assert np.max(np.abs(four["x"] - x[::4])) < 1e-10 * span


def test_co_simulation_agrees_with_an_independent_solution_over_40_periods(one_stage, reference):
    """The issue's done-when: x within 1e-4 of its range of the equations solved by SciPy, 40 periods."""
    tau, x, v = reference
    fmu = cs(one_stage, output=("x", "v", "mesh.deflection", "mesh.force", "mesh.contact"))
    span = np.ptp(x)
    error = np.max(np.abs(fmu["x"] - x)) / span
    assert error < 1e-4
    assert np.max(np.abs(fmu["v"] - v)) < 1e-4 * np.ptp(v)
    # the outputs are the mesh's: deflection x, elastic force k(tau) g(x, eta), contact state
    assert np.array_equal(fmu["mesh.deflection"], fmu["x"])
    k = 1 + 0.2 * np.cos(fmu["time"])
    assert np.allclose(fmu["mesh.force"], k * contact_of(fmu["x"], 10.0), rtol=1e-13, atol=1e-13)
    expected = np.where(fmu["x"] >= 0, 1, np.where(fmu["x"] <= -10.0, -1, 0))
    assert np.array_equal(fmu["mesh.contact"], expected) and set(expected) == {0, 1}  # (x stays above -eta)


def test_model_exchange_agrees_with_an_independent_solution_to_its_tolerance(one_stage, reference):
    tau, x, _ = reference
    span = np.ptp(x)
    loose = me(one_stage, tau[-1], TWO_PI / STEPS, rtol=1e-6)
    tight = me(one_stage, tau[-1], TWO_PI / STEPS, rtol=1e-10)
    error_loose, error_tight = (np.max(np.abs(r["x"] - x)) / span for r in (loose, tight))
    assert error_tight < 1e-4
    assert error_tight < error_loose / 20  # the error follows CVode's tolerance


@pytest.mark.slow
def test_model_exchange_stops_at_every_kink_of_the_backlash(one_stage):
    """The event indicators are x and -(x + eta): CVode stops where either changes sign, as many times as the
    independent solution crosses x = 0 and x = -eta (eta = 3 here, set through FMI, so that both flanks are
    hit), and the contact state it holds between events is the one the state has, as in co-simulation."""
    tau, x, _ = one_stage_reference(eta=3.0)
    drive, back = (int(np.count_nonzero(np.diff(np.sign(s)) != 0)) for s in (x, x + 3.0))
    assert drive > 20 and back > 20
    run = me(one_stage, tau[-1], TWO_PI / STEPS, output=("x", "mesh.contact"), events=True, eta=3.0)
    events = int(np.count_nonzero(np.diff(run["time"]) == 0))  # an event is recorded twice, before and after
    assert abs(events - (drive + back)) <= 2
    clear = (np.abs(run["x"]) > 1e-6) & (np.abs(run["x"] + 3.0) > 1e-6)
    rule = np.where(run["x"] >= 0, 1, np.where(run["x"] <= -3.0, -1, 0))
    assert np.array_equal(run["mesh.contact"][clear], rule[clear]) and set(rule) == {-1, 0, 1}
    co = cs(one_stage, output=("x", "mesh.contact"), eta=3.0)
    assert np.max(np.abs(co["x"] - x)) < 1e-4 * np.ptp(x)
    assert np.array_equal(co["mesh.contact"], np.where(co["x"] >= 0, 1, np.where(co["x"] <= -3.0, -1, 0)))


def test_event_indicators_are_the_surfaces_the_engine_locates():
    for name in ("one_stage", "two_stage", "planetary"):
        s = system(name)
        surfaces = switching_surfaces(s)
        found = indicators(s, surfaces)
        assert len(found) == len(surfaces) > 0
        assert all(any(sp.expand(a - b) == 0 for b in found) for a in surfaces), name


def test_the_indicators_the_fmu_gives_are_x_and_minus_x_plus_eta(one_stage):
    from fmpy import extract, instantiate_fmu

    where = extract(str(one_stage))
    try:
        md = read_model_description(where)
        fmu = instantiate_fmu(where, md, fmi_type="ModelExchange")
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        for x in (3.0, -4.0, -12.5):
            fmu.setContinuousStates(_doubles([x, 0.7]), 2)
            z = _doubles([0.0, 0.0])
            fmu.getEventIndicators(z, 2)
            assert list(z) == [x, -(x + 10.0)]
        fmu.terminate()
        fmu.freeInstance()
    finally:
        shutil.rmtree(where, ignore_errors=True)


def _doubles(values):
    from ctypes import c_double

    return (c_double * len(values))(*values)


def test_a_parameter_set_through_fmi_changes_the_result_as_set_does(one_stage):
    """omega = 1.2 set in the FMU gives gearsym's run with --set omega=1.2, and not the default's."""
    ours = gearsym.phase_trajectory(system("one_stage", k=K, omega=1.2),
                                    options=Integration(periods=10, discard=0, backend=ENGINE))
    fmu = cs(one_stage, periods=10, omega=1.2)
    default = cs(one_stage, periods=10)
    x = ours["x"][:10 * STEPS + 1]
    assert np.max(np.abs(fmu["x"] - x)) < 1e-10 * np.ptp(x)
    assert np.max(np.abs(default["x"] - x)) > 0.1 * np.ptp(x)


def refusal(path, **start) -> tuple[str, list[str]]:
    """What FMPy raises and what the FMU logs when a co-simulation is started with ``start``."""
    said = []

    def logger(environment, instance, status, category, message):
        said.append(message.decode() if isinstance(message, bytes) else message)

    with pytest.raises(FMICallException) as err:
        simulate_fmu(str(path), fmi_type="CoSimulation", stop_time=TWO_PI, output_interval=TWO_PI / STEPS,
                     start_values=start, logger=logger)
    return str(err.value), said


def test_a_value_the_engine_does_not_take_is_refused(one_stage):
    raised, said = refusal(one_stage, omega=-1.0)
    assert raised.startswith("fmi2ExitInitializationMode failed with status 3")
    assert said == ["the parameter values make the engine's omega -1, but it must be positive (the forcing frequency)"]
    raised, said = refusal(one_stage, substeps=0)
    assert raised.startswith("fmi2SetInteger failed with status 3") and said == ["substeps must be at least 1"]


# ------------------------------------------------------------------ a physical model: SI
def spur_reference(stop, step, **changed):
    """The spur pair's two gears by Lagrange, in SI, typed here (k = 1 + 0.2 cos of the mesh phase); ``changed``:
    values in SI other than the model file's."""
    from scipy.integrate import solve_ivp

    values = {n: q.si for n, q in gearsym.load_model("spur_pair").physical.items()}
    values.update(changed)
    I1, I2, r1, r2, kZ, damping, eta, M1, M2, M1a, theta = (values[n] for n in
                                                          "I1 I2 r1 r2 kZ cZ eta M1 M2 M1a Theta".split())
    mesh = 28 * values["speed"]  # rad/s: teeth x speed

    def force(t, x, xdot):
        contact = x if x >= 0 else (0.0 if x > -eta else x + eta)
        return kZ * (1 + 0.2 * math.cos(mesh * t)) * contact + damping * xdot

    def rhs(t, y):
        p1, p2, w1, w2 = y
        f = force(t, r1 * p1 - r2 * p2, r1 * w1 - r2 * w2)
        return [w1, w2, (M1 + M1a * math.cos(mesh * t + theta) - r1 * f) / I1, (-M2 + r2 * f) / I2]

    t = np.arange(round(stop / step) + 1) * step
    x0 = gearsym.scaling("spur_pair").length.to("m").magnitude  # the model starts at x = 1 length unit
    sol = solve_ivp(rhs, (0, t[-1]), [x0 / r1, 0, 0, 0], method="DOP853", t_eval=t, rtol=1e-12, atol=1e-16,
                    max_step=TWO_PI / mesh / 20)
    x, xdot = r1 * sol.y[0] - r2 * sol.y[1], r1 * sol.y[2] - r2 * sol.y[3]
    return t, x, xdot, np.array([force(*a) for a in zip(t, x, xdot)])


def spur_period(speed=None):
    values = gearsym.load_model("spur_pair").physical
    return TWO_PI / (28 * (values["speed"].si if speed is None else speed))


def test_a_physical_fmu_is_in_seconds_and_metres(spur):
    assert validate_fmu(str(spur)) == []
    md = read_model_description(str(spur))
    v = {x.name: x for x in md.modelVariables}
    assert v["time"].causality == "independent" and v["time"].unit == "s"
    assert (v["x"].unit, v["x"].displayUnit, v["v"].unit, v["mesh.force"].unit) == ("m", "um", "m/s", "N")
    assert (v["speed"].unit, v["speed"].displayUnit, v["kZ"].unit, v["eta"].displayUnit) == ("rad/s", "rpm", "N/m",
                                                                                           "um")
    assert v["speed"].start == repr(6000 * TWO_PI / 60)
    assert v["kZ"].description.startswith("mean mesh stiffness, computed from the pair's geometry")  # the model file's describe
    tunable = {x.name for x in md.modelVariables if x.causality == "parameter" and x.variability == "tunable"}
    fixed = {x.name for x in md.modelVariables if x.causality == "parameter" and x.variability == "fixed"}
    assert tunable == {"speed", "cZ", "eta", "M1a", "Theta", "substeps"}
    assert fixed == {"I1", "I2", "r1", "r2", "kZ", "M1", "M2"}
    units = {u.name: {d.name: d.factor for d in u.displayUnits} for u in md.unitDefinitions}
    assert units["rad/s"]["rpm"] == pytest.approx(60 / TWO_PI, rel=1e-15)


def test_a_physical_fmu_agrees_with_the_lagrange_equations_in_si(spur):
    """Co-simulation and model exchange of the spur pair against its Lagrange equations in SI, 40 periods of
    the mesh: x within 1e-4 of its range (the issue's done-when), its rate and the mesh force in N too."""
    period = spur_period()
    t, x, xdot, force = spur_reference(PERIODS * period, period / STEPS)
    fmu = simulate_fmu(str(spur), fmi_type="CoSimulation", stop_time=t[-1], output_interval=period / STEPS,
                       output=["x", "v", "mesh.force", "mesh.deflection", "tau"])
    assert len(fmu) == len(t) and np.allclose(fmu["time"], t, rtol=1e-12, atol=0)
    assert np.max(np.abs(fmu["x"] - x)) < 1e-4 * np.ptp(x)
    assert np.max(np.abs(fmu["v"] - xdot)) < 1e-4 * np.ptp(xdot)
    assert np.max(np.abs(fmu["mesh.force"] - force)) < 1e-4 * np.ptp(force)
    assert np.allclose(fmu["tau"], 28 * TWO_PI * 100 * t, rtol=1e-12)  # the mesh phase at 6000 rpm = 100 rev/s
    exchange = me(spur, t[-1], period / STEPS)
    assert np.max(np.abs(exchange["x"] - x)) < 1e-4 * np.ptp(x)


def test_a_derivative_read_as_a_variable_is_the_states_rate_in_si(spur):
    """der(x) and der(v) read through fmi2GetReal (as a tool records or plots them, not only through
    fmi2GetDerivatives) are rates per second: der(x) is v, and der(v) v's central difference over the steps."""
    period = spur_period()
    step = period / STEPS
    fmu = simulate_fmu(str(spur), fmi_type="CoSimulation", stop_time=2 * period, output_interval=step,
                       output=["x", "v", "der(x)", "der(v)"])
    assert np.allclose(fmu["der(x)"], fmu["v"], rtol=1e-9, atol=1e-12 * np.ptp(fmu["v"]))
    central = (fmu["v"][2:] - fmu["v"][:-2]) / (2 * step)
    assert np.max(np.abs(fmu["der(v)"][1:-1] - central)) < 1e-3 * np.ptp(fmu["der(v)"])


def test_a_physical_value_set_through_fmi_is_gearsyms_run_with_it(spur):
    """The speed, mesh damping, backlash and torque fluctuation are tunable: set in the FMU they give gearsym's own
    run with --set at those values (to rounding), in SI; a value baked into the engine's values is refused."""
    speed = 9000 * TWO_PI / 60
    scale = gearsym.scaling("spur_pair", speed="9000 rpm", cZ="500 N*s/m", eta="60 um", M1a="10 N*m")
    run = gearsym.phase_trajectory(scale.system(k=K), options=Integration(periods=5, discard=0, backend=ENGINE))
    ours = scale.to_physical(run)
    period = spur_period(speed)
    fmu = simulate_fmu(str(spur), fmi_type="CoSimulation", stop_time=5 * period, output_interval=period / STEPS,
                       output=["x"], start_values={"speed": speed, "cZ": 500.0, "eta": 60e-6, "M1a": 10.0})
    x = ours["x"].to("m").magnitude[:len(fmu)]
    assert np.allclose(fmu["time"], ours.time.to("s").magnitude[:len(fmu)], rtol=1e-12, atol=0)
    assert np.max(np.abs(fmu["x"] - x)) < 1e-9 * np.ptp(x)
    t, reference, _, _ = spur_reference(5 * period, period / STEPS, speed=speed, cZ=500.0, eta=60e-6, M1a=10.0)
    assert np.max(np.abs(fmu["x"] - reference)) < 1e-4 * np.ptp(reference)
    raised, said = refusal(spur, kZ=2e8)
    assert raised.startswith("fmi2SetReal failed with status 3")
    assert said == ["kZ is baked into the engine's values of this FMU: export it again with gearsym fmu ... --set to "
                    "change it"]


def test_a_speed_changed_during_a_co_simulation_keeps_the_forcing_phase_continuous(spur):
    """speed is tunable: changed between two communication steps, the forcing phase tau goes on from where it
    was at the new rate (no jump), and the run goes on."""
    from fmpy import extract, instantiate_fmu

    where = extract(str(spur))
    try:
        md = read_model_description(where)
        refs = {v.name: v.valueReference for v in md.modelVariables}
        fmu = instantiate_fmu(where, md, fmi_type="CoSimulation")
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        first, second = 6000 * TWO_PI / 60, 9000 * TWO_PI / 60
        step = spur_period() / STEPS
        t, taus = 0.0, []
        for k in range(2 * STEPS):
            if k == STEPS:
                fmu.setReal([refs["speed"]], [second])
            fmu.doStep(t, step)
            t += step
            taus.append(fmu.getReal([refs["tau"]])[0])
        x = fmu.getReal([refs["x"]])[0]
        fmu.terminate()
        fmu.freeInstance()
    finally:
        shutil.rmtree(where, ignore_errors=True)
    rates = np.diff(taus) / step
    assert np.allclose(rates[:STEPS - 1], 28 * first, rtol=1e-9)
    assert np.allclose(rates[STEPS:], 28 * second, rtol=1e-9)
    assert taus[STEPS] == pytest.approx(taus[STEPS - 1] + 28 * second * step, rel=1e-12)
    assert math.isfinite(x)


# ------------------------------------------------------------------ a planetary model
def planetary_reference(s, periods=PERIODS):
    """The planetary set's equations as SymPy derived them, lambdified (no CasADi, no C) and solved by SciPy."""
    from scipy.integrate import solve_ivp

    from gearsym.model.backlash import g

    def backlash(x, eta):
        return x if x >= 0 else (0.0 if x > -eta else x + eta)

    values = {sp.Symbol(n, real=True): v for n, v in s.parameters.items()}
    values[sp.Symbol("omega", positive=True)] = s.parameters["omega"]
    exprs = [e.xreplace(values) for e in s.rhs]
    f = sp.lambdify([s.time, s.states], exprs, modules=[{g.__name__: backlash}, "math"], cse=True)
    tau = np.arange(periods * STEPS + 1) * TWO_PI / STEPS
    sol = solve_ivp(f, (0, tau[-1]), np.array(s.initial_vector), method="DOP853", t_eval=tau, rtol=1e-10,
                    atol=1e-10)
    return tau, sol.y


@pytest.mark.slow
def test_a_planetary_fmu_runs_both_ways_and_agrees_with_its_equations(planetary):
    assert validate_fmu(str(planetary)) == []
    s = system("planetary")
    tau, y = planetary_reference(s)
    x1 = y[0]
    fmu = cs(planetary, output=["x1", "x2", "y1", "ring_planet2.deflection"])
    assert np.max(np.abs(fmu["x1"] - x1)) < 1e-4 * np.ptp(x1)
    # a mesh that closes the kinematic loop has no state: its deflection is x1 - x2 + y1
    assert np.allclose(fmu["ring_planet2.deflection"], fmu["x1"] - fmu["x2"] + fmu["y1"], rtol=1e-13, atol=1e-13)
    exchange = me(planetary, tau[-1], TWO_PI / STEPS, output=("x1",))
    assert np.max(np.abs(exchange["x1"] - x1)) < 1e-4 * np.ptp(x1)
    ours = gearsym.phase_trajectory(s, options=Integration(periods=PERIODS, discard=0, backend=ENGINE))
    assert np.max(np.abs(fmu["x1"] - ours["x1"][:len(fmu)])) < 1e-10 * np.ptp(x1)


# ------------------------------------------------------------------ the archive
def test_the_archive_is_the_same_bytes_when_built_again_and_names_nothing_of_this_machine(one_stage, built):
    again = built / "again.fmu"
    assert main(["fmu", "one_stage", "--set", f"k={K}", "--out", str(again)]) == 0
    assert again.read_bytes() == one_stage.read_bytes()
    with zipfile.ZipFile(one_stage) as zf:
        assert [i.date_time for i in zf.infolist()] == [(1980, 1, 1, 0, 0, 0)] * len(zf.infolist())
        assert zf.namelist() == sorted(zf.namelist())
        data = b"".join(zf.read(n) for n in zf.namelist())
    for where in {str(REPO_ROOT), str(built), str(Path.home()), str(gearsym.codegen.cache_dir())}:
        assert where.encode() not in data, where


@pytest.mark.slow
def test_the_fmu_carries_the_engines_c_and_fmpy_builds_it_from_its_sources(one_stage, built):
    """sources/ is enough: FMPy compiles it (CMake) into a binary that gives the same run."""
    from fmpy.build import build_platform_binary

    if shutil.which("cmake") is None:
        pytest.skip("FMPy builds from sources with CMake, which is not installed")
    folder = built / "from_sources"
    with zipfile.ZipFile(one_stage) as zf:
        zf.extractall(folder)
        digest = code_hash(system("one_stage", k=K), LoopOptions.of(Integration()))
        engine = code_directory("one_stage", digest) / "one_stage.c"  # (the C every gearsym run of it compiles)
        assert zf.read("sources/one_stage.c") == engine.read_bytes()
    shutil.rmtree(folder / "binaries")
    build_platform_binary(str(folder.resolve()))
    rebuilt = cs(folder.resolve(), periods=4)
    shipped = cs(one_stage, periods=4)
    assert np.max(np.abs(rebuilt["x"] - shipped["x"])) < 1e-12 * np.ptp(shipped["x"])


def test_the_wheel_packages_the_fmu_wrapper_and_the_fmi_headers():
    """Every file of the package that is not Python is package data in pyproject.toml (a wheel has them)."""
    config = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    package = REPO_ROOT / "gearsym"
    data = [p for p in package.rglob("*") if p.is_file() and p.suffix not in (".py", ".pyc")
            and "__pycache__" not in p.parts]
    assert {p.name for p in data} >= {"gearsym_fmu.c", "fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"}
    for p in data:
        owner = ".".join(p.relative_to(REPO_ROOT).parent.parts)
        matched = any(p.relative_to(REPO_ROOT / Path(*pkg.split("."))).match(pattern)
                      for pkg, patterns in config.items() if owner.startswith(pkg) for pattern in patterns)
        assert matched, p


# ------------------------------------------------------------------ bad input: one line, exit 2
@pytest.mark.parametrize("argv, message", [
    (["fmu", "no_such_model", "--out", "{tmp}/a.fmu"], "unknown model 'no_such_model'"),
    (["fmu", "one_stage", "--out", "{tmp}/missing/a.fmu"], "does not exist"),
    (["fmu", "one_stage", "--out", "{tmp}/a.zip"], "ends in .fmu"),
    (["fmu", "one_stage", "--all", "--out", "{tmp}/d"], "give a model or --all"),
    (["fmu", "one_stage", "--set", "k=__import__('os')", "--out", "{tmp}/a.fmu"], "must not start with '_'"),
])
def test_bad_input_gets_one_line_and_exit_status_2(argv, message, tmp_path, capsys):
    code = main([a.format(tmp=tmp_path) for a in argv])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("gearsym: error:") and message in err
    assert list(tmp_path.iterdir()) == []  # nothing written


# ------------------------------------------------------------------ the worked example of docs/fmu.md
def test_the_worked_examples_data_are_what_the_fmu_gives(one_stage, reference):
    import importlib.util

    spec = importlib.util.spec_from_file_location("fmu_example", REPO_ROOT / "docs" / "fmu_example.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    fresh = example.compute(one_stage, backend=ENGINE)  # (committed from the compiled run: equal to ~1e-14)
    committed = np.genfromtxt(io.StringIO(example.DATA.read_text()), delimiter=",", names=True)
    assert committed.dtype.names == tuple(fresh)
    for name, values in fresh.items():
        tolerance = 1e-6 if name == "x_model_exchange" else 1e-9
        assert np.max(np.abs(committed[name] - values)) < tolerance * max(1.0, np.ptp(values)), name
    # and, independently of any regeneration, the committed numbers against SciPy's solution of the equation
    tau, x, _ = reference
    assert np.allclose(committed["tau"], tau[::10], rtol=1e-13, atol=1e-12)
    for name in ("x_gearsym", "x_co_simulation", "x_model_exchange"):
        assert np.max(np.abs(committed[name] - x[::10])) < 1e-4 * np.ptp(x), name


# ------------------------------------------------------------------ issue 35: gearsym's step, descriptions, verdicts
def test_co_simulation_keeps_gearsyms_step_whatever_the_communication_step(one_stage):
    """20 communication steps per forcing period (the engine takes 200 RK4 steps per period) give what 400 give:
    the FMU takes as many substeps as keep each within the engine's step (one RK4 step per communication step
    was 1.5e-3 of the range off at 20)."""
    def run(per_period):
        r = simulate_fmu(str(one_stage), fmi_type="CoSimulation", stop_time=20 * TWO_PI,
                         output_interval=TWO_PI / per_period, output=["x"])
        return r["time"], r["x"]

    t20, x20 = run(20)
    t400, x400 = run(400)
    coarse_times = np.round(t20 / (TWO_PI / 20)).astype(int) * 20
    assert np.max(np.abs(x20 - x400[coarse_times])) < 1e-6 * np.ptp(x400)


def _layout_of(name: str):
    """The variables of the FMU of a shipped model (what build_fmu writes, without compiling it)."""
    from gearsym.fmu.frame import Frame
    from gearsym.fmu.physical import physical_frame
    from gearsym.fmu.variables import layout
    from conftest import load, reduced

    model, sys_ = load(name), system(name)
    frame = physical_frame(reduced(name), {}, sys_) if isinstance(model, gearsym.Drivetrain) else None
    return layout(sys_, frame or Frame(), ())


@pytest.mark.slow
@slow_models_group()  # (it reduces every model: with the other tests that reduce the slow ones)
def test_every_variable_of_every_shipped_models_fmu_has_a_description():
    from gearsym.registry import pregenerated_models

    missing = {name: [v.name for v in _layout_of(name).variables if not v.description.strip()]
               for name in pregenerated_models()}
    assert {name: names for name, names in missing.items() if names} == {}
    planetary = {v.name: v.description for v in _layout_of("planetary").variables}
    assert planetary["r_r"] == "base radius of 'ring' (held)" and planetary["I_p"] == "moment of inertia of 'planet1'"


def _logged(path, **start):
    """(the error FMPy raised, the FMU's log) of a co-simulation over 60 forcing periods."""
    log = []
    with pytest.raises(Exception) as failed:
        simulate_fmu(str(path), fmi_type="CoSimulation", stop_time=60 * TWO_PI / 1.5, output_interval=TWO_PI / 30,
                     start_values=start, output=["x"], logger=lambda *a: log.append(" ".join(map(str, a))))
    return str(failed.value), " ".join(log)


@pytest.fixture(scope="module")
def cracked(built):
    """An FMU with a tooth fault's depth q and the default stiffness wave's k_a."""
    path = built / "cracked_pair.fmu"
    assert main(["fmu", "cracked_pair", "--out", str(path)]) == 0
    return path


def test_a_motion_that_diverges_stops_the_co_simulation_with_an_error_and_says_so(cracked):
    error, log = _logged(cracked, k_a=5.0)  # (the stiffness goes negative over part of each period: x to 1e69)
    assert "fmi2DoStep failed with status 3 (error)" in error
    assert "the motion diverged in the step from" in log and "x reached" in log and "a gearsym run calls diverged" in log


def test_a_start_that_is_not_a_number_is_named_as_such(cracked):
    error, log = _logged(cracked, x=float("nan"))
    assert "fmi2ExitInitializationMode failed" in error
    assert "the start value of x is nan: every state needs a finite start value" in log and "step" not in log


@pytest.mark.parametrize("q", [1.5, -0.5])
def test_a_fault_depth_outside_0_to_1_is_refused_by_the_fmu(cracked, q):
    error, log = _logged(cracked, q=q)
    assert "failed with status 3 (error)" in error
    assert (f"the parameter values make the engine's q {q:g}, but it must be at least 0 and less than 1 (the fraction "
            "of the stiffness of the pair of tooth 7 of 'gear1' that its fault takes away)") in log


@pytest.mark.slow
def test_all_writes_one_fmu_per_model_into_the_folder(tmp_path, monkeypatch, capsys):
    """`gearsym fmu --all --out DIR` (docs/fmu.md): an FMU for each model of `gearsym list`, named after it, into
    DIR, each said in a line. Two models stand for the list here, the two whose FMUs build fastest (the plain ODEs,
    1.7-1.9 s of CPU each against one_stage's 2.8 s and spur_pair's 3.6 s): every shipped model's FMU costs a minute;
    the gear models' FMUs are built and checked by the tests above."""
    import gearsym.cli.fmu as command

    monkeypatch.setattr(command, "pregenerated_models", lambda: ["duffing", "lorenz"])
    assert main(["fmu", "--all", "--out", str(tmp_path)]) == 0
    said = capsys.readouterr().out.splitlines()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["duffing.fmu", "lorenz.fmu"]
    for name in ("duffing", "lorenz"):
        assert read_model_description(str(tmp_path / f"{name}.fmu")).modelName == name
        assert any(line.startswith(f"{name}: {tmp_path / name}.fmu") for line in said), said
