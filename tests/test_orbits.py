"""Periodic orbits by shooting and their continuation (``gearsym.periodic``), against what else can be known
about them: a brute-force sweep, Liouville's formula, the linear oscillator's closed form, an independent
SciPy shooting of the Duffing oscillator's folds and its harmonic balance, and a sweep's hysteresis."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import root

import gearsym
from conftest import system
from gearsym import FirstOrderSystem, Integration, compile_model
from gearsym.cli import main
from gearsym import continue_orbits, periodic_orbit
from gearsym.periodic import FOLD, PERIOD_DOUBLING

ZETA = 0.05


def duffing(zeta: float = ZETA, beta: float = 0.2, force: float = 0.3) -> FirstOrderSystem:
    return FirstOrderSystem.from_equations(
        "duffing_test", ["x", "v"], ["v", "-2*zeta*v - x - beta*x**3 + F*cos(omega*t)"],
        {"zeta": zeta, "beta": beta, "F": force, "omega": 1.0}, time="t", period="2*pi/omega")


@pytest.fixture(scope="module")
def one_stage():
    return compile_model(system("one_stage"), Integration())


# ------------------------------------------------------------------ (a) a brute-force sweep's periodic points
def test_the_stable_branch_passes_through_a_periodic_sweeps_points_with_its_exponents(one_stage):
    sweep = gearsym.run_sweep(one_stage, ["omega=0.5:0.6:0.05"])
    assert set(sweep["regime"]) == {"periodic"}
    branch = continue_orbits(one_stage, "omega", 0.5, 0.6, switch_depth=0).branches[0]
    assert branch.stable.all() and branch.values[0] == 0.5 and branch.values[-1] == 0.6
    measured = (one_stage.integration.periods - one_stage.integration.discard) * 2 * np.pi
    for i, omega in enumerate(sweep["omega"]):
        ends = np.nonzero(branch.values == omega)[0]  # the branch's first and last points lie on the grid
        orbit = periodic_orbit(one_stage, y0=branch.states[np.argmin(np.abs(branch.values - omega))], omega=omega)
        assert np.allclose(orbit.state, [sweep[f"final_{s}"][i] for s in one_stage.state_names], rtol=1e-8, atol=1e-8)
        for a in [orbit.amplitude["x"], *branch.amplitude[ends, 0]]:
            assert a == pytest.approx(sweep["A_x"][i], rel=1e-6)
        lam = [sweep[f"lambda_{k}"][i] for k in (1, 2)]
        err = [sweep[f"stderr_{k}"][i] for k in (1, 2)]
        assert np.allclose(orbit.exponents.real, lam, atol=max(3 * max(err), 2 / measured, 1e-4), rtol=0)


# ------------------------------------------------------------------ (b) Liouville
def liouville(model: str, omega: float) -> float:
    """exp(int_0^T tr J dt) over one forcing period: tr J is constant for the gear models (checked)."""
    sys_ = system(model)
    trace = sys_.jacobian().trace()
    assert not trace.free_symbols & (set(sys_.states) | {sys_.time}), trace
    values = {**sys_.parameters, "omega": omega}
    return float(sp.exp(trace.xreplace({s: values[s.name] for s in trace.free_symbols}) * 2 * sp.pi))


@pytest.mark.parametrize("model, omega, tolerance", [("one_stage", 1.5, 1e-8), ("flexible_shaft", 1.8, 1e-8)])
def test_the_product_of_the_multipliers_is_liouvilles_exp_of_the_integrated_trace(model, omega, tolerance):
    """det M = exp(int tr J dt) at 200 steps per period, to RK4's own error in the determinant."""
    orbit = periodic_orbit(compile_model(system(model), Integration()), omega=omega)
    assert np.prod(orbit.multipliers).real == pytest.approx(liouville(model, omega), rel=tolerance)


def test_with_finer_steps_liouvilles_formula_holds_to_1e_10():
    """RK4's determinant over a period is exact to O(h^4): 3e-9 at 200 steps, below 1e-10 at 800."""
    coarse = periodic_orbit(compile_model(system("one_stage"), Integration()), omega=1.5)
    fine = periodic_orbit(compile_model(system("one_stage"), Integration(steps_per_period=800, backend="in-process")),
                          y0=coarse.state, omega=1.5)
    assert np.prod(fine.multipliers).real == pytest.approx(liouville("one_stage", 1.5), rel=1e-10)


# ------------------------------------------------------------------ (c) the linear oscillator
def test_a_linear_oscillators_branch_is_its_exact_frequency_response():
    linear = FirstOrderSystem.from_equations("linear", ["x", "v"], ["v", "-2*zeta*v - x + F*cos(omega*t)"],
                                             {"zeta": ZETA, "F": 1.0, "omega": 1.0}, time="t", period="2*pi/omega")
    result = continue_orbits(linear, "omega", 0.5, 2.0)
    branch = result.branches[0]
    assert len(result.branches) == 1 and not result.bifurcations and branch.stable.all()
    assert branch.values[0] == 0.5 and branch.values[-1] == 2.0 and len(branch) > 20
    w = branch.values
    X = 1.0 / (1 - w**2 + 2j * ZETA * w)  # x(t) = Re(X exp(i w t))
    error = np.abs(branch.states - np.stack([X.real, -w * X.imag], axis=1)).max(axis=1) / np.abs(X)
    assert error.max() < 1e-6, error.max()
    mu = np.exp((-ZETA + 1j * np.sqrt(1 - ZETA**2)) * 2 * np.pi / w)  # exp(J T), J of the free oscillator
    exact = np.sort_complex(np.stack([mu, mu.conj()], axis=1))
    assert np.all(np.abs(np.sort_complex(branch.multipliers) - exact) < 1e-5 * np.abs(exact))


# ------------------------------------------------------------------ (d) the Duffing oscillator's folds
def scipy_fold(zeta: float, beta: float, force: float, guess: np.ndarray) -> float:
    """The fold of the Duffing oscillator's frequency response, independently: the state and the
    variational equations by DOP853 over one period, and (x, v, omega) with P(y) = y and det(DP - I) = 0
    by MINPACK's hybrid method."""
    def period_map(y, w):
        def f(t, s):
            x, v = s[0], s[1]
            jacobian = np.array([[0.0, 1.0], [-1 - 3 * beta * x * x, -2 * zeta]])
            return np.concatenate([[v, -2 * zeta * v - x - beta * x**3 + force * np.cos(w * t)],
                                   (jacobian @ s[2:].reshape(2, 2)).ravel()])
        end = solve_ivp(f, (0, 2 * np.pi / w), np.concatenate([y, np.eye(2).ravel()]), method="DOP853",
                        rtol=1e-12, atol=1e-12).y[:, -1]
        return end[:2], end[2:].reshape(2, 2)

    def equations(u):
        landing, M = period_map(u[:2], u[2])
        return np.concatenate([landing - u[:2], [np.linalg.det(M - np.eye(2))]])

    solution = root(equations, guess, method="hybr", options={"xtol": 1e-12})
    assert solution.success, solution.message
    return float(solution.x[2])


def harmonic_balance_folds(zeta: float, beta: float, force: float) -> np.ndarray:
    """Where the one-harmonic balance A^2 [(1 - w^2 + 3/4 beta A^2)^2 + (2 zeta w)^2] = F^2 turns back in w."""
    A = np.linspace(0.05, 5, 400_001)
    k = 0.75 * beta * A**2
    b, c = 4 * zeta**2 - 2 * (1 + k), (1 + k) ** 2 - force**2 / A**2
    disc = b * b - 4 * c
    real = disc >= 0
    w = np.sqrt((-b[real] + np.sqrt(disc[real])) / 2)  # the upper sheet holds both folds
    turns = np.nonzero(np.diff(np.sign(np.diff(w))) != 0)[0] + 1
    return np.sort(w[turns])


@pytest.mark.slow
def test_the_duffing_folds_agree_with_scipy_shooting_and_weakly_nonlinear_with_harmonic_balance():
    folds = continue_orbits(duffing(), "omega", 0.6, 2.0).of_kind(FOLD)
    assert len(folds) == 2
    for f in folds:  # SciPy starts a little off the continuation's fold
        assert f.value == pytest.approx(scipy_fold(ZETA, 0.2, 0.3, np.append(f.state + 1e-2, f.value + 1e-2)),
                                        abs=1e-7)
    weak = dict(zeta=0.02, beta=0.02, force=0.1)
    result = continue_orbits(duffing(**weak), "omega", 0.8, 1.3)
    folds = sorted(result.of_kind(FOLD), key=lambda f: f.value)
    assert np.allclose([f.value for f in folds], harmonic_balance_folds(**weak), atol=3e-4, rtol=0)
    branch = result.branches[0]
    upper = folds[-1]  # the peak, on the backbone w^2 = 1 + 3/4 beta A^2
    A = branch.amplitude[np.argmin(np.abs(branch.values - upper.value)), 0]
    assert upper.value == pytest.approx(np.sqrt(1 + 0.75 * weak["beta"] * A**2), rel=1e-2)


# ------------------------------------------------------------------ (e) a sweep's hysteresis
def test_folds_bracket_the_hysteresis_of_a_sweep_up_and_down_within_a_grid_step(tmp_path, capsys):
    step = 0.01
    assert main(["sweep", "one_stage", "--param", f"omega=0.8:0.95:{step}", "--direction", "both",
                 "--out", str(tmp_path / "s.csv"), "--quiet", "--jobs", "1"]) == 0
    hysteresis = json.loads((tmp_path / "s.json").read_text())["hysteresis"]
    assert main(["orbits", "one_stage", "--param", "omega=0.8:0.95", "--switch-depth", "0",
                 "--out", str(tmp_path / "o.csv")]) == 0
    folds = sorted(b["omega"] for b in json.loads((tmp_path / "o.json").read_text())["bifurcations"]
                   if b["type"] == FOLD)
    capsys.readouterr()
    assert len(hysteresis) == 1 and len(folds) == 2
    low, high = hysteresis[0]["from"], hysteresis[0]["to"]
    assert low - step < folds[0] <= low and high <= folds[1] < high + step, (hysteresis, folds)


# ------------------------------------------------------------------ the command
@pytest.mark.slow
def test_gearsym_orbits_writes_a_plain_odes_branches_bifurcations_and_curve(tmp_path, capsys):
    out = tmp_path / "frc.csv"
    assert main(["orbits", "duffing", "--param", "omega=0.8:1.6", "--out", str(out), "--plot",
                 str(tmp_path / "frc.png")]) == 0
    printed = capsys.readouterr().out
    record = json.loads((tmp_path / "frc.json").read_text())
    assert [b["type"] for b in record["bifurcations"]] == [FOLD, FOLD] and printed.count("fold at omega=") == 2
    assert record["model"] == "duffing" and record["settings"]["locate_crossings"] is True
    header, *rows = out.read_text().splitlines()
    columns = ["branch", "period_multiple", "omega", "A_x", "A_v", "mu_abs_1", "mu_abs_2", "stable"]
    assert header.split(",")[:8] == columns  # a plain ODE observes every state
    assert len(rows) == record["branches"][0]["points"] and {r.split(",")[7] for r in rows} == {"true", "false"}
    located = [float(r.split(",")[2]) for r in rows if r.endswith(FOLD)]  # the CSV's numbers read back to the bit
    assert located == [b["omega"] for b in record["bifurcations"]]
    assert (tmp_path / "frc.png").stat().st_size > 10_000
    assert main(["orbits", "duffing", "--set", "omega=1.0", "--out", str(tmp_path / "one.json")]) == 0
    assert "Floquet multipliers" in capsys.readouterr().out
    assert json.loads((tmp_path / "one.json").read_text())["stable"] is True


@pytest.mark.parametrize("argv, message", [
    (["--param", "omega=0.5"], "expected NAME=START:STOP"),
    (["--param", "omega=1:1"], "START and STOP must differ"),
    (["--plot", "f.png"], "--plot draws the branches of a continuation"),
    (["--param", "omega=0.5:2", "--segments", "3"], "3 shooting segments per period do not divide"),
    (["--param", "omega=0.5:2", "--period-multiple", "0"], "--period-multiple must be at least 1"),
    (["--param", "omegaa=0.5:2"], "unknown parameter 'omegaa'"),
    (["--param", "speed=1000rpm:3000rpm"], "has a unit, but the model has no physical values"),
])
def test_bad_orbit_options_are_one_line_errors(argv, message, capsys):
    assert main(["orbits", "duffing", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err


def test_multiple_shooting_finds_the_single_shooting_orbit_and_a_period_two_orbit(one_stage):
    single = periodic_orbit(one_stage, omega=0.6)
    multiple = periodic_orbit(one_stage, y0=single.state + 0.05, segments=4, omega=0.6)
    assert np.allclose(multiple.state, single.state, rtol=0, atol=1e-9)
    assert np.allclose(np.sort_complex(multiple.multipliers), np.sort_complex(single.multipliers), rtol=1e-9)
    doubled = periodic_orbit(one_stage, period_multiple=2, segments=2, omega=1.65)  # the stable period-2 orbit
    assert doubled.stable and doubled.period == pytest.approx(4 * np.pi)
    inputs = one_stage.prepare(one_stage.parameter_vector({"omega": 1.65}))
    once, twice = one_stage.orbit_run(doubled.state, 2, inputs)[0].T
    assert np.allclose(twice, doubled.state, atol=1e-8) and not np.allclose(once, doubled.state, atol=1e-3)


def test_an_interrupted_continuation_keeps_and_writes_what_it_traced(tmp_path, capsys, monkeypatch):
    from gearsym.periodic import continuation

    step, calls = continuation.Tracer.step, []

    def interrupted_later(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 12:
            raise KeyboardInterrupt
        return step(self, *args, **kwargs)

    monkeypatch.setattr(continuation.Tracer, "step", interrupted_later)
    out = tmp_path / "frc.csv"
    assert main(["orbits", "duffing", "--param", "omega=0.8:1.6", "--out", str(out)]) == 130
    assert "interrupted: kept 1 branch(es), 12 points" in capsys.readouterr().err
    record = json.loads((tmp_path / "frc.json").read_text())
    assert record["settings"]["interrupted"] is True and record["branches"][0]["end"] == "interrupted"
    assert len(out.read_text().splitlines()) == 1 + 12


@pytest.mark.slow
def test_a_physical_models_orbits_continue_over_a_speed_range_in_rpm(tmp_path, capsys):
    """speed=1000rpm:3000rpm is the omega range it moves: the mesh frequency is proportional to the speed."""
    from conftest import reduced
    from gearsym import scaling

    at_3000 = scaling(reduced("spur_pair"), speed="3000 rpm").values["omega"]
    assert main(["orbits", "spur_pair", "--param", "speed=1000rpm:3000rpm", "--switch-depth", "0",
                 "--out", str(tmp_path / "frc.csv")]) == 0
    record = json.loads((tmp_path / "frc.json").read_text())
    assert record["parameter"] == "omega" and record["stop"] == pytest.approx(at_3000, rel=1e-12)
    assert record["start"] == pytest.approx(at_3000 / 3, rel=1e-12)
    assert record["branches"][0]["to"] == pytest.approx(at_3000, rel=1e-12)
    assert "speed 1000 -> 3000 rpm is omega" in capsys.readouterr().out


def test_a_linear_regimes_period_doubling_has_a_vertical_period_two_branch_and_no_folds_on_it():
    """A linear system with a time-varying stiffness (Mathieu) has, where a multiplier is -1, a whole line of
    period-2 orbits at that one frequency: its branch is vertical, and rounding in its tangent is no fold."""
    mathieu = FirstOrderSystem.from_equations(
        "mathieu", ["x", "v"], ["v", "-2*zeta*v - (1 + eps*cos(omega*t))*x + F*cos(omega*t)"],
        {"zeta": 0.02, "eps": 0.3, "F": 0.1, "omega": 1.0}, time="t", period="2*pi/omega")
    result = continue_orbits(mathieu, "omega", 1.5, 2.0, max_points=60)
    (pd,), doubled = result.of_kind(PERIOD_DOUBLING), result.branches[1]
    assert doubled.period_multiple == 2 and len(doubled) == 60
    assert np.ptp(doubled.values) < 1e-9 and doubled.values[0] == pytest.approx(pd.value, abs=1e-9)
    assert np.ptp(doubled.amplitude[:, 0]) > doubled.amplitude[0, 0]  # it goes up the line
    assert not result.of_kind(FOLD), [(f.value, f.branch) for f in result.of_kind(FOLD)]


# ------------------------------------------------------------------ (g) into the interval from either end
@pytest.mark.slow
def test_the_continuation_goes_through_the_interval_from_either_end_and_finds_the_same_curve():
    """k = 1 + 0.2 cos(tau): from omega = 0.1 the branch went back out through 0.1 after 8 points (the corrector
    had converged behind the start), from 2.0 it came back to 2.0. Each way, the first branch must reach the
    other end, and the two traversals of the one curve must locate the same folds."""
    model = compile_model(system("one_stage", k="1 + 0.2*cos(tau)"), Integration())  # (as test_engine_invariants)
    ends = {}
    for start, stop in ((0.1, 2.0), (2.0, 0.1)):
        c = continue_orbits(model, "omega", start, stop, switch_depth=0)
        first = c.branches[0]
        assert first.values[0] == start and first.values[-1] == stop and first.end == f"reached omega={stop:g}"
        assert min(first.values) == 0.1 and max(first.values) == 2.0
        ends[start] = sorted(b.value for b in c.of_kind(FOLD))
    assert len(ends[0.1]) == 8 and ends[0.1] == pytest.approx(ends[2.0], abs=1e-7)


# ------------------------------------------------------------------ (h) counts that rounding cannot change
def test_folds_narrower_than_the_continuations_resolution_are_dropped_in_pairs_or_at_an_end():
    """The branch's turning points simplified by persistence: a wiggle (two folds closer than the width in the
    parameter) or a fold that close to an end of the branch is no fold; wider ones all stay."""
    from types import SimpleNamespace

    from gearsym.periodic.continuation import wiggles

    def branch(*values_and_folds):
        return [SimpleNamespace(value=v, event=(FOLD, "") if fold else None) for v, fold in values_and_folds]

    points = branch((1.0, False), (1.0000002, True), (0.9999996, True), (1.3, True), (1.1, True), (1.5, True),
                    (1.4999999, False))
    assert sorted(p.value for p in wiggles(points, 1e-5)) == [0.9999996, 1.0000002, 1.5]
    assert wiggles(points, 1e-8) == []
    assert [p.value for p in wiggles(branch((0.5, False), (0.4999, True), (0.7, False)), 1e-3)] == [0.4999]


@pytest.mark.slow
def test_the_count_of_each_bifurcation_is_the_same_when_the_linear_algebra_rounds_otherwise(monkeypatch):
    """On an AMD EPYC (another BLAS kernel) the D = 2 branches of the reproduction had 16 folds where the committed
    run had 17: the fold test (the tangent's parameter component) vanishes at a pitchfork's tip too, where a
    period-2 branch rejoins its parent, and whether that tip was counted as a fold depended on where the rejoin was
    located (last digits). The tip is never a fold, and folds narrower than the continuation's resolution are
    not counted: the counts do not change when every linear solve is perturbed by 1e-12 (its located values
    move by no more than that shows), and a period-2 branch starts on the same half of its pitchfork when
    LAPACK returns the eigenvector of the multiplier -1 with the other sign."""
    from gearsym.periodic.continuation import FOLD_WIDTH

    model = compile_model(system("one_stage_resonant"), Integration())

    def run():
        c = continue_orbits(model, "omega", 0.1, 0.25, k_a=0.05, switch_depth=1)
        return c, {kind: [b.value for b in c.of_kind(kind)] for kind in (FOLD, PERIOD_DOUBLING)}

    plain, found = run()
    assert [b.period_multiple for b in plain.branches] == [1, 2, 2] and all(
        b.end.startswith("rejoined") for b in plain.branches[1:])
    for b in plain.branches[1:]:  # no fold at either tip of a period-2 branch
        tips = (b.values[0], b.values[-1])
        assert not [f for f in plain.of_kind(FOLD) if f.branch == b.index
                    and min(abs(f.value - t) for t in tips) < FOLD_WIDTH * 0.15], b.index
    solve, eig, rng = np.linalg.solve, np.linalg.eig, np.random.default_rng(7)
    monkeypatch.setattr(np.linalg, "solve", lambda a, b: solve(a, b) * (1 + 1e-12 * rng.standard_normal(np.shape(b))))
    monkeypatch.setattr(np.linalg, "eig", lambda a: (eig(a)[0], -eig(a)[1]))
    perturbed, again = run()
    for kind in found:
        assert len(again[kind]) == len(found[kind]), kind
        assert again[kind] == pytest.approx(found[kind], abs=1e-6), kind
    for a, b in zip(plain.branches[1:], perturbed.branches[1:]):
        assert b.states[0] == pytest.approx(a.states[0], abs=1e-6)


def test_a_continuation_says_its_progress_as_it_goes_and_quiet_silences_it(monkeypatch, capsys):
    """Long work shows progress: each branch's points and its share of the range, a line every few seconds (here
    every point), to the caller's function in Python, on stderr from the command line unless --quiet."""
    import gearsym.periodic.continuation as continuation

    monkeypatch.setattr(continuation, "PROGRESS_SECONDS", 0.0)
    lines = []
    result = continue_orbits(compile_model(system("one_stage")), "omega", 1.6, 2.0, max_points=30,
                             execution=gearsym.Execution(progress=lines.append))
    said = [re.fullmatch(r"orbits: period-(\d+) branch: (\d+) points \(at most 30\), (-?\d+)% of the range from "
                         r"its start", line) for line in lines]
    assert said and all(said) and said[0].group(1) == "1", lines
    first = [(int(m.group(2)), int(m.group(3))) for m in said if m.group(1) == "1"]
    assert first == sorted(first) and 0 < first[-1][1] <= 100 and len(result.branches[0]) >= first[-1][0]
    assert continue_orbits(compile_model(system("one_stage")), "omega", 1.6, 2.0, max_points=30).branches
    argv = ["orbits", "one_stage", "--param", "omega=1.6:2.0", "--max-points", "30"]
    assert main(argv) == 0 and "orbits: period-1 branch: " in capsys.readouterr().err
    assert main([*argv, "--quiet"]) == 0 and "orbits: " not in capsys.readouterr().err
