"""Which tongues the mesh phasing leaves, to first order: the prediction drawn beside a chart of a model with several
meshes (a planetary set).

Linearised about its static state a gear model is x'' + (C/omega) x' + (A(tau)/omega^2) x = 0 in the tau-form,
A(tau) = A_0 + sum_l (A_l e^{i l tau} + c.c.) the stiffness matrix with each mesh's variation k(tau - phase). With
the modes of A_0 (natural frequencies omega_i = sqrt(lambda_i), in units of omega_n) and C_l = V^-1 A_l V the
l-th harmonic in modal coordinates, the method of multiple scales gives the first-order instability regions
(Nayfeh & Mook, Nonlinear Oscillations, ch. 5; as Lin & Parker, J. Sound Vib. 249 (2002) 129-145, do for
planetary gears):

* primary, l omega = 2 omega_i (+-) |C_l[ii]| / omega_i: a real multiplier through (-1)^l;
* combination, l omega = omega_i + omega_j (+-) sqrt(|C_l[ij] C_l[ji]| / (omega_i omega_j)): a complex pair;

for a repeated frequency (a planetary set's planet modes, N - 1 of them) the blocks' largest singular values.
A tongue whose modal coupling vanishes is absent to first order: that is what the mesh phasing does. For N
equally spaced planets on a sun of Z_s teeth, the l-th harmonics of the N sun meshes sum to zero over the planets
unless l Z_s / N is a whole number, so the rotational modes' tongues of the other harmonics vanish (and the planet
modes' appear): Parker's phasing rule, here not assumed but found from the model's own phases.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .chart import StabilityChart
from .kinds import FOLD, NEIMARK_SACKER, PERIOD_DOUBLING
from .recipe import CompiledLinearisation, anchor_parameter
from .static_states import solve_static

#: harmonics of the mesh frequency looked at (the higher ones' tongues are too thin to see on a chart)
HARMONICS = 3
#: samples of a period for the harmonics (exact for the models' Fourier series of lower degree)
SAMPLES = 64
#: a coupling below this fraction of the largest is cancelled (by the phasing)
CANCELLED = 1e-6


@dataclass(frozen=True)
class Tongue:
    """A first-order tongue: where it starts on the frequency axis, its half-width there per unit of the variation
    axis's value ``scale`` (a wedge), its kind, a label, and whether the phasing cancels it."""

    centre: float
    half_width: float
    kind: str
    label: str
    suppressed: bool
    coupling: float

    def edges(self, eps: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
        w = self.half_width * np.asarray(eps, dtype=float) / scale
        return self.centre - w, self.centre + w


@dataclass(frozen=True)
class PhasingPrediction:
    tongues: tuple[Tongue, ...]
    scale: float  # the variation axis's value the widths were computed at
    frequencies: tuple[float, ...]
    title: str


def phasing_prediction(chart: StabilityChart, lin: CompiledLinearisation, frequency_axis: str = "omega",
                       factor: float = 1.0) -> PhasingPrediction | None:
    """The first-order tongues of ``lin`` over ``chart``'s second axis (the stiffness variation) and its first
    (the forcing frequency ``frequency_axis`` of the engine; ``factor`` turns it into the chart's unit: rpm per
    unit of omega for a chart along the speed). None where the chart's axes are not those."""
    model = lin.model
    names = model.parameter_names
    if chart.names[0] != frequency_axis:
        return None
    variation = chart.names[1]
    engine_variation = variation if variation in lin.base_parameters else None
    if engine_variation is None or frequency_axis not in lin.base_parameters:
        return None
    scale = float(np.max(chart.values[1])) or 1.0
    base = dict(lin.base_parameters)
    base.update(chart.fixed)
    base.update({frequency_axis: 1.0, engine_variation: scale})
    A = [_stiffness(lin, {**base, engine_variation: at}, names) for at in (scale, scale / 2)]
    harmonics = [_harmonics(a) for a in A]
    A0, Al = harmonics[0]
    linear = all(np.allclose(2 * h2, h1, rtol=1e-6, atol=1e-12 * np.abs(A0).max()) for h1, h2 in
                 zip(Al, harmonics[1][1]))
    lam, V = np.linalg.eig(A0)
    order = np.argsort(lam.real)
    lam, V = lam[order].real, V[:, order]
    if np.any(lam <= 0):
        return None
    freq = np.sqrt(lam)
    groups = _groups(freq)
    Vinv = np.linalg.inv(V)
    candidates = []
    for l, Ah in enumerate(Al, start=1):
        C = Vinv @ Ah @ V
        for gi, g in enumerate(groups):
            for h in groups[gi:]:
                wg, wh = freq[g].mean(), freq[h].mean()
                s = np.sqrt(np.linalg.norm(C[np.ix_(g, h)], 2) * np.linalg.norm(C[np.ix_(h, g)], 2))
                primary = g == h
                half = s / (wg * l) if primary else s / (np.sqrt(wg * wh) * l)
                kind = (PERIOD_DOUBLING if l % 2 else FOLD) if primary else NEIMARK_SACKER
                gi_, hi_ = groups.index(g) + 1, groups.index(h) + 1
                label = f"2ω{gi_}/{l}" if primary else f"(ω{gi_}+ω{hi_})/{l}"
                candidates.append(((wg + wh) / l, half, kind, label, s))
    largest = max((c[4] for c in candidates), default=0.0)
    tongues = tuple(Tongue(centre * factor, half * factor, kind, label, s <= CANCELLED * largest, s)
                    for centre, half, kind, label, s in candidates)
    kept = sum(not t.suppressed for t in tongues)
    title = (f"first-order prediction with the mesh phases: {kept} tongue(s) kept, {len(tongues) - kept} suppressed "
             f"(harmonics 1-{HARMONICS}; ω_i = " + ", ".join(f"{w:.4g}" for w in freq[[g[0] for g in groups]]) + ")"
             + ("" if linear else "; the harmonics are not linear in the variation: wedges approximate"))
    return PhasingPrediction(tongues, scale, tuple(float(w) for w in freq), title)


def _stiffness(lin: CompiledLinearisation, values: dict, names) -> np.ndarray:
    """A(tau) at the samples (samples x n x n): minus the block of the Jacobian that takes positions to
    accelerations (at omega = 1 in ``values``), linearised at the static state."""
    model = lin.model
    base_names = tuple(lin.base_parameters)
    base = np.array([[values[n] for n in base_names]])
    static = solve_static(lin.recipe, base_names, base)
    p = np.array([values.get(n, 0.0) for n in names])
    for s in lin.anchors:
        p[names.index(anchor_parameter(s))] = static.states[0, lin.recipe.states.index(s)]
    period = model.prepare(p).period
    n = model.dimension
    J = np.array([model.jacobian(period * k / SAMPLES, np.zeros(n), p) for k in range(SAMPLES)])
    positions, velocities = _pairs(J[0])
    return -J[:, velocities][:, :, positions]


def _pairs(J: np.ndarray) -> tuple[list[int], list[int]]:
    """(positions, the row of each one's acceleration): x_i' = v_j rows of the first-order system."""
    positions, velocities = [], []
    for i, row in enumerate(J):
        ones = np.nonzero(row == 1.0)[0]
        if len(ones) == 1 and np.count_nonzero(row) == 1:
            positions.append(i)
            velocities.append(int(ones[0]))
    return positions, velocities


def _harmonics(A: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """The mean and the complex harmonics 1..HARMONICS of samples of a period."""
    k = np.arange(SAMPLES)
    A0 = A.mean(axis=0)
    return A0, [np.tensordot(np.exp(-1j * l * 2 * np.pi * k / SAMPLES), A, axes=1) / SAMPLES
                for l in range(1, HARMONICS + 1)]


def _groups(freq: np.ndarray) -> list[list[int]]:
    """Indices of equal frequencies (a repeated mode: a planetary set's planet modes)."""
    groups: list[list[int]] = []
    for i, w in enumerate(freq):
        if groups and abs(w - freq[groups[-1][0]]) <= 1e-7 * max(1.0, w):
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups
