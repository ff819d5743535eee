"""The fit's compiled windows: outputs and their derivatives by the start state and every parameter, in one C
call for all windows, the same as CasADi's in-process evaluation and as finite differences of the flow."""
from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import conftest
from gearsym.codegen.windows import Windows
from gearsym.fit import augment
from gearsym.fit.observed import observed_windows


@pytest.fixture(scope="module")
def case():
    # (the transmission errors' four parameters share the mesh force's derivative: taken all at once, see below)
    # (Coulomb friction at 0, its default: its time values divide, and are skipped, see the test of skipping)
    system = augment(conftest.system("one_stage"), ["cubic_stiffness", "torque_harmonic_3", "transmission_error_1",
                                                    "transmission_error_2", "coulomb_friction"],
                     values={"k3": 0.01, "B_c3": 0.4, "B_s3": -0.2, "e_c1": 0.1, "e_s2": -0.05})
    x, v = system.states
    channels = [x, system.rhs[1], sp.cos(7 * system.time) * x]  # a state, the acceleration, a high harmonic
    K = 5
    rng = np.random.default_rng(2)
    starts = np.vstack([rng.uniform(-12, 4, K), rng.uniform(-2, 2, K)])
    t0 = rng.uniform(0, 30, K)
    dt = np.full(K, 2 * np.pi / 37.3)
    samples = np.array([37, 38, 37, 38, 37])
    substeps = np.full(K, 6)
    p = np.tile(np.array(list(system.parameters.values()))[:, None], (1, K))
    return system, channels, (starts, t0, dt, samples, substeps, p)


@pytest.mark.slow
def test_compiled_and_in_process_windows_agree(case):
    system, channels, args = case
    compiled = Windows(system, channels, "compiled").run(*args)
    inprocess = Windows(system, channels, "in-process").run(*args)
    for a, b in zip((compiled.states, compiled.outputs, compiled.derivatives),
                    (inprocess.states, inprocess.outputs, inprocess.derivatives)):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    some = Windows(system, channels, "compiled").run(*args, channels=[2, 0])  # a call computes the channels it asks
    assert np.array_equal(some.outputs, compiled.outputs[[2, 0]])
    assert np.array_equal(some.derivatives, compiled.derivatives[[2, 0]])


def test_a_displacement_and_an_accelerometer_in_seconds_are_read_from_one_library(case):
    """x and 62500 x_ddot (an accelerometer in seconds, tau = 250 t) come from the model's one library of its states
    and rates: x the same bits as a library of its own gives, x_ddot its rate times the scale; a channel with the
    time in it has a library of its own."""
    system, _, (starts, t0, dt, samples, substeps, p) = case
    x, x_ddot = system.states[0], sp.Symbol("x_ddot", real=True)
    shown = observed_windows(system, [x], "in-process")
    felt = observed_windows(system, [62500.0 * x_ddot], "in-process")
    assert shown.windows is felt.windows
    own = Windows(system, [x, system.rhs[1]], "in-process").run(starts, t0, dt, samples, substeps, p, columns=[1, 3])
    a, b = (w.run(starts, t0, dt, samples, substeps, p, columns=[1, 3]) for w in (shown, felt))
    assert np.array_equal(a.outputs, own.outputs[:1]) and np.array_equal(a.derivatives, own.derivatives[:1])
    assert np.array_equal(b.outputs, 62500.0 * own.outputs[1:]) and np.array_equal(b.derivatives,
                                                                                   62500.0 * own.derivatives[1:])
    assert isinstance(observed_windows(system, [sp.cos(7 * system.time) * x], "in-process"), Windows)


@pytest.mark.slow
def test_time_values_only_effects_at_zero_use_are_skipped_with_the_same_results(case):
    """A window skips the time values that only matter while a parameter it has at 0, and whose column it does not ask
    for, is not (gearsym/codegen/time_gates.py): Coulomb friction's (which divide: kept finite, not set to 0), a
    transmission error's terms at 0, the cubic stiffness and the torque harmonic's pair in the windows that have them
    at 0. Outputs and derivatives, a column asked for at 0 among them, are the in-process evaluation's, which computes
    every time value at every step."""
    system, channels, (starts, t0, dt, samples, substeps, p) = case
    names = list(system.parameters)
    some = [2, 4]  # (two windows that start in contact: the mesh's parameters act from the first step)
    p = p[:, some].copy()
    p[names.index("k3"), 0] = 0
    p[names.index("B_c3"), 1] = p[names.index("B_s3"), 1] = 0
    at_rest = starts[:, some].copy()
    at_rest[1, 0] = 0  # (friction's 1 / sqrt(eps_c^2 + v^2) at v = 0: finite with its skipped eps_c^2 kept, not 0)
    args = (at_rest, t0[some], dt[some], np.array([12, 9]), substeps[some], p)
    compiled, inprocess = Windows(system, channels, "compiled"), Windows(system, channels, "in-process")
    gates = {tuple(names[j] for j in gate) for group in inprocess.functions.groups for gate in group.gates}
    assert {("mu_c",), ("e_c2",), ("k3",), ("B_c3", "B_s3")} <= gates, gates
    asked = [names.index(c) for c in ("zeta", "e_c2", "k3")]  # (e_c2 at 0 everywhere)
    for tangent in (True, False):
        a, b = (w.run(*args, tangent=tangent, columns=asked) for w in (compiled, inprocess))
        for x, y in zip((a.states, a.outputs, a.derivatives), (b.states, b.outputs, b.derivatives)):
            assert (x is None and y is None) or (np.all(np.isfinite(x)) and np.allclose(x, y, rtol=1e-12, atol=1e-12))
        assert not tangent or np.abs(a.derivatives[:, system.dimension + 1]).max() > 0.01  # (e_c2's: not 0)


def test_window_derivatives_are_those_of_the_discrete_flow(case):
    system, channels, (starts, t0, dt, samples, substeps, p) = case
    windows = Windows(system, channels, "compiled")
    run = windows.run(starts, t0, dt, samples, substeps, p)
    n = system.dimension
    names = list(system.parameters)
    for column in (0, 1, n + names.index("zeta"), n + names.index("k3"), n + names.index("B_s3")):
        h = 1e-6
        up, down = starts.copy(), starts.copy()
        pu, pd = p.copy(), p.copy()
        if column < n:
            up[column] += h
            down[column] -= h
        else:
            pu[column - n] += h
            pd[column - n] -= h
        diff = (windows.run(up, t0, dt, samples, substeps, pu, tangent=False).outputs
                - windows.run(down, t0, dt, samples, substeps, pd, tangent=False).outputs) / (2 * h)
        scale = np.abs(run.derivatives[:, column, :]).max()
        np.testing.assert_allclose(run.derivatives[:, column, :], diff, atol=1e-6 * scale)


def test_harmonics_of_time_are_evaluated_exactly(case):
    system, channels, (starts, t0, dt, samples, substeps, p) = case
    run = Windows(system, channels, "compiled").run(starts, t0, dt, samples, substeps, p, tangent=False)
    tau = np.concatenate([t + d * np.arange(s) for t, d, s in zip(t0, dt, samples)])
    np.testing.assert_allclose(run.outputs[2], np.cos(7 * tau) * run.states[0], rtol=0, atol=1e-12 * 20)


def test_every_column_at_once_is_each_column_asked_for_alone(case):
    """A call asking for every parameter's column takes them from every parameter's forcing at once (fewer operations
    than the columns one by one, which is what the driver compares: so here); a call asking for one parameter alone
    takes its own column function. They are the same derivatives."""
    system, channels, args = case
    windows = Windows(system, channels, "compiled")
    f = windows.functions
    forced = f["fit_column_forced"].n_instructions()  # (a column from its forcing: each parameter's own, or all)
    one_by_one = sum(f[f"fit_param_{j}"].n_instructions() + forced for j in range(windows.parameters))
    assert f["fit_forcing"].n_instructions() + windows.parameters * forced < one_by_one
    every = windows.run(*args).derivatives
    n = system.dimension
    for j in range(windows.parameters):
        alone = windows.run(*args, columns=[j]).derivatives
        np.testing.assert_allclose(every[:, :n], alone[:, :n], rtol=0, atol=1e-13 * np.abs(alone[:, :n]).max())
        scale = np.abs(alone[:, n]).max()
        np.testing.assert_allclose(every[:, n + j], alone[:, n], rtol=0, atol=1e-12 * max(scale, 1e-300),
                                   err_msg=list(system.parameters)[j])


@pytest.mark.parametrize("tangent,columns", [(True, None), (True, [1, 4]), (False, None)])
def test_windows_shared_between_threads_give_the_bits_of_one_call(case, monkeypatch, tangent, columns):
    """A large call is split over the cores, each thread writing its windows' columns: the same numbers, bit for
    bit, as the windows in one call (three pieces of unequal windows, every piece's columns offset)."""
    import gearsym.codegen.windows as windows

    system, channels, args = case
    compiled = Windows(system, channels, "compiled")
    one = compiled.run(*args, tangent=tangent, columns=columns)
    monkeypatch.setattr(windows, "MIN_SHARED_STEPS", 0)
    monkeypatch.setattr(windows.os, "cpu_count", lambda: 3)
    assert len(windows._pieces(args[3], args[4])) == 3
    shared = compiled.run(*args, tangent=tangent, columns=columns)
    for a, b in zip((one.states, one.outputs, one.derivatives), (shared.states, shared.outputs, shared.derivatives)):
        assert (a is None and b is None) or np.array_equal(a, b)
    assert np.all(shared.outputs[:, -1] != 0)  # the last piece's columns were written


def test_a_records_columns_are_projected_in_its_own_rows_as_the_whole_problem_projects_them():
    """The tooth scan's projection (issue 35: 250 records of 5000 samples took 7.5 GB as whole-problem columns per
    record) equals Jacobian.project_out of the same columns laid out over every row, in the norm and product the
    scan ranks teeth by, and in the column itself."""
    from gearsym.fit.jacobian import Jacobian
    from gearsym.fit.tooth_scan import RecordProjection

    rng = np.random.default_rng(7)
    lengths = rng.integers(5, 12, size=9)  # 9 windows: records of 3 windows each
    rows = np.concatenate([[0], np.cumsum(lengths)])
    window = np.repeat(np.arange(9), lengths)
    J = Jacobian(rng.normal(size=(rows[-1], 3)), rng.normal(size=(rows[-1], 2)), window, rows)
    y = J.project_out(rng.normal(size=(rows[-1], 1)))[:, 0]
    projection = RecordProjection.of(J, y)
    windows = np.array([3, 4, 5])
    own_rows = J.window_rows(windows)
    block = rng.normal(size=(len(own_rows), 4))
    full = np.zeros((rows[-1], 4))
    full[own_rows] = block
    dense = J.project_out(full)
    own, c, norms, dots = projection(block, windows, own_rows)
    column = -projection.fitted @ c
    column[own_rows] += own
    np.testing.assert_allclose(column, dense, atol=1e-12)
    np.testing.assert_allclose(norms, np.einsum("rz,rz->z", dense, dense), rtol=1e-10)
    np.testing.assert_allclose(dots, dense.T @ y, atol=1e-10)
