"""The Jacobian of a multiple-shooting fit's residuals, kept in its block structure (parameters dense, start states
per window), and the normal equations and projections made from it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Jacobian:
    """The Jacobian of the residuals by u = [theta, bias, S[:, 0], S[:, 1], ...], kept in its structure: the
    columns of the parameters and offsets (``P``, dense) and each residual's derivatives by its own window's
    start state (``S``; the rows of window k are ``rows[k]:rows[k + 1]``). The normal equations are then
    solved by the Schur complement on the parameters: O(windows) work, and small arrays only (threaded BLAS
    on a busy machine made the dense products of the whole J 10x slower)."""

    P: np.ndarray  # (residuals, parameters + offsets)
    S: np.ndarray  # (residuals, n)
    window: np.ndarray  # (residuals,)
    rows: np.ndarray  # (windows + 1,)

    @property
    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.P)) and np.all(np.isfinite(self.S)))

    def blocks(self, X: np.ndarray) -> np.ndarray:
        """Per window, the sum over its rows of ``X`` (rows first)."""
        return np.add.reduceat(X, self.rows[:-1], axis=0)

    def normal(self, r: np.ndarray):
        """U = P^T P, W_k = P_k^T S_k, V_k = S_k^T S_k and the gradients P^T r, S_k^T r."""
        P, S = self.P, self.S
        return (np.einsum("ri,rj->ij", P, P), self.blocks(np.einsum("ri,rj->rij", P, S)),
                self.blocks(np.einsum("ri,rj->rij", S, S)), np.einsum("ri,r->i", P, r),
                self.blocks(S * r[:, None]))

    def window_rows(self, windows: np.ndarray) -> np.ndarray:
        """The rows of ``windows`` (in their order)."""
        return np.concatenate([np.arange(self.rows[k], self.rows[k + 1]) for k in windows]) if len(windows) \
            else np.zeros(0, dtype=int)

    def out_of_starts(self, X: np.ndarray, windows: np.ndarray | None = None) -> np.ndarray:
        """``X`` (residuals x q) with what the start states can make removed; with ``windows``, ``X`` holds the rows
        of those windows only (:meth:`window_rows`), zero elsewhere, and so does the result (each window's start
        acts on its own rows only): the work and memory of those windows, not of them all."""
        if windows is None:
            S, rows, window = self.S, self.rows[:-1], self.window
        else:
            lengths = self.rows[np.asarray(windows) + 1] - self.rows[np.asarray(windows)]
            S = self.S[self.window_rows(windows)]
            rows = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(int)
            window = np.repeat(np.arange(len(lengths)), lengths)
        if not len(S):
            return X
        V = np.linalg.pinv(np.add.reduceat(np.einsum("rn,rm->rnm", S, S), rows, axis=0))
        SX = np.add.reduceat(np.einsum("rn,rq->rnq", S, X), rows, axis=0)
        return X - np.einsum("rn,rnq->rq", S, np.einsum("knm,kmq->knq", V, SX)[window])

    def project_out(self, Y: np.ndarray) -> np.ndarray:
        """``Y`` (residuals x q) with what the start states and then the parameters' columns can make removed."""
        def out_of_starts(X):
            V = np.linalg.pinv(self.blocks(np.einsum("rn,rm->rnm", self.S, self.S)))
            SX = self.blocks(np.einsum("rn,rq->rnq", self.S, X))
            return X - np.einsum("rn,rnq->rq", self.S, np.einsum("knm,kmq->knq", V, SX)[self.window])

        Y, P = out_of_starts(Y), out_of_starts(self.P)
        if P.shape[1]:
            Y = Y - P @ (np.linalg.pinv(np.einsum("ri,rj->ij", P, P)) @ np.einsum("ri,rq->iq", P, Y))
        return Y
