"""Measured data (issue 5, first layer): reading and checking tidy CSV files, simulated measurements,
forcing-period windows and the held-out split, ``gearsym simulate``."""
from __future__ import annotations

import argparse
import math

import numpy as np
import pytest
import sympy as sp

import conftest
from gearsym import Integration, load_measurements, phase_trajectory, simulate_measurements
from gearsym.cli import simulate as simulate_cli
from gearsym.data import DataError, write_measurements
from gearsym.errors import GearsymError

T = 2 * math.pi


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def recorded(model, periods: int, discard: int) -> Integration:
    """The model's scheme recording ``periods`` periods after ``discard`` transient ones."""
    return model.integration.run(discard + periods, discard)


@pytest.fixture(scope="module")
def simulated(one_stage):
    """Two records at different operating conditions, with velocities and 1 % noise."""
    return simulate_measurements(one_stage, options=recorded(one_stage, 6, 20), samples_per_period=25,
                                 noise=0.01, seed=3,
                                 records=[{"omega": 1.2, "B1": 3.0}, {"omega": 1.6}], velocities=True)


def write_csv(path, header, rows):
    path.write_text("\n".join([header, *(",".join(map(str, r)) for r in rows)]) + "\n")
    return path


def samples(periods=4, per_period=25, start=0.0, **columns):
    """Rows (tau, x) of an evenly sampled sine, ``periods`` whole periods plus the end point."""
    tau = start + (T / per_period) * np.arange(periods * per_period + 1)
    return [[repr(float(t)), repr(float(np.sin(t)))] for t in tau]


# --------------------------------------------------------------------------- simulate -> write -> load
def test_round_trip_gives_the_same_arrays(simulated, one_stage, tmp_path):
    path = write_measurements(simulated, tmp_path / "sim.csv")
    assert path.read_text().splitlines()[0] == "tau,record,omega,B1,x,v"
    data = load_measurements(path, one_stage.system)
    assert [r.record for r in data] == ["1", "2"] and data.observed == ("x", "v")
    for number, record in enumerate(data, 1):
        rows = simulated.rows_of(number)
        assert rows.size == 6 * 25 + 1 == record.samples
        np.testing.assert_array_equal(record.tau, simulated["tau"][rows])
        for state in ("x", "v"):
            np.testing.assert_array_equal(record[state], simulated[state][rows])
        assert record.samples_per_period == pytest.approx(25, rel=1e-9)
        assert record.period == pytest.approx(T) and record.lines == (rows[0] + 2, rows[-1] + 2)
    assert data[0].conditions == {"omega": 1.2, "B1": 3.0} and data[1].conditions == {"omega": 1.6, "B1": 4.0}
    # deterministic bytes: the same table written twice, and the same seed simulated twice
    assert write_measurements(simulated, tmp_path / "again.csv").read_bytes() == path.read_bytes()


def test_simulated_samples_are_engine_steps_and_seeds_matter(one_stage, simulated):
    again = simulate_measurements(one_stage, options=recorded(one_stage, 6, 20), samples_per_period=25,
                                  noise=0.01, seed=3,
                                  records=[{"omega": 1.2, "B1": 3.0}, {"omega": 1.6}], velocities=True)
    np.testing.assert_array_equal(again["x"], simulated["x"])
    other = simulate_measurements(one_stage, options=recorded(one_stage, 6, 20), samples_per_period=25,
                                  noise=0.01, seed=4,
                                  records=[{"omega": 1.2, "B1": 3.0}, {"omega": 1.6}], velocities=True)
    assert not np.array_equal(other["x"], simulated["x"])
    np.testing.assert_array_equal(other.clean["x"], simulated.clean["x"])
    # the clean signal is every 8th RK4 step (200 steps/period) of the engine's run at the record's conditions
    run = phase_trajectory(one_stage, options=recorded(one_stage, 6, 20), omega=1.6, B1=4.0)
    np.testing.assert_array_equal(simulated.clean["x"][simulated.rows_of(2)], run["x"][::8])
    assert simulated.steps_per_period == 200 and simulated.parameters[0]["omega"] == 1.2


def test_noise_has_the_asked_relative_size(one_stage):
    table = simulate_measurements(one_stage, options=recorded(one_stage, 40, 20), samples_per_period=50, noise=0.05,
                                  seed=1)
    clean, noisy = table.clean["x"], table["x"]
    assert table.noise_std[0]["x"] == pytest.approx(0.05 * np.std(clean))
    residual = noisy - clean
    assert np.std(residual) / np.std(clean) == pytest.approx(0.05, rel=0.1)  # 2001 samples: ~1.6 % spread
    assert abs(np.mean(residual)) < 4 * 0.05 * np.std(clean) / math.sqrt(residual.size)
    quiet = simulate_measurements(one_stage, options=recorded(one_stage, 3, 5), samples_per_period=20)
    np.testing.assert_array_equal(quiet["x"], quiet.clean["x"])
    assert quiet.columns == ("tau", "record", "x")  # no conditions, no velocities unless asked


def test_samples_must_divide_the_engine_steps(one_stage):
    with pytest.raises(GearsymError, match="must divide the engine's 200 steps"):
        simulate_measurements(one_stage, options=recorded(one_stage, 3, 0), samples_per_period=30)
    with pytest.raises(GearsymError, match="unknown parameter 'omgea'"):
        simulate_measurements(one_stage, options=recorded(one_stage, 3, 0), samples_per_period=20,
                              records=[{"omgea": 1.0}])
    with pytest.raises(GearsymError, match="noise"):
        simulate_measurements(one_stage, options=recorded(one_stage, 3, 0), samples_per_period=20, noise=-0.1)


# --------------------------------------------------------------------------- conditions, files, windows
def test_conditions_override_the_defaults_per_record(one_stage, tmp_path):
    rows = samples(3)
    path = write_csv(tmp_path / "runs.csv", "record,omega,tau,x",
                     [["a", 1.2, *r] for r in rows] + [["b", 0.9, *r] for r in rows] + [["c", 1.5, *r] for r in rows])
    data = load_measurements(path, one_stage.system, zeta=0.12)
    assert [r.record for r in data] == ["a", "b", "c"]
    assert [data.parameters(r)["omega"] for r in data] == [1.2, 0.9, 1.5]
    assert all(data.parameters(r)["zeta"] == 0.12 and data.parameters(r)["B1"] == 4.0 for r in data)
    assert data.defaults["omega"] == 1.5  # the model's default, untouched


def test_several_files_number_records_per_file(one_stage, tmp_path):
    a = write_csv(tmp_path / "a.csv", "tau,x", samples(3))
    b = write_csv(tmp_path / "b.csv", "record,tau,x,omega", [[1, *r, 1.1] for r in samples(4)]
                  + [[2, *r, 1.3] for r in samples(3)])
    data = load_measurements([a, b], one_stage.system)
    assert [(r.source.name, r.record) for r in data] == [("a.csv", "1"), ("b.csv", "1"), ("b.csv", "2")]
    assert data.sources == (a, b)
    assert data.find("1", source="b.csv").conditions == {"omega": 1.1}
    assert data.find("2").lines == (2 + 101, 2 + 101 + 75)
    with pytest.raises(GearsymError, match="more than one record '1'"):
        data.find("1")


def test_windows_are_whole_forcing_periods(simulated, one_stage, tmp_path):
    data = load_measurements(write_measurements(simulated, tmp_path / "sim.csv"), one_stage.system)
    windows = data[0].windows()
    assert [w.index for w in windows] == list(range(6))  # 151 samples: 6 whole periods and the end point
    for w in windows:
        assert w.tau.size == 25 and w.start == pytest.approx(w.index * T)
        assert np.all(w.tau >= w.start - 1e-9) and np.all(w.tau < w.stop - 1e-9)
        np.testing.assert_array_equal(w.observed["v"], data[0]["v"][25 * w.index:25 * (w.index + 1)])
    assert len(data.windows()) == 12


def test_a_window_needs_every_sample_of_its_period(one_stage, tmp_path):
    for count, whole in ((100, 4), (99, 3), (101, 4)):  # 25 samples per period
        path = write_csv(tmp_path / f"n{count}.csv", "tau,x", samples(4)[:count])
        windows = load_measurements(path, one_stage.system)[0].windows()
        assert len(windows) == whole and all(w.tau.size == 25 for w in windows), count


def test_windows_with_a_fractional_number_of_samples_per_period(one_stage, tmp_path):
    rows = samples(periods=4, per_period=41, start=3.0)[::2]  # 20.5 samples per period, tau starts at 3
    data = load_measurements(write_csv(tmp_path / "f.csv", "tau,x", rows), one_stage.system)
    record = data[0]
    assert record.samples_per_period == pytest.approx(20.5)
    windows = record.windows()
    assert len(windows) == 4  # 83 samples cover 4.05 periods
    sizes = [w.tau.size for w in windows]
    assert sorted(set(sizes)) == [20, 21] and windows[0].rows.start == 0
    assert all(a.rows.stop == b.rows.start for a, b in zip(windows, windows[1:]))  # disjoint, contiguous
    for w in windows:
        assert w.start == pytest.approx(3.0 + w.index * T)
        assert np.all(w.tau >= w.start) and np.all(w.tau < w.stop)


def test_held_out_split_by_time(one_stage, tmp_path):
    data = load_measurements(write_csv(tmp_path / "long.csv", "tau,x", samples(8)), one_stage.system)
    train, held = data.split(0.25)
    record, a, b = data[0], train[0], held[0]
    assert [w.index for w in a.windows()] == list(range(6))
    assert [w.index for w in b.windows()] == [6, 7]  # windows keep their place in the record
    np.testing.assert_array_equal(np.concatenate([a.tau, b.tau]), record.tau)
    np.testing.assert_array_equal(np.concatenate([a["x"], b["x"]]), record["x"])
    assert a.tau[-1] < 6 * T <= b.tau[0] + 1e-9 and b.samples == 2 * 25 + 1
    assert b.lines == (2 + 150, 2 + 200) and b.windows()[0].tau[0] == pytest.approx(6 * T)
    assert [r.samples for r in data.split(0.5)[1]] == [4 * 25 + 1]
    assert [w.index for w in data.split(0.1)[1].windows()] == [7]  # at least one period is held out
    short = load_measurements(write_csv(tmp_path / "short.csv", "tau,x", samples(3)), one_stage.system)
    assert [[w.index for w in part[0].windows()] for part in short.split(0.25)] == [[0, 1], [2]]
    with pytest.raises(GearsymError, match="held_out"):
        data.split(1.0)


def test_physical_time_with_a_time_scale(one_stage, tmp_path):
    rows = [[repr(float(t) / 250.0), x] for t, x in samples(3)]
    path = write_csv(tmp_path / "t.csv", "t,x", rows)
    record = load_measurements(path, one_stage.system, time_scale=250.0)[0]
    assert record.tau[-1] == pytest.approx(3 * T) and record.samples_per_period == pytest.approx(25)
    with pytest.raises(DataError, match="samples per forcing period.*check the time scale"):
        load_measurements(path, one_stage.system, time_scale=2500.0)


def test_a_model_whose_own_time_is_t(tmp_path):
    path = write_csv(tmp_path / "lorenz.csv", "t,x,z,rho", [[repr(k / 20), k, 2 * k, 28] for k in range(61)])
    record = load_measurements(path, conftest.system("lorenz"))[0]  # period 1 in t: 20 samples per period, 3 periods
    assert record.samples_per_period == pytest.approx(20) and len(record.windows()) == 3
    assert set(record.observed) == {"x", "z"}


def test_two_coordinates_and_a_partial_measurement(tmp_path):
    flexible = conftest.system("flexible_shaft")  # nothing compiled: only names and period
    both = write_csv(tmp_path / "both.csv", "x2,tau,x1,kS", [[1.0, *r, 0.5] for r in samples(3)])
    only = write_csv(tmp_path / "only.csv", "tau,x1", samples(3))
    data = load_measurements([both, only], flexible)
    assert set(data[0].observed) == {"x1", "x2"} and set(data[1].observed) == {"x1"}
    assert data.observed == ("x1", "x2") and data.parameters(data[0])["kS"] == 0.5
    assert data.parameters(data[1])["kS"] == 0.1
    with pytest.raises(DataError, match="Did you mean 'x.' or 'x.'") as caught:
        load_measurements(write_csv(tmp_path / "x.csv", "tau,x", samples(3)), flexible)
    assert caught.value.column == "x"


def test_derivative_channels_are_per_unit_of_the_files_time(one_stage, tmp_path):
    """A t file's derivatives are per unit t: with tau = s t the model's output is scaled, s dx/dtau and
    s^2 d2x/dtau2; a tau file's are per unit tau."""
    from gearsym.data.measurements import channel_expression

    system = one_stage.system
    x, v = system.states
    s = 250.0
    rows = [[repr(float(t) / s), x_, x_] for t, x_ in samples(3)]
    record = load_measurements(write_csv(tmp_path / "t.csv", "t,x_dot,x_ddot", rows), system, time_scale=s)[0]
    assert set(record.observed) == {"x_dot", "x_ddot"}
    assert channel_expression(record.channels["x_dot"], system) == s * v
    assert channel_expression(record.channels["x_ddot"], system) == s**2 * system.rhs[1]
    own = load_measurements(write_csv(tmp_path / "tau.csv", "tau,x_ddot", samples(3)), system)[0]
    assert channel_expression(own.channels["x_ddot"], system) == system.rhs[1]


def test_a_declared_combination_is_a_channel(tmp_path):
    from gearsym.data.measurements import channel_expression

    flexible = conftest.system("flexible_shaft")
    path = write_csv(tmp_path / "acc.csv", "tau,acc", samples(3))
    data = load_measurements(path, flexible, channels={"acc": "r1*x1_ddot + 0.5*x2"})
    expr = channel_expression(data[0].channels["acc"], flexible)
    assert sp.simplify(expr - (sp.Symbol("r1", real=True) * flexible.rhs[1] + 0.5 * flexible.states[2])) == 0
    with pytest.raises(GearsymError, match="channel acc: unknown name x3_ddot"):
        load_measurements(path, flexible, channels={"acc": "x3_ddot"})
    with pytest.raises(GearsymError, match="channel other is declared but no file has a column other"):
        load_measurements(path, flexible, channels={"acc": "x1", "other": "x2"})
    with pytest.raises(DataError, match="unknown column.*x_ddot"):
        load_measurements(write_csv(tmp_path / "b.csv", "tau,x1_dddot", samples(3)), flexible)


# --------------------------------------------------------------------------- bad files
GOOD = samples(3)


def bad(case):
    """Header and rows of each bad file, with the line and column its error must name."""
    rows = [list(r) for r in GOOD]
    if case == "no time column":
        return "x", [[r[1]] for r in rows], 1, None
    if case == "unknown column":
        return "tau,xx", rows, 1, "xx"
    if case == "t without a time scale":
        return "t,x", rows, 1, "t"
    if case == "both times":
        return "tau,t,x", [[r[0], *r] for r in rows], 1, "t"
    if case == "no state":
        return "tau,omega", [[r[0], 1.2] for r in rows], 1, None
    if case == "duplicate column":
        return "tau,x,x", [[*r, r[1]] for r in rows], 1, "x"
    if case == "empty cell":
        rows[3][1] = ""
        return "tau,x", rows, 5, "x"
    if case == "NaN":
        rows[10][1] = "nan"
        return "tau,x", rows, 12, "x"
    if case == "not a number":
        rows[7][0] = "0.5s"
        return "tau,x", rows, 9, "tau"
    if case == "cell count":
        rows[4].append("1")
        return "tau,x", rows, 6, None
    if case == "condition varies":
        return "tau,x,omega", [[*r, 1.2 if i < 40 else 1.3] for i, r in enumerate(rows)], 42, "omega"
    if case == "bad condition value":
        return "record,tau,x,eta", [[1, *r, 1.0] for r in rows] + [[2, *r, -1.0] for r in rows], 2 + len(rows), "eta"
    if case == "time not increasing":
        rows[20], rows[21] = rows[21], rows[20]
        return "tau,x", rows, 23, "tau"
    if case == "uneven":
        del rows[30]
        return "tau,x", rows, 32, "tau"
    if case == "too few samples per period":
        return "tau,x", rows[::2], 2, "tau"
    if case == "too short":
        return "record,tau,x", [[1, *r] for r in rows] + [[2, *r] for r in rows[:60]], 2 + len(rows), "tau"
    if case == "record again":
        return "record,tau,x", [[1, *r] for r in rows] + [[2, *r] for r in rows] + [[1, *r] for r in rows[:5]], \
            2 + 2 * len(rows), "record"
    raise AssertionError(case)


MESSAGES = {
    "no time column": "no time column: name it tau",
    "unknown column": "unknown column. Did you mean 'x'",
    "t without a time scale": "pass time_scale=",
    "both times": "both tau and t",
    "no state": "no measured state",
    "duplicate column": "appears twice",
    "empty cell": "empty cell",
    "NaN": "finite number",
    "not a number": "'0.5s' is not a number",
    "cell count": "3 cells, but the header",
    "condition varies": "omega varies within record 1",
    "bad condition value": "must not be negative",
    "time not increasing": "does not increase",
    "uneven": r"not evenly spaced.*tolerance 0.001",
    "too few samples per period": "12.5 samples per forcing period",
    "too short": r"too short to fit.*2 whole.*at least 3",
    "record again": "record 1 appears again",
}


@pytest.mark.parametrize("case", list(MESSAGES))
def test_bad_files_say_where(case, one_stage, tmp_path):
    header, rows, line, column = bad(case)
    path = write_csv(tmp_path / "bad.csv", header, rows)
    with pytest.raises(DataError, match=MESSAGES[case]) as caught:
        load_measurements(path, one_stage.system)
    error = caught.value
    assert (error.source, error.line, error.column) == (path, line, column)
    assert str(error).startswith(f"{path}, line {line}" + (f", column {column!r}" if column else "") + ": ")


def test_unreadable_and_empty_files(one_stage, tmp_path):
    with pytest.raises(DataError, match="no such file"):
        load_measurements(tmp_path / "missing.csv", one_stage.system)
    (tmp_path / "empty.csv").write_text("\n\n")
    with pytest.raises(DataError, match="empty"):
        load_measurements(tmp_path / "empty.csv", one_stage.system)
    (tmp_path / "header.csv").write_text("tau,x\n")
    with pytest.raises(DataError, match="no data rows"):
        load_measurements(tmp_path / "header.csv", one_stage.system)


def test_the_limits_can_be_relaxed(one_stage, tmp_path):
    path = write_csv(tmp_path / "short.csv", "tau,x", samples(2, per_period=10))
    record = load_measurements(path, one_stage.system, min_samples_per_period=10, min_periods=2)[0]
    assert len(record.windows()) == 2
    with pytest.raises(GearsymError, match="given twice"):
        load_measurements([path, tmp_path / ".." / tmp_path.name / "short.csv"], one_stage.system, min_periods=2)
    with pytest.raises(GearsymError, match="time_scale"):
        load_measurements(path, one_stage.system, time_scale=0)


# --------------------------------------------------------------------------- gearsym simulate
def cli_args(*argv):
    parser = argparse.ArgumentParser()
    simulate_cli.add_arguments(parser)
    return parser.parse_args(list(argv))


def test_simulate_command_writes_a_loadable_file(one_stage, tmp_path, capsys):
    out = tmp_path / "cli.csv"
    args = cli_args("one_stage", "--set", "zeta=0.1", "--periods", "14", "--discard", "10", "--samples-per-period",
                    "25", "--noise", "0.02", "--seed", "5", "--record", "omega=1.2,B1=4", "--record", "omega=1.5",
                    "--velocities", "--out", str(out))
    assert simulate_cli.run(args) == 0
    assert "2 record(s) of 101 samples" in capsys.readouterr().out
    data = load_measurements(out, one_stage.system, zeta=0.1)
    assert [r.conditions for r in data] == [{"omega": 1.2, "B1": 4.0}, {"omega": 1.5, "B1": 4.0}]
    assert data.observed == ("x", "v") and len(data.windows()) == 8
    # the same as the Python API with the same settings, to the byte
    api = simulate_measurements(conftest.system("one_stage", zeta=0.1), options=Integration(periods=14, discard=10),
                                samples_per_period=25, noise=0.02, seed=5,
                                records=[{"omega": 1.2, "B1": 4}, {"omega": 1.5}], velocities=True,
                                out=tmp_path / "api.csv")
    assert api.parameters[0]["zeta"] == 0.1
    assert (tmp_path / "api.csv").read_bytes() == out.read_bytes()


def test_simulate_command_rejects_bad_records(tmp_path):
    for text, message in (("omega", "NAME=NUMBER"), ("omega=fast", "is not a number"), ("omega=1,omega=2", "twice")):
        with pytest.raises(GearsymError, match=message):
            simulate_cli.run(cli_args("one_stage", "--record", text, "--out", str(tmp_path / "x.csv")))
