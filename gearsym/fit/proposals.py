"""Beyond the library: when the residual stays structured, terms proposed from a generic dictionary.

**Dictionary** (:func:`dictionary`), for the mesh coordinate x, its rate v, the states y and
g = g(x, eta): 1; the monomials of the states up to degree 2 and those of x, v of degree 3; g, g^2,
g^3; cos(n tau), sin(n tau) for n = 1 ... ``harmonics``; and those harmonics times x, v and g. Each
term enters the acceleration of the mesh coordinate, dv/dtau, with a coefficient of its own.

**Regression.** The residual is regressed on the model's *response* to each term rather than on a
differentiated record: the columns are the exact sensitivities of the fitted outputs to each term's
coefficient at 0 (the variational equations of the fit's own window integrator), with the
directions the fit already has (its parameters, every window's start state, the channel offsets)
projected out. To first order this is the regression of the residual acceleration (for an
accelerometer channel, exactly its residual), for any channel, without differentiating a noisy
displacement twice (which amplifies the noise by 1/h^2).

**Sparse method:** sequentially thresholded least squares (STLSQ, SINDy's optimiser), hand-written
below (:func:`stlsq`, about 20 lines) with a small ridge on columns of unit norm, the threshold swept from large to small
and the sparsest support kept that explains 90 % of what the whole dictionary explains (an
information criterion such as BIC kept dozens of terms: a structured residual keeps rewarding
more). It is one small dense least-squares problem; PySINDy (which brings scikit-learn) or scikit-learn's Lasso would add a dependency and no
capability here, and Lasso's shrinkage biases the coefficients that STLSQ refits without it.

Each chosen term, strongest first (at most ``MAX_PROPOSALS``), is then added to the final model
and refitted by multiple shooting; its coefficient and the held-out error of the refitted model are
reported, and its string is what ``gearsym explain --add-term`` takes (parsed by the safe parser).
"""
from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import sympy as sp

from ..options import Integration
from ..system import FirstOrderSystem
from .effects import augment, bounds_of, own_term, site, term_text
from .prediction import predict_ahead
from .score import score_columns
from .segment import Segment
from .shooting import fit_windows

MAX_PROPOSALS = 3
#: the ridge of STLSQ on unit-norm columns: steadies the fit where dictionary terms are nearly collinear
RIDGE = 1e-3
#: the sparsest support that explains this fraction of what the whole dictionary explains is chosen
EXPLAINED = 0.9


@dataclass(frozen=True)
class Proposal:
    """A term beyond the library: as ``--add-term`` takes it, its coefficient in dv/dtau (refitted), and the
    held-out error of the final model refitted with it (``error_before``: without)."""

    term: str
    coefficient: float
    stderr: float | None
    error: float
    error_before: float
    linearised: float  # the coefficient the regression gave, before the refit

    def as_dict(self) -> dict:
        return {"term": self.term, "coefficient": self.coefficient, "stderr": self.stderr,
                "held_out_error": self.error, "held_out_error_before": self.error_before,
                "regression_coefficient": self.linearised}


def dictionary(system: FirstOrderSystem, harmonics: int) -> list[sp.Expr]:
    """The generic terms (see the module docstring), without repeats, in a fixed order."""
    mesh = site(system, "mesh")
    x, v, gx, tau = mesh.x, mesh.v, mesh.backlash, system.time
    states = list(system.states)
    terms: list[sp.Expr] = [sp.S.One]
    terms += [sp.Mul(*c) for degree in (1, 2) for c in itertools.combinations_with_replacement(states, degree)]
    terms += [sp.Mul(*c) for c in itertools.combinations_with_replacement((x, v), 3)]
    terms += [gx, gx**2, gx**3]
    waves = [f(n * tau) for n in range(1, harmonics + 1) for f in (sp.cos, sp.sin)]
    terms += waves + [w * z for w in waves for z in (x, v, gx)]
    return list(dict.fromkeys(terms))


def stlsq(X: np.ndarray, y: np.ndarray, threshold: float, ridge: float = RIDGE, iterations: int = 10) -> np.ndarray:
    """Sequentially thresholded (ridge) least squares, SINDy's: fit, zero the coefficients below ``threshold``,
    refit the rest, until the support stays."""
    return _stlsq(*_normal(X, y), threshold, ridge, iterations)


def _normal(X: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """X^T X and X^T y: every ridge fit on a subset of X's columns reads its rows and columns of them (made once, not
    once a fit: on a loaded machine's threaded BLAS one X^T X of 900 x 45 took 30 ms of CPU, a sweep 120 of them)."""
    return X.T @ X, X.T @ y


def _stlsq(G: np.ndarray, b: np.ndarray, threshold: float, ridge: float, iterations: int) -> np.ndarray:
    coef = _ridge(G, b, ridge)
    for _ in range(iterations):
        keep = np.abs(coef) >= threshold
        new = np.zeros_like(coef)
        if keep.any():
            new[keep] = _ridge(G[np.ix_(keep, keep)], b[keep], ridge)
        if np.array_equal(keep, np.abs(new) >= threshold) or not keep.any():
            return new
        coef = new
    return coef


def _ridge(G: np.ndarray, b: np.ndarray, ridge: float) -> np.ndarray:
    """The ridge fit of the columns whose normal equations are G c = b."""
    return np.linalg.solve(G + ridge * np.eye(len(b)), b)


def sparse_regression(D: np.ndarray, y: np.ndarray, sweep: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients of the columns of ``D`` for ``y``, and each column's strength (its coefficient on a column of
    unit norm): STLSQ at thresholds from the largest coefficient down to 1e-3 of it, keeping the sparsest
    support that explains at least ``EXPLAINED`` of what the whole dictionary explains."""
    norms = np.linalg.norm(D, axis=0)
    usable = norms > 1e-12 * max(norms.max(initial=0.0), 1e-300)
    X = D[:, usable] / norms[usable]
    out, strength = np.zeros(D.shape[1]), np.zeros(D.shape[1])
    total = float(y @ y)
    if not usable.any() or total == 0:
        return out, strength

    def explained(coef):
        return 1 - float(np.sum((y - X @ coef) ** 2)) / total

    G, b = _normal(X, y)
    target = EXPLAINED * explained(_ridge(G, b, 1e-10))
    top = float(np.abs(_ridge(G, b, RIDGE)).max())
    best = None
    for threshold in np.geomspace(top, 1e-3 * top, sweep):
        coef = _stlsq(G, b, threshold, RIDGE, 10)
        k = int(np.count_nonzero(coef))
        if k and explained(coef) >= target and (best is None or k < np.count_nonzero(best)):
            best = coef
    if best is None:
        return out, strength
    out[usable] = best / norms[usable]
    strength[usable] = np.abs(best)
    return out, strength


def propose_terms(ex, superset: FirstOrderSystem, train: Sequence[Segment], test: Sequence[Segment], keys,
                  options: Integration, harmonics: int, say=None) -> list[Proposal]:
    """The terms of the dictionary that the final model's residual asks for, each refitted (module docstring). The
    terms are added to the final model (the declared one with the effects chosen), not to the search's ``superset``:
    its other candidates are 0 there, and each would cost the dictionary's compiled code and every step of its
    runs for nothing."""
    say = say or (lambda message: None)
    chosen = [ex.library[e] for e in ex.final.effects]
    final_model = augment(ex.system, chosen, name=f"{ex.system.name}_final") if chosen else ex.system
    terms = dictionary(final_model, harmonics)
    effects = [own_term(f"d{i}", f"d_{i}", t, f"dictionary term {term_text(t, final_model)}")
               for i, t in enumerate(terms)]
    model = augment(final_model, effects, name=f"{ex.system.name}_dictionary")
    zeros = {e.fitted[0]: 0.0 for e in effects}
    train = [replace(s, parameters={**s.parameters, **zeros}) for s in train]
    test = [replace(s, parameters={**s.parameters, **zeros}) for s in test]
    final = ex.final.fit
    names = list(final.estimates)
    coefficients = [e.fitted[0] for e in effects]
    y, projected, D = score_columns(model, train, final, coefficients, ex.bias, options)
    # a term the fit's own directions already make (its column all but gone) would be noise blown up
    projected[:, np.linalg.norm(projected, axis=0) < 1e-6 * np.linalg.norm(D, axis=0)] = 0.0
    coef, strength = sparse_regression(projected, y)
    chosen = [int(i) for i in np.argsort(-strength) if strength[i] > 0][:MAX_PROPOSALS]
    bounds = bounds_of([ex.library[e] for e in ex.final.effects])
    out = []
    for i in chosen:
        text = term_text(terms[i], final_model)
        result = fit_windows(model, train, names + [coefficients[i]], guess={**final.estimates, coefficients[i]: coef[i]},
                             starts=final.starts, options=options, bias=ex.bias, bounds=bounds, guess_bias=final.bias)
        prediction = predict_ahead(model, test, keys, result.estimates, options=options, bias=result.bias)
        say(f"proposed term {text}: held-out error {prediction.error:.4g}")
        out.append(Proposal(text, result.estimates[coefficients[i]], result.stderr[coefficients[i]], prediction.error,
                            ex.final.error, float(coef[i])))
    return sorted(out, key=lambda p: p.error)


__all__ = ["MAX_PROPOSALS", "Proposal", "dictionary", "propose_terms", "sparse_regression", "stlsq"]
