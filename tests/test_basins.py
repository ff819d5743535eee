"""Basins of attraction (gearsym/analysis/basins.py) and their fractions along a parameter
(gearsym/sweep/basin_continuation.py), against independent SciPy computations."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gearsym
from gearsym import Execution, FirstOrderSystem, Integration
import gearsym.jobs.basins as basin_jobs
import gearsym.sweep.basin_continuation as basin_continuation
from gearsym.analysis.basins import DIVERGED, UNDETERMINED, basin_map
from gearsym.jobs.basins import BasinMapJob
from gearsym.cli import main
from gearsym.figures.basins import plot_basin_map
from gearsym.opening import ModelRequest, open_model
from gearsym.physical.basins import GivenGrid, GridAxis
from gearsym.physical.sweeps import MeasuredAxis
from gearsym.sweep.grid import parse_axis
from gearsym.sweep.basin_continuation import APPEARS, VANISHES, continue_basins

import conftest

#: the forced Duffing oscillator of models/duffing.py: x'' + 2 zeta x' + x + beta x^3 = F cos(omega t)
ZETA, BETA, F = 0.05, 0.2, 0.3
#: inside its hysteresis window two period-1 orbits coexist (a small and a large one)
WINDOW_OMEGA = 1.25
RUN = Integration(periods=150, discard=100)


@pytest.fixture(scope="module")
def duffing():
    return conftest.compiled("duffing", Integration(periods=150, discard=100))


def scipy_final_states(xs, vs, omega: float, periods: int) -> np.ndarray:
    """Every start of the grid (rows: v, columns: x) integrated by DOP853 to t = periods T, all at once: the final
    Poincare points, (len(vs), len(xs), 2). The Duffing equation typed here, not gearsym's."""
    X, V = np.meshgrid(xs, vs)
    k = X.size

    def f(t, y):
        x, v = y[:k], y[k:]
        return np.concatenate([v, -2 * ZETA * v - x - BETA * x ** 3 + F * np.cos(omega * t)])

    T = 2 * math.pi / omega
    sol = solve_ivp(f, (0.0, periods * T), np.concatenate([X.ravel(), V.ravel()]), method="DOP853", rtol=1e-9,
                    atol=1e-9)
    assert sol.success
    return np.stack([sol.y[:k, -1], sol.y[k:, -1]], axis=-1).reshape(*X.shape, 2)


def clusters(points: np.ndarray, tolerance: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
    """Greedy clusters of points (..., 2) within ``tolerance``: their centres and each point's cluster index."""
    flat = points.reshape(-1, 2)
    centres, index = [], np.full(len(flat), -1)
    for i, p in enumerate(flat):
        for j, c in enumerate(centres):
            if np.abs(p - c).max() <= tolerance:
                index[i] = j
                break
        else:
            centres.append(p)
            index[i] = len(centres) - 1
    return np.array(centres), index.reshape(points.shape[:-1])


@pytest.mark.slow
def test_duffing_basins_in_its_hysteresis_window_agree_with_scipy(duffing):
    xs, vs = np.linspace(-4, 4, 11), np.linspace(-4, 4, 11)
    found = basin_map(duffing, {"x": xs, "v": vs}, options=RUN, omega=WINDOW_OMEGA)
    assert [a.period for a in found.attractors] == [1, 1] and found.undetermined.starts == found.diverged.starts == 0
    final = scipy_final_states(xs, vs, WINDOW_OMEGA, RUN.periods)
    centres, scipy_label = clusters(final)
    assert len(centres) == 2  # SciPy sees the same two attractors ...
    ours = np.array([a.points[:, 0] for a in found.attractors])  # ... at the same Poincare points (RK4: ~1e-6)
    match = [int(np.argmin(np.abs(centres - p).max(axis=1))) for p in ours]
    assert sorted(match) == [0, 1]
    assert np.abs(centres[match] - ours).max() < 1e-4
    expected = np.array(match)[scipy_label] + 1  # SciPy's cluster as our attractor's number
    agree = np.mean(expected == found.labels)
    assert agree >= 0.95, f"{agree:.3f} of starts agree"
    for a in found.attractors:
        scipy_fraction = np.mean(expected == a.number)
        assert abs(a.fraction - scipy_fraction) <= 2 * a.stderr + 1e-12
    for a, centre in zip(found.attractors, centres[match]):  # each orbit's amplitude: SciPy's over one period
        sol = solve_ivp(lambda t, y: [y[1], -2 * ZETA * y[1] - y[0] - BETA * y[0] ** 3 + F * np.cos(WINDOW_OMEGA * t)],
                        (0.0, 2 * math.pi / WINDOW_OMEGA), centre, method="DOP853", rtol=1e-10, atol=1e-10,
                        dense_output=True)
        x = sol.sol(np.linspace(0.0, 2 * math.pi / WINDOW_OMEGA, 4001))[0]
        assert a.amplitude["x"] == pytest.approx((x.max() - x.min()) / 2, rel=1e-3)
    assert found.attractors[0].amplitude["x"] != pytest.approx(found.attractors[1].amplitude["x"], rel=0.1)


def test_the_lanes_and_the_scalar_loops_give_the_same_map(duffing):
    grid = {"x": np.linspace(-4, 4, 7), "v": np.linspace(-4, 4, 5)}
    wide = basin_map(duffing, grid, options=RUN, omega=WINDOW_OMEGA)
    one = basin_map(duffing, grid, options=RUN, execution=Execution(lanes=False), omega=WINDOW_OMEGA)
    assert wide.lanes > 1 and one.lanes == 1
    assert np.array_equal(wide.labels, one.labels)
    assert [a.fraction for a in wide.attractors] == [a.fraction for a in one.attractors]


def escape_oscillator() -> FirstOrderSystem:
    """The escape equation x'' + d x' + x - x^2 = F cos(w t): bounded in the well around 0, unbounded (in finite
    time) beyond the hilltop at x = 1."""
    return FirstOrderSystem.from_equations("escape", ["x", "v"], ["v", "-d*v - x + x**2 + F*cos(w*t)"],
                                           {"d": 0.1, "F": 0.02, "w": 0.8}, time="t", period="2*pi/w")


def scipy_escapes(xs, vs, periods: int) -> np.ndarray:
    """Per start (rows: v, columns: x): does x leave [-50, 50] within ``periods`` periods (DOP853, typed here)?"""
    d, F, w = 0.1, 0.02, 0.8

    def leaves(t, y):
        return 50.0 - abs(y[0])
    leaves.terminal = True
    out = np.zeros((len(vs), len(xs)), dtype=bool)
    for j, v in enumerate(vs):
        for i, x in enumerate(xs):
            sol = solve_ivp(lambda t, y: [y[1], -d * y[1] - y[0] + y[0] ** 2 + F * math.cos(w * t)],
                            (0.0, periods * 2 * math.pi / w), [x, v], method="DOP853", rtol=1e-9, atol=1e-9,
                            events=leaves)
            out[j, i] = sol.status == 1
    return out


@pytest.mark.slow
def test_a_start_that_diverges_is_a_class_of_its_own_and_the_fractions_sum_to_one():
    model = gearsym.compile_model(escape_oscillator(), Integration(periods=80, discard=40))
    xs, vs = np.linspace(-1.2, 1.8, 7), np.linspace(-1.0, 1.0, 5)
    found = basin_map(model, {"x": xs, "v": vs})
    escapes = scipy_escapes(xs, vs, 80)
    assert escapes.any() and (~escapes).any()
    assert np.array_equal(found.labels == DIVERGED, escapes)
    assert found.diverged.starts == escapes.sum() and found.diverged.fraction == escapes.mean()
    assert [a.period for a in found.attractors] == [1]  # the rest: the one orbit in the well
    assert np.array_equal(found.labels == 1, ~escapes)
    assert sum(found.fractions.values()) == pytest.approx(1.0, abs=1e-12)
    assert sum(a.basin.starts for a in found.attractors) + found.diverged.starts + found.undetermined.starts \
        == found.starts == xs.size * vs.size
    data = found.as_dict()
    assert data["diverged"]["fraction"] == found.diverged.fraction
    assert sum(a["fraction"] for a in data["attractors"]) + data["diverged"]["fraction"] \
        + data["undetermined"]["fraction"] == pytest.approx(1.0, abs=1e-12)


def _accounted(found) -> None:
    """Every start is in exactly one class, each class's share is its count of the labels, and they sum to 1."""
    counts = {k: int(np.sum(found.labels == k)) for k in np.unique(found.labels)}
    assert counts == {**{a.number: a.basin.starts for a in found.attractors},
                      **({UNDETERMINED: found.undetermined.starts} if found.undetermined.starts else {}),
                      **({DIVERGED: found.diverged.starts} if found.diverged.starts else {})}
    assert sum(found.fractions.values()) == pytest.approx(1.0, abs=1e-12)


def test_fractions_sum_to_one_with_chaotic_and_undetermined_starts():
    model = conftest.compiled("one_stage", Integration.paper(periods=160, discard=60))
    found = basin_map(model, {"x": np.linspace(-5, 5, 9), "v": np.linspace(-5, 5, 9)}, omega=1.0)
    _accounted(found)
    assert any(a.regime == "chaotic" and a.period is None for a in found.attractors)
    # too short a run in Duffing's window: most starts still spiral onto their orbit, undetermined
    short = basin_map(conftest.compiled("duffing", Integration(periods=40, discard=4)),
                      {"x": np.linspace(-4, 4, 11), "v": np.linspace(-4, 4, 11)}, omega=WINDOW_OMEGA)
    assert short.undetermined.starts > 0 and short.attractors
    _accounted(short)


def test_an_interrupted_basin_continuation_resumes_to_the_same_files(duffing, tmp_path):
    grid = {"x": np.linspace(-4, 4, 7), "v": np.linspace(-4, 4, 7)}
    omegas = [1.1, 1.2, 1.3, 1.4]
    whole = continue_basins(duffing, grid, "omega", omegas, options=RUN, out=tmp_path / "whole.csv")
    seen = []

    def stop_after_two(found):
        seen.append(found)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        continue_basins(duffing, grid, "omega", omegas, options=RUN, out=tmp_path / "cut.csv", on_value=stop_after_two)
    assert json.loads((tmp_path / "cut.json").read_text())["values"]["done"] == 2
    resumed = continue_basins(duffing, grid, "omega", omegas, options=RUN, out=tmp_path / "cut.csv",
                              on_value=seen.append)
    assert len(seen) == 4  # two values computed before the interruption, two after it
    for suffix in (".csv", ".attractors.csv", ".json"):
        assert (tmp_path / f"whole{suffix}").read_bytes() == (tmp_path / f"cut{suffix}").read_bytes(), suffix
    assert resumed.as_dict()["rows"] == whole.as_dict()["rows"] and resumed.events == whole.events
    # the window's second attractor appears at 1.2 and the first vanishes past it: a period-1 orbit each
    assert [(e["value"], e["event"]) for e in whole.events] == [(1.2, APPEARS), (1.4, VANISHES)]
    assert [len(whole.at(w)) - 2 for w in omegas] == [1, 2, 2, 1]


def test_a_continuation_killed_before_a_values_record_computes_that_value_again_and_a_finished_one_writes_nothing(
        duffing, tmp_path, monkeypatch):
    """A value is finished once the record (written last) counts it: killed after the second value's rows and
    before its record, the run resumes at the second value, to the files of a run never interrupted; run once more,
    the finished continuation is read and no file is written."""
    grid = {"x": np.linspace(-4, 4, 5), "v": np.linspace(-4, 4, 5)}
    omegas = [1.1, 1.2, 1.4]
    whole = continue_basins(duffing, grid, "omega", omegas, options=RUN, out=tmp_path / "whole.csv")
    write = basin_continuation.write_atomically

    def killed_at_the_second_record(path, data):
        if path.suffix == ".json" and json.loads(data)["values"]["done"] == 2:
            raise KeyboardInterrupt
        return write(path, data)

    cut = tmp_path / "cut.csv"
    with monkeypatch.context() as m:
        m.setattr(basin_continuation, "write_atomically", killed_at_the_second_record)
        with pytest.raises(KeyboardInterrupt):
            continue_basins(duffing, grid, "omega", omegas, options=RUN, out=cut)
    assert "\n1.2," in cut.read_text() and json.loads((tmp_path / "cut.json").read_text())["values"]["done"] == 1
    seen = []
    resumed = continue_basins(duffing, grid, "omega", omegas, options=RUN, out=cut, on_value=seen.append)
    assert [found.parameters["omega"] for found in seen] == [1.2, 1.4]
    for suffix in (".csv", ".attractors.csv", ".json"):
        assert (tmp_path / f"whole{suffix}").read_bytes() == (tmp_path / f"cut{suffix}").read_bytes(), suffix
    assert resumed.as_dict() == whole.as_dict() and whole.events

    def no_write(path, data):
        raise AssertionError(f"a finished continuation wrote {path}")

    monkeypatch.setattr(basin_continuation, "write_atomically", no_write)
    again = continue_basins(duffing, grid, "omega", omegas, options=RUN, out=cut, on_value=seen.append)
    assert again.as_dict() == whole.as_dict() and len(seen) == 2


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_json_has_the_fractions_periods_regimes_amplitudes_and_exponents(capsys, tmp_path):
    code, out, _ = run_cli(capsys, "basins", "duffing", "--set", f"omega={WINDOW_OMEGA}", "--grid", "x=-4:4:2",
                           "--grid", "v=-4:4:2", "--periods", "150", "--discard", "100", "--format", "json",
                           "--out", str(tmp_path / "map.csv"), "--plot", str(tmp_path / "map.png"))
    assert code == 0
    data = json.loads(out)
    assert data["grid"]["x"] == [-4.0, -2.0, 0.0, 2.0, 4.0] and data["grid"]["starts"] == 25
    for a in data["attractors"]:
        assert {"fraction", "stderr", "period", "regime", "amplitude", "exponents"} <= set(a)
        assert a["period"] == 1 and a["regime"] == "periodic" and set(a["amplitude"]) == {"x", "v"}
        assert len(a["exponents"]) == 2 and max(a["exponents"]) < 0
    assert sum(a["fraction"] for a in data["attractors"]) + data["diverged"]["fraction"] \
        + data["undetermined"]["fraction"] == pytest.approx(1.0)
    rows = (tmp_path / "map.csv").read_text().splitlines()
    assert rows[0] == "x,v,attractor" and len(rows) == 26
    assert (tmp_path / "map.png").stat().st_size > 10_000


def test_cli_text_and_the_continuation_figure(capsys, tmp_path):
    code, out, _ = run_cli(capsys, "basins", "duffing", "--grid", "x=-4:4:4", "--grid", "v=-4:4:4",
                           "--param", "omega=1.2:1.3:0.1", "--periods", "150", "--discard", "100",
                           "--out", str(tmp_path / "c.csv"), "--plot", str(tmp_path / "c.png"), "--quiet")
    assert code == 0
    assert "basin fractions at 2 values of omega" in out and "omega=1.2:" in out
    assert (tmp_path / "c.png").stat().st_size > 10_000 and (tmp_path / "c.attractors.csv").is_file()


def test_a_python_caller_runs_the_commands_map_job_to_the_same_files_and_report(capsys, tmp_path):
    code, out, _ = run_cli(capsys, "basins", "duffing", "--grid", "x=-4:4:4", "--grid", "v=-4:4:4", "--periods", "150",
                           "--discard", "100", "--format", "json", "--out", str(tmp_path / "cli.csv"), "--quiet")
    assert code == 0
    job = BasinMapJob(grid=(GridAxis.read("x=-4:4:4"), GridAxis.read("v=-4:4:4")), out=tmp_path / "job.csv")
    done = job.run(open_model(ModelRequest("duffing", options=Integration(periods=150, discard=100))))
    assert done.report("json") + "\n" == out
    assert done.written == (f"wrote {tmp_path / 'job.csv'} and {tmp_path / 'job.json'}",)
    for suffix in (".csv", ".json"):
        assert (tmp_path / f"job{suffix}").read_bytes() == (tmp_path / f"cli{suffix}").read_bytes(), suffix


def test_ctrl_c_during_the_fractions_says_where_the_values_finished_are_and_during_a_map_only_that(capsys, tmp_path,
                                                                                                   monkeypatch):
    def first_value_only(*args, **kwargs):
        def stop(found):
            raise KeyboardInterrupt
        return continue_basins(*args, on_value=stop, **kwargs)

    monkeypatch.setattr(basin_jobs, "continue_basins", first_value_only)
    out = tmp_path / "c.csv"
    code, _, err = run_cli(capsys, "basins", "duffing", "--grid", "x=-4:4:4", "--grid", "v=-4:4:4", "--param",
                           "omega=1.2:1.3:0.1", "--periods", "150", "--discard", "100", "--out", str(out), "--quiet")
    assert code == 130 and json.loads((tmp_path / "c.json").read_text())["values"]["done"] == 1
    assert err.strip().splitlines()[-1] == (f"gearsym: interrupted; the values finished are in {out}: run the same "
                                            "command again to resume")

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(basin_jobs, "basin_map", interrupted)
    code, _, err = run_cli(capsys, "basins", "duffing", "--grid", "x=-4:4:4", "--grid", "v=-4:4:4", "--periods",
                           "150", "--discard", "100", "--out", str(tmp_path / "m.csv"), "--quiet")
    assert code == 130 and err.strip().splitlines()[-1] == "gearsym: interrupted"  # (nothing kept to say where)


@pytest.mark.parametrize("argv, message", [
    (("--grid", "x=-1:1:1"), "give two different states"),
    (("--grid", "x=-1:1:1", "--grid", "q=0,1"), "--grid q: not a state of one_stage"),
    (("--grid", "x=-1um:1um:1um", "--grid", "v=0,1"), "has a unit, but the model has no physical values"),
    (("--grid", "x=-1:1:1", "--grid", "v=0,1", "--param", "omega=1:2:0.5"), "give --out FILE.csv"),
])
def test_cli_errors_are_one_line_messages(capsys, argv, message):
    code, _, err = run_cli(capsys, "basins", "one_stage", *argv)
    *before, last = err.strip().splitlines()
    assert code == 2 and message in last and last.startswith("gearsym: error:") and "Traceback" not in err
    assert all(line.startswith("gearsym: compiling") for line in before)  # (at most the note of a first compile)


@pytest.mark.parametrize("model, grid, message", [
    ("spur_pair", "x=-1A:1A:1A", "--grid 'x=-1A:1A:1A': a drivetrain value is made of mass, length and time"),
    ("one_stage", "x=-1A:1A:1A", "has a unit, but the model has no physical values"),  # (its unit read, not said)
])
def test_a_grid_in_a_unit_of_another_kind_is_refused_before_the_model_is_compiled(capsys, model, grid, message):
    code, _, err = run_cli(capsys, "basins", model, "--grid", grid, "--grid", "v=0,1")
    assert code == 2 and message in err and "compiling" not in err


def test_a_grid_axis_is_read_into_si_units_once_when_it_is_parsed():
    axis = GridAxis.read("x=-20um:20um:20um")
    assert axis.values == (-20.0, 0.0, 20.0) and axis.unit == "um" and axis.dims == (0.0, 1.0, 0.0)
    assert axis.si_values == pytest.approx((-2e-5, 0.0, 2e-5), rel=1e-15)
    assert GridAxis.read("v=-1,1").dims is None and GridAxis.read("v=-1,1").si_values == ()


@pytest.mark.parametrize("model, param, message", [
    ("spur_pair", "speed=1A,2A", "--param 'speed=1A,2A': a drivetrain value is made of mass, length and time"),
    ("spur_pair", "speed=9000:11000:2000", "write speed=9000rpm:11000rpm:2000rpm"),
    ("one_stage", "omega=1A,2A", "has a unit, but the model has no physical values"),  # (its unit read, not said)
])
def test_a_parameter_in_a_unit_of_another_kind_is_refused_before_the_model_is_compiled(capsys, tmp_path, model,
                                                                                        param, message):
    grid = ("x=-1um:1um:1um", "v=0mm/s,1mm/s") if model == "spur_pair" else ("x=-1:1:1", "v=0,1")
    code, _, err = run_cli(capsys, "basins", model, "--grid", grid[0], "--grid", grid[1], "--param", param,
                           "--out", str(tmp_path / "c.csv"))
    assert code == 2 and message in err and "compiling" not in err and not list(tmp_path.iterdir())


def test_a_parameter_axis_is_read_in_its_unit_once_when_it_is_parsed():
    axis = MeasuredAxis.read("speed=9000rpm:11000rpm:2000rpm")
    assert [m.si for m in axis.measures] == pytest.approx([9000 * math.pi / 30, 11000 * math.pi / 30], rel=1e-15)
    assert {m.dims for m in axis.measures} == {(0.0, 0.0, -1.0)} and axis.plain == parse_axis(axis.spec)
    assert MeasuredAxis.read("omega=1,2").measures == () and not MeasuredAxis.read("omega=1,2").refused


@pytest.mark.slow
def test_a_model_with_physical_values_is_mapped_and_answered_in_its_units(capsys):
    code, out, _ = run_cli(capsys, "basins", "spur_pair", "--grid", "x=-20um:20um:20um", "--grid",
                           "v=-300mm/s:300mm/s:300mm/s", "--periods", "60", "--discard", "20", "--format", "json")
    assert code == 0
    data = json.loads(out)
    assert data["grid"]["x"] == {"values": [-20.0, 0.0, 20.0], "unit": "um"}
    assert data["grid"]["v"]["unit"] == "mm/s" and data["speed"]["unit"] == "rpm"
    for a in data["attractors"]:
        assert a["amplitude"]["x"]["unit"] == "µm" and a["points"]["v"]["unit"] == "mm/s"
    code, _, err = run_cli(capsys, "basins", "spur_pair", "--grid", "x=-1:1:1", "--grid", "v=0,1")
    assert code == 2 and "give the grid with its unit" in err


def test_a_physical_maps_title_gives_the_users_values_and_its_exponents_are_per_second(capsys, tmp_path,
                                                                                          monkeypatch):
    import gearsym.figures.basins as figures

    drawn = []

    def draw(shown, path=None):
        drawn.append(plot_basin_map(shown, path))
        return drawn[-1]

    monkeypatch.setattr(figures, "plot_basin_map", draw)
    code, out, _ = run_cli(capsys, "basins", "spur_pair", "--set", "speed=5000 rpm", "--grid", "x=-20um:20um:20um",
                           "--grid", "v=-300mm/s:300mm/s:300mm/s", "--periods", "60", "--discard", "20",
                           "--plot", str(tmp_path / "map.png"))
    assert code == 0
    fig = drawn[0]
    title = fig.axes[0].get_title().replace("\n", " ")
    assert "speed=5000 rpm" in title and "the rest as the model declares them" in title
    assert "ζ" not in title and "B0" not in title  # (the engine's groups: in the files, not the title)
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("λ₁ = " in t and t.endswith("1/s") for t in legend)
    assert "the rest as the model declares them" in out


def test_a_continuation_maps_each_value_of_a_grid_in_physical_units_as_the_basin_map_at_that_value():
    """Along a parameter other than omega, the grid's rates (mm/s) are turned into the engine's numbers at the
    model's own speed, as the map at that value turns them (a rate's engine unit moves with omega)."""
    model = open_model(ModelRequest("spur_pair", {"speed": gearsym.units.measure("5000 rpm", "speed")},
                                    Integration(periods=30, discard=10)))
    grid = GivenGrid(model.scaling.point_units(), [GridAxis.read("x=-20um:20um:20um"),
                                                     GridAxis.read("v=-300mm/s:300mm/s:300mm/s")])
    compiled = model.compiled()
    omega = dict(zip(compiled.parameter_names, compiled.parameter_vector()))["omega"]
    assert not math.isclose(omega, 1.0)
    at_speed = grid.at({"omega": omega})
    assert not np.allclose(at_speed["v"], grid.at({"omega": 1.0})["v"])  # (the rates' engine values move with omega)
    found = []
    continue_basins(compiled, grid, "zeta", [0.05], on_value=found.append)
    alone = basin_map(compiled, grid, zeta=0.05)
    for mapped in (found[0], alone):
        assert [(n, v.tolist()) for n, v in mapped.axes] == [(n, np.asarray(v).tolist()) for n, v in at_speed.items()]
    assert found[0].labels.tolist() == alone.labels.tolist()
