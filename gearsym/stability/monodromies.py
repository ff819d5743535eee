"""Monodromy matrices of many parameter points at once: one per lane, a block of points per native call.

Each point has its own parameter vector; its constants are computed in the lanes from it, its tables of time
are taken from a pool in which points whose tables are the same (the same values of the parameters that enter
them: ``CompiledModel.timed_parameters``) share one. A point never runs on another point's table: the pool is
keyed by those values, not by the order of the points (a chart across Theta or k_a has a table per value). The
points are ordered by their table so that a block of L lanes mostly shares one (copied once per block).

A model on the in-process backend, or without lanes, runs the scalar loops point by point (``shoot``): the same
numbers, slower.
"""
from __future__ import annotations

import ctypes
from collections.abc import Callable

import numpy as np

from ..codegen.compiled import CompiledModel
from ..codegen.lane_runs import LaneLibrary, chunked, lanes_of, threaded
from ..errors import GearsymError
from ..checks import check_fits

#: points per native call (and per task of a threaded run)
CALL_POINTS = 1024


class MonodromyRunner:
    """The monodromy matrices of ``model`` at many parameter vectors."""

    def __init__(self, model: CompiledModel, *, lanes: bool = True, jobs: int = 0, verbose: bool = False,
                 linear: bool = False):
        """``linear``: the model is linear and homogeneous (a linearisation): its state alone gives the matrix."""
        self.model, self.jobs, self.linear = model, jobs, linear
        self.library: LaneLibrary | None = lanes_of(model, verbose) if lanes else None
        names = model.parameter_names
        self.timed = [names.index(n) for n in names if n in model.timed_parameters]
        self._tables: dict[bytes, int] = {}
        self._pool: list[np.ndarray] = []

    @property
    def width(self) -> int:
        return self.library.width if self.library else 1

    def table_indices(self, p: np.ndarray) -> np.ndarray:
        """The index in the pool of each point's tables (computed, and the period checked, once per distinct
        value of the timed parameters)."""
        distinct, first, inverse = distinct_rows(p[:, self.timed])
        keys = [row.tobytes() for row in distinct]
        new = [k for k, key in enumerate(keys) if key not in self._tables]
        if new:
            tables = self.model.tables(p[first[new]])
            for k, table in zip(new, tables):
                self._tables[keys[k]] = len(self._pool)
                self._pool.append(table)
        return np.array([self._tables[key] for key in keys], dtype=np.int64)[inverse]

    def run(self, p: np.ndarray, y0: np.ndarray | None, periods: int = 1,
            progress: Callable[[int, int], None] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(state after ``periods`` periods, tangent map from the identity over them) for each row of ``p``
        (points x parameters) from the row of ``y0`` (points x states; None: every state 0)."""
        model = self.model
        count, n = len(p), model.dimension
        zero = y0 is None
        p, y0 = np.asarray(p, dtype=float), np.zeros((count, n)) if zero else np.asarray(y0, dtype=float)
        if p.shape != (count, len(model.parameter_names)) or y0.shape != (count, n):
            raise GearsymError(f"{model.name}: {p.shape} parameter vectors and {y0.shape} states do not fit "
                               f"{len(model.parameter_names)} parameters and {n} states")
        if not np.isfinite(p).all():
            raise GearsymError(f"{model.name}: every parameter value of a chart must be finite")
        check_fits(count, 8 * (2 * n * n + 2 * n + n * p.shape[1]), asked=f"a chart of {count} points",
                   item="point", what="each point's monodromy matrix, states and parameters")
        if count == 0:
            return np.empty((0, n)), np.empty((0, n, n))
        tix = self.table_indices(p)
        if self.library is None:
            return self._scalar(p, y0, periods, tix, progress)
        if self.linear:  # the state is its own tangent: the identity's columns, one lane each
            columns = self._lanes(p, None, tix, periods, progress, n)
            M = columns.reshape(count, n, n).transpose(0, 2, 1)
            return (y0 if zero else np.einsum("kij,kj->ki", M, y0)), M
        M = np.empty((count, n, n))
        return self._lanes(p, y0, tix, periods, progress, 0, M), M

    def _lanes(self, p, y, tix, periods, progress, columns: int, M=None) -> np.ndarray:
        """The lanes on every point, ordered by table (points that share one side by side), in chunks of
        :data:`CALL_POINTS` points on up to ``jobs`` threads: the final states (``columns``: n of them per point,
        from the identity's columns, without the tangent) and, with ``M``, the tangent maps."""
        count, n = len(p), self.model.dimension
        order = None if np.all(tix[1:] >= tix[:-1]) else np.argsort(tix, kind="stable")  # (a grid's are sorted)
        ordered = tix if order is None else tix[order]
        used = ordered[np.append(True, ordered[1:] != ordered[:-1])]  # (the tables of these points only: a
        pool = np.ascontiguousarray(np.stack([self._pool[k] for k in used]))  # refinement's pool grows by round)
        size, width = pool.shape[1], self.library.width
        P = np.ascontiguousarray(p if order is None else p[order])
        slot = np.empty(used[-1] + 1, dtype=np.int64)
        slot[used] = np.arange(len(used))
        T = slot[ordered]
        per = max(1, columns)
        Y = np.empty((count * per, n)) if columns else np.ascontiguousarray(y if order is None else y[order])
        out = None if M is None else M if order is None else np.empty_like(M)
        # the arrays' addresses once (numpy's .ctypes costs microseconds, a chart makes hundreds of calls); each
        # chunk's its rows' offsets from them, its work room a ctypes array of its own
        at = [pool.ctypes.data, T.ctypes.data, P.ctypes.data, Y.ctypes.data, 0 if out is None else out.ctypes.data]
        rows_of = [0, 8, 8 * P.shape[1], 8 * n * per, 8 * n * n]
        room = ctypes.c_double * (max(1, size) * width)

        def work(rows: slice):
            k, first = rows.stop - rows.start, rows.start
            buffer = room()
            _, t, q, yy, mm = (a + first * r for a, r in zip(at, rows_of))
            if M is None:
                self.library.states(at[0], t, q, k, int(periods), columns, yy, ctypes.addressof(buffer))
            else:
                self.library.monodromies(at[0], t, q, k, int(periods), yy, mm, ctypes.addressof(buffer))
            return k

        done = 0
        for finished in threaded(work, chunked(count, CALL_POINTS), self.jobs):
            done += finished
            if progress:
                progress(done, count)
        if order is None:
            return Y
        final = np.empty_like(Y)
        final.reshape(count, per, n)[order] = Y.reshape(count, per, n)
        if M is not None:
            M[order] = out
        return final

    def _scalar(self, p, y0, periods, tix, progress) -> tuple[np.ndarray, np.ndarray]:
        model = self.model
        y, M = np.empty_like(y0), np.empty((len(p), model.dimension, model.dimension))
        for i in range(len(p)):
            inputs = model.prepare(p[i])
            shot = model.shoot(y0[i], inputs, pieces=model.shooting_pieces * int(periods))
            y[i], M[i] = shot.state, shot.M
            if progress and (i + 1) % 256 == 0:
                progress(i + 1, len(p))
        return y, M


def distinct_rows(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(the distinct rows of ``keys`` in sorted order, the first row of each, the index of each row's among them):
    numpy's ``unique(axis=0)`` by numeric sorts (it sorts rows as bytes, 100 times slower on a chart's 160 000
    rows), on the runs of equal rows (a grid's points come row by row: the values of its second axis in runs)."""
    count = len(keys)
    if keys.shape[1] == 0 or count == 0:
        return keys[:min(1, count)], np.zeros(min(1, count), dtype=np.int64), np.zeros(count, dtype=np.int64)
    change = np.empty(count, dtype=bool)
    change[0] = True
    np.any(keys[1:] != keys[:-1], axis=1, out=change[1:])
    starts = np.flatnonzero(change)
    if len(starts) == 1:  # (one row: a grid across other parameters)
        return keys[:1], np.zeros(1, dtype=np.int64), np.zeros(count, dtype=np.int64)
    if len(starts) < count:  # (the distinct rows of the runs' first rows, each row its run's)
        distinct, first, inverse = _distinct_sorted(keys[starts])
        return distinct, starts[first], np.repeat(inverse, np.diff(np.append(starts, count)))
    return _distinct_sorted(keys)


def _distinct_sorted(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    count = len(keys)
    varying = np.nonzero((keys != keys[0]).any(axis=0))[0]
    if len(varying) == 1:  # (one column: numpy's own unique)
        _, first, inverse = np.unique(keys[:, varying[0]], return_index=True, return_inverse=True)
        return keys[first], first, inverse.reshape(-1)
    order = np.lexsort(keys.T[::-1])
    ordered = keys[order]
    new = np.ones(count, dtype=bool)
    new[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    group = np.cumsum(new) - 1
    inverse = np.empty(count, dtype=np.int64)
    inverse[order] = group
    first = order[new]
    return keys[first], first, inverse
