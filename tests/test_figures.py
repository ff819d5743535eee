"""Figures say what they show: line styles, the direction drawn, parameter values, the parameter set, and
(in the paper's figures) attractor marks by regime, the zoom on lambda_1 and lambda_2, and phase portraits
whose titles and Poincare points belong to the run drawn. Read from the matplotlib Figure objects."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from gearsym.figures.poincare import REGIME_MARKERS, _place_labels
from gearsym.figures.sweep import plot_sweep
from gearsym.reproduce import SCENARIOS
from gearsym.reproduce import figures as paper_figures
from conftest import quick_reproduction_group, system
from gearsym import Integration, run_sweep

SHORT = dict(options=Integration(periods=60, discard=20))


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


# ------------------------------------------------------------------ gearsym sweep --plot
@pytest.fixture(scope="module")
def up_and_down():
    return run_sweep(system("one_stage_resonant"), ["omega=1.3:1.4:0.02"], direction="both", poincare=5, zeta=0.07,
                     **SHORT)


@pytest.mark.slow
def test_sweep_plot_legends_say_which_line_style_is_which_direction(up_and_down):
    amplitude, exponents, bifurcation, _ = plot_sweep(up_and_down).axes[:4]
    labels = [t.get_text() for t in amplitude.get_legend().get_texts()]
    assert labels == ["up (solid)", "down (dashed)"]
    styles = {line.get_label(): line.get_linestyle() for line in amplitude.lines}
    assert styles == {"up (solid)": "-", "down (dashed)": "--"}
    legend = exponents.get_legend()
    by_text = {t.get_text(): h.get_linestyle() for t, h in zip(legend.get_texts(), legend.legend_handles)}
    assert by_text["solid: up"] == "-" and by_text["dashed: down"] == "--"


def test_the_bifurcation_panel_shows_and_names_one_direction(up_and_down):
    _, _, bifurcation, _ = plot_sweep(up_and_down).axes[:4]
    up = up_and_down.strobe["direction"] == "up"
    assert "the up run" in bifurcation.get_title()
    assert np.array_equal(bifurcation.lines[0].get_ydata(), up_and_down.strobe["x"][up])


def test_sweep_plot_titles_carry_the_fixed_parameter_values(up_and_down):
    title = plot_sweep(up_and_down)._suptitle.get_text().replace("\n", " ")
    assert "one_stage_resonant" in title and "omega = 1.3..1.4" in title
    assert "set: zeta=0.07" in title  # given with --set
    for name in ("B0", "B1", "D", "Theta", "Theta_p", "eta", "k_a"):  # the model's defaults
        assert f"{name}={up_and_down.record['parameters'][name]:g}" in title


@pytest.mark.slow
def test_2d_sweep_maps_name_their_axes_direction_and_fixed_values():
    result = run_sweep(system("one_stage"), ["omega=1.2,1.3", "B1=3.5,4"], **SHORT)
    fig = plot_sweep(result)
    titles = [ax.get_title() for ax in fig.axes[:3]]  # (the colour bars come after the maps)
    assert all("over omega and B1 (up)" in t for t in titles)
    assert "zeta=0.08" in fig._suptitle.get_text() and "B1 = 3.5..4" in fig._suptitle.get_text()


# ------------------------------------------------------------------ the paper's figures
# (as `gearsym reproduce --quick` writes them: the session's one quick reproduction, whose files test_reproduce.py
# checks; its first scenario, the one calibrated to the paper)
@pytest.fixture(scope="module")
def computed(quick_reproduction):
    return quick_reproduction.computed[SCENARIOS[0].name]


def written(quick_reproduction, name):
    """The figure ``name`` of the first scenario as the quick reproduction wrote it (laid out, titles fitted)."""
    return quick_reproduction.figures[f"{name}.png"]


def suptitle(fig) -> str:
    return fig._suptitle.get_text().replace("\n", " ")  # (as wrapped to fit: a line break for a space)


@pytest.mark.parametrize("name", ["fig3", "fig4", "fig6", "fig7", "hysteresis"])
@pytest.mark.slow
@quick_reproduction_group()
def test_every_paper_figure_states_its_parameter_set(quick_reproduction, computed, name):
    top = suptitle(written(quick_reproduction, name))
    assert f"parameter set: {computed.plan.scenario.label} ($k_a$=0.05" in top
    assert "the paper's values: " in top and "B1=4" in top


@pytest.mark.slow
@quick_reproduction_group()
def test_figure_4_marks_each_attractor_by_its_regime_in_both_panels(quick_reproduction, computed):
    fig = written(quick_reproduction, "fig4")
    for ax, omega in zip(fig.axes, (1.5, 1.6)):
        legend = ax.get_legend()
        entries = [(t.get_text(), h.get_marker()) for t, h in zip(legend.get_texts(), legend.legend_handles)]
        for model in ("one_stage", "one_stage_resonant"):
            for a in computed.attractors[(model, omega)].attractors:
                text, marker = next(e for e in entries if f"λ₁={a.lambda1:+.4f}" in e[0])
                assert marker == REGIME_MARKERS[a.regime] and f"'{a.paper_label}'" in text and "#" not in text


@pytest.mark.slow  # (it reads a reproduction)
@quick_reproduction_group()
def test_figure_6c_has_an_inset_on_lambda_1_and_2_near_zero(quick_reproduction, computed):
    fig = written(quick_reproduction, "fig6")
    panel = next(ax for ax in fig.axes if ax.get_title().startswith("kS = 0.1"))
    (inset,) = panel.child_axes
    r = computed.sweeps["fig6"]
    line = next(idx for d, values, idx in r.lines() if d == "up" and values["kS"] == 0.1)
    drawn = [ln.get_ydata() for ln in inset.lines if len(ln.get_ydata()) == len(line)]
    assert [np.array_equal(y, r[f"lambda_{i}"][line]) for i, y in enumerate(drawn, 1)] == [True, True]
    low, high = inset.get_ylim()
    assert low < 0 < high and (high - low) < 0.25 * np.diff(panel.get_ylim())[0]


@pytest.mark.slow  # (it reads a reproduction)
@quick_reproduction_group()
def test_figure_7_panels_show_their_runs_regime_and_poincare_points_in_the_drawn_window(quick_reproduction, computed):
    fig = written(quick_reproduction, "fig7")
    steps = computed.portraits[0].spectrum.steps_per_period
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert len(panels) == len(computed.portraits)
    for ax, p in zip(panels, computed.portraits):
        title = ax.get_title().replace("\n", " ")
        assert p.spectrum.regime in title and f"λ₁ = {p.spectrum.exponents[0]:+.4f}" in title
        trajectory, points = ax.lines[:2]
        window = np.column_stack([trajectory.get_xdata(), trajectory.get_ydata()])
        at_periods = window[::steps]  # the states of the drawn window at t = kT
        drawn = np.column_stack([points.get_xdata(), points.get_ydata()])
        assert len(drawn) == len(at_periods) and np.array_equal(drawn, at_periods)


# ================================================================== nothing in a figure hides anything else
# (figure_checks reads the laid-out Figure: texts inside it, legends off the data and naming what is drawn)
import dataclasses  # noqa: E402
from types import SimpleNamespace  # noqa: E402

import figure_checks as fc  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from gearsym import find_attractors, lyapunov_spectrum  # noqa: E402
from gearsym.analysis.poincare import phase_trajectory  # noqa: E402
from gearsym.figures import plot_point  # noqa: E402
from gearsym.figures.campbell import plot_campbell  # noqa: E402
from gearsym.figures.orbits import LABELLED, plot_branches, plot_orbits  # noqa: E402
from gearsym.figures.poincare import plot_attractors  # noqa: E402
from gearsym.figures.sweep import BIFURCATION_DOT, ZERO_CONTOUR, plot_bifurcation, plot_map  # noqa: E402
from gearsym.fit.prediction import Prediction  # noqa: E402
from gearsym.figures.fit_report import prediction_figure  # noqa: E402
from gearsym.periodic import FOLD, GRAZING, PERIOD_DOUBLING  # noqa: E402
from gearsym.periodic.branches import Bifurcation, Branch, Continuation  # noqa: E402
from gearsym.physical.campbell import Campbell, Crossing, Order  # noqa: E402
from gearsym.sweep.grid import Axis  # noqa: E402
from gearsym.sweep.result import SweepResult  # noqa: E402
from conftest import compiled  # noqa: E402


def synthetic_sweep(axes: dict, columns: dict, strobe: dict | None = None, units=None, model="synthetic"):
    """A SweepResult made from columns given here (the figures read nothing else)."""
    axes = tuple(Axis(name, tuple(values), name) for name, values in axes.items())
    return SweepResult(model, axes, "continuation", {k: np.asarray(v) for k, v in columns.items()}, strobe or {},
                       {"direction": "up", "parameters": {"zeta": 0.08}, "settings": {}}, None, units or {})


# ------------------------------------------------------------------ the Campbell diagram
def spur_campbell():
    """spur_pair's diagram as gearsym.physical.campbell makes it: its torque's first harmonic runs at the mesh
    frequency, so '1x mesh' and 'torque 1x' are one line."""
    per = 28 * 1.0  # mesh frequency per speed (rad/s per rad/s): 28 teeth
    orders = (Order("1x mesh", "mesh", per), Order("2x mesh", "mesh", 2 * per), Order("3x mesh", "mesh", 3 * per),
              Order("torque 1x", "torque", per))
    fn = 6059.96
    crossings = tuple(sorted((Crossing(o.label, fn, 60 * fn / o.per_speed) for o in orders), key=lambda c: c.speed))
    return Campbell("spur_pair", "rpm", np.arange(2000.0, 16001.0, 1000.0), (fn,), orders, crossings)


def campbell_sweep(diagram):
    speeds = diagram.speeds
    return synthetic_sweep({"speed": speeds}, {"speed": speeds, "direction": np.array(["up"] * len(speeds)),
                                               "A_x": 5 + 10 * np.exp(-((speeds - 6500) / 600) ** 2),
                                               "lambda_1": -np.ones(len(speeds)), "regime": ["periodic"] * len(speeds)},
                           units={"speed": "rpm", "A_x": "µm"}, model="spur_pair")


def test_campbell_orders_of_one_frequency_are_one_line_named_after_each():
    """The 1x mesh line was hidden under the torque's dotted line of the same frequency."""
    diagram = spur_campbell()
    left = plot_campbell(diagram).axes[0]
    orders = [ln for ln in left.lines if ln.get_label() and not ln.get_label().startswith("_")
              and len(ln.get_xdata()) > 2]
    data = [tuple(np.round(ln.get_ydata(), 6)) for ln in orders]
    assert len(set(data)) == len(data) == 3, "two order lines are drawn on top of each other"
    assert "1x mesh = torque 1x" in [ln.get_label() for ln in orders]
    assert fc.unmatched_legend_entries(left) == []


@pytest.mark.slow
def test_campbell_panels_span_the_same_speeds_and_mark_every_crossing_in_both():
    diagram = spur_campbell()
    fig = plot_campbell(diagram, sweep=campbell_sweep(diagram), settings={"kZ": "1.27e8 N/m"})
    left, right = fig.axes[:2]
    assert left.get_xlim() == right.get_xlim() == (2000.0, 16000.0)
    where = sorted({round(c.speed, 3) for c in diagram.crossings})  # 1x mesh and torque 1x: one point
    for ax in (left, right):
        marks = sorted(round(float(ln.get_xdata()[0]), 3) for ln in ax.lines if ln.get_marker() == "o")
        assert marks == where
    assert [t.get_text() for t in left.texts if "rpm" in t.get_text()] == [f"{s:.0f} rpm" for s in where]
    assert "spur_pair" in fig._suptitle.get_text() and "kZ=1.27e8 N/m" in fig._suptitle.get_text()
    for ax in (left, right):
        assert fc.unmatched_legend_entries(ax) == []
        assert fc.points_under_legend(ax) == 0
        assert all(p.get_label() in [t.get_text() for t in ax.get_legend().get_texts()] for p in ax.patches), (
            "a band or patch the legend does not explain")
    assert fc.clipped_texts(fig) == []


def test_campbell_frequencies_span_the_crossings_and_name_the_modes_above():
    """A two-stage box: modes up to 10.7 kHz, mesh orders reaching 3.6 kHz over 500-3000 rpm; the axis ran to 16 kHz
    with the labels of 9107 and 10654 Hz on top of each other."""
    orders = (Order("1x mesh", "mesh", 23.0), Order("2x mesh", "mesh", 46.0), Order("stage2 1x", "mesh", 23 * 19 / 61))
    natural = (64.4, 1313.8, 2208.9, 9107.2, 10653.5)
    crossings = tuple(sorted((Crossing(o.label, fn, 60 * fn / o.per_speed) for o in orders for fn in natural
                              if 500 <= 60 * fn / o.per_speed <= 3000), key=lambda c: c.speed))
    diagram = Campbell("two_stage_gearbox", "rpm", np.arange(500.0, 3001.0, 100.0), natural, orders, crossings)
    assert max(c.natural_frequency for c in crossings) == 2208.9
    fig = plot_campbell(diagram)
    left = fig.axes[0]
    assert left.get_ylim()[1] == pytest.approx(1.25 * 2208.9)
    drawn = sorted(round(float(ln.get_ydata()[0]), 1) for ln in left.lines
                   if len(ln.get_ydata()) == 2 and ln.get_ydata()[0] == ln.get_ydata()[1])
    assert drawn == [64.4, 1313.8, 2208.9]
    assert any("9107 Hz" in t.get_text() and "10654 Hz" in t.get_text() for t in left.texts)
    assert fc.clipped_texts(fig) == []


# ------------------------------------------------------------------ branches of periodic orbits
def synthetic_continuation(kinds_at, *, stable_only=False, period_two=True):
    """A continuation of period 1 (and 2) with bifurcations of ``kinds_at`` [(kind, value)] on branch 0."""
    def branch(index, period, values, amplitude, unstable_from):
        mu = np.where(values[:, None] < unstable_from, 0.5, 1.5) * np.ones((1, 2))
        half = np.column_stack([amplitude, amplitude])
        return Branch(index, period, values, np.zeros((len(values), 2)), mu.astype(complex), -half, half,
                      np.zeros(len(values)), np.zeros((len(values), 1), dtype=str), "reached",
                      events=np.array([int(np.argmin(np.abs(values - v))) for _, v in kinds_at]))
    values = np.linspace(0.5, 1.0, 101)
    branches = [branch(0, 1, values, 10 + 5 * np.sin(6 * values), np.inf if stable_only else 0.9)]
    if period_two:
        branches.append(branch(1, 2, values[40:], 6 + 0 * values[40:], 0.8))
    bifurcations = tuple(Bifurcation(k, v, 0, 1, np.ones(2), np.zeros(2)) for k, v in kinds_at)
    return Continuation("one_stage", "h", "omega", 0.5, 1.0, {"zeta": 0.08, "B1": 4.0}, ("x", "v"), ("x",),
                        ("mesh",), 2 * np.pi, tuple(branches), bifurcations, {})


CLUSTER = [(GRAZING, 0.680), (FOLD, 0.709), (PERIOD_DOUBLING, 0.680), (FOLD, 0.6805), (PERIOD_DOUBLING, 0.7)]


def test_bifurcation_markers_are_open_and_drawn_above_every_curve():
    """A grazing's triangle was hidden under a period doubling's white square at the same point."""
    fig = plot_orbits(synthetic_continuation(CLUSTER))
    top = fig.axes[0]
    marks = [ln for ln in top.lines if ln.get_marker() in ("o", "s", "^", "D") and len(ln.get_xdata()) == 1]
    curves = [ln for ln in top.lines if len(ln.get_xdata()) > 1]
    assert len(marks) == len(CLUSTER)
    assert all(ln.get_markerfacecolor() == "none" for ln in marks), "a filled marker hides one under it"
    assert min(ln.get_zorder() for ln in marks) > max(ln.get_zorder() for ln in curves)


def test_bifurcation_labels_overlap_neither_each_other_nor_the_markers():
    """'G 0.680' and 'F 0.709' were written on top of each other."""
    fig = plot_orbits(synthetic_continuation(CLUSTER))
    top = fig.axes[0]
    renderer = fc.laid_out(fig)
    labels = [Text.get_window_extent(t, renderer) for t in top.texts]  # (the text, without its leader line)
    assert len(labels) == len(CLUSTER) <= LABELLED
    assert fc.label_overlaps(labels) == []
    marks = [ln for ln in top.lines if len(ln.get_xdata()) == 1]
    for ln in marks:
        x, y = top.transData.transform((ln.get_xdata()[0], ln.get_ydata()[0]))
        r = ln.get_markersize() / 2 * fig.dpi / 72
        assert not any(b.overlaps(type(b).from_extents(x - r, y - r, x + r, y + r)) for b in labels)
    frame = top.get_window_extent(renderer)
    assert all(frame.contains(b.x0, b.y0) and frame.contains(b.x1, b.y1) for b in labels)


def test_the_orbits_legend_names_only_what_was_drawn():
    """It listed a sweep's 'continuation down' that did not run, and unstable styles never drawn."""
    result = synthetic_continuation([(FOLD, 0.7)], stable_only=True, period_two=False)
    x = np.linspace(0.5, 1.0, 11)
    sweep = synthetic_sweep({"omega": x}, {"omega": x, "direction": np.array(["up"] * 11), "A_x": 10 + 0 * x,
                                           "lambda_1": -x, "regime": ["periodic"] * 11})
    fig = plot_orbits(result, sweep=sweep)
    top = fig.axes[0]
    texts = [t.get_text() for t in top.get_legend().get_texts()]
    assert texts == ["period 1, stable", "F: fold (a multiplier through +1)", "sweep, continuation up"]
    assert fc.unmatched_legend_entries(top) == []
    assert fc.clipped_texts(fig) == []


# ------------------------------------------------------------------ one point: lyap --plot
@pytest.fixture(scope="module")
def point():
    cm = compiled("flexible_shaft", Integration(periods=60, discard=30))
    spectrum = lyapunov_spectrum(cm, omega=1.5)
    trajectory = phase_trajectory(cm, options=cm.integration.run(discard=50), omega=1.5)
    return spectrum, trajectory


@pytest.mark.slow
def test_a_long_title_is_wrapped_inside_the_figure(point):
    """`lyap --plot --coordinate x2` of a user model had its title cut off on both sides."""
    spectrum, trajectory = point
    many = {f"{name}_of_the_user_rig": 1234.5678 + i for i, name in enumerate("ABCDEFGHIJKLMNOP")}
    long = dataclasses.replace(spectrum, model="a_user_model_with_a_long_name", parameters=many)
    fig = plot_point(long, trajectory, x="x2")
    assert fc.clipped_texts(fig) == []
    title = fig._suptitle.get_text().replace("\n", " ")
    assert "a_user_model_with_a_long_name" in title and all(f"{k}=" in title for k in many)


@pytest.mark.slow
def test_the_legends_of_lyap_plot_cover_no_poincare_point(point):
    """Even where the Poincare points fill the phase plane (a chaotic attractor), no legend covers one."""
    spectrum, trajectory = point
    lo, hi = trajectory.states.min(axis=1), trajectory.states.max(axis=1)
    cloud = lo[:, None] + (hi - lo)[:, None] * np.random.default_rng(1).uniform(size=(len(lo), 400))
    for shown in (spectrum, dataclasses.replace(spectrum, strobe=cloud)):
        fig = plot_point(shown, trajectory, x="x2")
        for ax in fig.axes[:2]:
            assert fc.points_under_legend(ax) == 0
            assert fc.unmatched_legend_entries(ax) == []


# ------------------------------------------------------------------ attractors: poincare --plot
@pytest.mark.slow
def test_the_poincare_figure_names_the_model_and_every_parameter():
    """It was titled 'ω=1.6' only."""
    found = find_attractors(compiled("one_stage", Integration(periods=60, discard=40)), ics=3, seed=0, omega=1.6)
    fig = plot_attractors(found)
    title = fig._suptitle.get_text().replace("\n", " ")
    assert title.startswith("one_stage: ")
    for name in ("zeta", "B0", "B1", "eta"):
        assert f"{name}" in title or {"zeta": "ζ", "eta": "η"}[name] in title
    assert "ω=1.6" in title and "ζ=0.08" in title and "B1=4" in title
    assert fc.clipped_texts(fig) == []
    assert all(fc.points_under_legend(ax) == 0 for ax in fig.axes)


# ------------------------------------------------------------------ sweeps: maps, many exponents, dots
def map_sweep(values_of_lambda, coordinates=("x1", "x2"), regimes=None):
    omega, ks = np.linspace(1.2, 1.8, 7), np.linspace(0.0, 1.0, 5)
    w, k = (a.ravel() for a in np.meshgrid(omega, ks))
    columns = {"omega": w, "kS": k, "direction": np.array(["up"] * len(w)), "lambda_1": values_of_lambda(w, k),
               "regime": regimes if regimes is not None else np.array(["periodic"] * len(w))}
    columns.update({f"A_{c}": 1 + i + w * k for i, c in enumerate(coordinates)})
    return synthetic_sweep({"omega": omega, "kS": ks}, columns, model="flexible_shaft")


def test_a_lambda_map_uses_the_whole_colour_scale_on_each_side_of_zero():
    """Scaled to the largest |lambda|, the negative side (most of the map) was washed out."""
    rng = np.random.default_rng(0)
    r = map_sweep(lambda w, k: np.where(w > 1.6, rng.uniform(0.01, 0.06, w.size), rng.uniform(-0.03, -0.005, w.size)))
    fig = plt.figure()
    mesh = plot_map(fig.add_subplot(), r, "lambda_1")
    lam = r["lambda_1"]
    assert mesh.norm(np.percentile(lam, 2)) <= 0.02 and mesh.norm(np.percentile(lam, 98)) >= 0.98
    assert mesh.norm(0.0) == pytest.approx(0.5)


@pytest.mark.slow
def test_a_2d_sweep_names_its_zero_contour_and_maps_every_coordinate():
    r = map_sweep(lambda w, k: w - 1.5)
    fig = plot_sweep(r)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert any(ZERO_CONTOUR in t and t.startswith(r"$\lambda_1$") for t in titles)
    assert any(t.startswith("A (x1)") for t in titles) and any(t.startswith("A (x2)") for t in titles)
    assert fc.clipped_texts(fig) == []


def test_a_regime_without_a_colour_of_its_own_is_drawn_and_named():
    regimes = np.array(["periodic", "undetermined", "chaotic", "periodic", "undetermined"] * 7)
    r = map_sweep(lambda w, k: w - 1.5, regimes=regimes)
    fig = plot_sweep(r)
    bar = next(ax for ax in fig.axes if "undetermined" in [t.get_text() for t in ax.get_yticklabels()])
    assert [t.get_text() for t in bar.get_yticklabels()] == ["periodic", "chaotic", "undetermined"]


def eight_exponents():
    """A planetary-like sweep: 8 exponents, three pairs of them equal (degenerate planet modes)."""
    x = np.linspace(0.3, 2.0, 69)
    lam = [-0.02 - 0.01 * k - 0.01 * x for k in (0, 1, 1, 2, 2, 3, 4, 4)]
    columns = {"omega": x, "direction": np.array(["up"] * len(x)), "A_x1": 1 + x,
               **{f"lambda_{i}": v for i, v in enumerate(lam, 1)}, "regime": ["periodic"] * len(x)}
    strobe = {"omega": np.repeat(x, 2), "direction": np.array(["up"] * 2 * len(x)), "sample": np.tile([0.0, 1.0], len(x)),
              "x1": np.repeat(x, 2), "v1": np.zeros(2 * len(x))}
    return synthetic_sweep({"omega": x}, columns, strobe, model="planetary")


@pytest.mark.slow
def test_eight_exponent_lines_are_told_apart_even_where_they_coincide():
    """The planetary sweep's 8 exponent lines were indistinguishable."""
    fig = plot_sweep(eight_exponents())
    exponents = fig.axes[1]
    lines = [ln for ln in exponents.lines if ln.get_label().startswith(r"$\lambda")]
    assert len(lines) == 8
    assert len({(ln.get_color(), ln.get_marker()) for ln in lines}) == 8
    for a in range(8):
        for b in range(a + 1, 8):
            if np.array_equal(lines[a].get_ydata(), lines[b].get_ydata()):  # drawn on top of each other
                shown = [ln.get_markevery() for ln in (lines[a], lines[b])]
                assert all(shown) and all(ln.get_marker() not in ("", "None") for ln in (lines[a], lines[b])), (
                    "two lines drawn on top of each other without markers of their own: one hides the other")
                at = [set(range(len(lines[a].get_xdata()))[start::step]) for start, step in shown]
                assert at[0] and at[1] and not (at[0] & at[1]), "coinciding lines put their markers on the same points"
    assert fc.unmatched_legend_entries(exponents) == []
    assert fc.points_under_legend(exponents) == 0 and fc.points_under_legend(fig.axes[0]) == 0


def test_bifurcation_diagram_dots_can_be_seen():
    """They were 1 pixel."""
    fig = plt.figure()
    ax = fig.add_subplot()
    plot_bifurcation(ax, eight_exponents(), "x1")
    assert ax.lines[0].get_markersize() == BIFURCATION_DOT >= 2.0


# ------------------------------------------------------------------ explain: which record
def test_the_prediction_figure_says_which_record_and_periods_it_shows():
    windows = tuple((f"measured.csv record {r} (omega={w}) period {p}", 40) for r, w in ((1, 1.2), (2, 1.6))
                    for p in range(12, 16))
    n = 40 * len(windows)
    series = {"x": np.sin(np.arange(n) / 6.0)}
    prediction = Prediction(0.3, np.arange(n) / 6.0, series, series, np.zeros((2, n)), len(windows), {"x": 0.3},
                            windows)
    assert prediction.shown(3) == (120, "measured.csv record 1 (omega=1.2), periods 12-14")
    assert prediction.records() == ["measured.csv record 1 (omega=1.2)", "measured.csv record 2 (omega=1.6)"]
    candidate = SimpleNamespace(prediction=prediction, error=0.3)
    fig = prediction_figure(SimpleNamespace(base=candidate, final=candidate, effects=()), "one_stage")
    title = fig.axes[0].get_title()
    assert "one_stage" in title and "measured.csv record 1 (omega=1.2), periods 12-14" in title
    assert len(fig.axes[0].lines[0].get_xdata()) == 120


# ------------------------------------------------------------------ the paper's figures, as they are written
@pytest.mark.parametrize("name", [n for n in paper_figures.FIGURES if n != "study"])
@pytest.mark.slow
@quick_reproduction_group()
def test_no_paper_figure_clips_a_text_or_covers_a_curve_with_a_legend(quick_reproduction, computed, name):
    if name == "fig3-orbits" and not computed.orbits:
        pytest.skip("the quick plan has no continuation")
    fig = written(quick_reproduction, name)
    assert fc.clipped_texts(fig) == []
    for ax in fig.axes:
        assert fc.points_under_legend(ax) == 0, f"a legend covers data in {ax.get_title()!r}"
        assert fc.unmatched_legend_entries(ax) == [], ax.get_title()


def test_each_attractors_mark_keeps_clear_of_every_point_and_of_the_other_marks():
    """A chaotic cloud over the lower half of the axes and two periodic orbits above it: each mark's text box (half
    0.065 x 0.035 of the axes) covers no plotted point and no mark placed before it, though most spots near the
    cloud would."""
    rng = np.random.default_rng(3)
    cloud = rng.uniform(0, 1, 3000), rng.uniform(0, 0.55, 3000)
    drawn = [(SimpleNamespace(paper_label="2", regime="chaotic", period=0), *cloud, "C0"),
             (SimpleNamespace(paper_label="1", regime="periodic", period=1), [0.3], [0.8], "C1"),
             (SimpleNamespace(paper_label="1", regime="periodic", period=2), [0.7, 0.8], [0.75, 0.9], "C2")]
    fig, ax = plt.subplots()
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    _place_labels(ax, drawn)
    spots = [np.array(mark.xyann) for mark in ax.texts]
    points = np.vstack([np.column_stack([np.asarray(x, float), np.asarray(y, float)]) for _, x, y, _ in drawn])
    half = np.array([0.065, 0.035])
    plt.close(fig)
    assert len(spots) == 3
    for k, spot in enumerate(spots):
        assert (np.abs(points - spot) / half).max(axis=1).min() >= 1.0, f"mark {k} at {spot} covers a point"
        for other in spots[:k]:
            assert (np.abs(other - spot) / half).max() >= 2.0, f"mark {k} at {spot} covers the mark at {other}"
