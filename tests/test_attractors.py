"""Coexisting attractors: ``find_attractors``, its figures and ``gearsym poincare``.

The grouping is checked on a system whose attractors are known: the forced
two-well Duffing oscillator x'' + d x' - x + x^3 = g cos(w t). With weak forcing
each well holds its own period-1 orbit; at stronger forcing each well holds a
period-2 orbit, then a chaotic attractor (d = 0.3, w = 1.2). Every expectation
is checked directly as well, without the grouping (the sign of x on each run's
own Poincare points, the return of a run's points after one or two periods).
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np
import pytest

import conftest
from gearsym import FirstOrderSystem, GearsymError, Integration, compile_model, find_attractors, lyapunov_spectrum
from gearsym.analysis.attractors import cloud_distance, orbit_period, self_distance
from gearsym.cli import poincare

WELLS = {"x": (-2.0, 2.0), "v": (-1.0, 1.0)}


@pytest.fixture(scope="module")
def duffing():
    system = FirstOrderSystem.from_equations(
        "two_well_duffing", ["x", "v"], ["v", "-d*v + x - x**3 + g*cos(w*t)"], {"d": 0.3, "g": 0.1, "w": 1.2},
        time="t", period="2*pi/w")
    return compile_model(system, Integration(steps_per_period=100))


def run(model, periods: int, discard: int) -> Integration:
    """The model's scheme over ``periods`` forcing periods in all, the first ``discard`` left out."""
    return model.integration.run(periods, discard)


def side_of_each_run(found) -> list[int]:
    """+1 or -1: the sign of x on every Poincare point of a run (asserted to be one sign)."""
    sides = []
    for r in found.results:
        signs = np.sign(r.strobe[0])
        assert np.all(signs == signs[0]), f"run {r.index} visits both wells"
        sides.append(int(signs[0]))
    return sides


# ------------------------------------------------------------------------------------------ grouping
@pytest.mark.slow
def test_weak_forcing_gives_one_period_one_orbit_per_well(duffing):
    found = find_attractors(duffing, ics=12, seed=3, box=WELLS, options=run(duffing, 210, 150))
    assert len(found) == 2
    assert sorted(np.sign(a.centroid["x"]) for a in found) == [-1, 1]
    for a in found:
        assert a.regime == "periodic" and a.period == 1 and a.lambda1 < 0
        assert a.regular and a.paper_label == "1"
        assert np.all(np.sign(a.points[0]) == np.sign(a.centroid["x"]))
    sides = side_of_each_run(found)
    assert set(sides) == {-1, 1}  # this seed starts runs in both wells
    for r, side in zip(found.results, sides):
        assert np.ptp(r.strobe, axis=1).max() < 1e-8  # directly: the run repeats after one period
        assert np.sign(found.attractors[r.attractor - 1].centroid["x"]) == side
    members = sorted(i for a in found for i in a.members)
    assert members == list(range(12))
    assert [len(a.members) for a in found] == sorted((len(a.members) for a in found), reverse=True)


@pytest.mark.parametrize("resolution", [0.0, None])
def test_runs_on_one_chaotic_attractor_share_no_point_but_are_grouped(duffing, resolution):
    """With resolution 0 the self distance alone (the sampling's own resolution) must hold each attractor together."""
    more = {} if resolution is None else {"resolution": resolution}
    found = find_attractors(duffing, ics=10, seed=1, box=WELLS, options=run(duffing, 500, 200), g=0.3, **more)
    sides = side_of_each_run(found)
    assert set(sides) == {-1, 1}
    assert len(found) == 2
    for a in found:
        assert a.regime == "chaotic" and a.lambda1 > 3 * a.lambda1_stderr and a.period is None
        assert a.paper_label == "2" and not a.regular
    for r, side in zip(found.results, sides):
        assert np.sign(found.attractors[r.attractor - 1].centroid["x"]) == side
    a = found.attractors[0]
    first, second = (found.results[i].strobe for i in a.members[:2])
    assert np.abs(first[:, :, None] - second[:, None, :]).sum(axis=0).min() > 1e-9  # no point in common


def test_a_period_two_orbit_reached_with_shifted_phase_is_one_attractor(duffing):
    orbit = lyapunov_spectrum(duffing, options=run(duffing, 300, 260), y0={"x": 1.0}, g=0.28).strobe
    step = lambda k: np.abs(orbit[:, k:] - orbit[:, :-k]).max()  # noqa: E731
    assert step(2) < 1e-8 < 1e-2 < step(1), "precondition: g=0.28 holds a period-2 orbit"
    found = find_attractors(duffing, initial_states=[orbit[:, -1], orbit[:, -2]], options=run(duffing, 50, 10),
                            g=0.28)
    one, two = (r.strobe for r in found.results)
    assert np.abs(one[:, 0] - two[:, 0]).max() > 1e-2  # the two runs are out of phase ...
    assert np.abs(one[:, 1:] - two[:, :-1]).max() < 1e-8  # ... by one period
    assert len(found) == 1
    assert found.attractors[0].members == (0, 1) and found.attractors[0].period == 2
    assert found.seed is None and found.box is None


def test_the_same_seed_gives_the_same_runs_and_another_seed_other_starts(duffing):
    a = find_attractors(duffing, ics=5, seed=7, box=WELLS, options=run(duffing, 50, 30))
    b = find_attractors(duffing, ics=5, seed=7, box=WELLS, options=run(duffing, 50, 30))
    c = find_attractors(duffing, ics=5, seed=8, box=WELLS, options=run(duffing, 50, 30))
    starts = lambda s: np.array([list(r.initial_state.values()) for r in s.results])  # noqa: E731
    assert np.array_equal(starts(a), starts(b)) and not np.allclose(starts(a), starts(c))
    assert np.array_equal(a.assignment, b.assignment)
    assert all(np.array_equal(x.strobe, y.strobe) for x, y in zip(a.results, b.results))
    assert json.dumps(a.as_dict()) == json.dumps(b.as_dict())
    for s in (a, c):
        x, v = starts(s).T
        assert np.all((x >= -2) & (x < 2) & (v >= -1) & (v < 1))


def test_set_distances_ignore_order_and_see_a_missing_point():
    rng = np.random.default_rng(0)
    cloud = rng.normal(size=(2, 300))
    assert cloud_distance(cloud, cloud[:, rng.permutation(300)]) == pytest.approx(0, abs=1e-7)
    two = np.tile([[1.0, -1.0], [0.5, 0.2]], 20)  # a period-2 sequence
    assert self_distance(two) == pytest.approx(0, abs=1e-7)  # halves in time, not alternate points
    assert cloud_distance(two, two[:, 1:]) == pytest.approx(0, abs=1e-7)
    assert cloud_distance(two, two[:, ::2]) > 0.5  # one of the two points missing
    assert orbit_period([two], np.ones(2)) == 2 and orbit_period([two[:, ::2]], np.ones(2)) == 1
    assert orbit_period([cloud], np.ones(2)) is None


@pytest.mark.parametrize("kwargs,message", [
    ({"ics": 0}, "ics .* at least 1"),
    ({"ics": 2.5}, "whole number"),
    ({"seed": -1}, "seed must be at least 0"),
    ({"resolution": np.nan}, "resolution"),
    ({"box": {"xx": (0, 1)}}, "'xx', which is not a state. Did you mean 'x'"),
    ({"box": {"x": (1, 1)}}, "low < high"),
    ({"box": {"x": (2, -2)}}, "low < high"),
    ({"box": {"x": (0, "a")}}, "two numbers"),
    ({"box": {"x": (0, float("inf"))}}, "finite"),
    ({"box": {"x": (0, 1)}, "initial_states": [[0, 0]]}, "not both"),
    ({"initial_states": []}, "empty"),
    ({"initial_states": {"x": 1.0}}, "sequence of initial states"),
    ({"initial_states": [1.0, 2.0]}, "sequence of initial states"),
    ({"initial_states": [[1.0, 2.0, 3.0]]}, "needs 2 values"),
    ({"initial_states": [{"q": 1.0}]}, "unknown states"),
    ({"periods": 0}, "periods"),
    ({"periods": 5}, "discard=5.* must be shorter than the run"),
    ({"merge_factor": -1.0}, "merge_factor"),
    ({"gg": 0.2}, "Did you mean 'g'"),
])
def test_bad_input_is_a_clear_error(duffing, kwargs, message):
    with pytest.raises(GearsymError, match=message):
        find_attractors(duffing, options=run(duffing, kwargs.pop("periods", 15), 5), **kwargs)


# ------------------------------------------------------------------------------------------ figures
@pytest.mark.slow
def test_figures_are_written(duffing, tmp_path):
    from gearsym.figures.poincare import PhasePanel, phase_panel, plot_attractors, plot_phase_portraits

    weak = find_attractors(duffing, ics=6, seed=3, box=WELLS, options=run(duffing, 130, 100))
    strong = find_attractors(duffing, ics=6, seed=3, box=WELLS, options=run(duffing, 200, 100), g=0.3)
    out = tmp_path / "attractors.png"
    plot_attractors([[weak, strong], strong], out, labels=["g=0.1", "g=0.3"])
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000
    panels = [phase_panel(duffing, periods=50, discard=50, g=g, title_parameters=("w",)) for g in (0.1, 0.3)]
    assert panels[1].title == "w=1.2, g=0.3" and panels[1].points.shape == (2, 51)
    out = tmp_path / "phase.png"
    plot_phase_portraits([*panels, PhasePanel(panels[0].trajectory, x="v", y="x")], out)
    assert out.stat().st_size > 20_000
    with pytest.raises(GearsymError, match="no state 'q'"):
        plot_attractors(weak, tmp_path / "bad.png", x="q")
    with pytest.raises(GearsymError, match="2 overlaid sets but only 1 labels"):
        plot_attractors([[weak, strong]], tmp_path / "bad.png", labels=["one"])


def test_an_attractor_is_drawn_by_its_regime_whatever_order_it_was_found_in(duffing):
    """The same attractors, numbered the other way round (as another set of starts might find them),
    get the same labels, marks and markers: the marker is the regime's, the mark the paper's class."""
    import dataclasses

    import matplotlib.pyplot as plt

    from gearsym.figures.poincare import REGIME_MARKERS, plot_attractors

    def renumbered(s):
        flipped = [dataclasses.replace(a, number=len(s.attractors) + 1 - a.number) for a in s.attractors]
        return dataclasses.replace(s, attractors=tuple(sorted(flipped, key=lambda a: a.number)))

    weak = find_attractors(duffing, ics=6, seed=3, box=WELLS, options=run(duffing, 130, 100))  # two period-1 orbits
    strong = find_attractors(duffing, ics=6, seed=3, box=WELLS, options=run(duffing, 160, 100), g=0.3)  # chaotic
    assert len(weak) == 2 and {a.regime for a in weak} == {"periodic"} and not strong.attractors[0].regular
    fig = plot_attractors([[weak, strong], [renumbered(weak), renumbered(strong)]])

    def drawn(ax):
        legend = ax.get_legend()
        entries = sorted((t.get_text(), h.get_marker()) for t, h in zip(legend.get_texts(), legend.legend_handles))
        marks = sorted((t.get_text(), t.xyann) for t in ax.texts if "mathbf" in t.get_text())  # text and place
        return entries, marks

    first, second = fig.axes[:2]
    assert drawn(first) == drawn(second)
    entries, marks = drawn(first)
    for s in (weak, strong):
        for a in s.attractors:
            entry = next(e for e in entries if f"λ₁={a.lambda1:+.4f}" in e[0])
            assert entry[1] == REGIME_MARKERS[a.regime] and f"'{a.paper_label}'" in entry[0]
    assert sorted(m.split("}")[0][-1] for m, _ in marks) == sorted(a.paper_label for s in (weak, strong) for a in s)
    plt.close(fig)


# ------------------------------------------------------------------------------------------ command line
def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    """``gearsym poincare ...`` through main once the subcommand is registered, through the module before."""
    from gearsym import cli

    if any(module.NAME == poincare.NAME for module in cli.COMMANDS):
        code = cli.main([poincare.NAME, *argv])
    else:
        parser = argparse.ArgumentParser(prog="gearsym poincare")
        poincare.add_arguments(parser)
        try:
            code = poincare.run(parser.parse_args(list(argv)))
        except GearsymError as exc:
            print(f"gearsym: error: {exc}", file=sys.stderr)
            code = 2
    out, err = capsys.readouterr()
    return code, out, err


FAST = ("--set", "omega=1.6", "--ics", "3", "--periods", "70", "--discard", "40")  # 30 measured periods


def test_cli_json_partitions_the_initial_states(capsys):
    """At omega = 1.6 the one-stage pair settles on one periodic orbit of period 2 from every start in the box:
    one attractor, periodic, holding all three initial states, each with the spectrum of its own run."""
    code, out, _ = run_cli(capsys, "one_stage", *FAST, "--box", "x=-3:3", "--format", "json")
    assert code == 0
    data = json.loads(out)
    assert data["parameters"]["omega"] == 1.6 and data["seed"] == 0
    assert data["box"] == {"x": [-3.0, 3.0], "v": [-5.0, 5.0]}
    assert len(data["initial_conditions"]) == 3
    (found,) = data["attractors"]
    assert found["members"] == [0, 1, 2] and found["number"] == 1
    assert (found["regime"], found["paper_label"], found["period"]) == ("periodic", "1", 2)
    assert len(found["exponents"]) == len(found["stderr"]) == 2 and set(found["centroid"]) == {"x", "v"}
    assert max(found["exponents"]) < 0
    model = conftest.compiled("one_stage")
    for ic, start in zip(data["initial_conditions"], found["initial_states"]):
        assert ic["attractor"] == 1 and ic["initial_state"] == start and -3 <= start["x"] <= 3
        own = lyapunov_spectrum(model, options=Integration(periods=70, discard=40), y0=start, omega=1.6)
        assert ic["exponents"] == own.exponents.tolist() and ic["regime"] == own.regime
        # what the attractor is, seen on 200 more periods of each run, without the grouping: periodic, and
        # its Poincare points repeat after two periods, not one
        later = lyapunov_spectrum(model, options=Integration(periods=200, discard=0), y0=own.final_state,
                                  omega=1.6)
        assert later.regime == "periodic" and max(later.exponents) < -0.03
        strobe = later.strobe[:, 100:]
        assert np.abs(strobe[:, 2:] - strobe[:, :-2]).max() < 1e-9 < 1 < np.abs(strobe[:, 1:] - strobe[:, :-1]).min()


def test_cli_text_lists_attractors_and_runs_and_plots(capsys, tmp_path):
    plot = tmp_path / "poincare.png"
    code, out, err = run_cli(capsys, "one_stage", *FAST, "--plot", str(plot))
    assert code == 0 and f"wrote {plot}" in err and plot.stat().st_size > 20_000
    assert "attractor 1 ['" in out and "lambda_1 = " in out and "amplitude A_x = " in out and "centroid  x=" in out
    assert out.count("-> attractor") == 3


@pytest.mark.slow
def test_cli_plot_shows_the_coordinate_asked_for(capsys, tmp_path, monkeypatch):
    import gearsym.cli.poincare as command

    drawn = []
    real = command.plot_attractors
    monkeypatch.setattr(command, "plot_attractors", lambda *a, **k: drawn.append((a, real(*a, **k))) or drawn[-1][1])
    code, _, _ = run_cli(capsys, "flexible_shaft", "--ics", "2", "--periods", "30", "--discard", "10",
                         "--plot", str(tmp_path / "p.png"), "--coordinate", "x2")
    assert code == 0
    (found, *_), fig = drawn[0]
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x2", "v2")
    ix = found.state_names.index("x2")
    plotted = np.concatenate([line.get_xdata() for line in ax.lines])
    assert plotted.size and np.isin(plotted, np.concatenate([a.points[ix] for a in found.attractors])).all()


def test_cli_refuses_an_unknown_coordinate_before_any_run(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(poincare, "find_attractors", lambda *a, **k: pytest.fail("the runs started"))
    code, _, err = run_cli(capsys, "flexible_shaft", "--plot", str(tmp_path / "p.png"), "--coordinate", "x")
    assert code == 2 and "--coordinate x: no such coordinate. Did you mean" in err and "are x1, x2" in err


@pytest.mark.parametrize("argv,message", [
    (["--box", "x=1"], "NAME=LOW:HIGH"),
    (["--box", "x=a:b"], "NAME=LOW:HIGH"),
    (["--box", "x=0:1,x=1:2"], "gives x twice"),
    (["--box", "q=0:1"], "not a state"),
    (["--ics", "0"], "at least 1"),
    (["--set", "omgea=1.5"], "Did you mean 'omega'"),
])
def test_cli_errors_are_one_line_messages(capsys, argv, message):
    code, _, err = run_cli(capsys, "one_stage", "--periods", "15", "--discard", "5", *argv)
    assert code == 2 and message in err and "Traceback" not in err
