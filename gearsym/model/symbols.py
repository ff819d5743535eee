"""The few symbols every model shares, and the canonical parameter symbol.

All parameters are real SymPy symbols created through :func:`parameter_symbol`,
so that a model file, the reducer and a test that types the paper's equation
refer to the very same object.
"""
from __future__ import annotations

import sympy as sp

#: time in the paper's units (scaled so that the reference mesh has unit mean stiffness)
t = sp.Symbol("t", real=True)
#: nondimensional time tau = omega * t; one forcing period is 2*pi
tau = sp.Symbol("tau", real=True)
#: mesh phase: the argument of a mesh stiffness variation, 2*pi periodic
phi = sp.Symbol("phi", real=True)
#: forcing (and mesh) frequency in the units of t
omega = sp.Symbol("omega", positive=True)

RESERVED = {"t": t, "tau": tau, "phi": phi}


def parameter_symbol(name: str) -> sp.Symbol:
    """The canonical symbol of a parameter called ``name``."""
    if name == "omega":
        return omega
    return sp.Symbol(name, real=True)
