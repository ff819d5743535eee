"""Figures say what they show: line styles, the direction drawn, parameter values, the parameter set, and
(in the paper's figures) attractor marks by regime, the zoom on lambda_1 and lambda_2, and phase portraits
whose titles and Poincare points belong to the run drawn. Read from the matplotlib Figure objects."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from gearsym.figures.poincare import REGIME_MARKERS
from gearsym.figures.sweep import plot_sweep
from gearsym.reproduce import compute, paper_plan
from gearsym.reproduce import figures as paper_figures
from conftest import system
from gearsym import Integration, run_sweep

SHORT = dict(options=Integration(periods=60, discard=20), progress=False)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


# ------------------------------------------------------------------ gearsym sweep --plot
@pytest.fixture(scope="module")
def up_and_down():
    return run_sweep(system("one_stage_resonant"), ["omega=1.3:1.4:0.02"], direction="both", poincare=5, zeta=0.07,
                     **SHORT)


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
    title = plot_sweep(up_and_down).axes[0].get_title().replace("\n", " ")
    assert "one_stage_resonant" in title and "omega = 1.3..1.4" in title
    assert "set: zeta=0.07" in title  # given with --set
    for name in ("B0", "B1", "D", "Theta", "Theta_p", "eta", "k_a"):  # the model's defaults
        assert f"{name}={up_and_down.record['parameters'][name]:g}" in title


def test_2d_sweep_maps_name_their_axes_direction_and_fixed_values():
    result = run_sweep(system("one_stage"), ["omega=1.2,1.3", "B1=3.5,4"], **SHORT)
    fig = plot_sweep(result)
    titles = [ax.get_title() for ax in fig.axes[:3]]  # (the colour bars come after the maps)
    assert all("over omega and B1 (up)" in t for t in titles)
    assert "zeta=0.08" in fig._suptitle.get_text() and "B1 = 3.5..4" in fig._suptitle.get_text()


# ------------------------------------------------------------------ the paper's figures
@pytest.fixture(scope="module")
def computed(tmp_path_factory):
    return compute(paper_plan(quick=True, study=False), tmp_path_factory.mktemp("data"), progress=False)


@pytest.mark.parametrize("name", ["fig3", "fig4", "fig6", "fig7", "hysteresis"])
def test_every_paper_figure_states_its_parameter_set(computed, name):
    fig = paper_figures.FIGURES[name][0](computed)
    top = fig._suptitle.get_text()
    assert f"parameter set: {computed.plan.scenario.label} ($k_a$=0.05" in top
    assert "the paper's values: " in top and "B1=4" in top


def test_figure_4_marks_each_attractor_by_its_regime_in_both_panels(computed):
    fig = paper_figures.figure4(computed)
    for ax, omega in zip(fig.axes, (1.5, 1.6)):
        legend = ax.get_legend()
        entries = [(t.get_text(), h.get_marker()) for t, h in zip(legend.get_texts(), legend.legend_handles)]
        for model in ("one_stage", "one_stage_resonant"):
            for a in computed.attractors[(model, omega)].attractors:
                text, marker = next(e for e in entries if f"λ₁={a.lambda1:+.4f}" in e[0])
                assert marker == REGIME_MARKERS[a.regime] and f"'{a.paper_label}'" in text and "#" not in text


def test_figure_6c_has_an_inset_on_lambda_1_and_2_near_zero(computed):
    fig = paper_figures.figure6(computed)
    panel = next(ax for ax in fig.axes if ax.get_title().startswith("kS = 0.1"))
    (inset,) = panel.child_axes
    r = computed.sweeps["fig6"]
    line = next(idx for d, values, idx in r.lines() if d == "up" and values["kS"] == 0.1)
    drawn = [ln.get_ydata() for ln in inset.lines if len(ln.get_ydata()) == len(line)]
    assert [np.array_equal(y, r[f"lambda_{i}"][line]) for i, y in enumerate(drawn, 1)] == [True, True]
    low, high = inset.get_ylim()
    assert low < 0 < high and (high - low) < 0.25 * np.diff(panel.get_ylim())[0]


def test_figure_7_panels_show_their_runs_regime_and_poincare_points_in_the_drawn_window(computed):
    fig = paper_figures.figure7(computed)
    steps = computed.portraits[0].spectrum.steps_per_period
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert len(panels) == len(computed.portraits)
    for ax, p in zip(panels, computed.portraits):
        assert p.spectrum.regime in ax.get_title() and f"λ₁ = {p.spectrum.exponents[0]:+.4f}" in ax.get_title()
        trajectory, points = ax.lines[:2]
        window = np.column_stack([trajectory.get_xdata(), trajectory.get_ydata()])
        at_periods = window[::steps]  # the states of the drawn window at t = kT
        drawn = np.column_stack([points.get_xdata(), points.get_ydata()])
        assert len(drawn) == len(at_periods) and np.array_equal(drawn, at_periods)
