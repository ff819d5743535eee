"""Estimates in the form one writes them down: amplitudes >= 0, phases in (-pi, pi].

A model term ``A cos(tau + Theta)`` is the same physics as ``-A cos(tau + Theta + pi)`` and as
``A cos(tau + Theta + 2 pi)``, so a fit may end anywhere on those copies (B1 < 0 with Theta near
-13.8). Which parameters form such a pair is read from the equations, not from their names: (A, Theta)
is a pair if A -> -A, Theta -> Theta + pi leaves every equation unchanged, and a phase alone if
Theta -> Theta + 2 pi does. An effect's harmonic ``c cos(N phi) + s sin(N phi)`` is reported as
``A cos(N phi + theta)``: A = hypot(c, s), theta = atan2(-s, c), errors propagated from the
Gauss-Newton covariance.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import lru_cache

import numpy as np
import sympy as sp

from ..model.symbols import parameter_symbol
from ..system import FirstOrderSystem


def wrap_phase(phase: float) -> float:
    """``phase`` moved by whole turns into (-pi, pi]."""
    return math.pi - (math.pi - phase) % (2 * math.pi)


def _unchanged(rhs: tuple[sp.Expr, ...], change: dict) -> bool:
    """Whether ``change`` leaves every equation as it is, as SymPy's automatic evaluation shows it
    (cos(a + pi) = -cos(a), cos(a + 2 pi) = cos(a)): exact where it says so, and False where unsure."""
    return all(f.xreplace(change) == f for f in rhs if any(f.has(s) for s in change))


@lru_cache(maxsize=4096)
def _is_phase(rhs: tuple[sp.Expr, ...], name: str) -> bool:
    s = parameter_symbol(name)
    return any(f.has(s) for f in rhs) and _unchanged(rhs, {s: s + 2 * sp.pi})


@lru_cache(maxsize=4096)
def _is_pair(rhs: tuple[sp.Expr, ...], amplitude: str, phase: str) -> bool:
    a, s = parameter_symbol(amplitude), parameter_symbol(phase)
    return _unchanged(rhs, {a: -a, s: s + sp.pi})


def phase_pairs(system: FirstOrderSystem, names: Sequence[str]) -> tuple[tuple[str | None, str], ...]:
    """The (amplitude, phase) pairs among the parameters ``names`` of ``system`` (amplitude None: a phase
    alone, 2 pi periodic); see the module docstring."""
    rhs = tuple(system.rhs)
    phases = [n for n in names if _is_phase(rhs, n)]
    return tuple((next((a for a in names if a not in phases and _is_pair(rhs, a, p)), None), p) for p in phases)


def canonical(system: FirstOrderSystem, estimates: Mapping[str, float]) -> dict[str, float]:
    """``estimates`` with every amplitude >= 0 and every phase in (-pi, pi] (the same model)."""
    out = dict(estimates)
    for amplitude, phase in phase_pairs(system, list(estimates)):
        if amplitude is not None and out[amplitude] < 0:
            out[amplitude], out[phase] = -out[amplitude], out[phase] + math.pi
        out[phase] = wrap_phase(out[phase])
    return out


def amplitude_phase(c: float, s: float, covariance: np.ndarray | None = None):
    """``c cos(x) + s sin(x)`` as ``A cos(x + theta)``: (A, theta, stderr of A, stderr of theta); the errors
    from the 2x2 covariance of (c, s) (None without it, or at A = 0)."""
    A, theta = math.hypot(c, s), math.atan2(-s, c)
    if covariance is None or A == 0 or not np.all(np.isfinite(covariance)):
        return A, theta, None, None
    dA = np.array([c / A, s / A])
    dtheta = np.array([s / A**2, -c / A**2])
    return A, theta, float(np.sqrt(max(dA @ covariance @ dA, 0))), float(np.sqrt(max(dtheta @ covariance @ dtheta, 0)))
