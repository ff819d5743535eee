"""The backlash function g(x, eta) of the paper's Eq. 5 as a SymPy function.

The paper prints the third branch as ``x <= eta``; the intended (and only
consistent) branch is ``x <= -eta``: g is continuous, zero in the gap
``-eta < x < 0`` and has unit slope in contact on either flank.

``g`` keeps equations readable (it prints as g(x, eta)), differentiates to
``g_slope`` for exact Jacobians and rewrites to ``Piecewise`` for evaluation.
``G`` is its potential (dG/dx = g), the elastic energy of a unit-stiffness mesh,
which is what the Lagrangian needs.
"""
from __future__ import annotations

import sympy as sp


def _numbers(*args: sp.Expr) -> bool:
    return all(a.is_Number for a in args)


class g(sp.Function):  # noqa: N801 - the paper's name
    """Backlash nonlinearity g(x, eta): x (x >= 0), 0 (-eta < x < 0), x + eta (x <= -eta)."""

    nargs = 2

    @classmethod
    def eval(cls, x, eta):
        if eta.is_zero:  # no clearance: the mesh is linear
            return x
        if _numbers(x, eta):
            return x if x >= 0 else (x + eta if x <= -eta else sp.S.Zero)
        return None

    def fdiff(self, argindex=1):
        x, eta = self.args
        if argindex == 1:
            return g_slope(x, eta)
        if argindex == 2:
            return _dg_deta(x, eta)
        raise sp.ArgumentIndexError(self, argindex)

    def _eval_rewrite_as_Piecewise(self, x, eta, **kwargs):
        return sp.Piecewise((x, x >= 0), (sp.S.Zero, x > -eta), (x + eta, True))

    def _latex(self, printer, exp=None):
        x, eta = (printer._print(a) for a in self.args)
        base = rf"g\left({x}, {eta}\right)"
        return base if exp is None else rf"{base}^{{{exp}}}"


class g_slope(sp.Function):  # noqa: N801
    """dg/dx: 1 in contact (x >= 0 or x <= -eta), 0 in the gap. Its own derivative is 0 a.e."""

    nargs = 2

    @classmethod
    def eval(cls, x, eta):
        if eta.is_zero:
            return sp.S.One
        if _numbers(x, eta):
            return sp.S.One if (x >= 0 or x <= -eta) else sp.S.Zero
        return None

    def fdiff(self, argindex=1):
        if argindex in (1, 2):
            return sp.S.Zero
        raise sp.ArgumentIndexError(self, argindex)

    def _eval_rewrite_as_Piecewise(self, x, eta, **kwargs):
        return sp.Piecewise((sp.S.One, x >= 0), (sp.S.Zero, x > -eta), (sp.S.One, True))

    def _latex(self, printer, exp=None):
        x, eta = (printer._print(a) for a in self.args)
        return rf"g'\left({x}, {eta}\right)"


def _dg_deta(x, eta):
    """dg/d(eta): 1 on the coast flank (x <= -eta), else 0."""
    return sp.Piecewise((sp.S.One, x <= -eta), (sp.S.Zero, True))


class G(sp.Function):  # noqa: N801
    """Backlash potential: dG/dx = g(x, eta); x**2/2, 0, (x + eta)**2/2 on the three branches."""

    nargs = 2

    @classmethod
    def eval(cls, x, eta):
        if eta.is_zero:
            return x**2 / 2
        if _numbers(x, eta):
            return sp.Piecewise(*cls._branches(x, eta)).doit()
        return None

    @staticmethod
    def _branches(x, eta):
        return ((x**2 / 2, x >= 0), (sp.S.Zero, x > -eta), ((x + eta) ** 2 / 2, True))

    def fdiff(self, argindex=1):
        x, eta = self.args
        if argindex == 1:
            return g(x, eta)
        if argindex == 2:
            return sp.Piecewise((x + eta, x <= -eta), (sp.S.Zero, True))
        raise sp.ArgumentIndexError(self, argindex)

    def _eval_rewrite_as_Piecewise(self, x, eta, **kwargs):
        return sp.Piecewise(*self._branches(x, eta))

    def _latex(self, printer, exp=None):
        x, eta = (printer._print(a) for a in self.args)
        return rf"G\left({x}, {eta}\right)"


#: every custom function, for printers and code generators that must map them
BACKLASH_FUNCTIONS = (g, g_slope, G)
