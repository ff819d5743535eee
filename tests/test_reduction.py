"""The reduction to relative coordinates, checked structurally and numerically.

The numerical check does not use the library's reduction: it solves the full
Lagrange equations for psi'' at random numbers, maps them with the coordinate
transform typed here from the paper (x = r1 psi1 - r2 psi2, x2 = r2 (psi3 - psi2), ...)
and compares with the reduced equations evaluated at q = T psi.
"""
from __future__ import annotations

import random
import zlib

import numpy as np
import pytest
import sympy as sp
from sympy.core.function import AppliedUndef

import gearsym
from conftest import P, coord, load, psi, reduced
from gearsym.model.backlash import g
from gearsym.model.symbols import omega, t, tau

r1, r2, r3, r4 = P("r1"), P("r2"), P("r3"), P("r4")
I1, I2, I3, I4 = P("I1"), P("I2"), P("I3"), P("I4")

#: the coordinate transforms q = T psi, typed from the paper (and the two_stage docstring)
TRANSFORMS = {
    "one_stage": sp.Matrix([[r1, -r2]]),
    "one_stage_resonant": sp.Matrix([[r1, -r2]]),
    "flexible_shaft": sp.Matrix([[r1, -r2, 0], [0, -r2, r2]]),
    "two_stage": sp.Matrix([[r1, -r2, 0, 0], [0, -r2, r2, 0], [0, 0, r3, -r4]]),
    # conftest.rich_model: Shaft(disk3 -> gear2) gives x2 = r2 (psi2 - psi3)
    "rich": sp.Matrix([[r1, -r2, 0], [0, r2, -r2]]),
    # conftest.idler_model: x1 = r1 psi1 - r2 psi2, x2 = r2 psi2 - r3 psi3
    "idler": sp.Matrix([[r1, -r2, 0], [0, r2, -r3]]),
}
#: which coordinates are mesh deflections with backlash, and the symbol of their clearance
MESH_COORDS = {
    "one_stage": {0: P("eta")},
    "one_stage_resonant": {0: P("eta")},
    "flexible_shaft": {0: P("eta")},
    "two_stage": {0: P("eta"), 2: P("eta2")},
    "rich": {0: P("eta")},
    "idler": {0: P("eta"), 1: P("eta2")},
}


def is_zero(expr) -> bool:
    return sp.simplify(sp.expand(expr)) == 0


# ---------------------------------------------------------------------------- two_stage structure
def test_two_stage_sizes():
    nd = reduced("two_stage")
    red = nd.reduction
    assert len(red.resolved.bodies) == 4
    assert len(red.rigid_modes) == 1
    assert [c.name for c in nd.coordinates] == ["x1", "x2", "x3"]
    assert [s.name for s in nd.states] == ["x1", "v1", "x2", "v2", "x3", "v3"]
    assert len(nd.system().rhs) == 6


def test_two_stage_transform_and_coordinates():
    nd = reduced("two_stage")
    assert (nd.reduction.transform - TRANSFORMS["two_stage"]).applyfunc(sp.simplify) == sp.zeros(3, 4)
    angles = sp.Matrix([psi(i) for i in range(1, 5)])
    for c, expected in zip(nd.coordinates, TRANSFORMS["two_stage"] * angles):
        assert is_zero(c.definition - expected)


def test_two_stage_rigid_mode():
    (u,) = reduced("two_stage").reduction.rigid_modes
    assert u.shape == (4, 1)
    assert (TRANSFORMS["two_stage"] * u).applyfunc(sp.simplify) == sp.zeros(3, 1)
    expected = [1 / r1, 1 / r2, 1 / r2, r3 / (r2 * r4)]
    assert u[0] != 0
    for i in range(1, 4):
        assert is_zero(u[i] / u[0] - expected[i] / expected[0]), i


def test_two_stage_rigid_body_equation_has_no_coupling_force():
    nd = reduced("two_stage")
    (eq,) = nd.reduction.rigid_body_equations
    res = eq.lhs - eq.rhs
    coupling_params = {"kS", "cZ", "cZ2", "kZ", "kZ2", "eta", "eta2"}
    assert not ({s.name for s in res.free_symbols} & coupling_params)
    assert not res.atoms(AppliedUndef) - {psi(i) for i in range(1, 5)}
    assert not res.has(g)
    # and it is sum_i u_i (I_i psi_i'' - Q_i) with the paper's u ~ (1/r1, 1/r2, 1/r2, r3/(r2 r4))
    M1, M1a, M4, Theta = P("M1"), P("M1a"), P("M4"), P("Theta")
    acc = [sp.diff(psi(i), t, 2) for i in range(1, 5)]
    expected = (I1 * acc[0] / r1 + I2 * acc[1] / r2 + I3 * acc[2] / r2 + r3 / (r2 * r4) * I4 * acc[3]
                - (M1 + M1a * sp.cos(omega * t + Theta)) / r1 - r3 / (r2 * r4) * (-M4))
    ratio = sp.simplify(res / expected)
    assert ratio != 0 and not ratio.has(t) and not ratio.atoms(AppliedUndef)


def test_two_stage_period_is_4pi():
    assert sp.simplify(reduced("two_stage").period - 4 * sp.pi) == 0
    assert sp.simplify(reduced("one_stage").period - 2 * sp.pi) == 0


def test_two_stage_groups_free_of_states():
    nd = reduced("two_stage")
    state_names = {s.name for s in nd.states}
    assert nd.groups
    for gr in nd.groups:
        names = {s.name for s in gr.definition.free_symbols}
        assert not names & state_names, gr
        assert not names & {"t", "tau"}, gr
        assert not gr.definition.atoms(AppliedUndef), gr


# ---------------------------------------------------------------------------- numerical reduction check
def _value(expr: sp.Expr, subs: dict) -> float:
    out = sp.sympify(expr).rewrite(sp.Piecewise).xreplace(subs)
    out = out.rewrite(sp.Piecewise).evalf(30)
    return float(out)


def _accelerations_from_lagrange(eoms, n, subs_states, subs_params):
    """Solve the full Lagrange equations, linear in psi'', for psi'' at the given numbers."""
    acc_syms = sp.symbols(f"_acc0:{n}")
    rep = {sp.Derivative(psi(i + 1), (t, 2)): acc_syms[i] for i in range(n)}
    rep.update(subs_states)
    residuals = []
    for eq in eoms:
        e = (eq.lhs - eq.rhs).rewrite(sp.Piecewise)
        residuals.append(sp.expand(e.xreplace(rep).xreplace(subs_params).rewrite(sp.Piecewise).doit()))
    A, b = sp.linear_eq_to_matrix(residuals, acc_syms)
    A = np.array(A.evalf(30), dtype=float)
    b = np.array(b.evalf(30), dtype=float).ravel()
    return np.linalg.solve(A, b)


def _check_reduction_numerically(name: str, rng: random.Random, targets: dict[int, float]):
    model = load(name)
    nd = reduced(name)
    red = nd.reduction
    eoms = model.form_eoms()
    T = TRANSFORMS[name]
    n = T.shape[1]
    # parameters: everything but t; the opaque mesh stiffnesses kZ(t), kZ2(t) get random values too
    params = set()
    for eq in eoms:
        params |= eq.free_symbols
    params |= T.free_symbols
    params.discard(t)
    subs_params = {s: sp.Float(rng.uniform(0.5, 2.0), 30) for s in params}
    for clearance in MESH_COORDS[name].values():
        subs_params[clearance] = sp.Float(rng.uniform(0.5, 1.5), 30)
    for eq in eoms:
        for f in eq.atoms(AppliedUndef):
            if not f.func.__name__.startswith("psi_"):
                subs_params[f] = sp.Float(rng.uniform(0.5, 2.0), 30)
    subs_params[t] = sp.Float(rng.uniform(0.0, 10.0), 30)
    Tn = np.array(T.xreplace(subs_params).evalf(30), dtype=float)

    # angles with the mesh deflections at the requested values (contact, gap or coast flank)
    psi_v = np.array([rng.uniform(-1, 1) for _ in range(n)])
    psid_v = np.array([rng.uniform(-1, 1) for _ in range(n)])
    for row, fraction in targets.items():
        eta_v = float(subs_params[MESH_COORDS[name][row]])
        target = fraction * eta_v
        # move psi along the least-norm direction changing only this row
        direction = np.linalg.lstsq(Tn, np.eye(Tn.shape[0])[row], rcond=None)[0]
        psi_v = psi_v + (target - Tn[row] @ psi_v) * direction
    q_v, qd_v = Tn @ psi_v, Tn @ psid_v
    for row, fraction in targets.items():
        eta_v = float(subs_params[MESH_COORDS[name][row]])
        assert abs(q_v[row] - fraction * eta_v) < 1e-12

    subs_states = {}
    for i in range(n):
        subs_states[sp.Derivative(psi(i + 1), t)] = sp.Float(psid_v[i], 30)
        subs_states[psi(i + 1)] = sp.Float(psi_v[i], 30)
    acc = _accelerations_from_lagrange(eoms, n, subs_states, subs_params)
    expected_qdd = Tn @ acc

    # the reduced equations (dimensional time) at q = T psi
    subs_q = dict(subs_params)
    for i, c in enumerate(red.coordinates):
        subs_q[sp.Derivative(coord(c.name, t), t)] = sp.Float(qd_v[i], 30)
        subs_q[coord(c.name, t)] = sp.Float(q_v[i], 30)
    for i, eq in enumerate(red.equations):
        got = _value(eq.rhs, subs_q)
        assert abs(got - expected_qdd[i]) <= 1e-10 * max(1.0, abs(expected_qdd[i])), (
            name, red.coordinates[i].name, targets, got, expected_qdd[i])


#: fractions of eta: 0.4 (contact), -0.3 (gap), -1.6 (coast flank, x <= -eta)
CASES = [
    ("one_stage", {0: 0.4}),
    ("one_stage", {0: -0.3}),
    ("one_stage", {0: -1.6}),
    ("one_stage_resonant", {0: -0.7}),
    ("flexible_shaft", {0: 0.4}),
    ("flexible_shaft", {0: -0.5}),
    ("flexible_shaft", {0: -2.2}),
    ("two_stage", {0: 0.4, 2: -0.3}),
    ("two_stage", {0: -0.3, 2: -1.5}),
    ("two_stage", {0: -1.5, 2: 0.8}),
    ("rich", {0: 0.6}),
    ("rich", {0: -0.6}),
    ("rich", {0: -1.9}),
    ("idler", {0: 0.3, 1: -0.4}),
    ("idler", {0: -1.3, 1: 0.2}),
    ("idler", {0: -0.5, 1: -2.0}),
]


@pytest.mark.slow
@pytest.mark.parametrize("name,targets", CASES)
def test_reduced_equations_match_lagrange_numerically(name, targets):
    rng = random.Random(zlib.crc32(f"{name}{sorted(targets.items())}".encode()))
    for _ in range(2):
        _check_reduction_numerically(name, rng, targets)


# ---------------------------------------------------------------------------- FirstOrderSystem
def _num(expr, subs) -> float:
    return float(sp.sympify(expr).rewrite(sp.Piecewise).xreplace(subs).rewrite(sp.Piecewise).evalf(30))


def _system_rhs(system, state_values, tau_value):
    subs = {P(k): sp.Float(v, 30) for k, v in system.parameters.items()}
    subs.update({s: sp.Float(v, 30) for s, v in zip(system.states, state_values)})
    subs[system.time] = sp.Float(tau_value, 30)
    return [_num(f, subs) for f in system.rhs]


def test_first_order_system_one_stage_matches_eq2():
    nd = reduced("one_stage")
    system = nd.system()
    assert [s.name for s in system.states] == ["x", "v"]
    assert system.time == tau
    p = system.parameters
    k_expr = nd.functions[0].expression  # gearsym's declared k(tau): not in the paper
    rng = random.Random(3)
    eta = p["eta"]
    for x in (0.7 * eta, -0.4 * eta, -1.3 * eta):
        v, tau_v = rng.uniform(-2, 2), rng.uniform(0, 7)
        k_v = float(k_expr.subs({tau: tau_v, P("k_a"): p["k_a"]}))
        gx = x if x >= 0 else (0.0 if x > -eta else x + eta)
        # Eq. 2 solved for x''
        acc = (-2 * p["zeta"] / p["omega"] * v - k_v * gx / p["omega"] ** 2
               + (p["B0"] + p["B1"] * np.cos(tau_v + p["Theta"])) / p["omega"] ** 2)
        got = _system_rhs(system, [x, v], tau_v)
        assert got[0] == pytest.approx(v, abs=1e-12)
        assert got[1] == pytest.approx(acc, rel=1e-10, abs=1e-10)


def test_first_order_system_flexible_shaft_matches_eq9():
    nd = reduced("flexible_shaft")
    system = nd.system()
    p = system.parameters
    for name in ("I1", "I2", "I3", "r1", "r2", "kS", "zeta", "B0", "B1", "omega", "eta"):
        assert name in p, name
    beta1 = 1 / p["I2"]
    beta2 = 1 / p["I2"] + 1 / p["I3"]
    beta3 = (p["r2"] ** 2 / p["I2"]) / (p["r1"] ** 2 / p["I1"] + p["r2"] ** 2 / p["I2"])
    k_expr = nd.functions[0].expression
    rng = random.Random(5)
    w, eta = p["omega"], p["eta"]
    for x1 in (0.3 * eta, -0.5 * eta, -1.2 * eta):
        v1, x2, v2, tau_v = (rng.uniform(-2, 2) for _ in range(4))
        k_v = float(k_expr.subs({tau: tau_v, P("k_a"): p["k_a"]}))
        gx = x1 if x1 >= 0 else (0.0 if x1 > -eta else x1 + eta)
        a1 = (-2 * p["zeta"] / w * v1 - k_v * gx / w**2 - beta1 * p["kS"] * x2 / w**2
              + (p["B0"] + p["B1"] * np.cos(tau_v + p["Theta"])) / w**2)
        a2 = -beta2 * p["kS"] * x2 / w**2 - 2 * beta3 * p["zeta"] / w * v1 - beta3 * k_v * gx / w**2
        got = _system_rhs(system, [x1, v1, x2, v2], tau_v)
        assert got == pytest.approx([v1, a1, v2, a2], rel=1e-10, abs=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["one_stage_resonant", "two_stage", "rich"])
def test_first_order_system_matches_second_order_equations(name):
    """Generic: x_i'' from nd.equations with groups and k(tau) substituted, vs system().rhs."""
    nd = reduced(name)
    system = nd.system()
    values = {P(k): sp.Float(v, 30) for k, v in system.parameters.items()}
    rep = {sp.Function(f.name, real=True)(tau): f.expression for f in nd.functions}
    derived = {P(gr.name): gr.definition for gr in nd.groups if gr.kind == "derived"}
    rng = random.Random(11)
    state_vals = [rng.uniform(-3, 3) for _ in nd.states]
    tau_v = rng.uniform(0, 12)
    subs = dict(values)
    for c, (xv, vv) in zip(nd.coordinates, zip(state_vals[0::2], state_vals[1::2])):
        subs[sp.Derivative(coord(c.name, tau), tau)] = sp.Float(vv, 30)
        subs[coord(c.name, tau)] = sp.Float(xv, 30)
    subs[tau] = sp.Float(tau_v, 30)
    got = _system_rhs(system, state_vals, tau_v)
    for i, (c, eq) in enumerate(zip(nd.coordinates, nd.equations)):
        xdd = sp.Derivative(coord(c.name, tau), (tau, 2))
        acc = sp.solve(eq.lhs - eq.rhs, xdd)[0]
        acc = acc.xreplace(rep).xreplace(derived)
        assert got[2 * i] == pytest.approx(state_vals[2 * i + 1], abs=1e-12)
        assert got[2 * i + 1] == pytest.approx(_num(acc, subs), rel=1e-10, abs=1e-10)


def test_system_override_omega_changes_only_omega():
    nd = reduced("one_stage")
    base, changed = nd.system(), nd.system(omega=1.2)
    assert changed.parameters["omega"] == pytest.approx(1.2)
    assert base.parameters["omega"] == pytest.approx(1.5)
    assert {k: v for k, v in changed.parameters.items() if k != "omega"} == \
        {k: v for k, v in base.parameters.items() if k != "omega"}
    assert changed.rhs == base.rhs
    assert changed.states == base.states
    assert changed.period == base.period


def test_system_replaces_k():
    nd = reduced("one_stage")
    system = nd.system(k="1+0.3*cos(tau)")
    p = system.parameters
    assert "k_a" not in p  # the default wave (and its amplitude) is gone
    eta = p["eta"]
    for x, v, tau_v in ((0.5 * eta, 0.3, 1.1), (-0.5 * eta, -0.2, 2.5), (-1.5 * eta, 1.0, 4.0)):
        gx = x if x >= 0 else (0.0 if x > -eta else x + eta)
        acc = (-2 * p["zeta"] / p["omega"] * v - (1 + 0.3 * np.cos(tau_v)) * gx / p["omega"] ** 2
               + (p["B0"] + p["B1"] * np.cos(tau_v + p["Theta"])) / p["omega"] ** 2)
        got = _system_rhs(system, [x, v], tau_v)
        assert got[1] == pytest.approx(acc, rel=1e-10, abs=1e-10)


def test_system_rejects_k_not_periodic():
    with pytest.raises(gearsym.ModelError, match="periodic"):
        reduced("one_stage").system(k="1+0.3*cos(tau/2)")


def test_system_misspelt_setting_suggests():
    with pytest.raises(gearsym.UnknownParameterError, match="'zeta'") as err:
        reduced("one_stage").system(zeat=1)
    assert err.value.name == "zeat"
    assert "zeat" in str(err.value)


def test_system_replaced_k_with_new_parameter_can_be_given_its_value():
    """A replaced k(tau) may use a new parameter: without its value the error asks for 'a=...', and a=... is
    accepted as a parameter of the replaced function (a keyword is checked against the parameters of the
    equations with the replacement written in, not only the model's own)."""
    nd = reduced("one_stage")
    with pytest.raises(gearsym.ModelError, match="pass a="):
        nd.system(k="1+a*cos(tau)")
    system = nd.system(k="1+a*cos(tau)", a=0.3)
    assert system.parameters["a"] == pytest.approx(0.3)


def test_variation_periodic_only_at_its_default_is_rejected():
    """k(phi) = 1 + 0.2 cos(w phi) is 2 pi periodic only for whole w. It passes at the default w = 1,
    but a run with w = 0.5 would silently change the period, so the declaration is rejected outright
    (and names the parameter), while a truly periodic parameterised variation is accepted."""
    from gearsym import Drivetrain, Gear, Mesh, Torque

    def build(variation):
        m = Drivetrain("wfreq")
        a = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
        b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
        m.add(Mesh("mesh", a, b, variation=variation))
        m.add(Torque("M1", on=a, mean="M1"))
        m.set_defaults(w=1, omega=1.5, zeta=0.1, B0=1.0, eta=1.0)
        return m

    with pytest.raises(gearsym.ModelError, match=r"Mesh 'mesh'.*not 2\*pi-periodic.* at w="):
        gearsym.reduce(build("1+0.2*cos(w*phi)"))
    nd = gearsym.reduce(build("1+0.2*w*cos(phi)"))
    assert nd.system(w=0.5).parameters["w"] == 0.5


# ---------------------------------------------------------------------------- Lorenz
def test_lorenz_rhs_and_jacobian():
    lorenz = load("lorenz")
    assert isinstance(lorenz, gearsym.FirstOrderSystem)
    assert [s.name for s in lorenz.states] == ["x", "y", "z"]
    assert lorenz.parameters == pytest.approx({"sigma": 10.0, "rho": 28.0, "beta": 8.0 / 3.0})
    subs = {P(k): v for k, v in lorenz.parameters.items()}
    point = dict(zip(lorenz.states, (1.0, 2.0, 3.0)))
    subs.update(point)
    rhs = [float(f.xreplace(subs)) for f in lorenz.rhs]
    assert rhs == pytest.approx([10.0, 23.0, 2.0 - 8.0], abs=1e-12)
    jac = np.array(lorenz.jacobian().xreplace(subs), dtype=float)
    expected = np.array([[-10.0, 10.0, 0.0], [25.0, -1.0, -1.0], [2.0, 1.0, -8.0 / 3.0]])
    assert np.allclose(jac, expected, atol=1e-12)
    # a second point, with a changed parameter
    changed = lorenz.with_values(rho=10.0)
    subs2 = {P(k): v for k, v in changed.parameters.items()} | dict(zip(changed.states, (-2.0, 0.5, 4.0)))
    assert [float(f.xreplace(subs2)) for f in changed.rhs] == pytest.approx(
        [10.0 * (0.5 + 2.0), -2.0 * (10.0 - 4.0) - 0.5, -2.0 * 0.5 - 8.0 / 3.0 * 4.0])
