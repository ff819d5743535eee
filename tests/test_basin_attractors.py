"""Basin maps whose answers are known in closed form: attractors of period 16 and 3, several of them with basins
of known sizes (so their numbering is known), and a continuation along which attractors appear, merge and vanish.

Two small ODEs are designed for it (compiled once each):

* **clocked**: x' = -x (x^2 - 1)(x^2 - 4)/10 has stable points 0 and +-2 and unstable ones at +-1, so a start's
  attractor is read off its x; y' = -y + x c is driven by a clock (c, s), a rotation at w/K, so every attractor's
  Poincare points (at t = 2 pi n / w) are K points: the period is K forcing periods. At x* the orbit is
  y = x* (cos W t + W sin W t)/(1 + W^2), W = w/K: its points and amplitudes are written here.
* **fork**: x' = -20 x ((x - M)^2 + cos p), y' = -y: for cos p > 0 one stable point (0); for cos p < 0 two,
  M +- sqrt(-cos p), with 0 unstable between them. Along p the one splits into two, they merge back, and far
  apart ones appear: the continuation's events are known, as is which new attractor is the nearer.
"""
from __future__ import annotations

import csv
import json
import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_rgba

import gearsym
from gearsym import FirstOrderSystem, Integration
from gearsym.analysis.basins import basin_map
from gearsym.figures.basins import plot_basin_fractions, plot_basin_map
from gearsym.sweep.basin_continuation import APPEARS, CONTINUES, MERGES, VANISHES, continue_basins

#: the run of every start: measured periods enough for the tail of 32 points a period of 16 needs
RUN = Integration(periods=60, discard=20)


@pytest.fixture(scope="module")
def clocked():
    system = FirstOrderSystem.from_equations(
        "clocked", ["x", "y", "c", "s"],
        ["-x*(x**2 - 1)*(x**2 - 4)/10", "-y + x*c", "-w/K*s", "w/K*c"],
        {"w": 1.0, "K": 16.0}, time="t", period="2*pi/w", initial={"x": 0.5, "y": 0.0, "c": 1.0, "s": 0.0})
    return gearsym.compile_model(system, RUN)


def stable_point(x0: float) -> float:
    """Where x' = -x (x^2 - 1)(x^2 - 4)/10 takes x0 (not +-1): 0 inside, +-2 outside."""
    return 0.0 if abs(x0) < 1 else math.copysign(2.0, x0)


def orbit_points(x_star: float, K: int, w: float = 1.0) -> np.ndarray:
    """The K Poincare points (4, K) of the clocked attractor at x*: (x*, y, cos, sin) at t = 2 pi n / w."""
    W, n = w / K, np.arange(K)
    angle = 2 * math.pi * n / K
    c, s = np.cos(angle), np.sin(angle)
    return np.array([np.full(K, x_star), x_star * (c + W * s) / (1 + W * W), c, s])


def same_set(a: np.ndarray, b: np.ndarray, tolerance: float) -> bool:
    """Two sets of points (n, k) equal to ``tolerance`` (each point of one within it of a point of the other)."""
    d = np.abs(a[:, :, None] - b[:, None, :]).max(axis=0)
    return a.shape == b.shape and d.min(axis=1).max() <= tolerance and d.min(axis=0).max() <= tolerance


@pytest.fixture(scope="module")
def period_16(clocked):
    xs, ys = np.array([-2.5, -1.5, 0.5, 1.5, 2.0, 2.5]), np.array([-1.0, 0.0, 1.0])
    return xs, ys, basin_map(clocked, {"x": xs, "y": ys}, options=RUN, K=16.0)


@pytest.mark.slow
def test_an_orbit_of_period_16_is_found_with_its_16_points(period_16):
    """16 is the longest period told from the Poincare points: each attractor is period 16, its points those of
    the closed form."""
    _, _, found = period_16
    assert [a.period for a in found.attractors] == [16, 16, 16]
    assert found.undetermined.starts == found.diverged.starts == 0
    for a in found.attractors:
        x_star = a.points[0, 0]
        assert x_star == pytest.approx(round(x_star), abs=1e-9)
        assert a.points.shape == (4, 16) and same_set(a.points, orbit_points(round(x_star), 16), 1e-6)
        assert a.description.startswith("period 16")


def test_attractors_are_numbered_by_their_basins_size_and_every_start_is_labelled_with_its_own(period_16):
    """x > 1 holds 9 starts (x* = 2), x < -1 six (x* = -2), |x| < 1 three (x* = 0): numbered 1, 2, 3 in that
    order (not in the order the grid meets them), each start labelled with the number of the attractor its x
    leads to."""
    xs, ys, found = period_16
    attractors = found.attractors
    assert [a.number for a in attractors] == [1, 2, 3]
    assert [a.basin.starts for a in attractors] == [9, 6, 3]
    assert [a.points[0, 0] for a in attractors] == pytest.approx([2.0, -2.0, 0.0], abs=1e-9)
    number = {2.0: 1, -2.0: 2, 0.0: 3}
    expected = np.array([[number[stable_point(x)] for x in xs] for _ in ys])
    assert found.labels.shape == (len(ys), len(xs)) and np.array_equal(found.labels, expected)
    for a in attractors:  # the fraction and its binomial standard error, sqrt(f (1 - f) / N)
        f = a.basin.starts / 18
        assert a.fraction == f and a.stderr == pytest.approx(math.sqrt(f * (1 - f) / 18), rel=1e-12)
        first = int(np.argmax(found.labels.reshape(-1) == a.number))  # rows: y; columns: x (x fastest)
        assert a.representative == {"x": xs[first % len(xs)], "y": ys[first // len(xs)], "c": 1.0, "s": 0.0}
    assert sum(found.fractions.values()) == pytest.approx(1.0, abs=1e-15)


def test_each_attractors_amplitude_is_half_its_range_over_the_measured_periods(period_16):
    """A = (max - min)/2 over the measured periods (the mean over the basin's starts): y's orbit has the
    amplitude |x*| / sqrt(1 + W^2), the clock 1, x none."""
    _, _, found = period_16
    W = 1 / 16
    for a in found.attractors:
        x_star = round(a.points[0, 0])
        assert a.amplitude["x"] == pytest.approx(0.0, abs=1e-9)
        assert a.amplitude["y"] == pytest.approx(abs(x_star) / math.sqrt(1 + W * W), rel=1e-5, abs=1e-9)
        assert a.amplitude["c"] == pytest.approx(1.0, rel=1e-5) and a.amplitude["s"] == pytest.approx(1.0, rel=1e-5)


def test_the_maps_figure_colours_each_start_by_its_attractor_and_says_what_each_is(period_16):
    """The figure, read from its artists (not its file size): each cell in its attractor's colour, that colour's
    legend entry saying the attractor's number, period and share (with its standard error), and the attractor's
    Poincare points drawn where they are."""
    xs, ys, found = period_16
    fig = plot_basin_map(found)
    try:
        ax = fig.axes[0]
        mesh, *markers = ax.collections
        cells = mesh.to_rgba(mesh.get_array()).reshape(len(ys), len(xs), 4)
        legend = ax.get_legend()
        entries = [(text.get_text(), to_rgba(handle.get_facecolor()))
                   for handle, text in zip(legend.legend_handles, legend.get_texts())]
        assert len(entries) == 3  # (no start diverged or undetermined: no key for them ...)
        assert "no start diverged or undetermined" in legend.get_title().get_text()  # (... and the title says so)
        for a, (text, colour), drawn in zip(found.attractors, entries, markers):
            assert text.startswith(f"{a.number}: {a.description}, {100 * a.fraction:.1f} ± {100 * a.stderr:.1f} % "
                                   "of starts; A_x = ") and f"A_y = {a.amplitude['y']:.4g}," in text
            assert np.allclose(cells[found.labels == a.number], colour)
            assert not np.allclose(cells[found.labels != a.number], colour)
            assert np.allclose(drawn.get_offsets(), a.points[:2].T)  # (x, y) of its 16 points
        assert f"{100 * found.attractors[0].fraction:.1f}" == "50.0"  # (9 of 18 starts)
    finally:
        plt.close(fig)


def test_attractors_with_basins_of_one_size_are_numbered_by_their_points(clocked):
    """Period 3 (the clock at w/3); the two outer attractors have one start each: the one whose points lie lower
    (x* = -2) comes first."""
    xs, ys = np.array([-1.5, -0.5, 0.5, 1.5]), np.array([0.25])
    found = basin_map(clocked, {"x": xs, "y": ys}, options=RUN, K=3.0)
    assert [(a.period, a.basin.starts) for a in found.attractors] == [(3, 2), (3, 1), (3, 1)]
    assert [round(a.points[0, 0]) for a in found.attractors] == [0, -2, 2]
    for a in found.attractors:
        assert same_set(a.points, orbit_points(round(a.points[0, 0]), 3), 1e-6)
    assert found.labels.tolist() == [[2, 1, 1, 3]]


def test_a_period_is_read_from_the_end_of_a_run_that_begins_in_its_transient(clocked):
    """No periods discarded: starts near the unstable points x = +-1 take a few periods to leave them, so only the
    last points of their runs repeat; they are period 16 all the same, on the attractor their side leads to."""
    xs, ys = np.array([-1.05, -0.95, 0.95, 1.05]), np.array([0.0])
    found = basin_map(clocked, {"x": xs, "y": ys}, options=Integration(periods=60, discard=0), K=16.0)
    assert found.undetermined.starts == 0
    assert [(a.period, a.basin.starts, round(a.points[0, 0])) for a in found.attractors] == [
        (16, 2, 0), (16, 1, -2), (16, 1, 2)]


# ------------------------------------------------------------------------------------------ along a parameter
M = -0.05
#: cos p = 1 (one point, 0), -0.0225 (M +- 0.15: -0.2 and 0.1), 1 (one again), -1 (M +- 1: -1.05, 0.95)
VALUES = (0.0, math.acos(-0.0225), 2 * math.pi, 3 * math.pi)
FORK_RUN = Integration(periods=40, discard=20)


@pytest.fixture(scope="module")
def fork(tmp_path_factory):
    system = FirstOrderSystem.from_equations("fork", ["x", "y"], ["-20*x*((x - M)**2 + cos(p))", "-y"],
                                             {"M": M, "p": 0.0}, time="t", period="1",
                                             initial={"x": 0.0, "y": 0.0})
    model = gearsym.compile_model(system, FORK_RUN)
    grid = {"x": np.linspace(-1, 1, 8), "y": [-0.5, 0.5]}
    out = tmp_path_factory.mktemp("fork") / "fork.csv"
    return continue_basins(model, grid, "p", VALUES, options=FORK_RUN, out=out)


def stable_points(p: float) -> list[float]:
    """The stable points of the fork at p, from the cubic's roots (NumPy)."""
    roots = np.roots([-20, 40 * M, -20 * (M * M + math.cos(p)), 0.0])
    real = np.sort(roots[np.abs(roots.imag) < 1e-12].real)
    return [float(real[0]), float(real[-1])] if len(real) == 3 else [float(real[0])]


@pytest.mark.slow
def test_a_continuation_tracks_attractors_that_split_merge_and_vanish(fork):
    """0 splits into -0.2 and 0.1: the nearer (0.1, attractor 2 of the map by its points) keeps the id, -0.2 is new;
    they merge back into 0 (the farther one merges into the nearer's id); then two far apart points appear and
    0 vanishes."""
    assert [(e["value"], e["event"], e["attractor"], e["into"]) for e in fork.events] == [
        (VALUES[1], APPEARS, 2, None), (VALUES[2], MERGES, 2, 1),
        (VALUES[3], APPEARS, 3, None), (VALUES[3], APPEARS, 4, None), (VALUES[3], VANISHES, 1, None)]
    ids = {v: [(r.id, r.event) for r in fork.at(v) if r.kind == "attractor"] for v in VALUES}
    assert ids == {VALUES[0]: [(1, APPEARS)], VALUES[1]: [(1, CONTINUES), (2, APPEARS)],
                   VALUES[2]: [(1, f"{CONTINUES} {MERGES} 2")], VALUES[3]: [(3, APPEARS), (4, APPEARS)]}
    assert fork.ids == [1, 2, 3, 4]


def test_each_tracked_attractor_sits_at_its_stable_point_with_its_basins_share(fork):
    where = {v: {r.id: r for r in fork.at(v) if r.kind == "attractor"} for v in VALUES}
    assert where[VALUES[0]][1].points[0] == pytest.approx([0.0], abs=1e-6)
    low, high = stable_points(VALUES[1])
    assert (low, high) == pytest.approx((-0.2, 0.1), abs=1e-12)  # (the design: M -+ 0.15)
    assert where[VALUES[1]][1].points[0] == pytest.approx([high], abs=1e-6)  # the nearer to 0 kept id 1
    assert where[VALUES[1]][2].points[0] == pytest.approx([low], abs=1e-6)
    assert where[VALUES[2]][1].points[0] == pytest.approx([0.0], abs=1e-6)
    low, high = stable_points(VALUES[3])
    assert where[VALUES[3]][3].points[0] == pytest.approx([low], abs=1e-6)
    assert where[VALUES[3]][4].points[0] == pytest.approx([high], abs=1e-6)
    # each of two attractors holds the starts on its side of 0 (8 of 16); the one attractor all of them
    assert [r.starts for r in fork.at(VALUES[1]) if r.kind == "attractor"] == [8, 8]
    assert [r.fraction for r in fork.at(VALUES[2])] == [1.0, 0.0, 0.0]
    assert fork.fractions(1).tolist() == [1.0, 0.5, 1.0, 0.0] and fork.fractions(4).tolist() == [0, 0, 0, 0.5]
    assert all(r.period == 1 for r in fork.rows if r.kind == "attractor")


def test_the_continuations_files_say_what_it_returned(fork):
    """The record's events and the CSV's rows are the result's (read back, not compared as bytes)."""
    record = json.loads(fork.path.with_suffix(".json").read_text())
    assert record["status"] == "complete" and record["events"] == list(fork.events)
    rows = list(csv.DictReader(fork.path.open()))
    attractors = [(float(r["p"]), int(r["attractor"]), r["event"]) for r in rows if r["class"] == "attractor"]
    assert attractors == [(r.value, r.id, r.event) for r in fork.rows if r.kind == "attractor"]


def test_the_continuations_figure_draws_each_ids_fractions_and_says_its_events(fork):
    """Read from its artists: one line per id through its fractions at the values where it exists, keyed in its
    colour, and each event written at its value."""
    fig = plot_basin_fractions(fork)
    try:
        top = fig.axes[0]
        keys = {text.get_text(): to_rgba(handle.get_color())
                for handle, text in zip(top.get_legend().legend_handles, top.get_legend().get_texts())}
        assert set(keys) == {f"attractor {i}" for i in fork.ids}
        drawn = {to_rgba(line.get_color()): (tuple(line.get_xdata()), tuple(line.get_ydata())) for line in top.lines
                 if len(line.get_xdata()) and line.get_linestyle() == "-"}
        for aid in fork.ids:
            rows = [r for r in fork.rows if r.id == aid]
            assert drawn[keys[f"attractor {aid}"]] == (tuple(r.value for r in rows), tuple(r.fraction for r in rows))
        said = sorted((round(t.xy[0], 9), t.get_text()) for t in top.texts)
        assert said == sorted([(round(VALUES[1], 9), "2 appears"), (round(VALUES[2], 9), "2 merges into 1"),
                               (round(VALUES[3], 9), "3 appears, 4 appears, 1 vanishes")])
    finally:
        plt.close(fig)
