"""The static states of many parameter points at once, from a :class:`~.linearised.StaticRecipe`.

Semismooth Newton on the averaged equations at rest (piecewise linear in the deflections for gear models, with
the backlash: exact once every mesh's flank is right, in a few steps), vectorised over the distinct values of
the parameters the static state depends on. Where Newton does not converge (a mesh that never closes under its
load, a singular stiffness) the point has no static state: it is marked, not guessed.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import casadi as ca
import numpy as np

from .recipe import StaticRecipe
from .monodromies import distinct_rows

#: Newton steps before a point's static state is declared not found
MAX_STEPS = 60
#: a residual below this times (1 + its size at the start) is zero
TOLERANCE = 1e-12

DRIVE, GAP, BACK, EDGE = "drive flank", "gap", "back flank", "edge of contact"


@dataclass(frozen=True)
class StaticStates:
    """The static states of many points, solved once per distinct value of the parameters they depend on: per
    distinct value (``index``: each point's), the static state (NaN where none was found), whether it was found,
    and each mesh's deflection and flank (``EDGE``: the deflection sits on a corner of g, 0 or -eta: linearised
    with g's slope 1); and how many of the points found are on each flank, per mesh. Per point: :attr:`states`,
    :attr:`found`, :meth:`deflection`, :meth:`flank`."""

    distinct_states: np.ndarray  # (distinct values, n)
    distinct_found: np.ndarray  # (distinct values,)
    index: np.ndarray  # (points,)
    distinct_deflection: dict[str, np.ndarray]
    distinct_flank: dict[str, np.ndarray]
    flank_counts: dict[str, dict[str, int]]

    @property
    def states(self) -> np.ndarray:
        """(points, n)"""
        return self.distinct_states[self.index]

    @property
    def found(self) -> np.ndarray:
        """(points,)"""
        if len(self.distinct_found) == 1:  # (a chart across parameters the static state does not depend on)
            return np.full(len(self.index), bool(self.distinct_found[0]))
        return self.distinct_found[self.index]

    def deflection(self, mesh: str) -> np.ndarray:
        return self.distinct_deflection[mesh][self.index]

    def flank(self, mesh: str) -> np.ndarray:
        return self.distinct_flank[mesh][self.index]


def solve_static(recipe: StaticRecipe, names: tuple[str, ...], p: np.ndarray) -> StaticStates:
    """The static states at the parameter vectors ``p`` (points x parameters, in the order ``names``)."""
    points = p.shape[0]
    columns = [names.index(name) for name in recipe.depends]
    distinct, _, index = distinct_rows(p[:, columns])
    if points == 0:
        return StaticStates(np.zeros((0, len(recipe.states))), np.zeros(0, dtype=bool), index, {}, {}, {})
    u, U = len(recipe.unknowns), distinct.shape[0]
    evaluate = _function(recipe.function).map(U)
    y = np.zeros((U, u))
    done = np.zeros(U, dtype=bool)
    scale = None
    for _ in range(MAX_STEPS):
        residual, jacobian, contact, eta = (np.array(v) for v in evaluate(y.T, distinct.T))
        residual = residual.reshape(u, U).T
        size = np.max(np.abs(residual), axis=1) if u else np.zeros(U)
        if scale is None:
            scale = 1.0 + size
        done = np.isfinite(size) & (size <= TOLERANCE * scale)
        if done.all():
            break
        active = np.nonzero(~done)[0]
        J = jacobian.reshape(u, U, u).transpose(1, 0, 2)[active] if u else None  # (CasADi maps side by side)
        step = _steps(J, -residual[active])
        y[active] += step
    states = np.zeros((U, len(recipe.states)))
    where = [recipe.states.index(s) for s in recipe.unknowns]
    states[:, where] = y
    states[~done] = np.nan
    contact = np.array(contact).reshape(len(recipe.meshes), U) if recipe.meshes else np.zeros((0, U))
    eta = np.array(eta).reshape(len(recipe.meshes), U) if recipe.meshes else np.zeros((0, U))
    deflection = {m: contact[k] for k, m in enumerate(recipe.meshes)}
    flanks = {m: _flanks(contact[k], eta[k]) for k, m in enumerate(recipe.meshes)}
    weight = np.bincount(index, minlength=U) * done  # (points found, per distinct value)
    counts = {}
    for m, f in flanks.items():
        counts[m] = {}
        for k in np.nonzero(weight)[0]:
            counts[m][f[k]] = counts[m].get(f[k], 0) + int(weight[k])
    return StaticStates(states, done, index, deflection, flanks, counts)


@lru_cache(maxsize=16)
def _function(serialised: str) -> ca.Function:
    f = ca.Function.deserialize(serialised)
    if f.class_name() != "SXFunction":  # (only an expression graph: nothing that loads code)
        raise ValueError("a static recipe must be an SX function")
    return f


def _steps(J: np.ndarray | None, rhs: np.ndarray) -> np.ndarray:
    """Newton steps J d = rhs, row by row (least squares where J is singular: a mesh in its gap)."""
    if J is None:
        return rhs
    try:
        return np.linalg.solve(J, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.array([np.linalg.lstsq(a, b, rcond=None)[0] for a, b in zip(J, rhs)])


def _flanks(d: np.ndarray, eta: np.ndarray) -> np.ndarray:
    tol = 1e-12 * np.maximum(1.0, np.abs(eta))
    out = np.where(d > tol, DRIVE, np.where(d < -eta - tol, BACK, GAP)).astype(object)
    out[(np.abs(d) <= tol) | (np.abs(d + eta) <= tol)] = EDGE
    out[~np.isfinite(d)] = "none"
    return out
