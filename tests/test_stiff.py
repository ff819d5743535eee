"""The stiff step (RODAS4 with the exact Jacobian), the step chosen from the fastest linearised mode, and exponents
reported only where the run resolved them (issue 38).

The references are independent: the exact decay rates of a linear damped chain (the real parts of its matrix's
eigenvalues), SciPy's DOP853 on the variational equations, SciPy's Radau at tight tolerance on a stiff model, the
trace of the Jacobian (Liouville: the sum of the exponents, the product of the Floquet multipliers)."""
from __future__ import annotations

import functools
import math

import casadi as ca
import numpy as np
import pytest
import sympy as sp

import gearsym
from conftest import compiled, system
from gearsym import FirstOrderSystem, Integration, compile_model, lyapunov_spectrum, phase_trajectory
from gearsym.codegen.rosenbrock import rosenbrock_state
from gearsym.codegen.fastest_mode import fastest_rate
from gearsym.codegen.mode_rates import chosen_by_compiled
from gearsym.codegen.step_choice import RK4_RESOLVED, choices_from, chosen, round_steps


# ------------------------------------------------------------------ a linear damped chain, modes far apart
def chain(w2: float) -> FirstOrderSystem:
    """Two modes in modal coordinates, coupled by a constant matrix (so that neither is a state alone): a slow
    one (1 rad per unit time, damping ratio 0.05) and a fast one (``w2``, 0.2), forced at period 2 pi."""
    rhs = ["v1", "-(a*x1 + b*x2) - c1*v1 + cos(t)", "v2", "-(b*x1 + d*x2) - c2*v2"]
    values = {"a": 1.0, "b": 0.3 * w2, "d": w2**2, "c1": 0.1, "c2": 0.4 * w2}
    return FirstOrderSystem.from_equations("chain", ["x1", "v1", "x2", "v2"], rhs, values, time="t",
                                           period="2*pi", initial={"x1": 1.0, "x2": 0.5})


def exact_rates(s: FirstOrderSystem) -> np.ndarray:
    """The real parts of the eigenvalues of the chain's constant matrix, descending: its exact exponents."""
    J = np.array(s.jacobian().subs({sp.Symbol(k, real=True): v for k, v in s.parameters.items()}), dtype=float)
    return np.sort(np.linalg.eigvals(J).real)[::-1]


@functools.cache
def run(w2: float, integrator: str = "auto", reorthonormalise: bool = True):
    """The chain's model and spectrum, in-process (CasADi's functions: 0.25 s of CPU each, where compiling them is
    1-2 s for a library no other test uses; the compiled stiff step is checked against SciPy's Radau below)."""
    s = chain(w2)
    model = compile_model(s, Integration(periods=60, discard=10, integrator=integrator, backend="in-process"))
    if not reorthonormalise:  # (the sabotage check: Gram-Schmidt once per period)
        model = compile_model(s, Integration.paper(periods=60, discard=10, backend="in-process",
                                                   steps_per_period=model.integration.steps_per_period))
    return model, lyapunov_spectrum(model)


@pytest.mark.slow
def test_every_exponent_of_a_linear_chain_with_modes_30_times_apart_is_its_exact_decay_rate():
    model, result = run(30.0)
    assert model.integration.integrator == "rk4" and model.integration.steps_per_period == 800  # chosen, said
    assert "fastest linearised mode" in model.integration.choice
    exact = exact_rates(chain(30.0))
    assert exact[-1] < 100 * exact[0]  # decay rates 0.05 and 6 per unit time: e^-38 over one period
    assert fastest_rate(chain(30.0)) * 2 * math.pi / 800 <= RK4_RESOLVED
    assert result.resolution.all_resolved
    np.testing.assert_allclose(result.exponents, exact, rtol=1e-3)


@pytest.mark.slow
def test_exponents_lost_in_round_off_are_not_reported_as_values():
    heavy = {"c2": 1.6 * 30.0}  # the fast mode's damping ratio 0.8: it decays by e^-150 over a period
    exact = exact_rates(chain(30.0).with_values(**heavy))
    model, _ = run(30.0)
    resolved = lyapunov_spectrum(model, **heavy)  # re-orthonormalised every 25 steps: every exponent measured
    assert resolved.resolution.all_resolved
    np.testing.assert_allclose(resolved.exponents, exact, rtol=1e-3)
    paper, _ = run(30.0, reorthonormalise=False)  # Gram-Schmidt once per period (the paper's plain scheme)
    lost = lyapunov_spectrum(paper, **heavy)
    assert lost.exponents[-1] > 0.5 * exact[-1]  # the number measured is the rounding's, not the mode's
    assert list(lost.resolution.reasons) == ["", "", "round-off", "round-off"]
    assert "round-off" in lost.resolution.note(3)


@pytest.mark.slow
def test_the_stiff_step_is_chosen_where_rk4_would_need_many_more_steps_and_resolves_the_slow_modes():
    model, result = run(100.0)
    assert model.integration.integrator == "stiff" and model.integration.steps_per_period == 200
    assert "RK4 would need 2500 steps" in model.integration.choice
    exact = exact_rates(chain(100.0))
    np.testing.assert_allclose(result.exponents[:2], exact[:2], rtol=1e-4)  # the slow pair, resolved
    assert list(result.resolution.reasons) == ["", "", "step", "step"]  # h |mu| = 3.1: damped, not measured
    note = result.resolution.note(3)
    assert "not resolved" in note and f"{exact[-1]:.6g}" in note  # the linearised estimate, said as such


def test_the_step_choice_rounds_up_and_keeps_what_is_asked():
    assert [round_steps(x) for x in (200, 201, 377, 1257, 0.3)] == [200, 250, 400, 1500, 1]
    asked = Integration(integrator="rk4", steps_per_period=100)
    assert chosen(asked, rho=1e6, cycle=1.0) is asked  # an integrator given is taken as given


def test_a_sweeps_step_resolves_its_fastest_end_alike_from_the_model_and_from_its_compiled_library():
    """The one-stage model's own values need 200 steps, omega = 0.1 (its fastest point) 250; a cached model's sweep
    reads the rates from its library's Jacobian and period (no SymPy) and chooses the same, note and all."""
    ends = [{"omega": 0.1}, {"omega": 2.0}]
    from_model = gearsym.chosen_integration(Integration(), system("one_stage"), ends)
    assert compiled("one_stage").integration.steps_per_period == 200
    assert from_model.steps_per_period == 250 and "at omega=0.1:" in from_model.choice
    assert chosen_by_compiled(Integration(), compiled("one_stage"), ends) == from_model


def test_the_choices_a_faster_point_can_make_are_all_listed():
    """A sweep finds a library of its model among them (the model's own values are its slowest point at best)."""
    listed = [(o.integrator, o.steps_per_period) for o in choices_from(Integration(), 10.0, 2 * math.pi)]
    for rho in np.geomspace(10.0, 1e4, 200):
        made = chosen(Integration(), rho, 2 * math.pi)
        assert (made.integrator, made.steps_per_period) in listed


# ------------------------------------------------------------------ the step itself: 4th order, tangent too
def _step_function():
    y, h = ca.SX.sym("y", 2), ca.SX.sym("h")
    Ta, Tb, Tc = (ca.SX.sym(n, 4) for n in ("Ta", "Tb", "Tc"))  # tables: cos t, sin 3t, then their rates

    def f(x, T):
        return ca.vertcat(x[1], -x[0] - 0.3 * x[1] + T[0] + 0.5 * x[0] * T[1])

    def J(x, T):
        xs = ca.SX.sym("xs", 2)
        return ca.substitute(ca.jacobian(f(xs, T), xs), xs, x)

    y1 = rosenbrock_state(f, J, y, h, Ta, Tb, Tc, 2)
    return ca.Function("step", [y, h, Ta, Tb, Tc], [y1, ca.jacobian(y1, y)])


def test_the_stiff_step_and_its_tangent_map_converge_at_fourth_order_by_step_halving():
    from scipy.integrate import solve_ivp

    step = _step_function()

    def table(t):
        return [math.cos(t), math.sin(3 * t), -math.sin(t), 3 * math.cos(3 * t)]

    def rhs(t, z):  # the state and its variational equations, typed here
        x, P = z[:2], z[2:].reshape(2, 2)
        J = np.array([[0.0, 1.0], [-1 + 0.5 * math.sin(3 * t), -0.3]])
        return np.concatenate([[x[1], -x[0] - 0.3 * x[1] + math.cos(t) + 0.5 * x[0] * math.sin(3 * t)],
                               (J @ P).ravel()])

    ref = solve_ivp(rhs, (0, 2.0), [1, 0, 1, 0, 0, 1], method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
    errors = []
    for N in (10, 20, 40, 80):
        h, x, M = 2.0 / N, np.array([1.0, 0.0]), np.eye(2)
        for k in range(N):
            x1, Mk = step(x, h, table(k * h), table((k + 0.5) * h), table((k + 1) * h))
            x, M = np.array(x1).ravel(), np.array(Mk) @ M
        errors.append(max(np.abs(x - ref[:2]).max(), np.abs(M.ravel() - ref[2:]).max()))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(orders > 3.8), (errors, orders)


# ------------------------------------------------------------------ on a gear model, crossings located
@functools.cache
def stiff_shaft():
    """In-process (CasADi's functions: 1 s of CPU here, where compiling them is 4): the compiled stiff step is
    checked against SciPy's Radau below."""
    return compile_model(system("flexible_shaft"), Integration(periods=160, discard=60, integrator="stiff",
                                                               backend="in-process"))


@pytest.mark.slow
def test_the_stiff_step_gives_the_explicit_steps_exponents_and_their_sum_is_the_mean_trace():
    values = {"omega": 1.8, "kS": 0.1}
    stiff = lyapunov_spectrum(stiff_shaft(), **values)
    rk4 = lyapunov_spectrum(system("flexible_shaft"), options=Integration(periods=160, discard=60,
                                                                          integrator="rk4"), **values)
    np.testing.assert_allclose(stiff.exponents, rk4.exponents, rtol=0, atol=1e-6)
    assert stiff.sum == pytest.approx(-2 * 0.08 / 1.8, rel=1e-7)  # Liouville (zeta = 0.08)


def test_the_floquet_multipliers_of_a_stiff_orbit_multiply_to_the_exponential_of_the_integrated_trace():
    orbit = gearsym.periodic_orbit(stiff_shaft(), omega=1.8, kS=0.1)
    assert orbit.residual < 1e-9
    expected = math.exp(-2 * 0.08 / 1.8 * orbit.period)
    assert abs(np.prod(orbit.multipliers)) == pytest.approx(expected, rel=1e-6)


@pytest.mark.slow
def test_a_stiff_damped_shaft_integrated_by_the_stiff_step_agrees_with_scipys_radau():
    from scipy.integrate import solve_ivp

    # a gear pair with backlash and a shaft whose damped mode (rate 105, decay 17 per unit time) is 70 times the
    # mesh's: RK4 would need 2500 steps per period, the stiff step takes 200 and damps the shaft's transient
    values = {"kS": 1e4, "cS": 20.0}
    s = system("rich").with_values(**values)
    model = compile_model(s, Integration(periods=4, discard=0))
    assert model.integration.integrator == "stiff"
    trajectory = phase_trajectory(model)
    numbers = {sp.Symbol(k, real=True): v for k, v in s.parameters.items()}
    numbers[sp.Symbol("omega", positive=True)] = s.parameters["omega"]
    rhs = sp.Matrix(s.rhs).subs(numbers)
    numpy_g = {"g": lambda x, eta: np.where(x >= 0, x, np.where(x <= -eta, x + eta, 0.0)),
               "g_slope": lambda x, eta: np.where((x >= 0) | (x <= -eta), 1.0, 0.0)}  # (in contact 1, in the gap 0)
    f = sp.lambdify([s.time, sp.Matrix(s.states)], rhs, modules=[numpy_g, "numpy"])
    J = sp.lambdify([s.time, sp.Matrix(s.states)], rhs.jacobian(s.states), modules=[numpy_g, "numpy"])
    radau = solve_ivp(lambda t, y: np.asarray(f(t, y), dtype=float).ravel(), (0.0, trajectory.time[-1]),
                      s.initial_vector, method="Radau", rtol=1e-9, atol=1e-11,
                      jac=lambda t, y: np.asarray(J(t, y), dtype=float))
    assert radau.success
    ours = np.array([trajectory[name][-1] for name in s.state_names])
    scale = np.max(np.abs(radau.y), axis=1)
    assert np.max(np.abs(ours - radau.y[:, -1]) / scale) < 1e-6


def test_a_ranges_step_is_said_in_seconds_and_hz_at_the_speed_whose_fastest_mode_chose_it():
    from types import SimpleNamespace

    from gearsym.cli.arguments.integration import step_line
    from gearsym.codegen.fastest_mode import chosen_integration

    scaling = gearsym.scaling("spur_pair")  # declared at 6000 rpm
    s = scaling.system()
    low = scaling.omega("1000 rpm")  # per unit tau, its modes are 6 times faster there: it chooses the step

    def said(points):
        options = chosen_integration(Integration(), s, points)
        steps = options.steps_per_period
        return options, step_line(SimpleNamespace(integration=options, system=s, steps_per_cycle=steps,
                                                  steps_per_period=steps, cycles=1), scaling)

    own, line_own = said([])
    ranged, line = said([{"omega": low}, {"omega": s.parameters["omega"]}])
    hz = fastest_rate(s, {"omega": low}) * low * scaling.omega_n_si / (2 * math.pi)
    assert ranged.steps_per_period > own.steps_per_period
    def hz_said(text):  # (from the rate as printed, 4 digits)
        return float(text.split("per unit time = ")[1].split(" Hz")[0])

    assert " Hz at 1000 rpm" in line and hz_said(line) == pytest.approx(hz, rel=1e-3)  # (not 6 times it)
    assert hz_said(line_own) == pytest.approx(hz, rel=2e-3)  # the same mode at 6000 rpm
    h = 2 * math.pi / ranged.steps_per_period / (low * scaling.omega_n_si)
    assert f"h = {h * 1e6:.4g} µs at 1000 rpm" in line
