"""``gearsym reproduce``: the committed report is what the code makes of the committed record, the
record is what the engine computes, and a quick run writes every output."""
from __future__ import annotations

import dataclasses
import io
import json
import re
import sys

import numpy as np
import pytest

import gearsym
from gearsym import Integration
from gearsym.analysis.basins import basin_map
from gearsym.checks import json_safe
from gearsym.files.paths import REPO_ROOT
from gearsym.periodic import FOLD, GRAZING, NEIMARK_SACKER, PERIOD_DOUBLING
from gearsym.reproduce import jumps
from gearsym.reproduce.plan import PAPER_JUMPS
from gearsym.reproduce import claims as claim_checks
from gearsym.reproduce import SCENARIOS, compute, paper_plan, render, reproduce
from gearsym.reproduce.compute import box_grid
from gearsym.reproduce.report import VERDICT_MARK
from gearsym.reproduce.stability import grid as stability_grid
from conftest import quick_reproduction_group
from same_numbers import differences, json_differences

DOCS = REPO_ROOT / "docs"
RECORD = DOCS / "figures" / "claims.json"


@pytest.fixture(scope="module")
def committed() -> dict:
    return json.loads(RECORD.read_text())


def test_the_committed_report_is_rendered_from_the_committed_record(committed):
    assert (DOCS / "reproduction.md").read_text() == render(committed, "figures"), (
        "docs/reproduction.md is out of date with docs/figures/claims.json: run `gearsym reproduce`")


def test_every_figure_the_report_shows_is_committed():
    text = (DOCS / "reproduction.md").read_text()
    shown = re.findall(r"\]\((figures/[^)]+\.png)\)", text)
    assert {"figures/fig3.png", "figures/fig4.png", "figures/fig6.png", "figures/fig7.png", "figures/basins.png",
            "figures/basin-fractions.png", "figures/basins-defaults.png", "figures/basin-fractions-defaults.png"} \
        <= set(shown)
    for name in shown:
        assert (DOCS / name).stat().st_size > 20_000, name


def test_every_claim_has_a_verdict_by_its_rule_in_every_scenario(committed):
    assert [s["name"] for s in committed["scenarios"]] == [s.name for s in SCENARIOS]
    for scenario in committed["scenarios"]:
        ids = [c["id"] for c in scenario["claims"]]
        assert len(ids) == len(claim_checks.CHECKS) == len(set(ids))
        assert all(c["verdict"] in VERDICT_MARK and c["measured"] for c in scenario["claims"])
    assert set(committed["scenarios"][0]["study"]) == {"k_a", "kS", "I2"}


@pytest.mark.slow
def test_figure_3_claims_recomputed_match_the_committed_record(tmp_path, committed):
    """The Fig. 3 sweeps again, on the paper's grid: the same verdicts, the same measured sentences with their
    numbers to 2 % (the share of chaotic points, the ends of chaotic intervals), and the same branches, bifurcations
    and paper's jumps to 1e-5 of omega. With the C compiled without FMA contraction the chaotic points are other
    realizations of their attractors: the list of the up run's jumps (one of eight, at a chaotic point, comes and
    goes) and the ends of the hysteresis intervals between chaotic attractors moved; the verdicts, the periodic
    branches and what the paper's jumps are did not. So the jumps' list is compared only when the C rounds as the
    committed run's did (the sweeps' amplitudes at the periodic points are the test of that)."""
    full = paper_plan(scenario=SCENARIOS[0])
    plan = dataclasses.replace(full, sweeps=tuple(s for s in full.sweeps if s.name.startswith("fig3")),
                               attractors=(), portraits=(), basins=(), fractions=())  # (the basins: their own test)
    computed = compute(plan, tmp_path)
    recorded = {c["id"]: c for c in committed["scenarios"][0]["claims"]}
    for check in (claim_checks.chaos_d0, claim_checks.regular_d2, claim_checks.amplitude_d2, claim_checks.jumps_d2):
        claim = check(computed, {})
        assert claim["verdict"] == recorded[claim["id"]]["verdict"], claim["id"]
        if check is not claim_checks.jumps_d2:
            assert not differences(claim["measured"], recorded[claim["id"]]["measured"], rel=0.02), claim["id"]
        else:
            assert claim["values"]["matched"] == recorded[claim["id"]]["values"]["matched"]
    made, orbits = json_safe(computed.jumps), committed["scenarios"][0]["orbits"]
    for sweep in orbits:  # the branches, their bifurcations and what the paper's jumps are
        for key in ("branches", "bifurcations", "paper_jumps"):
            assert not json_differences(made[sweep].get(key), orbits[sweep].get(key), rel=1e-5), (sweep, key)


def test_every_paper_jump_and_hysteresis_end_is_a_located_bifurcation_a_crisis_or_said_undecided(committed):
    """docs/reproduction.md says for each jump of the paper (Fig. 3a, D = 2) and each end of each hysteresis
    interval what it is; each is one of the kinds the continuation locates, or a chaotic attractor's crisis, or
    (a hysteresis end only) an attractor the run cannot decide, said as such. The paper's jumps are all explained."""
    explained = {FOLD, PERIOD_DOUBLING, NEIMARK_SACKER, GRAZING, jumps.CRISIS, jumps.STEEP}

    def said(end: dict) -> bool:  # or, for an orbit of a period not continued, that period and that it is not
        long = re.match(r"a period-(\d+) orbit .*not on the continued", end["text"])
        undecided = end["kind"] == jumps.UNDECIDED and "cannot decide" in end["text"]
        return end["kind"] in explained or undecided or (end["kind"] == jumps.OTHER and bool(long)
                                                         and int(long[1]) > jumps.CONTINUED_PERIOD)

    for scenario in committed["scenarios"]:
        for orbits in scenario["orbits"].values():
            ends = [h[run] for h in orbits["hysteresis"] for run in ("up", "down")]
            assert ends and all(map(said, ends)), ends
    paper = committed["scenarios"][0]["orbits"][jumps.PAPER_SWEEP]["paper_jumps"]
    assert [j["omega"] for j in paper] == list(PAPER_JUMPS) and all(j["kind"] in explained for j in paper), paper
    page = (DOCS / "reproduction.md").read_text()
    assert all(j["text"] in page for j in paper)


@pytest.mark.slow
@quick_reproduction_group()
def test_a_quick_reproduction_writes_every_output_and_reuses_its_data(quick_reproduction, monkeypatch):
    """A quick run (the session's, whose figures test_figures.py checks) writes every figure, the record and the
    report; a second run reuses the first run's data (no point computed again, the basins' files read, not
    written) and makes the same record. The second run's figures are not drawn again: the first run's are checked
    above, and drawing them is most of a run that reuses its data (each is drawn from what the run computed, which
    the record compared equal shows is the same)."""
    out, record = quick_reproduction.out, quick_reproduction.record
    for name in ("fig3.png", "fig3-orbits.png", "fig4.png", "fig6.png", "fig7.png", "hysteresis.png", "study.png",
                 "basins.png", "basin-fractions.png", "basins-defaults.png", "basin-fractions-defaults.png",
                 "stability.png", "claims.json"):
        assert (out / "figures" / name).stat().st_size > 1000, name
    page = (out / "reproduction.md").read_text()
    for scenario in record["scenarios"]:
        assert len(scenario["claims"]) == len(claim_checks.CHECKS)
        assert all(c["measured"] in page for c in scenario["claims"])
    records = sorted((out / "figures" / "data").glob("*/*.json"))
    assert len(records) == sum(len(paper_plan(True, s, study=i == 0).sweeps) for i, s in enumerate(SCENARIOS))
    assert all(json.loads(p.read_text())["points"]["computed"] > 0 for p in records)
    maps = sorted((out / "figures" / "data").glob("*/basins/map-*.json"))
    assert len(maps) == 2 * len(paper_plan(True).basins)
    stamps = {p: p.stat().st_mtime_ns for p in (*maps, *(out / "figures" / "data").glob("*/basins/*.csv"))}
    drawn = []  # what the second run would draw: each scenario's computed plan, reused, and the stability chart
    monkeypatch.setattr(sys.modules["gearsym.reproduce"], "draw_all",
                        lambda computed, folder, suffix="": drawn.append((computed.plan.scenario.name, suffix)) or [])
    monkeypatch.setattr(sys.modules["gearsym.reproduce"], "draw_stability",
                        lambda chart, folder: drawn.append(("stability", chart.shape)))
    again = reproduce(out / "figures", out / "reproduction.md", quick=True)
    assert drawn == [(s.name, "" if i == 0 else f"-{s.name}") for i, s in enumerate(SCENARIOS)] + [
        ("stability", (len(stability_grid(True)["k_a"]), len(stability_grid(True)["omega"])))]
    assert all(json.loads(p.read_text())["points"]["computed"] == 0 for p in records)  # the data were reused
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps  # the basins' too: read, not written again
    assert again == record


@pytest.mark.slow
def test_a_basin_map_recomputed_matches_the_committed_record(committed):
    """Fig. 4 as basins (D = 2, omega = 1.5, calibrated), again on the committed grid: the same attractors, and
    their shares to a start or two (a start on a basin boundary may go either way on another CPU's rounding)."""
    plan = paper_plan(scenario=SCENARIOS[0])
    job = next(j for j in plan.basins if j.model == "one_stage_resonant" and j.omega == 1.5)
    recorded = next(m for m in committed["scenarios"][0]["basins"]["maps"]
                    if m["model"] == job.model and m["omega"] == job.omega)
    options = Integration.paper(periods=plan.attractor_discard + plan.attractor_periods, discard=plan.attractor_discard)
    model = gearsym.compile_model(gearsym.load(job.model), options)
    found = basin_map(model, box_grid(job.points), **SCENARIOS[0].settings(job.model), omega=job.omega)
    assert [(a.description, a.period) for a in found.attractors] == \
        [(a["description"], a["period"]) for a in recorded["attractors"]]
    for a, r in zip(found.attractors, recorded["attractors"]):
        assert abs(a.basin.starts - r["starts"]) <= 2


def test_a_record_equal_to_the_committed_one_within_rounding_leaves_the_files_as_they_are(tmp_path, committed):
    """Another machine rounds the continuation's located values otherwise (the last digits of claims.json): the
    committed record and report stay, byte for byte; a result that differs is written."""
    from gearsym.reproduce.report import write

    record, page = tmp_path / "figures" / "claims.json", tmp_path / "reproduction.md"
    record.parent.mkdir()
    record.write_text((DOCS / "figures" / "claims.json").read_text())
    page.write_text((DOCS / "reproduction.md").read_text())
    before = (record.read_bytes(), page.read_bytes())
    rounded = json.loads(json.dumps(committed))
    fold = rounded["scenarios"][0]["orbits"]["fig3_D2"]["bifurcations"][0]
    fold["omega"] *= 1 + 3e-7
    assert write(rounded, record, page) == committed
    assert (record.read_bytes(), page.read_bytes()) == before
    fold["omega"] *= 1 + 1e-3
    assert write(rounded, record, page) == rounded
    assert json.loads(record.read_text()) == rounded


def test_a_figure_redrawn_with_a_line_moved_by_rounding_is_kept_and_a_changed_one_replaced(tmp_path):
    from gearsym.figures.save import pyplot, save_figure

    def draw(shift: float):
        fig, ax = pyplot().subplots(figsize=(4, 3))
        x = np.linspace(0, 2, 200)
        ax.plot(x, np.sin(3 * x) + shift)
        ax.set_title("sin 3x")
        return fig

    path = save_figure(draw(0.0), tmp_path / "f.png", dpi=80)
    first = path.read_bytes()
    assert save_figure(draw(2e-3), tmp_path / "g.png", dpi=80).read_bytes() != first  # other antialiasing
    assert save_figure(draw(2e-3), path, dpi=80, keep_same=True).read_bytes() == first
    assert save_figure(draw(0.3), path, dpi=80, keep_same=True).read_bytes() != first


def test_a_saved_figure_is_drawn_once_and_is_the_picture_matplotlib_saves_of_its_layout(tmp_path, monkeypatch):
    """save_figure lays a figure out at the resolution it writes, then draws it once: with matplotlib's 'none' layout
    engine (a stand-in) savefig drew it twice, once without rendering. The PNG is byte for byte the one matplotlib's
    own savefig writes of that layout, and the figure keeps its layout engine."""
    from matplotlib.figure import Figure

    from gearsym.figures.layout import fit_texts
    from gearsym.figures.save import pyplot, save_figure

    def draw():
        fig, (a, b) = pyplot().subplots(1, 2, figsize=(5, 3), constrained_layout=True)
        a.plot([0, 1, 2], [1, 3, 2])
        b.set_title("the right panel")
        fig.suptitle("a figure of two panels")
        return fig

    reference, image = draw(), io.BytesIO()
    reference.set_dpi(80)
    fit_texts(reference, again=True)
    reference.set_layout_engine("none")
    reference.savefig(image, format="png", dpi=80, metadata={"Software": None})
    drawn, real = [], Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda fig, renderer: drawn.append(fig) or real(fig, renderer))
    fig = draw()
    engine = fig.get_layout_engine()
    assert save_figure(fig, tmp_path / "f.png", dpi=80).read_bytes() == image.getvalue()
    assert drawn == [fig] and fig.get_layout_engine() is engine
