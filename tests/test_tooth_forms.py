"""The tooth-by-tooth forms of the data loop (issue 41), piece by piece and cheaply: the fit's slots are the written-out
form within every window; the fit's problem maps each slot to its tooth's parameter and adds the slot's derivative
to that tooth's column (against finite differences); a regularised fit's uncertainties are the posterior's; which
teeth stand out; a spall is in the library. tests/test_faults.py finds faults with them on an independent rig."""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import gearsym
from gearsym import explain, load_measurements
from gearsym.errors import GearsymError
from gearsym.fit.effect_types import site
from gearsym.fit.effects import augment
from gearsym.fit.jacobian import Jacobian
from gearsym.fit.problem import Problem
from gearsym.fit.segment import Segment
from gearsym.fit.selection import candidate_library
from gearsym.fit.tooth_forms import general_forms, local_effect, place_slots, standing_out
from gearsym.fit.uncertainty import uncertainty
from gearsym.options import Integration

TEETH = (5, 7)


@pytest.fixture(scope="module")
def geared():
    return gearsym.load("one_stage", teeth=TEETH)


def _numeric(expr, system, values: dict):
    """``expr`` with the system's parameters at ``values`` (else their defaults) as a function of (tau, x)."""
    x = system.states[0]
    subs = {p: values.get(p.name, system.parameters.get(p.name, 0.0)) for p in expr.free_symbols
            if p not in (system.time, x)}
    return sp.lambdify((system.time, x), expr.xreplace(subs), "numpy")


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["tooth_stiffness", "tooth_profile"])
def test_the_fits_slots_are_the_written_out_form_in_every_window(geared, kind):
    """Per-tooth values at random: within two forcing periods from any start, the mesh law of the form the fit
    compiles (each gear's slots, placed for that start) is the law of every tooth written out, to 5e-5 of the
    largest tooth value (the windows' tanh tails beyond the slots, and on so small a gear a window's leak on the far
    side of the revolution, where its periodic edges' sines turn back)."""
    (e,) = general_forms(geared, (kind,)).values()
    rng = np.random.default_rng(1)
    values = dict(zip(e.fitted, rng.uniform(-0.3, 0.3, len(e.fitted))))
    s = site(geared, "mesh")
    local, slots = local_effect(e, 1.0, 2 * math.pi)
    written, compiled = e.build(s), local.build(s)
    law = (lambda c: c.law.xreplace({s.backlash: 1})) if kind == "tooth_stiffness" else (lambda c: c.contact)
    full = _numeric(law(written), geared, values)
    for start in (0.3, 17.9, 2 * math.pi * 35 + 1.1):  # (the last beyond a hunting period of 35 mesh periods)
        segment = Segment(np.array([start]), {}, {}, "", {}, None)
        (placed,) = place_slots([segment], slots, values)
        part = _numeric(law(compiled), geared, placed.parameters)
        tau = start + np.linspace(0, 4 * math.pi, 301)
        np.testing.assert_allclose(part(tau, 1.5 + 0 * tau), full(tau, 1.5 + 0 * tau), atol=5e-5 * 0.3, rtol=0)
    # two windows of one mesh period each, the contact ratio's overlap, the tails: 6 slots; the 5-tooth gear's 5 once
    assert [len(sl.slots) for sl in slots] == [5, 6]


def test_the_problem_maps_each_slot_to_its_tooth_and_adds_its_derivative_there(geared):
    """On the in-process backend (no C compiled): the parameters each window runs with are its teeth's values, and
    the Jacobian's column of a tooth is the finite difference of the residuals by that tooth's value."""
    (e,) = general_forms(geared, ("tooth_stiffness",)).values()
    local, slots = local_effect(e, 1.0, 2 * math.pi)
    model = augment(geared, [local], name="one_stage_slots_test")
    tau0 = [0.4, 2 * math.pi * 3 + 0.4, 2 * math.pi * 6 + 0.4]
    segments = [Segment(t + np.linspace(0, 2 * math.pi, 21)[:-1], {"x": np.sin(np.linspace(0, 6, 20)) + 0.5},
                        dict(model.parameters), f"w{k}", {"x": sp.Symbol("x", real=True)}, (("r", 1), k))
                for k, t in enumerate(tau0)]
    fit = ["zeta", *e.fitted]
    problem = Problem(model, segments, fit, [], 2 * math.pi, Integration(backend="in-process"), slots)
    theta = np.concatenate([[0.08], np.linspace(-0.2, 0.25, len(e.fitted))])
    P = problem.parameters(theta)
    placed = place_slots(segments, slots, dict(zip(fit, theta)))
    for k, seg in enumerate(placed):
        for name in (*slots[0].slots, *slots[1].slots, slots[0].first, slots[1].first):
            assert P[problem.names.index(name), k] == pytest.approx(seg.parameters[name], abs=0)
    u = np.concatenate([theta, np.tile([1.0, 0.2], len(segments))])
    r, J = problem(u)
    for name in ("kt2_gear1", "kt4_gear2", "kt7_gear2"):
        i = fit.index(name)
        h = 1e-6
        up, down = u.copy(), u.copy()
        up[i] += h
        down[i] -= h
        numeric = (problem(up, False)[0] - problem(down, False)[0]) / (2 * h)
        np.testing.assert_allclose(J.P[:, i], numeric, rtol=1e-5, atol=1e-7 * np.abs(numeric).max())
        assert np.abs(J.P[:, i]).max() > 0


def test_a_regularised_fits_uncertainties_are_the_posteriors():
    """Without start states' coupling (one window, its start columns orthogonal), the covariance is
    sigma^2 (J^T J + W)^-1 with W the ridge's weights; a direction the data cannot see is then determined by the
    prior, not flagged."""
    rng = np.random.default_rng(2)
    rows = 40
    A = rng.normal(size=(rows, 3))
    A[:, 2] = A[:, 0] + A[:, 1]  # a direction the data cannot see
    S = np.zeros((rows, 2))
    J = Jacobian(A, S, np.zeros(rows, dtype=int), np.array([0, rows]))
    r = rng.normal(size=rows) * 0.1
    sigma2 = 0.01
    names = ["a", "b", "c"]
    without = uncertainty(J, r, sigma2, names, np.zeros(3, dtype=bool))
    assert not all(without[1].values())  # not identifiable without a prior
    ridge = np.array([0.5, 0.5, 0.5])
    stderr, identifiable, _, covariance = uncertainty(J, r, sigma2, names, np.zeros(3, dtype=bool), ridge)
    expected = sigma2 * np.linalg.inv(A.T @ A + np.diag(ridge))
    assert all(identifiable.values())
    for i, n in enumerate(names):
        assert stderr[n] == pytest.approx(math.sqrt(expected[i, i]), rel=1e-9)
        for j, m in enumerate(names):
            assert covariance[n][m] == pytest.approx(expected[i, j], rel=1e-9, abs=1e-15)


def test_the_teeth_that_stand_out_depart_from_their_gears_median_by_many_standard_errors():
    values = {"gear1": [(0.02, 0.01)] * 8 + [(0.02 + 0.3, 0.01)],
              "gear2": [(-0.01, 0.01), (0.03, 0.01), (-0.02, 0.01), (-0.01, 0.01), (-0.015, 0.01)]}
    assert standing_out(values) == {"gear1": [9], "gear2": []}
    values["gear1"][8] = (0.02 + 0.04, 0.01)  # 4 standard errors: not enough
    assert standing_out(values) == {"gear1": [], "gear2": []}
    values["gear2"][1] = (0.3, 0.05)  # large, but within 6 standard errors of its gear: stands out
    assert standing_out(values) == {"gear1": [], "gear2": [2]}


def test_a_spall_is_in_the_library_of_a_model_with_teeth(geared):
    library = candidate_library(geared)
    assert {"spall_gear1", "spall_gear2", "tooth_fault_gear1", "tooth_fault_gear2"} <= set(library)
    spall = library["spall_gear2"]
    assert spall.scan == "spall_tooth_gear2" and spall.bounds["ws_gear2"][:2] == (0.0, 0.95)
    assert not any(name.startswith(("spall", "tooth_stiffness")) for name in candidate_library(gearsym.load("one_stage")))
    # the tooth-by-tooth forms are tried after the named faults (in explain), not refitted among them
    assert not any(e.gears for e in library.values())


def test_the_tooth_by_tooth_forms_need_tooth_counts(tmp_path):
    """Asked for on a model whose gears have no tooth counts: one line that says what to give."""
    tau = np.linspace(0, 8 * math.pi, 100, endpoint=False)
    path = tmp_path / "m.csv"
    path.write_text("tau,x\n" + "".join(f"{float(t)!r},{math.sin(t)!r}\n" for t in tau))
    one_stage = gearsym.load("one_stage")
    with pytest.raises(GearsymError, match="tooth_stiffness: no mesh of one_stage has two gears with tooth counts"):
        explain(one_stage, load_measurements([path], one_stage), ["zeta"], candidates=["tooth_stiffness"])
