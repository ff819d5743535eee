"""Shared bits of the peer implementations: models, defaults, result type, MGS.

Every peer module has ``make(model, accuracy=None, **params) -> Tool``; the
Tool computes the Lyapunov spectrum of one of the two gear models by the
common task (P forcing periods of length 2 pi, the first D discarded, tangent
vectors Q = I at the start of every point, Q' = J Q with the exact Jacobian,
modified Gram-Schmidt after every period, exponents in Gram-Schmidt column
order). See bench/yardstick/flexible_shaft.c for the fixed-step scheme.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Protocol, Sequence

import numpy as np

T = 2.0 * math.pi  # forcing period in nondimensional time

MODELS = ("one_stage", "flexible_shaft")

DEFAULTS: dict[str, dict[str, float]] = {
    "one_stage": dict(zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.2),
    "flexible_shaft": dict(zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, kS=0.1, k_a=0.2,
                           I1=1.0, I2=1.0, I3=1.0, r1=1.0, r2=1.0),
}
Y0: dict[str, tuple[float, ...]] = {
    "one_stage": (-2.0, -0.5),
    "flexible_shaft": (-2.0, -0.5, 0.0, 0.0),
}
DIM = {m: len(y) for m, y in Y0.items()}

# Mesh stiffness k(tau) = 1 + k_a * sum_m c_m cos(m tau): gearsym's default (rectangular_mesh_stiffness(), 12 digits;
# the paper shows k only as a plot): the same numbers tests/test_crossings.py checks against that formula.
K_HARMONICS: tuple[tuple[int, float], ...] = (
    (1, 1.18003861468), (2, -0.336894506314), (3, -0.195632837787),
    (4, 0.192724343884), (6, -0.0605674179821), (7, 0.0148837545288),
)


def model_params(model: str, **params: float) -> dict[str, float]:
    """The model's defaults overridden by ``params``; unknown names are an error."""
    if model not in DEFAULTS:
        raise ValueError(f"unknown model {model!r}; known: {MODELS}")
    unknown = set(params) - set(DEFAULTS[model])
    if unknown:
        raise TypeError(f"model {model!r} has no parameter(s) {sorted(unknown)}; "
                        f"known: {tuple(DEFAULTS[model])}")
    return {**DEFAULTS[model], **{k: float(v) for k, v in params.items()}}


def default_state(model: str) -> tuple[float, ...]:
    """The paper's start (x, v) = (-2, -0.5), shaft at rest for flexible_shaft."""
    if model not in Y0:
        raise ValueError(f"unknown model {model!r}; known: {MODELS}")
    return Y0[model]


def initial_state(model: str, y0: Sequence[float] | None) -> np.ndarray:
    y = np.array(default_state(model) if y0 is None else y0, dtype=float)
    if y.shape != (DIM[model],):
        raise ValueError(f"y0 for {model!r} needs {DIM[model]} values, got shape {y.shape}")
    return y


def shaft_constants(p: dict[str, float]) -> tuple[float, float, float]:
    """b1, b2, b3 of the flexible-shaft model."""
    b1 = 1.0 / p["I2"]
    b2 = 1.0 / p["I2"] + 1.0 / p["I3"]
    a2, a1 = p["r2"] ** 2 / p["I2"], p["r1"] ** 2 / p["I1"]
    return b1, b2, a2 / (a2 + a1)


def sum_rule(model: str, omega: float, **params: float) -> float:
    """Sum of the exponents = time average of trace J = -2 zeta/omega (both models)."""
    return -2.0 * model_params(model, **params)["zeta"] / omega


def mgs(Q: np.ndarray) -> np.ndarray:
    """Modified Gram-Schmidt in place on the columns of Q; returns log of the norms."""
    n = Q.shape[1]
    lognorm = np.empty(n)
    for j in range(n):
        for i in range(j):
            Q[:, j] -= (Q[:, i] @ Q[:, j]) * Q[:, i]
        nrm = math.sqrt(Q[:, j] @ Q[:, j])
        Q[:, j] /= nrm
        lognorm[j] = math.log(nrm)
    return lognorm


@dataclass
class PointResult:
    exponents: np.ndarray    # Gram-Schmidt column order
    final_state: np.ndarray  # state after the last period (the next point's start)
    seconds: float           # compute time of this point, excluding setup, by the tool's own clock


class Tool(Protocol):
    name: str
    model: str
    setup_seconds: float     # time make() took in this process (compile / JIT / code generation)
    setup_note: str
    accuracy: dict           # {"steps": N} fixed step, or {"rtol": .., "atol": ..} adaptive

    def spectrum(self, omega: float, y0=None, periods: int = 400, discard: int = 100) -> PointResult: ...

    def sweep(self, omegas, y0=None, periods: int = 400, discard: int = 100) -> list[PointResult]: ...


def fixed_step_accuracy(accuracy: dict | None, tool: str) -> dict:
    """``{"steps": N}`` (default 200 steps per period) for a fixed-step tool; anything else is an error."""
    if set(accuracy or {}) - {"steps"}:
        raise ValueError(f"{tool} is fixed-step: accuracy takes only 'steps', got {accuracy}")
    return {"steps": int((accuracy or {}).get("steps", 200))}


def check_periods(periods: int, discard: int) -> None:
    if not 0 <= discard < periods:
        raise ValueError(f"need periods > discard >= 0, got periods={periods}, discard={discard}")


class ContinuationSweep:
    """Mixin: ``sweep`` by continuation over ``spectrum`` (each point starts
    from the previous final state; ``spectrum`` resets Q = I)."""

    model: str

    def spectrum(self, omega: float, y0=None, periods: int = 400, discard: int = 100) -> PointResult:
        raise NotImplementedError

    def sweep(self, omegas, y0=None, periods: int = 400, discard: int = 100) -> list[PointResult]:
        y = initial_state(self.model, y0)
        out = []
        for w in omegas:
            r = self.spectrum(float(w), y, periods, discard)
            out.append(r)
            y = r.final_state
        return out


class Stopwatch:
    """perf_counter around a block: ``with Stopwatch() as sw: ...; sw.seconds``."""

    def __enter__(self) -> "Stopwatch":
        self._t0 = time.perf_counter()
        return self

    def __exit__(self, *exc) -> None:
        self.seconds = time.perf_counter() - self._t0
