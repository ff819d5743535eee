"""Sweeps: the grid, continuation hand-over, resume after an interruption, threads, and the CLI."""
from __future__ import annotations

import json
import multiprocessing
import os
import time

import numpy as np
import pytest

import conftest
from conftest import interrupt_after
from gearsym import Execution, Integration, lyapunov_spectrum, read_sweep, run_sweep
from gearsym.cli import main
from gearsym.errors import GearsymError
from gearsym.sweep import SweepInterrupted, parse_axis

RUN = Integration(periods=60, discard=20)
SHORT = dict(options=RUN)


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


# ------------------------------------------------------------------ grid
def test_ranges_are_counted_in_decimal_and_include_stop():
    axis = parse_axis("omega=0.1:2.0:0.01")
    assert len(axis.values) == 191 and axis.values[0] == 0.1 and axis.values[-1] == 2.0
    assert 0.3 in axis.values and 1.36 in axis.values  # not 0.30000000000000004
    assert parse_axis("kS=1.0,0,0.1").values == (0.0, 0.1, 1.0)
    assert parse_axis("D=2").values == (2.0,)


@pytest.mark.parametrize("text, words", [
    ("omega", "NAME=START:STOP:STEP"), ("omega=1:2", "NAME=START:STOP:STEP"), ("omega=a,b", "NAME=V1"),
    ("omega=1:2:0", "step must be nonzero"), ("omega=2:1:0.1", "lead from start to stop"),
    ("kS=0,0.1,0", "repeat"), ("omega=0:1e9:1e-9", "more than the 1000000 one --param may have; give a larger step"),
])
def test_bad_axes_say_what_is_expected(text, words):
    with pytest.raises(GearsymError, match=words):
        parse_axis(text)


def test_unknown_or_doubly_given_parameters_are_refused(one_stage):
    with pytest.raises(GearsymError, match="unknown parameter 'omgea'.*omega"):
        run_sweep(one_stage, ["omgea=1,2"], **SHORT)
    with pytest.raises(GearsymError, match="both swept"):
        run_sweep(one_stage, ["omega=1,2"], omega=1.5, **SHORT)
    with pytest.raises(GearsymError, match="must be positive|must not be negative"):
        run_sweep(one_stage, ["zeta=-1,0.1"], **SHORT)


# ------------------------------------------------------------------ what a point is
def test_continuation_hands_the_final_state_on(one_stage):
    result = run_sweep(one_stage, {"omega": [1.0, 1.1, 1.2]}, **SHORT)
    state = None
    for i, w in enumerate((1.0, 1.1, 1.2)):
        direct = lyapunov_spectrum(one_stage, options=RUN, y0=state, omega=w)
        assert result["lambda_1"][i] == direct.exponents[0] and result["A_x"][i] == direct.amplitude["x"]
        assert result["final_x"][i] == direct.final_state["x"]
        state = [direct.final_state["x"], direct.final_state["v"]]
    from_default = lyapunov_spectrum(one_stage, options=RUN, omega=1.2)
    assert result["final_x"][2] != from_default.final_state["x"]  # it did not restart


def test_independent_points_start_from_the_initial_state(one_stage):
    result = run_sweep(one_stage, {"omega": [1.0, 1.2]}, mode="independent", y0=[-1.0, 0.3], **SHORT)
    direct = lyapunov_spectrum(one_stage, options=RUN, y0=[-1.0, 0.3], omega=1.2)
    assert result["lambda_1"][1] == direct.exponents[0] and set(result["direction"]) == {"independent"}


def test_both_directions_go_up_then_back_down_from_where_up_ended(one_stage):
    result = run_sweep(one_stage, {"omega": [1.0, 1.1, 1.2]}, direction="both", **SHORT)
    assert result["direction"].tolist() == ["up"] * 3 + ["down"] * 3
    assert result["omega"].tolist() == [1.0, 1.1, 1.2, 1.2, 1.1, 1.0]
    top = [result["final_x"][2], result["final_v"][2]]
    down = lyapunov_spectrum(one_stage, options=RUN, y0=top, omega=1.2)
    assert result["final_x"][3] == down.final_state["x"]


def test_regime_column_names_the_motion(one_stage):
    result = run_sweep(one_stage, {"omega": [1.2, 1.6]}, mode="independent",
                       options=Integration(periods=400, discard=100))
    assert result["regime"].tolist() == ["chaotic", "periodic"]


# ------------------------------------------------------------------ files, resume, threads
#: how long the sweep's own process waits at most for a live forked worker to take a task (it takes milliseconds)
WORKER_START = 60.0


def share_with_a_forked_worker(monkeypatch, in_the_worker=None) -> list:
    """Make the next sweep on forked workers share its tasks whatever the machine's load, with no race: the
    sweep's own process, once it holds a task, waits until a forked worker has taken one too. A forked worker
    then calls ``in_the_worker()`` before it computes. Returns the points computed in the sweep's own process
    (a forked worker would count in its own copy of the list)."""
    from gearsym.sweep.point_runs import PointRuns

    worker_took_a_task = multiprocessing.get_context("fork").Event()  # made before the fork: shared with it
    sweep_process, task, computed_here = os.getpid(), PointRuns.task, []

    def shared(self, compiled, points, state):
        if os.getpid() != sweep_process:
            worker_took_a_task.set()
            if in_the_worker:
                in_the_worker()
        else:  # (a worker that took a task has said so before it can end: no child left means none will)
            deadline = time.monotonic() + WORKER_START
            while not worker_took_a_task.wait(0.05):
                assert multiprocessing.active_children() and time.monotonic() < deadline, \
                    "no forked worker took a task, and none is alive: did the sweep fork?"
            computed_here.extend(points)
        yield from task(self, compiled, points, state)

    monkeypatch.setattr(PointRuns, "task", shared)
    return computed_here


@pytest.mark.parametrize("mode, jobs", [("continuation", 2), ("independent", 2), ("continuation", 1)])
def test_an_interrupted_sweep_resumes_to_the_same_files(tmp_path, one_stage, mode, jobs):
    axes = ["omega=0.9:1.3:0.1", "B1=3.5,4"]
    whole = run_sweep(one_stage, axes, mode=mode, execution=Execution(jobs=jobs), out=tmp_path / "whole.csv", **SHORT)
    assert len(whole) == 10
    part = tmp_path / "part.csv"
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(one_stage, axes, mode=mode, execution=Execution(jobs=jobs), out=part, on_point=interrupt_after(4),
                  **SHORT)
    assert info.value.done >= 4 and "run the same command again" in str(info.value)
    kept = part.read_text().splitlines()
    assert len(kept) - 1 == info.value.done  # every finished point is on disk
    part.write_text(part.read_text() + kept[-1][:10])  # as if killed while writing a row
    resumed = run_sweep(one_stage, axes, mode=mode, execution=Execution(jobs=jobs), out=part, **SHORT)
    assert part.read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert (tmp_path / "part.poincare.csv").read_bytes() == (tmp_path / "whole.poincare.csv").read_bytes()
    assert np.array_equal(resumed["lambda_1"], whole["lambda_1"])
    again = run_sweep(one_stage, axes, mode=mode, execution=Execution(jobs=jobs), out=part, on_point=interrupt_after(1),
                      **SHORT)
    assert len(again) == 10  # complete: nothing left to run, nothing recomputed


@pytest.mark.parametrize("parallel", ["threads", "processes"])
def test_threads_and_processes_do_not_change_a_single_bit(tmp_path, one_stage, parallel, monkeypatch):
    axes = ["omega=0.9:1.4:0.1", "B1=3.5,4"]
    run_sweep(one_stage, axes, mode="independent", execution=Execution(jobs=1, parallel=parallel),
              out=tmp_path / "j1.csv", **SHORT)
    computed_here = share_with_a_forked_worker(monkeypatch) if parallel == "processes" else None
    run_sweep(one_stage, axes, mode="independent", execution=Execution(jobs=2, parallel=parallel),
              out=tmp_path / "j2.csv", **SHORT)
    if parallel == "processes":  # the two processes both computed
        assert 0 < len(computed_here) < 12
    for name in ("j{}.csv", "j{}.poincare.csv"):
        assert (tmp_path / name.format(1)).read_bytes() == (tmp_path / name.format(2)).read_bytes()


def test_the_sweeps_own_process_computes_beside_the_processes_it_forks(one_stage, monkeypatch):
    computed_here = share_with_a_forked_worker(monkeypatch)
    result = run_sweep(one_stage, ["omega=0.9:1.4:0.1"], mode="independent",
                       execution=Execution(jobs=2, parallel="processes"), **SHORT)
    assert len(result) == 6 and 0 < len(computed_here) < 6  # the rest came from the forked worker


def test_a_worker_process_that_dies_is_reported_and_the_points_finished_here_are_kept(tmp_path, one_stage,
                                                                                      monkeypatch):
    share_with_a_forked_worker(monkeypatch, in_the_worker=lambda: os._exit(3))
    out, axes = tmp_path / "s.csv", ["omega=0.9:1.4:0.1"]
    with pytest.raises(GearsymError, match=r"a sweep worker process died \(exit code 3\); the points finished so far "
                                           "are kept"):
        run_sweep(one_stage, axes, mode="independent", execution=Execution(jobs=2, parallel="processes"), out=out,
                  **SHORT)
    assert 0 < len(out.read_text().splitlines()) - 1 < 6
    monkeypatch.undo()
    resumed = run_sweep(one_stage, axes, mode="independent", out=out, on_point=interrupt_after(6), **SHORT)  # (were all
    assert len(resumed) == 6  # six recomputed, the sixth would press Ctrl-C)


def test_an_error_in_a_worker_process_names_the_point():
    with pytest.raises(GearsymError, match=r"at sigma=1000 \(independent\): .*non-finite"):  # the orbit diverges
        run_sweep(conftest.system("lorenz"), ["sigma=10,1000"], mode="independent",
                  execution=Execution(jobs=2, parallel="processes"), options=Integration(periods=10, discard=2))


def test_an_unknown_way_to_run_in_parallel_is_refused(one_stage):
    with pytest.raises(GearsymError, match="parallel='gpu'.*processes, threads"):
        run_sweep(one_stage, ["omega=1.1,1.2"], execution=Execution(parallel="gpu"), **SHORT)


def test_resuming_with_other_options_says_what_differs(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)
    with pytest.raises(GearsymError, match="different sweep.*periods: 60 before, 80 now") as refused:
        run_sweep(one_stage, ["omega=1,1.1"], out=out, options=RUN.run(periods=80))
    assert str(refused.value).endswith("repeat the call it came from; to start again pass overwrite=True or choose "
                                       "another out")  # (Python's spelling: no --flags)
    run_sweep(one_stage, ["omega=1,1.1"], out=out, options=RUN.run(periods=80), overwrite=True)
    assert read_sweep(out).record["periods"] == 80


def test_the_command_line_advises_its_own_flags_where_python_is_advised_keywords(tmp_path, capsys):
    """sweeps.md's Python example after its CLI example was told to 'pass --overwrite'."""
    out = tmp_path / "d2.csv"
    short = ["--periods", "30", "--discard", "10", "--quiet", "--jobs", "1"]
    assert main(["sweep", "one_stage", "--param", "omega=1,1.1", "--out", str(out), *short]) == 0
    assert main(["sweep", "one_stage", "--param", "omega=1.3,1.31", "--out", str(out), *short]) == 2
    err = capsys.readouterr().err
    assert "repeat the command it came from; to start again pass --overwrite or choose another --out" in err
    assert "overwrite=True" not in err and "out=" not in err.replace("--out", "")


def test_a_cache_of_sweeps_starts_again_what_another_sweep_wrote_and_resumes_its_own(tmp_path, one_stage):
    out, computed = tmp_path / "s.csv", []
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT, overwrite="stale", on_point=computed.append)
    assert computed == []  # the same sweep: resumed, nothing to do
    run_sweep(one_stage, ["omega=1,1.1"], out=out, options=RUN.run(periods=80), overwrite="stale",
              on_point=computed.append)
    assert len(computed) == 2 and read_sweep(out).record["periods"] == 80
    with pytest.raises(GearsymError, match="overwrite must be False, True or 'stale', not 'yes'"):
        run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT, overwrite="yes")


def test_a_damaged_sweep_file_is_named_with_its_row(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    run_sweep(one_stage, ["omega=1:1.3:0.1"], out=out, **SHORT)
    lines = out.read_text().splitlines()
    lines[2] = lines[2].rsplit(",", 3)[0]
    out.write_text("\n".join(lines) + "\n")
    with pytest.raises(GearsymError, match=r"s.csv, row 3: .* fields"):
        run_sweep(one_stage, ["omega=1:1.3:0.1"], out=out, **SHORT)
    (tmp_path / "s.json").unlink()
    with pytest.raises(GearsymError, match="cannot be resumed"):
        run_sweep(one_stage, ["omega=1:1.3:0.1"], out=out, **SHORT)


def test_the_table_has_the_documented_columns(tmp_path):
    out = tmp_path / "f.csv"
    result = run_sweep(conftest.system("flexible_shaft"), ["omega=1.4,1.5", "kS=0.1"], out=out, poincare=5, **SHORT)
    assert out.read_text().splitlines()[0] == (
        "omega,kS,direction,A_x1,A_x2,lambda_1,lambda_2,lambda_3,lambda_4,stderr_1,stderr_2,stderr_3,stderr_4,"
        "regime,final_x1,final_v1,final_x2,final_v2")
    assert len(result.strobe["x1"]) == 2 * 5
    record = read_sweep(out).record
    assert record["parameters"]["kS"] == 0.1 and record["model_hash"] == conftest.compiled("flexible_shaft").hash


def test_the_record_lists_the_jumps_and_hysteresis_found(tmp_path, one_stage):
    """one_stage falls off its resonance peak between omega 0.88 and 0.9 going up, and
    earlier going down (the up and down branches coexist there)."""
    out = tmp_path / "j.csv"
    result = run_sweep(one_stage, ["omega=0.8:1.0:0.01"], direction="both", out=out)
    record = json.loads((tmp_path / "j.json").read_text())
    assert record["status"] == "complete" and record["jumps"] == json.loads(json.dumps(result.findings()["jumps"]))
    up = [j for j in record["jumps"] if j["direction"] == "up"]
    assert any(j["from"] <= 0.89 <= j["to"] and j["A_after"] < j["A_before"] / 1.5 for j in up)
    assert record["hysteresis"] and all(h["from"] <= h["to"] for h in record["hysteresis"])


@pytest.mark.parametrize("parallel", ["threads", "processes"])
def test_continuation_lines_in_parallel_do_not_change_a_single_bit(tmp_path, one_stage, parallel, monkeypatch):
    axes = ["omega=0.9:1.3:0.1", "B1=3.5,4"]
    run_sweep(one_stage, axes, direction="both", execution=Execution(jobs=1, parallel=parallel),
              out=tmp_path / "c1.csv", **SHORT)
    computed_here = share_with_a_forked_worker(monkeypatch) if parallel == "processes" else None
    run_sweep(one_stage, axes, direction="both", execution=Execution(jobs=2, parallel=parallel),
              out=tmp_path / "c2.csv", **SHORT)
    if parallel == "processes":  # one line here, the other in the forked worker
        assert len(computed_here) == 10
    assert (tmp_path / "c1.csv").read_bytes() == (tmp_path / "c2.csv").read_bytes()


def test_resume_in_the_down_half_after_a_kill_mid_row(tmp_path, one_stage):
    """Up 0.7 ... 1.0 and down again: at omega = 0.9 the two runs hold different orbits (hysteresis)."""
    axes = ["omega=0.7:1.0:0.1"]
    whole = run_sweep(one_stage, axes, direction="both", out=tmp_path / "whole.csv", **SHORT)
    up, down = ({w: a for w, a, d in zip(whole["omega"], whole["A_x"], whole["direction"]) if d == run}
                for run in ("up", "down"))
    # where both runs of the interrupted sweep below went, the amplitudes differ by more than 5 % (the
    # library's threshold) at 0.9, the up run's larger orbit (measured: there only; 1.0 is chaotic both ways)
    differ = [w for w in (0.8, 0.9, 1.0) if abs(up[w] - down[w]) > 0.05 * max(up[w], down[w])]
    assert differ[:1] == [0.9], (up, down)
    part = tmp_path / "part.csv"
    with pytest.raises(SweepInterrupted):
        run_sweep(one_stage, axes, direction="both", out=part, on_point=interrupt_after(7), **SHORT)
    whole_rows = (tmp_path / "whole.csv").read_text().splitlines()
    part.write_text(part.read_text() + whole_rows[8][:15])  # the 8th point (going down) cut while written
    strobe = tmp_path / "part.poincare.csv"
    strobe.write_text(strobe.read_text() + "0.7,down,0,0.12")  # and its Poincare rows
    partial = read_sweep(part)  # reading an interrupted sweep leaves the cut row out ...
    assert len(partial) == 7 and partial["direction"].tolist() == ["up"] * 4 + ["down"] * 3
    # ... and compares only what both runs have, point by point: the one interval where they differ
    assert partial.findings()["hysteresis"] == [{"coordinate": "x", "from": 0.9, "to": differ[-1]}]
    resumed = run_sweep(one_stage, axes, direction="both", out=part, **SHORT)
    assert part.read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert strobe.read_bytes() == (tmp_path / "whole.poincare.csv").read_bytes()
    assert resumed.findings() == whole.findings() == read_sweep(part).findings()


def test_a_sweep_that_finished_no_point_starts_again_with_new_options(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    with pytest.raises(SweepInterrupted):
        run_sweep(one_stage, ["omega=1,1.1"], out=out, on_point=interrupt_after(1), **SHORT)
    out.write_text(out.read_text().splitlines()[0] + "\n")  # as if stopped before the first point was written
    result = run_sweep(one_stage, ["omega=1,1.1"], out=out, options=RUN.run(periods=80))
    assert len(result) == 2 and read_sweep(out).record["periods"] == 80


def test_missing_poincare_samples_are_not_silently_dropped(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    with pytest.raises(SweepInterrupted):
        run_sweep(one_stage, ["omega=1:1.3:0.1"], out=out, on_point=interrupt_after(2), **SHORT)
    (tmp_path / "s.poincare.csv").unlink()
    with pytest.raises(GearsymError, match="lacks the Poincare samples of 2 finished points"):
        run_sweep(one_stage, ["omega=1:1.3:0.1"], out=out, **SHORT)


# ------------------------------------------------------------------ command line
@pytest.mark.slow
def test_sweep_command(tmp_path, capsys):
    out = tmp_path / "s.csv"
    code = main(["sweep", "one_stage_resonant", "--param", "omega=1.3:1.4:0.05", "--direction", "both",
                 "--periods", "60", "--discard", "20", "--out", str(out), "--plot", str(tmp_path / "s.png"),
                 "--quiet"])
    text, err = capsys.readouterr()
    assert code == 0 and "6 points" in text and "regimes:" in text
    assert (tmp_path / "s.png").stat().st_size > 10_000 and (tmp_path / "s.json").exists()
    code = main(["sweep", "one_stage", "--param", "omega=1,2", "--set", "zetta=1", "--out", str(out), "--quiet"])
    assert code == 2 and "unknown parameter 'zetta'" in capsys.readouterr().err


def test_a_second_writer_on_the_same_file_is_refused(tmp_path, one_stage):
    import fcntl

    out = tmp_path / "s.csv"
    with open(tmp_path / "s.csv.lock", "a") as held:  # as another process running this sweep holds it
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(GearsymError, match="another gearsym process is writing"):
            run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)  # free again
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)  # and released by the sweep itself


def test_independent_points_have_no_direction(one_stage):
    with pytest.raises(GearsymError, match="applies to a continuation"):
        run_sweep(one_stage, ["omega=1,1.1"], mode="independent", direction="both", **SHORT)


# ------------------------------------------------------------------ what the command prints
JUMPY = ["--param", "omega=0.8:1.0:0.01", "--param", "B1=3.5,4", "--direction", "both", "--periods", "60",
         "--discard", "20", "--quiet"]  # one_stage falls off its resonance peak on every line


def test_each_jump_of_a_2d_sweep_names_the_line_it_lies_on(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "one_stage", *JUMPY, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    jumps = [line for line in text.splitlines() if line.startswith("jump in")]
    record = json.loads((tmp_path / "s.json").read_text())
    assert len(jumps) == len(record["jumps"]) >= 4
    for line, j in zip(jumps, record["jumps"]):
        assert line.startswith(f"jump in A_x ({j['direction']}, B1={j['B1']:g}): omega {j['from']:g} -> ")
    assert {j["B1"] for j in record["jumps"]} == {3.5, 4.0}  # the record keeps the other parameter's value
    intervals = [line for line in text.splitlines() if line.startswith("hysteresis in")]
    assert intervals and all("(B1=" in line for line in intervals)


def test_a_long_list_of_jumps_is_summarised_and_points_to_the_record(tmp_path, capsys, monkeypatch):
    from gearsym.sweep import report

    out = tmp_path / "s.csv"
    main(["sweep", "one_stage", *JUMPY, "--out", str(out)])
    jumps = json.loads((tmp_path / "s.json").read_text())["jumps"]
    capsys.readouterr()
    monkeypatch.setattr(report, "LISTED", 2)
    monkeypatch.setattr(report, "LARGEST", 2)
    assert main(["sweep", "one_stage", *JUMPY, "--out", str(out)]) == 0  # complete: only reads and reports
    text = capsys.readouterr().out
    assert f"{len(jumps)} jumps (A_x {len(jumps)}) on " in text
    per_line = next(line for line in text.splitlines() if "per line:" in line)
    for direction in ("up", "down"):
        count = sum(j["direction"] == direction and j["B1"] == 3.5 for j in jumps)
        assert f"{direction}, B1=3.5: {count}" in per_line
    largest = sorted(jumps, key=lambda j: abs(j["A_after"] - j["A_before"]), reverse=True)[:2]
    listed = [line.strip() for line in text.splitlines() if line.strip().startswith("jump in")]
    assert len(listed) == 2 and all(f"A {j['A_before']:.4g} -> {j['A_after']:.4g}" in line
                                    for line, j in zip(listed, largest))
    assert f"{tmp_path / 's.json'} (\"jumps\")" in text


def test_sweep_plot_shows_the_coordinate_asked_for(tmp_path, capsys, monkeypatch):
    import gearsym.cli.sweep as command

    drawn = []
    real = command.plot_sweep
    monkeypatch.setattr(command, "plot_sweep", lambda *a, **k: drawn.append(real(*a, **k)) or drawn[-1])
    out = tmp_path / "f.csv"
    code = main(["sweep", "flexible_shaft", "--param", "omega=1.3:1.5:0.1", "--periods", "30", "--discard", "10",
                 "--poincare", "5", "--out", str(out), "--plot", str(tmp_path / "f.png"), "--coordinate", "x2",
                 "--quiet"])
    assert code == 0
    result = read_sweep(out)
    amplitude, _, bifurcation, _ = drawn[0].axes[:4]
    assert np.array_equal(amplitude.lines[0].get_ydata(), result["A_x2"])
    assert np.array_equal(np.sort(bifurcation.lines[0].get_ydata()), np.sort(result.strobe["x2"]))
    assert "x2" in bifurcation.get_title() and "x2" in amplitude.get_ylabel()


def test_an_unknown_coordinate_is_refused_before_any_point_runs(tmp_path, capsys, monkeypatch):
    import gearsym.cli.sweep as sweep_command

    monkeypatch.setattr(sweep_command, "run_sweep", lambda *a, **k: pytest.fail("the sweep ran"))
    argv = ["sweep", "flexible_shaft", "--param", "omega=1,2", "--out", str(tmp_path / "s.csv"), "--quiet"]
    assert main([*argv, "--plot", str(tmp_path / "s.png"), "--coordinate", "x3"]) == 2
    err = capsys.readouterr().err
    assert "--coordinate x3: no such coordinate" in err and "x1, x2" in err and len(err.splitlines()) == 1
    assert main([*argv, "--coordinate", "x2"]) == 2 and "add --plot" in capsys.readouterr().err
