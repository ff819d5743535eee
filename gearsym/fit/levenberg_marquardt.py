"""Levenberg-Marquardt on a multiple-shooting problem, projected onto the parameters' bounds, with each step solved
by the Schur complement on the parameters (the start-state blocks are n x n per window)."""
from __future__ import annotations

import numpy as np

from .problem import Problem


def levenberg_marquardt(problem: Problem, u, low, high, max_iterations: int, ridge=None):
    """Gauss-Newton steps with Marquardt's damping, projected onto the bounds: robust where the backlash makes
    the exact Hessian jump, and it needs only the Jacobian. ``ridge``: per parameter and offset a weight w, the
    cost r.r + sum w u^2 (a regularised fit; None: none)."""
    r, J = problem(u)
    p = J.P.shape[1]
    ridge = np.zeros(p) if ridge is None else np.asarray(ridge, dtype=float)

    def total(r, u):
        return float(r @ r) + float(ridge @ (u[:p] * u[:p]))

    cost, mu = total(r, u), 1e-3
    converged, iteration = False, 0
    if not (np.isfinite(cost) and J.finite):  # the model does not even run from the first guess
        return u, J, r, iteration, converged
    for iteration in range(1, max_iterations + 1):
        U, W, V, gP, gS = J.normal(r)
        U, gP = U + np.diag(ridge), gP + ridge * u[:p]
        held = ((u[:p] <= low[:p]) & (gP > 0)) | ((u[:p] >= high[:p]) & (gP < 0))  # the descent would leave the box
        while True:
            try:
                step = _damped_step(U, W, V, gP, gS, mu, ~held)
            except np.linalg.LinAlgError:
                step = None
            if step is None or not np.all(np.isfinite(step)):
                mu *= 10
                if mu > 1e12:
                    return u, J, r, iteration, converged
                continue
            u_new = np.clip(u + step, low, high)
            r_new, J_new = problem(u_new)
            new_cost = total(r_new, u_new) if np.all(np.isfinite(r_new)) and J_new.finite else np.inf
            if new_cost < cost:
                break
            mu *= 10
            if mu > 1e12:
                return u, J, r, iteration, True  # no step lowers the cost: a (bounded) minimum
        gain = cost - new_cost
        moved = np.max(np.abs(u_new - u))
        u, r, J, cost = u_new, r_new, J_new, new_cost
        mu = max(mu / 3, 1e-9)
        if gain <= 1e-12 * max(cost, 1e-300) or moved < 1e-10:
            converged = True
            break
    return u, J, r, iteration, converged


def _damped_step(U, W, V, gP, gS, mu: float, free: np.ndarray) -> np.ndarray:
    """The Levenberg-Marquardt step for [parameters (the ``free`` ones), start states] from the normal equations'
    blocks, by the Schur complement on the parameters (the start-state blocks are n x n per window)."""
    n = V.shape[1]
    dV = np.maximum(np.diagonal(V, axis1=1, axis2=2), 1e-12)
    Vinv = np.linalg.inv(V + mu * dV[:, :, None] * np.eye(n))
    dP = np.zeros(U.shape[0])
    if free.any():
        Uf, Wf = U[np.ix_(free, free)], W[:, free, :]
        WVi = np.einsum("kpn,knm->kpm", Wf, Vinv)
        schur = Uf + mu * np.diag(np.maximum(np.diag(Uf), 1e-12)) - np.einsum("kpm,kqm->pq", WVi, Wf)
        dP[free] = -np.linalg.solve(schur, gP[free] - np.einsum("kpm,km->p", WVi, gS))
    dS = -np.einsum("knm,km->kn", Vinv, gS + np.einsum("kpn,p->kn", W, dP))
    return np.concatenate([dP, dS.reshape(-1)])
