"""The regime classifier on known cases, and jump / hysteresis detection on curves with known answers."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import compiled
from gearsym import Integration, lyapunov_spectrum
from gearsym.analysis.divergence import own_rate
from gearsym.analysis.jumps import find_jumps, hysteresis_intervals
from gearsym.analysis.regime import classify_regime
from gearsym.errors import GearsymError


# ------------------------------------------------------------------ regimes
@pytest.mark.parametrize("omega, regime", [(1.6, "periodic"), (1.2, "chaotic")])
def test_known_gear_points(omega, regime):
    assert lyapunov_spectrum(compiled("one_stage"), omega=omega).regime == regime  # the default run: 400 periods


def test_lorenz_is_chaotic_once_the_flow_exponent_is_set_aside():
    spectrum = lyapunov_spectrum(compiled("lorenz"), options=Integration(periods=600, discard=100))
    assert spectrum.autonomous and spectrum.regime == "chaotic"


@pytest.mark.parametrize("exponents, stderr, autonomous, regime", [
    ([-0.05, -0.1], [0.001, 0.001], False, "periodic"),
    ([0.0004, -0.1], [0.001, 0.001], False, "quasi-periodic"),
    ([0.04, -0.2], [0.003, 0.003], False, "chaotic"),
    ([0.04, 0.02, -0.01, -0.3], [0.003, 0.003, 0.003, 0.003], False, "hyperchaotic"),
    ([0.004, -0.2], [0.003, 0.003], False, "quasi-periodic"),  # within 3 errors of zero: not evidence of chaos
    ([0.0, -0.5, -1.0], [0.001, 0.001, 0.001], True, "periodic"),  # a limit cycle of a flow
    ([0.0, 0.0, -1.0], [0.001, 0.001, 0.001], True, "quasi-periodic"),  # a torus
    ([-0.3, -0.5, -1.0], [0.001, 0.001, 0.001], True, "equilibrium"),
    ([0.9, 0.0, -14.5], [0.01, 0.001, 0.01], True, "chaotic"),
    ([0.3, 0.1, 0.0, -3.0], [0.01, 0.01, 0.001, 0.01], True, "hyperchaotic"),
])
def test_classifier_rules(exponents, stderr, autonomous, regime):
    assert classify_regime(exponents, stderr, measured_time=2000.0, autonomous=autonomous) == regime


def test_a_short_run_widens_the_zero_band():
    # 5/T: after 100 time units a zero exponent's estimate is still ~0.02 away from zero
    assert classify_regime([0.02, -0.3], [0.0, 0.0], measured_time=100.0) == "quasi-periodic"
    assert classify_regime([0.02, -0.3], [0.0, 0.0], measured_time=5000.0) == "chaotic"
    assert classify_regime([0.02, -0.3], [np.nan, np.nan], measured_time=5000.0) == "chaotic"


# ------------------------------------------------------------------ jumps
OMEGA = np.round(np.arange(0.1, 2.0001, 0.01), 2)


def smooth(omega):
    return 3 + 2 * np.sin(2 * omega) + 0.5 * omega


def test_a_known_jump_is_found_where_it_is_and_nowhere_else():
    a = smooth(OMEGA) + np.where(OMEGA > 1.36, -1.2, 0.0)
    jumps = find_jumps(OMEGA, a)
    assert len(jumps) == 1
    assert (jumps[0].start, jumps[0].end) == (1.36, 1.37) and jumps[0].size == pytest.approx(-1.2, abs=0.05)


def test_steep_smooth_curves_and_noise_are_not_jumps():
    assert find_jumps(OMEGA, 10 * np.tanh((OMEGA - 1) / 0.3)) == []
    noisy = smooth(OMEGA) + np.random.default_rng(1).normal(0, 0.01, OMEGA.size)
    assert find_jumps(OMEGA, noisy) == []


def test_a_cliff_over_a_few_steps_is_one_jump_and_direction_is_kept():
    a = smooth(OMEGA) + np.interp(OMEGA, [1.69, 1.72], [0.0, -2.5])
    jumps = find_jumps(OMEGA, a)
    assert len(jumps) == 1 and jumps[0].start == 1.69 and jumps[0].end == 1.72
    down = find_jumps(OMEGA[::-1], a[::-1])  # the same curve run downwards
    assert len(down) == 1 and down[0].start == 1.72 and down[0].size > 0


def test_hysteresis_is_where_up_and_down_differ():
    up = smooth(OMEGA) + np.where(OMEGA > 1.5, -2.0, 0.0)  # up stays on the upper branch until 1.5
    down = smooth(OMEGA) + np.where(OMEGA > 1.3, -2.0, 0.0)  # down falls off at 1.3
    assert hysteresis_intervals(OMEGA, up, down) == [(1.31, 1.5)]
    assert hysteresis_intervals(OMEGA, up, up) == []


def test_a_tiny_step_on_a_flat_curve_is_not_a_jump():
    """Numerical wobble: the step stands out from its neighbours, but is nothing next to A itself."""
    a = 10 + 1e-9 * np.random.default_rng(2).normal(size=OMEGA.size) + np.where(OMEGA > 1.0, 1e-6, 0.0)
    assert find_jumps(OMEGA, a) == []
    up, down = a.copy(), a + 1e-6
    assert hysteresis_intervals(OMEGA, up, down) == []


def test_a_forcing_too_fast_for_the_run_is_no_torus():
    """At omega = 1e308 the tau-form's forces (over omega^2) underflow to zero: x drifts at a constant rate, its
    Poincare points step evenly, which looked stationary (a torus). The run lasts 1e-306 of a period of the
    model's own fastest motion: undetermined, and the settling says why."""
    result = lyapunov_spectrum(compiled("one_stage"), omega=1e308, options=Integration(periods=70, discard=10))
    assert result.regime == "undetermined"
    assert result.settling.state == "brief" and "too short for its Poincare points to show" in result.settling.describe()
    assert lyapunov_spectrum(compiled("one_stage"), omega=1.5, options=Integration(periods=70, discard=10)).regime \
        != "undetermined"  # (a run long enough is judged as before)


def test_a_forcing_frequency_that_overflows_the_equations_is_one_line():
    with pytest.raises(GearsymError, match=r"omega=1e-308.*the equations are not finite at the start with these "
                                           r"values: a value overflows the engine's doubles"):
        lyapunov_spectrum(compiled("one_stage"), omega=1e-308, options=Integration(periods=70, discard=10))


def test_a_smooth_decay_from_the_first_point_is_not_a_jump():
    """The issue's sweep: 7.956, 7.559, 7.307 um at 800, 850, 900 rpm and flatter beyond: a slope that goes on is no
    jump, however it compares with the flat curve further on; a step at the first point that stands alone is."""
    speed = np.arange(800.0, 1801.0, 50.0)
    decay = 6.9 + 1.056 * np.exp(-(speed - 800) / 110)  # 7.956, 7.570, 7.325, ...
    assert find_jumps(speed, decay) == []
    alone = np.where(speed > 800, 6.9, 9.0)
    (jump,) = find_jumps(speed, alone)
    assert (jump.start, jump.end) == (800.0, 850.0)


def test_the_fastest_own_motion_is_looked_for_only_until_it_is_fast_enough(monkeypatch):
    """A run long next to the model's fastest own motion needs only one Jacobian whose rate reaches the bound (a
    cached spectrum's start-up solved 16 eigenvalue problems to learn that); below it, all are looked at."""
    model = compiled("one_stage")
    p = model.parameter_vector(omega=1.5)
    y, period = np.array([0.3, 0.1]), model.prepare(p).period
    full = own_rate(model, y, p, period)
    calls = []
    jacobian = model.jacobian
    monkeypatch.setattr(model, "jacobian", lambda *args: calls.append(1) or jacobian(*args))
    assert own_rate(model, y, p, period, enough=full / 2) >= full / 2 and len(calls) < 16
    calls.clear()
    assert own_rate(model, y, p, period, enough=2 * full) == full and len(calls) == 16
