"""Levenberg-Marquardt on a multiple-shooting problem, projected onto the parameters' bounds, with each step solved
by the Schur complement on the parameters (the start-state blocks are n x n per window).

It stops where the statistics say iterating on is pointless: when the step just taken, or the Gauss-Newton step from
the current estimates, moves every unknown (parameters, offsets, start states) by less than ``STEP_IN_SIGMAS`` of its
own standard error (Bates & Watts' relative offset criterion, taken unknown by unknown: the estimates are then as good
as the noise lets them be, and a further step changes nothing a reader can see). Both are needed: near the backlash
kink the cost is rough at a few hundredths of a standard error, where the Gauss-Newton step keeps pointing that far
while the steps that lower the cost shrink. On data without noise neither happens; the cost's relative gain below
``RELATIVE_GAIN`` stops it there."""
from __future__ import annotations

import numpy as np

from .problem import Problem

#: the fit stops once a step (the last, or the next Gauss-Newton one) moves every unknown by less than this fraction of
#: its standard error (tests/test_explain.py checks that the estimates are then those of a fit run to RELATIVE_GAIN
#: alone, within 1 % of their standard errors)
STEP_IN_SIGMAS = 1e-3
#: ... or once a step lowers the cost by less than this fraction of it (data without noise: no standard error to use)
RELATIVE_GAIN = 1e-12


def levenberg_marquardt(problem: Problem, u, low, high, max_iterations: int, ridge=None):
    """Gauss-Newton steps with Marquardt's damping, projected onto the bounds: robust where the backlash makes
    the exact Hessian jump, and it needs only the Jacobian. ``ridge``: per parameter and offset a weight w, the
    cost r.r + sum w u^2 (a regularised fit; None: none). Returns (u, J, r, steps taken, converged)."""
    r, J = problem(u)
    p = J.P.shape[1]
    ridge = np.zeros(p) if ridge is None else np.asarray(ridge, dtype=float)

    def total(r, u):
        return float(r @ r) + float(ridge @ (u[:p] * u[:p]))

    cost, mu = total(r, u), 1e-3
    converged, iteration, moved = False, 0, None
    if not (np.isfinite(cost) and J.finite):  # the model does not even run from the first guess
        return u, J, r, iteration, converged
    for iteration in range(1, max_iterations + 1):
        U, W, V, gP, gS = J.normal(r)
        U, gP = U + np.diag(ridge), gP + ridge * u[:p]
        held = ((u[:p] <= low[:p]) & (gP > 0)) | ((u[:p] >= high[:p]) & (gP < 0))  # the descent would leave the box
        spread, newton = standard_errors_and_newton_step(U, W, V, gP, gS, ~held, float(r @ r), r.size)
        if within_noise(moved, spread) or within_noise(np.clip(u + newton, low, high) - u, spread):
            return u, J, r, iteration - 1, True
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
        moved = u_new - u
        u, r, J, cost = u_new, r_new, J_new, new_cost
        mu = max(mu / 3, 1e-9)
        if gain <= RELATIVE_GAIN * max(cost, 1e-300) or np.max(np.abs(moved)) < 1e-10:
            converged = True
            break
    return u, J, r, iteration, converged


def within_noise(move: np.ndarray | None, spread: np.ndarray | None) -> bool:
    """Whether ``move`` changes every unknown by less than ``STEP_IN_SIGMAS`` of its standard error ``spread``."""
    if move is None or spread is None or not STEP_IN_SIGMAS > 0:
        return False
    return bool(np.all(np.isfinite(move)) and np.all(np.abs(move) <= STEP_IN_SIGMAS * spread))


def standard_errors_and_newton_step(U, W, V, gP, gS, free: np.ndarray, rss: float, residuals: int):
    """Every unknown's standard error and the (undamped) Gauss-Newton step, from the normal equations' blocks: the
    covariance sigma^2 (J^T J)^-1 with sigma^2 = RSS / (residuals - unknowns), the parameters' block the inverse C of
    the Schur complement, each window's start state's V_k^-1 + V_k^-1 W_k^T C W_k V_k^-1 (what the parameters'
    uncertainty adds to it); the parameters held at a bound (not ``free``) neither move nor count. Directions the data
    cannot determine (the pseudo-inverses' null spaces) have a standard error 0 and do not move: they stop nothing.
    (None, None) where sigma^2 is no positive number (data without noise)."""
    K, n = V.shape[0], V.shape[1]
    p = U.shape[0]
    sigma2 = rss / max(1, residuals - int(free.sum()) - K * n)
    if not (np.isfinite(sigma2) and sigma2 > 0):
        return None, None
    Vinv = _pinv_scaled(V)
    dP, varP = np.zeros(p), np.zeros(p)
    WVi, C = np.zeros((K, 0, n)), np.zeros((0, 0))
    if free.any():
        Wf = W[:, free, :]
        WVi = np.einsum("kpn,knm->kpm", Wf, Vinv)
        C = _pinv_scaled(U[np.ix_(free, free)] - np.einsum("kpm,kqm->pq", WVi, Wf))
        dP[free] = -C @ (gP[free] - np.einsum("kpm,km->p", WVi, gS))
        varP[free] = np.diag(C)
    dS = -np.einsum("knm,km->kn", Vinv, gS + np.einsum("kpn,p->kn", W, dP))
    varS = np.diagonal(Vinv, axis1=1, axis2=2) + np.einsum("kpi,pq,kqi->ki", WVi, C, WVi)
    spread = np.sqrt(sigma2 * np.maximum(np.concatenate([varP, varS.reshape(-1)]), 0.0))
    return spread, np.concatenate([dP, dS.reshape(-1)])


def _pinv_scaled(A: np.ndarray) -> np.ndarray:
    """The pseudo-inverse of the symmetric matrix ``A`` (or of each of a stack), its rows and columns scaled to unit
    diagonal first (the unknowns' units differ), singular values below 1e-12 of the largest taken as zero."""
    d = np.sqrt(np.maximum(np.diagonal(A, axis1=-2, axis2=-1), 0.0))
    d = np.where(d > 0, d, 1.0)
    scaled = A / (d[..., :, None] * d[..., None, :])
    return np.linalg.pinv(scaled, rcond=1e-12, hermitian=True) / (d[..., :, None] * d[..., None, :])


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
