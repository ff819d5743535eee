"""Honest verdicts (issue 25, items 4-6): a run that diverged is not chaos; where the exponents cannot decide, the
Poincare points do or the verdict is "undetermined" with the periods that would decide; a complex pair of Floquet
multipliers is reported as its common real part with an error that covers the QR method's finite-time bias.

Every answer here is known without gearsym's QR: the damped linear oscillator (duffing with beta = 0) has the
exponents -zeta +- sqrt(zeta^2 - 1) exactly, and RK4's one-step matrix R(hA) gives those of the discrete map the
engine integrates; the undamped forced oscillator's motion is a 2-torus (x = A cos(t + phi) + the forced response);
the one-stage model's period-1 orbits have the Floquet exponents of the shooting's monodromy matrix; Lorenz has its
published lambda_1 = 0.9056; k(tau) = 1 + k_a w(tau) is negative somewhere exactly when k_a > -1/min w.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

import conftest
import gearsym
from gearsym import Integration, lyapunov_spectrum, periodic_orbit, run_sweep
from gearsym.analysis.statistics import batch_means_stderr
from gearsym.analysis.divergence import GROWING, PAST_BOUND
from gearsym.analysis.pairs import finite_time_bias
from gearsym.cli import main
from gearsym.errors import GearsymError
from gearsym.model.stiffness import rectangular_mesh_stiffness
from gearsym.model.symbols import phi

#: the damped linear oscillator: duffing without its cubic term, forced off resonance, started off its response
LINEAR = dict(beta=0.0, omega=1.3, F=0.3)
START = {"x": 1.0, "v": 0.0}


@pytest.fixture(scope="module")
def duffing():
    return conftest.compiled("duffing")


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def rk4_exponents(zeta: float, omega: float, steps: int) -> np.ndarray:
    """The exponents of the map RK4 makes of x'' + 2 zeta x' + x = F cos(omega t) over one forcing period:
    R(hA)^steps, R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 (the forcing does not enter the tangent map)."""
    period = 2 * np.pi / omega
    hA = period / steps * np.array([[0.0, 1.0], [-1.0, -2.0 * zeta]])
    R = np.eye(2) + hA + hA @ hA / 2 + hA @ hA @ hA / 6 + hA @ hA @ hA @ hA / 24
    mu = np.linalg.eigvals(np.linalg.matrix_power(R, steps))
    return np.sort(np.log(np.abs(mu)) / period)[::-1]


# ------------------------------------------------------------------ item 6: complex Floquet pairs
def test_a_complex_pair_is_reported_as_its_common_real_part_with_an_error_that_brackets_it(duffing):
    zeta = 0.05
    r = lyapunov_spectrum(duffing, y0=START, zeta=zeta, **LINEAR)
    exact = rk4_exponents(zeta, LINEAR["omega"], duffing.steps_per_period)
    assert exact == pytest.approx([-zeta, -zeta], abs=1e-8)  # (RK4 at 200 steps: the continuous -zeta omega_n)
    assert r.pairs == ((0, 1),) and r.exponents[0] == r.exponents[1]
    assert np.all(np.abs(r.exponents - exact) <= 3 * r.stderr + 1e-12 * zeta)
    assert r.as_dict()["pairs"] == [[1, 2]]


def test_distinct_real_exponents_stay_distinct(duffing):
    zeta = 2.0  # overdamped: -2 +- sqrt(3)
    r = lyapunov_spectrum(duffing, y0=START, zeta=zeta, **LINEAR)
    assert r.pairs == ()
    assert r.exponents == pytest.approx(rk4_exponents(zeta, LINEAR["omega"], duffing.steps_per_period), abs=1e-9)
    assert r.exponents == pytest.approx([-zeta + np.sqrt(zeta**2 - 1), -zeta - np.sqrt(zeta**2 - 1)], rel=1e-6)


def test_spur_pairs_orbit_has_both_exponents_at_minus_zeta_omega_n():
    """The orbit stays in contact: x'' + 2 zeta x' + k(tau) x = ..., whose trace is -2 zeta everywhere, so a complex
    pair has the real part -zeta omega_n = -1724.93 /s exactly (up to RK4's error at 200 steps, 1e-6 of it). At
    5000 rpm, below the resonance of the mesh frequency's second harmonic (5883 rpm), where the teeth separate."""
    s = gearsym.scaling("spur_pair", speed="5000 rpm")
    compiled = gearsym.compile_model(s.system())
    r = lyapunov_spectrum(compiled)
    point = s.to_physical(r)
    exact = -0.05 * 2 * np.pi * s.omega_n.to("Hz").magnitude
    exponents, stderr = point.exponents.magnitude, point.stderr.magnitude
    assert r.pairs == ((0, 1),) and exponents[0] == exponents[1]
    assert abs(exponents[0] - exact) <= 3 * stderr[0] + 1e-6 * abs(exact)
    # what the pair replaces: Gram-Schmidt's two columns, -1730.1 and -1719.8 /s, split by a bias of 5.2 /s that
    # their batch-means error of 1.0 /s does not see
    run = compiled.tangent_run(None, r.periods, compiled.prepare(compiled.parameter_vector()))
    per_second = exponents[0] / r.exponents[0]
    measured = run.log_stretch[:, r.discard:] / r.period * per_second
    assert np.max(np.abs(measured.mean(axis=1) - exact)) > 4 * batch_means_stderr(measured).max()


@pytest.mark.parametrize("theta", [0.3, 1.1, 2.9])
def test_the_finite_time_bias_estimate_covers_an_oscillating_one_over_k_bias(theta):
    """A running mean with bounded, oscillating partial sums (what Gram-Schmidt gives a column of a turning plane,
    or a pair's mean while its plane settles) is off by c(M)/M: the estimate must cover it, within a few times."""
    k = np.arange(1, 301)
    for phase in np.linspace(0, 2 * np.pi, 7):
        x = -0.05 + 0.8 * np.cos(theta * k + phase)
        true = abs(x.mean() + 0.05)
        bound = 0.8 / abs(np.sin(theta / 2)) / k.size  # |sum cos| <= 1/|sin(theta/2)|
        assert true <= finite_time_bias(x[:, None])[0] <= 4 * bound


# ------------------------------------------------------------------ item 5: what the exponents cannot decide
def test_a_decaying_transient_is_undetermined_and_the_periods_it_names_decide_it(duffing, capsys):
    zeta = 0.001  # the free oscillation decays at 0.001: inside the zero band 5/T of 300 periods (0.0034)
    r = lyapunov_spectrum(duffing, y0=START, zeta=zeta, **LINEAR)
    assert r.regime == "undetermined" and r.settling.state == "converging"
    assert r.settling.rate == pytest.approx(-zeta, rel=0.01)  # the transient's decay rate is -zeta omega_n
    needed = r.periods_to_decide
    assert needed == pytest.approx(10 / zeta / r.period, rel=0.02)
    longer = lyapunov_spectrum(duffing, options=Integration(periods=needed + 100, discard=100), y0=START,
                               zeta=zeta, **LINEAR)
    assert longer.regime == "periodic" and longer.exponents == pytest.approx([-zeta, -zeta], rel=1e-6)
    assert main(["lyap", "duffing", *sum((["--set", f"{k}={v}"] for k, v in {**LINEAR, "zeta": zeta}.items()), []),
                 "--y0", "x=1,v=0"]) == 0
    out = capsys.readouterr().out
    assert "regime: undetermined" in out and f"about {needed} measured periods would decide" in out


def test_a_torus_is_quasi_periodic(duffing):
    """x'' + x = F cos(omega t) with 1/omega irrational: the free and the forced oscillation, a 2-torus."""
    r = lyapunov_spectrum(duffing, y0=START, zeta=0.0, beta=0.0, F=0.3, omega=(np.sqrt(5) - 1) / 2)
    assert r.regime == "quasi-periodic" and r.settling.state == "stationary"
    assert np.abs(r.exponents).max() < 1e-6


@pytest.mark.parametrize("omega, paired", [(1.8, False), (1.9, True)])  # real and complex multipliers
def test_the_papers_period_one_orbit_is_periodic_with_its_floquet_exponents(one_stage, omega, paired):
    orbit = periodic_orbit(one_stage, omega=omega)
    floquet = np.sort(np.log(np.abs(orbit.multipliers)) / (2 * np.pi))[::-1]
    r = lyapunov_spectrum(one_stage, omega=omega)
    assert orbit.stable and r.regime == "periodic" and bool(r.pairs) == paired
    assert r.exponents == pytest.approx(floquet, abs=1e-6)


def test_a_chaotic_attractor_is_chaotic():
    r = lyapunov_spectrum(conftest.compiled("lorenz"))
    assert r.regime == "chaotic" and r.exponents[0] == pytest.approx(0.9056, abs=0.05)


# ------------------------------------------------------------------ item 4: divergence is not chaos
def stiffness_threshold() -> float:
    """k_a above which k = 1 + k_a w(tau) goes below 0: -1 / min w, from a dense grid and a bounded minimiser."""
    from scipy.optimize import minimize_scalar

    w = sp.lambdify(phi, (rectangular_mesh_stiffness("k_a") - 1).subs(sp.Symbol("k_a", real=True), 1), "numpy")
    grid = np.linspace(0, 2 * np.pi, 20001)
    i = int(np.argmin(w(grid)))
    best = minimize_scalar(w, bounds=(grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]), method="bounded",
                           options={"xatol": 1e-12})
    return -1.0 / best.fun


def test_a_run_that_blows_up_is_diverged_not_chaotic(one_stage):
    r = lyapunov_spectrum(one_stage, k_a=5.0)  # a verdict, not an exception
    assert r.regime == "diverged" and r.divergence.reason == PAST_BOUND and r.divergence.coordinate == "x"
    assert r.divergence.period == 8 and r.divergence.overflow == 240  # the bound (1e6 x 21.4) first, inf later
    assert json.loads(json.dumps(r.as_dict()))["divergence"]["period"] == 8


def test_the_command_line_says_how_it_diverged_and_where_the_stiffness_turns_negative(capsys):
    assert main(["lyap", "one_stage", "--set", "k_a=5"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1 and "the motion diverged" in lines[0]
    assert "period 8 of 400" in lines[0] and "chaotic" not in lines[0]
    said = float(lines[0].split("below 0 for k_a > ")[1].split(" ")[0])
    assert said == pytest.approx(stiffness_threshold(), rel=1e-5)  # 0.8186


def test_a_mesh_without_stiffness_drifts_and_that_is_divergence(capsys):
    assert main(["lyap", "one_stage", "--set", "k=0"]) == 2
    err = capsys.readouterr().err
    assert "the motion diverged" in err and "rising in every quarter" in err and "zero, nothing holds" in err
    r = lyapunov_spectrum(gearsym.load("one_stage", k="0"))
    assert r.regime == "diverged" and r.divergence.reason == GROWING


def test_a_free_disk_turning_away_is_not_a_divergence():
    """kS = 0 (the paper's curve '1' of Fig. 6): the twist x2 of a shaft without stiffness drifts while the gears
    vibrate; only a mesh's deflection growing without bound is a divergence."""
    r = lyapunov_spectrum(conftest.compiled("flexible_shaft"), kS=0.0)
    assert r.regime != "diverged" and r.amplitude["x2"] > 1e4


def test_a_step_too_large_for_rk4_is_an_error_not_a_verdict(one_stage):
    with pytest.raises(GearsymError, match=r"non-finite in period 1 .*RK4 is stable only below"):
        lyapunov_spectrum(one_stage, omega=1e-8)


def test_a_sweep_marks_diverged_points_and_goes_on_from_the_last_good_state(one_stage, tmp_path, capsys):
    result = run_sweep(one_stage, {"k_a": [0.2, 1.4, 3.0]}, out=tmp_path / "s.csv")
    assert result["regime"].tolist() == ["periodic", "diverged", "periodic"]
    first = lyapunov_spectrum(one_stage, k_a=0.2)
    after = lyapunov_spectrum(one_stage, y0=list(first.final_state.values()), k_a=3.0)
    assert result["lambda_1"][2] == after.exponents[0] and result["A_x"][2] == after.amplitude["x"]
    assert not json.loads((tmp_path / "s.json").read_text())["jumps"]  # no jump to or from a diverged point
    assert main(["sweep", "one_stage", "--param", "k_a=0.2,1.4,3.0", "--out", str(tmp_path / "s.csv"),
                 "--quiet"]) == 0  # (resumed: every point is there)
    assert "diverged at 1 point(s), k_a in [1.4, 1.4]" in capsys.readouterr().out
