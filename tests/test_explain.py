"""The data loop: a missing effect is named and added, and the held-out error falls; data without one get
none; what no library effect describes is reported, and terms beyond the library are proposed.

Data come from two simulators: gearsym's own (``simulate_measurements``, the library's effects one by one)
and an independent one typed in ``tests/rig.py`` (SciPy DOP853 of the paper's one-stage equations, sampled
as a rig records: a rate that is no whole multiple of the forcing, from an arbitrary phase, with noise).
"""
from __future__ import annotations

import json
import math
from dataclasses import replace
import re
import shlex

import numpy as np
import pytest
import sympy as sp

import conftest
import rig
from same_numbers import csv_differences, differences, measured_differences, wrong_models_held
from gearsym import EFFECTS, Integration, explain, load_measurements, simulate_measurements
from gearsym.model.backlash import g
from gearsym.cli import main
from gearsym.errors import GearsymError, ModelError
import gearsym.fit.levenberg_marquardt as marquardt
from gearsym.fit import Effect, augment, effect_terms, fit_windows, term_effect
from gearsym.fit.canonical import amplitude_phase, canonical, wrap_phase
from gearsym.fit.effects import Change
from gearsym.fit.problem import Problem
from gearsym.fit.selection import segments_of
from gearsym.checks import json_safe
from gearsym.figures.fit_report import residual_figure
from gearsym.fit.report import report_page
from gearsym.files.paths import REPO_ROOT
from gearsym.model.symbols import parameter_symbol

RECORDS = [{"omega": 1.2}, {"omega": 1.6}]
#: the true strengths: large enough to stand out of 1 % noise
CASES = {
    "coulomb_friction": ({"mu_c": 0.6}, RECORDS),
    # (at 0.4/0.2 the as-declared fit can reach a local optimum within 4.9x of the noise floor)
    "mesh_stiffness_harmonic_2": ({"k_c2": 0.5, "k_s2": 0.25}, RECORDS),
    "transmission_error_1": ({"e_c1": 0.5, "e_s1": 0.3}, RECORDS),
    "coast_side_stiffness": ({"c_coast": 1.0}, [{"omega": 0.8}, {"omega": 0.9}]),  # big swings reach x <= -eta
}
#: each record: 16 periods sampled after 100 of transient (in-process: no C compiled for each augmented model)
RECORD = Integration(periods=116, discard=100, backend="in-process")
#: the coast flank switches at Min(0, g(x, eta)): simulated with the paper's plain RK4 like the other flank
PLAIN_RECORD = Integration.paper(periods=116, discard=100, backend="in-process")


@pytest.fixture(scope="module")
def one_stage():
    return conftest.system("one_stage")


def measure(system, tmp_path, name, records=RECORDS, noise=0.01, options=RECORD):
    path = tmp_path / f"{name}.csv"
    simulate_measurements(system, options=options, samples_per_period=40, noise=noise, seed=1, records=records,
                          out=path)
    return load_measurements([path], conftest.system("one_stage"))


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.slow
def test_a_missing_effect_is_named_and_the_error_falls_fivefold(one_stage, tmp_path, name):
    values, records = CASES[name]
    data = measure(augment(one_stage, [name], values=values), tmp_path, name, records,
                   options=PLAIN_RECORD if name == "coast_side_stiffness" else RECORD)
    ex = explain(one_stage, data, ["zeta", "B1"])
    assert ex.effects == [name] and ex.verdict == "explained"
    assert ex.final.error <= ex.base.error / 5, (ex.base.error, ex.final.error)
    for p, true in values.items():  # and the effect's strength comes back
        assert ex.final.fit.estimates[p] == pytest.approx(true, rel=0.1, abs=0.02)


# --------------------------------------------------------------------------- rig-shaped data
def stiffness(tau):
    return 1 + 0.2 * rig.variation(tau)


#: what the declared model lacks, typed here: (the extra acceleration, its parameters as the library names them)
TRUTHS = {
    "cubic": lambda t, x, v, w: -stiffness(t) * 0.02 * rig.backlash(x, 10.0) ** 3 / w**2,
    "stiffness_3": lambda t, x, v, w: -(0.2 * math.cos(3 * t) + 0.08 * math.sin(3 * t)) * rig.backlash(x, 10.0) / w**2,
    "torque_2": lambda t, x, v, w: (1.2 * math.cos(2 * t) + 0.5 * math.sin(2 * t)) / w**2,
    "quadratic_damping": lambda t, x, v, w: -0.3 * v * abs(v),
    "damping_ripple": lambda t, x, v, w: -0.15 * v * math.cos(2 * t),  # in no library: a damping varying with mesh
    # a profile error e = 0.5 cos(tau) + 0.3 sin(tau): the mesh force k(tau) g(x - e) instead of k(tau) g(x)
    "transmission_error": lambda t, x, v, w: -stiffness(t) * (rig.backlash(x - 0.5 * math.cos(t) - 0.3 * math.sin(t),
                                                                            10.0) - rig.backlash(x, 10.0)) / w**2,
    # issue 41's accelerometer case: a profile error of amplitude 0.25, e = 0.25 cos(tau)
    "small_transmission_error": lambda t, x, v, w: -stiffness(t) * (rig.backlash(x - 0.25 * math.cos(t), 10.0)
                                                                    - rig.backlash(x, 10.0)) / w**2,
    "clean": None,
    "clean_default": None,  # (the rig's own values: the accelerometer's clean floor)
}
RIG_VALUES = {"clean": {"Theta": 2.0, "B1": 3.5}}


@pytest.fixture(scope="module")
def rig_runs():
    cache = {}

    def runs(case, omegas=(1.2, 1.6)):
        if (case, omegas) not in cache:
            cache[case, omegas] = [(w, rig.record(w, extra=TRUTHS[case], **RIG_VALUES.get(case, {}))) for w in omegas]
        return cache[case, omegas]

    return runs


def rig_data(rig_runs, tmp_path, case, channels=("x",), bias=None, omegas=(1.2, 1.6)):
    path = rig.write(tmp_path / f"rig_{case}_{'_'.join(channels)}.csv", rig_runs(case, omegas), channels, bias=bias)
    return load_measurements([path], conftest.system("one_stage"))


@pytest.mark.slow
def test_an_accelerometer_record_with_an_offset_is_explained_as_well_as_a_displacement_record(
        one_stage, rig_runs, tmp_path):
    """At omega = 1.0 and 1.8, where the motion with the cubic stiffness is periodic (at 1.2 and 1.6 it is
    chaotic, and a period-ahead prediction from an accelerometer's start estimate is the first to suffer)."""
    candidates, omegas = ["cubic_stiffness", "coulomb_friction", "hertzian_contact"], (1.0, 1.8)
    shown = explain(one_stage, rig_data(rig_runs, tmp_path, "cubic", omegas=omegas), ["zeta", "B1"],
                    candidates=candidates)
    felt = explain(one_stage, rig_data(rig_runs, tmp_path, "cubic", ("x_ddot",), {"x_ddot": 0.3}, omegas),
                   ["zeta", "B1"], candidates=candidates, bias=["x_ddot"])
    for ex in (shown, felt):
        assert ex.effects == ["cubic_stiffness"] and ex.verdict == "explained"
        assert ex.final.fit.estimates["k3"] == pytest.approx(0.02, rel=0.05)
        assert ex.final.fit.estimates["zeta"] == pytest.approx(0.08, rel=0.05)
    assert felt.final.error <= 1.5 * shown.final.error, (felt.final.error, shown.final.error)
    assert felt.final.fit.bias["x_ddot"] == pytest.approx(0.3, abs=3 * felt.final.fit.bias_stderr["x_ddot"] + 0.01)


@pytest.mark.slow
def test_an_accelerometers_offset_is_fitted_by_default_and_the_report_says_so(one_stage, rig_runs, tmp_path):
    """Issue 25: with a 5 % offset in an accelerometer's channel every candidate made the held-out error worse and
    the verdict was 'unexplained', unless --bias was given. Bounded motion has zero mean acceleration, so the
    offset of an acceleration channel is fitted by default."""
    runs = rig_runs("transmission_error", (1.0, 1.8))
    offset = 0.05 * float(np.std(np.concatenate([run["x_ddot"] for _, run in runs])))  # 5 % of the spread
    data = load_measurements([rig.write(tmp_path / "acc.csv", runs, ("x_ddot",), bias={"x_ddot": offset})],
                             conftest.system("one_stage"))
    ex = explain(one_stage, data, ["zeta", "B1"],
                 candidates=["transmission_error", "torque_harmonic", "cubic_stiffness", "coulomb_friction"])
    assert ex.bias_by_default == ex.bias == ("x_ddot",)
    assert ex.verdict == "explained" and ex.effects == ["transmission_error_1"]
    assert ex.final.error <= ex.base.error / 5, (ex.base.error, ex.final.error)
    assert ex.final.fit.estimates["e_c1"] == pytest.approx(0.5, rel=0.05)
    assert ex.final.fit.estimates["e_s1"] == pytest.approx(0.3, rel=0.05)
    assert ex.final.fit.bias["x_ddot"] == pytest.approx(offset, abs=3 * ex.final.fit.bias_stderr["x_ddot"])
    data = json_safe(ex.as_dict())
    assert data["bias_by_default"] == ["x_ddot"]
    page = report_page(ex, one_stage, augment(one_stage, ex.effects), data, ())
    assert ("and the offsets of x_ddot, fitted by default: an acceleration's steady mean is zero for bounded "
            "motion, so a constant offset is the sensor's bias") in page


@pytest.mark.slow
def test_an_accelerometer_with_an_offset_measures_a_small_transmission_error_to_its_amplitude(one_stage, rig_runs,
                                                                                             tmp_path):
    """Issue 41: acceleration-only records (omega 1.2 and 1.6) with a 5 % offset and a profile error of amplitude
    0.25 were reported to stop at a held-out error of 0.037 with amplitude 0.22. Here the profile error is named with
    its amplitude within 10 % (0.250), the offset is the one written, and the held-out error falls to the clean
    records' (the same accelerometer, no profile error) within 1.5x. The offset is estimated with B0 held at its
    value, as explain does: with B0 fitted as well, the two trade a constant acceleration (1/omega^2 against 1) and
    both come out off by several per cent."""
    runs = rig_runs("small_transmission_error")
    offset = 0.05 * float(np.std(np.concatenate([run["x_ddot"] for _, run in runs])))
    data = load_measurements([rig.write(tmp_path / "acc.csv", runs, ("x_ddot",), bias={"x_ddot": offset})],
                             conftest.system("one_stage"))
    clean = load_measurements([rig.write(tmp_path / "clean.csv", rig_runs("clean_default"), ("x_ddot",),
                                         bias={"x_ddot": offset})], conftest.system("one_stage"))
    candidates = ["transmission_error", "hertzian_contact", "coast_side_stiffness"]
    ex = explain(one_stage, data, ["zeta", "B1"], candidates=candidates, propose=False)
    floor = explain(one_stage, clean, ["zeta", "B1"], candidates=[], propose=False).base.error
    assert ex.verdict == "explained" and ex.effects == ["transmission_error_1"]
    (te,) = ex.harmonics().values()
    assert te["amplitude"] == pytest.approx(0.25, rel=0.1) and abs(te["phase"]) < 0.1
    assert ex.final.error <= 1.5 * floor, (ex.final.error, floor)
    assert ex.final.fit.bias["x_ddot"] == pytest.approx(offset, abs=3 * ex.final.fit.bias_stderr["x_ddot"])


def test_only_channels_of_accelerations_get_an_offset_by_default(tmp_path):
    from gearsym.fit.selection import acceleration_channels

    flexible = conftest.system("flexible_shaft")
    tau = np.linspace(0, 30 * np.pi, 301)
    columns = {"x1": np.sin(tau), "x1_ddot": -np.sin(tau), "v2": np.cos(tau), "x2_dot": np.cos(tau),
               "acc": -np.sin(tau), "mix": np.sin(tau)}
    path = tmp_path / "channels.csv"
    path.write_text("\n".join([",".join(["tau", *columns])] + [
        ",".join([repr(float(t)), *(repr(float(c[i])) for c in columns.values())]) for i, t in enumerate(tau)]) + "\n")
    data = load_measurements([path], flexible, channels={"acc": "r1*x1_ddot + 0.5*x2_ddot", "mix": "x1_ddot + x2"})
    assert acceleration_channels(data, flexible) == ("x1_ddot", "acc")


@pytest.mark.slow
def test_an_additive_third_stiffness_harmonic_is_named_with_its_order_amplitude_and_phase(one_stage, rig_runs, tmp_path):
    ex = explain(one_stage, rig_data(rig_runs, tmp_path, "stiffness_3"), ["zeta", "B1"])
    assert ex.effects == ["mesh_stiffness_harmonic_3"]
    h = ex.as_dict()["harmonics"]["mesh_stiffness_harmonic_3"]
    amplitude, phase = math.hypot(0.2, 0.08), math.atan2(-0.08, 0.2)  # 0.2 cos 3t + 0.08 sin 3t = A cos(3t + phase)
    assert h["order"] == 3 and h["amplitude"] == pytest.approx(amplitude, rel=0.1)
    assert h["phase"] == pytest.approx(phase, abs=0.15)


def test_a_second_torque_harmonic_is_named_and_the_held_out_error_falls_fivefold(one_stage, rig_runs, tmp_path):
    ex = explain(one_stage, rig_data(rig_runs, tmp_path, "torque_2"), ["zeta", "B1"])
    assert ex.effects == ["torque_harmonic_2"] and ex.verdict == "explained"
    assert ex.final.error <= ex.base.error / 5, (ex.base.error, ex.final.error)
    h = ex.harmonics()["torque_harmonic_2"]
    assert h["amplitude"] == pytest.approx(math.hypot(1.2, 0.5), rel=0.1)
    assert h["phase"] == pytest.approx(math.atan2(-0.5, 1.2), abs=0.1)


@pytest.mark.slow
def test_quadratic_damping_is_named_nonlinear_damping_never_negative_friction(one_stage, rig_runs, tmp_path):
    ex = explain(one_stage, rig_data(rig_runs, tmp_path, "quadratic_damping"), ["zeta", "B1"])
    assert ex.effects == ["nonlinear_damping"] and ex.verdict == "explained"
    assert ex.final.fit.estimates["c_nl"] == pytest.approx(0.3, rel=0.1)
    friction = [c for c in ex.tried if "coulomb_friction" in c.effects]
    assert all(c.fit.estimates["mu_c"] >= 0 for c in friction)  # tried or not, never a force with the motion
    why = ex.info["screened"][0]["why_not"].get("coulomb_friction", "")
    assert friction or why.startswith("it would need mu_c < 0, but")  # refused for its sign, and said so
    correlated = {(a, b) for a, b, _ in ex.final.fit.correlations}
    assert ("zeta", "c_nl") in correlated  # linear and quadratic damping share the work: said, not hidden


def test_clean_rig_data_get_no_effect_and_canonical_parameters(rig_runs, tmp_path):
    """Forcing phase 2 unknown, the fit started from B1 < 0 and a phase four turns away: the same physics,
    reported as B1 > 0 and Theta in (-pi, pi]."""
    data = rig_data(rig_runs, tmp_path, "clean")
    assert not float(data[0].samples_per_period).is_integer()
    ex = explain(conftest.system("one_stage", B1=-4.0, Theta=-11.0), data, ["zeta", "B1", "Theta"])
    assert ex.effects == [] and ex.verdict == "nothing missing"
    p = ex.final.fit.estimates
    assert p["B1"] == pytest.approx(3.5, rel=0.02) and p["Theta"] == pytest.approx(2.0, abs=0.02)
    assert ex.final.error < 0.02  # the noise floor (1 % noise)


@pytest.mark.slow
@pytest.mark.usefixtures("report_without_its_two_plots")  # (it never looks at the residual and prediction plots)
def test_a_term_beyond_the_library_is_proposed_and_adding_it_by_hand_closes_the_loop(rig_runs, tmp_path, capsys):
    path = rig.write(tmp_path / "ripple.csv", rig_runs("damping_ripple"))
    out = tmp_path / "first"
    assert main(["explain", str(path), "--model", "one_stage", "--fit", "zeta,B1", "--out", str(out), "--quiet"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["verdict"] == "unexplained" and report["effects"] == []
    best = report["proposed"][0]
    assert best["term"] == "v*cos(2*tau)" and best["coefficient"] == pytest.approx(-0.15, rel=0.05)
    assert best["held_out_error"] <= report["error_before"] / 5
    assert "v*cos(2*tau)" in (out / "report.md").read_text()
    closed = tmp_path / "closed"
    assert main(["explain", str(path), "--model", "one_stage", "--fit", "zeta,B1", "--out", str(closed), "--quiet",
                 "--effects", "coulomb_friction", "--add-term", best["term"]]) == 0
    report = json.loads((closed / "report.json").read_text())
    assert report["effects"] == ["term_1"] and report["verdict"] == "explained"
    assert report["parameters"]["c_term1"] == pytest.approx(-0.15, rel=0.05)
    assert report["error_after"] <= report["error_before"] / 5


# --------------------------------------------------------------------------- the pieces
def test_an_effect_on_a_coupling_acts_in_every_row_its_force_enters():
    flexible = conftest.system("flexible_shaft")
    mesh, shaft = flexible.coupling("x1"), flexible.coupling("x2")
    omega, k3, c_sh = parameter_symbol("omega"), parameter_symbol("k3"), parameter_symbol("c_sh")
    terms = effect_terms(flexible, ["cubic_stiffness", "shaft_damping", "torque_harmonic_2"])
    law = mesh.stiffness * k3 * g(sp.Symbol("x1", real=True), mesh.backlash) ** 3 / omega**2
    for row, factor in mesh.rows:  # v1 with 1, v2 with beta_3
        assert sp.cancel(terms["cubic_stiffness"][flexible.state_names[row]] + factor * law) == 0
    v2 = sp.Symbol("v2", real=True)
    for row, factor in shaft.rows:
        assert sp.cancel(terms["shaft_damping"][flexible.state_names[row]] + factor * c_sh * v2 / omega) == 0
    assert set(terms["torque_harmonic_2"]) == {"v1"}  # the torque enters where the mean torque B0 does


def test_amplitude_phase_pairs_are_reported_in_canonical_form(one_stage):
    # B1 < 0 with Theta near -13.8 is B1 > 0 with Theta wrapped by 4 pi and shifted by pi
    out = canonical(one_stage, {"zeta": 0.08, "B1": -3.5, "Theta": -13.8})
    assert out["B1"] == 3.5 and -math.pi < out["Theta"] <= math.pi
    assert out["Theta"] == pytest.approx(-13.8 + math.pi + 4 * math.pi)
    assert canonical(one_stage, {"zeta": -0.1})["zeta"] == -0.1  # not a pair: left as it is
    assert wrap_phase(math.pi) == math.pi and wrap_phase(-math.pi) == math.pi
    A, theta, *_ = amplitude_phase(-0.3, 0.4)  # -0.3 cos x + 0.4 sin x = A cos(x + theta)
    x = 0.77
    assert A == pytest.approx(0.5) and A * math.cos(x + theta) == pytest.approx(-0.3 * math.cos(x) + 0.4 * math.sin(x))


def test_a_parameter_the_data_cannot_determine_is_not_identifiable_never_zero_plus_minus_zero(one_stage, rig_runs,
                                                                                              tmp_path):
    path = rig.write(tmp_path / "small.csv", [(1.6, rig.record(1.6, B1=1.0, periods=6.3))])
    gentle = conftest.system("one_stage", B1=1.0)  # small swings: always in contact, the coast flank never reached
    model = augment(gentle, ["coast_side_stiffness"])
    segments, _ = segments_of(model, load_measurements([path], gentle))
    result = fit_windows(model, segments, ["zeta", "B1", "c_coast"])
    assert result.identifiable == {"zeta": True, "B1": True, "c_coast": False}
    assert result.stderr["c_coast"] is None and result.stderr["zeta"] > 0


@pytest.fixture(scope="module")
def clean_explained(rig_runs, tmp_path_factory):
    """Clean rig data explained by the declared model, one candidate tried: (the declared model, the explanation)."""
    declared = conftest.system("one_stage", **RIG_VALUES["clean"])
    data = rig_data(rig_runs, tmp_path_factory.mktemp("clean"), "clean")
    return declared, explain(declared, data, ["zeta"], candidates=["cubic_stiffness"])


@pytest.mark.slow
def test_the_as_declared_residual_figure_is_drawn_when_no_effect_is_added(clean_explained):
    declared, ex = clean_explained
    assert ex.effects == []
    fig = residual_figure(ex, declared)
    assert all(ax.lines and len(ax.lines[0].get_xdata()) > 100 for ax in fig.axes[:3])
    assert fig.axes[0].get_title() and len(fig.axes[3].patches) == len(ex.spectrum.orders)


@pytest.mark.slow
def test_a_partly_explained_report_leads_with_its_verdict_and_never_says_zero_plus_minus_zero(clean_explained):
    """A cubic stiffness made final, its k3 undetermined (a fit leaves its estimate at 0 with no error) and the
    residual still structured."""
    declared, ex = clean_explained
    base = ex.base.fit
    fit = replace(base, estimates={**base.estimates, "k3": 0.0}, stderr={**base.stderr, "k3": None},
                  identifiable={**base.identifiable, "k3": False})
    partly = replace(ex, final=replace(ex.base, effects=("cubic_stiffness",), fit=fit), unexplained=True)
    data = json_safe(partly.as_dict())
    page = report_page(partly, declared, augment(declared, ["cubic_stiffness"]), data, ())
    assert partly.verdict == data["verdict"] == "partly explained"
    assert page.index("## Verdict: partly explained") < page.index("## Candidates") < page.index("## Estimates")
    assert data["not_identifiable"] == ["k3"] and "Not identifiable from these data: k3." in page
    assert re.search(r"^\| k3 \|  \| not identifiable \|$", page, re.M)
    assert not re.search(r"± 0(?![.\d])", page)


def test_a_term_is_read_by_the_safe_parser_only(one_stage):
    e = term_effect("v*cos(2*tau) + g**2", one_stage)
    x, v = one_stage.states
    assert e.fitted == ("c_term1",)
    assert e.term == v * sp.cos(2 * one_stage.time) + g(x, parameter_symbol("eta")) ** 2
    with pytest.raises(ModelError, match="not allowed"):
        term_effect("__import__('os').getcwd()", one_stage)
    with pytest.raises(GearsymError, match="unknown name w"):
        term_effect("w*v", one_stage)


def test_the_fit_recovers_known_parameters_within_their_errors(one_stage, tmp_path):
    truth = one_stage.with_values(zeta=0.08, B1=4.0)
    data = measure(truth, tmp_path, "known", noise=0.005)
    segments, _ = segments_of(one_stage, data)
    result = fit_windows(one_stage, segments, ["zeta", "B1"], guess={"zeta": 0.12, "B1": 3.3})
    assert result.success
    for p, true in (("zeta", 0.08), ("B1", 4.0)):
        assert abs(result.estimates[p] - true) < 4 * result.stderr[p] + 1e-4
    # the fit's outputs come from the run that ended it, kept by its problem (not run again): the same bits as a new run
    # at its estimates, which a problem gives only for unknowns it has not run at lately
    problem = Problem(one_stage, segments, ["zeta", "B1"], [], 2 * np.pi, Integration())
    at = np.concatenate([[result.estimates["zeta"], result.estimates["B1"]], result.starts.reshape(-1, order="F")])
    fresh = problem.run_at(at)
    assert problem.run_at(at) is not fresh  # (a run of run_at's own is not kept: only those of the fit's calls)
    problem(at)
    kept = problem.run_at(at)
    problem(at + 1e-3)  # a later trial elsewhere
    assert problem.run_at(at) is kept and problem.run_at(at + 2e-3) is not kept
    for a, b in ((fresh.states, kept.states), (fresh.outputs, kept.outputs)):
        assert np.array_equal(a, b)
    np.testing.assert_array_equal(np.concatenate([res["x"] for res in result.residuals]),
                                  np.concatenate([seg.observed["x"] for seg in segments]) - fresh.outputs[0])


def test_the_fit_stops_where_a_further_step_changes_nothing_the_noise_lets_one_see(one_stage, rig_runs, tmp_path,
                                                                                    monkeypatch):
    """Levenberg-Marquardt stops once a step would move every unknown by less than STEP_IN_SIGMAS (1e-3) of its
    standard error: its estimates, offset and noise level are those of the same fit run on until a step gains less
    than 1e-12 of the cost (the stop before), within 1 % of their standard errors, in fewer steps. An accelerometer
    with an offset and the start far off: its start states are unmeasured, the slowest fit the loop makes."""
    path = rig.write(tmp_path / "acc.csv", rig_runs("cubic", (1.0, 1.8))[:1], ("x_ddot",), bias={"x_ddot": 0.3})
    model = augment(one_stage, ["cubic_stiffness"])
    segments, _ = segments_of(model, load_measurements([path], one_stage))

    def fitted():
        return fit_windows(model, segments, ["zeta", "B1", "k3"], guess={"zeta": 0.12, "B1": 3.3, "k3": 0.0},
                           bias=["x_ddot"])

    stopped = fitted()
    monkeypatch.setattr(marquardt, "STEP_IN_SIGMAS", 0.0)  # the relative gain alone stops it
    tight = fitted()
    assert stopped.success and tight.success and stopped.iterations < tight.iterations, (stopped.iterations,
                                                                                         tight.iterations)
    for p, value in tight.estimates.items():
        assert abs(stopped.estimates[p] - value) <= 0.01 * tight.stderr[p], (p, stopped.estimates[p], value)
    assert abs(stopped.bias["x_ddot"] - tight.bias["x_ddot"]) <= 0.01 * tight.bias_stderr["x_ddot"]
    assert stopped.sigma == pytest.approx(tight.sigma, rel=1e-4)


def test_effects_extend_the_symbolic_model(one_stage):
    model = augment(one_stage, ["cubic_stiffness", "coulomb_friction"], values={"k3": 0.1})
    assert model.name == "one_stage_with_cubic_stiffness_and_coulomb_friction"
    assert model.parameters["k3"] == 0.1 and model.parameters["mu_c"] == 0.0 and model.parameters["eps_c"] == 0.05
    assert model.rhs[0] == one_stage.rhs[0]
    every = [*EFFECTS, "mesh_stiffness_harmonic_3", "torque_harmonic_2", "transmission_error_1"]
    every.remove("shaft_damping")  # the one-stage model has no shaft
    off = augment(one_stage, every)  # every effect at 0 is the declared model
    point = {s: val for s, val in zip(off.states, (-13.3, 0.7))} | {off.time: 0.4}  # on the coast flank
    values = {parameter_symbol(k): val for k, val in off.parameters.items()}
    a = float(off.rhs[1].subs(point).subs(values).rewrite(sp.Piecewise))
    b = float(one_stage.rhs[1].subs(point).subs(values).rewrite(sp.Piecewise))
    assert a == pytest.approx(b, rel=1e-12)
    custom = Effect("third_harmonic_torque", "B3 cos(3 tau) in the torque", ("B3",), {},
                    lambda s: Change(torque=s.parameter("B3") * sp.cos(3 * s.time)), acts_on="torque")
    assert augment(one_stage, [custom]).rhs[1] - one_stage.rhs[1] == parameter_symbol("B3") * sp.cos(
        3 * one_stage.time) / parameter_symbol("omega") ** 2


def test_bad_requests_say_what_is_wrong(one_stage, tmp_path, capsys):
    with pytest.raises(GearsymError, match="unknown effect 'cubic'.*cubic_stiffness"):
        augment(one_stage, ["cubic"])
    with pytest.raises(GearsymError, match="torque_harmonic needs its order: torque_harmonic_2"):
        augment(one_stage, ["torque_harmonic"])
    with pytest.raises(ModelError, match="no mesh force"):
        augment(conftest.load("lorenz"), ["cubic_stiffness"])
    with pytest.raises(ModelError, match="no shaft force"):
        augment(one_stage, ["shaft_damping"])
    data = measure(one_stage, tmp_path, "bad", options=Integration(periods=106, discard=100, backend="in-process"))
    with pytest.raises(GearsymError, match="cannot fit zetta"):
        explain(one_stage, data, ["zetta"])
    with pytest.raises(GearsymError, match="bias of x_ddot: no such channel in the data \\(x\\)"):
        explain(one_stage, data, ["zeta"], bias=["x_ddot"])
    injection = "__import__('os').system('touch pwned')"  # --add-term goes through the safe parser only
    assert main(["explain", str(tmp_path / "bad.csv"), "--model", "one_stage", "--fit", "zeta", "--out",
                 str(tmp_path / "out"), "--add-term", injection]) == 2
    assert "gearsym: error: term" in capsys.readouterr().err and not (REPO_ROOT / "pwned").exists()
    assert not (tmp_path / "pwned").exists() and not (tmp_path / "out" / "report.md").exists()


@pytest.mark.slow
def test_explain_command_writes_the_report(one_stage, tmp_path, capsys):
    data = tmp_path / "cubic.csv"
    simulate_measurements(augment(one_stage, ["cubic_stiffness"], values={"k3": 0.02}), options=RECORD,
                          samples_per_period=40, noise=0.01, seed=1, records=RECORDS, out=data)
    out = tmp_path / "report"
    code = main(["explain", str(data), "--model", "one_stage", "--fit", "zeta,B1", "--out", str(out), "--quiet",
                 "--effects", "cubic_stiffness,coulomb_friction"])
    assert code == 0 and "explained: effects added: cubic_stiffness" in capsys.readouterr().out
    report = json.loads((out / "report.json").read_text())
    assert {"verdict", "effects", "unexplained", "error_before", "error_after", "parameters", "spectrum",
            "proposed"} <= set(report)
    assert report["effects"] == ["cubic_stiffness"] and report["error_after"] < report["error_before"] / 5
    page = (out / "report.md").read_text()
    assert page.index("## Verdict: explained") < page.index("## Candidates") < page.index("## The residual's spectrum")
    assert "k_{3}" in (out / "derived_model.md").read_text() and "cubic_stiffness" in page
    assert all((out / f).stat().st_size > 10_000 for f in ("residuals.png", "prediction.png"))
    assert np.isfinite(report["parameters"]["k3"])
    assert main(["explain", str(data), "--model", "one_stage", "--fit", "zeta", "--out", str(out), "--channel",
                 "acc"]) == 2
    assert "--channel 'acc': write NAME=FORMULA" in capsys.readouterr().err


EXAMPLE = REPO_ROOT / "docs" / "examples" / "explain-cubic-stiffness"


@pytest.mark.slow
def test_the_worked_example_data_are_what_the_documented_command_writes(tmp_path, monkeypatch, capsys):
    page = (REPO_ROOT / "docs" / "data-loop.md").read_text().replace("\\\n", " ")
    command = re.search(r"^gearsym simulate .*$", page, re.M).group(0)
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(command)[1:]) == 0
    # Both records are chaotic (largest exponents 0.075 at omega = 1.2 and 0.038 at 1.6): without FMA contraction
    # the first record is another trajectory of the same attractor, so it is compared as the attractor it is on.
    assert not measured_differences((tmp_path / "measured.csv").read_text(), (EXAMPLE / "measured.csv").read_text(),
                                    ("x",), attractor=True), (
        "docs/examples/explain-cubic-stiffness/measured.csv is not what docs/data-loop.md's command writes: rerun it")


@pytest.mark.slow
@pytest.mark.usefixtures("report_without_its_two_plots")  # (it never looks at the residual and prediction plots)
def test_the_committed_worked_example_is_what_explain_writes(tmp_path):
    from gearsym.figures.fit_report import explain_files

    example = EXAMPLE
    out = tmp_path / "example"
    out.mkdir()
    (out / "measured.csv").write_bytes((example / "measured.csv").read_bytes())
    report = explain_files([out / "measured.csv"], conftest.system("one_stage"), ["zeta", "B1"], out=out)
    for name in ("report.md", "derived_model.md"):
        assert not differences((out / name).read_text(), (example / name).read_text()), (
            f"docs/examples/explain-cubic-stiffness/{name} is out of date: rerun the commands in docs/data-loop.md there")
    committed = json.loads((example / "report.json").read_text())
    assert report["effects"] == committed["effects"] == ["cubic_stiffness"]
    assert report["error_after"] == pytest.approx(committed["error_after"], rel=1e-6)


RIG_EXAMPLE = REPO_ROOT / "docs" / "examples" / "explain-rig-accelerometer"


def test_the_rig_example_data_are_what_the_documented_command_writes(tmp_path):
    page = (REPO_ROOT / "docs" / "data-loop.md").read_text()
    assert "python tests/rig.py measured.csv" in page
    rig.example(tmp_path / "measured.csv")
    assert not csv_differences((tmp_path / "measured.csv").read_text(), (RIG_EXAMPLE / "measured.csv").read_text()), (
        "docs/examples/explain-rig-accelerometer/measured.csv is not what `python tests/rig.py` writes: rerun it")


@pytest.mark.slow
@pytest.mark.usefixtures("report_without_its_two_plots")  # (it never looks at the residual and prediction plots)
def test_the_committed_rig_example_is_what_explain_writes(tmp_path, monkeypatch, capsys):
    page = (REPO_ROOT / "docs" / "data-loop.md").read_text()
    command = re.search(r"^\s*gearsym explain measured.csv .*--time-scale.*$", page, re.M).group(0).strip()
    (tmp_path / "measured.csv").write_bytes((RIG_EXAMPLE / "measured.csv").read_bytes())
    monkeypatch.chdir(tmp_path)
    assert main([*shlex.split(command)[1:], "--quiet"]) == 0
    (made, held), (committed, kept) = map(wrong_models_held, ((tmp_path / "report.md").read_text(),
                                                             (RIG_EXAMPLE / "report.md").read_text()))
    assert not differences(made, committed), (
        "docs/examples/explain-rig-accelerometer/report.md is out of date: rerun the commands in docs/data-loop.md")
    assert held["errors"].keys() == kept["errors"].keys() and held["notes"] == kept["notes"]
    assert min(held["errors"].values()) > 5 * held["chosen"], held
    assert held["estimates"].keys() == kept["estimates"].keys() and held["estimates"]
    for name, (value, stderr) in held["estimates"].items():
        assert abs(value - kept["estimates"][name][0]) <= 3 * (stderr + kept["estimates"][name][1]), (name, value)
    assert held["screened"] == kept["screened"] and held["orders"] == kept["orders"]
    assert not differences((tmp_path / "derived_model.md").read_text(), (RIG_EXAMPLE / "derived_model.md").read_text()), (
        "docs/examples/explain-rig-accelerometer/derived_model.md is out of date: rerun the commands in docs/data-loop.md")
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["verdict"] == "explained" and report["effects"] == ["torque_harmonic_2"]
    assert report["harmonics"]["torque_harmonic_2"]["amplitude"] == pytest.approx(math.hypot(*rig.EXAMPLE["ripple"]),
                                                                                  rel=0.02)


def test_a_file_in_seconds_takes_the_time_unit_of_a_model_with_physical_values(tmp_path, monkeypatch):
    import gearsym.cli.explain
    from gearsym import scaling

    passed = []

    def recorded(paths, system, fit, *, time_scale=None, **rest):
        passed.append(time_scale)
        return {"verdict": "nothing missing", "effects": [], "error_before": 0.0, "error_after": 0.0,
                "unexplained": False, "proposed": []}

    monkeypatch.setattr(gearsym.cli.explain, "explain_files", recorded)
    command = ["explain", "measured.csv", "--model", "spur_pair", "--fit", "zeta", "--out", str(tmp_path), "--quiet"]
    assert main(command) == 0
    omega_n = scaling(conftest.reduced("spur_pair")).omega_n.to("rad/s").magnitude  # tau = omega_n t, t in seconds
    assert passed == [pytest.approx(omega_n)] and omega_n > 1000
    assert main(["explain", "measured.csv", "--model", "one_stage", "--fit", "zeta", "--out", str(tmp_path),
                 "--quiet"]) == 0
    assert passed[-1] is None  # a nondimensional model has no seconds: a t column needs --time-scale
