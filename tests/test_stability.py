"""Stability charts (issue 40) against what is known exactly or computed independently here.

* The one-stage model without backlash, damping and forcing, with k = 1 + k_a cos(tau), is Mathieu's equation:
  x'' + (1 + k_a cos tau) x / omega^2 = 0 in tau; with tau = 2 z, x_zz + (a - 2 q cos 2z) x = 0, a = 4 / omega^2,
  q = -2 k_a / omega^2. Its transition curves a = a_r(|q|), b_r(|q|) (SciPy's characteristic values) bound the
  tongues; the chart's boundaries must lie on them to 1e-6 in omega for the first three.
* With damping, and for the two-degree-of-freedom flexible shaft, the monodromy matrices against SciPy's
  DOP853 on the variational equations typed here.
* Liouville: the product of the multipliers is exp(int tr J) at every point.
* The lanes give every point its own tables: a chart whose lanes all differ in k_a equals the scalar loops'.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.special import mathieu_a, mathieu_b

import conftest
import gearsym
import gearsym.stability
from gearsym import Execution
from gearsym.cli import main
from gearsym.stability import (ABOUT, FOLD, NEIMARK_SACKER, NO_ORBIT, PERIOD_DOUBLING, compile_linearisation,
                               static_chart)
from gearsym.stability.chart import orbit_chart
from gearsym.stability.linearised import static_recipe

ROOT = Path(__file__).resolve().parents[1]
MATHIEU = dict(k="1+k_a*cos(tau)", zeta=0, eta=0, B0=0, B1=0)


@pytest.fixture(scope="module")
def mathieu():
    """The one-stage model with k = 1 + k_a cos(tau), linearised about its static state (x = 0, on the edge of
    contact: g' = 1 there) and compiled once; zeta, B0, eta are runtime values."""
    return compile_linearisation(conftest.system("one_stage", **MATHIEU))


def exact_omega(r: int, ka: float, curve, lo: float, hi: float) -> float:
    """omega on Mathieu's transition curve a = curve(r, |q|) at this k_a (a = 4/omega^2, q = 2 k_a/omega^2)."""
    return brentq(lambda w: 4 / w**2 - curve(r, 2 * ka / w**2), lo, hi, xtol=1e-14)


@pytest.mark.slow
def test_the_undamped_one_stage_chart_has_mathieus_tongues_to_1e_6_in_omega(mathieu):
    rows = [0.35, 0.55, 0.75]  # (the third tongue is 0.0046 wide at k_a = 0.35: two grid steps)
    chart = static_chart(mathieu, {"omega": np.round(np.arange(0.6, 2.4, 0.002), 10), "k_a": rows})
    for r, kind in ((1, PERIOD_DOUBLING), (2, FOLD), (3, PERIOD_DOUBLING)):
        for ka in rows:
            centre = 2 / r  # (the tongue's foot: where to look)
            lo = min(exact_omega(r, ka, c, 0.55 * centre, 1.6 * centre) for c in (mathieu_a, mathieu_b))
            hi = max(exact_omega(r, ka, c, 0.55 * centre, 1.6 * centre) for c in (mathieu_a, mathieu_b))
            found = sorted(c.value for c in chart.crossings if c.axis == 0 and chart.values[1][c.i] == ka
                           and lo - 0.03 < c.value < hi + 0.03)
            assert len(found) == 2, (r, ka, found)
            assert abs(found[0] - lo) < 1e-6 and abs(found[1] - hi) < 1e-6, (r, ka, found, lo, hi)
            inside = (chart.values[0] > lo) & (chart.values[0] < hi)
            i = rows.index(ka)
            assert set(chart.kind[i][inside]) <= {kind}, (r, ka, set(chart.kind[i][inside]))
    assert all(c.error <= 1e-7 * (2.4 - 0.6) for c in chart.crossings)
    assert chart.max_modulus.shape == (3, len(chart.values[0]))


def scipy_monodromy(J, omega_period=2 * np.pi) -> np.ndarray:
    """The monodromy matrix of q' = J(tau) q over one period, by DOP853 on the n^2 equations."""
    n = J(0.0).shape[0]
    sol = solve_ivp(lambda t, y: (J(t) @ y.reshape(n, n)).reshape(-1), (0, omega_period), np.eye(n).reshape(-1),
                    method="DOP853", rtol=1e-12, atol=1e-12)
    return sol.y[:, -1].reshape(n, n)


def same(mu: np.ndarray, nu: np.ndarray, tol: float = 1e-6) -> bool:
    """The same multipliers, as sets, to ``tol``."""
    d = np.abs(np.asarray(mu)[:, None] - np.asarray(nu)[None, :])
    return bool(d.min(axis=1).max() < tol and d.min(axis=0).max() < tol)


def one_stage_J(omega, zeta, ka):
    return lambda t: np.array([[0.0, 1.0], [-(1 + ka * np.cos(t)) / omega**2, -2 * zeta / omega]])


def test_a_damped_chart_has_scipys_multipliers_boundaries_and_liouvilles_product(mathieu):
    zeta = 0.05
    chart = static_chart(mathieu, {"omega": np.round(np.arange(1.5, 2.5, 0.05), 10), "k_a": [0.15, 0.3, 0.6]},
                         zeta=zeta)
    a, b = chart.values
    for i, j in ((0, 2), (1, 10), (2, 10), (2, 19)):
        M = scipy_monodromy(one_stage_J(a[j], zeta, b[i]))
        assert same(chart.multipliers[i, j], np.linalg.eigvals(M)), (a[j], b[i])
    # the principal tongue with damping: its edges where SciPy's largest modulus is 1
    for c in [c for c in chart.crossings if c.axis == 0][:3]:
        ka = b[c.i]
        largest = lambda w: np.abs(np.linalg.eigvals(scipy_monodromy(one_stage_J(w, zeta, ka)))).max() - 1
        assert abs(brentq(largest, a[c.j], a[c.j + 1], xtol=1e-12) - c.value) < 1e-6
    assert chart.kind[2][np.argmin(np.abs(a - 2.0))] == PERIOD_DOUBLING
    # Liouville at every point: det M = exp(int tr J) = exp(-2 zeta / omega * 2 pi)
    product = np.prod(chart.multipliers, axis=-1)
    expected = np.exp(-4 * np.pi * zeta / a)[None, :]
    assert np.allclose(product.real, expected, rtol=1e-8, atol=0) and np.allclose(product.imag, 0, atol=1e-12)


@pytest.fixture(scope="module")
def shaft():
    return compile_linearisation(conftest.system("flexible_shaft", k="1+k_a*cos(tau)", kS=0.5, zeta=0.01))


def shaft_J(omega, ka, zeta=0.01, kS=0.5, I1=1.0, I2=1.0, I3=1.0, r1=1.0, r2=1.0):
    """The flexible shaft's Jacobian at its static state (drive flank in contact), typed from Eqs. 8-9."""
    c = r2**2 / I2 + r1**2 / I1

    def J(t):
        k = 1 + ka * np.cos(t)
        return np.array([[0, 1, 0, 0],
                         [-k / omega**2, -2 * zeta / omega, -kS / (I2 * omega**2), 0],
                         [0, 0, 0, 1],
                         [-r2**2 * k / (I2 * c * omega**2), -2 * r2**2 * zeta / (I2 * omega * c),
                          -kS * (1 / I3 + 1 / I2) / omega**2, 0]])
    return J


@pytest.mark.slow
def test_the_flexible_shaft_chart_matches_an_independent_floquet_computation_with_a_combination_tongue(shaft):
    # modes of the mean stiffness: omega_i^2 = 0.5 and 1.5; tongues at 2 omega_1 = 1.41, omega_1 + omega_2 = 1.93
    # (the combination: a complex pair leaves the circle), 2 omega_2 = 2.45
    chart = static_chart(shaft, {"omega": np.round(np.arange(1.3, 2.6, 0.05), 10), "k_a": [0.2, 0.5]})
    a, b = chart.values
    for i, j in ((1, 2), (1, 12), (1, 23), (0, 5)):
        mu = np.linalg.eigvals(scipy_monodromy(shaft_J(a[j], b[i])))
        assert same(chart.multipliers[i, j], mu), (a[j], b[i])
    kinds = set(chart.kind[1])
    assert {PERIOD_DOUBLING, NEIMARK_SACKER} <= kinds, kinds
    j = np.argmin(np.abs(a - 1.93))
    assert chart.kind[1][j] == NEIMARK_SACKER
    mu = np.linalg.eigvals(scipy_monodromy(shaft_J(a[j], 0.5)))
    assert np.abs(mu).max() > 1 and np.abs(mu[np.argmax(np.abs(mu))].imag) > 1e-3
    # Liouville: tr J = -2 zeta / omega (only the mesh is damped)
    product = np.prod(chart.multipliers, axis=-1)
    assert np.allclose(product.real, np.exp(-4 * np.pi * 0.01 / a)[None, :], rtol=1e-8, atol=0)


def test_every_lane_has_its_own_tables_the_chart_equals_the_scalar_loops(mathieu):
    """k_a enters the tables of time: a grid whose first axis is k_a puts points of different tables side by
    side in the lanes; each must run on its own (the scalar loops run point by point)."""
    grid = {"k_a": np.round(np.linspace(0.0, 0.7, 16), 10), "omega": [0.9, 1.1, 1.9]}
    lanes = static_chart(mathieu, grid, refine=False, zeta=0.01)
    scalar = static_chart(mathieu, grid, refine=False, zeta=0.01, execution=Execution(lanes=False))
    assert all(same(m, s, 1e-12) for m, s in zip(lanes.multipliers.reshape(-1, 2), scalar.multipliers.reshape(-1, 2)))
    assert (lanes.kind == scalar.kind).all()


@pytest.mark.slow
def test_about_the_orbit_a_linear_models_multipliers_are_its_static_states(mathieu):
    """Without backlash the model is linear: the variational equation about its forced orbit is the one about
    its static state, so the two charts' multipliers agree; Newton finds every orbit off the tongues' edges."""
    values = dict(MATHIEU, B0=1.0, B1=0.5, zeta=0.05)
    system = conftest.system("one_stage", **values)
    model = gearsym.compile_model(system, gearsym.Integration())
    grid = {"omega": [0.8, 1.0, 1.3, 2.0, 2.2], "k_a": [0.2, 0.6]}
    orbit = orbit_chart(model, static_recipe(system), grid, refine=False)
    static = static_chart(mathieu, grid, refine=False, zeta=0.05)
    assert (orbit.stable != None).all()  # noqa: E711
    assert all(same(m, s, 1e-9) for m, s in zip(orbit.multipliers.reshape(-1, 2), static.multipliers.reshape(-1, 2)))
    assert orbit.about == "orbit" and "period-1 orbit" in orbit.notes[0]


def test_the_command_writes_the_chart_as_json_and_says_what_it_linearised(tmp_path, capsys):
    out = tmp_path / "chart.csv"
    args = ["stability", "one_stage", *(f"--set={k}={v}" for k, v in MATHIEU.items()),
            "--param", "omega=1.7:2.3:0.1", "--param", "k_a=0.2,0.4", "--format", "json", "--quiet", "--out", str(out)]
    assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) >= {"grid", "points", "boundaries"}
    assert data["grid"]["omega"][0] == 1.7 and len(data["points"]) == 7 * 2
    point = data["points"][3]
    assert set(point) == {"omega", "k_a", "max_modulus", "stable", "kind"}
    assert point["stable"] is False and point["kind"] == PERIOD_DOUBLING  # omega = 2: the principal tongue
    assert any("edge of contact" in n for n in data["notes"])
    assert [b["kind"] for b in data["boundaries"]] and out.read_text().startswith("omega,k_a,max_modulus")
    assert json.loads(out.with_suffix(".json").read_text())["boundaries"] == data["boundaries"]


@pytest.mark.slow
def test_a_physical_axis_is_charted_when_the_start_up_cache_already_holds_the_models_numbers(capsys):
    """After another command on the model (here lyap), its scaling comes from the start-up cache (a stand-in that
    converts no axis): the chart converts the speed in rpm with the full scaling all the same."""
    assert main(["lyap", "spur_pair", "--periods", "10", "--discard", "0"]) == 0
    capsys.readouterr()
    args = ["stability", "spur_pair", "--param", "speed=4000rpm,6000rpm", "--param", "zeta=0.05,0.1", "--no-refine",
            "--quiet", "--format", "json"]
    assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["grid"]["speed"] == [4000.0, 6000.0] and len(data["points"]) == 4


@pytest.mark.parametrize("args, message", [
    (["--param", "omega=1:2:0.5"], "give two --param axes"),
    (["--param", "omega=1:2:0.5", "--param", "nope=1,2"], "nope is not a parameter"),
    (["--param", "omega=1:2:0.5", "--param", "k_a=0.1", "--tolerance", "2"], "--tolerance 2.0"),
])
def test_bad_requests_are_refused_in_one_line(args, message, capsys):
    assert main(["stability", "one_stage", *args, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_the_phasing_prediction_places_the_shafts_tongues_where_its_modes_put_them(shaft):
    """One mesh, no phasing to cancel anything: the first-order tongues at 2 omega_i / l and (omega_i + omega_j) / l
    from the mean stiffness matrix's modes (here omega_i^2 = 0.5, 1.5), each where the chart is unstable."""
    chart = static_chart(shaft, {"omega": np.round(np.arange(1.3, 2.6, 0.05), 10), "k_a": [0.5]}, refine=False)
    prediction = gearsym.stability.phasing_prediction(chart, shaft)
    w1, w2 = np.sqrt(0.5), np.sqrt(1.5)
    first = {t.label: t for t in prediction.tongues if t.label.endswith("/1")}
    assert np.allclose([first["2ω1/1"].centre, first["(ω1+ω2)/1"].centre, first["2ω2/1"].centre],
                       [2 * w1, w1 + w2, 2 * w2], atol=1e-9)
    assert not any(t.suppressed for t in first.values())
    assert first["(ω1+ω2)/1"].kind == NEIMARK_SACKER and first["2ω1/1"].kind == PERIOD_DOUBLING
    for t in first.values():
        j = np.argmin(np.abs(chart.values[0] - t.centre))
        assert chart.stable[0, j] == False, t.label  # noqa: E712 (an object array: True, False or None)


@pytest.mark.slow
def test_the_reproductions_stability_chart_recomputed_matches_the_committed_record(tmp_path):
    """docs/reproduction.md's chart of the paper's model, again: the same tongues, opening at the committed k_a to
    1e-5 (located to 6e-7; another CPU rounds differently), the same verdicts for the two parameter sets."""
    from gearsym.reproduce.stability import MODEL, chart, stability_record

    committed = json.loads((ROOT / "docs" / "figures" / "claims.json").read_text())["stability"]
    again = stability_record(chart(compile_linearisation(conftest.system(MODEL))))
    assert [t["kind"] for t in again["tongues"]] == [t["kind"] for t in committed["tongues"]]
    for t, c in zip(again["tongues"], committed["tongues"]):
        assert abs(t["opens_at_k_a"] - c["opens_at_k_a"]) < 1e-5 and abs(t["omega"] - c["omega"]) < 1e-9
    assert again["scenarios"] == committed["scenarios"]
    assert abs(again["counts"]["stable"] - committed["counts"]["stable"]) <= 2


@pytest.mark.parametrize("about", ABOUT)
@pytest.mark.parametrize("args, message", [
    (["--param", "nope=1,2"], "nope is not a parameter"),
    (["--param", "k_a=1N/m:2N/m:1N/m"], "has a unit, but the model has no physical values"),
    (["--param", "k_a=0.1,0.2", "--set", "k_a=0.3"], "k_a is both swept"),
])
def test_a_wrong_axis_is_refused_in_one_line_before_anything_is_compiled(about, args, message, capsys, monkeypatch):
    """A --set value no other run uses: the cache cannot hold this model, so the command would have to compile it
    (and fails the test) if it checked the axes only after compiling."""
    def compiling(*_, **__):
        raise AssertionError("compiling started before the axes were checked")

    monkeypatch.setattr(gearsym.stability, "compile_linearisation", compiling)
    monkeypatch.setattr(gearsym, "compile_model", compiling)
    argv = ["stability", "one_stage", "--set", "zeta=0.0123457", "--about", about, "--param", "omega=1:2:0.5", *args,
            "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.startswith("gearsym: error: ") and err.count("\n") == 1, err


def test_the_phasing_panel_draws_each_kept_tongue_as_its_wedge_and_each_suppressed_one_as_a_cross(shaft):
    """The second panel of the figure: a kept first-order tongue is a wedge of its kind's colour from its centre
    on the frequency axis to its edges at the top of the variation axis; a suppressed one a dotted line and a
    cross at its centre (the shaft has one mesh, nothing suppressed: one tongue is marked so here to draw both);
    each is named, the chart's boundaries are drawn beside them, and no text leaves the figure."""
    from dataclasses import replace

    from figure_checks import clipped_texts
    from gearsym.figures.save import pyplot
    from gearsym.figures.stability import KIND_COLORS, plot_stability
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgb

    chart = static_chart(shaft, {"omega": np.round(np.arange(1.3, 2.6, 0.05), 10), "k_a": [0.2, 0.5]}, refine=False,
                         execution=Execution(lanes=False))  # (the scalar loops: no lanes to compile for a few points)
    prediction = gearsym.stability.phasing_prediction(chart, shaft)
    tongues = list(prediction.tongues)
    combination = next(k for k, t in enumerate(tongues) if t.label == "(ω1+ω2)/1")
    tongues[combination] = replace(tongues[combination], suppressed=True)
    prediction = replace(prediction, tongues=tuple(tongues))
    fig = plot_stability(chart, prediction=prediction)
    assert len(fig.axes) == 2
    panel = fig.axes[1]
    assert panel.get_title().split() == prediction.title.split()  # (wrapped to fit)
    a, b = chart.values
    shown = [t for t in tongues if a.min() <= t.centre <= a.max()]
    kept = [t for t in shown if not t.suppressed and 2 * t.half_width >= 2e-3 * np.ptp(a)]
    wedges = [c for c in panel.collections if isinstance(c, PolyCollection)]
    assert len(wedges) == len(kept) and kept
    for t, wedge in zip(kept, wedges):
        x, y = wedge.get_paths()[0].vertices.T
        lo, hi = t.edges(np.array([b.max()]), prediction.scale)
        assert np.isclose(x[y == 0].mean(), t.centre) and np.isclose(x.min(), lo[0]) and np.isclose(x.max(), hi[0])
        assert np.allclose(wedge.get_facecolor()[0][:3], to_rgb(KIND_COLORS[t.kind]))
    crosses = [line for line in panel.lines if line.get_marker() == "x"]
    dotted = [line for line in panel.lines if line.get_linestyle() == ":"]
    assert [float(c.get_xdata()[0]) for c in crosses] == [tongues[combination].centre]
    assert [float(d.get_xdata()[0]) for d in dotted] == [tongues[combination].centre]
    grey = [line for line in panel.lines if to_rgb(line.get_color()) == to_rgb("0.65")]
    assert len(grey) == len(chart.boundaries) > 0
    assert sorted(t.get_text() for t in panel.texts) == sorted(t.label for t in shown)
    assert clipped_texts(fig) == []
    pyplot().close(fig)


@pytest.mark.slow  # (a model of its own compiled: ~4 s of CPU)
def test_a_point_without_a_periodic_orbit_is_marked_not_guessed():
    """k = k_m (1 + 0.2 cos tau) with a static load: at k_m = 0 there is no stiffness, the load drives the gear
    off at a growing distance and no period-1 orbit exists (nor a static state to start from); Newton from the
    neighbours' orbits cannot converge. Those points are marked, with no multipliers, and said in a note; the
    others have the orbits' multipliers, whose product is Liouville's exp(-4 pi zeta / omega)."""
    zeta = 0.05
    values = dict(k="k_m*(1+0.2*cos(tau))", k_m=1.0, zeta=zeta, eta=0, B0=1.0, B1=0.5)
    system = conftest.system("one_stage", **values)
    model = gearsym.compile_model(system, gearsym.Integration())
    chart = orbit_chart(model, static_recipe(system), {"omega": [0.8, 1.3], "k_m": [0.0, 0.5, 1.0]}, refine=False,
                        execution=Execution(lanes=False))
    assert (chart.stable[0] == None).all() and (chart.kind[0] == NO_ORBIT).all()  # noqa: E711
    assert np.isnan(chart.multipliers[0]).all() and np.isnan(chart.max_modulus[0]).all()
    assert (chart.stable[1:] != None).all() and chart.counts()[NO_ORBIT] == 2  # noqa: E711
    product = np.prod(chart.multipliers[1:], axis=-1)
    assert np.allclose(product, np.exp(-4 * np.pi * zeta / chart.values[0])[None, :], rtol=1e-6, atol=0)  # (RK4)
    assert any("2 point(s): no periodic orbit found" in n and NO_ORBIT in n for n in chart.notes), chart.notes
