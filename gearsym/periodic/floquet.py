"""What a periodic orbit's monodromy matrix and extremes say: Floquet multipliers, stability, the test
functions of its bifurcations, and each mesh's contact regime over the orbit.

Test functions (each changes sign at its bifurcation, and is located where it does):

* fold (saddle-node, a multiplier through +1): the parameter component of the branch's tangent, which
  vanishes where the branch turns back;
* period doubling (a multiplier through -1): det(M + I);
* Neimark-Sacker (a complex pair through |mu| = 1): the product over pairs i < j of (mu_i mu_j - 1) (the
  bialternate product's determinant), which also vanishes at a neutral saddle (two real multipliers with
  mu_i mu_j = 1): that is told apart where it is located. With two states the product is det M - 1,
  which damping keeps below zero: a damped one-degree-of-freedom oscillator has no torus;
* grazing (the non-smooth events of gears): a mesh's contact coordinate x, over the orbit, reaching the
  surface x = 0 (its minimum: tooth separation begins; its maximum: the drive flank is left entirely) or
  x = -eta (its minimum: back-flank impacts begin; its maximum: the orbit leaves the back flank).

The contact regime of a mesh with backlash eta over an orbit, from the minimum of its contact coordinate:
``no impact`` (x >= 0 throughout: the teeth never separate), ``single-sided impact`` (-eta < min x < 0:
the teeth separate and strike the drive flank again), ``double-sided impact`` (min x <= -eta: the back
flank is struck too), and ``no contact`` for an orbit that stays in the gap. The extremes are those over
the RK4 steps (the amplitudes of ``gearsym sweep`` use the same ones).
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from ..codegen import CompiledModel

NO_IMPACT, SINGLE_SIDED, DOUBLE_SIDED, NO_CONTACT = ("no impact", "single-sided impact", "double-sided impact",
                                                     "no contact")
CONTACT_REGIMES = (NO_IMPACT, SINGLE_SIDED, DOUBLE_SIDED, NO_CONTACT)

FOLD, PERIOD_DOUBLING, NEIMARK_SACKER, GRAZING = "fold", "period doubling", "Neimark-Sacker", "grazing"


def multipliers(M: np.ndarray) -> np.ndarray:
    """The Floquet multipliers (eigenvalues of the monodromy matrix), largest modulus first."""
    mu = np.linalg.eigvals(M)
    return mu[np.lexsort((-mu.imag, -np.abs(mu)))]


def stable(mu: np.ndarray) -> bool:
    """Every multiplier inside the unit circle (for a forced system none sits on it by construction)."""
    return bool(np.max(np.abs(mu)) < 1.0)


def period_doubling_test(M: np.ndarray) -> float:
    return float(np.linalg.det(M + np.eye(len(M))))


def neimark_sacker_test(mu: np.ndarray) -> float:
    return float(np.real(np.prod([a * b - 1 for a, b in combinations(mu, 2)]))) if len(mu) > 2 else -1.0


def torus_pair(mu: np.ndarray, tolerance: float = 1e-3) -> bool:
    """A complex pair on the unit circle (told apart from a neutral saddle where the NS test vanishes)."""
    return any(abs(m.imag) > tolerance and abs(abs(m) - 1) < tolerance for m in mu)


@dataclass(frozen=True)
class MeshWatch:
    """A mesh with backlash whose contact coordinate the orbit's extremes are read on."""

    name: str
    coordinate: str
    column: int  # in the model's observed states
    backlash: float | str | object  # a number, a parameter's name or a SymPy expression in parameters
    offset: float | str | object  # contact = coordinate + offset (an effect may shift it by parameters)

    def value(self, expr, names: tuple[str, ...], p: np.ndarray) -> float:
        if isinstance(expr, (int, float)):
            return float(expr)
        if isinstance(expr, str):
            return float(p[names.index(expr)])
        return float(expr.xreplace({s: float(p[names.index(s.name)]) for s in expr.free_symbols}))

    def extremes(self, low: np.ndarray, high: np.ndarray, names, p) -> tuple[float, float, float]:
        """(min, max) of the contact coordinate over the orbit, and eta."""
        shift = self.value(self.offset, names, p)
        return float(low[self.column] + shift), float(high[self.column] + shift), self.value(self.backlash, names, p)


def mesh_watches(model: CompiledModel) -> tuple[MeshWatch, ...]:
    """The meshes with backlash of ``model`` whose contact coordinate is observed and shifted by parameters
    only (every mesh of the shipped drivetrains); none for a plain ODE. A model from the start-up cache reads
    them from its summary (no SymPy, no reduction)."""
    return tuple(MeshWatch(name, coordinate, model.observed.index(coordinate), backlash, offset)
                 for name, coordinate, backlash, offset in model.system.contact_watches)


def contact_regime(low: float, high: float, eta: float) -> str:
    """The contact regime of a mesh over an orbit from the extremes of its contact coordinate."""
    if low >= 0:
        return NO_IMPACT
    if low <= -eta:
        return DOUBLE_SIDED
    return SINGLE_SIDED if high >= 0 else NO_CONTACT


def grazing_tests(watch: MeshWatch, low: np.ndarray, high: np.ndarray, names, p) -> dict[str, float]:
    """The four grazing test functions of one mesh, keyed by what their zero means."""
    lo, hi, eta = watch.extremes(low, high, names, p)
    x = watch.coordinate
    return {f"{watch.name}: min {x} = 0, tooth separation": lo,
            f"{watch.name}: min {x} = -eta, back-flank impact": lo + eta,
            f"{watch.name}: max {x} = 0, drive flank left": hi,
            f"{watch.name}: max {x} = -eta, back flank left": hi + eta}
