"""Mesh stiffness variation k(phi): a declared, replaceable SymPy expression.

The paper shows k(tau) only as a plot (its Fig. 2, from a source we cannot
read), so the formula is a declared default, not a reproduction. The default is
the usual picture of spur-gear meshing: the stiffness alternates between
double-tooth contact (a fraction ``contact_ratio - 1`` of each mesh period) and
single-tooth contact. A rectangular wave would make the right-hand side
discontinuous in time, so we use its first ``harmonics`` Fourier terms with
Lanczos sigma factors (no Gibbs overshoot), normalised to mean 1 and
peak-to-peak ``2 * amplitude`` (before smoothing).
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import sympy as sp

from ..errors import ModelError
from .symbols import phi, parameter_symbol

#: documented defaults of the stiffness variation
DEFAULT_CONTACT_RATIO = 1.6
DEFAULT_HARMONICS = 7
DEFAULT_AMPLITUDE_NAME = "k_a"
DEFAULT_AMPLITUDE = 0.2


def rectangular_mesh_stiffness(
    amplitude: str | float = DEFAULT_AMPLITUDE_NAME,
    contact_ratio: float = DEFAULT_CONTACT_RATIO,
    harmonics: int = DEFAULT_HARMONICS,
    variable: sp.Symbol = phi,
) -> sp.Expr:
    """Smoothed rectangular stiffness wave of mean 1, as a function of the mesh phase.

    ``1 + a * sum_n sigma_n * 4/(n*pi) * sin(n*pi*d) * cos(n*phi)`` with duty
    ``d = contact_ratio - 1`` and Lanczos factor ``sigma_n = sinc(n/(N+1))``.
    Coefficients are rounded to 12 significant digits so the expression (and
    the code generated from it) is the same on every machine.
    """
    if not 1.0 < contact_ratio < 2.0:
        raise ModelError(f"contact_ratio must lie in (1, 2), got {contact_ratio}", "mesh stiffness")
    if harmonics < 1:
        raise ModelError(f"harmonics must be at least 1, got {harmonics}", "mesh stiffness")
    duty = contact_ratio - 1.0
    a = parameter_symbol(amplitude) if isinstance(amplitude, str) else sp.Float(amplitude)
    wave = sp.S.Zero
    for n in range(1, harmonics + 1):
        x = n / (harmonics + 1)
        sigma = math.sin(math.pi * x) / (math.pi * x)
        c = sigma * 4.0 / (n * math.pi) * math.sin(n * math.pi * duty)
        if abs(c) < 1e-12:  # a harmonic the duty cycle cancels exactly
            continue
        wave += sp.Float(f"{c:.12g}") * sp.cos(n * variable)
    return 1 + a * wave


def check_periodic(
    expr: sp.Expr,
    variable: sp.Symbol,
    where: str,
    values: Mapping[sp.Symbol, float] | None = None,
    period: sp.Expr = 2 * sp.pi,
) -> None:
    """Raise ModelError unless ``expr`` is ``period``-periodic in ``variable`` for every parameter value.

    First symbolically (shift and simplify). If SymPy cannot decide, numerically
    at 24 phases, with the other symbols at ``values`` and at three random
    parameter sets: a period that holds only at the defaults (``cos(w*phi)`` with
    w = 1) would break as soon as w is changed at run time, so it is rejected.
    """
    if variable not in expr.free_symbols:
        return
    diff = sp.simplify(expr.subs(variable, variable + period) - expr)
    if diff == 0:
        return
    others = sorted((expr.free_symbols | diff.free_symbols) - {variable}, key=lambda s: s.name)
    rng = np.random.default_rng(12345)
    trials = [{s: (values or {}).get(s, 1.0) for s in others}]
    trials += [{s: float(rng.uniform(0.3, 1.7)) for s in others} for _ in range(3)]
    xs = np.linspace(0.0, float(period), 24, endpoint=False) + 0.137
    for subs in trials:
        f = sp.lambdify(variable, diff.subs(subs).rewrite(sp.Piecewise), "numpy")
        scale = sp.lambdify(variable, expr.subs(subs).rewrite(sp.Piecewise), "numpy")
        err = float(np.max(np.abs(np.asarray(f(xs), dtype=float) * np.ones_like(xs))))
        ref = max(1.0, float(np.max(np.abs(np.asarray(scale(xs), dtype=float) * np.ones_like(xs)))))
        if not np.isfinite(err) or err > 1e-9 * ref:
            at = ", ".join(f"{k}={v:.3g}" for k, v in subs.items())
            raise ModelError(
                f"the mesh stiffness {expr} is not {period}-periodic in {variable}"
                f"{' at ' + at if at else ''} (the shift by one period changes it by up to {err:.3g}). "
                f"Write it with whole multiples of the mesh phase, e.g. 1 + 0.2*cos({variable}), "
                "and set a mesh's frequency with its `order`, not with a parameter.",
                where,
            )
