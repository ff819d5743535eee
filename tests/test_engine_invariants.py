"""The compiled engine against invariants, published values and an independent implementation."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import sympy as sp

from conftest import compiled, paper_rk4_spectrum, system
from gearsym import Integration, compile_model, lyapunov_spectrum, phase_trajectory, poincare_samples


# ------------------------------------------------------------------ sum of exponents = mean trace
@pytest.mark.parametrize("name", ["one_stage", "one_stage_resonant", "flexible_shaft", "two_stage"])
def test_trace_of_jacobian_is_minus_two_zeta_over_omega(name):
    trace = sp.simplify(system(name).jacobian().trace())
    zeta, omega = sp.Symbol("zeta", real=True), sp.Symbol("omega", positive=True)
    if name == "two_stage":  # a second damped mesh adds its own term
        zeta2 = sp.Symbol("zeta2", real=True)
        assert sp.simplify(trace - (-2 * zeta / omega - 2 * zeta2 / omega)) == 0
    else:
        assert sp.simplify(trace - (-2 * zeta / omega)) == 0


#: each case's bound on |sum - mean trace| / |mean trace|: ten times the error measured (in brackets), which is
#: RK4's truncation error of the tangent map's determinant (stable to 2 % over starts 1e-9 apart, chaotic or not)
@pytest.mark.parametrize("name,settings,rel", [
    ("one_stage", {"omega": 1.5}, 3e-8),                     # the paper's point [2.6e-9]
    ("one_stage", {"omega": 1.2}, 6e-8),                     # chaotic: the sum holds all the same [5.3e-9]
    ("one_stage_resonant", {"omega": 1.36}, 4e-8),           # [3.3e-9]
    ("flexible_shaft", {"omega": 1.5, "kS": 0.1}, 5e-8),     # [5.0e-9]
    ("flexible_shaft", {"omega": 0.9, "kS": 1.0}, 8e-7),     # [7.4e-8]
    ("two_stage", {"omega": 1.2}, 5e-6),  # period 4 pi: the second mesh turns at half the speed [4.1e-7]
])
@pytest.mark.slow
def test_exponents_sum_to_mean_trace(name, settings, rel):
    result = lyapunov_spectrum(compiled(name), options=Integration(periods=300, discard=100), **settings)
    trace = system(name).jacobian().trace()  # constant for these models: the mean trace is its value
    expected = float(trace.subs({sp.Symbol(k, real=True): v for k, v in result.parameters.items()}
                                | {sp.Symbol("omega", positive=True): result.parameters["omega"]}))
    if name != "two_stage":
        assert expected == pytest.approx(-2 * result.parameters["zeta"] / result.parameters["omega"])
    assert len(result.exponents) == len(result.final_state)
    assert result.sum == pytest.approx(expected, rel=rel, abs=0)  # an exponent averaged over one period too
    # many or few is off by ~1/(measured periods) = 5e-3
    assert np.all(np.diff(result.exponents) <= 0), "exponents must be listed in descending order"


def test_a_plain_ode_with_a_parameter_dependent_period():
    """Duffing x'' + d x' + x^3 - x = F cos(w t): forcing period 2 pi / w is a runtime input too."""
    from gearsym import FirstOrderSystem

    duffing = FirstOrderSystem.from_equations(
        "duffing", ["x", "v"], ["v", "-d*v - x**3 + x + F*cos(w*t)"], {"d": 0.3, "F": 0.5, "w": 1.2},
        time="t", period="2*pi/w", initial={"x": 1.0})
    cm = compile_model(duffing)
    for w in (1.0, 1.2):
        r = lyapunov_spectrum(cm, options=Integration(periods=200, discard=50), w=w)
        assert r.period == pytest.approx(2 * np.pi / w)
        assert r.sum == pytest.approx(-0.3, abs=1e-5)


@pytest.mark.parametrize("scheme", [Integration.paper, Integration])
@pytest.mark.slow
def test_trace_error_shrinks_with_more_steps(scheme):
    """RK4's tangent map has det = exp(trace * h) + O(h^5): the error of the sum falls ~ h^4 (measured ratios
    5.5 and 11 for the plain scheme, 8.7 and 13 with the crossings located). The scheme is CasADi's functions, run
    in-process, as test_crossings' order tests: three step counts would be three C libraries (4-5 s of compiling)
    for the same functions' numbers, which the compiled library gives to 1e-12 (test_codegen's
    test_compiled_and_in_process_agree; here the errors agree to 3e-16)."""
    errors = []
    for steps in (100, 200, 400):
        options = scheme(periods=120, discard=20, steps_per_period=steps, backend="in-process")
        r = lyapunov_spectrum(system("one_stage"), options=options, omega=0.2)
        errors.append(abs(r.sum + 2 * 0.08 / 0.2))
    assert errors[0] > 4 * errors[1] > 16 * errors[2] > 0
    assert errors[1] < 1e-3


# ------------------------------------------------------------------ published values
def test_lorenz_published_exponents():
    """Lorenz sigma=10, rho=28, beta=8/3: 0.9056, 0, -14.5723 (sum exactly -(sigma + 1 + beta))."""
    r = lyapunov_spectrum(compiled("lorenz"), options=Integration(periods=3100, discard=100))
    assert r.exponents == pytest.approx([0.9056, 0.0, -14.5723], abs=0.02)
    assert r.sum == pytest.approx(-(10 + 1 + 8 / 3), abs=1e-4)  # RK4 at h = 0.005: ~6e-6
    assert np.all(r.stderr < 0.02)
    assert r.kaplan_yorke_dimension == pytest.approx(2.062, abs=0.005)  # 2 + 0.9056/14.5723


# ------------------------------------------------------------------ an independent implementation (in conftest)
@pytest.mark.slow
@pytest.mark.parametrize("omega", [0.5, 1.6])
def test_one_stage_agrees_with_independent_numpy_rk4(omega):
    periods, discard, steps = 30, 10, 200  # (one scheme twice: it differs in any period)
    ref_lam, ref_y, ref_amp = paper_rk4_spectrum(omega, periods, discard, steps)
    assert ref_lam[0] < -1e-3, "the comparison point must be periodic (errors do not grow)"
    r = lyapunov_spectrum(system("one_stage", k="1 + 0.2*cos(tau)"),
                          options=Integration.paper(periods=periods, discard=discard, steps_per_period=steps),
                          omega=omega)
    expected = np.sort(ref_lam)[::-1]
    for i, j in r.pairs:  # a rotating pair is reported as its common real part (analysis/pairs.py)
        expected[i] = expected[j] = (expected[i] + expected[j]) / 2
    assert r.exponents == pytest.approx(expected, abs=1e-9)
    assert [r.final_state["x"], r.final_state["v"]] == pytest.approx(ref_y, abs=1e-9)
    assert r.amplitude["x"] == pytest.approx(ref_amp, abs=1e-9)


# ------------------------------------------------------------------ the analyses agree with each other
def test_strobe_samples_agree_between_tangent_orbit_and_trajectory_runs():
    cm = compiled("one_stage")
    run = Integration(periods=30, discard=10)  # 20 periods after the transient, for every analysis
    lyap = lyapunov_spectrum(cm, options=run, omega=0.8)
    orbit = poincare_samples(cm, options=run, omega=0.8)
    traj = phase_trajectory(cm, options=run, omega=0.8)
    assert orbit.strobe == pytest.approx(lyap.strobe, abs=1e-12)
    assert traj.strobe[:, 1:] == pytest.approx(orbit.strobe, abs=1e-12)
    assert traj.states.shape == (2, 20 * 200 + 1)
    assert traj.time[0] == pytest.approx(10 * 2 * np.pi)
    assert orbit.amplitude["x"] == pytest.approx(lyap.amplitude["x"], abs=1e-12)
    x = traj["x"]
    assert (x.max() - x.min()) / 2 == pytest.approx(orbit.amplitude["x"], abs=1e-12)


def test_the_librarys_own_calls_give_casadis_numbers():
    """trajectory, rhs and jacobian call the compiled library directly (no CasADi call, no copies of its results):
    the same C, so the numbers of CasADi's call of it to the bit; a state of the wrong size is CasADi's to refuse."""
    cm = compiled("one_stage")
    through_casadi = dataclasses.replace(cm, native=None)
    inputs = cm.prepare(cm.parameter_vector(omega=0.8))
    y = cm.initial_state(None) + 0.3
    (time, states), (time_casadi, states_casadi) = (m.trajectory(y, 3, inputs) for m in (cm, through_casadi))
    assert states.shape == (2, 3 * cm.steps_per_period + 1)
    assert np.array_equal(states, states_casadi) and np.array_equal(time, time_casadi)
    for t in (0.0, 1.3):
        assert np.array_equal(cm.rhs(t, y, inputs.p), through_casadi.rhs(t, y, inputs.p))
        assert np.array_equal(cm.jacobian(t, y, inputs.p), through_casadi.jacobian(t, y, inputs.p))
    with pytest.raises(RuntimeError):
        cm.jacobian(0.0, np.append(y, 0.0), inputs.p)


def test_history_and_initial_state():
    cm = compiled("flexible_shaft")
    y0 = np.array([-1.0, 0.2, 0.5, 0.0])
    r = lyapunov_spectrum(cm, options=Integration(periods=200, discard=50), omega=1.5, y0=y0)
    assert r.history.shape == (150, 4) and r.strobe.shape == (4, 150)
    assert r.history[-1] == pytest.approx(r.exponents, abs=1e-12)
    # the first running estimate is the first measured period's stretch, from the run's own data
    run = cm.tangent_run(y0, 200, cm.prepare(cm.parameter_vector(omega=1.5)))
    stretch = run.log_stretch[:, 50:] / (2 * np.pi)
    first = stretch[np.argsort(-stretch.mean(axis=1)), 0]  # the exponents' order: descending final values
    for i, j in r.pairs:  # a rotating pair's running estimate is its common real part's (analysis/pairs.py)
        first[i] = first[j] = (first[i] + first[j]) / 2
    assert r.history[0] == pytest.approx(first, abs=1e-12)
    assert r.strobe[:, -1] == pytest.approx(run.strobe[:, -1], abs=0)
    other = lyapunov_spectrum(cm, options=Integration(periods=200, discard=50), omega=1.5)  # the model's own start
    assert not np.allclose(other.strobe[:, :5], r.strobe[:, :5])


def test_too_few_periods_for_an_error_give_null_in_json():
    r = lyapunov_spectrum(compiled("lorenz"), options=Integration(periods=101, discard=100))
    assert np.all(np.isnan(r.stderr))
    assert r.as_dict()["stderr"] == [None, None, None]
