"""The lanes where their blocks are not simple: a last block partly filled, points that each bring their own tables
of time, sweeps longer than a block, blocks that alternate between shared and per-lane tables.

Each lanes result is compared with the scalar loops' (the engine's other path) and, where the numbers are the
paper's equation, with SciPy's solution of Eq. 2 typed here. The runs are short: a partly filled block is seen
in the states the starts end in before they reach their attractor, and a wrong table in the amplitude.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import gearsym
from gearsym import Integration, lyapunov_spectrum
from gearsym.analysis.lane_spectra import lyapunov_spectra
from gearsym.codegen.compiler import find_compiler
from gearsym.codegen.lane_runs import LaneRunner

import conftest

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="the lanes need a C compiler")

#: the paper's one-stage values (models/one_stage.py)
ZETA, B0, B1, ETA, K_A = 0.08, 1.0, 4.0, 10.0, 0.2
SWEEP = dict(mode="independent", options=Integration(periods=60, discard=20))
LANES, SCALAR = gearsym.Execution(jobs=1, lanes=True), gearsym.Execution(jobs=1)


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def lanes_width(model) -> int:
    """Trajectories per native call of this build (4 or 8 on x86-64)."""
    return LaneRunner(model, 0, 1).width


def eq2_final_state(start, omega: float, periods: int, Theta: float = 0.0) -> np.ndarray:
    """Eq. 2 of the paper, x'' + 2 zeta/omega x' + k(tau) g(x)/omega^2 = (B0 + B1 cos(tau + Theta))/omega^2, typed
    here with the backlash g, from ``start`` over ``periods`` forcing periods (DOP853). k(tau) is the model's
    mesh stiffness (its rectangular series), taken from the model's equations."""
    system = conftest.system("one_stage")
    (backlash,) = [f for f in system.rhs[1].atoms(sp.Function) if f.func.__name__ == "g"]
    G = sp.Dummy("G")
    stiffness = -sp.diff(system.rhs[1].subs(backlash, G), G) * sp.Symbol("omega", real=True) ** 2
    k = sp.lambdify(system.time, sp.expand(stiffness).subs(
        {s: system.parameters[s.name] for s in stiffness.free_symbols if s.name in system.parameters}), "math")

    def g(x):
        return x if x >= 0 else (0.0 if x > -ETA else x + ETA)

    def rhs(tau, y):
        x, v = y
        return [v, -2 * ZETA * v / omega + (B0 + B1 * math.cos(tau + Theta)) / omega ** 2 - k(tau) * g(x) / omega ** 2]

    sol = solve_ivp(rhs, (0.0, 2 * math.pi * periods), list(start), method="DOP853", rtol=1e-11, atol=1e-11)
    return sol.y[:, -1]


def test_starts_in_a_partly_filled_last_block_end_in_their_own_states(one_stage):
    """One more than a block and three more (width + 3 starts): the last block's three lanes are the starts'
    own, the rest of it padding; every start ends where the scalar loop and SciPy take it."""
    width = lanes_width(one_stage)
    starts = np.random.default_rng(11).uniform(-6, 6, size=(width + 3, 2))
    options = Integration(periods=3, discard=1)
    p = one_stage.parameter_vector(omega=1.2)
    wide = lyapunov_spectra(one_stage, starts, options, p)
    assert len(wide) == len(starts)
    finals = np.array([[w.final_state["x"], w.final_state["v"]] for w in wide])
    assert len({tuple(np.round(f, 6)) for f in finals}) == len(starts)  # (still apart after 3 periods)
    for y0, w, final in zip(starts, wide, finals):
        one = lyapunov_spectrum(one_stage, options=options, y0=y0, omega=1.2)
        assert final == pytest.approx([one.final_state["x"], one.final_state["v"]], rel=0, abs=1e-9), y0
        assert w.strobe[:, -1] == pytest.approx(final, rel=0, abs=1e-12)  # the last Poincare point is the end
        assert np.allclose(w.strobe, one.strobe, rtol=0, atol=1e-9), y0
        assert w.amplitude["x"] == pytest.approx(one.amplitude["x"], rel=1e-9)
        assert np.allclose(w.exponents, one.exponents, rtol=0, atol=1e-9), y0
        assert final == pytest.approx(eq2_final_state(y0, 1.2, 3), rel=0, abs=2e-5), y0


def test_a_lanes_sweep_over_a_phase_gives_each_point_its_own_tables(one_stage):
    """Theta moves the forcing's table of time, so every lane of the call has a table of its own: the issue's
    sweep gives the scalar sweep's A_x = 4.65, 5.30, 5.76, 6.29, not one value four times."""
    axes = ["Theta=0,0.5,1,1.5"]
    wide = gearsym.run_sweep(one_stage, axes, execution=LANES, **SWEEP)
    one = gearsym.run_sweep(one_stage, axes, execution=SCALAR, **SWEEP)
    assert np.allclose(wide["A_x"], one["A_x"], rtol=0, atol=1e-3)
    assert np.allclose(wide["A_x"], [4.65, 5.30, 5.76, 6.29], rtol=0, atol=0.01)
    assert np.min(np.diff(wide["A_x"])) > 0.3  # four different motions
    assert np.allclose(wide["lambda_1"], one["lambda_1"], rtol=0, atol=0.01)  # (chaotic points: 0.01)
    # the periodic point (Theta = 0) against SciPy: its last state and its amplitude over the measured periods
    assert wide["regime"][0] == one["regime"][0] == "periodic"
    final = eq2_final_state([-2.0, -0.5], 1.5, 60, Theta=0.0)
    assert [wide["final_x"][0], wide["final_v"][0]] == pytest.approx(final, rel=0, abs=1e-4)


def test_a_lanes_sweep_longer_than_a_block_gives_the_scalar_sweeps_rows(one_stage):
    """A block and a partly filled one (width + 2 points; 10 on an 8-lane build): every row, the extremes and
    exponents of the second block's points included, is the scalar sweep's."""
    width = lanes_width(one_stage)
    omegas = np.round(np.linspace(1.5, 1.95, width + 2), 6)
    axes = {"omega": omegas}
    wide = gearsym.run_sweep(one_stage, axes, execution=LANES, **SWEEP)
    one = gearsym.run_sweep(one_stage, axes, execution=SCALAR, **SWEEP)
    assert len(wide) == len(one) == width + 2
    assert list(wide["regime"]) == list(one["regime"])
    for column in ("A_x", "A_v", "lambda_1", "lambda_2", "final_x", "final_v"):
        if column in one.columns:
            assert np.allclose(wide[column], one[column], rtol=1e-7, atol=1e-9), column
    # the amplitudes differ from point to point (a row copied from a neighbour would be seen)
    assert len(set(np.round(one["A_x"], 4))) == width + 2


def test_blocks_of_shared_tables_then_others_each_use_their_own(one_stage):
    """omega x Theta (the first axis fastest): each block of points shares one table (one Theta), the next block
    another, so a table kept from the block before would be seen; the rows are the scalar sweep's."""
    width = lanes_width(one_stage)
    omegas = np.round(np.linspace(1.5, 1.85, width), 6)
    axes = {"omega": omegas, "Theta": [0.0, 1.0, 2.0]}
    wide = gearsym.run_sweep(one_stage, axes, execution=LANES, **SWEEP)
    one = gearsym.run_sweep(one_stage, axes, execution=SCALAR, **SWEEP)
    assert len(wide) == 3 * width
    assert list(wide["Theta"]) == list(one["Theta"]) and list(wide["omega"]) == list(one["omega"])
    periodic = np.array([r == "periodic" for r in one["regime"]])
    assert periodic.sum() >= width  # (most of these points are periodic: compared tightly)
    assert np.allclose(wide["A_x"][periodic], one["A_x"][periodic], rtol=1e-7, atol=1e-9)
    assert np.allclose(wide["A_x"], one["A_x"], rtol=0, atol=0.05)
    assert np.allclose(wide["lambda_1"], one["lambda_1"], rtol=0, atol=0.01)
