"""The compiled engine against invariants, published values and an independent implementation."""
from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from conftest import compiled, system
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


@pytest.mark.parametrize("name,settings", [
    ("one_stage", {"omega": 1.5}),            # the paper's point
    ("one_stage", {"omega": 1.2}),            # chaotic: the sum holds all the same
    ("one_stage_resonant", {"omega": 1.36}),
    ("flexible_shaft", {"omega": 1.5, "kS": 0.1}),
    ("flexible_shaft", {"omega": 0.9, "kS": 1.0}),
    ("two_stage", {"omega": 1.2}),            # period 4 pi: the second mesh turns at half the speed
])
def test_exponents_sum_to_mean_trace(name, settings):
    result = lyapunov_spectrum(compiled(name), options=Integration(periods=300, discard=100), **settings)
    trace = system(name).jacobian().trace()  # constant for these models: the mean trace is its value
    expected = float(trace.subs({sp.Symbol(k, real=True): v for k, v in result.parameters.items()}
                                | {sp.Symbol("omega", positive=True): result.parameters["omega"]}))
    if name != "two_stage":
        assert expected == pytest.approx(-2 * result.parameters["zeta"] / result.parameters["omega"])
    assert len(result.exponents) == len(result.final_state)
    assert abs(result.sum - expected) < 1e-3
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
def test_trace_error_shrinks_with_more_steps(scheme):
    """RK4's tangent map has det = exp(trace * h) + O(h^5): the error of the sum falls ~ h^4 (measured ratios
    5.5 and 11 for the plain scheme, 8.7 and 13 with the crossings located)."""
    errors = []
    for steps in (100, 200, 400):
        r = lyapunov_spectrum(system("one_stage"), options=scheme(periods=120, discard=20, steps_per_period=steps),
                              omega=0.2)
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


# ------------------------------------------------------------------ an independent implementation
def _numpy_reference(omega, periods, discard, steps, zeta=0.08, B0=1.0, B1=4.0, eta=10.0, a=0.2):
    """Eq. 2 with k(tau) = 1 + a cos(tau), typed from the paper: plain NumPy RK4 on the state and
    its 2x2 tangent matrix, Gram-Schmidt (QR) once per period (the paper's scheme)."""
    def g(x):
        return x if x >= 0 else (x + eta if x <= -eta else 0.0)

    def dg(x):
        return 1.0 if (x >= 0 or x <= -eta) else 0.0

    def f(tau, y, Q):
        x, v = y
        k = 1 + a * np.cos(tau)
        dy = np.array([v, -2 * zeta / omega * v - k * g(x) / omega**2 + (B0 + B1 * np.cos(tau)) / omega**2])
        J = np.array([[0.0, 1.0], [-k * dg(x) / omega**2, -2 * zeta / omega]])
        return dy, J @ Q

    h = 2 * np.pi / steps
    y, Q = np.array([-2.0, -0.5]), np.eye(2)
    logs, lo, hi = [], np.inf, -np.inf
    for period in range(periods):
        for i in range(steps):
            tau = i * h
            k1, K1 = f(tau, y, Q)
            k2, K2 = f(tau + h / 2, y + h / 2 * k1, Q + h / 2 * K1)
            k3, K3 = f(tau + h / 2, y + h / 2 * k2, Q + h / 2 * K2)
            k4, K4 = f(tau + h, y + h * k3, Q + h * K3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            Q = Q + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)
            if period >= discard:
                lo, hi = min(lo, y[0]), max(hi, y[0])
        q, r = np.linalg.qr(Q)
        signs = np.sign(np.diag(r))
        Q = q * signs
        logs.append(np.log(np.abs(np.diag(r))))
    lam = np.array(logs[discard:]).sum(axis=0) / ((periods - discard) * 2 * np.pi)
    return lam, y, (hi - lo) / 2


@pytest.mark.parametrize("omega", [0.5, 1.6])
def test_one_stage_agrees_with_independent_numpy_rk4(omega):
    periods, discard, steps = 60, 20, 200
    ref_lam, ref_y, ref_amp = _numpy_reference(omega, periods, discard, steps)
    assert ref_lam[0] < -1e-3, "the comparison point must be periodic (errors do not grow)"
    r = lyapunov_spectrum(system("one_stage", k="1 + 0.2*cos(tau)"),
                          options=Integration.paper(periods=periods, discard=discard, steps_per_period=steps),
                          omega=omega)
    assert r.exponents == pytest.approx(np.sort(ref_lam)[::-1], abs=1e-9)
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


def test_history_and_initial_state():
    cm = compiled("flexible_shaft")
    y0 = np.array([-1.0, 0.2, 0.5, 0.0])
    r = lyapunov_spectrum(cm, options=Integration(periods=200, discard=50), omega=1.5, y0=y0)
    assert r.history.shape == (150, 4) and r.strobe.shape == (4, 150)
    assert r.history[-1] == pytest.approx(r.exponents, abs=1e-12)
    # the first running estimate is the first measured period's stretch, from the run's own data
    run = cm.tangent_run(y0, 200, cm.prepare(cm.parameter_vector(omega=1.5)))
    first = np.sort(run.log_stretch[:, 50] / (2 * np.pi))[::-1]
    assert np.sort(r.history[0])[::-1] == pytest.approx(first, abs=1e-12)
    assert r.strobe[:, -1] == pytest.approx(run.strobe[:, -1], abs=0)
    other = lyapunov_spectrum(cm, options=Integration(periods=200, discard=50), omega=1.5)  # the model's own start
    assert not np.allclose(other.strobe[:, :5], r.strobe[:, :5])


def test_too_few_periods_for_an_error_give_null_in_json():
    r = lyapunov_spectrum(compiled("lorenz"), options=Integration(periods=101, discard=100))
    assert np.all(np.isnan(r.stderr))
    assert r.as_dict()["stderr"] == [None, None, None]
