"""The library's equations against the paper's Eqs. 1-10, typed independently here.

Litak & Friswell, "Nonlinear Vibration in Gear Systems". Every comparison is
``sympy.simplify(ours - paper) == 0`` on complete equations (lhs - rhs), so a
wrong sign, factor or term anywhere makes the test fail.

Known misprints of the paper that the typed equations below correct:
* Eq. 5 third branch reads ``x <= eta``; it must be ``x <= -eta`` (continuity).
* Eq. 9 writes the forcing as ``cos(omega t + Theta)`` in the tau-form; with
  tau = omega t this is ``cos(tau + Theta)``.
"""
from __future__ import annotations

import pytest
import sympy as sp

from conftest import GEAR_MODELS, P, coord, load, psi, reduced
from gearsym.model.backlash import g
from gearsym.model.symbols import omega, t, tau

I1, I2, I3 = P("I1"), P("I2"), P("I3")
r1, r2 = P("r1"), P("r2")
kZ, cZ, kS, eta = P("kZ"), P("cZ"), P("kS"), P("eta")
M1, M1a, M1d, M2, M3 = P("M1"), P("M1a"), P("M1d"), P("M2"), P("M3")
Theta, Theta_p = P("Theta"), P("Theta_p")
zeta, B0, B1, D = P("zeta"), P("B0"), P("B1"), P("D")
beta_1, beta_2, beta_3 = P("beta_1"), P("beta_2"), P("beta_3")

kZ_t = sp.Function("kZ", real=True)(t)  # the opaque mesh stiffness of the Lagrange equations
k_tau = sp.Function("k", real=True)(tau)  # the nondimensional stiffness k(tau)

#: the driving torque as declared in models/one_stage.py: mean M1 plus M1a cos(omega t + Theta)
M1_total = M1 + M1a * sp.cos(omega * t + Theta)

#: r1^2/I1 + r2^2/I2, the paper's bracket in Eqs. 3 and 4
BRACKET = r1**2 / I1 + r2**2 / I2


def is_zero(expr) -> bool:
    return sp.simplify(sp.expand(expr)) == 0


def residual(eq: sp.Eq) -> sp.Expr:
    return eq.lhs - eq.rhs


def linear_constant_stiffness(expr: sp.Expr) -> sp.Expr:
    """eta = 0 (so g(x, 0) = x) and kZ(t) -> the constant kZ: the setting of Eqs. 1 and 8."""
    return expr.subs(eta, 0).subs(kZ_t, kZ)


def same_up_to_sign(a: sp.Expr, b: sp.Expr) -> bool:
    return is_zero(a - b) or is_zero(a + b)


# ---------------------------------------------------------------------------- Eq. 1
def paper_eq1(stiffness=kZ, force_law=lambda d: d):
    """Eq. 1: I1 psi1'' + [kZ(r1 psi1 - r2 psi2) + cZ(r1 psi1' - r2 psi2')] r1 = M1, ... = -M2."""
    d = r1 * psi(1) - r2 * psi(2)
    force = stiffness * force_law(d) + cZ * sp.diff(d, t)
    return [
        I1 * sp.diff(psi(1), t, 2) + force * r1 - M1_total,
        I2 * sp.diff(psi(2), t, 2) - force * r2 - (-M2),
    ]


def test_eq1_one_stage_lagrange_equations_equal_paper():
    eoms = load("one_stage").form_eoms()
    assert len(eoms) == 2
    for ours, paper in zip(eoms, paper_eq1()):
        assert is_zero(linear_constant_stiffness(residual(ours)) - paper)


def test_eq1_with_backlash_and_varying_stiffness():
    """With eta kept, the elastic mesh force is kZ(t) g(r1 psi1 - r2 psi2, eta) (Eqs. 4 and 5)."""
    eoms = load("one_stage").form_eoms()
    expected = paper_eq1(stiffness=kZ_t, force_law=lambda d: g(d, eta))
    for ours, paper in zip(eoms, expected):
        assert is_zero(residual(ours) - paper)


def test_eq1_detects_a_wrong_sign():
    """The comparison is sharp: flipping the load torque breaks it."""
    eom2 = linear_constant_stiffness(residual(load("one_stage").form_eoms()[1]))
    wrong = I2 * sp.diff(psi(2), t, 2) - (kZ * (r1 * psi(1) - r2 * psi(2))
                                          + cZ * (r1 * sp.diff(psi(1), t) - r2 * sp.diff(psi(2), t))) * r2 - M2
    assert not is_zero(eom2 - wrong)


# ---------------------------------------------------------------------------- Eq. 8
def test_eq8_flexible_shaft_lagrange_equations_equal_paper():
    eoms = load("flexible_shaft").form_eoms()
    assert len(eoms) == 3
    d = r1 * psi(1) - r2 * psi(2)
    force = kZ * d + cZ * sp.diff(d, t)
    twist = psi(3) - psi(2)
    paper = [
        I1 * sp.diff(psi(1), t, 2) + force * r1 - M1_total,
        I2 * sp.diff(psi(2), t, 2) - force * r2 - kS * twist - (-M2),
        I3 * sp.diff(psi(3), t, 2) + kS * twist - (-M3),
    ]
    for ours, theirs in zip(eoms, paper):
        assert is_zero(linear_constant_stiffness(residual(ours)) - theirs)


# ---------------------------------------------------------------------------- Eqs. 2-4
def paper_eq2(x, rhs_numerator):
    return (sp.diff(x, tau, 2) + 2 * zeta / omega * sp.diff(x, tau) + k_tau * g(x, eta) / omega**2
            - rhs_numerator / omega**2)


def test_eq2_one_stage_nondimensional_equation():
    nd = reduced("one_stage")
    assert [c.name for c in nd.coordinates] == ["x"]
    x = coord("x", tau)
    assert len(nd.equations) == 1
    assert is_zero(residual(nd.equations[0]) - paper_eq2(x, B0 + B1 * sp.cos(tau + Theta)))


def test_eq2_relative_coordinate_definition():
    nd = reduced("one_stage")
    assert is_zero(nd.coordinates[0].definition - (r1 * psi(1) - r2 * psi(2)))


def test_eq3_group_definitions():
    nd = reduced("one_stage")
    assert is_zero(2 * nd.group("zeta").definition - cZ * BRACKET)
    assert is_zero(nd.group("B0").definition - (r1 * M1 / I1 + r2 * M2 / I2))
    assert is_zero(nd.group("B1").definition - r1 * M1a / I1)
    assert {gr.name for gr in nd.groups} == {"zeta", "B0", "B1"}


def test_eq4_stiffness_function_definition():
    """k(tau) g(x, eta) replaces kZ [r1^2/I1 + r2^2/I2] x: k = kZ(t) times the bracket."""
    nd = reduced("one_stage")
    assert [f.name for f in nd.functions] == ["k"]
    k = nd.functions[0]
    assert k.applied == k_tau
    as_function_of_time = k.definition.subs(tau, omega * t)
    assert is_zero(as_function_of_time - kZ_t * BRACKET)


def test_time_unit_condition_makes_mean_stiffness_one():
    nd = reduced("one_stage")
    conds = [c.equation for c in nd.conditions]
    assert any(is_zero(residual(c) - (kZ * BRACKET - 1)) or is_zero(residual(c) + (kZ * BRACKET - 1))
               for c in conds)


# ---------------------------------------------------------------------------- Eq. 6
def test_eq6_one_stage_resonant():
    nd = reduced("one_stage_resonant")
    x = coord("x", tau)
    forcing = B0 + B1 * sp.cos(tau + Theta) + D * sp.cos(tau + Theta_p)
    assert is_zero(residual(nd.equations[0]) - paper_eq2(x, forcing))
    assert is_zero(nd.group("D").definition - r1 * M1d / I1)
    assert is_zero(nd.group("B1").definition - r1 * M1a / I1)
    assert is_zero(nd.group("B0").definition - (r1 * M1 / I1 + r2 * M2 / I2))
    assert is_zero(2 * nd.group("zeta").definition - cZ * BRACKET)


# ---------------------------------------------------------------------------- Eqs. 9-10
def test_eq9_coordinates():
    nd = reduced("flexible_shaft")
    assert [c.name for c in nd.coordinates] == ["x1", "x2"]
    assert is_zero(nd.coordinates[0].definition - (r1 * psi(1) - r2 * psi(2)))
    assert is_zero(nd.coordinates[1].definition - r2 * (psi(3) - psi(2)))


def test_eq10_beta_groups():
    nd = reduced("flexible_shaft")
    assert is_zero(nd.group("beta_1").definition - 1 / I2)
    assert is_zero(nd.group("beta_2").definition - (1 / I2 + 1 / I3))
    assert is_zero(nd.group("beta_3").definition - (r2**2 / I2) / BRACKET)
    # the one-stage groups are unchanged
    assert is_zero(2 * nd.group("zeta").definition - cZ * BRACKET)
    assert is_zero(nd.group("B0").definition - (r1 * M1 / I1 + r2 * M2 / I2))
    assert is_zero(nd.group("B1").definition - r1 * M1a / I1)


def test_eq10_torque_balance_condition():
    nd = reduced("flexible_shaft")
    paper = r2 * M2 / I2 - r2 * M3 / I3  # 0 = r2 M2/I2 - r2 M3/I3
    balance = [c for c in nd.conditions if M3 in c.equation.free_symbols]
    assert len(balance) == 1
    assert same_up_to_sign(residual(balance[0].equation), paper)


def test_eq9_flexible_shaft_nondimensional_equations():
    nd = reduced("flexible_shaft")
    x1, x2 = coord("x1", tau), coord("x2", tau)
    paper_1 = (sp.diff(x1, tau, 2) + 2 * zeta / omega * sp.diff(x1, tau) + k_tau * g(x1, eta) / omega**2
               + beta_1 * kS * x2 / omega**2 - (B0 + B1 * sp.cos(tau + Theta)) / omega**2)
    paper_2 = (sp.diff(x2, tau, 2) + beta_2 * kS * x2 / omega**2 + 2 * beta_3 * zeta / omega * sp.diff(x1, tau)
               + beta_3 * k_tau * g(x1, eta) / omega**2)
    assert len(nd.equations) == 2
    assert is_zero(residual(nd.equations[0]) - paper_1)
    assert is_zero(residual(nd.equations[1]) - paper_2)


# ---------------------------------------------------------------------------- consistency tau <-> t
def tau_form_in_t(nd, expr: sp.Expr) -> sp.Expr:
    """Undo the nondimensionalisation: groups -> definitions, x(tau) -> x(t), d/dtau = (1/omega) d/dt."""
    rep = {}
    for c in nd.coordinates:
        xt, xtau = coord(c.name, t), coord(c.name, tau)
        rep[sp.Derivative(xtau, (tau, 2))] = sp.Derivative(xt, (t, 2)) / omega**2
        rep[sp.Derivative(xtau, tau)] = sp.Derivative(xt, t) / omega
        rep[xtau] = xt
    for f in nd.functions:
        rep[sp.Function(f.name, real=True)(tau)] = f.definition.subs(tau, omega * t)
    expr = expr.xreplace(rep)
    expr = expr.xreplace({P(gr.name): gr.definition for gr in nd.groups})
    return expr.subs(tau, omega * t)


@pytest.mark.parametrize("name", GEAR_MODELS + ("rich", "idler"))
def test_tau_form_equals_reduced_t_form(name):
    """Substituting the groups back, x(tau) -> x(t), d/dtau = d/dt / omega, k -> its definition and
    multiplying by omega^2 gives Reduction.equations, up to a constant that a condition sets to zero."""
    nd = reduced(name)
    red = nd.reduction
    assert len(nd.equations) == len(red.equations) == len(nd.coordinates)
    for c, eq_tau, eq_t in zip(nd.coordinates, nd.equations, red.equations):
        assert eq_t.lhs == sp.Derivative(coord(c.name, t), (t, 2))
        back = omega**2 * tau_form_in_t(nd, residual(eq_tau))
        assert not back.has(tau)
        assert {s.name for s in back.free_symbols} & {gr.name for gr in nd.groups} == set()
        difference = sp.simplify(sp.expand(back - residual(eq_t)))
        if difference == 0:
            continue
        # the only thing the tau-form may drop is a constant that a declared condition sets to zero
        # (the torque balance of Eq. 10 for the unforced shaft twist)
        assert not difference.has(t) and not difference.atoms(sp.Function), f"{name}: {c.name}: {difference}"
        assert any(same_up_to_sign(difference, residual(cond.equation)) for cond in nd.conditions), (
            f"{name}: {c.name}: the tau-form differs from the t-form by {difference}, which no condition removes")


def test_flexible_shaft_tau_form_drops_exactly_the_torque_balance():
    """The x2 row loses r2 M2/I2 - r2 M3/I3 and nothing else (Eq. 9's zero right-hand side)."""
    nd = reduced("flexible_shaft")
    back = omega**2 * tau_form_in_t(nd, residual(nd.equations[1]))
    difference = back - residual(nd.reduction.equations[1])
    assert is_zero(difference - (r2 * M2 / I2 - r2 * M3 / I3))
