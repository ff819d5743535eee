"""Steps split at backlash crossings (``locate_crossings``, the default): 4th order exponents, checked against DOP853.

Plain RK4 with a fixed step is only first order for the exponents of the gear models: the slope of
the backlash g jumps, so the variational equations have a discontinuous right-hand side and the
error jumps about with the step count. The order tests use the in-process backend (no compile of
the 3200-step loops); the DOP853 comparison and the sum rule use the compiled library at 200 steps.
"""
from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import gearsym
import rig
from conftest import system
from gearsym import FirstOrderSystem, Integration, ModelError, compile_model
from gearsym.model.backlash import g
from gearsym.codegen.functions import LoopOptions, build_functions
from gearsym.codegen.generate import code_hash, write_code
from gearsym.model.stiffness import rectangular_mesh_stiffness
from gearsym.files.paths import REPO_ROOT
from gearsym.model.symbols import parameter_symbol, phi

PERIODS, DISCARD = 80, 30
STEPS = (100, 200, 400, 800)
REFERENCE_STEPS = 1600


def exponents(model, steps: int, locate: bool, periods: int = PERIODS, discard: int = DISCARD,
              backend: str = "in-process", **values) -> np.ndarray:
    model = system(model) if isinstance(model, str) else model
    cm = compile_model(model, Integration(steps_per_period=steps, locate_crossings=locate, backend=backend))
    inputs = cm.prepare(cm.parameter_vector(values))
    run = cm.tangent_run(None, periods, inputs)
    return np.sort(run.log_stretch[:, discard:].mean(axis=1) / inputs.period)[::-1]


def errors(model, locate: bool, **values) -> list[float]:
    reference = exponents(model, REFERENCE_STEPS, locate, **values)
    return [float(np.abs(exponents(model, n, locate, **values) - reference).max()) for n in STEPS]


@pytest.mark.parametrize("model, omega", [("one_stage", 1.5), ("one_stage", 1.8), ("flexible_shaft", 1.8)])
@pytest.mark.slow
def test_exponents_converge_at_fourth_order_with_crossings_located(model, omega):
    located = errors(model, True, omega=omega)
    ratios = [a / b for a, b in zip(located, located[1:])]
    assert all(r >= 8 for r in ratios), (located, ratios)  # 4th order: 16 per halving (measured 13-16)
    assert located[1] < 1e-8, located  # 200 steps per period
    plain = errors(model, False, omega=omega)
    assert not all(a / b >= 8 for a, b in zip(plain, plain[1:])), plain  # plain RK4 is not (first order)
    assert plain[1] > 10 * located[1]


def test_time_dependent_switching_surface_converges_at_fourth_order():
    """A surface that moves with time (g(x - sin(t)/2, eta)): the crossing's slope includes dT/dt."""
    t, x, v = sp.symbols("t x v", real=True)
    eta = parameter_symbol("eta")
    rhs = (v, -(1 + sp.Rational(3, 10) * sp.cos(t)) * g(x - sp.sin(t) / 2, eta) - v / 10 + 2 * sp.cos(t))
    moving = FirstOrderSystem("moving_kink", t, (x, v), rhs, {"eta": 1.0}, 2 * sp.pi, initial={"x": 0.3})
    reference = exponents(moving, 1600, True, periods=40, discard=20)
    errs = [float(np.abs(exponents(moving, n, True, periods=40, discard=20) - reference).max())
            for n in (100, 200, 400)]
    assert all(a / b >= 8 for a, b in zip(errs, errs[1:])), errs


# ---------------------------------------------------------------- an independent reference: DOP853
ZETA, B0, B1, THETA, ETA, K_A = 0.08, 1.0, 4.0, 0.0, 10.0, 0.2
#: (n, coefficient of cos(n tau)) of the mesh stiffness variation: gearsym's own default k(tau)
#: (rectangular_mesh_stiffness(): contact ratio 1.6, 7 Lanczos-smoothed harmonics, 12 digits; the paper shows
#: k only as a plot), checked against its formula by quadrature in the test below
HARMONICS = ((1, 1.18003861468), (2, -0.336894506314), (3, -0.195632837787), (4, 0.192724343884),
             (6, -0.0605674179821), (7, 0.0148837545288))


def test_the_stiffness_constants_are_the_smoothed_rectangular_wave():
    """HARMONICS, and STIFFNESS of tests/rig.py, against what rectangular_mesh_stiffness() says they are, computed
    here by quadrature: the Fourier coefficients of a rectangular wave of mean 0 and height 2 (the double-contact
    fraction d = contact ratio - 1 = 0.6 of each period above the rest) averaged over a window of 2 pi/8 (Lanczos'
    sigma factors on 7 harmonics are that moving average), to the 12 digits they are rounded to; and gearsym's
    default k(tau) is made of these numbers."""
    d, harmonics = 0.6, 7
    window = 2 * np.pi / (harmonics + 1)

    def smoothed(angle):  # the wave's mean over angle -+ window/2, for an angle in [-pi, pi]
        inside = np.minimum(angle + window / 2, np.pi * d) - np.maximum(angle - window / 2, -np.pi * d)
        return 2 * np.clip(inside, 0, None) / window - 2 * d

    nodes, weights = np.polynomial.legendre.leggauss(40)
    kinks = [-np.pi, -np.pi * d - window / 2, -np.pi * d + window / 2, np.pi * d - window / 2,
             np.pi * d + window / 2, np.pi]

    def integral(f):  # Gauss-Legendre between the kinks: exact to rounding for each smooth piece
        return sum((b - a) / 2 * weights @ f((b - a) / 2 * nodes + (a + b) / 2) for a, b in zip(kinks, kinks[1:]))

    assert integral(smoothed) == pytest.approx(0, abs=1e-14)  # mean 0: the stiffness's mean is 1
    coefficients = [integral(lambda angle: smoothed(angle) * np.cos(n * angle)) / np.pi
                    for n in range(1, harmonics + 1)]
    assert list(rig.STIFFNESS) == pytest.approx(coefficients, rel=1e-11, abs=1e-14)
    assert dict(HARMONICS) == pytest.approx({n: c for n, c in enumerate(coefficients, 1) if abs(c) > 1e-12},
                                            rel=1e-11)
    wave = sp.expand((rectangular_mesh_stiffness() - 1) / parameter_symbol("k_a"))
    assert {n: float(wave.coeff(sp.cos(n * phi))) for n in range(1, harmonics + 1)} == \
        dict(enumerate(rig.STIFFNESS, 1))


def dop853_exponents(omega: float, periods: int, discard: int) -> np.ndarray:
    """The one-stage model (Eq. 2) and its variational equations typed in NumPy, DOP853 at 1e-11,
    modified Gram-Schmidt every period."""

    def f(tau, u):
        x, v = u[0], u[1]
        k = 1 + K_A * sum(c * np.cos(j * tau) for j, c in HARMONICS)
        gx = x if x >= 0 else (x + ETA if x <= -ETA else 0.0)
        slope = 1.0 if (x >= 0 or x <= -ETA) else 0.0
        a = -2 * ZETA / omega * v + (B0 + B1 * np.cos(tau + THETA)) / omega**2 - k * gx / omega**2
        J = np.array([[0.0, 1.0], [-k * slope / omega**2, -2 * ZETA / omega]])
        return np.concatenate(([v, a], (J @ u[2:].reshape(2, 2)).ravel()))

    period, y, Q, logs = 2 * np.pi, np.array([-2.0, -0.5]), np.eye(2), []
    for k in range(periods):
        sol = solve_ivp(f, (k * period, (k + 1) * period), np.concatenate((y, Q.ravel())), method="DOP853",
                        rtol=1e-11, atol=1e-11)
        u = sol.y[:, -1]
        y, M = u[:2], u[2:].reshape(2, 2)
        q1 = M[:, 0] / np.linalg.norm(M[:, 0])
        w = M[:, 1] - (q1 @ M[:, 1]) * q1
        logs.append([np.log(np.linalg.norm(M[:, 0])), np.log(np.linalg.norm(w))])
        Q = np.column_stack((q1, w / np.linalg.norm(w)))
    return np.sort(np.mean(logs[discard:], axis=0) / period)[::-1]


@pytest.fixture(scope="module")
def at_200_steps():
    """one_stage at omega = 1.5 (a periodic orbit), 200 steps per period: plain, and located (compiled)."""
    return {locate: exponents("one_stage", 200, locate, periods=60, discard=20,
                              backend="auto" if locate else "in-process", omega=1.5)
            for locate in (False, True)}


@pytest.fixture(scope="module")
def dop853_at_1_5():
    """DOP853's exponents of one_stage at omega = 1.5 over at_200_steps' 60 periods (20 discarded): 3 s of SciPy
    calling Python, made once for the two tests that compare with them."""
    return dop853_exponents(1.5, 60, 20)


@pytest.mark.slow
def test_agrees_with_dop853_where_plain_rk4_does_not(at_200_steps, dop853_at_1_5):
    reference = dop853_at_1_5
    located = np.abs(at_200_steps[True] - reference).max()
    plain = np.abs(at_200_steps[False] - reference).max()
    assert located <= 1e-6, located  # measured 4.5e-9
    assert plain >= 1e-4, plain  # measured 1.0e-3


def test_sum_rule_holds_with_crossings_located(at_200_steps):
    assert abs(at_200_steps[True].sum() + 2 * ZETA / 1.5) < 1e-9  # trace of J = -2 zeta / omega


@pytest.mark.slow
def test_the_default_integration_locates_the_crossings(at_200_steps, dop853_at_1_5):
    """gearsym.lyapunov_spectrum with no scheme asked for: DOP853's exponents, not the paper's plain RK4's."""
    default = gearsym.lyapunov_spectrum(system("one_stage"), options=Integration(periods=60, discard=20),
                                        omega=1.5).exponents
    assert np.abs(default - dop853_at_1_5).max() <= 1e-7
    assert np.abs(default - at_200_steps[False]).max() >= 1e-4  # plain RK4 is 1e-3 off
    assert Integration().locate_crossings and not Integration.paper().locate_crossings


def test_compiled_and_in_process_agree_and_every_loop_steps_the_same_way():
    compiled = compile_model(system("one_stage"), Integration(locate_crossings=True, backend="auto"))
    in_process = compile_model(system("one_stage"), Integration(locate_crossings=True, backend="in-process"))
    runs = []
    for cm in (compiled, in_process):
        inputs = cm.prepare(cm.parameter_vector(omega=1.5))
        tangent = cm.tangent_run(None, 12, inputs)
        strobe, low, high = cm.orbit_run(None, 12, inputs)
        _, states = cm.trajectory(None, 12, inputs)
        np.testing.assert_array_equal(strobe, tangent.strobe)  # orbit loops split the same steps
        np.testing.assert_array_equal(low, tangent.low)
        # and so does the trajectory: CasADi's loop, the others gearsym's, which gcc fuses differently (FMA)
        np.testing.assert_allclose(states[:, 200::200], strobe, rtol=0, atol=0 if cm.backend == "in-process" else 1e-13)
        runs.append(tangent)
    np.testing.assert_allclose(runs[0].log_stretch, runs[1].log_stretch, rtol=0, atol=1e-12)
    np.testing.assert_allclose(runs[0].strobe, runs[1].strobe, rtol=0, atol=1e-12)


#: (s0, d0, s1, d1, mode, fresh) of crossing steps' cubics on which fewer iterations stop short: the first
#: two from two_stage at omega = 0.9 (an extremum just past the step's end: the secant starts far off), then
#: flexible_shaft at 0.9 and two_stage at 1.0 (all at 200 steps), and a dip's way out after its way in
#: (fresh: the zero at the start is not counted)
HARD_CUBICS = [
    (-0.006763789091944972, 0.01597439481748599, 0.001157322969682184, -0.00022153709545308836, 0, 0),
    (0.0011570964042988408, -0.00022327042040917034, -0.007381266667559672, -0.01692898574603797, 1, 0),
    (-0.002198732650235513, 0.0115627636321836, 0.005948018829446511, 0.004726433234713725, 0, 0),
    (-0.005779022834273893, 0.006048622173602194, 0.004248976678907491, 0.014067138743883347, 0, 0),
    (0.0, 0.02, -0.004, -0.03, 1, 1),
]


def first_root(s0, d0, s1, d1, fresh) -> float:
    """The earliest zero in (0, 1] of the cubic Hermite (of it divided by t if fresh), to 30 digits."""
    t = sp.Symbol("t")
    s0, d0, s1, d1 = (sp.Rational(v) for v in (s0, d0, s1, d1))
    cubic = (2 * t**3 - 3 * t**2 + 1) * s0 + (t**3 - 2 * t**2 + t) * d0 + (3 * t**2 - 2 * t**3) * s1 \
        + (t**3 - t**2) * d1
    poly = sp.Poly(sp.cancel(cubic / t) if fresh else cubic, t)
    return float(min(r for r in poly.nroots(n=30) if r.is_real and 0 < r <= 1))


def compiled_first_zero():
    import casadi as ca

    from gearsym.codegen.crossing import _first_zero

    args = [ca.SX.sym(name) for name in ("s0", "d0", "s1", "d1", "mode", "fresh")]
    return ca.Function("first_zero", args, list(_first_zero(*args)))


def test_the_located_crossing_is_the_cubics_zero_to_rounding():
    """The fixed count of iterations in _first_zero reaches the zero on the hardest crossing steps met."""
    first_zero = compiled_first_zero()
    for s0, d0, s1, d1, mode, fresh in HARD_CUBICS:
        for sign in (1, -1):  # the same crossing seen from the other side
            found, theta = first_zero(sign * s0, sign * d0, sign * s1, sign * d1, mode if sign > 0 else 1 - mode,
                                      fresh)
            assert float(found) == 1
            assert abs(float(theta) - first_root(s0, d0, s1, d1, fresh)) <= 1e-15, (s0, d0, s1, d1, fresh)



@pytest.mark.parametrize("middle, delta", [(0.6, 1e-4), (0.7, 1e-5), (0.45, 1e-6)])
def test_near_a_grazing_the_located_crossing_is_the_zero_to_its_conditioning(middle, delta):
    """s = a ((t - middle)^2 - delta) + b (t - middle)^3: two zeros sqrt(delta) apart, where Newton-like
    iterations converge only linearly; the fixed count still reaches the first to what rounding allows."""
    a, b = 0.01, 0.003
    s = lambda t: a * ((t - middle) ** 2 - delta) + b * (t - middle) ** 3  # noqa: E731
    slope = lambda t: 2 * a * (t - middle) + 3 * b * (t - middle) ** 2  # noqa: E731
    found, theta = compiled_first_zero()(s(0.0), slope(0.0), s(1.0), slope(1.0), 1, 0)
    root = first_root(s(0.0), slope(0.0), s(1.0), slope(1.0), 0)
    rounding = 8 * np.finfo(float).eps * a / abs(slope(root))  # the zero's own sensitivity to rounding in s
    assert float(found) == 1 and abs(float(theta) - root) <= 1e-15 + rounding, (float(theta) - root, rounding)

# ---------------------------------------------------------------- default, paper scheme, what is not handled
def test_the_default_options_generate_the_committed_c_and_the_paper_scheme_other_code(tmp_path):
    """Integration() locates the crossings: its loops are those of generated/; Integration.paper() is other code."""
    one_stage = system("one_stage")
    options = LoopOptions.of(Integration())
    assert options == LoopOptions(locate_crossings=True)
    fresh = write_code(build_functions(one_stage, options), tmp_path, code_hash(one_stage, options))
    assert fresh.source.read_bytes() == (REPO_ROOT / "generated" / "one_stage" / "one_stage.c").read_bytes()
    default = compile_model(one_stage, Integration(backend="in-process"))
    assert default.hash == compile_model(one_stage, Integration(locate_crossings=True, backend="in-process")).hash
    assert default.options == options
    plain = compile_model(one_stage, Integration.paper(backend="in-process"))
    assert plain.hash != default.hash and plain.options == LoopOptions(locate_crossings=False, reorthonormalise=0)


def test_split_runs_behind_a_real_branch_in_the_c(tmp_path):
    one_stage = system("one_stage")
    options = LoopOptions(locate_crossings=True)
    code = write_code(build_functions(one_stage, options), tmp_path, code_hash(one_stage, options))
    text = code.source.read_text()
    step = re.search(r"void gs_state_step\(.*?\n}\n", text, re.S).group(0)  # (the printed loops' step)
    assert re.search(r"\n  if \(GEARSYM_UNLIKELY\(flag != 0\)\) gs_state_split\(.*\n  else gs_state_keep\(", step)
    step = re.search(r"void gs_tangent_step\(.*?\n}\n", text, re.S).group(0)  # (the vectors' steps in the else)
    assert re.search(r"\n  if \(GEARSYM_UNLIKELY\(flag != 0\)\) \{\n.*gs_tangent_split\(.*\n  \} else \{\n", step, re.S)
    assert "static GEARSYM_NOINLINE void gs_tangent_split(" in text  # out of the way of the steps that do not cross


def test_a_model_without_backlash_is_unchanged_and_other_switches_are_refused(tmp_path):
    lorenz = system("lorenz")
    texts = []
    for locate in (False, True):
        options = LoopOptions(locate_crossings=locate)
        code = write_code(build_functions(lorenz, options), tmp_path / str(locate), code_hash(lorenz, options))
        texts.append(code.source.read_bytes())
    assert texts[0] == texts[1]
    kinked = FirstOrderSystem.from_equations("abs_spring", ["x", "v"], ["v", "-Abs(x) - v/10 + cos(t)"], {},
                                             time="t", period="2*pi")
    with pytest.raises(ModelError, match=r"handles the backlash g.*Integration.paper\(\), --plain"):
        build_functions(kinked, LoopOptions(locate_crossings=True))


def test_one_flank_of_the_backlash_is_located_on_the_backlash_surfaces():
    """The data loop's coast-side stiffness adds c k min(g, 0): it switches where g does, so the default
    scheme takes it (4th order) instead of refusing it."""
    from gearsym.fit.effects import augment

    coast = augment(system("one_stage"), ["coast_side_stiffness"], values={"c_coast": 0.5})
    located = errors(coast, True, omega=1.8)
    assert all(a / b >= 8 for a, b in zip(located, located[1:])), located
    assert located[1] < 1e-8, located


def test_the_frozen_backlash_is_g_on_each_side_and_reads_the_state_once():
    from gearsym.codegen.switching import find_switching as _switching
    from gearsym.codegen.time_tables import split_rhs

    t, x, v = sp.symbols("t x v", real=True)
    eta = parameter_symbol("eta")
    kink = FirstOrderSystem("kink", t, (x, v), (v, -g(x, eta)), {"eta": 1.0}, 2 * sp.pi)
    split = split_rhs(kink, factored=True)
    switching = _switching(kink, split)
    frozen = -switching.rhs[1].subs({c: value for c, value in split.constants})
    contact, other_flank = switching.sides  # x >= 0, x <= -eta
    for value in (1.5, -0.5, -2.5):  # contact, gap, the other flank
        sides = {contact: int(value >= 0), other_flank: int(value <= -1)}
        assert float(frozen.subs({x: value, eta: 1, **sides})) == float(g(value, 1))
    # one product on the path from the state to the next stage: x appears once in the frozen g
    assert frozen.count(x) == 1, frozen
