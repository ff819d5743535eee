"""Which exponents a run resolved: a value is reported only where the step and the re-orthonormalisation could
measure it.

Two things lose an exponent, and neither shows in the number itself:

* **the step.** A mode with |h mu| beyond what the method resolves (:data:`~gearsym.codegen.step_choice.
  RK4_RESOLVED` for RK4, ``STIFF_RESOLVED`` for the stiff RODAS4, which damps such a
  mode out in a step or two) has the discrete method's rate, not the model's. The linearised modes (the Jacobian
  averaged over a forcing period at the run's final state) say how many there are: that many of the lowest
  exponents (and any exponent with |h lambda| beyond the limit) are not resolved.
* **round-off.** Between two Gram-Schmidt steps a tangent vector that decays e^36 times faster than the first
  falls below the rounding of the others (the 2e-16 of double precision): its measured rate is then that of the
  rounding noise, an upper bound on the true one. The loops re-orthonormalise every 25 steps (but the paper's
  plain scheme, once per period), so this needs a spread beyond what RK4 is stable for.

An exponent not resolved is reported as such, never as a value: with the bound the run gives (round-off: at most
the measured rate) or the linearisation's rate of its mode as an estimate (the step), and the way to resolve it.
"""
from __future__ import annotations


import numpy as np

from ..records import record_class
from ..codegen.step_choice import RK4_RESOLVED, STIFF_RESOLVED

#: ln of the spread between two re-orthonormalisations beyond which a tangent vector is lost in round-off
#: (e^-30 = 1e-13: ~1000 times the rounding of the vectors it is orthogonalised against)
ROUND_OFF_SPREAD = 30.0


@record_class
class Resolution:
    """Per exponent (in the spectrum's descending order): whether the run resolved it, and if not why and what is
    known of it (``bound``: an upper bound for a round-off loss, ``estimate``: the linearised mode's rate)."""

    resolved: tuple[bool, ...]
    reasons: tuple[str, ...]  # "" (resolved), "step" or "round-off"
    estimate: tuple[float, ...]  # the linearised modes' real parts (descending), per unit time
    step: float  # h, per unit time
    limit: float  # |h mu| the method resolves

    @property
    def all_resolved(self) -> bool:
        return all(self.resolved)

    def note(self, i: int, rate: float = 1.0, unit: str = "") -> str:
        """What is said of exponent i (0-based) that was not resolved; '' if it was."""
        if self.resolved[i]:
            return ""
        if self.reasons[i] == "round-off":
            return ("not resolved: lost in round-off between two re-orthonormalisations; at most the rate measured "
                    "(give more steps per period)")
        return (f"not resolved: its mode is faster than the step resolves (|h mu| > {self.limit:g}); the "
                f"linearised mode's rate is about {self.estimate[i] * rate:.6g}{unit} (an estimate, not an exponent;"
                f" give more steps per period, or --integrator rk4 with enough of them)")

    def as_dict(self) -> dict:
        return {"resolved": list(self.resolved), "reasons": list(self.reasons),
                "linearised_estimate": [float(e) for e in self.estimate], "step": self.step, "limit": self.limit}


def linearised_eigenvalues(model, state, p: np.ndarray, cycle: float) -> np.ndarray:
    """The eigenvalues of the Jacobian averaged over a forcing period ``cycle`` (8 times) at ``state``."""
    mean = sum(np.array(model.jacobian(cycle * k / 8, state, p), dtype=float) for k in range(8)) / 8
    return np.linalg.eigvals(mean) if np.all(np.isfinite(mean)) else np.full(len(state), np.nan)


def resolution(model, exponents: np.ndarray, p: np.ndarray, state, period: float) -> Resolution:
    """What ``model``'s run at the parameter vector ``p`` resolved of ``exponents`` (descending, per unit
    time), its final ``state``, the run's ``period`` (see the module's docstring)."""
    n = len(exponents)
    h = period / model.steps_per_period
    limit = RK4_RESOLVED if model.options.method == "rk4" else STIFF_RESOLVED
    mu = linearised_eigenvalues(model, np.asarray(state, dtype=float), p, period / model.cycles)
    fast = int(np.sum(np.abs(mu) * h > limit)) if np.all(np.isfinite(mu)) else 0
    fast = max(fast, int(np.sum(np.abs(exponents) * h > limit)))
    interval = h * (model.options.reorthonormalise or model.steps_per_period)
    reasons = ["step" if i >= n - fast else "" for i in range(n)]
    for i in range(n):
        if not reasons[i] and (exponents[0] - exponents[i]) * interval > ROUND_OFF_SPREAD:
            reasons[i] = "round-off"
    estimate = tuple(float(x) for x in np.sort(mu.real)[::-1]) if np.all(np.isfinite(mu)) else (np.nan,) * n
    return Resolution(tuple(not r for r in reasons), tuple(reasons), estimate, h, limit)
