"""Which tooth: the scan that places a tooth fault on one tooth of its gear, in every record.

A tooth fault's severity is a parameter like any other, but its tooth is a whole number: for each record and
each of the gear's Z teeth, the linearised gain of the severity (the score test of :mod:`.explain`: the fraction
of the training residual its exact sensitivity column would remove, with the fit's own directions projected
out) is computed, and each record takes the tooth of largest gain whose severity comes out positive (a fault
takes stiffness away). Records are placed separately, because each may start at another angle of the gear.

The column of tooth n is zero outside the windows where its pair is in mesh (its share of the stiffness is 0
there to rounding, and every window has its own start state), so each tooth's column is computed on those
windows only: the whole scan costs about three runs of the record's windows, not Z. The faults scanned together
share those runs: every severity is 0 at the fit, so the state, its stages and the start's columns are the same
for all of them, and one compiled call gives each fault its own column with its own tooth (the 20/53 pair's library
of docs/examples/explain-cracked-tooth scans four faults, a tooth fault and a spall on each gear: its scans' window
runs 7.5 -> 4.7 s of CPU, the placements and the report the same bits).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..options import Integration
from ..system import FirstOrderSystem
from .effect_types import Effect
from .problem import Problem
from .result import Fit
from .segment import Segment

#: mesh periods beyond a pair's path of contact in which its column is still computed (its window's edges)
MARGIN = 0.5
#: the contact ratio of the effects' tooth share (:func:`gearsym.model.shaft_orders.tooth_share`)
CONTACT = 1.6


@dataclass(frozen=True)
class Placement:
    """Where a tooth fault sits: per record (its key), the tooth counted from tau = 0; the gain of each record's
    best tooth, and the gain of them all together (what the candidate is ranked by)."""

    teeth: dict  # record key -> tooth (1 ... Z), counted from tau = 0
    gains: dict  # record key -> the gain of that tooth in that record alone
    gain: float
    why: str = ""  # why the effect cannot act (0 gain)


def scan_teeth(system: FirstOrderSystem, segments: Sequence[Segment], fit: Fit, effects: Sequence[Effect],
               bias: Sequence[str], options: Integration) -> dict[str, Placement]:
    """Place each tooth fault of ``effects`` in every record of ``segments`` at the fit ``fit`` (see the module
    docstring), by name. The residual, its Jacobian by what the fit estimates and their projection are the same for
    every fault (its severity is 0 at the fit, its own column computed tooth by tooth): computed once for them all."""
    if not effects:
        return {}
    fitted = list(fit.estimates)
    problem = Problem(system, segments, fitted, list(bias), 2 * np.pi, options)
    theta = np.array([fit.estimates[p] for p in fitted])
    b = np.array([fit.bias[c] for c in problem.bias])
    starts = fit.starts
    r, nuisance = problem(np.concatenate([theta, b, starts.reshape(-1, order="F")]))
    y = nuisance.project_out(-r[:, None])[:, 0]
    total = float(y @ y) or 1.0
    projection = RecordProjection.of(nuisance, y)
    records = list(dict.fromkeys(seg.key[0] if seg.key else k for k, seg in enumerate(segments)))
    of_record = np.array([records.index(seg.key[0] if seg.key else k) for k, seg in enumerate(segments)])
    P = problem.parameters(theta)
    scans = [_Scan.of(problem, e, len(y), projection.fitted.shape[1]) for e in effects]
    # the faults whose severity is 0 at the fit in every window share their runs (the state, its stages and the
    # start's columns the same bits for all: their severities move nothing), each asking for its own column with its
    # own tooth; a fault in place (a refit's own) runs alone, as the others see it
    shared = [s for s in scans if not np.any(P[s.index_q, :])]
    groups = ([shared] if shared else []) + [[s] for s in scans if s not in shared]
    for ri, record in enumerate(records):
        windows = np.nonzero(of_record == ri)[0]
        rows = nuisance.window_rows(windows)
        for group in groups:
            blocks = _record_columns(problem, windows, rows, starts, P, group)
            for scan, block in zip(group, blocks):
                scan.add(record, rows, projection(block, windows, rows), total)
    return {s.effect.name: s.placement(projection, y, total) for s in scans}


@dataclass
class _Scan:
    """One tooth fault's scan as it goes through the records: each record's tooth of largest gain, its gain, and the
    chosen columns' sum (own rows, and along the fitted parameters' projected columns)."""

    effect: Effect
    order: float
    index_q: int
    index_n: int
    teeth: dict
    gains: dict
    raw: np.ndarray  # (residuals,)
    along: np.ndarray  # (fitted parameters,)

    @classmethod
    def of(cls, problem: Problem, e: Effect, residuals: int, fitted: int) -> "_Scan":
        order = float(next(c.order for c in problem.system.couplings if c.coordinate == e.coordinate) or 1)
        return cls(e, order, problem.names.index(e.fitted[0]), problem.names.index(e.scan), {}, {},
                   np.zeros(residuals), np.zeros(fitted))

    def add(self, record, rows: np.ndarray, projected, total: float) -> None:
        """The record's columns, one a tooth, as ``RecordProjection`` gives them: its best tooth chosen."""
        own, c, norms, dots = projected
        with np.errstate(invalid="ignore", divide="ignore"):
            coef = np.where(norms > 0, dots / norms, 0.0)
            gain = np.where((norms > 0) & (coef > 0), dots**2 / (norms * total), 0.0)
        best = int(np.argmax(gain))
        self.teeth[record], self.gains[record] = best + 1, float(gain[best])
        self.raw[rows] += own[:, best]
        self.along += c[:, best]

    def placement(self, projection: "RecordProjection", y: np.ndarray, total: float) -> Placement:
        """The fault placed in every record: each record's tooth of largest gain, and their gain together."""
        together = self.raw - projection.fitted @ self.along
        norm = float(together @ together)
        if norm <= 0 or not any(g > 0 for g in self.gains.values()):
            return Placement(self.teeth, self.gains, 0.0, "no tooth of it would need a positive loss of stiffness")
        coef = float(together @ y) / norm
        gain = float((together @ y) ** 2 / (norm * total)) if coef > 0 else 0.0
        return Placement(self.teeth, self.gains, gain)


@dataclass(frozen=True)
class RecordProjection:
    """``nuisance.project_out`` of columns that are nonzero on one record's rows only, in that record's memory: the
    start states act on their own windows' rows, so that part stays there; the fitted parameters' part is a small
    dense correction along their projected columns ``fitted`` (never formed per record). With the projected
    residual ``y``, each column's squared norm and its product with ``y`` (the score test's gain)."""

    fitted: np.ndarray  # the parameters' columns with the starts' part removed (residuals, k)
    inverse: np.ndarray  # (fitted^T fitted)^+
    along_y: np.ndarray  # fitted^T y
    nuisance: object
    y: np.ndarray

    @classmethod
    def of(cls, nuisance, y: np.ndarray) -> "RecordProjection":
        fitted = nuisance.out_of_starts(nuisance.P)
        return cls(fitted, np.linalg.pinv(fitted.T @ fitted), fitted.T @ y, nuisance, y)

    def __call__(self, block: np.ndarray, windows: np.ndarray, rows: np.ndarray):
        """For ``block`` (the rows of ``windows``, which are ``rows``): its starts-projected part on those rows, the
        coefficients ``c`` of its parameters' part (the whole projection is own on the rows minus fitted @ c), and
        each column's squared norm and product with y."""
        own = self.nuisance.out_of_starts(block, windows)
        a = self.fitted[rows].T @ own  # (k, columns)
        c = self.inverse @ a
        norms = np.einsum("rz,rz->z", own, own) - np.einsum("kz,kz->z", a, c)
        dots = own.T @ self.y[rows] - c.T @ self.along_y
        return own, c, norms, dots


def _record_columns(problem: Problem, windows: np.ndarray, rows: np.ndarray, starts: np.ndarray, P: np.ndarray,
                    scans: Sequence[_Scan]) -> list[np.ndarray]:
    """For each fault of ``scans``, the sensitivity column of its severity with the fault on each tooth 1 ... Z in
    turn, on the windows of one record (its ``rows`` of the whole problem only: zero elsewhere), (rows, Z): each
    tooth's windows only, in compiled calls shared by the faults (run i of a window puts each fault on its i-th tooth
    that meets the window, every severity at 0 and each asked for its own column)."""
    runs, which = [], []  # per run: its window, and each fault's tooth (0: none of its teeth left for that window)
    for k in windows:
        t0 = problem.t0[k]
        t1 = t0 + problem.dt[k] * (problem.samples[k] - 1)
        met = [[n for n in range(1, s.effect.teeth + 1) if _meets(t0, t1, n, s.effect.teeth, 2 * np.pi / s.order)]
               for s in scans]
        for i in range(max(map(len, met))):
            runs.append(k)
            which.append([teeth[i] if i < len(teeth) else 0 for teeth in met])
    out = [np.zeros((len(rows), s.effect.teeth)) for s in scans]
    if not runs:
        return out
    runs, which = np.array(runs), np.array(which)
    params = P[:, runs].copy()
    for j, s in enumerate(scans):
        params[s.index_q, :] = 0.0  # (the fault's severity at the fit: 0)
        params[s.index_n, :] = np.where(which[:, j] > 0, which[:, j], 1)  # (a tooth of none left: its column unused)
    run = problem.engine.run(starts[:, runs], problem.t0[runs], problem.dt[runs], problem.samples[runs],
                             problem.substeps[runs], params, True, columns=[s.index_q for s in scans])
    sub_offsets = np.concatenate([[0], np.cumsum(problem.samples[runs])])
    first = {k: int(np.searchsorted(rows, problem.row_offsets[k])) for k in windows}  # (where window k starts)
    for i, k in enumerate(runs):
        these = slice(problem.row_offsets[k], problem.row_offsets[k + 1])
        channels = problem.rows[0][these]
        samples = problem.rows[1][these] - problem.offsets[k] + sub_offsets[i]
        at = slice(first[k], first[k] + these.stop - these.start)
        for j, n in enumerate(which[i]):
            if n:
                out[j][at, n - 1] = run.derivatives[channels, problem.n + j, samples] * problem.weight[these]
    return out


def _meets(t0: float, t1: float, tooth: int, teeth: int, period: float) -> bool:
    """Whether the pair of ``tooth`` is in mesh (within MARGIN mesh periods) somewhere in [t0, t1]."""
    revolution = teeth * period
    centre = (tooth - 0.5) * period
    reach = (CONTACT / 2 + MARGIN) * period
    k = np.floor((t0 - centre - reach) / revolution)
    while centre + k * revolution - reach <= t1:
        if centre + k * revolution + reach >= t0:
            return True
        k += 1
    return False


def from_record_start(tooth: int, teeth: int, start: float, order: float = 1.0) -> int:
    """A tooth counted from tau = 0 as counted from a record that starts at ``start``: tooth 1 is the one whose pair
    is in single contact in the mesh period the record starts in."""
    cycle = int(np.floor(order * start / (2 * np.pi) + 1e-9))
    return (tooth - 1 - cycle) % teeth + 1
