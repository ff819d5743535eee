"""The backlash function g(x, eta) of the paper's Eq. 5 (third branch read as x <= -eta)."""
from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from gearsym.model.backlash import G, g, g_slope

x = sp.Symbol("x", real=True)
eta = sp.Symbol("eta", real=True)
ETA = sp.Rational(3, 2)


def paper_g(xv: float, etav: float) -> float:
    """Eq. 5, typed independently: x (x >= 0), 0 (-eta < x < 0), x + eta (x <= -eta)."""
    if xv >= 0:
        return xv
    if xv > -etav:
        return 0.0
    return xv + etav


@pytest.mark.parametrize("xv,expected", [
    (sp.Rational(5, 2), sp.Rational(5, 2)),     # contact (drive flank)
    (sp.Integer(0), sp.Integer(0)),             # boundary x = 0
    (sp.Rational(-1, 2), sp.Integer(0)),        # gap
    (sp.Rational(-149, 100), sp.Integer(0)),    # gap, near -eta
    (-ETA, sp.Integer(0)),                      # boundary x = -eta
    (sp.Rational(-7, 2), sp.Integer(-2)),       # coast flank: x + eta
])
def test_three_branches_and_boundaries(xv, expected):
    assert g(xv, ETA) == expected


def test_float_arguments():
    assert g(sp.Float(0.25), sp.Float(1.0)) == pytest.approx(0.25)
    assert g(sp.Float(-0.25), sp.Float(1.0)) == 0
    assert g(sp.Float(-3.0), sp.Float(1.0)) == pytest.approx(-2.0)


def test_continuity_at_zero_and_minus_eta():
    e = 1.5
    for h in (1e-3, 1e-6, 1e-9):
        assert abs(float(g(sp.Float(h), sp.Float(e))) - float(g(sp.Float(-h), sp.Float(e)))) <= h + 1e-15
        assert abs(float(g(sp.Float(-e + h), sp.Float(e))) - float(g(sp.Float(-e - h), sp.Float(e)))) <= h + 1e-15
    assert float(g(sp.Float(-e - 1e-9), sp.Float(e))) == pytest.approx(-1e-9, abs=1e-12)


def test_no_clearance_is_linear():
    assert g(x, 0) == x
    assert g(x, sp.Float(0.0)) == x
    assert g(sp.Rational(-7, 3), 0) == sp.Rational(-7, 3)
    assert g_slope(x, 0) == 1
    assert sp.simplify(G(x, 0) - x**2 / 2) == 0


def test_symbolic_call_stays_unevaluated():
    expr = g(x, eta)
    assert isinstance(expr, g)
    assert expr.subs({x: -4, eta: 1}) == -3


def test_slope():
    assert sp.diff(g(x, eta), x) == g_slope(x, eta)
    e = sp.Integer(2)
    assert g_slope(sp.Integer(3), e) == 1     # contact
    assert g_slope(sp.Integer(0), e) == 1     # boundary, contact side
    assert g_slope(sp.Integer(-1), e) == 0    # gap
    assert g_slope(sp.Integer(-2), e) == 1    # boundary x = -eta, coast flank
    assert g_slope(sp.Integer(-5), e) == 1    # coast flank
    # the derivative of the Piecewise form agrees away from the kinks
    dpw = sp.diff(g(x, eta).rewrite(sp.Piecewise), x)
    for xv in (2.3, -0.7, -4.1):
        assert float(dpw.subs({x: xv, eta: 2})) == float(g_slope(sp.Float(xv), e))


def test_potential_derivative_is_g():
    assert sp.diff(G(x, eta), x) == g(x, eta)
    pw = sp.diff(G(x, eta).rewrite(sp.Piecewise), x)
    for xv in np.linspace(-4.0, 3.0, 29):
        assert float(pw.subs({x: xv, eta: 1.5})) == pytest.approx(paper_g(xv, 1.5), abs=1e-14)
    # G itself on the three branches
    assert G(sp.Integer(2), ETA) == 2
    assert G(sp.Integer(-1), ETA) == 0
    assert G(sp.Integer(-3), ETA) == sp.Rational(9, 8)


def test_piecewise_rewrite_agrees_with_eval_on_a_grid():
    pw = g(x, eta).rewrite(sp.Piecewise)
    assert isinstance(pw, sp.Piecewise)
    f = sp.lambdify((x, eta), pw, "numpy")
    for etav in (0.5, 1.5, 10.0):
        grid = np.concatenate([np.linspace(-3 * etav, 2 * etav, 401), [0.0, -etav]])
        numeric = np.asarray(f(grid, etav), dtype=float)
        expected = np.array([paper_g(v, etav) for v in grid])
        assert np.allclose(numeric, expected, atol=1e-14, rtol=0)
        for v in grid[::20]:
            assert float(g(sp.Float(v), sp.Float(etav))) == pytest.approx(paper_g(v, etav), abs=1e-14)
            assert float(pw.subs({x: v, eta: etav})) == pytest.approx(paper_g(v, etav), abs=1e-14)


def test_slope_piecewise_rewrite_agrees_with_eval():
    pw = g_slope(x, eta).rewrite(sp.Piecewise)
    for v in (-5.0, -2.0, -1.0, 0.0, 1.0):
        assert float(pw.subs({x: v, eta: 2.0})) == float(g_slope(sp.Float(v), sp.Float(2.0)))
