"""The data loop names shaft-order faults on data from an independent simulator (tests/fault_rig.py: SciPy's
solve_ivp of the one-stage equations with a tooth fault, an eccentric gear or spacing errors typed in the test):
which gear, which tooth counted from the record's start, how much, with the held-out error before and after;
clean data with the same tooth counts get none; a record shorter than a revolution is refused for the effect.

A pinion of 9 and a wheel of 13 teeth keep the records short: each record is 4 revolutions of the wheel (52 mesh
periods, the last 13 held out), starting 30.3 mesh periods into the run (not at a whole revolution, so the tooth
counted from the record's start is not the tooth counted from the start of the run).
"""
from __future__ import annotations

import functools
import json
import math
import re
from pathlib import Path
import shlex
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.colors import to_rgb

import fault_rig
from same_numbers import differences, measured_differences, wrong_models_held
import gearsym
import gearsym.cli.spectrum
import gearsym.figures.fit_report
from gearsym import Integration, explain, load_measurements
from gearsym.cli import main
from gearsym.errors import GearsymError
from gearsym.figures.fit_report import tooth_figure, write_report
from gearsym.figures.save import pyplot
from gearsym.fit.report import TEETH_FIGURE
from gearsym.fit import augment
from gearsym.fit.selection import candidate_library, segments_of
from gearsym.fit.tooth_scan import scan_teeth
from gearsym.files.paths import REPO_ROOT

TEETH = (9, 13)
OMEGAS = (1.2, 1.6)
PERIODS, TRANSIENT = 52, 30.3
#: the truths: the wheel's tooth 9 (counted from tau = 0) loses 30 % of its stiffness; the pinion runs out by 0.4
#: (in x's unit, the backlash being 10) at phase 0.7; the pinion's spacing errors (zero mean)
CRACK = (2, 9, 0.3)
ECCENTRIC = (1, 0.4, 0.7)
SPACING = (1, [0.2, -0.1, 0.05, -0.25, 0.15, 0.0, 0.1, -0.2, 0.05])
#: a crack of no named fault's shape: the whole mesh stiffness 30 % lower while the wheel's tooth 9 is in mesh
WHOLE = (2, 9, 0.3)
CASES = {"crack": {"fault": CRACK}, "eccentric": {"eccentric": ECCENTRIC}, "spacing": {"spacing": SPACING},
         "clean": {}, "whole": {"whole": WHOLE}}
#: what the noise alone leaves: 1 % of each record's spread
NOISE = 0.01
#: every test searches the same library (compiled once): the shaft-order effects of both gears (the pinion's
#: spacing errors too) and the mesh-order effects they could be mistaken for, at orders 1 and 2
LIBRARY = ["tooth_fault", "eccentricity", "spacing_errors_gear1", "transmission_error", "mesh_stiffness_harmonic"]
HARMONICS = 2
#: the searches of the rig's faults refit the screen's three candidates of largest linearised gain (each case's true
#: effect and its closest competitors: eccentricity and spacing errors screen within 1e-4 of each other on the eccentric
#: pinion's data, both tooth faults are refitted on a cracked wheel's); the worked example (the last test) runs the
#: default search, which refits eight a round
REFITS = 3


def from_record_start(tooth: int, teeth: int) -> int:
    """The tooth of the run counted from a record that starts TRANSIENT mesh periods in (typed here)."""
    return (tooth - 1 - math.floor(TRANSIENT)) % teeth + 1


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    folder = tmp_path_factory.mktemp("faults")
    made = {}

    def get(case: str):
        if case not in made:
            pair = fault_rig.Pair(teeth=TEETH, **CASES[case])
            runs = [(w, pair.record(w, periods=PERIODS, transient=TRANSIENT)) for w in OMEGAS]
            made[case] = fault_rig.write(folder / f"{case}.csv", runs, noise=NOISE)
        return made[case]

    return get


@pytest.fixture(scope="module")
def geared():
    return gearsym.load("one_stage", teeth=TEETH)


@pytest.mark.slow
@pytest.mark.usefixtures("report_without_its_two_plots")  # (it never looks at the residual and prediction plots)
def test_a_cracked_tooth_on_the_wheel_is_named_with_its_tooth_and_severity(data, tmp_path, capsys, monkeypatch):
    """The documented command: the fault found on the wheel (not on the pinion), on its tooth counted from each
    record's start, with its severity and standard error (the screen's three of largest gain refitted, see REFITS)."""
    monkeypatch.setattr(gearsym.figures.fit_report, "explain", functools.partial(explain, refits=REFITS))
    out = tmp_path / "report"
    assert main(["explain", str(data("crack")), "--model", "one_stage", "--teeth", f"{TEETH[0]},{TEETH[1]}",
                 "--fit", "zeta,B1", "--effects", ",".join(LIBRARY), "--harmonics", str(HARMONICS),
                 "--out", str(out), "--quiet"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["verdict"] == "explained" and report["effects"] == ["tooth_fault_gear2"]
    (fault,) = report["faults"]
    gear, tooth, q = CRACK
    assert fault["gear"] == "gear2" and fault["tooth"] == from_record_start(tooth, TEETH[1]) == 5
    assert set(fault["tooth_by_record"].values()) == {5}
    assert fault["severity"] == pytest.approx(q, rel=0.05)  # (the rig's smoothstep edges are not gearsym's tanh)
    assert 0 < fault["severity_stderr"] < 0.02
    assert report["error_after"] <= report["error_before"] / 3 and report["error_after"] < 1.5 * NOISE
    page = (out / "report.md").read_text()
    assert f"tooth 5 of gear2: stiffness −{100 * fault['severity']:.3g} %" in page
    sidebands = report["sidebands"]["before"]["energy"]
    assert sidebands["gear2"] > sidebands["gear1"]  # the evidence points at the wheel
    assert report["sidebands"]["after"]["energy"]["gear2"] < sidebands["gear2"] / 3


@pytest.mark.slow
def test_an_eccentric_pinion_is_named_with_its_amplitude_and_phase(data, geared):
    ex = explain(geared, load_measurements([data("eccentric")], geared), ["zeta", "B1"], candidates=LIBRARY,
                 harmonics=HARMONICS, refits=REFITS)
    assert ex.verdict == "explained" and ex.effects == ["eccentricity_gear1"]
    (found,) = ex.as_dict()["faults"]
    _, amplitude, phase = ECCENTRIC
    assert found["amplitude"] == pytest.approx(amplitude, rel=0.03)
    assert found["phase"] == pytest.approx(phase, abs=0.03)
    assert found["amplitude_stderr"] < 0.02 and found["phase_stderr"] < 0.05
    assert ex.final.error <= ex.base.error / 5


@pytest.mark.slow
def test_spacing_errors_of_the_pinion_are_named_tooth_by_tooth(data, geared):
    """Spacing errors are Z - 1 parameters, so they are tried when named; the tooth faults and eccentricities of
    both gears and the mesh-order terms compete with them (screened by their linearised gains, the closest refitted)."""
    ex = explain(geared, load_measurements([data("spacing")], geared), ["zeta", "B1"], candidates=LIBRARY,
                 harmonics=HARMONICS, refits=REFITS)
    assert ex.verdict == "explained" and ex.effects == ["spacing_errors_gear1"]
    (found,) = ex.as_dict()["faults"]
    true = np.array(SPACING[1])
    got = np.array(found["errors"])
    # teeth are counted from tau = 0 in the model: the records' time is the run's
    assert np.max(np.abs(got - true)) < 0.05, (got, true)
    assert ex.final.error <= ex.base.error / 3


@pytest.fixture(scope="module")
def clean(data, geared):
    """The clean record explained with the named faults and the tooth-by-tooth form of every tooth's stiffness."""
    return explain(geared, load_measurements([data("clean")], geared), ["zeta", "B1"],
                   candidates=[*LIBRARY, "tooth_stiffness"], harmonics=HARMONICS)


@pytest.mark.slow
def test_clean_data_with_the_same_tooth_counts_get_no_fault(clean):
    """Not even from the tooth-by-tooth form, which gives every tooth a parameter (it was tried, for it was named)."""
    assert clean.effects == [] and clean.verdict == "nothing missing"
    assert clean.as_dict()["faults"] == []
    assert clean.base.error < 1.5 * NOISE
    assert any(c.effects == ("tooth_stiffness_gear1_gear2",) for c in clean.tried)


@pytest.fixture(scope="module")
def whole(data, geared):
    """The record whose crack softens the whole mesh, explained with the named faults and the tooth-by-tooth form."""
    measured = load_measurements([data("whole")], geared)
    return explain(geared, measured, ["zeta", "B1"], candidates=[*LIBRARY, "tooth_stiffness"],
                   harmonics=HARMONICS, refits=REFITS), measured


@pytest.mark.slow
def test_a_crack_that_softens_the_whole_mesh_is_found_tooth_by_tooth(whole, clean):
    """Issue 41: the rig's crack lowers the whole mesh stiffness by 30 % while the wheel's tooth 9 is in mesh, a window
    no named fault has. The named tooth fault is tried first and leaves something systematic; the tooth-by-tooth form
    (every tooth of both gears, 22 parameters) names the wheel's tooth, counted from each record's start, and its
    held-out error falls to within 1.5x of the clean record's."""
    ex, _ = whole
    named = min((c for c in ex.tried if c.effects and not c.slots), key=lambda c: c.error)
    assert named.effects == ("tooth_fault_gear2",)  # the named fault's best guess: the right gear
    assert ex.effects == ["tooth_stiffness_gear1_gear2"] and ex.verdict == "explained"
    assert ex.final.error <= 1.5 * clean.base.error < named.error, (ex.final.error, clean.base.error, named.error)
    (found,) = ex.as_dict()["faults"]
    gear, tooth, q = WHOLE
    assert found["standing_out"] == {"gear1": [], "gear2": [tooth]}  # counted from tau = 0
    counted = from_record_start(tooth, TEETH[1])
    assert all(teeth == {"gear1": [], "gear2": [counted]} for teeth in found["standing_out_by_record"].values())
    value, stderr = found["refitted"]["gear2"][tooth]
    assert value == pytest.approx(q, rel=0.05) and 0 < stderr < 0.01


@pytest.mark.slow
def test_tooth_faults_scanned_together_are_placed_as_each_alone(whole, geared):
    """A scan's tooth faults share their compiled runs (every severity is 0 at the fit, each fault asks for its own
    column with its own tooth): each fault is placed, with the same gains to the last bit, as when it is scanned alone
    (here on the whole-mesh crack's records, at the declared model's fit: the wheel's tooth fault gains most, on the
    rig's tooth)."""
    ex, measured = whole
    library = candidate_library(geared, LIBRARY, HARMONICS)
    superset = augment(geared, list(library.values()), name=f"{geared.name}_candidates")
    segments, _ = segments_of(superset, measured.split(0.25)[0])
    faults = [e for e in library.values() if e.scan]
    together = scan_teeth(superset, segments, ex.base.fit, faults, (), Integration())
    alone = {e.name: scan_teeth(superset, segments, ex.base.fit, [e], (), Integration())[e.name] for e in faults}
    assert [e.name for e in faults] == ["tooth_fault_gear1", "tooth_fault_gear2"] and together == alone
    wheel, pinion = together["tooth_fault_gear2"], together["tooth_fault_gear1"]
    assert wheel.gain > pinion.gain > 0 and set(wheel.teeth.values()) == {WHOLE[1]}  # (counted from tau = 0)


@pytest.mark.slow
@pytest.mark.usefixtures("report_without_its_two_plots")  # (it never looks at the residual and prediction plots)
def test_the_report_names_and_draws_the_teeth_that_stand_out(whole, geared, tmp_path):
    """The report of a tooth-by-tooth form says which tooth of which gear stands out (counted from the record's start)
    with its refitted change, and teeth.png draws every tooth's value: the one that stands out in red, where the rig
    put it, about 30 % down; no other tooth of either gear in red, none of them near it. A later report without a
    tooth-by-tooth form leaves no teeth.png of this one behind."""
    ex, measured = whole
    write_report(ex, geared, tmp_path, measured.sources)
    counted = from_record_start(WHOLE[1], TEETH[1])
    value, stderr = ex.as_dict()["faults"][0]["refitted"]["gear2"][WHOLE[1]]
    assert f"**gear2, tooth {counted}: mesh stiffness while in mesh −{100 * value:.3g} % ± {100 * stderr:.2g} %**" in (
        tmp_path / "report.md").read_text()
    assert (tmp_path / TEETH_FIGURE).is_file()
    fig = tooth_figure(ex, ex.final, geared.name, measured.sources)
    pinion, wheel = fig.axes[:2]
    red = {ax: [(b.get_x() + b.get_width() / 2, b.get_height()) for b in ax.patches
                if b.get_facecolor()[:3] == to_rgb("C3")] for ax in (pinion, wheel)}
    assert red[pinion] == [] and [round(x) for x, _ in red[wheel]] == [counted]
    assert red[wheel][0][1] == pytest.approx(-100 * WHOLE[2], abs=5)
    others = [b.get_height() for ax in (pinion, wheel) for b in ax.patches if b.get_facecolor()[:3] != to_rgb("C3")]
    assert len(others) == sum(TEETH) - 1 and max(map(abs, others)) < 5
    assert f"gear2: standing out (red): {counted}" == wheel.get_title()
    pyplot().close(fig)
    clean_report = tmp_path / "again"
    clean_report.mkdir()
    (clean_report / TEETH_FIGURE).write_bytes((tmp_path / TEETH_FIGURE).read_bytes())
    named = replace(ex, tried=[c for c in ex.tried if not any(ex.library[e].gears for e in c.effects)], final=ex.base)
    write_report(named, geared, clean_report, measured.sources)
    assert not (clean_report / TEETH_FIGURE).exists()


@pytest.mark.slow
def test_a_record_shorter_than_a_revolution_is_refused_for_that_effect(tmp_path, geared):
    pair = fault_rig.Pair(teeth=TEETH)
    runs = [(1.2, pair.record(1.2, periods=10, transient=5))]
    data = load_measurements([fault_rig.write(tmp_path / "short.csv", runs)], geared)
    with pytest.raises(GearsymError, match=r"shorter than one revolution of gear2: 13 mesh periods"):
        explain(geared, data, ["zeta", "B1"], candidates=["tooth_fault_gear2"])
    # asked for as a kind (or in the default library) it is not tried on that gear, and the report says why; the
    # pinion's (9 teeth) fits into the 10 mesh periods
    ex = explain(geared, data, ["zeta", "B1"], candidates=["tooth_fault"])
    assert list(ex.as_dict()["not_tried"]) == ["tooth_fault_gear2"] and "tooth_fault_gear1" in ex.library
    assert "covers 10 mesh periods" in ex.as_dict()["not_tried"]["tooth_fault_gear2"]


def test_shaft_order_effects_need_tooth_counts():
    one_stage = gearsym.load("one_stage")
    with pytest.raises(GearsymError, match="no gear of one_stage has a tooth count"):
        candidate_library(one_stage, ["tooth_fault"])
    with pytest.raises(GearsymError, match="'gear3' is not a gear with a tooth count"):
        candidate_library(gearsym.load("one_stage", teeth=TEETH), ["eccentricity_gear3"])
    assert not any(e.shaft_order for e in candidate_library(one_stage).values())  # none in the default library


# --------------------------------------------------------------------------- the worked example
EXAMPLE = REPO_ROOT / "docs" / "examples" / "explain-cracked-tooth"


def example_commands() -> dict[str, list[str]]:
    """The worked example's three commands, as docs/data-loop.md gives them."""
    page = (REPO_ROOT / "docs" / "data-loop.md").read_text()
    found = {}
    for verb in ("simulate", "explain", "spectrum"):
        line = re.search(rf"^\s*gearsym {verb} .*--teeth 20,53.*$", page, re.M).group(0).strip()
        found[verb] = shlex.split(line)[1:]
    return found


@pytest.mark.slow
@pytest.mark.usefixtures("report_without_its_two_plots")  # (it never looks at the residual and prediction plots)
def test_the_cracked_tooth_example_is_what_its_commands_write(tmp_path, monkeypatch):
    commands = example_commands()
    # (it never looks at spectrum.png either: drawn empty; the spectrum command's figure is drawn and checked in
    # tests/test_shaft_orders.py)
    monkeypatch.setattr(gearsym.cli.spectrum, "plot_order_spectra", lambda spectra, path, **kw: path.write_bytes(b""))
    (tmp_path / "simulated").mkdir()
    monkeypatch.chdir(tmp_path / "simulated")
    assert main(commands["simulate"]) == 0
    # The record at omega = 1.2 is chaotic (largest exponent 0.075): without FMA contraction it leaves the committed
    # trajectory within its 160 mesh periods, so it is compared as the attractor it is on, and the committed record
    # is what explain and spectrum read here, as they read it in the example's folder.
    assert not measured_differences(Path("measured.csv").read_text(), (EXAMPLE / "measured.csv").read_text(),
                                    ("x",), attractor=True), (
        "docs/examples/explain-cracked-tooth/measured.csv is not what docs/data-loop.md's command writes: rerun it")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "measured.csv").write_bytes((EXAMPLE / "measured.csv").read_bytes())
    assert main([*commands["explain"], "--quiet"]) == 0 and main(commands["spectrum"]) == 0
    (made, held), (committed, kept) = (wrong_models_held(p.read_text()) for p in (tmp_path / "report.md",
                                                                                   EXAMPLE / "report.md"))
    assert not differences(made, committed), (
        "docs/examples/explain-cracked-tooth/report.md is out of date: rerun the commands in docs/data-loop.md")
    assert held["errors"].keys() == kept["errors"].keys() and min(held["errors"].values()) > held["chosen"]
    assert not differences((tmp_path / "derived_model.md").read_text(), (EXAMPLE / "derived_model.md").read_text()), (
        "docs/examples/explain-cracked-tooth/derived_model.md is out of date: rerun the commands in docs/data-loop.md")
    report = json.loads((tmp_path / "report.json").read_text())
    (fault,) = report["faults"]
    assert report["effects"] == ["tooth_fault_gear1"] and fault["tooth"] == 7 and fault["gear"] == "gear1"
    assert fault["severity"] == pytest.approx(0.3, abs=3 * fault["severity_stderr"])
    assert "**tooth 7 of gear1: stiffness −29.3 % ± 0.42 %**" in (EXAMPLE / "report.md").read_text()
    made, committed = (json.loads(p.read_text()) for p in (tmp_path / "spectrum.json", EXAMPLE / "spectrum.json"))
    for a, b in zip(made["spectra"], committed["spectra"]):
        assert [ln["label"] for ln in a["lines"]] == [ln["label"] for ln in b["lines"]]
        np.testing.assert_allclose([ln["amplitude"] for ln in a["lines"]], [ln["amplitude"] for ln in b["lines"]],
                                   rtol=1e-6, atol=1e-12)
