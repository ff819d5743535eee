"""Running a compiled model's lanes: many trajectories at one parameter point (or at several that share their
tables of time), L at a time per native call, blocks of them on threads.

The lanes' C (``<model>_lanes.c``, printed by :mod:`.lanes` beside the model's C) is compiled into a library of
its own the first time a model's lanes are asked for (cached like every library). Each call integrates ``L``
trajectories (the lanes of this build: 4 with AVX2, 8 with AVX-512) for whole periods, every lane giving the
scalar loop's numbers for its start (to the bit without fused multiply-adds; with them, to rounding where gcc
fuses other multiply-adds in the scalar loop than in the lanes: tests/test_lanes.py). A model on the in-process
backend, or without a C compiler, runs the scalar loops start by start instead: the same numbers.

Nothing here needs SymPy or the code generator: a cached model's lanes are found and compiled from files.
"""
from __future__ import annotations

import ctypes
import os
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GearsymError
from .code_files import code_directory, is_committed, lanes_describes, lanes_file, source_describes, source_file
from .compiled import CompiledModel, RunInputs
from .compiler import compile_library
from .loaded import load_once, open_library
from .trust import trusted

_ptr = ctypes.c_void_p
#: starts per task of a threaded run: a few dozen native calls, then the caller's reduction of them
CHUNK = 64


class LaneLibrary:
    """The entry points of one lanes library (plain C, called through ctypes: they release Python's lock)."""

    def __init__(self, path: Path):
        self.path = path
        library = open_library(path)
        self.width = int(library.gearsym_lanes())
        self.orbit = library.gearsym_lanes_orbit
        self.orbit.argtypes = [_ptr, _ptr, ctypes.c_longlong, _ptr, _ptr, _ptr, _ptr]
        self.lyapunov = library.gearsym_lanes_lyapunov
        self.lyapunov.argtypes = [_ptr, _ptr, ctypes.c_longlong, _ptr, _ptr, _ptr, _ptr, _ptr, _ptr]
        self.monodromies = library.gearsym_lanes_monodromies  # (pool, tix, p, count, periods, y, M, work)
        self.monodromies.argtypes = [_ptr, _ptr, _ptr, ctypes.c_longlong, ctypes.c_longlong, _ptr, _ptr, _ptr]
        self.states = library.gearsym_lanes_states  # (pool, tix, p, count, periods, columns, y, work)
        self.states.argtypes = [_ptr, _ptr, _ptr, ctypes.c_longlong, ctypes.c_longlong, ctypes.c_longlong, _ptr,
                                _ptr]
        for f in (self.orbit, self.lyapunov, self.monodromies, self.states):
            f.restype = ctypes.c_int


#: one compile of a model's lanes at a time (threads asking at once wait for the first)
_COMPILING = threading.Lock()


def lanes_of(model: CompiledModel, verbose: bool = False) -> LaneLibrary | None:
    """The lanes of ``model``, compiled the first time (a few seconds, once: cached); None for a model on the
    in-process backend (its scalar loops run start by start instead)."""
    if model.backend != "compiled" or model.library is None:
        return None
    folder = code_directory(model.name, model.hash)
    source, included = folder / lanes_file(model.name), folder / source_file(model.name)
    with _COMPILING:
        for path, describes in ((source, lanes_describes), (included, source_describes)):
            if not path.is_file():
                raise GearsymError(f"{model.name}: the C of its lanes ({path}) is missing; generate it again: "
                                   f"`gearsym compile {model.name}` (or delete {folder} and rerun)")
            # (C in the cache is code: compiled only if it is what gearsym wrote there, as the model's own C)
            if not is_committed(folder, model.name) and trusted(path, describes(model.name, model.hash)) is None:
                raise GearsymError(f"{model.name}: the C of its lanes ({path}) is not what gearsym wrote for this "
                                   f"model; delete {folder} and rerun: gearsym makes it again")
        announce = (lambda message: print(f"gearsym: {message}", file=sys.stderr, flush=True)) if verbose else None
        library = compile_library(source, f"{model.name}_lanes", announce=announce, includes=(included,))
    return load_once(("lanes", model.hash, str(library.path)), lambda: LaneLibrary(library.path))


@dataclass(frozen=True)
class OrbitRecords:
    """What runs from many starts recorded after their transient: per start, every measured period's strobe
    (the Poincare points), the observed states' minimum and maximum over its steps, and the final state."""

    strobe: np.ndarray  # (starts, periods, n)
    low: np.ndarray  # (starts, periods, observed)
    high: np.ndarray
    final: np.ndarray  # (starts, n)


@dataclass(frozen=True)
class TangentRecords(OrbitRecords):
    """:class:`OrbitRecords` with each measured period's log stretches of the tangent vectors, and the final
    tangent vectors."""

    log_stretch: np.ndarray  # (starts, periods, n)
    Q: np.ndarray  # (starts, n, n): the final orthonormal tangent vectors (columns)


class LaneRunner:
    """Runs of ``model`` from many starts, ``discard`` periods of transient then ``measured`` recorded, L at a
    time (the lanes) or, without lanes, one at a time (the scalar loops: the same numbers)."""

    def __init__(self, model: CompiledModel, discard: int, measured: int, *, lanes: bool | LaneLibrary = True,
                 verbose: bool = False):
        """``lanes``: True (the model's lanes, compiled the first time), False (the scalar loops), or a
        :class:`LaneLibrary` of the model's lanes built otherwise."""
        self.model, self.discard, self.measured = model, int(discard), int(measured)
        self.library = lanes if isinstance(lanes, LaneLibrary) else lanes_of(model, verbose) if lanes else None
        self.width = self.library.width if self.library else 1
        self._local = threading.local()  # the scalar loops' model of each thread (its work arrays are its own)

    def _scalar_model(self) -> CompiledModel:
        if threading.current_thread() is threading.main_thread():
            return self.model
        model = getattr(self._local, "model", None)
        if model is None:
            model = self._local.model = self.model.clone()
        return model

    @property
    def vectorised(self) -> bool:
        return self.library is not None

    def orbits(self, starts: np.ndarray, inputs: RunInputs | Sequence[RunInputs], constants: np.ndarray | None = None,
               tangent: bool = False) -> OrbitRecords:
        """The records of runs from ``starts`` (k, n) at ``inputs``: one point's for all, or one per start (points
        of a sweep; ``constants``: one row per start instead of the constants of the one ``inputs``, whose table
        they share); ``tangent``: with n tangent vectors from the identity, re-orthonormalised every period."""
        starts = np.asarray(starts, dtype=float)
        n, o = self.model.dimension, len(self.model.observed)
        k, P = starts.shape[0], self.measured
        points = list(inputs) if not isinstance(inputs, RunInputs) else [
            inputs if constants is None else _with_constants(inputs, constants[i]) for i in range(k)]
        if len(points) != k:
            raise GearsymError(f"{self.model.name}: {k} starts but the inputs of {len(points)} points")
        strobe, logs = np.empty((k, P, n)), (np.empty((k, P, n)) if tangent else None)
        low, high, final = np.empty((k, P, o)), np.empty((k, P, o)), np.empty((k, n))
        Q = np.empty((k, n, n)) if tangent else None
        run = self._lane_block if self.library else self._scalar_block
        for at in range(0, k, self.width):
            rows = slice(at, min(k, at + self.width))
            run(starts[rows], points[rows], tangent, strobe[rows], low[rows], high[rows], final[rows],
                None if logs is None else logs[rows], None if Q is None else Q[rows])
        if tangent:
            return TangentRecords(strobe, low, high, final, logs, Q)
        return OrbitRecords(strobe, low, high, final)

    def _lane_block(self, starts, points: list[RunInputs], tangent, strobe, low, high, final, logs, Qs) -> None:
        L, (count, n), o, P = self.width, starts.shape, len(self.model.observed), self.measured
        lanes = np.empty((n, L))
        lanes[:, :count] = starts.T
        lanes[:, count:] = starts[-1:].T  # (unused lanes repeat the last start: finite numbers)
        used = points + [points[-1]] * (L - count)
        cl = np.stack([p.constants for p in used], axis=-1)  # (constants, lanes)
        tables = [p.table for p in used]
        if all(x is tables[0] for x in tables):  # one point's: the same table in every lane (made once)
            made = self.__dict__.get("_shared")
            if made is None or made[0] is not tables[0]:
                made = self._shared = (tables[0], np.repeat(tables[0].reshape(-1, order="F")[:, None], L, axis=1))
            Tl = made[1]
        else:  # step k's entry j of lane l at L*(rows*k + j) + l (a table is column-major: rows x steps)
            Tl = np.stack([x.reshape(-1, order="F") for x in tables], axis=-1)
        Tl = np.ascontiguousarray(Tl)
        s, lo, hi = np.empty((P, n, L)), np.empty((P, o, L)), np.empty((P, o, L))
        table = Tl.ctypes.data
        lib = self.library
        if tangent:
            Q = np.zeros((n * n, L))
            Q[::n + 1] = 1.0  # (r, j) at r*n + j: the identity's diagonal
            lg = np.empty((P, n, L))
            if self.discard:
                lib.lyapunov(table, cl.ctypes.data, self.discard, lanes.ctypes.data, Q.ctypes.data, None, None, None,
                             None)
            lib.lyapunov(table, cl.ctypes.data, P, lanes.ctypes.data, Q.ctypes.data, s.ctypes.data, lg.ctypes.data,
                         lo.ctypes.data, hi.ctypes.data)
            logs[...] = lg.transpose(2, 0, 1)[:count]
            Qs[...] = Q.reshape(n, n, L).transpose(2, 0, 1)[:count]  # (r, j) of lane l: row r of vector j
        else:
            if self.discard:
                lib.orbit(table, cl.ctypes.data, self.discard, lanes.ctypes.data, None, None, None)
            lib.orbit(table, cl.ctypes.data, P, lanes.ctypes.data, s.ctypes.data, lo.ctypes.data, hi.ctypes.data)
        strobe[...] = s.transpose(2, 0, 1)[:count]
        low[...], high[...] = lo.transpose(2, 0, 1)[:count], hi.transpose(2, 0, 1)[:count]
        final[...] = lanes.T[:count]

    def _scalar_block(self, starts, points: list[RunInputs], tangent, strobe, low, high, final, logs, Qs) -> None:
        model, d, periods = self._scalar_model(), self.discard, self.discard + self.measured
        for i, (y0, point) in enumerate(zip(starts, points)):
            try:
                if tangent:
                    run = model.tangent_run(y0, periods, point)
                    s, lo, hi = run.strobe, run.low, run.high
                    logs[i], Qs[i] = run.log_stretch[:, d:].T, run.Q
                else:
                    s, lo, hi = model.orbit_run(y0, periods, point)
            except GearsymError:  # diverged: its records are not finite (as the lanes' would be: inf or NaN)
                o = len(model.observed)
                s, lo, hi = (np.full((rows, periods), np.nan) for rows in (model.dimension, o, o))
                if tangent:
                    logs[i], Qs[i] = np.nan, np.nan
            strobe[i], low[i], high[i], final[i] = s[:, d:].T, lo[:, d:].T, hi[:, d:].T, s[:, -1]


def _with_constants(inputs: RunInputs, constants: np.ndarray) -> RunInputs:
    """``inputs`` with other constants (the same table)."""
    c = np.ascontiguousarray(constants, dtype=float)
    point = RunInputs(inputs.p, inputs.table, c, inputs.period, inputs.t0, inputs.model_hash)
    point.__dict__["addresses"] = (inputs.addresses[0], c.ctypes.data)
    return point


def chunked(count: int, size: int = CHUNK) -> list[slice]:
    """``range(count)`` in slices of ``size``."""
    return [slice(a, min(count, a + size)) for a in range(0, count, size)]


def threaded(work: Callable[[slice], object], chunks: Sequence[slice], jobs: int) -> Iterator:
    """``work(chunk)`` of every chunk on up to ``jobs`` threads (the native calls release Python's lock), the
    results yielded in the chunks' order; on an error or Ctrl-C the threads stop after their current chunk."""
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(chunks)))
    if jobs == 1:
        for chunk in chunks:
            yield work(chunk)
        return
    stop = threading.Event()

    def guarded(chunk):
        return None if stop.is_set() else work(chunk)

    pool = ThreadPoolExecutor(max_workers=jobs, thread_name_prefix="gearsym-lanes")
    try:
        futures = [pool.submit(guarded, chunk) for chunk in chunks]
        for future in futures:
            yield future.result()
    finally:
        stop.set()
        pool.shutdown(wait=True, cancel_futures=True)


def finite_rows(records: OrbitRecords) -> np.ndarray:
    """Per start, whether its records stayed finite (a start that diverged did not)."""
    return np.isfinite(records.strobe).all(axis=(1, 2)) & np.isfinite(records.final).all(axis=1)
