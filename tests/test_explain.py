"""The data loop on synthetic measurements: each effect of the library, left out of the fitted model,
is named and added, and the held-out error falls at least 5x; no effect is added to data without one;
a discrepancy outside the library is reported as unexplained."""
from __future__ import annotations

import json
import re
import shlex

import numpy as np
import pytest
import sympy as sp

import conftest
from gearsym import EFFECTS, Integration, explain, load_measurements, simulate_measurements
from gearsym.cli import main
from gearsym.errors import GearsymError, ModelError
from gearsym.fit import Effect, augment, fit_windows
from gearsym.paths import REPO_ROOT
from gearsym.fit.explain import segments_of
from gearsym.symbols import parameter_symbol

RECORDS = [{"omega": 1.2}, {"omega": 1.6}]
#: the true strengths: large enough to stand out of 1 % noise
CASES = {
    "cubic_stiffness": ({"k3": 0.02}, RECORDS),
    "coulomb_friction": ({"mu_c": 0.6}, RECORDS),
    "mesh_stiffness_harmonic": ({"a_h": 0.4, "b_h": 0.2}, RECORDS),
    "transmission_error": ({"e_c": 0.5, "e_s": 0.3}, RECORDS),
    "coast_side_stiffness": ({"c_coast": 1.0}, [{"omega": 0.8}, {"omega": 0.9}]),  # big swings reach x <= -eta
}
#: a third harmonic of the driving torque: not a mesh effect, so not in the library
#: each record: 16 periods sampled after 100 of transient (in-process: no C compiled for each augmented model)
RECORD = Integration(periods=116, discard=100, backend="in-process")
#: the coast flank switches at Min(0, g(x, eta)), where the engine locates no crossing: the paper's plain RK4
PLAIN_RECORD = Integration.paper(periods=116, discard=100, backend="in-process")
THIRD_HARMONIC = Effect("third_harmonic_torque", "B3 cos(3 tau) in the driving torque", ("B3",), {},
                        lambda m: (m.parameter("B3") * sp.cos(3 * m.system.time) / m.omega**2, None))


@pytest.fixture(scope="module")
def one_stage():
    return conftest.system("one_stage")


def measure(system, tmp_path, name, records=RECORDS, noise=0.01, options=RECORD):
    path = tmp_path / f"{name}.csv"
    simulate_measurements(system, options=options, samples_per_period=40, noise=noise, seed=1, records=records,
                          out=path)
    return load_measurements([path], conftest.system("one_stage"))


@pytest.mark.parametrize("name", list(CASES))
def test_a_missing_effect_is_named_and_the_error_falls_fivefold(one_stage, tmp_path, name):
    values, records = CASES[name]
    data = measure(augment(one_stage, [name], values=values), tmp_path, name, records,
                   options=PLAIN_RECORD if name == "coast_side_stiffness" else RECORD)
    ex = explain(one_stage, data, ["zeta", "B1"])
    assert ex.effects == [name]
    assert ex.final.error <= ex.base.error / 5, (ex.base.error, ex.final.error)
    assert not ex.unexplained
    for p, true in values.items():  # and the effect's strength comes back
        assert ex.final.fit.estimates[p] == pytest.approx(true, rel=0.1, abs=0.02)


def test_no_effect_is_added_to_data_without_one(one_stage, tmp_path):
    ex = explain(one_stage, measure(one_stage, tmp_path, "clean"), ["zeta", "B1"])
    assert ex.effects == [] and not ex.unexplained
    assert ex.final.error < 0.02  # the noise floor (1 % noise)


def test_a_discrepancy_outside_the_library_is_unexplained(one_stage, tmp_path):
    truth = augment(one_stage, [THIRD_HARMONIC], values={"B3": 3.0})
    ex = explain(one_stage, measure(truth, tmp_path, "outside"), ["zeta", "B1"])
    assert ex.unexplained and ex.effects == []
    assert ex.final.error > 2 * 0.01


def test_the_fit_recovers_known_parameters_within_their_errors(one_stage, tmp_path):
    truth = one_stage.with_values(zeta=0.08, B1=4.0)
    data = measure(truth, tmp_path, "known", noise=0.005)
    segments, _ = segments_of(one_stage, data)
    result = fit_windows(one_stage, segments, ["zeta", "B1"], guess={"zeta": 0.12, "B1": 3.3})
    assert result.success
    for p, true in (("zeta", 0.08), ("B1", 4.0)):
        assert abs(result.estimates[p] - true) < 4 * result.stderr[p] + 1e-4


def test_effects_extend_the_symbolic_model(one_stage):
    model = augment(one_stage, ["cubic_stiffness", "coulomb_friction"], values={"k3": 0.1})
    assert model.name == "one_stage_with_cubic_stiffness_and_coulomb_friction"
    assert model.parameters["k3"] == 0.1 and model.parameters["mu_c"] == 0.0 and model.parameters["eps_c"] == 0.05
    assert model.rhs[0] == one_stage.rhs[0]
    off = augment(one_stage, list(EFFECTS))  # every effect at 0 is the declared model
    point = {s: val for s, val in zip(off.states, (-13.3, 0.7))} | {off.time: 0.4}  # on the coast flank
    values = {parameter_symbol(k): val for k, val in off.parameters.items()}
    a = float(off.rhs[1].subs(point).subs(values).rewrite(sp.Piecewise))
    b = float(one_stage.rhs[1].subs(point).subs(values).rewrite(sp.Piecewise))
    assert a == pytest.approx(b, rel=1e-12)


def test_bad_requests_say_what_is_wrong(one_stage, tmp_path):
    with pytest.raises(GearsymError, match="unknown effect 'cubic'.*cubic_stiffness"):
        augment(one_stage, ["cubic"])
    lorenz = conftest.load("lorenz")
    with pytest.raises(ModelError, match="no mesh force"):
        augment(lorenz, ["cubic_stiffness"])
    data = measure(one_stage, tmp_path, "bad")
    with pytest.raises(GearsymError, match="cannot fit zetta"):
        explain(one_stage, data, ["zetta"])


def test_explain_command_writes_the_report(one_stage, tmp_path, capsys):
    data = tmp_path / "cubic.csv"
    simulate_measurements(augment(one_stage, ["cubic_stiffness"], values={"k3": 0.02}), options=RECORD,
                          samples_per_period=40, noise=0.01, seed=1, records=RECORDS, out=data)
    out = tmp_path / "report"
    code = main(["explain", str(data), "--model", "one_stage", "--fit", "zeta,B1", "--out", str(out), "--quiet",
                 "--effects", "cubic_stiffness,coulomb_friction"])
    assert code == 0 and "effects added: cubic_stiffness" in capsys.readouterr().out
    report = json.loads((out / "report.json").read_text())
    assert {"effects", "unexplained", "error_before", "error_after", "parameters"} <= set(report)
    assert report["effects"] == ["cubic_stiffness"] and report["error_after"] < report["error_before"] / 5
    assert "k_{3}" in (out / "derived_model.md").read_text() and "cubic_stiffness" in (out / "report.md").read_text()
    assert all((out / f).stat().st_size > 10_000 for f in ("residuals.png", "prediction.png"))
    assert np.isfinite(report["parameters"]["k3"])


EXAMPLE = REPO_ROOT / "docs" / "examples" / "explain-cubic-stiffness"


def test_the_worked_example_data_are_what_the_documented_command_writes(tmp_path, monkeypatch, capsys):
    page = (REPO_ROOT / "docs" / "data-loop.md").read_text().replace("\\\n", " ")
    command = re.search(r"^gearsym simulate .*$", page, re.M).group(0)
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(command)[1:]) == 0
    assert (tmp_path / "measured.csv").read_bytes() == (EXAMPLE / "measured.csv").read_bytes(), (
        "docs/examples/explain-cubic-stiffness/measured.csv is not what docs/data-loop.md's command writes: rerun it")


def test_the_committed_worked_example_is_what_explain_writes(tmp_path):
    from gearsym.fit import explain_files

    example = EXAMPLE
    out = tmp_path / "example"
    out.mkdir()
    (out / "measured.csv").write_bytes((example / "measured.csv").read_bytes())
    report = explain_files([out / "measured.csv"], conftest.system("one_stage"), ["zeta", "B1"], out=out)
    assert (out / "report.md").read_text() == (example / "report.md").read_text(), (
        "docs/examples/explain-cubic-stiffness is out of date: rerun the commands in docs/data-loop.md there")
    assert (out / "derived_model.md").read_text() == (example / "derived_model.md").read_text()
    committed = json.loads((example / "report.json").read_text())
    assert report["effects"] == committed["effects"] == ["cubic_stiffness"]
    assert report["error_after"] == pytest.approx(committed["error_after"], rel=1e-6)
