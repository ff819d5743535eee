"""docs/performance.md is rendered from the committed benchmark record, and its numbers follow from it.

The benchmark itself (``python -m bench.speed``, ~10 min, needs numba, jitcode,
scipy) is not run here; these tests check that the committed page and figure
are exactly what the committed measurements give, and that the summary rules
(errors against the converged reference, equal-accuracy picks, verdicts) do
what the page says they do.
"""
from __future__ import annotations

import copy
import json
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from bench.speed import report, summary  # noqa: E402

RECORD = REPO / "bench" / "results" / "speed.json"


@pytest.fixture(scope="module")
def raw():
    return json.loads(RECORD.read_text())


@pytest.mark.slow
def test_page_and_figure_regenerate_from_the_record(raw, tmp_path):
    page, fig = report.write_report(RECORD, tmp_path / "performance.md", tmp_path / "performance.png")[:2]
    assert page.read_text() == report.PAGE.read_text(), "docs/performance.md differs: run python -m bench.speed.report"
    # pixels, not bytes: another matplotlib release may encode the same picture differently
    from matplotlib.image import imread

    new, committed = imread(fig), imread(report.FIGURE)
    assert new.shape == committed.shape and abs(new - committed).mean() < 2e-3, "docs/figures/performance.png differs"


def test_stored_summary_is_what_the_rules_give(raw):
    assert summary.summarise(raw) == raw["summary"]


def test_record_is_a_full_run(raw):
    assert not raw["quick"]
    assert raw["settings"]["periods"] == 400 and raw["settings"]["discard"] == 100
    for model in ("one_stage", "flexible_shaft"):
        m = raw["models"][model]
        assert m["omegas"] == [0.9, 1.2, 1.5, 1.8]
        assert {"JiTCODE", "SciPy RK45", "gearsym", "C", "Numba RK4"} <= set(m["precision"])
        assert len(m["sweep"]["gearsym"]["exponents"]) == 191
    assert {v["what"].split(",")[0] for v in raw["summary"]["verdicts"]} >= {
        "gearsym / hand-written C", *(f"{tool} / gearsym ({scheme}) at equal accuracy"
                                      for tool in ("JiTCODE", "SciPy RK45")
                                      for scheme in ("the paper's RK4", "crossings located"))}


def test_sum_rule_holds_for_every_tool(raw):
    """Every tool's exponents sum to the mean trace of the Jacobian, -2 zeta/omega (an exact invariant)."""
    for s in raw["summary"]["models"].values():
        for label, t in s["tools"].items():
            assert t["sum_rule"] < 1e-6, label
        for rows in s["precision"].values():
            for r in rows:  # adaptive tools: within their tolerance
                assert r["sum_rule"] < max(1e-6, 10 * r["accuracy"].get("rtol", 0.0)), r


LIKE_FOR_LIKE = "gearsym (the paper's RK4) − hand-written C"


def test_the_recorded_gearsym_rows_ran_the_c_programs_scheme(raw):
    """The rows timed against the C are the same computation: the C's exponents to rounding, every model."""
    rows = [v for v in summary.summarise(raw)["verdicts"] if v["what"].startswith(LIKE_FOR_LIKE)]
    assert len(rows) == len(raw["models"]) and all(v["met"] for v in rows), rows


def test_gearsym_rows_with_the_crossings_located_are_not_like_for_like_with_the_c(raw):
    located = copy.deepcopy(raw)
    for m in located["models"].values():
        m["fixed"]["gearsym"] = m["fixed"]["gearsym (crossings located)"]
    rows = [v for v in summary.summarise(located)["verdicts"] if v["what"].startswith(LIKE_FOR_LIKE)]
    assert rows and not any(v["met"] for v in rows)
    assert all(v["value"] > 1e-4 for v in rows)  # the plain scheme's error at the kinks, not rounding


def _model(errors_by_setting: dict[str, float], gearsym_error: float) -> dict:
    """A synthetic record: one periodic point; gearsym and a C build at 200 steps, SciPy on a ladder."""
    ref = {"0.5": {"omega": 0.5, "reference": [0.0, -1.0], "converged": True}}

    def rec(err: float, seconds: float, acc: dict) -> dict:
        return {"name": "x", "setup_seconds": 0.0, "setup_note": "", "accuracy": acc,
                "points": {"0.5": {"seconds": [seconds], "exponents": [err, -1.0], "sum": -1.0 + err - 0.32}}}

    ladder = {k: rec(e, 10.0 / float(k), {"rtol": float(k), "atol": float(k)}) for k, e in errors_by_setting.items()}
    return {"zeta": 0.08, "reference": ref,
            "fixed": {"gearsym": rec(gearsym_error, 0.001, {"steps": 200}),
                      "C -O3": rec(gearsym_error, 0.002, {"steps": 200})},
            "precision": {"SciPy RK45": ladder}}


def test_equal_accuracy_takes_the_loosest_tolerance_at_least_as_accurate():
    s = summary.summarise_model(_model({"1e-04": 3e-3, "1e-06": 5e-4, "1e-08": 1e-7}, gearsym_error=1e-3), 0.08)
    eq = s["equal_accuracy"]["gearsym"]["SciPy RK45"]
    assert eq["setting"] == "1e-06" and eq["reached"]
    assert eq["vs_gearsym"] == pytest.approx((10.0 / 1e-6) / 0.001)
    assert s["tools"]["gearsym"]["vs_c"] == pytest.approx(0.5)
    assert s["c_reference"] == "C -O3"


def test_equal_accuracy_says_when_no_tolerance_reaches_it():
    s = summary.summarise_model(_model({"1e-04": 3e-3, "1e-06": 2e-3}, gearsym_error=1e-3), 0.08)
    eq = s["equal_accuracy"]["gearsym"]["SciPy RK45"]
    assert eq["setting"] == "1e-06" and not eq["reached"]


def test_chaotic_points_are_kept_apart_from_the_error():
    m = _model({"1e-04": 3e-3}, gearsym_error=1e-3)
    m["reference"]["0.7"] = {"omega": 0.7, "reference": [0.05, -1.0], "converged": False}
    for rec in [*m["fixed"].values(), *m["precision"]["SciPy RK45"].values()]:
        rec["points"]["0.7"] = {"seconds": [0.0], "exponents": [0.04, -1.0], "sum": -0.96}
    s = summary.summarise_model(m, 0.08)
    assert s["tools"]["gearsym"]["errors"] == {"periodic": pytest.approx(1e-3), "chaotic": pytest.approx(0.01)}
    assert s["chaotic_omegas"] == [0.7] and s["periodic_omegas"] == [0.5]


def test_a_missed_target_is_reported_as_missed(raw):
    slow = copy.deepcopy(raw)
    for m in slow["models"].values():
        for p in m["fixed"]["gearsym"]["points"].values():
            p["seconds"] = [x * 100 for x in p["seconds"]]
    rows = {v["what"]: v for v in summary.summarise(slow)["verdicts"]}
    assert not rows["gearsym / hand-written C, per point, one_stage"]["met"]


ORBITS = REPO / "bench" / "results" / "orbits.json"


def test_the_orbits_record_is_a_full_run_and_its_section_says_what_it_gives(tmp_path):
    """``python -m bench.orbits``: the whole period-1 curve (folds located) against the 191-point sweep."""
    from bench.orbits import report as orbits_report
    from bench.orbits.__main__ import summary as orbits_summary

    record = json.loads(ORBITS.read_text())
    assert record["sweep"]["points"] == 191 and record["range"] == [0.1, 2.0]
    assert all(len(v) == record["repeats"] >= 3 for v in record["seconds"].values())
    assert {b["type"] for b in record["curve"]["bifurcations"]} >= {"fold", "period doubling"}
    s = orbits_summary(record)
    assert s == record["summary"]
    assert f"**{s['curve_over_sweep']:.2f}×**" in report.PAGE.read_text()
    from matplotlib.image import imread

    fig = orbits_report.figure(record, tmp_path / "orbits-speed.png")
    new, committed = imread(fig), imread(orbits_report.FIGURE)
    assert new.shape == committed.shape and abs(new - committed).mean() < 2e-3, "docs/figures/orbits-speed.png differs"
